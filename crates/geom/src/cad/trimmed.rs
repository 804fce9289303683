//! Triangulation of a trimmed face: its boundary loops, mapped into the surface's parameter domain, are
//! triangulated, made constrained-Delaunay and refined with interior points until every triangle lies within a
//! chord tolerance of the surface.
//!
//! 1. The domain is scaled by the lengths of the surface's partial derivatives at its middle (`|S_u|`, `|S_v|`), so
//!    that parameter distances approximate lengths on the surface (exactly for a cylinder's and a plane's).
//! 2. The loop of largest area is the outer one; the loops are triangulated by ear clipping with holes
//!    ([`crate::triangulate`]: exact `orient2d` decisions).
//! 3. Lawson's edge flips make the triangulation constrained-Delaunay: an edge that is not a loop edge is flipped
//!    while the far vertex of one triangle lies strictly inside the other's circumcircle (exact `incircle`,
//!    J. R. Shewchuk, *Adaptive precision floating-point arithmetic and fast robust geometric predicates*, 1997). On a
//!    cylinder or a cone whose loops are sampled at the same angles on both ends, the result is the quadrilaterals
//!    between consecutive generators, each split into two coplanar triangles.
//! 4. Refinement (in the manner of Delaunay refinement, J. Ruppert, *A Delaunay refinement algorithm for quality
//!    2-dimensional mesh generation*, J. Algorithms 18, 1995, with the chord error as the criterion): the chord error
//!    of a triangle is the largest distance of the surface points at its centroid and at the middles of its interior
//!    edges from the flat triangle or edge; a triangle above the tolerance gets its centroid inserted, and the flips
//!    are redone around it. Loop edges are never split, so the boundary samples, shared with the neighbouring faces,
//!    stay as they are and the mesh of a solid is watertight.
//!
//! The triangles come out counter-clockwise seen from the side the loops are counter-clockwise about (the outer one
//! in the parameter plane, reversed when that loop runs clockwise there).
//!
//! Complexity: ear clipping O(n^2) for n boundary points; each flip O(1) and each insertion O(1) plus its flips
//! (O(1) expected); the refinement inserts m points for O((n + m) log(n + m)) expected work in all.

use super::geometry::{FaceSurface, segment_distance};
use crate::triangulate::{TriangulationError, triangulate};
use glam::{DVec2, DVec3};
use std::collections::HashSet;

const NONE: usize = usize::MAX;

/// A boundary point of a face: its parameters, its point in space and its index in the solid's mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopPoint {
    /// Parameters on the surface.
    pub q: DVec2,
    /// The point (an edge's sample, shared with the neighbouring face).
    pub p: DVec3,
    /// Its index among the mesh's points.
    pub id: usize,
}

/// Why a face's domain could not be triangulated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrimmedError {
    /// No loop encloses any area in the parameter domain.
    #[error("its loops enclose no area in the surface's parameter domain")]
    NoArea,
    /// The loops in the parameter domain are not simple or cross each other.
    #[error("its loops in the surface's parameter domain are not simple, disjoint polygons: {0}")]
    Loops(TriangulationError),
    /// The refinement did not reach the tolerance within the point budget.
    #[error("{points} interior points do not bring it within {tolerance} mm of its surface")]
    Budget {
        /// Interior points inserted.
        points: usize,
        /// The chord tolerance (mm).
        tolerance: f64,
    },
    /// A triangle joins a point to itself (a loop through a pole or along a seam that the domain does not cut).
    #[error("a triangle joins the point ({:.4}, {:.4}, {:.4}) to itself", point.x, point.y, point.z)]
    Degenerate {
        /// The point.
        point: DVec3,
    },
}

/// The triangulation of one face: its new interior points (numbered from `first_id` in order) and its triangles
/// (mesh point indices).
#[derive(Debug, Clone, Default)]
pub struct FaceMesh {
    /// Interior points, numbered `first_id`, `first_id + 1`, ...
    pub points: Vec<DVec3>,
    /// Triangles.
    pub triangles: Vec<[usize; 3]>,
}

