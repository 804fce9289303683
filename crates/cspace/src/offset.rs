//! Obstacles derived by plane arithmetic: clearance, insertion obstacles and horizontal slices.
//!
//! * **Clearance** (\[A\] section 6.1.2, eq. 10-11): the robot's positioning error `delta` is absorbed by moving every
//!   face plane of the obstacle outwards by `delta` (`n . p <= d + delta`). This is the *mitred* offset: along an edge
//!   or at a vertex the offset planes meet farther out than `delta` (by a factor `1 / cos(phi / 2)` at an edge whose
//!   faces' normals make an angle `phi`), so it contains the exact offset `C (+) Ball(delta)` and is slightly
//!   conservative there; over every face it is exact. O(F).
//! * **Insertion obstacle** (\[A\] condition 4; `docs/algorithms.md`, "C-space obstacle of a convex pair"): the part
//!   reaches `p` by translating straight down from far above; it is blocked iff `p + t z` is in the interior of `C`
//!   for some `t >= 0`, i.e. iff `p` is in the interior of `C (+) {-t z : t >= 0}`. Its support function is
//!   `h(u) = h_C(u)` for `u_z >= 0` and `+inf` for `u_z < 0`, so its facets are: the faces of `C` with `n_z > 0` (the
//!   top), the vertical faces of `C` (`n_z = 0`), and one vertical face per *silhouette edge* of `C` (an edge between
//!   a face with `n_z > 0` and one with `n_z < 0`) with the horizontal normal orthogonal to the edge (oriented away
//!   from `C`). Faces with `n_z < 0` disappear. O(E).
//! * **Slice** at `p_z = z` (\[A\] VII-A, the `{px, py}` c-space): the convex polygon `C ∩ {p_z = z}`, from the
//!   crossings of the edges of `C` with the plane and the vertices on it, in counter-clockwise order seen from above.
//!   O(E log E).
//!
//! The decision "horizontal / vertical / downward" uses the angular tolerance of the Gauss-map overlay; rotations about
//! `z` keep `z` components exact, so horizontal and vertical faces of rotated prisms are classified exactly.

use crate::minkowski::{ANGULAR_TOLERANCE, Obstacle};
use glam::{DVec2, DVec3};
use stackplan_geom::polytope::{ConvexPolytope, Plane};
use stackplan_geom::predicates::orient2d;
use stackplan_geom::{HullError, convex_hull};

/// A convex polyhedron in H-form: `p` is inside iff `plane.normal . p <= plane.offset` for every plane.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HalfSpaces {
    /// The planes (unit normals).
    pub planes: Vec<Plane>,
}

impl HalfSpaces {
    /// The largest signed distance of `p` over the planes (negative inside, positive outside).
    pub fn max_violation(&self, p: DVec3) -> f64 {
        self.planes.iter().map(|pl| pl.signed_distance(p)).fold(f64::NEG_INFINITY, f64::max)
    }

    /// Whether `p` is strictly inside by more than `tol` (interference).
    pub fn interior_contains(&self, p: DVec3, tol: f64) -> bool {
        self.max_violation(p) < -tol
    }

    /// Every plane moved outwards by `delta` (the mitred offset).
    pub fn grown(&self, delta: f64) -> Self {
        Self { planes: self.planes.iter().map(|p| Plane { normal: p.normal, offset: p.offset + delta }).collect() }
    }
}

/// The obstacle grown by the clearance `delta` (mm): every face plane offset by `delta`. See the module docs.
pub fn clearance(obstacle: &Obstacle, delta: f64) -> HalfSpaces {
    HalfSpaces { planes: obstacle.planes().copied().collect() }.grown(delta)
}

/// The insertion obstacle `C (+) {-t z : t >= 0}` in H-form. See the module documentation.
pub fn insertion(polytope: &ConvexPolytope) -> HalfSpaces {
    let faces = polytope.faces();
    let mut planes: Vec<Plane> = Vec::with_capacity(faces.len());
    let is_up = |n: DVec3| n.z > ANGULAR_TOLERANCE;
    let is_down = |n: DVec3| n.z < -ANGULAR_TOLERANCE;
    for f in faces {
        if !is_down(f.plane.normal) {
            planes.push(f.plane);
        }
    }
    let verts = polytope.vertices();
    for e in polytope.edges() {
        let (n0, n1) = (faces[e.faces[0]].plane.normal, faces[e.faces[1]].plane.normal);
        if !((is_up(n0) && is_down(n1)) || (is_down(n0) && is_up(n1))) {
            continue;
        }
        let (a, b) = (verts[e.vertices[0]], verts[e.vertices[1]]);
        let h = DVec3::new(b.y - a.y, a.x - b.x, 0.0);
        let len = h.length();
        if len.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            continue; // a vertical edge between an up and a down face cannot exist on a convex polytope
        }
        let mut normal = h / len;
        // outward: the normal must point the same way as the horizontal parts of the two face normals
        if normal.dot(n0 + n1) < 0.0 {
            normal = -normal;
        }
        planes.push(Plane { normal, offset: normal.dot(a).max(normal.dot(b)) });
    }
    HalfSpaces { planes }
}

