//! Pictures of parts and stacks: SVG and PNG figures made of panels, each panel one view of a scene.
//!
//! Each convex component is drawn face by face: faces turned away from the viewer are culled, the rest are sorted
//! back to front by the depth of their centroid (painter's algorithm) and shaded with a fixed light (Lambert). For
//! convex components of parts that do not interpenetrate this ordering is right almost everywhere; where two faces of
//! different parts overlap in depth it can be wrong in a small region — pictures are for people, the JSON is the
//! result. O(F log F) for F faces.
//!
//! A face's edges are outlined except the *seams* of the convex decomposition: an edge shared by two coplanar faces
//! (same outward normal) of one part is drawn in the face's own colour, so a sheet-metal face split into convex pieces
//! reads as the one face it is, and its bends, holes and outline stay drawn
//! (`outlines_skip_the_seams_of_a_decomposition`). Seams are found by matching edges whose end points agree after
//! rounding to 1e-7 of the scene's size, once per scene (the three views of a stack share them).
//!
//! One drawing routine ([`draw_figure`]) serves both formats through the [`Canvas`] trait: [`SvgCanvas`] writes SVG
//! elements, [`PngCanvas`] paints with tiny-skia and writes text with the bundled DejaVu Sans
//! (`assets/fonts/DejaVuSans.ttf`, rasterised by `ab_glyph`; the SVG names the same font). Text is measured with that
//! font for both formats, so the two lay out alike.
//!
//! Every figure reads without the docs: a title, a legend under it ([`LegendItem`]: the colours, the c.g. mark, the
//! floor), a caption under each panel (the view's name), and the parts' numbers. A number sits in a white box above
//! its part's c.g. when that place is free; otherwise the box goes to the nearest free place in the panel and a leader
//! line joins it to the c.g. ([`label_layout`]), so that no two boxes overlap. O(L^2 G) for L labels and G candidate
//! places per panel.

use ab_glyph::{Font, FontRef, PxScale, ScaleFont};
use stackplan_geom::{ConvexPolytope, DVec2, DVec3};
use std::fmt::Write;

/// One thing to draw: a convex solid in world coordinates with its colour and the label of the part it belongs to.
#[derive(Debug, Clone)]
pub struct Solid {
    /// The solid, in world coordinates.
    pub polytope: ConvexPolytope,
    /// Base colour (sRGB, 0..255).
    pub color: [u8; 3],
    /// Index of the part it belongs to (0-based; the pictures number parts from 1).
    pub part: usize,
}

/// A marker drawn on top (e.g. a centre of gravity).
#[derive(Debug, Clone, Copy)]
pub struct Marker {
    /// World position.
    pub position: DVec3,
    /// Colour.
    pub color: [u8; 3],
}

/// A scene: solids, markers, an optional floor rectangle/polygon (z = 0) and a title.
#[derive(Debug, Clone, Default)]
pub struct Scene {
    /// Solids.
    pub solids: Vec<Solid>,
    /// Markers.
    pub markers: Vec<Marker>,
    /// Floor polygon at z = 0 (drawn as an outline), if any.
    pub floor: Vec<DVec3>,
    /// Title.
    pub title: String,
    /// Label each part with its number at its c.g. (one position per part; the number as written, 1-based).
    pub labels: Vec<(usize, DVec3)>,
    /// The legend of its pictures.
    pub legend: Vec<LegendItem>,
}

/// A view: the direction the viewer looks along and the screen's up vector.
#[derive(Debug, Clone, Copy)]
pub struct View {
    /// Name shown under the view.
    pub name: &'static str,
    /// Direction from the scene to the viewer.
    pub toward_viewer: DVec3,
    /// World direction that points up on screen.
    pub up: DVec3,
}

/// The isometric view.
pub const ISOMETRIC: View = View { name: "isometric", toward_viewer: DVec3::new(1.0, -1.0, 0.9), up: DVec3::Z };

/// The three views of every stack and part picture.
pub const VIEWS: [View; 3] = [
    ISOMETRIC,
    View { name: "top", toward_viewer: DVec3::Z, up: DVec3::Y },
    View { name: "side (from -y)", toward_viewer: DVec3::NEG_Y, up: DVec3::Z },
];

/// A palette of distinguishable colours for numbered parts.
pub fn part_color(i: usize) -> [u8; 3] {
    const P: [[u8; 3]; 10] = [
        [78, 121, 167],
        [242, 142, 43],
        [225, 87, 89],
        [118, 183, 178],
        [89, 161, 79],
        [237, 201, 72],
        [176, 122, 161],
        [255, 157, 167],
        [156, 117, 95],
        [186, 176, 172],
    ];
    P[i % P.len()]
}

/// The colour of parts that are not highlighted (earlier parts in a build frame).
pub const MUTED: [u8; 3] = [214, 214, 214];

/// One panel of a figure: a scene seen in one view, with a caption below it.
#[derive(Debug, Clone)]
pub struct FigurePanel<'a> {
    /// What is drawn.
    pub scene: &'a Scene,
    /// How it is seen.
    pub view: View,
    /// Text under the panel.
    pub caption: String,
}

