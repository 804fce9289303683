//! Planar polygon utilities for the sheet-metal model: plane fit, exact projection to 2-D, orientation, simplicity
//! and hole-containment checks.
//!
//! # Projection without rounding
//! A planar face is projected to 2-D by *dropping* the coordinate along which its normal is largest (the classic
//! trick of point-in-polygon tests, e.g. J. O'Rourke, *Computational Geometry in C*, 2nd ed., 1998, sec. 7.5). The
//! two kept coordinates are copied bit for bit, so every 2-D decision (orientation, intersection, containment) is
//! made by the exact [`crate::predicates::orient2d`] on the *input* numbers: no rounding happens between the file and
//! the combinatorial decisions. The projection is an affine bijection between the face plane and the 2-D plane, so
//! convexity, simplicity and containment carry over unchanged. The kept coordinates are taken in cyclic order
//! (`x` dropped: `(y, z)`; `y` dropped: `(z, x)`; `z` dropped: `(x, y)`), so a 2-D counter-clockwise turn is a
//! counter-clockwise turn about the positive dropped axis.
//!
//! Going back to 3-D ([`FacePlane::lift`]) keeps the two coordinates and solves the plane equation for the dropped
//! one. Lifted points lie on the fitted plane up to rounding, and their projections are exactly the input's, so the
//! 2-D decisions remain true of the lifted polygon.
//!
//! # Planarity tolerance
//! Points come from user files (rounded decimal output of CAD systems), so exact coplanarity cannot be required. A
//! face is accepted as planar when every vertex (outline and holes) lies within
//! `PLANARITY_FACTOR * Tolerance::for_points(face).linear = 1e-6 * (face bounding-box diagonal, at least 1 mm)` of
//! the fitted plane. The factor 1000 over the kernel's policy tolerance (`1e-9 * scale`) admits coordinates printed
//! with about seven significant digits, while a genuinely bent face (a bend of 0.001 rad over the face already
//! deviates by `1e-3 * size`) is rejected.
//!
//! # Complexity
//! Plane fit O(n); [`check_rings`] (simplicity of every ring, holes strictly inside and pairwise disjoint) sorts
//! the edges by their smallest x and tests only pairs whose x-ranges overlap: O(n log n + k) for k such pairs,
//! O(n^2) in the worst case.

use crate::polytope::newell_normal;
use crate::predicates::orient2d;
use crate::tolerance::Tolerance;
use glam::{DVec2, DVec3};
use std::cmp::Ordering;

/// Planarity tolerance as a multiple of the kernel's policy tolerance, see the module documentation.
pub const PLANARITY_FACTOR: f64 = 1000.0;

/// The supporting plane of a face and the axis dropped for its exact 2-D projection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FacePlane {
    /// Unit normal (the Newell normal of the outline; its sign follows the outline's orientation).
    pub normal: DVec3,
    /// `normal . x = offset` on the plane (mean over the fitted points).
    pub offset: f64,
    /// The dropped coordinate axis (0 = x, 1 = y, 2 = z): the one with the largest `|normal|` component.
    pub drop_axis: usize,
}

impl FacePlane {
    /// Fits a plane to a polygon outline: Newell normal, offset = mean of `normal . p` over the outline (so a
    /// lifted hole is reported as off the plane rather than dragging the plane away from the outline).
    ///
    /// Returns `None` when the outline has zero vector area (collinear or cancelling), or the normal is not finite.
    pub fn fit(outline: &[DVec3]) -> Option<Self> {
        let n = newell_normal(outline.iter().copied());
        let len = n.length();
        if !(len > 0.0 && len.is_finite()) || outline.is_empty() {
            return None;
        }
        let normal = n / len;
        let offset = outline.iter().map(|p| normal.dot(*p)).sum::<f64>() / outline.len() as f64;
        let a = normal.abs();
        let drop_axis = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        Some(Self { normal, offset, drop_axis })
    }

    /// Signed distance of `p` from the plane.
    #[inline]
    pub fn distance(&self, p: DVec3) -> f64 {
        self.normal.dot(p) - self.offset
    }

