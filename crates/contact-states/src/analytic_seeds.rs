//! Analytic candidate configurations for edge-edge contacts (a deterministic complement to the GA of \[P\] II-D).
//!
//! An e-e state is thin: the two edges must cross at one point while the faces next to them stay clear, and eq. 8
//! has its minimum on a 5-dimensional manifold next to the f-e, e-f and f-f states that share the edges. The GA
//! minimum of eq. 8 usually lands in one of those (the closure), where the strict check rejects it. Here the
//! crossing is built directly: for each rotation `R` of a grid over the box's angle ranges (`angle_steps` values
//! per angle, the bounds included) and each point `b(u)` of B's edge (`edge_steps` interior parameters
//! `u = (i + 1/2) / edge_steps`), the translation that puts `b(u)` on A's edge at parameter `s`,
//! `x(s) = a0 + s (a1 - a0) - R b(u)`, is a line in translation space; its part inside the box's translation
//! ranges (intersected with `0 < s < 1`) is an interval of `s`, whose midpoint and ends (just inside, for states
//! that exist only against a bound of the box) give the candidates. The edges
//! then meet exactly (the e-e equality holds), and the strict check decides whether nothing else touches or
//! penetrates. Pairs of nearly parallel edges (`|da x R db| <= 1e-6 |da| |db|`) make no crossing and are skipped.
//! After all of these, per rotation the corners of the whole crossing region: with both parameters free,
//! `x(s, u) = a0 - R b0 + s da - u R db`, and the part of `(s, u) in [0, 1]^2` mapped into the box's translation
//! ranges is a convex polygon (10 half-planes); its corners (pulled `1e-6` towards their mean) have two bounds
//! active at once, where states that exist only in a corner of the box lie.
//! Cost: `angle_steps^3 (3 edge_steps + at most 10)` candidates, O(1) each to build (the corners by intersecting the
//! 45 pairs of constraint lines); the caller checks them in order.

use crate::pose::{Config, ConfigBox, Pose};
use crate::surface::SurfaceElements;
use stackplan_geom::DVec3;

/// Grid values of variable `k` of `bounds`: `steps` evenly spaced values including both bounds (one when the range
/// is a point).
fn grid(bounds: &ConfigBox, k: usize, steps: usize) -> Vec<f64> {
    let steps = steps.max(1);
    if bounds.width(k) <= 0.0 || steps == 1 {
        return vec![0.5 * (bounds.min[k] + bounds.max[k])];
    }
    (0..steps).map(|i| bounds.min[k] + bounds.width(k) * i as f64 / (steps - 1) as f64).collect()
}