/// A figure: panels on a grid of equal cells under a title.
#[derive(Debug, Clone)]
pub struct Figure<'a> {
    /// Title at the top.
    pub title: String,
    /// What the colours and marks mean, in a row under the title (none: no row).
    pub legend: Vec<LegendItem>,
    /// The panels, row by row.
    pub panels: Vec<FigurePanel<'a>>,
    /// Panels per row (at least 1).
    pub columns: usize,
    /// Cell width and height (SVG units; the caption lies below the cell).
    pub cell: (f64, f64),
    /// One scale for every panel, each panel's lowest point on its cell's bottom (so heights compare across panels,
    /// as in a build strip or a sweep); otherwise each panel is fitted and centred on its own.
    pub common_scale: bool,
}

const MARGIN: f64 = 14.0;
const TITLE: f64 = 28.0;
const LEGEND: f64 = 20.0;
const CAPTION: f64 = 18.0;

/// The mark drawn before a legend entry's text.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Swatch {
    /// A filled square of this colour (a part's colour).
    Square([u8; 3]),
    /// A disc of this colour (the c.g. mark).
    Disc([u8; 3]),
    /// A dashed outline on the floor's grey (the floor area).
    Floor,
    /// A numbered label box with a leader line.
    Label,
}

/// One entry of a figure's legend.
#[derive(Debug, Clone, PartialEq)]
pub struct LegendItem {
    /// The mark.
    pub swatch: Swatch,
    /// What it means.
    pub text: String,
}

impl LegendItem {
    /// An entry.
    pub fn new(swatch: Swatch, text: impl Into<String>) -> Self {
        Self { swatch, text: text.into() }
    }
}

/// The legend of pictures of numbered parts: part colours, label boxes, the c.g. mark and (with `floor`) the floor.
pub fn parts_legend(floor: bool) -> Vec<LegendItem> {
    let mut items = vec![
        LegendItem::new(Swatch::Square(part_color(0)), "one colour per part"),
        LegendItem::new(Swatch::Label, "part number: 1 = placed first"),
        LegendItem::new(Swatch::Disc(CG_MARK), "centre of gravity"),
    ];
    if floor {
        items.push(LegendItem::new(Swatch::Floor, "floor area"));
    }
    items
}

/// The colour of the centre-of-gravity mark.
pub const CG_MARK: [u8; 3] = [200, 0, 0];

struct Frame {
    right: DVec3,
    up: DVec3,
    toward: DVec3,
}

impl Frame {
    fn new(v: &View) -> Self {
        let toward = v.toward_viewer.normalize();
        let right = v.up.cross(toward);
        let right = if right.length_squared() < 1e-12 { DVec3::X } else { right.normalize() };
        let up = toward.cross(right);
        Self { right, up, toward }
    }
    fn project(&self, p: DVec3) -> DVec2 {
        DVec2::new(self.right.dot(p), self.up.dot(p))
    }
}

/// Where a panel's projected coordinates land on the figure: `screen = origin + (q - lo) * scale`, y flipped.
struct Placement {
    frame: Frame,
    origin: DVec2,
    lo: DVec2,
    scale: f64,
}

impl Placement {
    fn to_screen(&self, p: DVec3) -> DVec2 {
        let q = self.frame.project(p);
        DVec2::new(self.origin.x + (q.x - self.lo.x) * self.scale, self.origin.y - (q.y - self.lo.y) * self.scale)
    }
}

/// Projected extent of a scene in a view: (lo, hi); a unit box for an empty scene.
fn extent(scene: &Scene, frame: &Frame) -> (DVec2, DVec2) {
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    let all =
        scene.solids.iter().flat_map(|s| s.polytope.vertices().iter().copied()).chain(scene.floor.iter().copied());
    for p in all {
        let q = frame.project(p);
        lo = lo.min(q);
        hi = hi.max(q);
    }
    if !lo.is_finite() {
        return (DVec2::ZERO, DVec2::ONE);
    }
    (lo, hi.max(lo + DVec2::splat(1e-9)))
}

impl Figure<'_> {
    fn rows(&self) -> usize {
        self.panels.len().div_ceil(self.columns.max(1)).max(1)
    }

    /// Height of the title and legend above the panels.
    fn header(&self) -> f64 {
        TITLE + if self.legend.is_empty() { 0.0 } else { LEGEND }
    }

    /// Width and height of the figure.
    pub fn size(&self) -> (f64, f64) {
        let cols = self.columns.clamp(1, self.panels.len().max(1));
        (cols as f64 * self.cell.0, self.header() + self.rows() as f64 * (self.cell.1 + CAPTION))
    }

    fn cell_origin(&self, k: usize) -> DVec2 {
        let cols = self.columns.max(1);
        DVec2::new((k % cols) as f64 * self.cell.0, self.header() + (k / cols) as f64 * (self.cell.1 + CAPTION))
    }

    fn placements(&self) -> Vec<Placement> {
        let inner = DVec2::new(self.cell.0 - 2.0 * MARGIN, self.cell.1 - 2.0 * MARGIN).max(DVec2::ONE);
        let fitted: Vec<(Frame, DVec2, DVec2, f64)> = self
            .panels
            .iter()
            .map(|p| {
                let frame = Frame::new(&p.view);
                let (lo, hi) = extent(p.scene, &frame);
                let size = hi - lo;
                let scale = (inner.x / size.x).min(inner.y / size.y);
                (frame, lo, size, scale)
            })
            .collect();
        let common = fitted.iter().map(|f| f.3).fold(f64::INFINITY, f64::min);
        fitted
            .into_iter()
            .enumerate()
            .map(|(k, (frame, lo, size, own))| {
                let cell = self.cell_origin(k);
                let scale = if self.common_scale { common } else { own };
                let x = cell.x + MARGIN + (inner.x - size.x * scale) / 2.0;
                let bottom = if self.common_scale {
                    cell.y + MARGIN + inner.y
                } else {
                    cell.y + MARGIN + (inner.y - size.y * scale) / 2.0 + size.y * scale
                };
                Placement { frame, origin: DVec2::new(x, bottom), lo, scale }
            })
            .collect()
    }
}

