//! Pictures of parts and stacks: SVG and PNG with an isometric view beside top and side views.
//!
//! Each convex component is drawn face by face: faces turned away from the viewer are culled, the rest are sorted
//! back to front by the depth of their centroid (painter's algorithm) and shaded with a fixed light (Lambert). For
//! convex components of parts that do not interpenetrate this ordering is right almost everywhere; where two faces of
//! different parts overlap in depth it can be wrong in a small region — pictures are for people, the JSON is the
//! result. O(F log F) for F faces.

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

/// The three views of every picture.
pub const VIEWS: [View; 3] = [
    View { name: "isometric", toward_viewer: DVec3::new(1.0, -1.0, 0.9), up: DVec3::Z },
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

struct Projected {
    points: Vec<DVec2>,
    depth: f64,
    fill: [u8; 3],
}

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

fn shade(c: [u8; 3], normal: DVec3) -> [u8; 3] {
    let light = DVec3::new(0.4, -0.6, 1.0).normalize();
    let k = 0.45 + 0.55 * normal.dot(light).max(0.0);
    [(c[0] as f64 * k) as u8, (c[1] as f64 * k) as u8, (c[2] as f64 * k) as u8]
}

fn project_view(scene: &Scene, view: &View) -> (Vec<Projected>, Frame) {
    let frame = Frame::new(view);
    let mut faces = Vec::new();
    for s in &scene.solids {
        let v = s.polytope.vertices();
        for f in s.polytope.faces() {
            if f.plane.normal.dot(frame.toward) <= 1e-9 {
                continue;
            }
            let centroid = f.vertices.iter().map(|&i| v[i]).sum::<DVec3>() / f.vertices.len() as f64;
            faces.push(Projected {
                points: f.vertices.iter().map(|&i| frame.project(v[i])).collect(),
                depth: frame.toward.dot(centroid),
                fill: shade(s.color, f.plane.normal),
            });
        }
    }
    faces.sort_by(|a, b| a.depth.total_cmp(&b.depth));
    (faces, frame)
}

struct Layout {
    /// For each view: (offset x, offset y, scale, frame min)
    panels: Vec<(f64, f64, f64, DVec2)>,
    width: f64,
    height: f64,
}

const PANEL: f64 = 360.0;
const MARGIN: f64 = 20.0;
const TITLE: f64 = 28.0;

fn layout(scene: &Scene) -> Layout {
    let mut panels = Vec::new();
    for (k, view) in VIEWS.iter().enumerate() {
        let frame = Frame::new(view);
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
            lo = DVec2::ZERO;
            hi = DVec2::ONE;
        }
        let size = (hi - lo).max(DVec2::splat(1e-9));
        let scale = (PANEL - 2.0 * MARGIN) / size.x.max(size.y);
        let ox = k as f64 * PANEL + MARGIN + ((PANEL - 2.0 * MARGIN) - size.x * scale) / 2.0;
        let oy = TITLE + MARGIN + ((PANEL - 2.0 * MARGIN) - size.y * scale) / 2.0 + size.y * scale;
        panels.push((ox, oy, scale, lo));
    }
    Layout { panels, width: PANEL * VIEWS.len() as f64, height: PANEL + TITLE + 16.0 }
}

fn to_screen(panel: (f64, f64, f64, DVec2), q: DVec2) -> (f64, f64) {
    let (ox, oy, s, lo) = panel;
    (ox + (q.x - lo.x) * s, oy - (q.y - lo.y) * s)
}

