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
//! elements, [`PngCanvas`] paints with tiny-skia. tiny-skia has no text, so the PNG writes text with a built-in 5 x 7
//! bitmap font ([`GLYPHS`]: digits and the few signs of part numbers, frame and sweep captions such as `n = 12`,
//! `w = 0.5`); text with other characters (titles, view names) is drawn in the SVG only.

use stackplan_geom::{ConvexPolytope, DVec2, DVec3};
use std::fmt::Write;

/// One thing to draw: a convex solid in world coordinates with its colour and the label of the part it belongs to.
#[derive(Debug, Clone)]
pub struct Solid {
    /// The solid, in world coordinates.
    pub polytope: ConvexPolytope,
    /// Base colour (sRGB, 0..255).
    pub color: [u8; 3],
    /// Index of the part it belongs to (parts are numbered in the picture from 1).
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
    /// Label each part with its number at its c.g. (one position per part).
    pub labels: Vec<(usize, DVec3)>,
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
    /// Title at the top (SVG only unless it uses the bitmap font's characters).
    pub title: String,
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
const CAPTION: f64 = 18.0;

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

    /// Width and height of the figure.
    pub fn size(&self) -> (f64, f64) {
        let cols = self.columns.clamp(1, self.panels.len().max(1));
        (cols as f64 * self.cell.0, TITLE + self.rows() as f64 * (self.cell.1 + CAPTION))
    }

    fn cell_origin(&self, k: usize) -> DVec2 {
        let cols = self.columns.max(1);
        DVec2::new((k % cols) as f64 * self.cell.0, TITLE + (k / cols) as f64 * (self.cell.1 + CAPTION))
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
    /// A white background (halo) under the text, for numbers drawn over parts.
    pub halo: bool,
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

/// Draws `figure` on `canvas` (the canvas is `figure.size()` large).
pub fn draw_figure(figure: &Figure<'_>, canvas: &mut dyn Canvas) {
    let title = TextStyle { size: 16.0, anchor: Anchor::Start, color: [0, 0, 0], halo: false };
    canvas.text(DVec2::new(MARGIN, 20.0), &figure.title, title);
    let label = TextStyle { size: 11.0, anchor: Anchor::Middle, color: [0, 0, 0], halo: true };
    let caption = TextStyle { size: 12.0, anchor: Anchor::Start, color: [85, 85, 85], halo: false };
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
            canvas.polygon(&pts, Some([242, 242, 242]), Some(([136, 136, 136], 0.8, true)));
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
        for (n, p) in &scene.labels {
            canvas.text(at.to_screen(*p) - DVec2::new(0.0, 3.0), &n.to_string(), label);
        }
        let cell = figure.cell_origin(k);
        canvas.text(DVec2::new(cell.x + MARGIN, cell.y + figure.cell.1 + CAPTION - 5.0), &panel.caption, caption);
        canvas.end_group();
    }
}

/// The standard picture of one scene: isometric, top and side views side by side, each fitted on its own.
pub fn three_views(scene: &Scene) -> Figure<'_> {
    Figure {
        title: scene.title.clone(),
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
        let halo = if style.halo { r#" stroke="white" stroke-width="2.5" paint-order="stroke""# } else { "" };
        let _ = writeln!(
            self.out,
            r#"<text x="{:.2}" y="{:.2}" font-size="{}"{anchor} fill="{}"{halo}>{}</text>"#,
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
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" font-family=\"sans-serif\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
        ),
    };
    draw_figure(figure, &mut canvas);
    canvas.out.push_str("</svg>\n");
    canvas.out
}

/// The 5 x 7 bitmap font of the PNG pictures: each glyph is 7 rows of 5 bits (the high bit on the left).
pub const GLYPHS: [(char, [u8; 7]); 16] = [
    ('0', [0b01110, 0b10001, 0b10011, 0b10101, 0b11001, 0b10001, 0b01110]),
    ('1', [0b00100, 0b01100, 0b00100, 0b00100, 0b00100, 0b00100, 0b01110]),
    ('2', [0b01110, 0b10001, 0b00001, 0b00010, 0b00100, 0b01000, 0b11111]),
    ('3', [0b11111, 0b00010, 0b00100, 0b00010, 0b00001, 0b10001, 0b01110]),
    ('4', [0b00010, 0b00110, 0b01010, 0b10010, 0b11111, 0b00010, 0b00010]),
    ('5', [0b11111, 0b10000, 0b11110, 0b00001, 0b00001, 0b10001, 0b01110]),
    ('6', [0b00110, 0b01000, 0b10000, 0b11110, 0b10001, 0b10001, 0b01110]),
    ('7', [0b11111, 0b00001, 0b00010, 0b00100, 0b01000, 0b01000, 0b01000]),
    ('8', [0b01110, 0b10001, 0b10001, 0b01110, 0b10001, 0b10001, 0b01110]),
    ('9', [0b01110, 0b10001, 0b10001, 0b01111, 0b00001, 0b00010, 0b01100]),
    ('.', [0b00000, 0b00000, 0b00000, 0b00000, 0b00000, 0b01100, 0b01100]),
    ('=', [0b00000, 0b00000, 0b11111, 0b00000, 0b11111, 0b00000, 0b00000]),
    ('-', [0b00000, 0b00000, 0b00000, 0b11111, 0b00000, 0b00000, 0b00000]),
    ('w', [0b00000, 0b00000, 0b10001, 0b10001, 0b10101, 0b10101, 0b01010]),
    ('n', [0b00000, 0b00000, 0b10110, 0b11001, 0b10001, 0b10001, 0b10001]),
    (' ', [0; 7]),
];

fn glyph(c: char) -> Option<&'static [u8; 7]> {
    GLYPHS.iter().find(|(g, _)| *g == c).map(|(_, rows)| rows)
}

