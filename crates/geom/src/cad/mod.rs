//! Parts from CAD: STEP B-reps and single-shell triangle meshes recognised as sheet metal and decomposed
//! conservatively into convex pieces.
//!
//! Both inputs are first reduced to one boundary description, [`Brep`]: planar faces with their boundary loops (lines
//! and circular arcs kept exact) and cylindrical faces with their axis, radius and boundary points. The STEP reader
//! ([`crate::io::step`]) gives it from the file's exact surfaces; [`mesh_faces`] segments a closed triangle mesh into
//! the same faces (planar regions, and cylinders fitted to the chains of facets that tessellate bends).
//! [`recognise`] then finds the sheet: its thickness, the plates (pairs of opposite planar faces one thickness
//! apart, with their mid-surface outline and holes) and the bends (pairs of coaxial cylinders whose radii differ by
//! the thickness), and [`bend`] turns each bend into convex segments that contain it.

pub mod bend;
pub mod geometry;
pub mod mesh_faces;
pub mod nurbs;
pub mod recognise;
pub mod trimmed;

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Where a face of a [`Brep`] came from, for messages.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum FaceSource {
    /// A STEP `ADVANCED_FACE` (or `FACE_SURFACE`) entity, by its instance number (`#17` is 17).
    Step {
        /// The instance number.
        entity: u64,
    },
    /// A region of a triangle mesh: a set of connected triangles.
    Mesh {
        /// 0-based region index (regions are numbered by their first triangle in file order).
        region: usize,
        /// The file place (line or byte) of the region's first triangle, as [`crate::io::Place`] prints it.
        first_triangle: String,
    },
}

impl std::fmt::Display for FaceSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FaceSource::Step { entity } => write!(f, "face #{entity}"),
            FaceSource::Mesh { region, first_triangle } => {
                write!(f, "mesh region {region} (first triangle at {first_triangle})")
            }
        }
    }
}

/// One piece of a boundary loop.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Segment {
    /// A straight segment.
    Line {
        /// Start point.
        start: DVec3,
        /// End point.
        end: DVec3,
    },
    /// A circular arc from `start` to `end`, turning counter-clockwise about `axis` (seen from the tip of `axis`).
    /// `start == end` is the full circle.
    Arc {
        /// Centre.
        center: DVec3,
        /// Unit axis; the arc turns counter-clockwise about it.
        axis: DVec3,
        /// Radius (mm), > 0.
        radius: f64,
        /// Start point (on the circle).
        start: DVec3,
        /// End point (on the circle).
        end: DVec3,
    },
}

impl Segment {
    /// The start point.
    pub fn start(&self) -> DVec3 {
        match *self {
            Segment::Line { start, .. } | Segment::Arc { start, .. } => start,
        }
    }

    /// The end point.
    pub fn end(&self) -> DVec3 {
        match *self {
            Segment::Line { end, .. } | Segment::Arc { end, .. } => end,
        }
    }

    /// The same segment traversed the other way.
    pub fn reversed(&self) -> Segment {
        match *self {
            Segment::Line { start, end } => Segment::Line { start: end, end: start },
            Segment::Arc { center, axis, radius, start, end } => {
                Segment::Arc { center, axis: -axis, radius, start: end, end: start }
            }
        }
    }

    /// The swept angle of an arc in `(0, 2 pi]` (a full circle when `start == end`); 0 for a line.
    pub fn sweep(&self) -> f64 {
        match *self {
            Segment::Line { .. } => 0.0,
            Segment::Arc { center, axis, start, end, .. } => {
                let (u, v) = (start - center, end - center);
                let angle = axis.dot(u.cross(v)).atan2(u.dot(v));
                if start == end {
                    std::f64::consts::TAU
                } else if angle <= 0.0 {
                    angle + std::f64::consts::TAU
                } else {
                    angle
                }
            }
        }
    }

    /// `n + 1` points from start to end (`n >= 1`): the end points and, for an arc, `n - 1` points on the circle at
    /// equal angles between them; for a line only its two end points whatever `n`.
    pub fn points(&self, n: usize) -> Vec<DVec3> {
        match *self {
            Segment::Line { start, end } => vec![start, end],
            Segment::Arc { center, axis, start, end, .. } => {
                let n = n.max(1);
                let sweep = self.sweep();
                let u = start - center;
                let w = axis.cross(u);
                let mut out: Vec<DVec3> = (0..n)
                    .map(|k| {
                        let a = sweep * k as f64 / n as f64;
                        center + u * a.cos() + w * a.sin()
                    })
                    .collect();
                out.push(end);
                out
            }
        }
    }
}