/// Configurations in `bounds` at which edge `edge_a` of A and edge `edge_b` of B cross (see the module docs), in a
/// fixed order: rotations outermost (rx, then ry, then rz), then the parameter on B's edge.
pub fn edge_edge_candidates(
    fixed: &SurfaceElements,
    edge_a: usize,
    moving: &SurfaceElements,
    edge_b: usize,
    bounds: &ConfigBox,
    angle_steps: usize,
    edge_steps: usize,
) -> Vec<Config> {
    let (a0, a1) = fixed.edge_points(edge_a);
    let (b0, b1) = moving.edge_points(edge_b);
    let da = a1 - a0;
    let mut out = Vec::new();
    let (gx, gy, gz) = (grid(bounds, 3, angle_steps), grid(bounds, 4, angle_steps), grid(bounds, 5, angle_steps));
    // the grid's rotations at which the two edges are not parallel, in the fixed order, with B's edge turned
    let mut rotations: Vec<([f64; 3], Pose, DVec3)> = Vec::new();
    for &rx in &gx {
        for &ry in &gy {
            for &rz in &gz {
                let pose = Pose::from_config(&[0.0, 0.0, 0.0, rx, ry, rz]);
                let db = pose.apply_vector(b1 - b0);
                if da.cross(db).length() > 1e-6 * da.length() * db.length() {
                    rotations.push(([rx, ry, rz], pose, db));
                }
            }
        }
    }
    for &([rx, ry, rz], ref pose, _) in &rotations {
        for i in 0..edge_steps.max(1) {
            let u = (i as f64 + 0.5) / edge_steps.max(1) as f64;
            // x(s) = c + s da with c = a0 - R b(u)
            let c = a0 - pose.apply(b0 + (b1 - b0) * u);
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            for k in 0..3 {
                let (bmin, bmax) = (bounds.min[k], bounds.max[k]);
                if da[k].abs() <= 1e-300 {
                    if c[k] < bmin || c[k] > bmax {
                        hi = -1.0;
                    }
                    continue;
                }
                let (s0, s1) = ((bmin - c[k]) / da[k], (bmax - c[k]) / da[k]);
                lo = lo.max(s0.min(s1));
                hi = hi.min(s0.max(s1));
            }
            // an interior crossing: strictly inside (0, 1), not at a vertex
            if hi <= lo || hi <= 0.0 || lo >= 1.0 {
                continue;
            }
            // the middle of the interval, and its ends (just inside): states that exist only against a
            // bound of the box (a thin region at x = x_max, say) are met at the ends
            let margin = 1e-6 * (hi - lo);
            for s in [0.5 * (lo + hi), lo.max(0.0) + margin, hi.min(1.0) - margin] {
                let x = c + da * s;
                let mut t = [x.x, x.y, x.z, rx, ry, rz];
                // rounding can leave the translation a hair outside a bound it lies on
                bounds.clamp(&mut t);
                out.push(t);
            }
        }
    }
    // then the corners of the crossing region: for each rotation the translations `x(s, u)` with both edges'
    // parameters free form a parallelogram; its part inside the box is a convex polygon in `(s, u)`, whose corners
    // put two bounds active at once (x at its maximum and z at its minimum, say), where the slivers of states that
    // exist only in a corner of the box lie
    for &([rx, ry, rz], ref pose, db) in &rotations {
        let c0 = a0 - pose.apply(b0);
        for (s, u) in crossing_region_corners(da, db, c0, bounds) {
            let x = c0 + da * s - db * u;
            let mut t = [x.x, x.y, x.z, rx, ry, rz];
            bounds.clamp(&mut t);
            out.push(t);
        }
    }
    out
}