/// Triangulates the domain bounded by `loops` on `surface` within `tolerance` (mm); at most `budget` interior
/// points. See the module documentation.
pub fn triangulate_trimmed(
    surface: &FaceSurface,
    loops: &[Vec<LoopPoint>],
    tolerance: f64,
    first_id: usize,
    budget: usize,
) -> Result<FaceMesh, TrimmedError> {
    // 1. the metric
    let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
    for p in loops.iter().flatten() {
        lo = lo.min(p.q);
        hi = hi.max(p.q);
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return Err(TrimmedError::NoArea);
    }
    let (_, su, sv) = surface.eval(0.5 * (lo + hi));
    let positive = |x: f64| if x.is_finite() && x > 1e-12 { x } else { 1.0 };
    let scale = DVec2::new(positive(su.length()), positive(sv.length()));
    let mut mesh = Mesh { xy: Vec::new(), q: Vec::new(), p: Vec::new(), id: Vec::new(), ..Mesh::default() };
    // 2. rings without repeated points, outer first
    let mut rings: Vec<Vec<usize>> = Vec::new();
    for lp in loops {
        let mut ring: Vec<usize> = Vec::new();
        for point in lp {
            let xy = point.q * scale;
            if ring.last().is_some_and(|&k| mesh.id[k] == point.id || mesh.xy[k] == xy) {
                continue;
            }
            ring.push(mesh.push(xy, point.q, point.p, point.id));
        }
        while ring.len() > 1 && (mesh.id[ring[0]] == mesh.id[ring[ring.len() - 1]]) {
            let last = ring[ring.len() - 1];
            if mesh.xy[last] != mesh.xy[ring[0]] {
                break; // the same point at two places of the domain: a seam, kept
            }
            ring.pop();
        }
        if ring.len() >= 3 {
            rings.push(ring);
        }
    }
    let areas: Vec<f64> = rings.iter().map(|r| mesh.area(r)).collect();
    let outer = (0..rings.len())
        .max_by(|&a, &b| areas[a].abs().total_cmp(&areas[b].abs()))
        .filter(|&k| areas[k] != 0.0)
        .ok_or(TrimmedError::NoArea)?;
    let reversed = areas[outer] < 0.0;
    for (k, ring) in rings.iter_mut().enumerate() {
        if (k == outer) == (areas[k] < 0.0) {
            ring.reverse();
        }
    }
    for ring in &rings {
        for k in 0..ring.len() {
            let (a, b) = (ring[k], ring[(k + 1) % ring.len()]);
            mesh.constrained.insert((a.min(b), a.max(b)));
        }
    }
    let holes: Vec<Vec<usize>> =
        rings.iter().enumerate().filter(|(k, _)| *k != outer).map(|(_, r)| r.clone()).collect();
    let triangles = triangulate(&mesh.xy, &rings[outer], &holes).map_err(TrimmedError::Loops)?;
    mesh.build(triangles);
    // 3. constrained Delaunay
    let mut stack: Vec<(usize, usize)> = (0..mesh.tris.len()).flat_map(|t| (0..3).map(move |k| (t, k))).collect();
    mesh.legalize(&mut stack);
    // 4. refinement
    let first_new = mesh.xy.len();
    if !surface.is_plane() {
        let mut queue: Vec<usize> = (0..mesh.tris.len()).collect();
        while let Some(t) = queue.pop() {
            if mesh.chord_error(surface, t) <= tolerance {
                continue;
            }
            if mesh.xy.len() - first_new >= budget {
                return Err(TrimmedError::Budget { points: budget, tolerance });
            }
            let [a, b, c] = mesh.tris[t];
            let q = (mesh.q[a] + mesh.q[b] + mesh.q[c]) / 3.0;
            let id = first_id + (mesh.xy.len() - first_new);
            let m = mesh.push(q * scale, q, surface.point(q), id);
            let new = mesh.split(t, m);
            let mut stack: Vec<(usize, usize)> = new.iter().map(|&x| (x, 0)).collect();
            let touched = mesh.legalize(&mut stack);
            queue.extend(new);
            queue.extend(touched);
        }
    }
    let mut out = FaceMesh { points: mesh.p[first_new..].to_vec(), triangles: Vec::with_capacity(mesh.tris.len()) };
    for v in &mesh.tris {
        let ids = v.map(|k| mesh.id[k]);
        if ids[0] == ids[1] || ids[1] == ids[2] || ids[0] == ids[2] {
            let k = if ids[0] == ids[1] || ids[0] == ids[2] { v[0] } else { v[1] };
            return Err(TrimmedError::Degenerate { point: mesh.p[k] });
        }
        out.triangles.push(if reversed { [ids[0], ids[2], ids[1]] } else { ids });
    }
    Ok(out)
}

