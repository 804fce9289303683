//! A solid with faces on surfaces other than planes and cylinders, or edges on curves other than lines, circles and
//! polylines, tessellated into one closed triangle mesh and segmented into faces as a mesh is
//! ([`crate::cad::mesh_faces`]), so that its recognition is the one a mesh gets.
//!
//! Surfaces read (ISO 10303-42 entities, parametrised as in [`crate::cad::geometry`]): `PLANE`,
//! `CYLINDRICAL_SURFACE`, `CONICAL_SURFACE`, `SPHERICAL_SURFACE`, `TOROIDAL_SURFACE`, `SURFACE_OF_LINEAR_EXTRUSION`
//! and `B_SPLINE_SURFACE_WITH_KNOTS`, simple or in the complex form with `RATIONAL_B_SPLINE_SURFACE`. Curves: `LINE`,
//! `CIRCLE`, `ELLIPSE`, `POLYLINE` and `B_SPLINE_CURVE_WITH_KNOTS` of any degree, simple or rational (complex form),
//! through `SURFACE_CURVE`, `SEAM_CURVE` and `INTERSECTION_CURVE` (the 3-D curve is taken).
//!
//! 1. **Edges** are sampled once each, within the chord tolerance, from the start vertex to the end vertex
//!    ([`Curve::samples`]): a circle or an ellipse over its arc in the sense of the edge (the whole period when both
//!    vertices are one), a B-spline between the parameters of its vertices (its whole domain when they are one). The
//!    vertices and samples are the mesh's points, shared by the two faces of each edge.
//! 2. **Faces**: each loop's points are mapped into the surface's parameter domain ([`FaceSurface::inverse`], each
//!    point from the previous one, so a periodic parameter runs on continuously across the seam and a loop along a
//!    seam edge closes on the far side of the period; a face between two loops that wind around the period in
//!    opposite senses, with no seam edge, is cut along a seam of its own), then the domain is triangulated and refined
//!    ([`crate::cad::trimmed`]) with the same tolerance; interior points are new mesh points. A boundary point more
//!    than ten tolerances off its surface is an error naming the face.
//! 3. The triangles are oriented by the loops (the face on the left of each loop seen from outside, as the bounds'
//!    and edges' flags give them), so two faces traverse their common edge in opposite directions and the mesh is
//!    closed; each triangle's place is its face's entity, which is how the mesh's errors and faces name it.
//!
//! Complexity: O(E s) evaluations for E edges of s samples; per face as in [`crate::cad::trimmed`].

use super::brep::{Entity, Graph, number};
use super::p21::{Instance, Value};
use crate::cad::geometry::{Curve, FaceSurface, Frame};
use crate::cad::nurbs::{BSplineCurve, BSplineSurface, NurbsError};
use crate::cad::trimmed::{LoopPoint, triangulate_trimmed};
use crate::io::mesh::MeshPolygon;
use crate::io::{IoError, Place};
use glam::{DVec2, DVec3};
use std::collections::HashMap;

/// Most interior points one face may get.
const FACE_BUDGET: usize = 200_000;
/// Deepest chain of curves wrapping curves followed.
const MAX_CHAIN: usize = 8;

/// The mesh of a solid and what it took.
#[derive(Debug)]
pub(super) struct SolidMesh {
    pub points: Vec<DVec3>,
    pub triangles: Vec<MeshPolygon>,
    /// Faces tessellated.
    pub faces: usize,
    /// Of these, faces on surfaces other than planes and cylinders or bounded by curves other than lines, circles
    /// and polylines.
    pub curved: usize,
}

/// One oriented edge of a loop: its mesh points from its start to its end.
struct Piece {
    id: u64,
    start_vertex: u64,
    end_vertex: u64,
    points: Vec<usize>,
}

struct Builder<'g, 'a> {
    graph: &'g Graph<'a>,
    tolerance: f64,
    points: Vec<DVec3>,
    vertices: HashMap<u64, usize>,
    /// Each edge's points from its start vertex to its end vertex, and whether its curve is exact in the B-rep.
    edges: HashMap<u64, (Vec<usize>, bool)>,
}