/// How text sits on its anchor point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Anchor {
    /// The point is the start of the baseline.
    Start,
    /// The point is the middle of the baseline.
    Middle,
}

/// Text style.
#[derive(Debug, Clone, Copy)]
pub struct TextStyle {
    /// Font size (SVG units: the height of a capital).
    pub size: f64,
    /// Anchor.
    pub anchor: Anchor,
    /// Colour.
    pub color: [u8; 3],
    /// The SVG element's class (`label` for part numbers), for readers of the SVG.
    pub class: Option<&'static str>,
}

/// Something a figure is drawn on.
pub trait Canvas {
    /// A closed polygon, filled and/or outlined (`stroke`: colour, width, dashed).
    fn polygon(&mut self, points: &[DVec2], fill: Option<[u8; 3]>, stroke: Option<([u8; 3], f64, bool)>);
    /// Line segments (`stroke`: colour and width), round-capped.
    fn lines(&mut self, segments: &[(DVec2, DVec2)], color: [u8; 3], width: f64);
    /// A filled disc.
    fn disc(&mut self, centre: DVec2, radius: f64, fill: [u8; 3]);
    /// Text at `at` (its baseline).
    fn text(&mut self, at: DVec2, text: &str, style: TextStyle);
    /// Starts a group of elements (SVG `<g id>`); no-op elsewhere.
    fn begin_group(&mut self, _id: &str) {}
    /// Ends the group.
    fn end_group(&mut self) {}
}

struct ProjectedFace {
    points: Vec<DVec2>,
    depth: f64,
    fill: [u8; 3],
    /// `seam[k]`: the edge from point `k` to point `k + 1` is shared with a coplanar face of the same part.
    seam: Vec<bool>,
}

/// A world point rounded to a grid of `cell`, for matching the end points of edges of different components.
fn grid_key(p: DVec3, cell: f64) -> [i64; 3] {
    (p / cell).round().to_array().map(|c| c as i64)
}

/// The edges of face `f` of `s`, as world end points in the face's order.
fn face_edges<'a>(s: &'a Solid, f: &'a stackplan_geom::Face) -> impl Iterator<Item = (DVec3, DVec3)> + 'a {
    let v = s.polytope.vertices();
    let n = f.vertices.len();
    (0..n).map(move |k| (v[f.vertices[k]], v[f.vertices[(k + 1) % n]]))
}

/// For every face of `scene` (solids in order, faces in order), whether each edge is a seam: the same edge (end points
/// equal on a grid of 1e-7 of the scene's size) of another face of the same part with the same outward normal.
fn seams(scene: &Scene) -> Vec<Vec<Vec<bool>>> {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for v in scene.solids.iter().flat_map(|s| s.polytope.vertices()) {
        (lo, hi) = (lo.min(*v), hi.max(*v));
    }
    let cell = 1e-7 * (hi - lo).max_element().max(f64::MIN_POSITIVE);
    // an edge as one 64-bit hash of (part, rounded normal, rounded end points in order): two different edges agree
    // with probability 2^-64, and would only lose an outline
    let edge_key = |part: usize, normal: DVec3, a: DVec3, b: DVec3| -> u64 {
        let (a, b) = (grid_key(a, cell), grid_key(b, cell));
        let (a, b) = if a <= b { (a, b) } else { (b, a) };
        let normal = (normal * 1e9).round().to_array().map(|c| c as i64);
        [part as i64].iter().chain(&normal).chain(&a).chain(&b).fold(0x9e37_79b9_7f4a_7c15_u64, |h, &x| {
            let h = (h ^ x as u64).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            h ^ (h >> 31)
        })
    };
    let keys: Vec<Vec<Vec<u64>>> = scene
        .solids
        .iter()
        .map(|s| {
            let faces = s.polytope.faces().iter();
            faces.map(|f| face_edges(s, f).map(|(a, b)| edge_key(s.part, f.plane.normal, a, b)).collect()).collect()
        })
        .collect();
    let mut sorted: Vec<u64> = keys.iter().flatten().flatten().copied().collect();
    sorted.sort_unstable();
    let shared = |key: &u64| sorted.partition_point(|k| k <= key) - sorted.partition_point(|k| k < key) > 1;
    keys.iter().map(|solid| solid.iter().map(|face| face.iter().map(shared).collect()).collect()).collect()
}

/// The colour of the faces' outlines.
const OUTLINE: [u8; 3] = [34, 34, 34];

fn shade(c: [u8; 3], normal: DVec3) -> [u8; 3] {
    let light = DVec3::new(0.4, -0.6, 1.0).normalize();
    let k = 0.45 + 0.55 * normal.dot(light).max(0.0);
    [(c[0] as f64 * k) as u8, (c[1] as f64 * k) as u8, (c[2] as f64 * k) as u8]
}