/// A triangulation of the domain with adjacency.
#[derive(Default)]
struct Mesh {
    /// Scaled parameters (the metric plane).
    xy: Vec<DVec2>,
    /// Parameters.
    q: Vec<DVec2>,
    /// Points in space.
    p: Vec<DVec3>,
    /// Mesh indices.
    id: Vec<usize>,
    /// Counter-clockwise triangles of local indices.
    tris: Vec<[usize; 3]>,
    /// The triangle across edge `k` (`v[k] -> v[k + 1]`), or `NONE`.
    nbr: Vec<[usize; 3]>,
    /// Loop edges (never flipped), as ordered pairs of local indices.
    constrained: HashSet<(usize, usize)>,
}

impl Mesh {
    fn push(&mut self, xy: DVec2, q: DVec2, p: DVec3, id: usize) -> usize {
        self.xy.push(xy);
        self.q.push(q);
        self.p.push(p);
        self.id.push(id);
        self.xy.len() - 1
    }

    fn area(&self, ring: &[usize]) -> f64 {
        let n = ring.len();
        let o = self.xy[ring[0]];
        (1..n.saturating_sub(1)).map(|k| (self.xy[ring[k]] - o).perp_dot(self.xy[ring[k + 1]] - o)).sum::<f64>() / 2.0
    }

    fn build(&mut self, tris: Vec<[usize; 3]>) {
        let mut directed = std::collections::HashMap::with_capacity(3 * tris.len());
        for (t, v) in tris.iter().enumerate() {
            for k in 0..3 {
                directed.insert((v[k], v[(k + 1) % 3]), t);
            }
        }
        self.nbr = tris
            .iter()
            .map(|v| {
                let mut n = [NONE; 3];
                for k in 0..3 {
                    n[k] = directed.get(&(v[(k + 1) % 3], v[k])).copied().unwrap_or(NONE);
                }
                n
            })
            .collect();
        self.tris = tris;
    }

    fn is_constrained(&self, a: usize, b: usize) -> bool {
        self.constrained.contains(&(a.min(b), a.max(b)))
    }

    /// The edge index of `a -> b` in triangle `t`.
    fn edge(&self, t: usize, a: usize, b: usize) -> Option<usize> {
        let v = self.tris[t];
        (0..3).find(|&k| v[k] == a && v[(k + 1) % 3] == b)
    }

    /// Points triangle `x`'s pointer across its edge `b -> a` to `t` (`x` may be `NONE`).
    fn repoint(&mut self, x: usize, a: usize, b: usize, t: usize) {
        if x != NONE
            && let Some(k) = self.edge(x, b, a)
        {
            self.nbr[x][k] = t;
        }
    }

    /// Flips the edges on the stack (triangle, edge) while they are not locally Delaunay; returns the triangles
    /// changed.
    fn legalize(&mut self, stack: &mut Vec<(usize, usize)>) -> Vec<usize> {
        let mut touched = Vec::new();
        let mut flips = 0usize;
        let limit = 64 * (self.tris.len() + 16) * (self.tris.len() + 16);
        while let Some((t, k)) = stack.pop() {
            let s = self.nbr[t][k];
            let [a, b, c] = [self.tris[t][k], self.tris[t][(k + 1) % 3], self.tris[t][(k + 2) % 3]];
            if s == NONE || self.is_constrained(a, b) {
                continue;
            }
            let Some(j) = self.edge(s, b, a) else { continue };
            let d = self.tris[s][(j + 2) % 3];
            let inside = robust::incircle(c2(self.xy[a]), c2(self.xy[b]), c2(self.xy[c]), c2(self.xy[d]));
            if inside <= 0.0 {
                continue;
            }
            flips += 1;
            if flips > limit {
                break;
            }
            // t = (a, b, c), s = (b, a, d)  ->  t = (a, d, c), s = (d, b, c)
            let n_bc = self.nbr[t][(k + 1) % 3];
            let n_ca = self.nbr[t][(k + 2) % 3];
            let n_ad = self.nbr[s][(j + 1) % 3];
            let n_db = self.nbr[s][(j + 2) % 3];
            self.tris[t] = [a, d, c];
            self.nbr[t] = [n_ad, s, n_ca];
            self.tris[s] = [d, b, c];
            self.nbr[s] = [n_db, n_bc, t];
            self.repoint(n_ad, a, d, t);
            self.repoint(n_bc, b, c, s);
            touched.push(t);
            touched.push(s);
            stack.extend([(t, 0), (t, 2), (s, 0), (s, 1)]);
        }
        touched
    }