/// Tessellates the solid `solid` within `tolerance` (mm).
pub(super) fn tessellate_solid(graph: &Graph<'_>, solid: u64, tolerance: f64) -> Result<SolidMesh, IoError> {
    let (shell, faces, flip) = graph.shell(solid)?;
    let mut b = Builder { graph, tolerance, points: Vec::new(), vertices: HashMap::new(), edges: HashMap::new() };
    let mut triangles = Vec::new();
    let mut curved = 0;
    for &f in &faces {
        let exact = b.face(f, shell, flip, &mut triangles)?;
        curved += usize::from(!exact);
    }
    Ok(SolidMesh { points: b.points, triangles, faces: faces.len(), curved })
}

impl Builder<'_, '_> {
    fn file(&self) -> &std::path::Path {
        self.graph.file
    }

    fn failure(&self, face: u64, message: String) -> IoError {
        IoError::Tessellation { file: self.file().to_path_buf(), at: Place::Entity(face), message }
    }

    /// Tessellates one face; returns whether its surface and curves are ones the exact B-rep keeps.
    fn face(&mut self, id: u64, from: u64, flip: bool, out: &mut Vec<MeshPolygon>) -> Result<bool, IoError> {
        let g = self.graph;
        let e = g.expect(id, from, &["ADVANCED_FACE", "FACE_SURFACE", "ORIENTED_FACE"])?;
        if e.name() == "ORIENTED_FACE" {
            e.arity(4)?;
            let inner = e.reference(2, "face")?;
            let orientation = e.logical(3, "orientation")?;
            let inner_e = g.expect(inner, id, &["ADVANCED_FACE", "FACE_SURFACE"])?;
            return self.face(inner_e.id, id, flip == orientation, out);
        }
        e.arity(4)?;
        let bounds = e.references(1, "bounds")?;
        let surface_id = e.reference(2, "face geometry")?;
        let surface = self.surface(surface_id, id)?;
        let mut exact = matches!(surface, FaceSurface::Plane(_) | FaceSurface::Cylinder { .. });
        let mut loops: Vec<Vec<usize>> = Vec::new();
        for b in bounds {
            let be = g.expect(b, id, &["FACE_OUTER_BOUND", "FACE_BOUND"])?;
            be.arity(3)?;
            let loop_id = be.reference(1, "bound")?;
            let orientation = be.logical(2, "orientation")?;
            let Some((mut lp, loop_exact)) = self.edge_loop(loop_id, b, id)? else { continue };
            exact &= loop_exact;
            if orientation == flip {
                lp.reverse();
            }
            if lp.len() >= 2 {
                loops.push(lp);
            }
        }
        if loops.is_empty() {
            return Err(self.failure(id, format!("{}: the face has no edge loop to bound it", e.name())));
        }
        // into the parameter domain, each point from the previous one
        let allowed = (10.0 * self.tolerance).max(1e-3);
        let mut domain_loops = Vec::with_capacity(loops.len());
        let mut winding: Vec<(Vec<LoopPoint>, usize, f64)> = Vec::new();
        for lp in &loops {
            let mut hint: Option<DVec2> = None;
            let mut ring = Vec::with_capacity(lp.len() + 1);
            for &k in lp.iter().chain(std::iter::once(&lp[0])) {
                let p = self.points[k];
                let q = surface.inverse(p, hint);
                let off = (surface.point(q) - p).length();
                if off.is_nan() || off > allowed {
                    return Err(self.failure(
                        id,
                        format!(
                            "its boundary point ({:.4}, {:.4}, {:.4}) is {} mm off its surface #{surface_id}",
                            p.x,
                            p.y,
                            p.z,
                            crate::io::short_number(off)
                        ),
                    ));
                }
                hint = Some(q);
                ring.push(LoopPoint { q, p, id: k });
            }
            // the first point again, reached around the loop: the same parameters unless the loop winds around a
            // period of the surface
            let (Some(first), Some(last)) = (ring.first().copied(), ring.pop()) else { continue };
            let d = last.q - first.q;
            if d.length() <= 1e-6 * (1.0 + first.q.length()) {
                domain_loops.push(ring);
                continue;
            }
            let (pu, pv) = surface.periods();
            let around = |x: f64, y: f64, p: Option<f64>| {
                p.is_some_and(|p| (x.abs() - p).abs() <= 1e-6 * p && y.abs() <= 1e-6 * p)
            };
            let axis = if around(d.x, d.y, pu) {
                0
            } else if around(d.y, d.x, pv) {
                1
            } else {
                return Err(self.failure(
                    id,
                    format!("a loop does not close in the parameter domain of its surface #{surface_id}"),
                ));
            };
            winding.push((ring, axis, d[axis]));
        }
        match winding.as_slice() {
            [] => {}
            [(a, i, wa), (b, j, wb)] if i == j && wa * wb < 0.0 => {
                let band = self.band(&surface, a, b, *i, *wa);
                domain_loops.push(band);
            }
            _ => {
                return Err(self.failure(
                    id,
                    format!(
                        "{} of its loops wind around a period of its surface #{surface_id} (a face around a pole or \
                         apex), which is not supported",
                        winding.len()
                    ),
                ));
            }
        }
        let mesh = triangulate_trimmed(&surface, &domain_loops, self.tolerance, self.points.len(), FACE_BUDGET)
            .map_err(|reason| self.failure(id, format!("its surface #{surface_id} cannot be tessellated: {reason}")))?;
        self.points.extend(mesh.points);
        out.extend(mesh.triangles.into_iter().map(|t| MeshPolygon { vertices: t.to_vec(), place: Place::Entity(id) }));
        Ok(exact)
    }