/// The visible faces of a scene, back to front, in screen coordinates.
fn visible_faces(scene: &Scene, seams: &[Vec<Vec<bool>>], at: &Placement) -> Vec<ProjectedFace> {
    let mut faces = Vec::new();
    for (s, solid_seams) in scene.solids.iter().zip(seams) {
        let v = s.polytope.vertices();
        for (f, seam) in s.polytope.faces().iter().zip(solid_seams) {
            if f.plane.normal.dot(at.frame.toward) <= 1e-9 {
                continue;
            }
            let centroid = f.vertices.iter().map(|&i| v[i]).sum::<DVec3>() / f.vertices.len() as f64;
            faces.push(ProjectedFace {
                points: f.vertices.iter().map(|&i| at.to_screen(v[i])).collect(),
                depth: at.frame.toward.dot(centroid),
                fill: shade(s.color, f.plane.normal),
                seam: seam.clone(),
            });
        }
    }
    faces.sort_by(|a, b| a.depth.total_cmp(&b.depth));
    faces
}

/// Size of the part numbers (SVG units: the em).
const LABEL_SIZE: f64 = 11.0;
/// Space between a number and its box's edge.
const LABEL_PAD: f64 = 2.0;
/// Height of a digit, as a fraction of the em (DejaVu Sans: 1493 / 2048).
const DIGIT_HEIGHT: f64 = 0.73;
/// Step of the candidate places of a moved label box (SVG units).
const LABEL_STEP: f64 = 2.0;
/// The colour of label boxes' outlines and leader lines.
const LEADER: [u8; 3] = [90, 90, 90];

/// A part number's box as drawn in a figure (SVG units; the PNG is `scale` times larger).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LabelBox {
    /// The panel it is drawn in (0-based, row by row).
    pub panel: usize,
    /// The part's number, as written (1-based).
    pub number: usize,
    /// Where the part's c.g. is drawn: the leader line's end when the box was moved away from it.
    pub anchor: DVec2,
    /// The box's top-left corner.
    pub min: DVec2,
    /// The box's bottom-right corner.
    pub max: DVec2,
}

impl LabelBox {
    /// Whether the two boxes share interior or boundary points.
    pub fn overlaps(&self, other: &LabelBox) -> bool {
        self.min.x <= other.max.x && other.min.x <= self.max.x && self.min.y <= other.max.y && other.min.y <= self.max.y
    }

    /// Whether the box sits at its anchor (no leader line): its bottom edge centred just above the c.g.
    pub fn at_anchor(&self) -> bool {
        let preferred = preferred_min(self.anchor, self.max - self.min);
        (self.min - preferred).length() < 1e-9
    }

    /// The point of the box nearest to `p`.
    fn nearest(&self, p: DVec2) -> DVec2 {
        p.clamp(self.min, self.max)
    }
}

/// The preferred top-left corner of a label box of `size` for a c.g. drawn at `anchor`: centred above it.
fn preferred_min(anchor: DVec2, size: DVec2) -> DVec2 {
    DVec2::new(anchor.x - size.x / 2.0, anchor.y - 4.0 - size.y)
}

/// Whether a label box at `min` of `size` is free in its panel: one unit away from every box in `placed`, and
/// clear of every c.g. mark (`anchors`).
fn label_free(placed: &[LabelBox], anchors: &[DVec2], min: DVec2, size: DVec2) -> bool {
    let b = LabelBox { panel: 0, number: 0, anchor: DVec2::ZERO, min, max: min + size };
    let grown = LabelBox { min: b.min - DVec2::ONE, max: b.max + DVec2::ONE, ..b };
    let mark = |a: DVec2| LabelBox { min: a - DVec2::splat(3.5), max: a + DVec2::splat(3.5), ..b };
    !placed.iter().any(|p| p.overlaps(&grown)) && !anchors.iter().any(|a| mark(*a).overlaps(&b))
}

/// The free place for a box of `size` nearest to `target` on a grid of [`LABEL_STEP`] within `[lo, hi]`, if any.
fn nearest_free(
    placed: &[LabelBox],
    anchors: &[DVec2],
    target: DVec2,
    size: DVec2,
    lo: DVec2,
    hi: DVec2,
) -> Option<DVec2> {
    let (nx, ny) = (((hi.x - lo.x - size.x) / LABEL_STEP).floor(), ((hi.y - lo.y - size.y) / LABEL_STEP).floor());
    if nx < 0.0 || ny < 0.0 {
        return None;
    }
    let mut candidates: Vec<DVec2> = (0..=nx as usize)
        .flat_map(|i| (0..=ny as usize).map(move |j| (i, j)))
        .map(|(i, j)| lo + DVec2::new(i as f64, j as f64) * LABEL_STEP)
        .collect();
    // nearest first; ties by position, so that the layout does not depend on the sort
    candidates.sort_by(|a, b| {
        let (da, db) = ((*a - target).length_squared(), (*b - target).length_squared());
        da.total_cmp(&db).then(a.y.total_cmp(&b.y)).then(a.x.total_cmp(&b.x))
    });
    candidates.into_iter().find(|c| label_free(placed, anchors, *c, size))
}