    /// Splits triangle `t` at the new point `m` into three; returns them.
    fn split(&mut self, t: usize, m: usize) -> [usize; 3] {
        let [a, b, c] = self.tris[t];
        let [n_ab, n_bc, n_ca] = self.nbr[t];
        let (t1, t2) = (self.tris.len(), self.tris.len() + 1);
        self.tris[t] = [a, b, m];
        self.nbr[t] = [n_ab, t1, t2];
        self.tris.push([b, c, m]);
        self.nbr.push([n_bc, t2, t]);
        self.tris.push([c, a, m]);
        self.nbr.push([n_ca, t, t1]);
        self.repoint(n_bc, b, c, t1);
        self.repoint(n_ca, c, a, t2);
        [t, t1, t2]
    }

    /// The chord error of triangle `t`: see the module documentation.
    fn chord_error(&self, surface: &FaceSurface, t: usize) -> f64 {
        let v = self.tris[t];
        let [a, b, c] = v.map(|k| self.p[k]);
        if self.id[v[0]] == self.id[v[1]] || self.id[v[1]] == self.id[v[2]] || self.id[v[0]] == self.id[v[2]] {
            return f64::INFINITY;
        }
        let q = (self.q[v[0]] + self.q[v[1]] + self.q[v[2]]) / 3.0;
        let centre = surface.point(q);
        let normal = (b - a).cross(c - a);
        let len = normal.length();
        let longest = (b - a).length().max((c - b).length()).max((a - c).length());
        let mut error = if len > 1e-12 * longest * longest {
            (centre - a).dot(normal).abs() / len
        } else {
            // a flat triangle in space: no plane, the distance from its edges
            segment_distance(centre, a, b).min(segment_distance(centre, b, c)).min(segment_distance(centre, c, a))
        };
        for k in 0..3 {
            let (i, j) = (v[k], v[(k + 1) % 3]);
            if self.is_constrained(i, j) {
                continue;
            }
            let mid = surface.point(0.5 * (self.q[i] + self.q[j]));
            error = error.max(segment_distance(mid, self.p[i], self.p[j]));
        }
        error
    }
}

