//! Insertion straight down and removal straight up (\[A\] II-B condition (iv); `docs/algorithms.md`, "C-space obstacle
//! of a convex pair" and "Stability, grasp and insertion").
//!
//! Part `i` reaches its pose by translating along -z from far above. It collides on the way iff some component `C`
//! of it, swept upward to above everything present (`C (+) [0, L z]`), penetrates a component of a part already in
//! place. The sweep is convex, so the test is the separating-axis test of [`crate::sat`] with the sweep folded into
//! the support intervals; touching (penetration within the tolerance) is allowed, so a part may slide down along a
//! neighbour's wall or land on a support. The floor never blocks a downward insertion (the final pose is checked for
//! floor penetration by the interference test).
//!
//! Removal: in safe unstacking the parts are lifted straight up in reverse order. Geometrically the upward path of
//! part `i` against parts `0..i` is the reverse of its insertion path, so the sweep test is the same one; what
//! removal adds is that the parts left behind (`0..i`) must stay in equilibrium — the prefix-stack stability computed by
//! [`crate::check`]. [`liftable_from_full_stack`] answers the different question whether a part can be lifted out of
//! the finished stack right now (against all other parts).
//!
//! Cost: per component pair whose (swept) boxes meet, one separating-axis test.

use crate::sat::{Shape, separation};
use crate::world::{WorldPart, aabb_overlap};
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// The first obstruction found for a vertical motion.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Obstruction {
    /// The obstructing part.
    pub part: usize,
    /// Its component.
    pub component: usize,
    /// The moving part's component.
    pub moving_component: usize,
    /// Penetration depth of the sweep into it (mm).
    pub depth: f64,
}

/// Checks the vertical path of part `moving` against the parts `others`: `Ok(())` when free, else the deepest
/// obstruction. The path goes from the pose up to above every part of `others`.
pub fn vertical_path_obstruction(
    parts: &[WorldPart],
    moving: usize,
    others: impl IntoIterator<Item = usize>,
    tol: f64,
) -> Result<(), Obstruction> {
    let Some(m) = parts.get(moving) else { return Ok(()) };
    let others: Vec<usize> = others.into_iter().filter(|&j| j != moving && j < parts.len()).collect();
    let top = others.iter().map(|&j| parts[j].aabb.1.z).fold(m.aabb.1.z, f64::max);
    let lift = top - m.aabb.0.z + 1.0;
    let sweep = DVec3::Z * lift;
    let swept_box = |b: &(DVec3, DVec3)| (b.0, b.1 + sweep);
    let mut worst: Option<Obstruction> = None;
    for &j in &others {
        let o = &parts[j];
        if !aabb_overlap(&swept_box(&m.aabb), &o.aabb, tol) {
            continue;
        }
        for (cm, c) in m.components.iter().enumerate() {
            let cbox = swept_box(&c.aabb);
            if !aabb_overlap(&cbox, &o.aabb, tol) {
                continue;
            }
            let shape = Shape { component: c, sweep };
            for (co, oc) in o.components.iter().enumerate() {
                if !aabb_overlap(&cbox, &oc.aabb, tol) {
                    continue;
                }
                let sep = separation(&shape, &Shape::of(oc));
                if sep.distance < -tol && worst.is_none_or(|w| -sep.distance > w.depth) {
                    worst = Some(Obstruction { part: j, component: co, moving_component: cm, depth: -sep.distance });
                }
            }
        }
    }
    match worst {
        Some(w) => Err(w),
        None => Ok(()),
    }
}

/// Whether part `i` can be lowered straight down into its pose with parts `0..i` in place.
pub fn insertion_obstruction(parts: &[WorldPart], i: usize, tol: f64) -> Result<(), Obstruction> {
    vertical_path_obstruction(parts, i, 0..i, tol)
}

/// Whether part `i` can be lifted straight up out of the complete stack (all other parts in place).
pub fn liftable_from_full_stack(parts: &[WorldPart], i: usize, tol: f64) -> Result<(), Obstruction> {
    vertical_path_obstruction(parts, i, 0..parts.len(), tol)
}
