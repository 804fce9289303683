//! The shortcuts of the check must decide exactly what the direct analysis decides:
//!
//! * the equilibrium problem of a stack splits into groups of parts connected by part-part contacts
//!   (`solve_equilibrium`), and `check_stack` solves each prefix stack through the group that the newest part joins.
//!   Random stacks of two or three box columns (placed layer by layer, alternating between the columns, optionally
//!   bridged by a plank on top) against the check of every prefix stack on its own (`check_stack(&stack[..=i])`,
//!   which has no memory of the steps), and against the check of every column on its own: the stack is stable iff
//!   every column is, and its margin (same load direction for all parts) is the smallest column margin;
//! * the closed-form margin of a part on a flat horizontal support against the margin SOCPs
//!   (`EquilibriumOptions::margins_by_socp_only`), for random boxes on random supports, off-centre and overhanging;
//! * the fast equilibrium and margins of `solve_equilibrium` (support trees, flat supports in closed form, reduced
//!   contact points, the triangle certificate) against one plain SOCP per group (and per group and direction), both
//!   options `*_by_socp_only`, through `check_stack` against `check_stack_reference`: on random stacks of box columns
//!   (flat supports, off-centre ones whose least-squares forces go negative, tipping and sliding limits, planks
//!   bridging the columns so that the support graph has cycles) with random friction, and on columns of every
//!   fixture part (`fixtures/parts/*.json`) in its two lowest resting poses, nested (parts lowered onto the one
//!   below until they touch, straight and shifted sideways), on the planned Channel stack (flat supports at two
//!   heights) and on staggered brick walls (cyclic support graphs, side contacts between neighbours, overhanging
//!   rows: the vertical certificate of the prefix verdicts): identical verdicts of every kind (except `Unstable`
//!   by a certificate of instability where the plain SOCP ends `Unknown`, see `same_verdict`), margins within 1e-6
//!   relative, the same minimum-norm forces (see `assert_equivalent`).

use crate::common;

use common::{at, box_layers, box_part, build, for_each_fixture_column, placements, planned_channels, same_margin};
use glam::DVec3;
use proptest::prelude::*;
use stackplan_stability::check::{CheckOptions, StackCheck, check_stack, check_stack_reference};
use stackplan_stability::contacts::analyse_contacts;
use stackplan_stability::equilibrium::{ContactForce, Equilibrium};
use stackplan_stability::equilibrium::{EquilibriumOptions, Verdict, solve_equilibrium};
use stackplan_stability::world::{PlacedPart, stack_tolerance, world_stack};

fn options() -> CheckOptions {
    let mut o = CheckOptions { mu: 0.6, margin_directions: 8, ..CheckOptions::default() };
    o.grasp.cup_diameter = 5.0;
    o
}

/// Same verdict, margins within 1e-6 relative, the same minimum-norm forces: the same points, the sum of squares
/// within 1e-6 relative, every force within `1e-3 * weight` (the minimum-norm forces are unique, but a duality gap
/// of 1e-8 relative bounds the distance of a solver's forces to them only by about `sqrt(1e-8)` of their norm).
fn assert_equivalent(fast: &Equilibrium, plain: &Equilibrium, weight: f64, what: &str) {
    assert!(same_verdict(&fast.verdict, &plain.verdict), "{what}: verdict {:?} vs {:?}", fast.verdict, plain.verdict);
    assert!(same_margin(fast.margin, plain.margin), "{what}: margin {:?} vs {:?}", fast.margin, plain.margin);
    assert_same_forces(&fast.forces, &plain.forces, weight, what);
}

/// The same verdict, or `Unstable` where the plain SOCP ends unsure (`Unknown`, e.g. `AlmostPrimalInfeasible`): a
/// certificate of instability (`equilibrium::instability`) decides what the solver could not.
fn same_verdict(fast: &Verdict, plain: &Verdict) -> bool {
    fast == plain || (*fast == Verdict::Unstable && matches!(plain, Verdict::Unknown(_)))
}