    /// The exact 2-D projection (two coordinates copied, in cyclic order after the dropped axis).
    #[inline]
    pub fn project(&self, p: DVec3) -> DVec2 {
        match self.drop_axis {
            0 => DVec2::new(p.y, p.z),
            1 => DVec2::new(p.z, p.x),
            _ => DVec2::new(p.x, p.y),
        }
    }

    /// The point of the plane whose projection is `q` (the dropped coordinate solved from the plane equation).
    #[inline]
    pub fn lift(&self, q: DVec2) -> DVec3 {
        let n = self.normal;
        match self.drop_axis {
            0 => DVec3::new((self.offset - n.y * q.x - n.z * q.y) / n.x, q.x, q.y),
            1 => DVec3::new(q.y, (self.offset - n.z * q.x - n.x * q.y) / n.y, q.x),
            _ => DVec3::new(q.x, q.y, (self.offset - n.x * q.x - n.y * q.y) / n.z),
        }
    }

    /// Whether a counter-clockwise 2-D polygon is counter-clockwise about [`Self::normal`] in 3-D.
    #[inline]
    pub fn projection_keeps_orientation(&self) -> bool {
        self.normal[self.drop_axis] > 0.0
    }

    /// The planarity tolerance for a face with these points (see the module documentation).
    pub fn planarity_tolerance(points: &[DVec3]) -> f64 {
        PLANARITY_FACTOR * Tolerance::for_points(points).linear
    }
}

/// Twice the signed area of a 2-D polygon (shoelace formula; positive when counter-clockwise). Rounded, for
/// reports and tests; orientation decisions use [`ring_orientation`].
pub fn signed_area2(points: &[DVec2]) -> f64 {
    let n = points.len();
    let mut s = 0.0;
    for i in 0..n {
        let a = points[i];
        let b = points[(i + 1) % n];
        s += a.x * b.y - a.y * b.x;
    }
    s
}

/// Exact orientation of a *simple* ring: the turn at its lexicographically smallest vertex (a convex vertex of any
/// simple polygon). `Equal` only when all points are collinear.
pub fn ring_orientation(points: &[DVec2]) -> Ordering {
    let n = points.len();
    if n < 3 {
        return Ordering::Equal;
    }
    let lowest = (0..n).min_by(|&i, &j| lex(points[i], points[j])).unwrap_or(0);
    // skip neighbours that coincide with the lowest point (not expected after de-duplication)
    let prev = points[(lowest + n - 1) % n];
    let next = points[(lowest + 1) % n];
    let o = orient2d(prev, points[lowest], next);
    if o != Ordering::Equal {
        return o;
    }
    // the lowest vertex is straight (collinear neighbours): fall back on the signed area's sign, which for a simple
    // polygon with this vertex straight is decided by any strictly convex vertex; search one.
    for i in 0..n {
        let o = orient2d(points[(i + n - 1) % n], points[i], points[(i + 1) % n]);
        if o != Ordering::Equal && is_convex_hull_vertex(points, i) {
            return o;
        }
    }
    Ordering::Equal
}

/// Whether vertex `i` is a vertex of the convex hull of `points` (lexicographic extreme along some axis suffices
/// for the four extremes we test).
fn is_convex_hull_vertex(points: &[DVec2], i: usize) -> bool {
    let p = points[i];
    let by = |key: fn(DVec2) -> (f64, f64)| {
        points.iter().all(|q| key(*q).partial_cmp(&key(p)).is_some_and(|o| o != Ordering::Greater))
    };
    by(|q| (q.x, q.y)) || by(|q| (-q.x, -q.y)) || by(|q| (q.y, -q.x)) || by(|q| (-q.y, q.x))
}

/// Lexicographic order (x, then y).
#[inline]
pub fn lex(a: DVec2, b: DVec2) -> Ordering {
    a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y))
}

/// Whether a simple ring given counter-clockwise is (weakly) convex: no clockwise turn (straight vertices allowed).
pub fn is_convex_ccw(points: &[DVec2]) -> bool {
    let n = points.len();
    (0..n).all(|i| orient2d(points[(i + n - 1) % n], points[i], points[(i + 1) % n]) != Ordering::Less)
}