    /// The one loop of a band: a face between two loops that wind around a period of its surface in opposite
    /// senses (a full cylinder or cone between two circles, as Parasolid writes them, without a seam edge). The
    /// domain is cut along a seam from the first point of `a` to the point of `b` nearest it in that parameter:
    /// `a`, the seam, `b`, the seam back (the same points, one period over). `axis` is the winding parameter (0: u,
    /// 1: v) and `wa` the signed period `a` winds by.
    fn band(
        &mut self,
        surface: &FaceSurface,
        a: &[LoopPoint],
        b: &[LoopPoint],
        axis: usize,
        wa: f64,
    ) -> Vec<LoopPoint> {
        let period = wa.abs();
        let ua = a[0].q[axis];
        let offset = |x: f64| {
            let r = (x - ua).rem_euclid(period);
            r.min(period - r)
        };
        let k = (0..b.len()).min_by(|&x, &y| offset(b[x].q[axis]).total_cmp(&offset(b[y].q[axis]))).unwrap_or(0);
        let mut b: Vec<LoopPoint> = b[k..].iter().chain(&b[..k]).copied().collect();
        for j in 1..b.len() {
            let step = b[j - 1].q[axis] - b[j].q[axis];
            b[j].q[axis] += period * (step / period).round();
        }
        let shift = period * ((ua + wa - b[0].q[axis]) / period).round();
        for p in &mut b {
            p.q[axis] += shift;
        }
        let mut a_end = a[0];
        a_end.q[axis] += wa;
        let mut b_end = b[0];
        b_end.q[axis] -= wa;
        // the seam from the end of a to the start of b, sampled within the tolerance; its points serve both sides
        let (from, to) = (a_end.q, b[0].q);
        let path = |t: f64| surface.point(from + (to - from) * t);
        let seam: Vec<LoopPoint> = crate::cad::geometry::chord_params(&path, 0.0, 1.0, self.tolerance)
            .into_iter()
            .map(|t| {
                let p = path(t);
                self.points.push(p);
                LoopPoint { q: from + (to - from) * t, p, id: self.points.len() - 1 }
            })
            .collect();
        let mut ring: Vec<LoopPoint> = a.to_vec();
        ring.push(a_end);
        ring.extend(seam.iter().copied());
        ring.extend(b.iter().copied());
        ring.push(b_end);
        ring.extend(seam.iter().rev().map(|s| {
            let mut s = *s;
            s.q[axis] -= wa;
            s
        }));
        ring
    }

