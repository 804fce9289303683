//! The Euclidean distance of two disjoint convex polytopes given by their vertices, by closest features: accurate to
//! rounding (about `1e-16` times the coordinates' magnitude) at every distance, down to a fraction of the tolerance.
//!
//! Why not GJK: parry3d-f64's GJK ends its iteration on a relative improvement threshold and takes a tiny simplex as
//! an intersection; a few tolerances from touching it answers `0` (Triangle parts 5e-7 mm apart) or a distance above
//! the clearance (1e-5 mm apart at 17.3 degrees), so separated pairs would be reported at gap 0 or not at all.
//!
//! The method: the closest points `x` of `A` and `y` of `B` of two disjoint convex polytopes lie on their boundaries,
//! and the set of closest pairs `(x, y)` is convex; an extreme pair of it has `x` at a vertex of `A` and `y` in a
//! face of `B`, or the other way round, or `x` and `y` on an edge each. So the distance is the least of
//!
//! * **vertex - face**: for a vertex `p` of one polytope and a face `f` of the other whose polygon contains the
//!   projection of `p`, the plane distance `|n . (p - v0)|` (`n` the face's unit normal, accurate for slivers too:
//!   `geom`'s hull computes it in double-double; "contains" is decided exactly, by the side of `p` relative to the
//!   plane through each polygon edge and the normal, `predicates::side`), and
//! * **edge - edge**: the distance of two segments (`segment_distance`): the four endpoint-to-segment distances and,
//!   when the unconstrained closest points of the two lines lie inside both segments, their distance. Every value is
//!   the distance of two actual points of the segments, never below the true one beyond rounding; for nearly
//!   parallel segments (`sin^2` of their angle below `1e-6`), where the closed-form parameters lose accuracy, the
//!   interior minimum is found by a golden-section search on the convex distance along one segment instead.
//!
//! Each candidate is the distance between two subsets of the polytopes, so none is below the distance, and the
//! closest pair of features gives it. The hulls are `geom`'s exact hulls of the vertex sets (so the features are
//! complete whatever the input's order or its near-coplanar points), O(V log V) each; the search is
//! O(V_A F_B k + V_B F_A k + E_A E_B) with `k` the face size, pruned by bounding boxes.

use glam::DVec3;
use stackplan_geom::polytope::ConvexPolytope;
use stackplan_geom::predicates::side;
use std::cmp::Ordering;

/// The Euclidean distance of the convex hulls of `a` and `b`, which must be disjoint (for overlapping hulls the
/// result is a boundary distance, meaningless). `None` when either point set has no 3-D hull (flat, collinear,
/// coincident, empty or non-finite).
pub fn convex_distance(a: &[DVec3], b: &[DVec3]) -> Option<f64> {
    let ha = stackplan_geom::convex_hull(a).ok()?.polytope;
    let hb = stackplan_geom::convex_hull(b).ok()?.polytope;
    Some(polytope_distance(&ha, &hb))
}

/// The Euclidean distance of two disjoint convex polytopes (see the module documentation).
pub fn polytope_distance(a: &ConvexPolytope, b: &ConvexPolytope) -> f64 {
    let mut best = f64::INFINITY;
    vertex_face(a, b, &mut best);
    vertex_face(b, a, &mut best);
    let boxes = |p: &ConvexPolytope| -> Vec<(DVec3, DVec3)> {
        p.edges()
            .iter()
            .map(|e| {
                let (u, v) = (p.vertices()[e.vertices[0]], p.vertices()[e.vertices[1]]);
                (u.min(v), u.max(v))
            })
            .collect()
    };
    let (boxes_a, boxes_b) = (boxes(a), boxes(b));
    for (ea, box_a) in a.edges().iter().zip(&boxes_a) {
        for (eb, box_b) in b.edges().iter().zip(&boxes_b) {
            // the boxes' distance is a lower bound of the segments'
            let gap = (box_b.0 - box_a.1).max(box_a.0 - box_b.1).max(DVec3::ZERO);
            if gap.length() >= best {
                continue;
            }
            let d = segment_distance(
                a.vertices()[ea.vertices[0]],
                a.vertices()[ea.vertices[1]],
                b.vertices()[eb.vertices[0]],
                b.vertices()[eb.vertices[1]],
            );
            best = best.min(d);
        }
    }
    best
}