/// Whether the turn `u -> v -> w` is *nearly straight* under the length `flat`: `w` lies within `flat` of the line
/// through `u` and `v`, or `u` within `flat` of the line through `v` and `w` (these are the distances that
/// [`crate::polytope::ConvexPolytope::validate`] tests across the side edge at `v` of an extruded prism). Also true
/// for an edge shorter than `flat`. Rounded arithmetic: a tolerance decision, not an exact one.
pub fn nearly_straight(u: DVec2, v: DVec2, w: DVec2, flat: f64) -> bool {
    let distance = |p: DVec2, a: DVec2, b: DVec2| {
        let dir = b - a;
        let len = dir.length();
        if len > 0.0 { dir.perp_dot(p - a).abs() / len } else { (p - a).length() }
    };
    distance(w, u, v) <= flat || distance(u, v, w) <= flat
}

/// Removes nearly straight vertices ([`nearly_straight`] with `flat`) from a ring, repeatedly, keeping the input
/// index of every kept point. Exactly straight vertices (collinear runs) are always removed. O(n^2) worst case.
pub fn simplify_ring(ring: &[(usize, DVec2)], flat: f64) -> Vec<(usize, DVec2)> {
    let mut out = ring.to_vec();
    let mut k = 0;
    let mut unchanged = 0;
    while out.len() >= 3 && unchanged < out.len() {
        let n = out.len();
        let i = k % n;
        let (u, v, w) = (out[(i + n - 1) % n].1, out[i].1, out[(i + 1) % n].1);
        if orient2d(u, v, w) == Ordering::Equal || nearly_straight(u, v, w, flat) {
            out.remove(i);
            unchanged = 0;
            k = i + n - 2; // revisit the previous vertex
        } else {
            unchanged += 1;
            k = i + 1;
        }
    }
    out
}

/// Drops straight vertices (exactly collinear with their neighbours) from a cycle of indices, repeatedly.
pub fn drop_collinear(cycle: &[usize], points: &[DVec2]) -> Vec<usize> {
    let mut out: Vec<usize> = cycle.to_vec();
    loop {
        let n = out.len();
        if n < 3 {
            return out;
        }
        let straight = (0..n).find(|&i| {
            orient2d(points[out[(i + n - 1) % n]], points[out[i]], points[out[(i + 1) % n]]) == Ordering::Equal
        });
        match straight {
            Some(i) => {
                out.remove(i);
            }
            None => return out,
        }
    }
}

/// Where a point is relative to a ring.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointInRing {
    /// Strictly inside.
    Inside,
    /// On an edge or vertex.
    Boundary,
    /// Strictly outside.
    Outside,
}

/// Exact point-in-ring test (crossing number along +x with exact orientation; boundary detected exactly). O(n).
pub fn point_in_ring(p: DVec2, ring: &[DVec2]) -> PointInRing {
    let n = ring.len();
    let mut inside = false;
    for i in 0..n {
        let a = ring[i];
        let b = ring[(i + 1) % n];
        let o = orient2d(a, b, p);
        if o == Ordering::Equal && on_closed_segment_collinear(a, b, p) {
            return PointInRing::Boundary;
        }
        let a_above = a.y > p.y;
        let b_above = b.y > p.y;
        if a_above != b_above {
            // upward edge (b above): crossing to the right iff p is left of a->b
            let crosses = if b_above { o == Ordering::Greater } else { o == Ordering::Less };
            if crosses {
                inside = !inside;
            }
        }
    }
    if inside { PointInRing::Inside } else { PointInRing::Outside }
}

/// For `p` collinear with `a, b`: whether `p` lies on the closed segment `ab`.
#[inline]
fn on_closed_segment_collinear(a: DVec2, b: DVec2, p: DVec2) -> bool {
    p.x >= a.x.min(b.x) && p.x <= a.x.max(b.x) && p.y >= a.y.min(b.y) && p.y <= a.y.max(b.y)
}