    /// A loop's mesh points in order (each edge's points but its last), and whether its curves are exact ones;
    /// `None` for a vertex loop.
    fn edge_loop(&mut self, id: u64, from: u64, face: u64) -> Result<Option<(Vec<usize>, bool)>, IoError> {
        let g = self.graph;
        let (entity, inst) = g.simple(id, from)?;
        let unsupported = || IoError::Unsupported {
            file: g.file.to_path_buf(),
            at: Place::Entity(id),
            kind: inst.type_name(),
            role: "loops",
            face: Some(face),
        };
        let e = entity.ok_or_else(unsupported)?;
        match e.name() {
            "VERTEX_LOOP" => Ok(None),
            "POLY_LOOP" => {
                e.arity(2)?;
                let mut out = Vec::new();
                for p in e.references(1, "polygon")? {
                    let point = g.point(p, id)?;
                    out.push(self.push_vertex(p, point));
                }
                out.dedup();
                Ok(Some((out, true)))
            }
            "EDGE_LOOP" => {
                e.arity(2)?;
                let mut pieces = Vec::new();
                let mut exact = true;
                for edge in e.references(1, "edge list")? {
                    let (piece, edge_exact) = self.oriented_edge(edge, id, face)?;
                    exact &= edge_exact;
                    pieces.push(piece);
                }
                let mut out = Vec::new();
                for (k, piece) in pieces.iter().enumerate() {
                    let next = &pieces[(k + 1) % pieces.len()];
                    if piece.end_vertex != next.start_vertex {
                        return Err(g.syntax(
                            id,
                            format!(
                                "EDGE_LOOP is not closed: edge #{} ends at vertex #{} but the next edge #{} starts \
                                 at vertex #{}",
                                piece.id, piece.end_vertex, next.id, next.start_vertex
                            ),
                        ));
                    }
                    out.extend_from_slice(&piece.points[..piece.points.len() - 1]);
                }
                Ok(Some((out, exact)))
            }
            _ => Err(unsupported()),
        }
    }

    fn push_vertex(&mut self, id: u64, point: DVec3) -> usize {
        *self.vertices.entry(id).or_insert_with(|| {
            self.points.push(point);
            self.points.len() - 1
        })
    }

    fn oriented_edge(&mut self, id: u64, from: u64, face: u64) -> Result<(Piece, bool), IoError> {
        let g = self.graph;
        let e = g.expect(id, from, &["ORIENTED_EDGE"])?;
        e.arity(5)?;
        let edge = e.reference(3, "edge element")?;
        let orientation = e.logical(4, "orientation")?;
        let ec = g.expect(edge, id, &["EDGE_CURVE"])?;
        ec.arity(5)?;
        let mut start_vertex = ec.reference(1, "edge start")?;
        let mut end_vertex = ec.reference(2, "edge end")?;
        if !self.edges.contains_key(&edge) {
            let sampled = self.edge_curve(ec, face)?;
            self.edges.insert(edge, sampled);
        }
        let (mut points, exact) = self.edges.get(&edge).cloned().unwrap_or_default();
        if !orientation {
            points.reverse();
            std::mem::swap(&mut start_vertex, &mut end_vertex);
        }
        Ok((Piece { id, start_vertex, end_vertex, points }, exact))
    }

    /// An `EDGE_CURVE`'s mesh points from its start vertex to its end vertex, and whether its curve is one the exact
    /// B-rep keeps.
    fn edge_curve(&mut self, e: Entity<'_>, face: u64) -> Result<(Vec<usize>, bool), IoError> {
        let g = self.graph;
        let start_vertex = e.reference(1, "edge start")?;
        let end_vertex = e.reference(2, "edge end")?;
        let curve_id = e.reference(3, "edge geometry")?;
        let same_sense = e.logical(4, "same_sense")?;
        let start = g.vertex(start_vertex, e.id)?;
        let end = g.vertex(end_vertex, e.id)?;
        let (curve, exact) = self.curve(curve_id, e.id, face)?;
        let closed = start_vertex == end_vertex;
        let (t0, t1) = match (curve.period(), curve.domain()) {
            (Some(period), _) => {
                // the arc in the edge's sense: the whole period when its ends are one point
                let t0 = curve.inverse(start);
                let d = (curve.inverse(end) - t0).rem_euclid(period);
                let full = closed || d < 1e-12 || period - d < 1e-12;
                let sweep = match (same_sense, full) {
                    (true, true) => period,
                    (true, false) => d,
                    (false, true) => -period,
                    (false, false) => d - period,
                };
                (t0, t0 + sweep)
            }
            (None, Some((a, b))) if closed => {
                if same_sense {
                    (a, b)
                } else {
                    (b, a)
                }
            }
            _ => (curve.inverse(start), curve.inverse(end)),
        };
        let samples = if closed && curve.period().is_none() && curve.domain().is_none() {
            Vec::new()
        } else {
            curve.samples(t0, t1, self.tolerance)
        };
        let mut out = vec![self.push_vertex(start_vertex, start)];
        for p in samples {
            self.points.push(p);
            out.push(self.points.len() - 1);
        }
        out.push(self.push_vertex(end_vertex, end));
        Ok((out, exact))
    }

