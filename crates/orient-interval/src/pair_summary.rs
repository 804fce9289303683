//! Regression summary of a part pair for `cargo xtask regress` (docs/formats.md, "Regression scenarios"): per convex
//! pair, the constant-structure intervals over a full turn and the constructions vs extrapolations of a sweep.
//! Deterministic (no timings). Cost: one sweep per component pair.

use crate::critical::PairEvents;
use crate::sweep::{PairSweep, degree_steps};
use glam::{DMat3, DVec3};
use serde_json::{Value, json};
use stackplan_geom::part::Part;

fn round6(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

/// Summary JSON for moving part `moving` (rotated about `z`) against `fixed` placed by `fixed_pose`
/// (`x -> rotation * x + translation`), sweeping at `step_deg` degree steps:
/// `{"step_deg", "pairs": [{"moving_piece", "fixed_piece", "intervals", "event_windows", "constructions",
/// "extrapolations", "unextrapolable", "event_kinds": {kind: count}, "interval_starts_deg": [...]}],
/// "totals": {"pairs", "intervals", "constructions", "extrapolations"}}`.
pub fn regress_summary(moving: &Part, fixed: &Part, fixed_pose: (DMat3, DVec3), step_deg: f64) -> Value {
    let angles = degree_steps(step_deg);
    let mut pairs = Vec::new();
    let (mut t_intervals, mut t_constructions, mut t_extrapolations, mut t_errors) = (0u64, 0u64, 0u64, 0u64);
    for (i, a) in moving.components().iter().enumerate() {
        for (j, b) in fixed.components().iter().enumerate() {
            let placed = b.transformed(fixed_pose.0, fixed_pose.1);
            let events = PairEvents::new(a, &placed);
            let turn = events.full_turn();
            let constant: Vec<_> = turn.iter().filter(|t| !t.degenerate).collect();
            let mut kinds = std::collections::BTreeMap::<String, u64>::new();
            for b in events.bands() {
                *kinds.entry(b.event.kind.name().to_string()).or_default() += 1;
            }
            let mut sweep = PairSweep::new(a.clone(), placed, angles.clone());
            let mut errors = 0u64;
            for k in 0..angles.len() {
                if let Some(Err(e)) = sweep.obstacle_at(k) {
                    tracing::warn!(moving_piece = i, fixed_piece = j, k, error = %e, "sweep step failed");
                    errors += 1;
                }
            }
            let s = sweep.stats();
            t_intervals += constant.len() as u64;
            t_constructions += s.constructions;
            t_extrapolations += s.extrapolations;
            t_errors += errors;
            pairs.push(json!({
                "moving_piece": i,
                "fixed_piece": j,
                "intervals": constant.len(),
                "event_windows": turn.len() - constant.len(),
                "constructions": s.constructions,
                "extrapolations": s.extrapolations,
                "unextrapolable": s.unextrapolable,
                "errors": errors,
                "event_kinds": kinds,
                "interval_starts_deg": constant.iter().map(|t| round6(t.start.to_degrees())).collect::<Vec<_>>(),
            }));
        }
    }
    json!({
        "step_deg": step_deg,
        "pairs": pairs,
        "totals": {
            "pairs": moving.components().len() * fixed.components().len(),
            "intervals": t_intervals,
            "constructions": t_constructions,
            "extrapolations": t_extrapolations,
            "errors": t_errors,
        }
    })
}