/// Whether the PNG's bitmap font can write `text`.
pub fn bitmap_font_has(text: &str) -> bool {
    !text.is_empty() && text.chars().all(|c| glyph(c).is_some())
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

    fn pixel_rect(&mut self, x: f64, y: f64, w: f64, h: f64, c: [u8; 3]) {
        if let Some(r) = tiny_skia::Rect::from_xywh(x as f32, y as f32, w as f32, h as f32) {
            self.pixmap.fill_rect(r, &paint(c, false), tiny_skia::Transform::identity(), None);
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
    /// Bitmap text: one font pixel is a square of whole device pixels, so the digits stay sharp; with a halo, a
    /// white box one font pixel larger than the text on every side.
    fn text(&mut self, at: DVec2, text: &str, style: TextStyle) {
        if !bitmap_font_has(text) {
            return;
        }
        let cell = (style.size * self.scale / 8.0).round().max(1.0);
        let width = (text.chars().count() * 6 - 1) as f64 * cell;
        let height = 7.0 * cell;
        let base = at * self.scale;
        let x0 = (if style.anchor == Anchor::Middle { base.x - width / 2.0 } else { base.x }).round();
        let y0 = (base.y - height).round();
        if style.halo {
            self.pixel_rect(x0 - cell, y0 - cell, width + 2.0 * cell, height + 2.0 * cell, [255, 255, 255]);
        }
        for (k, c) in text.chars().enumerate() {
            let Some(rows) = glyph(c) else { continue };
            for (row, bits) in rows.iter().enumerate() {
                for col in 0..5 {
                    if bits & (0b10000 >> col) != 0 {
                        let x = x0 + (k * 6 + col) as f64 * cell;
                        self.pixel_rect(x, y0 + row as f64 * cell, cell, cell, style.color);
                    }
                }
            }
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

/// The scene's three views as a PNG image, `scale` pixels per SVG unit (part numbers in the bitmap font).
pub fn png(scene: &Scene, scale: f64) -> anyhow::Result<Vec<u8>> {
    figure_png(&three_views(scene), scale)
}

#[cfg(test)]
mod tests {
    use super::*;
    use stackplan_geom::convex_hull;

    fn cube_at(o: DVec3) -> ConvexPolytope {
        let pts: Vec<DVec3> =
            (0..8).map(|i| o + DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64)).collect();
        convex_hull(&pts).expect("cube").polytope
    }

    fn two_cubes() -> Scene {
        Scene {
            solids: vec![
                Solid { polytope: cube_at(DVec3::ZERO), color: part_color(0), part: 0 },
                Solid { polytope: cube_at(DVec3::new(0.0, 0.0, 1.0)), color: part_color(1), part: 1 },
            ],
            markers: vec![Marker { position: DVec3::splat(0.5), color: [200, 0, 0] }],
            floor: vec![DVec3::new(-1.0, -1.0, 0.0), DVec3::new(2.0, -1.0, 0.0), DVec3::new(2.0, 2.0, 0.0)],
            title: "two cubes <test>".into(),
            labels: vec![(1, DVec3::splat(0.5)), (2, DVec3::new(0.5, 0.5, 1.5))],
        }
    }

    fn decode(png: &[u8]) -> tiny_skia::Pixmap {
        tiny_skia::Pixmap::decode_png(png).expect("decodes")
    }

    #[test]
    fn pictures_contain_every_visible_face() {
        let scene = two_cubes();
        let s = svg(&scene);
        // isometric: 3 faces per cube; top: 1 per cube (the upward face); side: 1 per cube
        assert_eq!(s.matches("stroke-linejoin").count(), 2 * 3 + 2 + 2);
        assert!(s.contains("&lt;test&gt;"));
        assert_eq!(s.matches(">2</text>").count(), 3, "part 2 numbered in each view");
        let p = png(&scene, 1.0).expect("png");
        assert_eq!(&p[1..4], b"PNG");
    }

    /// Two boxes side by side as one part (a face split into two convex pieces): their shared edge on top is a seam,
    /// drawn in the face's colour; as two parts it is an outline. Seen from the top, at the middle of that edge.
    #[test]
    fn outlines_skip_the_seams_of_a_decomposition() {
        let boxes = |second_part: usize| Scene {
            solids: vec![
                Solid { polytope: cube_at(DVec3::ZERO), color: part_color(0), part: 0 },
                Solid { polytope: cube_at(DVec3::X), color: part_color(0), part: second_part },
            ],
            ..Scene::default()
        };
        let seams_of = |scene: &Scene| seams(scene).iter().flatten().flatten().filter(|s| **s).count();
        // the shared edges of the top, bottom, front and back faces (the glued side faces have opposite normals)
        assert_eq!(seams_of(&boxes(0)), 2 * 4);
        assert_eq!(seams_of(&boxes(1)), 0);
        let top = View { name: "top", toward_viewer: DVec3::Z, up: DVec3::Y };
        let pixel_on_the_shared_edge = |scene: &Scene| {
            let figure = Figure {
                title: String::new(),
                panels: vec![FigurePanel { scene, view: top, caption: String::new() }],
                columns: 1,
                cell: (200.0, 120.0),
                common_scale: false,
            };
            let at = figure.placements();
            let p = at[0].to_screen(DVec3::new(1.0, 0.5, 1.0));
            let image = decode(&figure_png(&figure, 1.0).expect("png"));
            let c = image.pixel(p.x.round() as u32, p.y.round() as u32).expect("inside");
            [c.red(), c.green(), c.blue()]
        };
        let fill = shade(part_color(0), DVec3::Z);
        assert_eq!(pixel_on_the_shared_edge(&boxes(0)), fill, "a seam is drawn in the face's colour");
        let outlined = pixel_on_the_shared_edge(&boxes(1));
        assert!(outlined.iter().zip(fill).all(|(o, f)| *o < f), "{outlined:?} is the outline, darker than {fill:?}");
        // the SVG: one face with a seam gets its outline as a path of the other three edges
        let s = svg(&boxes(0));
        assert!(s.contains(r##"fill="none" stroke="#222222""##), "{s}");
    }

    /// The PNG's part numbers: the pixels of the glyphs of "12" appear, black on a white box, at the label.
    #[test]
    fn png_numbers_are_drawn_in_the_bitmap_font() {
        let mut canvas = PngCanvas { pixmap: tiny_skia::Pixmap::new(60, 30).expect("pixmap"), scale: 1.0 };
        canvas.pixmap.fill(tiny_skia::Color::from_rgba8(0, 0, 255, 255));
        let style = TextStyle { size: 8.0, anchor: Anchor::Start, color: [0, 0, 0], halo: true };
        canvas.text(DVec2::new(10.0, 20.0), "12", style);
        // cell = 1 px; glyph origin (10, 13); '1' row 0 = 00100 -> pixel (12, 13) black; (10, 13) white (halo box)
        let px = |canvas: &PngCanvas, x: u32, y: u32| {
            let c = canvas.pixmap.pixel(x, y).expect("inside");
            [c.red(), c.green(), c.blue()]
        };
        assert_eq!(px(&canvas, 12, 13), [0, 0, 0]);
        assert_eq!(px(&canvas, 10, 13), [255, 255, 255]);
        // '2' starts 6 px later: row 6 = 11111 -> (16..=20, 19) black
        assert!((16..=20).all(|x| px(&canvas, x, 19) == [0, 0, 0]));
        // outside the halo box the background stays
        assert_eq!(px(&canvas, 5, 5), [0, 0, 255]);
        // text outside the font (a title) is not drawn at all
        canvas.text(DVec2::new(30.0, 28.0), "Stack", style);
        assert_eq!(px(&canvas, 31, 25), [0, 0, 255]);
    }

    #[test]
    fn common_scale_puts_every_panel_on_one_floor_line() {
        let low = two_cubes();
        let mut tall = two_cubes();
        tall.solids.push(Solid { polytope: cube_at(DVec3::new(0.0, 0.0, 2.0)), color: part_color(2), part: 2 });
        let figure = Figure {
            title: String::new(),
            panels: vec![
                FigurePanel { scene: &low, view: ISOMETRIC, caption: "n = 2".into() },
                FigurePanel { scene: &tall, view: ISOMETRIC, caption: "n = 3".into() },
            ],
            columns: 2,
            cell: (200.0, 200.0),
            common_scale: true,
        };
        let at = figure.placements();
        assert_eq!(at[0].scale, at[1].scale);
        let floor_corner = DVec3::new(-1.0, -1.0, 0.0);
        assert!((at[0].to_screen(floor_corner).y - at[1].to_screen(floor_corner).y).abs() < 1e-9);
        let png = figure_png(&figure, 1.0).expect("png");
        let image = decode(&png);
        assert_eq!((image.width(), image.height()), (400, (TITLE + 200.0 + CAPTION) as u32));
    }
}