    /// The 3-D curve `id` (through curve wrappers), and whether it is one the exact B-rep keeps (a line, a circle,
    /// a polyline or a degree-1 B-spline).
    fn curve(&self, mut id: u64, mut from: u64, face: u64) -> Result<(Curve, bool), IoError> {
        let g = self.graph;
        for _ in 0..=MAX_CHAIN {
            let (entity, inst) = g.simple(id, from)?;
            let unsupported = || IoError::Unsupported {
                file: g.file.to_path_buf(),
                at: Place::Entity(id),
                kind: inst.type_name(),
                role: "edges",
                face: Some(face),
            };
            let Some(c) = entity else {
                return match inst.record("B_SPLINE_CURVE") {
                    Some(_) => Ok((self.bspline_curve(id, inst)?, false)),
                    None => Err(unsupported()),
                };
            };
            return Ok(match c.name() {
                "SURFACE_CURVE" | "SEAM_CURVE" | "INTERSECTION_CURVE" => {
                    c.arity(4)?;
                    from = id;
                    id = c.reference(1, "curve_3d")?;
                    continue;
                }
                "LINE" => {
                    c.arity(3)?;
                    let point = g.point(c.reference(1, "pnt")?, id)?;
                    let vector = g.expect(c.reference(2, "dir")?, id, &["VECTOR"])?;
                    vector.arity(3)?;
                    let direction = g.direction(vector.reference(1, "orientation")?, vector.id)?;
                    (Curve::Line { point, direction }, true)
                }
                "CIRCLE" => {
                    c.arity(3)?;
                    let frame = self.placement(c.reference(1, "position")?, id)?;
                    (Curve::Circle { frame, radius: g.length(c, 2, "radius")? }, true)
                }
                "ELLIPSE" => {
                    c.arity(4)?;
                    let frame = self.placement(c.reference(1, "position")?, id)?;
                    (
                        Curve::Ellipse { frame, a: g.length(c, 2, "semi_axis_1")?, b: g.length(c, 3, "semi_axis_2")? },
                        false,
                    )
                }
                "POLYLINE" => {
                    c.arity(2)?;
                    let points = c.references(1, "points")?;
                    if points.len() < 2 {
                        return Err(c.error(format!("POLYLINE needs at least 2 points, got {}", points.len())));
                    }
                    let pts = points.iter().map(|&p| g.point(p, id)).collect::<Result<Vec<_>, _>>()?;
                    (Curve::Polyline(pts), true)
                }
                "B_SPLINE_CURVE_WITH_KNOTS" => {
                    let curve = self.bspline_curve(id, inst)?;
                    let linear = matches!(&curve, Curve::BSpline(b) if b.degree() == 1);
                    (curve, linear)
                }
                _ => return Err(unsupported()),
            });
        }
        Err(g.syntax(id, format!("curves nested more than {MAX_CHAIN} deep")))
    }

    fn placement(&self, id: u64, from: u64) -> Result<Frame, IoError> {
        self.graph.frame(id, from)
    }