/// The boxes of every part number of `figure`, where [`draw_figure`] draws them, panel by panel and in increasing
/// numbers within a panel. In increasing numbers, each box goes to its preferred place, centred above its c.g., when
/// that place is free: one unit away from every box placed before and clear of every c.g. mark of the panel. The
/// others are moved beside the parts' drawing, into a column left of it (a c.g. left of the drawing's middle) or right
/// of it, ordered by the height of their c.g.s and as close to it as the column allows, joined to their c.g. by a
/// leader line ([`LabelBox::at_anchor`] is false). A box that finds no free place there takes the free place nearest
/// to its c.g. on a grid of `LABEL_STEP` inside the panel's cell. Boxes of one panel never overlap, unless the cell
/// has no free place left (hundreds of parts in one view), when a box stays at its preferred place.
pub fn label_layout(figure: &Figure<'_>) -> Vec<LabelBox> {
    const GAP: f64 = 3.0;
    let mut out = Vec::new();
    for (k, (panel, at)) in figure.panels.iter().zip(figure.placements()).enumerate() {
        let cell = figure.cell_origin(k);
        let (lo, hi) = (cell + DVec2::splat(2.0), cell + DVec2::new(figure.cell.0, figure.cell.1) - DVec2::splat(2.0));
        let inside = |min: DVec2, size: DVec2| min.cmpge(lo).all() && (min + size).cmple(hi).all();
        let mut labels: Vec<(usize, DVec2)> = panel.scene.labels.iter().map(|(n, p)| (*n, at.to_screen(*p))).collect();
        labels.sort_by_key(|(n, _)| *n);
        let anchors: Vec<DVec2> = labels.iter().map(|(_, a)| *a).collect();
        // the parts' drawing on screen
        let (mut dlo, mut dhi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for p in panel
            .scene
            .solids
            .iter()
            .flat_map(|s| s.polytope.vertices())
            .map(|v| at.to_screen(*v))
            .chain(anchors.iter().copied())
        {
            (dlo, dhi) = (dlo.min(p), dhi.max(p));
        }
        let mut placed: Vec<LabelBox> = Vec::new();
        let mut moved: Vec<(usize, DVec2, DVec2)> = Vec::new();
        for (number, anchor) in labels {
            let size = DVec2::new(
                text_width(&number.to_string(), LABEL_SIZE) + 2.0 * LABEL_PAD,
                DIGIT_HEIGHT * LABEL_SIZE + 2.0 * LABEL_PAD,
            );
            let preferred = preferred_min(anchor, size);
            if inside(preferred, size) && label_free(&placed, &anchors, preferred, size) {
                placed.push(LabelBox { panel: k, number, anchor, min: preferred, max: preferred + size });
            } else {
                moved.push((number, anchor, size));
            }
        }
        let middle = (dlo.x + dhi.x) / 2.0;
        for left in [true, false] {
            let mut column: Vec<&(usize, DVec2, DVec2)> = moved.iter().filter(|m| (m.1.x < middle) == left).collect();
            column.sort_by(|a, b| a.1.y.total_cmp(&b.1.y).then(a.0.cmp(&b.0)));
            // each centred on its c.g.'s height, pushed down below the one above, then up to end inside the cell
            let mut tops: Vec<f64> = Vec::with_capacity(column.len());
            let mut bottom = lo.y - GAP;
            for (_, anchor, size) in &column {
                let top = (anchor.y - size.y / 2.0).max(bottom + GAP);
                tops.push(top);
                bottom = top + size.y;
            }
            let mut limit = hi.y;
            for (top, (_, _, size)) in tops.iter_mut().zip(&column).rev() {
                *top = top.min(limit - size.y);
                limit = *top - GAP;
            }
            for (top, &&(number, anchor, size)) in tops.into_iter().zip(&column) {
                let x = if left { dlo.x - 8.0 - size.x } else { dhi.x + 8.0 };
                let min = DVec2::new(x.clamp(lo.x, (hi.x - size.x).max(lo.x)), top);
                let min = if inside(min, size) && label_free(&placed, &anchors, min, size) {
                    min
                } else {
                    nearest_free(&placed, &anchors, min, size, lo, hi).unwrap_or_else(|| preferred_min(anchor, size))
                };
                placed.push(LabelBox { panel: k, number, anchor, min, max: min + size });
            }
        }
        placed.sort_by_key(|b| b.number);
        out.extend(placed);
    }
    out
}

fn rectangle(min: DVec2, max: DVec2) -> [DVec2; 4] {
    [min, DVec2::new(max.x, min.y), max, DVec2::new(min.x, max.y)]
}

/// Draws the legend's entries in a row under the title.
fn draw_legend(items: &[LegendItem], canvas: &mut dyn Canvas) {
    let text = TextStyle { size: 11.0, anchor: Anchor::Start, color: [60, 60, 60], class: None };
    let baseline = TITLE + LEGEND - 7.0;
    let mut x = MARGIN;
    for item in items {
        let (top, bottom) = (baseline - 9.0, baseline + 1.0);
        let width = match item.swatch {
            Swatch::Square(c) => {
                canvas.polygon(
                    &rectangle(DVec2::new(x, top), DVec2::new(x + 10.0, bottom)),
                    Some(c),
                    Some((OUTLINE, 0.5, false)),
                );
                10.0
            }
            Swatch::Disc(c) => {
                canvas.disc(DVec2::new(x + 4.0, baseline - 4.0), 3.0, c);
                8.0
            }
            Swatch::Floor => {
                let r = rectangle(DVec2::new(x, top), DVec2::new(x + 16.0, bottom));
                canvas.polygon(&r, Some(FLOOR), Some((FLOOR_EDGE, 0.8, true)));
                16.0
            }
            Swatch::Label => {
                let style = TextStyle { size: 9.0, anchor: Anchor::Middle, color: [0, 0, 0], class: None };
                let (min, max) = (DVec2::new(x + 8.0, top - 1.0), DVec2::new(x + 17.0, bottom + 1.0));
                canvas.lines(&[(DVec2::new(x + 1.0, bottom + 1.0), DVec2::new(min.x, max.y))], LEADER, 0.6);
                canvas.polygon(&rectangle(min, max), Some([255, 255, 255]), Some((LEADER, 0.6, false)));
                canvas.text(DVec2::new((min.x + max.x) / 2.0, baseline), "1", style);
                17.0
            }
        };
        canvas.text(DVec2::new(x + width + 4.0, baseline), &item.text, text);
        x += width + 4.0 + text_width(&item.text, text.size) + 16.0;
    }
}

/// The floor's fill and outline.
const FLOOR: [u8; 3] = [242, 242, 242];
const FLOOR_EDGE: [u8; 3] = [136, 136, 136];

/// Draws `figure` on `canvas` (the canvas is `figure.size()` large); returns the part numbers' boxes as drawn
/// ([`label_layout`]).
pub fn draw_figure(figure: &Figure<'_>, canvas: &mut dyn Canvas) -> Vec<LabelBox> {
    let title = TextStyle { size: 16.0, anchor: Anchor::Start, color: [0, 0, 0], class: None };
    canvas.text(DVec2::new(MARGIN, 20.0), &figure.title, title);
    if !figure.legend.is_empty() {
        canvas.begin_group("legend");
        draw_legend(&figure.legend, canvas);
        canvas.end_group();
    }
    let label = TextStyle { size: LABEL_SIZE, anchor: Anchor::Middle, color: [0, 0, 0], class: Some("label") };
    let caption = TextStyle { size: 12.0, anchor: Anchor::Start, color: [85, 85, 85], class: None };
    let boxes = label_layout(figure);
    let mut last_seams: Option<(&Scene, Vec<Vec<Vec<bool>>>)> = None;
    for (k, (panel, at)) in figure.panels.iter().zip(figure.placements()).enumerate() {
        canvas.begin_group(&format!("view-{k}"));
        let scene = panel.scene;
        // consecutive views of one scene (a stack's three views) share its seams
        let scene_seams = match last_seams.take() {
            Some((seen, found)) if std::ptr::eq(seen, scene) => found,
            _ => seams(scene),
        };
        if scene.floor.len() >= 3 {
            let pts: Vec<DVec2> = scene.floor.iter().map(|p| at.to_screen(*p)).collect();
            canvas.polygon(&pts, Some(FLOOR), Some((FLOOR_EDGE, 0.8, true)));
        }
        let faces = visible_faces(scene, &scene_seams, &at);
        last_seams = Some((scene, scene_seams));
        for f in faces {
            if !f.seam.contains(&true) {
                canvas.polygon(&f.points, Some(f.fill), Some((OUTLINE, 0.5, false)));
                continue;
            }
            // a seam is stroked in the face's own colour (covering the anti-aliased gap between the pieces), the
            // other edges in the outline colour
            canvas.polygon(&f.points, Some(f.fill), Some((f.fill, 0.5, false)));
            let n = f.points.len();
            let outline: Vec<(DVec2, DVec2)> =
                (0..n).filter(|&k| !f.seam[k]).map(|k| (f.points[k], f.points[(k + 1) % n])).collect();
            if !outline.is_empty() {
                canvas.lines(&outline, OUTLINE, 0.5);
            }
        }
        for m in &scene.markers {
            canvas.disc(at.to_screen(m.position), 3.0, m.color);
        }
        let panel_boxes: Vec<&LabelBox> = boxes.iter().filter(|b| b.panel == k).collect();
        let leaders: Vec<(DVec2, DVec2)> =
            panel_boxes.iter().filter(|b| !b.at_anchor()).map(|b| (b.anchor, b.nearest(b.anchor))).collect();
        if !leaders.is_empty() {
            canvas.lines(&leaders, LEADER, 0.6);
        }
        for b in &panel_boxes {
            canvas.polygon(&rectangle(b.min, b.max), Some([255, 255, 255]), Some((LEADER, 0.6, false)));
            let baseline = DVec2::new((b.min.x + b.max.x) / 2.0, b.max.y - LABEL_PAD);
            canvas.text(baseline, &b.number.to_string(), label);
        }
        let cell = figure.cell_origin(k);
        canvas.text(DVec2::new(cell.x + MARGIN, cell.y + figure.cell.1 + CAPTION - 5.0), &panel.caption, caption);
        canvas.end_group();
    }
    boxes
}

/// The standard picture of one scene: isometric, top and side views side by side, each fitted on its own.
pub fn three_views(scene: &Scene) -> Figure<'_> {
    Figure {
        title: scene.title.clone(),
        legend: scene.legend.clone(),
        panels: VIEWS.iter().map(|v| FigurePanel { scene, view: *v, caption: v.name.to_string() }).collect(),
        columns: VIEWS.len(),
        cell: (360.0, 340.0),
        common_scale: false,
    }
}