/// Corners of the polygon `{(s, u) in [0, 1]^2 : min_k <= (c0 + s da - u db)_k <= max_k, k = x, y, z}`, each
/// pulled towards the corners' mean by `1e-6` of the way (strictly inside: an interior crossing, bounds kept).
fn crossing_region_corners(da: DVec3, db: DVec3, c0: DVec3, bounds: &ConfigBox) -> Vec<(f64, f64)> {
    // lines alpha s + beta u = gamma; inside means lo <= alpha s + beta u <= hi
    let mut constraints: Vec<(f64, f64, f64, f64)> = vec![(1.0, 0.0, 0.0, 1.0), (0.0, 1.0, 0.0, 1.0)];
    for k in 0..3 {
        constraints.push((da[k], -db[k], bounds.min[k] - c0[k], bounds.max[k] - c0[k]));
    }
    let scale = 1.0 + da.length() + db.length() + c0.length();
    let inside = |s: f64, u: f64| {
        constraints.iter().all(|&(a, b, lo, hi)| {
            let v = a * s + b * u;
            v >= lo - 1e-12 * scale && v <= hi + 1e-12 * scale
        })
    };
    let lines: Vec<(f64, f64, f64)> = constraints.iter().flat_map(|&(a, b, lo, hi)| [(a, b, lo), (a, b, hi)]).collect();
    let mut corners: Vec<(f64, f64)> = Vec::new();
    for (i, &(a1, b1, g1)) in lines.iter().enumerate() {
        for &(a2, b2, g2) in &lines[i + 1..] {
            let det = a1 * b2 - a2 * b1;
            if det.abs() <= 1e-12 * (a1.abs() + b1.abs()) * (a2.abs() + b2.abs()) {
                continue;
            }
            let (s, u) = ((g1 * b2 - g2 * b1) / det, (a1 * g2 - a2 * g1) / det);
            if inside(s, u) && !corners.iter().any(|&(p, q)| (p - s).abs() + (q - u).abs() <= 1e-12) {
                corners.push((s, u));
            }
        }
    }
    if corners.len() < 3 {
        return Vec::new();
    }
    let n = corners.len() as f64;
    let (ms, mu) = corners.iter().fold((0.0, 0.0), |(a, b), &(s, u)| (a + s / n, b + u / n));
    corners.into_iter().map(|(s, u)| (s + 1e-6 * (ms - s), u + 1e-6 * (mu - u))).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::criteria::tests::box_part;
    use crate::manifold::segment_segment_distance;

    #[test]
    fn candidates_make_the_edges_cross_inside_the_box() {
        let slab = box_part("slab", DVec3::new(-50.0, -50.0, -10.0), DVec3::new(50.0, 50.0, 0.0));
        let cube = box_part("cube", DVec3::splat(-0.5), DVec3::splat(0.5));
        let (sa, sb) = (&slab.surface, &cube.surface);
        let bounds =
            ConfigBox::new([-60.0, -60.0, -2.0, -0.3, -0.3, -0.3], [60.0, 60.0, 2.0, 0.3, 0.3, 0.3]).expect("box");
        let mut crossing_pairs = 0;
        for ea in 0..sa.edges.len() {
            for eb in 0..sb.edges.len() {
                let cands = edge_edge_candidates(sa, ea, sb, eb, &bounds, 3, 3);
                crossing_pairs += usize::from(!cands.is_empty());
                let (a0, a1) = sa.edge_points(ea);
                let (b0, b1) = sb.edge_points(eb);
                for t in &cands {
                    assert!(bounds.contains(t));
                    let pose = Pose::from_config(t);
                    let d = segment_segment_distance(a0, a1, pose.apply(b0), pose.apply(b1));
                    assert!(d < 1e-9, "edges {ea} {eb} apart by {d} at {t:?}");
                }
            }
        }
        // the corners of the crossing regions put two translation bounds active at once (with a box tight in x and z)
        let tight =
            ConfigBox::new([49.5, -60.0, -0.3, -0.3, -0.3, -0.3], [49.9, 60.0, 0.3, 0.3, 0.3, 0.3]).expect("box");
        let active = |t: &Config| {
            (0..3).filter(|&k| (t[k] - tight.min[k]).abs().min((t[k] - tight.max[k]).abs()) < 1e-4).count()
        };
        let with_two_bounds = (0..sa.edges.len())
            .flat_map(|ea| (0..sb.edges.len()).map(move |eb| (ea, eb)))
            .flat_map(|(ea, eb)| edge_edge_candidates(sa, ea, sb, eb, &tight, 3, 3))
            .filter(|t| active(t) >= 2)
            .count();
        assert!(with_two_bounds > 0);
        // every edge of the slab can cross most of the cube's edges under some rotation of the grid
        assert!(crossing_pairs > sa.edges.len() * sb.edges.len() / 2, "{crossing_pairs}");
        // a translation box that keeps the cube far from the slab's edges gives no candidate
        let far = ConfigBox::new([-5.0, -5.0, 5.0, -0.3, -0.3, -0.3], [5.0, 5.0, 6.0, 0.3, 0.3, 0.3]).expect("box");
        for ea in 0..sa.edges.len() {
            for eb in 0..sb.edges.len() {
                assert!(edge_edge_candidates(sa, ea, sb, eb, &far, 3, 3).is_empty());
            }
        }
    }
}