fn hex(c: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

/// The scene as an SVG document.
pub fn svg(scene: &Scene) -> String {
    let lay = layout(scene);
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif">"#,
        w = lay.width,
        h = lay.height
    );
    let _ = writeln!(out, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(out, r#"<text x="{MARGIN}" y="20" font-size="16">{}</text>"#, escape(&scene.title));
    for (k, view) in VIEWS.iter().enumerate() {
        let panel = lay.panels[k];
        let (faces, frame) = project_view(scene, view);
        let _ = writeln!(out, r#"<g id="view-{k}">"#);
        if scene.floor.len() >= 3 {
            let pts: Vec<String> = scene
                .floor
                .iter()
                .map(|p| {
                    let (x, y) = to_screen(panel, frame.project(*p));
                    format!("{x:.2},{y:.2}")
                })
                .collect();
            let _ = writeln!(
                out,
                r##"<polygon points="{}" fill="#f2f2f2" stroke="#888" stroke-dasharray="4 3"/>"##,
                pts.join(" ")
            );
        }
        for f in &faces {
            let pts: Vec<String> = f
                .points
                .iter()
                .map(|q| {
                    let (x, y) = to_screen(panel, *q);
                    format!("{x:.2},{y:.2}")
                })
                .collect();
            let _ = writeln!(
                out,
                r##"<polygon points="{}" fill="{}" stroke="#222" stroke-width="0.4" stroke-linejoin="round"/>"##,
                pts.join(" "),
                hex(f.fill)
            );
        }
        for m in &scene.markers {
            let (x, y) = to_screen(panel, frame.project(m.position));
            let _ = writeln!(out, r#"<circle cx="{x:.2}" cy="{y:.2}" r="3" fill="{}"/>"#, hex(m.color));
        }
        for (n, p) in &scene.labels {
            let (x, y) = to_screen(panel, frame.project(*p));
            let _ = writeln!(
                out,
                r#"<text x="{x:.2}" y="{y:.2}" font-size="11" text-anchor="middle" fill="black" stroke="white" stroke-width="2.5" paint-order="stroke">{n}</text>"#
            );
        }
        let _ = writeln!(
            out,
            r##"<text x="{:.1}" y="{:.1}" font-size="12" fill="#555">{}</text>"##,
            k as f64 * PANEL + MARGIN,
            lay.height - 6.0,
            view.name
        );
        let _ = writeln!(out, "</g>");
    }
    let _ = writeln!(out, "</svg>");
    out
}

/// The scene as a PNG image (same layout as the SVG, without text), `scale` pixels per SVG unit.
pub fn png(scene: &Scene, scale: f64) -> anyhow::Result<Vec<u8>> {
    use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Stroke, Transform};
    let lay = layout(scene);
    let (w, h) = ((lay.width * scale).ceil() as u32, (lay.height * scale).ceil() as u32);
    let mut pixmap =
        Pixmap::new(w.max(1), h.max(1)).ok_or_else(|| anyhow::anyhow!("cannot allocate a {w}x{h} image"))?;
    pixmap.fill(Color::WHITE);
    let t = Transform::from_scale(scale as f32, scale as f32);
    let polygon = |pts: &[(f64, f64)]| {
        let mut pb = PathBuilder::new();
        for (i, (x, y)) in pts.iter().enumerate() {
            if i == 0 {
                pb.move_to(*x as f32, *y as f32);
            } else {
                pb.line_to(*x as f32, *y as f32);
            }
        }
        pb.close();
        pb.finish()
    };
    let mut edge = Paint::default();
    edge.set_color_rgba8(34, 34, 34, 255);
    edge.anti_alias = true;
    let stroke = Stroke { width: 0.5, ..Stroke::default() };
    for (k, view) in VIEWS.iter().enumerate() {
        let panel = lay.panels[k];
        let (faces, frame) = project_view(scene, view);
        if scene.floor.len() >= 3 {
            let pts: Vec<(f64, f64)> = scene.floor.iter().map(|p| to_screen(panel, frame.project(*p))).collect();
            if let Some(path) = polygon(&pts) {
                let mut paint = Paint::default();
                paint.set_color_rgba8(242, 242, 242, 255);
                pixmap.fill_path(&path, &paint, FillRule::Winding, t, None);
            }
        }
        for f in &faces {
            let pts: Vec<(f64, f64)> = f.points.iter().map(|q| to_screen(panel, *q)).collect();
            let area2: f64 = (0..pts.len())
                .map(|k| pts[k].0 * pts[(k + 1) % pts.len()].1 - pts[(k + 1) % pts.len()].0 * pts[k].1)
                .sum();
            if area2.abs() < 1e-6 {
                continue; // seen edge-on: nothing to fill
            }
            if let Some(path) = polygon(&pts) {
                let mut paint = Paint::default();
                paint.set_color_rgba8(f.fill[0], f.fill[1], f.fill[2], 255);
                paint.anti_alias = true;
                pixmap.fill_path(&path, &paint, FillRule::Winding, t, None);
                pixmap.stroke_path(&path, &edge, &stroke, t, None);
            }
        }
        for m in &scene.markers {
            let (x, y) = to_screen(panel, frame.project(m.position));
            if let Some(path) = PathBuilder::from_circle(x as f32, y as f32, 3.0) {
                let mut paint = Paint::default();
                paint.set_color_rgba8(m.color[0], m.color[1], m.color[2], 255);
                pixmap.fill_path(&path, &paint, FillRule::Winding, t, None);
            }
        }
    }
    pixmap.encode_png().map_err(|e| anyhow::anyhow!("PNG encoding failed: {e}"))
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

    #[test]
    fn pictures_contain_every_visible_face() {
        let scene = Scene {
            solids: vec![
                Solid { polytope: cube_at(DVec3::ZERO), color: part_color(0), part: 0 },
                Solid { polytope: cube_at(DVec3::new(0.0, 0.0, 1.0)), color: part_color(1), part: 1 },
            ],
            markers: vec![Marker { position: DVec3::splat(0.5), color: [200, 0, 0] }],
            floor: vec![DVec3::new(-1.0, -1.0, 0.0), DVec3::new(2.0, -1.0, 0.0), DVec3::new(2.0, 2.0, 0.0)],
            title: "two cubes <test>".into(),
            labels: vec![(1, DVec3::splat(0.5)), (2, DVec3::new(0.5, 0.5, 1.5))],
        };
        let s = svg(&scene);
        // isometric: 3 faces per cube; top: 1 per cube (the upward face); side: 1 per cube
        assert_eq!(s.matches("stroke-linejoin").count(), 2 * 3 + 2 + 2);
        assert!(s.contains("&lt;test&gt;"));
        let p = png(&scene, 1.0).expect("png");
        assert_eq!(&p[1..4], b"PNG");
    }
}