fn c2(p: DVec2) -> robust::Coord<f64> {
    robust::Coord { x: p.x, y: p.y }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cad::geometry::Frame;
    use std::f64::consts::PI;

    /// The loop of a rectangle of the parameter plane, sampled on its sides through `samples`.
    fn rectangle(
        surface: &FaceSurface,
        corners: [DVec2; 4],
        samples: &dyn Fn(DVec2, DVec2) -> usize,
    ) -> Vec<LoopPoint> {
        let mut out = Vec::new();
        for k in 0..4 {
            let (a, b) = (corners[k], corners[(k + 1) % 4]);
            let n = samples(a, b);
            for s in 0..n {
                let q = a + (b - a) * s as f64 / n as f64;
                out.push(LoopPoint { q, p: surface.point(q), id: out.len() });
            }
        }
        out
    }

    #[test]
    fn a_cylinder_strip_becomes_coplanar_pairs_between_generators() {
        let frame = Frame::new(DVec3::ZERO, DVec3::Y, Some(DVec3::X));
        let (r, w, tol) = (3.0, 40.0, 0.025);
        let cylinder = FaceSurface::Cylinder { frame, radius: r };
        let n = crate::cad::geometry::conic_steps(r, PI / 2.0, tol);
        let corners = [DVec2::new(0.0, 0.0), DVec2::new(PI / 2.0, 0.0), DVec2::new(PI / 2.0, w), DVec2::new(0.0, w)];
        let lp = rectangle(&cylinder, corners, &|a, b| if a.y == b.y { n } else { 1 });
        let mesh = triangulate_trimmed(&cylinder, std::slice::from_ref(&lp), tol, lp.len(), 1000).expect("mesh");
        assert!(mesh.points.is_empty(), "no interior point on a ruled strip");
        assert_eq!(mesh.triangles.len(), 2 * n);
        let p = |i: usize| lp[i].p;
        for t in &mesh.triangles {
            // each triangle spans one step of angle
            let angles: Vec<f64> = t.iter().map(|&i| p(i).z.atan2(p(i).x)).collect();
            let spread = angles.iter().copied().fold(f64::NEG_INFINITY, f64::max)
                - angles.iter().copied().fold(f64::INFINITY, f64::min);
            assert!(spread <= PI / 2.0 / n as f64 + 1e-12, "{angles:?}");
            // counter-clockwise seen from outside: the normal points away from the axis
            let normal = (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0]));
            let centre = (p(t[0]) + p(t[1]) + p(t[2])) / 3.0;
            assert!(normal.dot(centre.with_y(0.0)) > 0.0);
        }
    }

    #[test]
    fn a_torus_patch_is_refined_within_the_tolerance() {
        let frame = Frame::new(DVec3::ZERO, DVec3::Z, None);
        let torus = FaceSurface::Torus { frame, major: 8.0, minor: 3.0 };
        let tol = 0.01;
        let corners = [DVec2::new(0.0, -1.0), DVec2::new(2.0, -1.0), DVec2::new(2.0, 1.5), DVec2::new(0.0, 1.5)];
        let lp = rectangle(&torus, corners, &|a, b| {
            let r = if a.y == b.y { 8.0 + 3.0 * a.y.cos() } else { 3.0 };
            crate::cad::geometry::conic_steps(r, (b - a).length(), tol)
        });
        let mesh = triangulate_trimmed(&torus, std::slice::from_ref(&lp), tol, lp.len(), 100_000).expect("mesh");
        assert!(!mesh.points.is_empty());
        let point = |i: usize| if i < lp.len() { lp[i].p } else { mesh.points[i - lp.len()] };
        let mut area = 0.0;
        for t in &mesh.triangles {
            let [a, b, c] = t.map(point);
            area += 0.5 * (b - a).cross(c - a).length();
            // the centroid of every triangle is within the tolerance of the torus
            let g = (a + b + c) / 3.0;
            let off = ((g.x.hypot(g.y) - 8.0).hypot(g.z) - 3.0).abs();
            assert!(off <= tol * 1.5, "{off}");
        }
        // the area of the patch: integral of r (R + r cos v) du dv
        let exact = 3.0 * 2.0 * (8.0 * 2.5 + 3.0 * (1.5f64.sin() - (-1.0f64).sin()));
        assert!((area - exact).abs() < 0.01 * exact, "{area} vs {exact}");
    }

    #[test]
    fn a_plane_with_a_hole_needs_no_interior_point_and_loops_that_cross_are_an_error() {
        let plane = FaceSurface::Plane(Frame::new(DVec3::ZERO, DVec3::Z, Some(DVec3::X)));
        let pt = |x: f64, y: f64, id: usize| LoopPoint { q: DVec2::new(x, y), p: DVec3::new(x, y, 0.0), id };
        let outer = vec![pt(0.0, 0.0, 0), pt(10.0, 0.0, 1), pt(10.0, 10.0, 2), pt(0.0, 10.0, 3)];
        let hole = vec![pt(4.0, 4.0, 4), pt(6.0, 4.0, 5), pt(6.0, 6.0, 6), pt(4.0, 6.0, 7)];
        let mesh = triangulate_trimmed(&plane, &[hole.clone(), outer.clone()], 0.01, 8, 10).expect("mesh");
        assert!(mesh.points.is_empty());
        assert_eq!(mesh.triangles.len(), 8);
        let crossing = vec![pt(5.0, -1.0, 4), pt(6.0, -1.0, 5), pt(6.0, 6.0, 6), pt(5.0, 6.0, 7)];
        let e = triangulate_trimmed(&plane, &[outer, crossing], 0.01, 8, 10).expect_err("crossing loops");
        assert!(matches!(e, TrimmedError::Loops(_)), "{e}");
    }
}