fn assert_same_forces(fast: &[ContactForce], plain: &[ContactForce], weight: f64, what: &str) {
    assert_eq!(fast.len(), plain.len(), "{what}: forces");
    for (f, p) in fast.iter().zip(plain) {
        assert_eq!((f.patch, f.point), (p.patch, p.point), "{what}: force order");
        assert!((f.force - p.force).length() <= 1e-3 * weight, "{what}: force {} vs {}", f.force, p.force);
    }
    let squares = |forces: &[ContactForce]| forces.iter().map(|f| f.force.length_squared()).sum::<f64>();
    let (a, b) = (squares(fast), squares(plain));
    assert!((a - b).abs() <= 1e-6 * b.max(weight * weight * 1e-6), "{what}: sum of squares {a} vs {b}");
}

/// Every verdict identical, margins and forces equivalent (see [`assert_equivalent`]).
fn assert_checks_equivalent(fast: &StackCheck, plain: &StackCheck, weight: f64, what: &str) {
    assert_equivalent(&fast.stack, &plain.stack, weight, &format!("{what}, whole stack"));
    assert_eq!(fast.parts.len(), plain.parts.len());
    for (f, p) in fast.parts.iter().zip(&plain.parts) {
        let part = format!("{what}, part {}", f.index);
        assert!(same_verdict(&f.stable, &p.stable), "{part}: stable {:?} vs {:?}", f.stable, p.stable);
        assert!(
            same_verdict(&f.stack_stable, &p.stack_stable),
            "{part}: stack stable {:?} vs {:?}",
            f.stack_stable,
            p.stack_stable
        );
        assert_eq!(
            (f.graspable, f.insertable, f.removable, f.ok),
            (p.graspable, p.insertable, p.removable, p.ok),
            "{part}: verdicts"
        );
        assert!(same_margin(f.margin, p.margin), "{part}: margin {:?} vs {:?}", f.margin, p.margin);
        assert_same_forces(&f.forces, &p.forces, weight, &part);
    }
}

#[test]
fn shortcuts_match_the_plain_socps_on_fixture_columns() {
    for_each_fixture_column(&[(0.0, 0.0), (7.0, -3.0)], |label, part, stack| {
        let mut options = options();
        options.mu = 0.4;
        let fast = check_stack(stack, &options).expect("check");
        let plain = check_stack_reference(stack, &options).expect("check");
        assert_checks_equivalent(&fast, &plain, part.mass().mass, label);
    });
}

/// A light thin plank overhanging a heavy box, both movable (one group): the plank's c.g. 0.5 mm inside the box's +x
/// edge and 2 mm above it tips at `0.5 / 2 = 0.25` (friction 1 does not limit it; the box holds far more), so the
/// whole stack's margin is 0.25, by the closed form and by the plain SOCP within 5e-8. At clarabel's default
/// tolerances (1e-8) the plain margin came out 6.8e-7 high: a residual of the plank's moment row (the plank is 1/16 of
/// the group's weight) over its 2 mm lever arm; at the margin solves' 1e-10 (`MARGIN_TOLERANCE`) it is 6.8e-9. A
/// 4096-case run of `shortcuts_match_the_plain_socps_on_random_box_stacks` found this (seed 10053: 1.4e-6 apart on a
/// 6 mm plank; the case is kept in the regressions file).
#[test]
fn a_light_plank_on_a_heavy_box_tips_at_its_closed_form_margin_in_the_plain_socp() {
    let base = box_part("base", DVec3::new(60.0, 60.0, 40.0));
    let plank = box_part("plank", DVec3::new(60.0, 40.0, 4.0));
    let stack = [at(&base, DVec3::ZERO), at(&plank, DVec3::new(29.5, 10.0, 40.0))];
    let options = CheckOptions { mu: 1.0, ..options() };
    let plain = check_stack_reference(&stack, &options).expect("check");
    let fast = check_stack(&stack, &options).expect("check");
    for (what, check) in [("plain", &plain), ("fast", &fast)] {
        let margin = check.stack.margin.expect("stable stack has a margin");
        assert!((margin - 0.25).abs() <= 5e-8, "{what}: margin {margin}, closed form 0.25");
        let direction = check.stack.weakest_direction.expect("direction");
        assert!((direction - DVec3::X).length() <= 1e-9, "{what}: weakest direction {direction}");
    }
}