/// The surface a face lies on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Surface {
    /// A plane through `point` with the face's outward unit normal `normal`.
    Plane {
        /// A point of the plane.
        point: DVec3,
        /// Outward unit normal of the face (out of the solid).
        normal: DVec3,
    },
    /// A circular cylinder.
    Cylinder {
        /// A point of the axis.
        point: DVec3,
        /// Unit direction of the axis.
        axis: DVec3,
        /// Radius (mm), > 0.
        radius: f64,
        /// Whether the face's outward normal points away from the axis (the outer surface of a bend, or a boss);
        /// `false`: towards it (the inner surface of a bend, the wall of a hole).
        convex: bool,
    },
}

/// One face of a [`Brep`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BrepFace {
    /// Where the face came from.
    pub source: FaceSource,
    /// Its surface.
    pub surface: Surface,
    /// Its boundary loops, each a closed chain of segments (each segment's end is the next one's start, the last
    /// one's end the first one's start). For a planar face the outer loop is the first, counter-clockwise seen from
    /// outside (from the tip of the outward normal), so that the face lies to the left of every loop; holes follow,
    /// clockwise. For a cylindrical face the loops are only its boundary (their order and orientation carry no
    /// meaning).
    pub loops: Vec<Vec<Segment>>,
}

impl BrepFace {
    /// Points on the face's boundary: every segment's start and, on arcs, points at most `max_angle` radians apart.
    pub fn boundary_points(&self, max_angle: f64) -> Vec<DVec3> {
        let mut out = Vec::new();
        for lp in &self.loops {
            for s in lp {
                let n = if max_angle > 0.0 { (s.sweep() / max_angle).ceil().max(1.0) as usize } else { 1 };
                let pts = s.points(n);
                out.extend_from_slice(&pts[..pts.len() - 1]);
            }
        }
        out
    }
}

/// A solid's boundary reduced to what sheet-metal recognition needs: planar and cylindrical faces.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Brep {
    /// The faces.
    pub faces: Vec<BrepFace>,
    /// The solid's volume (mm^3) where the source knows it exactly (a mesh: its enclosed volume), else `None` and
    /// recognition computes it from the recognised sheet.
    pub volume: Option<f64>,
    /// For a STEP solid with faces on other surfaces than planes and cylinders: how it was tessellated (its faces
    /// are then those [`mesh_faces`] finds in the tessellation).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tessellation: Option<Tessellation>,
}

/// How a STEP solid was tessellated to take it through the mesh route ([`crate::io::step`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Tessellation {
    /// The solid's faces (all are tessellated).
    pub faces: usize,
    /// Of these, the faces on surfaces other than planes and cylinders, or bounded by curves other than lines,
    /// circles and polylines: the ones that called for it.
    pub curved_faces: usize,
    /// Triangles of the mesh.
    pub triangles: usize,
    /// The chord tolerance (mm): every triangle and edge chord lies within it of the exact faces, so the pieces
    /// recognised from the mesh contain the solid to within it.
    pub chord_tolerance: f64,
}

/// The area enclosed by a closed loop of segments (mm^2), signed positive when it turns counter-clockwise about `normal` (a unit
/// vector): the polygon of the segments' chords plus, for every arc, the circular segment between chord and arc
/// (`r^2 (t - sin t) / 2` for a sweep `t`, with the sign of the arc's axis along the normal); a full circle gives
/// `pi r^2`. O(segments).
pub fn loop_area(lp: &[Segment], normal: DVec3) -> f64 {
    let origin = lp.first().map_or(DVec3::ZERO, Segment::start);
    lp.iter()
        .map(|s| {
            let chord = 0.5 * (s.start() - origin).cross(s.end() - origin).dot(normal);
            match *s {
                Segment::Line { .. } => chord,
                Segment::Arc { axis, radius, .. } => {
                    let t = s.sweep();
                    chord + axis.dot(normal) * 0.5 * radius * radius * (t - t.sin())
                }
            }
        })
        .sum()
}