/// The vertices of `p` against the faces of `q` whose polygons contain their projections: `best` lowered to the
/// least plane distance found.
fn vertex_face(p: &ConvexPolytope, q: &ConvexPolytope, best: &mut f64) {
    let qv = q.vertices();
    for face in q.faces() {
        let n = face.plane.normal;
        let v0 = qv[face.vertices[0]];
        for &x in p.vertices() {
            let h = n.dot(x - v0).abs();
            if h >= *best {
                continue;
            }
            // inside the polygon: on the inner side of the plane through each edge and the normal (the polygon is
            // counter-clockwise seen from outside, so the inner side is to the left of the edge; `side` is exact)
            let k = face.vertices.len();
            let inside = (0..k).all(|i| {
                let (u, w) = (qv[face.vertices[i]], qv[face.vertices[(i + 1) % k]]);
                let up = u + n * (w - u).length();
                side(u, w, up, x) != Ordering::Greater
            });
            if inside {
                *best = h;
            }
        }
    }
}

/// The distance of `x` to the segment `[u, w]` (`u != w`): the closest parameter clamped to `[0, 1]`, then the
/// distance of the two points.
fn point_segment_distance(x: DVec3, u: DVec3, w: DVec3) -> f64 {
    let d = w - u;
    let len2 = d.length_squared();
    let t = if len2 > 0.0 { ((x - u).dot(d) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (x - (u + d * t)).length()
}

/// `sin^2` of the angle between two segments below which the closed-form parameters of their lines' closest points
/// are not trusted (their error grows as `eps / sin^2`) and the interior minimum is searched for instead.
const NEARLY_PARALLEL: f64 = 1e-6;

/// The distance of the segments `[p1, q1]` and `[p2, q2]` (see the module documentation).
pub fn segment_distance(p1: DVec3, q1: DVec3, p2: DVec3, q2: DVec3) -> f64 {
    let ends = point_segment_distance(p1, p2, q2)
        .min(point_segment_distance(q1, p2, q2))
        .min(point_segment_distance(p2, p1, q1))
        .min(point_segment_distance(q2, p1, q1));
    let (d1, d2) = (q1 - p1, q2 - p2);
    let (a, e, b) = (d1.length_squared(), d2.length_squared(), d1.dot(d2));
    if a == 0.0 || e == 0.0 {
        return ends;
    }
    let cross = d1.cross(d2);
    if cross == DVec3::ZERO {
        // exactly parallel: the distance over the overlap is constant, so an endpoint attains it
        return ends;
    }
    let r = p1 - p2;
    let (c, f) = (d1.dot(r), d2.dot(r));
    let denom = a * e - b * b;
    let interior = if denom > NEARLY_PARALLEL * a * e {
        // the closest points of the two lines; only an interior pair adds to the endpoints' distances
        let s = (b * f - c * e) / denom;
        let t = (a * f - b * c) / denom;
        ((0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t)).then(|| ((p1 + d1 * s) - (p2 + d2 * t)).length())
    } else {
        // nearly parallel: `g(s) = dist(p1 + s d1, [p2, q2])` is convex; golden-section search on its values (each
        // accurate to rounding: the sign of its derivative is not, it is a product of two tiny quantities)
        let g = |s: f64| point_segment_distance(p1 + d1 * s, p2, q2);
        let ratio = 0.5 * (5f64.sqrt() - 1.0);
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        let (mut m1, mut m2) = (hi - ratio * (hi - lo), lo + ratio * (hi - lo));
        let (mut g1, mut g2) = (g(m1), g(m2));
        for _ in 0..80 {
            if g1 <= g2 {
                hi = m2;
                (m2, g2) = (m1, g1);
                m1 = hi - ratio * (hi - lo);
                g1 = g(m1);
            } else {
                lo = m1;
                (m1, g1) = (m2, g2);
                m2 = lo + ratio * (hi - lo);
                g2 = g(m2);
            }
        }
        Some(g1.min(g2))
    };
    interior.map_or(ends, |d| d.min(ends))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_crossing_at_a_tiny_angle_and_height() {
        // two horizontal segments 1e-6 apart in z, crossing in projection at their middles at 1e-7 rad: the
        // endpoints are about 5e-6 from the other segment, the interior pair is 1e-6
        let theta: f64 = 1e-7;
        let (p1, q1) = (DVec3::new(-50.0, 0.0, 0.0), DVec3::new(50.0, 0.0, 0.0));
        let dir = DVec3::new(theta.cos(), theta.sin(), 0.0) * 50.0;
        let (p2, q2) = (DVec3::new(0.0, 0.0, 1e-6) - dir, DVec3::new(0.0, 0.0, 1e-6) + dir);
        let d = segment_distance(p1, q1, p2, q2);
        assert!((d - 1e-6).abs() < 1e-15, "{d}");
        // and at a generic angle
        let dir = DVec3::new(0.6, 0.8, 0.0) * 50.0;
        let d = segment_distance(p1, q1, DVec3::new(0.0, 0.0, 1e-6) - dir, DVec3::new(0.0, 0.0, 1e-6) + dir);
        assert!((d - 1e-6).abs() < 1e-15, "{d}");
    }

    #[test]
    fn parallel_and_skew_segments_beyond_their_ends() {
        // parallel, overlapping: the constant distance
        let d = segment_distance(DVec3::ZERO, DVec3::X * 4.0, DVec3::new(1.0, 3.0, 0.0), DVec3::new(9.0, 3.0, 0.0));
        assert_eq!(d, 3.0);
        // collinear with a gap of 2
        let d = segment_distance(DVec3::ZERO, DVec3::X, DVec3::X * 3.0, DVec3::X * 5.0);
        assert_eq!(d, 2.0);
        // the lines cross at (0, 0, 0) and (0, 0, 1), outside the second segment: an endpoint is closest
        let d = segment_distance(-DVec3::X, DVec3::X, DVec3::new(0.0, 2.0, 1.0), DVec3::new(0.0, 5.0, 1.0));
        assert!((d - 5f64.sqrt()).abs() < 1e-15, "{d}");
    }

    #[test]
    fn boxes_apart_by_a_face_an_edge_and_a_corner() {
        let unit = ConvexPolytope::cuboid(DVec3::ZERO, DVec3::ONE).expect("box");
        let moved = |p: DVec3| unit.transformed(glam::DMat3::IDENTITY, p);
        let cases = [
            (DVec3::new(1.0 + 5e-7, 0.25, 0.5), 5e-7),
            (DVec3::new(1.0 + 3e-7, 1.0 + 4e-7, 0.5), 5e-7),
            (DVec3::new(1.0 + 2e-7, 1.0 + 3e-7, 1.0 + 6e-7), 7e-7),
            (DVec3::new(4.0, 5.0, 0.0), 5.0),
        ];
        for (p, expected) in cases {
            let d = polytope_distance(&unit, &moved(p));
            assert!((d - expected).abs() < 1e-15, "{p}: {d} vs {expected}");
            let d = polytope_distance(&moved(p), &unit);
            assert!((d - expected).abs() < 1e-15, "{p}: {d} vs {expected}");
        }
        // the vertex-only entry point builds the same hulls
        let d = convex_distance(unit.vertices(), moved(DVec3::new(1.0 + 5e-7, 0.25, 0.5)).vertices());
        assert!(d.is_some_and(|d| (d - 5e-7).abs() < 1e-15), "{d:?}");
        // no solid hull, no distance
        assert_eq!(convex_distance(&[DVec3::ZERO, DVec3::X, DVec3::Y], unit.vertices()), None);
    }
}