/// Whether the closed segments `ab` and `cd` share at least one point (exact).
pub fn segments_intersect(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let o1 = orient2d(a, b, c);
    let o2 = orient2d(a, b, d);
    let o3 = orient2d(c, d, a);
    let o4 = orient2d(c, d, b);
    let zero = Ordering::Equal;
    if o1 != zero && o2 != zero && o3 != zero && o4 != zero {
        return o1 != o2 && o3 != o4;
    }
    // Some endpoint lies on the other segment's line: the segments meet iff such an endpoint lies on the other
    // segment (if `c` is on line ab but outside segment ab, the lines meet only at `c`, or coincide).
    (o1 == zero && on_closed_segment_collinear(a, b, c))
        || (o2 == zero && on_closed_segment_collinear(a, b, d))
        || (o3 == zero && on_closed_segment_collinear(c, d, a))
        || (o4 == zero && on_closed_segment_collinear(c, d, b))
}

/// A ring-level defect found by [`check_rings`]. Ring 0 is the outline, ring `k + 1` is hole `k`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RingDefect {
    /// Two edges of one ring intersect (edge `i` joins vertex `i` and `i + 1`); adjacent edges only when they
    /// overlap (a spike).
    SelfIntersection {
        /// Ring index.
        ring: usize,
        /// First edge.
        edge_a: usize,
        /// Second edge.
        edge_b: usize,
    },
    /// A hole is not strictly inside the outline (touches it, crosses it or lies outside).
    HoleNotInside {
        /// Ring index of the hole (>= 1).
        ring: usize,
    },
    /// Two holes touch, cross or nest.
    HolesOverlap {
        /// Ring index of the first hole.
        ring_a: usize,
        /// Ring index of the second hole.
        ring_b: usize,
    },
}

/// Checks that every ring is simple, every hole lies strictly inside the outline and the holes are pairwise
/// disjoint (no shared point at all). Rings must have at least three vertices without consecutive duplicates.
/// Returns the first defect found.
pub fn check_rings(rings: &[Vec<DVec2>]) -> Result<(), RingDefect> {
    #[derive(Clone, Copy)]
    struct E {
        ring: usize,
        edge: usize,
        a: DVec2,
        b: DVec2,
        lo: f64,
        hi: f64,
    }
    let mut edges: Vec<E> = Vec::new();
    for (r, ring) in rings.iter().enumerate() {
        let n = ring.len();
        for i in 0..n {
            let a = ring[i];
            let b = ring[(i + 1) % n];
            edges.push(E { ring: r, edge: i, a, b, lo: a.x.min(b.x), hi: a.x.max(b.x) });
        }
    }
    edges.sort_by(|p, q| p.lo.total_cmp(&q.lo));
    for i in 0..edges.len() {
        let e = edges[i];
        for f in &edges[i + 1..] {
            if f.lo > e.hi {
                break;
            }
            let (e1, f1) = if (e.ring, e.edge) <= (f.ring, f.edge) { (e, *f) } else { (*f, e) };
            if e1.ring == f1.ring {
                let n = rings[e1.ring].len();
                let adjacent_fwd = (e1.edge + 1) % n == f1.edge;
                let adjacent_bwd = (f1.edge + 1) % n == e1.edge;
                if adjacent_fwd || adjacent_bwd {
                    // share exactly one vertex; defect only if they overlap along a segment (a spike), or for a
                    // triangle-like ring of two edges (n == 2 excluded by the caller)
                    let (shared, p, q) = if adjacent_fwd { (e1.b, e1.a, f1.b) } else { (e1.a, e1.b, f1.a) };
                    if spike(p, shared, q) || (adjacent_fwd && adjacent_bwd && n <= 2) {
                        return Err(RingDefect::SelfIntersection { ring: e1.ring, edge_a: e1.edge, edge_b: f1.edge });
                    }
                    continue;
                }
                if segments_intersect(e1.a, e1.b, f1.a, f1.b) {
                    return Err(RingDefect::SelfIntersection { ring: e1.ring, edge_a: e1.edge, edge_b: f1.edge });
                }
            } else if segments_intersect(e1.a, e1.b, f1.a, f1.b) {
                return Err(if e1.ring == 0 {
                    RingDefect::HoleNotInside { ring: f1.ring }
                } else {
                    RingDefect::HolesOverlap { ring_a: e1.ring, ring_b: f1.ring }
                });
            }
        }
    }
    // No two rings share a point, so each ring lies entirely inside or outside each other ring: test one vertex.
    for h in 1..rings.len() {
        if point_in_ring(rings[h][0], &rings[0]) != PointInRing::Inside {
            return Err(RingDefect::HoleNotInside { ring: h });
        }
        for g in 1..rings.len() {
            if g != h && point_in_ring(rings[h][0], &rings[g]) != PointInRing::Outside {
                return Err(RingDefect::HolesOverlap { ring_a: g.min(h), ring_b: g.max(h) });
            }
        }
    }
    Ok(())
}

