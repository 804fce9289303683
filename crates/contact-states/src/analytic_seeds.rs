//! Analytic candidate configurations for edge-edge contacts (a deterministic complement to the GA of [P] II-D).
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
//! Cost: `3 angle_steps^3 edge_steps` candidates, each O(1) to build; the caller checks them in order.

use crate::pose::{Config, ConfigBox, Pose};
use crate::surface::SurfaceElements;

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
    for &rx in &gx {
        for &ry in &gy {
            for &rz in &gz {
                let pose = Pose::from_config(&[0.0, 0.0, 0.0, rx, ry, rz]);
                let db = pose.apply_vector(b1 - b0);
                if da.cross(db).length() <= 1e-6 * da.length() * db.length() {
                    continue;
                }
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
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::criteria::tests::box_part;
    use crate::manifold::segment_segment_distance;
    use stackplan_geom::DVec3;

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