    /// A B-spline curve, simple (`B_SPLINE_CURVE_WITH_KNOTS(name, degree, poles, form, closed, self_intersect,
    /// multiplicities, knots, spec)`) or complex (`B_SPLINE_CURVE(degree, poles, ...)
    /// B_SPLINE_CURVE_WITH_KNOTS(multiplicities, knots, spec)` with an optional `RATIONAL_B_SPLINE_CURVE(weights)`).
    fn bspline_curve(&self, id: u64, inst: &Instance) -> Result<Curve, IoError> {
        let g = self.graph;
        let file = g.file;
        let entity = |rec| Entity { id, rec, file };
        let (degree, poles, mults, knots) =
            match (inst.record("B_SPLINE_CURVE"), inst.record("B_SPLINE_CURVE_WITH_KNOTS")) {
                (Some(base), Some(with)) => {
                    let (b, w) = (entity(base), entity(with));
                    (b.integer(0, "degree")?, b.references(1, "control points")?, integers(w, 0)?, reals(w, 1)?)
                }
                (None, Some(simple)) => {
                    let s = entity(simple);
                    s.arity(9)?;
                    (s.integer(1, "degree")?, s.references(2, "control points")?, integers(s, 6)?, reals(s, 7)?)
                }
                _ => {
                    return Err(g.syntax(id, format!("{} has no knots (B_SPLINE_CURVE_WITH_KNOTS)", inst.type_name())));
                }
            };
        let weights = match inst.record("RATIONAL_B_SPLINE_CURVE") {
            Some(rec) => Some(reals(entity(rec), 0)?),
            None => None,
        };
        let points = poles.iter().map(|&p| g.point(p, id)).collect::<Result<Vec<_>, _>>()?;
        BSplineCurve::new(degree, &mults, &knots, &points, weights.as_deref())
            .map(Curve::BSpline)
            .map_err(|e| nurbs_error(g, id, inst, e))
    }

    /// The surface `id` of face `face`.
    fn surface(&self, id: u64, face: u64) -> Result<FaceSurface, IoError> {
        let g = self.graph;
        let (entity, inst) = g.simple(id, face)?;
        let unsupported = || IoError::Unsupported {
            file: g.file.to_path_buf(),
            at: Place::Entity(id),
            kind: inst.type_name(),
            role: "faces",
            face: Some(face),
        };
        let Some(e) = entity else {
            return match inst.record("B_SPLINE_SURFACE") {
                Some(_) => self.bspline_surface(id, inst),
                None => Err(unsupported()),
            };
        };
        Ok(match e.name() {
            "PLANE" => {
                e.arity(2)?;
                FaceSurface::Plane(self.placement(e.reference(1, "position")?, id)?)
            }
            "CYLINDRICAL_SURFACE" => {
                e.arity(3)?;
                let frame = self.placement(e.reference(1, "position")?, id)?;
                FaceSurface::Cylinder { frame, radius: g.length(e, 2, "radius")? }
            }
            "CONICAL_SURFACE" => {
                e.arity(4)?;
                let frame = self.placement(e.reference(1, "position")?, id)?;
                let radius = e.number(2, "radius")? * g.scale;
                let semi_angle = e.number(3, "semi_angle")? * g.angle;
                if !(radius >= 0.0 && semi_angle > 0.0 && semi_angle < std::f64::consts::FRAC_PI_2) {
                    return Err(e.error(format!(
                        "CONICAL_SURFACE needs a radius >= 0 and a semi-angle strictly between 0 and 90 degrees, got \
                         {radius} mm and {semi_angle} rad"
                    )));
                }
                FaceSurface::Cone { frame, radius, semi_angle }
            }
            "SPHERICAL_SURFACE" => {
                e.arity(3)?;
                let frame = self.placement(e.reference(1, "position")?, id)?;
                FaceSurface::Sphere { frame, radius: g.length(e, 2, "radius")? }
            }
            "TOROIDAL_SURFACE" => {
                e.arity(4)?;
                let frame = self.placement(e.reference(1, "position")?, id)?;
                let major = g.length(e, 2, "major_radius")?;
                let minor = g.length(e, 3, "minor_radius")?;
                FaceSurface::Torus { frame, major, minor }
            }
            "SURFACE_OF_LINEAR_EXTRUSION" => {
                e.arity(3)?;
                let (curve, _) = self.curve(e.reference(1, "swept_curve")?, id, face)?;
                let vector = g.expect(e.reference(2, "extrusion_axis")?, id, &["VECTOR"])?;
                vector.arity(3)?;
                let direction = g.direction(vector.reference(1, "orientation")?, vector.id)?;
                let magnitude = g.length(vector, 2, "magnitude")?;
                FaceSurface::Extrusion { curve, vector: direction * magnitude }
            }
            "B_SPLINE_SURFACE_WITH_KNOTS" => self.bspline_surface(id, inst)?,
            _ => return Err(unsupported()),
        })
    }