fn hex(c: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

/// SVG elements written into a string.
#[derive(Debug, Default)]
pub struct SvgCanvas {
    out: String,
}

impl Canvas for SvgCanvas {
    fn polygon(&mut self, points: &[DVec2], fill: Option<[u8; 3]>, stroke: Option<([u8; 3], f64, bool)>) {
        let pts: Vec<String> = points.iter().map(|p| format!("{:.2},{:.2}", p.x, p.y)).collect();
        let fill = fill.map_or("none".to_string(), hex);
        let stroke = match stroke {
            Some((c, w, true)) => format!(r#" stroke="{}" stroke-width="{w}" stroke-dasharray="4 3""#, hex(c)),
            Some((c, w, false)) => format!(r#" stroke="{}" stroke-width="{w}" stroke-linejoin="round""#, hex(c)),
            None => String::new(),
        };
        let _ = writeln!(self.out, r#"<polygon points="{}" fill="{fill}"{stroke}/>"#, pts.join(" "));
    }
    fn lines(&mut self, segments: &[(DVec2, DVec2)], color: [u8; 3], width: f64) {
        let d: Vec<String> =
            segments.iter().map(|(a, b)| format!("M{:.2},{:.2}L{:.2},{:.2}", a.x, a.y, b.x, b.y)).collect();
        let _ = writeln!(
            self.out,
            r#"<path d="{}" fill="none" stroke="{}" stroke-width="{width}" stroke-linecap="round"/>"#,
            d.join(""),
            hex(color)
        );
    }
    fn disc(&mut self, c: DVec2, r: f64, fill: [u8; 3]) {
        let _ = writeln!(self.out, r#"<circle cx="{:.2}" cy="{:.2}" r="{r}" fill="{}"/>"#, c.x, c.y, hex(fill));
    }
    fn text(&mut self, at: DVec2, text: &str, style: TextStyle) {
        if text.is_empty() {
            return;
        }
        let anchor = if style.anchor == Anchor::Middle { r#" text-anchor="middle""# } else { "" };
        let class = style.class.map(|c| format!(r#" class="{c}""#)).unwrap_or_default();
        let _ = writeln!(
            self.out,
            r#"<text{class} x="{:.2}" y="{:.2}" font-size="{}"{anchor} fill="{}">{}</text>"#,
            at.x,
            at.y,
            style.size,
            hex(style.color),
            escape(text)
        );
    }
    fn begin_group(&mut self, id: &str) {
        let _ = writeln!(self.out, r#"<g id="{id}">"#);
    }
    fn end_group(&mut self) {
        let _ = writeln!(self.out, "</g>");
    }
}

/// A figure as an SVG document.
pub fn figure_svg(figure: &Figure<'_>) -> String {
    let (w, h) = figure.size();
    let mut canvas = SvgCanvas {
        out: format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" font-family=\"DejaVu Sans, sans-serif\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
        ),
    };
    draw_figure(figure, &mut canvas);
    canvas.out.push_str("</svg>\n");
    canvas.out
}

/// The pictures' font: DejaVu Sans (`assets/fonts/`, with its licence).
static FONT_BYTES: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// The bundled font, parsed once (`None` only if the bundled file were not a font: a unit test reads it).
pub fn font() -> Option<&'static FontRef<'static>> {
    static FONT: std::sync::OnceLock<Option<FontRef<'static>>> = std::sync::OnceLock::new();
    FONT.get_or_init(|| FontRef::try_from_slice(FONT_BYTES).ok()).as_ref()
}

/// The glyph scale of an em of `em` pixels (ab_glyph scales by the font's height, ascent to descent).
fn px_scale(font: &FontRef<'_>, em: f64) -> PxScale {
    let per_em = font.units_per_em().unwrap_or(2048.0) as f64;
    PxScale::from((em * font.height_unscaled() as f64 / per_em) as f32)
}

/// The advance width of `text` at a font size (em) of `size`, in the same unit, kerning included.
pub fn text_width(text: &str, size: f64) -> f64 {
    let Some(font) = font() else { return 0.6 * size * text.chars().count() as f64 };
    let scaled = font.as_scaled(px_scale(font, size));
    let mut width = 0.0;
    let mut previous = None;
    for c in text.chars() {
        let id = scaled.glyph_id(c);
        if let Some(p) = previous {
            width += scaled.kern(p, id) as f64;
        }
        width += scaled.h_advance(id) as f64;
        previous = Some(id);
    }
    width
}

/// A tiny-skia pixmap, `scale` pixels per SVG unit.
#[derive(Debug)]
pub struct PngCanvas {
    pixmap: tiny_skia::Pixmap,
    scale: f64,
}

fn paint(c: [u8; 3], anti_alias: bool) -> tiny_skia::Paint<'static> {
    let mut p = tiny_skia::Paint::default();
    p.set_color_rgba8(c[0], c[1], c[2], 255);
    p.anti_alias = anti_alias;
    p
}

impl PngCanvas {
    fn transform(&self) -> tiny_skia::Transform {
        tiny_skia::Transform::from_scale(self.scale as f32, self.scale as f32)
    }

    /// Covers pixel `(x, y)` with colour `c` by `coverage` (0 to 1); the picture is opaque, so premultiplied and
    /// plain colours agree.
    fn blend(&mut self, x: i64, y: i64, c: [u8; 3], coverage: f32) {
        let (w, h) = (self.pixmap.width() as i64, self.pixmap.height() as i64);
        if x < 0 || y < 0 || x >= w || y >= h {
            return;
        }
        let k = ((y * w + x) * 4) as usize;
        let a = coverage.clamp(0.0, 1.0);
        let data = self.pixmap.data_mut();
        for (i, channel) in c.iter().enumerate() {
            let d = data[k + i] as f32;
            data[k + i] = (d + (*channel as f32 - d) * a).round() as u8;
        }
    }
}

impl Canvas for PngCanvas {
    fn polygon(&mut self, points: &[DVec2], fill: Option<[u8; 3]>, stroke: Option<([u8; 3], f64, bool)>) {
        let n = points.len();
        let area2: f64 = (0..n).map(|k| points[k].perp_dot(points[(k + 1) % n])).sum();
        if n < 3 || area2.abs() < 1e-6 {
            return; // seen edge-on: nothing to fill
        }
        // a face seen almost edge-on can still be thinner than tiny-skia fills (1/4096 pixel): its outline is all
        // there is to see, and filling it would only raise tiny-skia's warning about empty paths
        let (lo, hi) =
            points.iter().fold((DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            });
        let thin = ((hi - lo) * self.scale).min_element() < 1e-3;
        let fill = if thin { None } else { fill };
        let mut pb = tiny_skia::PathBuilder::new();
        pb.move_to(points[0].x as f32, points[0].y as f32);
        for p in &points[1..] {
            pb.line_to(p.x as f32, p.y as f32);
        }
        pb.close();
        let Some(path) = pb.finish() else { return };
        let t = self.transform();
        if let Some(c) = fill {
            self.pixmap.fill_path(&path, &paint(c, true), tiny_skia::FillRule::Winding, t, None);
        }
        if let Some((c, width, dashed)) = stroke {
            let dash = if dashed { tiny_skia::StrokeDash::new(vec![4.0, 3.0], 0.0) } else { None };
            let stroke = tiny_skia::Stroke { width: width as f32, dash, ..tiny_skia::Stroke::default() };
            self.pixmap.stroke_path(&path, &paint(c, true), &stroke, t, None);
        }
    }
    fn lines(&mut self, segments: &[(DVec2, DVec2)], color: [u8; 3], width: f64) {
        let mut pb = tiny_skia::PathBuilder::new();
        for (a, b) in segments {
            pb.move_to(a.x as f32, a.y as f32);
            pb.line_to(b.x as f32, b.y as f32);
        }
        let Some(path) = pb.finish() else { return };
        let stroke =
            tiny_skia::Stroke { width: width as f32, line_cap: tiny_skia::LineCap::Round, ..Default::default() };
        self.pixmap.stroke_path(&path, &paint(color, true), &stroke, self.transform(), None);
    }
    fn disc(&mut self, c: DVec2, r: f64, fill: [u8; 3]) {
        if let Some(path) = tiny_skia::PathBuilder::from_circle(c.x as f32, c.y as f32, r as f32) {
            let t = self.transform();
            self.pixmap.fill_path(&path, &paint(fill, true), tiny_skia::FillRule::Winding, t, None);
        }
    }
    /// Text in the bundled font, anti-aliased, its baseline at `at`.
    fn text(&mut self, at: DVec2, text: &str, style: TextStyle) {
        let Some(font) = font() else { return };
        let scale = px_scale(font, style.size * self.scale);
        let scaled = font.as_scaled(scale);
        let width = text_width(text, style.size) * self.scale;
        let mut x = at.x * self.scale - if style.anchor == Anchor::Middle { width / 2.0 } else { 0.0 };
        let y = at.y * self.scale;
        let mut previous = None;
        for c in text.chars() {
            let id = scaled.glyph_id(c);
            if let Some(p) = previous {
                x += scaled.kern(p, id) as f64;
            }
            let glyph = id.with_scale_and_position(scale, ab_glyph::point(x as f32, y as f32));
            if let Some(outlined) = font.outline_glyph(glyph) {
                let bounds = outlined.px_bounds();
                let (x0, y0) = (bounds.min.x as i64, bounds.min.y as i64);
                outlined.draw(|gx, gy, coverage| self.blend(x0 + gx as i64, y0 + gy as i64, style.color, coverage));
            }
            x += scaled.h_advance(id) as f64;
            previous = Some(id);
        }
    }
}

/// A figure as a PNG image, `scale` pixels per SVG unit.
pub fn figure_png(figure: &Figure<'_>, scale: f64) -> anyhow::Result<Vec<u8>> {
    let (w, h) = figure.size();
    let (w, h) = ((w * scale).ceil() as u32, (h * scale).ceil() as u32);
    let mut pixmap =
        tiny_skia::Pixmap::new(w.max(1), h.max(1)).ok_or_else(|| anyhow::anyhow!("cannot allocate a {w}x{h} image"))?;
    pixmap.fill(tiny_skia::Color::WHITE);
    let mut canvas = PngCanvas { pixmap, scale };
    draw_figure(figure, &mut canvas);
    canvas.pixmap.encode_png().map_err(|e| anyhow::anyhow!("PNG encoding failed: {e}"))
}

/// Decodes a PNG into its RGBA bytes, row by row (premultiplied alpha; opaque pictures are unchanged), for checks
/// of written pictures.
pub fn decode_png(png: &[u8]) -> anyhow::Result<Vec<u8>> {
    let pixmap = tiny_skia::Pixmap::decode_png(png).map_err(|e| anyhow::anyhow!("not a PNG: {e}"))?;
    Ok(pixmap.take())
}

/// The scene's three views as an SVG document.
pub fn svg(scene: &Scene) -> String {
    figure_svg(&three_views(scene))
}

/// The scene's three views as a PNG image, `scale` pixels per SVG unit.
pub fn png(scene: &Scene, scale: f64) -> anyhow::Result<Vec<u8>> {
    figure_png(&three_views(scene), scale)
}

#[cfg(test)]
mod tests;