/// Whether the two edges `p -> shared -> q` fold back on each other (overlap along a segment).
#[inline]
fn spike(p: DVec2, shared: DVec2, q: DVec2) -> bool {
    orient2d(p, shared, q) == Ordering::Equal && (p - shared).dot(q - shared) > 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    fn square() -> Vec<DVec2> {
        vec![v(0.0, 0.0), v(4.0, 0.0), v(4.0, 4.0), v(0.0, 4.0)]
    }

    #[test]
    fn projection_is_exact_and_lift_inverts_it() {
        let n = DVec3::new(0.3, -0.2, 0.9).normalize();
        for (axis_normal, axis) in [(n, 2), (DVec3::new(n.z, n.x, n.y), 0), (DVec3::new(n.y, n.z, n.x), 1)] {
            let plane = FacePlane { normal: axis_normal, offset: 2.5, drop_axis: axis };
            let q = v(1.25, -3.5);
            let p = plane.lift(q);
            assert_eq!(plane.project(p), q);
            assert!(plane.distance(p).abs() < 1e-12);
        }
    }

    #[test]
    fn fit_picks_dominant_axis_and_orientation() {
        let pts: Vec<DVec3> = square().iter().map(|p| DVec3::new(p.x, 7.0, p.y)).collect();
        // (x, z) in order (0,0),(4,0),(4,4),(0,4): counter-clockwise about -y, i.e. normal -y
        let plane = FacePlane::fit(&pts).expect("plane");
        assert_eq!(plane.drop_axis, 1);
        assert!((plane.normal - DVec3::new(0.0, -1.0, 0.0)).length() < 1e-15);
        assert!((plane.offset + 7.0).abs() < 1e-15);
        let proj: Vec<DVec2> = pts.iter().map(|p| plane.project(*p)).collect();
        let ccw = ring_orientation(&proj) == Ordering::Greater;
        assert_eq!(ccw, plane.projection_keeps_orientation());
        let collinear = vec![DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
        assert!(FacePlane::fit(&collinear).is_none());
    }

    #[test]
    fn orientation_and_area() {
        let s = square();
        assert_eq!(ring_orientation(&s), Ordering::Greater);
        let mut r = s.clone();
        r.reverse();
        assert_eq!(ring_orientation(&r), Ordering::Less);
        assert_eq!(signed_area2(&s), 32.0);
        // lowest vertex straight: (0,0) between (0,2) and (2,0)? make the lowest vertex lie on a straight run
        let straight = vec![v(0.0, 0.0), v(2.0, 0.0), v(4.0, 0.0), v(4.0, 4.0), v(0.0, 4.0), v(0.0, 2.0)];
        assert_eq!(ring_orientation(&straight), Ordering::Greater);
        assert!(is_convex_ccw(&straight));
        let idx: Vec<usize> = (0..straight.len()).collect();
        assert_eq!(drop_collinear(&idx, &straight), vec![0, 2, 3, 4]);
        let l = vec![v(0.0, 0.0), v(4.0, 0.0), v(4.0, 2.0), v(2.0, 2.0), v(2.0, 4.0), v(0.0, 4.0)];
        assert!(!is_convex_ccw(&l));
    }

    #[test]
    fn point_in_ring_cases() {
        let s = square();
        assert_eq!(point_in_ring(v(1.0, 1.0), &s), PointInRing::Inside);
        assert_eq!(point_in_ring(v(4.0, 1.0), &s), PointInRing::Boundary);
        assert_eq!(point_in_ring(v(0.0, 0.0), &s), PointInRing::Boundary);
        assert_eq!(point_in_ring(v(5.0, 0.0), &s), PointInRing::Outside);
        assert_eq!(point_in_ring(v(-1.0, 4.0), &s), PointInRing::Outside);
        // ray through a vertex
        let diamond = vec![v(0.0, -1.0), v(1.0, 0.0), v(0.0, 1.0), v(-1.0, 0.0)];
        assert_eq!(point_in_ring(v(-0.5, 0.0), &diamond), PointInRing::Inside);
        assert_eq!(point_in_ring(v(-2.0, 0.0), &diamond), PointInRing::Outside);
    }

    #[test]
    fn segment_intersection_cases() {
        assert!(segments_intersect(v(0.0, 0.0), v(2.0, 2.0), v(0.0, 2.0), v(2.0, 0.0)));
        assert!(segments_intersect(v(0.0, 0.0), v(2.0, 0.0), v(1.0, 0.0), v(1.0, 5.0))); // T
        assert!(segments_intersect(v(0.0, 0.0), v(2.0, 0.0), v(1.0, 0.0), v(3.0, 0.0))); // overlap
        assert!(!segments_intersect(v(0.0, 0.0), v(2.0, 0.0), v(3.0, 0.0), v(4.0, 0.0))); // collinear apart
        assert!(!segments_intersect(v(0.0, 0.0), v(2.0, 0.0), v(0.0, 1.0), v(2.0, 1.0))); // parallel
        assert!(!segments_intersect(v(0.0, 0.0), v(2.0, 2.0), v(3.0, 0.0), v(2.0, 1.5)));
    }

    #[test]
    fn ring_checks() {
        let s = square();
        let hole = vec![v(1.0, 1.0), v(1.0, 2.0), v(2.0, 2.0), v(2.0, 1.0)];
        assert_eq!(check_rings(&[s.clone(), hole.clone()]), Ok(()));
        let bowtie = vec![v(0.0, 0.0), v(2.0, 2.0), v(2.0, 0.0), v(0.0, 2.0)];
        assert!(matches!(check_rings(&[bowtie]), Err(RingDefect::SelfIntersection { ring: 0, .. })));
        let spiky = vec![v(0.0, 0.0), v(4.0, 0.0), v(2.0, 0.0), v(2.0, 3.0)];
        assert!(matches!(check_rings(&[spiky]), Err(RingDefect::SelfIntersection { ring: 0, .. })));
        let touching = vec![v(0.0, 1.0), v(0.0, 2.0), v(1.0, 2.0), v(1.0, 1.0)];
        assert_eq!(check_rings(&[s.clone(), touching]), Err(RingDefect::HoleNotInside { ring: 1 }));
        let outside = vec![v(5.0, 1.0), v(5.0, 2.0), v(6.0, 2.0), v(6.0, 1.0)];
        assert_eq!(check_rings(&[s.clone(), outside]), Err(RingDefect::HoleNotInside { ring: 1 }));
        let inner = vec![v(1.25, 1.25), v(1.25, 1.5), v(1.5, 1.5), v(1.5, 1.25)];
        assert_eq!(
            check_rings(&[s.clone(), hole.clone(), inner]),
            Err(RingDefect::HolesOverlap { ring_a: 1, ring_b: 2 })
        );
        let sharing_vertex = vec![v(2.0, 2.0), v(2.0, 3.0), v(3.0, 3.0)];
        assert_eq!(check_rings(&[s, hole, sharing_vertex]), Err(RingDefect::HolesOverlap { ring_a: 1, ring_b: 2 }));
        // a ring touching itself at a vertex (figure eight through one point)
        let eight = vec![v(0.0, 0.0), v(2.0, 0.0), v(1.0, 1.0), v(2.0, 2.0), v(0.0, 2.0), v(1.0, 1.0)];
        assert!(matches!(check_rings(&[eight]), Err(RingDefect::SelfIntersection { ring: 0, .. })));
    }
}