    /// A B-spline surface, simple (`B_SPLINE_SURFACE_WITH_KNOTS(name, u_degree, v_degree, poles, form, u_closed,
    /// v_closed, self_intersect, u_multiplicities, v_multiplicities, u_knots, v_knots, spec)`) or complex
    /// (`B_SPLINE_SURFACE(u_degree, v_degree, poles, ...) B_SPLINE_SURFACE_WITH_KNOTS(u_multiplicities,
    /// v_multiplicities, u_knots, v_knots, spec)` with an optional `RATIONAL_B_SPLINE_SURFACE(weights)`).
    fn bspline_surface(&self, id: u64, inst: &Instance) -> Result<FaceSurface, IoError> {
        let g = self.graph;
        let file = g.file;
        let entity = |rec| Entity { id, rec, file };
        let (base, first) = match (inst.record("B_SPLINE_SURFACE"), inst.record("B_SPLINE_SURFACE_WITH_KNOTS")) {
            (Some(base), Some(with)) => ((entity(base), 0), (entity(with), 0)),
            (None, Some(simple)) => {
                let s = entity(simple);
                s.arity(13)?;
                ((s, 1), (s, 8))
            }
            _ => {
                return Err(g.syntax(id, format!("{} has no knots (B_SPLINE_SURFACE_WITH_KNOTS)", inst.type_name())));
            }
        };
        let ((b, i), (w, j)) = (base, first);
        let degree = (b.integer(i, "u_degree")?, b.integer(i + 1, "v_degree")?);
        let net = self.point_grid(b, i + 2)?;
        let mults = (integers(w, j)?, integers(w, j + 1)?);
        let knots = (reals(w, j + 2)?, reals(w, j + 3)?);
        let weights = match inst.record("RATIONAL_B_SPLINE_SURFACE") {
            Some(rec) => {
                let r = entity(rec);
                let rows = r.list(0, "weights_data")?;
                Some(
                    rows.iter()
                        .map(|row| match row {
                            Value::List(xs) => xs
                                .iter()
                                .map(|x| number(x).ok_or_else(|| r.wrong(0, "weights_data", "lists of numbers", x)))
                                .collect::<Result<Vec<f64>, _>>(),
                            other => Err(r.wrong(0, "weights_data", "a list of lists", other)),
                        })
                        .collect::<Result<Vec<_>, _>>()?,
                )
            }
            None => None,
        };
        BSplineSurface::new(degree, (&mults.0, &mults.1), (&knots.0, &knots.1), &net, weights.as_deref())
            .map(FaceSurface::BSpline)
            .map_err(|e| nurbs_error(g, id, inst, e))
    }

    /// A list of lists of `CARTESIAN_POINT` references as points.
    fn point_grid(&self, e: Entity<'_>, i: usize) -> Result<Vec<Vec<DVec3>>, IoError> {
        let rows = e.list(i, "control_points_list")?;
        rows.iter()
            .map(|row| match row {
                Value::List(refs) => refs
                    .iter()
                    .map(|v| match v {
                        Value::Ref(p) => self.graph.point(*p, e.id),
                        other => Err(e.wrong(i, "control_points_list", "lists of references", other)),
                    })
                    .collect(),
                other => Err(e.wrong(i, "control_points_list", "a list of lists", other)),
            })
            .collect()
    }
}

/// A list of integers.
fn integers(e: Entity<'_>, i: usize) -> Result<Vec<i64>, IoError> {
    e.list(i, "knot_multiplicities")?
        .iter()
        .map(|v| match v {
            Value::Integer(n) => Ok(*n),
            other => Err(e.wrong(i, "knot_multiplicities", "a list of integers", other)),
        })
        .collect()
}

/// A list of numbers.
fn reals(e: Entity<'_>, i: usize) -> Result<Vec<f64>, IoError> {
    e.list(i, "knots")?.iter().map(|v| number(v).ok_or_else(|| e.wrong(i, "knots", "a list of numbers", v))).collect()
}

fn nurbs_error(g: &Graph<'_>, id: u64, inst: &Instance, e: NurbsError) -> IoError {
    g.syntax(id, format!("{}: {e}", inst.type_name()))
}
