//! Small planar routines: convex hull of points, intersection of (possibly degenerate) convex sets, distances.
//!
//! Contact patches are intersections of two convex supporting sets projected onto the contact plane; each set is a
//! point, a segment or a convex polygon. [`convex_hull_2d`] is Andrew's monotone chain (A. M. Andrew, *Another
//! efficient algorithm for convex hulls in two dimensions*, IPL 9(5), 1979), O(n log n); [`intersect_convex`] clips
//! with Sutherland-Hodgman (I. Sutherland, G. Hodgman, *Reentrant polygon clipping*, CACM 17(1), 1974), O(n m), with
//! explicit cases for points and segments. All decisions use an explicit length tolerance `tol` (the tolerance policy
//! of `stackplan_geom::tolerance`), because the inputs are computed (rotated) coordinates.

use glam::DVec2;

/// `(b - a) x (c - a)`: twice the signed area of the triangle, positive when counter-clockwise.
#[inline]
pub fn cross(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

/// Convex hull of `points` counter-clockwise, without collinear points (within `tol` of a hull edge).
///
/// Returns one point when all points coincide (within `tol`), two when they are collinear, otherwise a polygon.
/// Empty input gives an empty output.
pub fn convex_hull_2d(points: &[DVec2], tol: f64) -> Vec<DVec2> {
    let mut pts: Vec<DVec2> = points.iter().copied().filter(|p| p.is_finite()).collect();
    if pts.is_empty() {
        return pts;
    }
    pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    // drop points within tol of a point kept before (duplicates of computed coordinates); the points are sorted by x,
    // so only the kept points with x >= p.x - tol can be that close (the same points as comparing with all of them,
    // in O(n k) for k points in a strip of width tol instead of O(n^2))
    let mut unique: Vec<DVec2> = Vec::with_capacity(pts.len());
    for p in pts {
        let near = unique.iter().rev().take_while(|q| q.x >= p.x - tol).any(|q: &DVec2| (*q - p).length() <= tol);
        if !near {
            unique.push(p);
        }
    }
    if unique.len() <= 2 {
        return unique;
    }
    // a turn counts only when the third point is more than tol away from the line of the first two
    let left = |a: DVec2, b: DVec2, c: DVec2| {
        let len = (b - a).length();
        len > 0.0 && cross(a, b, c) > tol * len
    };
    let mut lower: Vec<DVec2> = Vec::new();
    for &p in &unique {
        while lower.len() >= 2 && !left(lower[lower.len() - 2], lower[lower.len() - 1], p) {
            lower.pop();
        }
        lower.push(p);
    }
    let mut upper: Vec<DVec2> = Vec::new();
    for &p in unique.iter().rev() {
        while upper.len() >= 2 && !left(upper[upper.len() - 2], upper[upper.len() - 1], p) {
            upper.pop();
        }
        upper.push(p);
    }
    lower.pop();
    upper.pop();
    lower.extend(upper);
    if lower.len() == 2 && (lower[0] - lower[1]).length() <= tol {
        lower.truncate(1);
    }
    if lower.len() < 3 {
        // collinear input: the hull is the segment between the two extreme points
        let (mut a, mut b) = (unique[0], unique[unique.len() - 1]);
        let mut best = (a - b).length_squared();
        for &p in &unique {
            for &q in &unique {
                let d = (p - q).length_squared();
                if d > best {
                    best = d;
                    a = p;
                    b = q;
                }
            }
        }
        return if (a - b).length() <= tol { vec![a] } else { vec![a, b] };
    }
    lower
}

/// Distance from `p` to the segment `[a, b]`.
pub fn point_segment_distance(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    if len2 == 0.0 {
        return (p - a).length();
    }
    let t = ((p - a).dot(ab) / len2).clamp(0.0, 1.0);
    (p - (a + ab * t)).length()
}

/// Signed distance from `p` to the boundary of the convex counter-clockwise polygon `poly` (at least 3 vertices):
/// positive inside (the distance to the nearest edge line, exact for a convex polygon), negative outside (minus the
/// distance to the polygon).
pub fn signed_boundary_distance(p: DVec2, poly: &[DVec2]) -> f64 {
    let n = poly.len();
    let mut inside = f64::INFINITY;
    let mut outside = false;
    for k in 0..n {
        let a = poly[k];
        let b = poly[(k + 1) % n];
        let len = (b - a).length();
        if len == 0.0 {
            continue;
        }
        let d = cross(a, b, p) / len;
        if d < 0.0 {
            outside = true;
        }
        inside = inside.min(d);
    }
    if !outside {
        return inside;
    }
    let mut dist = f64::INFINITY;
    for k in 0..n {
        dist = dist.min(point_segment_distance(p, poly[k], poly[(k + 1) % n]));
    }
    -dist
}

/// Whether `p` lies inside the convex counter-clockwise polygon `poly` by more than `margin`: the same answer as
/// `signed_boundary_distance(p, poly) > margin` for `margin >= 0`, without the distances to the edges of an outside
/// point (it stops at the first edge line that `p` is not beyond by more than `margin`). O(n).
pub fn inside_by(p: DVec2, poly: &[DVec2], margin: f64) -> bool {
    let n = poly.len();
    (0..n).all(|k| {
        let (a, b) = (poly[k], poly[(k + 1) % n]);
        let len = (b - a).length();
        len == 0.0 || cross(a, b, p) / len > margin
    })
}

/// Whether `p` lies in the closed convex polygon `poly` (counter-clockwise, >= 3 vertices) enlarged by `tol`.
///
/// The same answer as `signed_boundary_distance(p, poly) >= -tol` with an early exit: a point beyond an edge line by
/// more than `tol` is farther than `tol` from the polygon, and one behind every edge line is inside; only a point
/// outside within `tol` of an edge line needs the distances to the edges. O(n).
pub fn contains(poly: &[DVec2], p: DVec2, tol: f64) -> bool {
    let n = poly.len();
    let mut inside = true;
    for k in 0..n {
        let (a, b) = (poly[k], poly[(k + 1) % n]);
        let len = (b - a).length();
        if len == 0.0 {
            continue;
        }
        let d = cross(a, b, p) / len;
        if d < -tol {
            return false;
        }
        inside &= d >= 0.0;
    }
    inside || signed_boundary_distance(p, poly) >= -tol
}

/// Clips the convex set `subject` (a point, segment or polygon) by the half-plane left of `a -> b` (enlarged by tol).
fn clip_half_plane(subject: &[DVec2], a: DVec2, b: DVec2, tol: f64) -> Vec<DVec2> {
    let len = (b - a).length();
    if len == 0.0 {
        return subject.to_vec();
    }
    let side = |p: DVec2| cross(a, b, p) / len + tol;
    let n = subject.len();
    if n == 1 {
        return if side(subject[0]) >= 0.0 { subject.to_vec() } else { Vec::new() };
    }
    let mut out = Vec::with_capacity(n + 2);
    let closed = n >= 3;
    let count = if closed { n } else { n - 1 };
    for k in 0..count {
        let p = subject[k];
        let q = subject[(k + 1) % n];
        let (sp, sq) = (side(p), side(q));
        if sp >= 0.0 {
            out.push(p);
        }
        if (sp >= 0.0) != (sq >= 0.0) {
            let t = sp / (sp - sq);
            out.push(p + (q - p) * t);
        }
        if !closed && k == count - 1 && sq >= 0.0 {
            out.push(q);
        }
    }
    out
}

/// Intersection of two convex sets given as hulls from [`convex_hull_2d`] (1 point, 2 points = segment, or a
/// counter-clockwise polygon). The result is again such a hull; empty when they do not meet within `tol`.
pub fn intersect_convex(a: &[DVec2], b: &[DVec2], tol: f64) -> Vec<DVec2> {
    if a.is_empty() || b.is_empty() {
        return Vec::new();
    }
    // make `b` the polygon when exactly one of them is
    if a.len() >= 3 && b.len() < 3 {
        return intersect_convex(b, a, tol);
    }
    if b.len() >= 3 {
        // exact clipping first (no enlargement); only when that loses the set (touching along an edge or at a
        // vertex, where rounding decides) clip again with the half-planes enlarged by tol
        for t in [0.0, tol] {
            let mut subject = a.to_vec();
            let n = b.len();
            for k in 0..n {
                subject = clip_half_plane(&subject, b[k], b[(k + 1) % n], t);
                if subject.is_empty() {
                    break;
                }
            }
            // the enlarged clip can leave slivers of width ~tol: collapse them with a coarser hull tolerance
            let hull = convex_hull_2d(&subject, if t > 0.0 { 4.0 * tol } else { tol });
            if !hull.is_empty() {
                return hull;
            }
        }
        return Vec::new();
    }
    // both are points or segments
    match (a.len(), b.len()) {
        (1, 1) => {
            if (a[0] - b[0]).length() <= tol {
                vec![(a[0] + b[0]) * 0.5]
            } else {
                Vec::new()
            }
        }
        (1, _) => {
            if point_segment_distance(a[0], b[0], b[1]) <= tol {
                vec![a[0]]
            } else {
                Vec::new()
            }
        }
        (_, 1) => intersect_convex(b, a, tol),
        _ => segment_segment(a[0], a[1], b[0], b[1], tol),
    }
}

fn segment_segment(p0: DVec2, p1: DVec2, q0: DVec2, q1: DVec2, tol: f64) -> Vec<DVec2> {
    let d = p1 - p0;
    let e = q1 - q0;
    let len = d.length();
    let denom = d.perp_dot(e);
    let parallel = denom.abs() <= 1e-12 * d.length() * e.length();
    if parallel {
        // collinear within tol: overlap of the parameter intervals along d
        let dist = (cross(p0, p1, q0) / len).abs().max((cross(p0, p1, q1) / len).abs());
        if dist > tol {
            return Vec::new();
        }
        let dir = d / len;
        let (mut s0, mut s1) = ((q0 - p0).dot(dir), (q1 - p0).dot(dir));
        if s0 > s1 {
            std::mem::swap(&mut s0, &mut s1);
        }
        let lo = s0.max(0.0);
        let hi = s1.min(len);
        if hi < lo - tol {
            return Vec::new();
        }
        if hi - lo <= tol {
            return vec![p0 + dir * ((lo + hi) * 0.5)];
        }
        return vec![p0 + dir * lo, p0 + dir * hi];
    }
    let t = (q0 - p0).perp_dot(e) / denom;
    let x = p0 + d * t;
    if point_segment_distance(x, p0, p1) <= tol && point_segment_distance(x, q0, q1) <= tol {
        vec![x]
    } else {
        Vec::new()
    }
}

/// Area of a counter-clockwise polygon (0 for points and segments).
pub fn area(poly: &[DVec2]) -> f64 {
    if poly.len() < 3 {
        return 0.0;
    }
    let mut s = 0.0;
    for k in 0..poly.len() {
        s += poly[k].perp_dot(poly[(k + 1) % poly.len()]);
    }
    s * 0.5
}

/// Distance between two convex sets in hull form (0 when they intersect).
pub fn convex_distance(a: &[DVec2], b: &[DVec2]) -> f64 {
    if a.is_empty() || b.is_empty() {
        return f64::INFINITY;
    }
    if !intersect_convex(a, b, 0.0).is_empty() {
        return 0.0;
    }
    let edges = |p: &[DVec2]| -> Vec<(DVec2, DVec2)> {
        match p.len() {
            1 => vec![(p[0], p[0])],
            2 => vec![(p[0], p[1])],
            n => (0..n).map(|k| (p[k], p[(k + 1) % n])).collect(),
        }
    };
    let mut best = f64::INFINITY;
    let (ea, eb) = (edges(a), edges(b));
    for &(a0, a1) in &ea {
        for &(b0, b1) in &eb {
            best = best
                .min(point_segment_distance(a0, b0, b1))
                .min(point_segment_distance(a1, b0, b1))
                .min(point_segment_distance(b0, a0, a1))
                .min(point_segment_distance(b1, a0, a1));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    #[test]
    fn hull_drops_interior_and_collinear_points() {
        let pts = [v(0.0, 0.0), v(1.0, 0.0), v(2.0, 0.0), v(2.0, 2.0), v(0.0, 2.0), v(1.0, 1.0), v(0.0, 1.0)];
        let h = convex_hull_2d(&pts, 1e-12);
        assert_eq!(h.len(), 4);
        assert!((area(&h) - 4.0).abs() < 1e-12);
        assert_eq!(convex_hull_2d(&[v(1.0, 1.0), v(1.0, 1.0)], 1e-12), vec![v(1.0, 1.0)]);
        let seg = convex_hull_2d(&[v(0.0, 0.0), v(3.0, 3.0), v(1.0, 1.0)], 1e-12);
        assert_eq!(seg.len(), 2);
        assert!(((seg[0] - seg[1]).length() - 18f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn intersections_of_all_kinds() {
        let sq = convex_hull_2d(&[v(0.0, 0.0), v(2.0, 0.0), v(2.0, 2.0), v(0.0, 2.0)], 1e-12);
        let sq2 = convex_hull_2d(&[v(1.0, 1.0), v(3.0, 1.0), v(3.0, 3.0), v(1.0, 3.0)], 1e-12);
        let i = intersect_convex(&sq, &sq2, 1e-12);
        assert!((area(&i) - 1.0).abs() < 1e-9);
        // segment through the square
        let s = [v(-1.0, 1.0), v(3.0, 1.0)];
        let i = intersect_convex(&s, &sq, 1e-12);
        assert_eq!(i.len(), 2);
        assert!(((i[0] - i[1]).length() - 2.0).abs() < 1e-12);
        // crossing segments
        let i = intersect_convex(&[v(0.0, 0.0), v(2.0, 2.0)], &[v(0.0, 2.0), v(2.0, 0.0)], 1e-12);
        assert_eq!(i.len(), 1);
        assert!((i[0] - v(1.0, 1.0)).length() < 1e-12);
        // collinear overlapping segments
        let i = intersect_convex(&[v(0.0, 0.0), v(2.0, 0.0)], &[v(1.0, 0.0), v(5.0, 0.0)], 1e-12);
        assert_eq!(i.len(), 2);
        // touching squares share an edge
        let sq3 = convex_hull_2d(&[v(2.0, 0.0), v(4.0, 0.0), v(4.0, 2.0), v(2.0, 2.0)], 1e-12);
        let i = intersect_convex(&sq, &sq3, 1e-9);
        assert_eq!(i.len(), 2);
        // disjoint
        assert!(intersect_convex(&sq, &[v(5.0, 5.0)], 1e-9).is_empty());
        assert!((convex_distance(&sq, &[v(5.0, 2.0)]) - 3.0).abs() < 1e-12);
    }

    #[test]
    fn boundary_distance() {
        let sq = convex_hull_2d(&[v(0.0, 0.0), v(4.0, 0.0), v(4.0, 2.0), v(0.0, 2.0)], 1e-12);
        assert!((signed_boundary_distance(v(2.0, 1.0), &sq) - 1.0).abs() < 1e-12);
        // contains answers signed_boundary_distance(p) >= -tol (near the corners too)
        for x in [-1.0, -0.3, -0.1, 0.0, 0.05, 2.0, 3.95, 4.0, 4.1, 4.3, 6.0] {
            for y in [-1.0, -0.3, -0.1, 0.0, 0.05, 1.0, 1.95, 2.0, 2.1, 2.3, 5.0] {
                for tol in [0.0, 0.2, 0.5] {
                    let p = v(x, y);
                    assert_eq!(contains(&sq, p, tol), signed_boundary_distance(p, &sq) >= -tol, "{p} {tol}");
                }
            }
        }
        // inside_by answers signed_boundary_distance(p) > margin
        for x in [-1.0, 0.0, 0.5, 1.0, 2.0, 3.5, 4.0, 6.0] {
            for y in [-1.0, 0.0, 0.5, 1.0, 2.0, 3.0, 5.0] {
                for margin in [0.0, 0.5, 1.0] {
                    let p = v(x, y);
                    assert_eq!(inside_by(p, &sq, margin), signed_boundary_distance(p, &sq) > margin, "{p} {margin}");
                }
            }
        }
        assert!((signed_boundary_distance(v(7.0, 6.0), &sq) + 5.0).abs() < 1e-12);
    }
}
