//! The shortcuts of the check must decide exactly what the direct analysis decides:
//!
//! * the equilibrium problem of a stack splits into groups of parts connected by part-part contacts
//!   (`solve_equilibrium`), and `check_stack` solves each prefix stack through the group that the newest part joins.
//!   Random stacks of two or three box columns (placed layer by layer, alternating between the columns, optionally
//!   bridged by a plank on top) against the check of every prefix stack on its own (`check_stack(&stack[..=i])`,
//!   which has no memory of the steps), and against the check of every column on its own: the stack is stable iff
//!   every column is, and its margin (same load direction for all parts) is the smallest column margin;
//! * the closed-form margin of a part on a flat horizontal support against the margin SOCPs
//!   (`EquilibriumOptions::margins_by_socp_only`), for random boxes on random supports, off-centre and overhanging.

mod common;

use common::{at, box_part};
use glam::DVec3;
use proptest::prelude::*;
use stackplan_stability::check::{CheckOptions, check_stack};
use stackplan_stability::contacts::analyse_contacts;
use stackplan_stability::equilibrium::{EquilibriumOptions, Verdict, solve_equilibrium};
use stackplan_stability::world::{PlacedPart, stack_tolerance, world_stack};

fn options() -> CheckOptions {
    let mut o = CheckOptions { mu: 0.6, margin_directions: 8, ..CheckOptions::default() };
    o.grasp.cup_diameter = 5.0;
    o
}

/// Stacks the boxes given per layer and column; returns (part index -> column, lower corner) in placement order.
/// A layer: its height and per column (centre offset x, y, size x, y).
type Layer = (f64, Vec<(f64, f64, f64, f64)>);

fn build(layers: &[Layer], columns: usize) -> Vec<(usize, DVec3, DVec3)> {
    let mut out = Vec::new();
    let mut z = 0.0;
    for (height, boxes) in layers {
        for (c, &(cx, cy, sx, sy)) in boxes.iter().take(columns).enumerate() {
            let centre = DVec3::new(200.0 * c as f64 + cx, cy, z);
            out.push((c, centre - DVec3::new(sx / 2.0, sy / 2.0, 0.0), DVec3::new(sx, sy, *height)));
        }
        z += height;
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig { cases: std::env::var("PROPTEST_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(16), ..ProptestConfig::default() })]

    #[test]
    fn groups_decide_like_direct_solves(
        columns in 2usize..=3,
        layers in prop::collection::vec(
            (10.0f64..30.0, prop::collection::vec((-12.0f64..12.0, -12.0f64..12.0, 30.0f64..70.0, 30.0f64..70.0), 3)),
            1..=3,
        ),
        bridge in prop::option::of((-30.0f64..30.0, 5.0f64..20.0)),
    ) {
        let layout = build(&layers, columns);
        let mut parts: Vec<_> = layout.iter().enumerate().map(|(k, (_, _, size))| box_part(&format!("b{k}"), *size)).collect();
        let top = layers.iter().map(|l| l.0).sum::<f64>();
        let mut placed: Vec<(Option<usize>, DVec3)> = layout.iter().map(|(c, lo, _)| (Some(*c), *lo)).collect();
        if let Some((shift, thickness)) = bridge {
            // a plank on the top layer spanning all columns (it touches the top boxes of every column)
            parts.push(box_part("plank", DVec3::new(200.0 * (columns - 1) as f64 + 40.0, 40.0, thickness)));
            placed.push((None, DVec3::new(-20.0 + shift.clamp(-10.0, 10.0), -20.0, top)));
        }
        let stack: Vec<PlacedPart<'_>> = parts.iter().zip(&placed).map(|(p, (_, lo))| at(p, *lo)).collect();
        let report = check_stack(&stack, &options()).expect("check");
        // every prefix against a direct check of the prefix stack
        for i in 0..stack.len() {
            let direct = check_stack(&stack[..=i], &options()).expect("check");
            prop_assert_eq!(&report.parts[i].stack_stable, &direct.stack.verdict, "prefix {}", i);
        }
        // columns on their own (only when no plank joins them)
        if bridge.is_none() {
            let mut all_stable = true;
            let mut smallest = f64::INFINITY;
            for c in 0..columns {
                let column: Vec<PlacedPart<'_>> = stack.iter().zip(&placed).filter(|(_, (col, _))| *col == Some(c)).map(|(p, _)| *p).collect();
                let r = check_stack(&column, &options()).expect("check");
                prop_assert!(!matches!(r.stack.verdict, Verdict::Unknown(_)), "{:?}", r.stack.verdict);
                all_stable &= r.stack.verdict.is_stable();
                if let Some(m) = r.stack.margin {
                    smallest = smallest.min(m);
                }
            }
            prop_assert_eq!(report.stack.verdict.is_stable(), all_stable);
            if all_stable {
                let m = report.stack.margin.expect("margin");
                prop_assert!((m - smallest).abs() <= 1e-6 * (1.0 + smallest), "stack {} vs columns {}", m, smallest);
            }
        }
    }

    #[test]
    fn closed_form_margin_matches_the_socp(
        support in (20.0f64..80.0, 20.0f64..80.0, 5.0f64..30.0),
        top in (20.0f64..80.0, 20.0f64..80.0, 5.0f64..60.0),
        offset in (-30.0f64..30.0, -30.0f64..30.0),
        mu in 0.1f64..1.2,
        directions in 1usize..=12,
    ) {
        let a = box_part("support", DVec3::new(support.0, support.1, support.2));
        let b = box_part("top", DVec3::new(top.0, top.1, top.2));
        let stack = [at(&a, DVec3::ZERO), at(&b, DVec3::new(offset.0, offset.1, support.2))];
        let parts = world_stack(&stack).expect("world");
        let tol = stack_tolerance(&parts).linear;
        let contacts = analyse_contacts(&parts, tol, |_| true);
        // the top part alone on the fixed support, and the support alone on the floor (the top one fixed as well)
        for movable in [[false, true], [true, false]] {
            let closed = EquilibriumOptions::new(mu, directions);
            let socp = EquilibriumOptions { margins_by_socp_only: true, ..closed };
            let fast = solve_equilibrium(&parts, &movable, &contacts.patches, &closed).expect("solve");
            let slow = solve_equilibrium(&parts, &movable, &contacts.patches, &socp).expect("solve");
            prop_assert_eq!(&fast.verdict, &slow.verdict);
            match (fast.margin, slow.margin) {
                (Some(f), Some(s)) => prop_assert!((f - s).abs() <= 1e-6 * (1.0 + s), "closed form {} vs SOCP {}", f, s),
                (f, s) => prop_assert!(f.is_none() && s.is_none(), "{:?} vs {:?}", f, s),
            }
        }
    }
}