/// The insertion obstacle truncated at `floor_z` as a polytope (for pictures): the hull of the vertices of `C` and
/// their vertical projections onto `z = floor_z`. `floor_z` should lie below `C`.
pub fn insertion_polytope(polytope: &ConvexPolytope, floor_z: f64) -> Result<ConvexPolytope, HullError> {
    let mut pts: Vec<DVec3> = polytope.vertices().to_vec();
    pts.extend(polytope.vertices().iter().map(|v| DVec3::new(v.x, v.y, floor_z.min(v.z))));
    Ok(convex_hull(&pts)?.polytope)
}

/// The slice `C ∩ {p_z = z}` as a convex polygon, counter-clockwise seen from above (empty if the plane misses `C`;
/// fewer than three points when it only touches a vertex or an edge).
pub fn slice(polytope: &ConvexPolytope, z: f64) -> Vec<DVec2> {
    let verts = polytope.vertices();
    let mut pts: Vec<DVec2> = Vec::new();
    for v in verts {
        if v.z == z {
            pts.push(v.truncate());
        }
    }
    for e in polytope.edges() {
        let (a, b) = (verts[e.vertices[0]], verts[e.vertices[1]]);
        if (a.z < z && b.z > z) || (a.z > z && b.z < z) {
            let t = (z - a.z) / (b.z - a.z);
            pts.push((a + (b - a) * t).truncate());
        }
    }
    convex_polygon(pts)
}

/// Counter-clockwise convex hull of 2-D points (Andrew's monotone chain with the exact orientation predicate), then
/// dropping corners within the policy's length tolerance (relative to the extent) of their neighbours' line.
pub fn convex_polygon(mut pts: Vec<DVec2>) -> Vec<DVec2> {
    // numeric order (-0.0 and 0.0 tie)
    pts.sort_by(|a, b| {
        a.x.partial_cmp(&b.x)
            .unwrap_or(std::cmp::Ordering::Equal)
            .then(a.y.partial_cmp(&b.y).unwrap_or(std::cmp::Ordering::Equal))
    });
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    // length tolerance of the policy on the polygon's extent: closer points are one point, a corner within it of the
    // line through its neighbours is not a corner
    let (lo, hi) = pts.iter().fold((pts[0], pts[0]), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let lin = stackplan_geom::tolerance::RELATIVE * (hi - lo).length();
    let mut unique: Vec<DVec2> = Vec::with_capacity(pts.len());
    for p in pts {
        if !unique.iter().any(|q| (p - *q).length() <= lin) {
            unique.push(p);
        }
    }
    let pts = unique;
    if pts.len() < 3 {
        return pts;
    }
    let left = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o) > lin * (b - o).length();
    // exact orientation inside the chain, tolerance only in the clean-up below
    let exact_left = |o: DVec2, a: DVec2, b: DVec2| orient2d(o, a, b) == std::cmp::Ordering::Greater;
    let mut hull: Vec<DVec2> = Vec::with_capacity(pts.len() + 1);
    for &p in &pts {
        while hull.len() >= 2 && !exact_left(hull[hull.len() - 2], hull[hull.len() - 1], p) {
            hull.pop();
        }
        hull.push(p);
    }
    let lower = hull.len() + 1;
    for &p in pts.iter().rev().skip(1) {
        while hull.len() >= lower && !exact_left(hull[hull.len() - 2], hull[hull.len() - 1], p) {
            hull.pop();
        }
        hull.push(p);
    }
    hull.pop();
    // the chain's first point is never tested: drop it (or any other corner) if it is collinear with its neighbours
    let mut k = 0;
    while hull.len() > 3 && k < hull.len() {
        let n = hull.len();
        if left(hull[(k + n - 1) % n], hull[k], hull[(k + 1) % n]) {
            k += 1;
        } else {
            hull.remove(k);
            k = k.saturating_sub(1);
        }
    }
    hull
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::minkowski::obstacle;
    use glam::DMat3;

    fn cuboid(lo: DVec3, hi: DVec3) -> ConvexPolytope {
        ConvexPolytope::cuboid(lo, hi).expect("box")
    }

    #[test]
    fn box_slice_and_insertion() {
        let a = cuboid(DVec3::ZERO, DVec3::ONE);
        let b = cuboid(DVec3::ZERO, DVec3::new(2.0, 2.0, 1.0));
        let o = obstacle(&a, DMat3::IDENTITY, &b).expect("obstacle");
        let s = slice(o.polytope(), 0.0);
        assert_eq!(s.len(), 4);
        let area: f64 = (0..4).map(|k| s[k].perp_dot(s[(k + 1) % 4])).sum::<f64>() / 2.0;
        assert!((area - 9.0).abs() < 1e-12);
        let ins = insertion(o.polytope());
        // top plane and four sides, no bottom
        assert_eq!(ins.planes.len(), 5);
        assert!(ins.interior_contains(DVec3::new(0.5, 0.5, -100.0), 1e-9));
        assert!(!ins.interior_contains(DVec3::new(0.5, 0.5, 1.5), 1e-9));
        let g = clearance(&o, 0.5);
        assert!(g.interior_contains(DVec3::new(2.3, 0.5, 0.0), 1e-9));
        assert!(!g.interior_contains(DVec3::new(2.6, 0.5, 0.0), 1e-9));
        let t = insertion_polytope(o.polytope(), -10.0).expect("hull");
        assert!((t.volume() - 9.0 * 11.0).abs() < 1e-9);
    }
}