/// The planner's 15-part Channel stack (flipped channels straddling a flange of the one below: flat supports at two
/// heights, where the minimum-norm forces need friction).
#[test]
fn shortcuts_match_the_plain_socps_on_the_planned_channel_stack() {
    let plan = planned_channels();
    let stack = placements(&plan);
    for mu in [0.2, 0.5, 1.0] {
        let options = CheckOptions { mu, ..options() };
        let fast = check_stack(&stack, &options).expect("check");
        let plain = check_stack_reference(&stack, &options).expect("check");
        assert_checks_equivalent(&fast, &plain, plan.part.mass().mass, &format!("planned channels, mu {mu}"));
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: common::cases(16), ..ProptestConfig::default() })]

    #[test]
    fn groups_decide_like_direct_solves(
        columns in 2usize..=3,
        layers in box_layers(10.0f64..30.0, 12.0, 30.0f64..70.0),
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
    fn shortcuts_match_the_plain_socps_on_random_box_stacks(
        columns in 1usize..=3,
        layers in box_layers(10.0f64..40.0, 25.0, 20.0f64..70.0),
        bridge in prop::option::of((-30.0f64..30.0, 5.0f64..20.0)),
        mu in 0.1f64..1.2,
    ) {
        let layout = build(&layers, columns);
        let mut parts: Vec<_> = layout.iter().enumerate().map(|(k, (_, _, size))| box_part(&format!("b{k}"), *size)).collect();
        let mut placed: Vec<DVec3> = layout.iter().map(|(_, lo, _)| *lo).collect();
        if let Some((shift, thickness)) = bridge {
            let top = layers.iter().map(|l| l.0).sum::<f64>();
            parts.push(box_part("plank", DVec3::new(200.0 * (columns - 1) as f64 + 40.0, 40.0, thickness)));
            placed.push(DVec3::new(-20.0 + shift.clamp(-10.0, 10.0), -20.0, top));
        }
        let stack: Vec<PlacedPart<'_>> = parts.iter().zip(&placed).map(|(p, lo)| at(p, *lo)).collect();
        let options = CheckOptions { mu, ..options() };
        let fast = check_stack(&stack, &options).expect("check");
        let plain = check_stack_reference(&stack, &options).expect("check");
        let weight: f64 = parts.iter().map(|p| p.mass().mass).sum();
        assert_checks_equivalent(&fast, &plain, weight, "random boxes");
    }

    #[test]
    fn shortcuts_match_the_plain_socps_on_brick_walls(
        rows in 2usize..=4,
        shift in 0.0f64..160.0,
        mu in 0.2f64..1.0,
    ) {
        // a staggered wall of 200 x 100 x 50 bricks, row r shifted by r * shift (100 = the pyramid of the benchmark;
        // beyond 100 the upper rows overhang): adjacent bricks touch side by side, upper bricks rest on two below, so
        // the support graph has cycles (the vertical certificate of the prefix verdicts) and some walls topple
        let brick = box_part("brick", DVec3::new(200.0, 100.0, 50.0));
        let mut stack = Vec::new();
        for row in 0..rows {
            for k in 0..(rows - row) {
                stack.push(at(&brick, DVec3::new(shift * row as f64 + 200.0 * k as f64, 0.0, 50.0 * row as f64)));
            }
        }
        let options = CheckOptions { mu, ..options() };
        let fast = check_stack(&stack, &options).expect("check");
        let plain = check_stack_reference(&stack, &options).expect("check");
        assert_checks_equivalent(&fast, &plain, brick.mass().mass * stack.len() as f64, "brick wall");
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
