//! `GrowingStack::check_candidate` (the planner's per-candidate verdict) against `check_added_part`'s report: for
//! every prefix `stack[..=i]` whose stack without its last part is stable (the precondition), the candidate fails at
//! the first of stable, stack stable, graspable, insertable that the report fails, with the same verdict, or passes
//! with the report's grasp radius bit for bit. Stacks: columns of every fixture part in its two lowest resting poses,
//! nested and shifted; the planned 15-part Channel stack; staggered brick walls; random box columns with planks; the
//! same candidate tested twice and on a stack grown in between (the memos), and tilted copies of a part (the grasp
//! memo per rotation).

use crate::common;
use stackplan_geom::Pose;

use common::{at, box_layers, box_part, build, for_each_fixture_column, placements, planned_channels};
use glam::{DMat3, DVec3};
use proptest::prelude::*;
use stackplan_stability::check::{CheckOptions, PartCheck, check_stack};
use stackplan_stability::check_added_part;
use stackplan_stability::equilibrium::Verdict;
use stackplan_stability::growing::{Accepted, GrowingStack, Rejection, ToleranceScale};
use stackplan_stability::world::{PlacedPart, stack_tolerance, world_stack};

fn options(mu: f64, cup_diameter: f64) -> CheckOptions {
    let mut o = CheckOptions { mu, margin_directions: 0, prefix_stability: false, ..CheckOptions::default() };
    o.grasp.cup_diameter = cup_diameter;
    o
}

/// What the planner reads of a full report, in its order.
fn expected(report: &PartCheck) -> Result<f64, Rejection> {
    if !report.stable.is_stable() {
        Err(Rejection::NotStable(report.stable.clone()))
    } else if !report.stack_stable.is_stable() {
        Err(Rejection::StackNotStable(report.stack_stable.clone()))
    } else if !report.graspable {
        Err(Rejection::NotGraspable)
    } else if let Some(o) = report.insertion_obstruction {
        Err(Rejection::NotInsertable(o))
    } else {
        Ok(report.grasp_radius)
    }
}

fn is_unknown(v: &Verdict) -> bool {
    matches!(v, Verdict::Unknown(_))
}

/// Grows `stack` part by part, comparing every candidate whose precondition holds; returns how many were compared.
fn compare_candidates(stack: &[PlacedPart<'_>], options: &CheckOptions, what: &str) -> usize {
    compare_candidates_at(stack, options, what, ToleranceScale::Exact)
}

/// [`compare_candidates`] with the candidates' tolerance chosen by `scale`: the report it is compared with is
/// `check_added_part`'s at the tolerance the growing stack says it uses ([`GrowingStack::tolerance_for`]).
fn compare_candidates_at(stack: &[PlacedPart<'_>], options: &CheckOptions, what: &str, scale: ToleranceScale) -> usize {
    let mut growing = GrowingStack::new(options).expect("options").with_tolerance_scale(scale);
    let mut compared = 0;
    for (i, &candidate) in stack.iter().enumerate() {
        let before_stable = i == 0 || check_stack(&stack[..i], options).expect("check").stack.verdict.is_stable();
        if before_stable {
            let tol = growing.tolerance_for(&candidate).expect("pose");
            if scale == ToleranceScale::Exact {
                let exact = stack_tolerance(&world_stack(&stack[..=i]).expect("world")).linear;
                assert_eq!(tol.to_bits(), exact.to_bits(), "{what}, part {i}: the exact tolerance");
            }
            let at_tol = CheckOptions { contact_tolerance: Some(tol), ..options.clone() };
            let report = check_added_part(&stack[..=i], &at_tol).expect("added");
            let tested = growing.check_candidate(candidate).expect("candidate");
            // the same candidate again: the memos answer the same
            assert_eq!(growing.check_candidate(candidate).expect("candidate"), tested, "{what}, part {i}: repeated");
            let unknown = is_unknown(&report.stable) || is_unknown(&report.stack_stable);
            match (expected(&report), tested) {
                (Ok(radius), Ok(Accepted { grasp_radius })) => {
                    assert_eq!(grasp_radius.to_bits(), radius.to_bits(), "{what}, part {i}: grasp radius");
                }
                (want, got) => {
                    // a certificate may resolve an Unknown of the solver (never seen in these stacks)
                    assert!(
                        unknown || want.as_ref().err() == got.as_ref().err(),
                        "{what}, part {i}: {want:?} vs {got:?}"
                    );
                    assert!(!unknown, "{what}, part {i}: an Unknown verdict {report:?}");
                }
            }
            compared += 1;
        }
        growing.push(candidate).expect("push");
    }
    assert_eq!(growing.len(), stack.len());
    compared
}

#[test]
fn candidates_fail_and_pass_like_the_added_part_report_on_fixture_columns() {
    let mut compared = 0;
    for_each_fixture_column(&[(0.0, 0.0), (7.0, -3.0), (40.0, 0.0)], |label, _, stack| {
        for (mu, cup) in [(0.4, 5.0), (0.8, 10.0), (0.5, 400.0)] {
            compared += compare_candidates(stack, &options(mu, cup), &format!("{label} mu {mu} cup {cup}"));
        }
    });
    assert!(compared >= 150, "only {compared} candidates compared");
}

/// The stacking planner's choice: the box diagonal rounded up to a power of two (between 1 and 2 times the exact
/// tolerance), shared by candidates that widen the box by different amounts; the verdicts are the report's at that
/// tolerance.
#[test]
fn candidates_at_power_of_two_tolerances_fail_and_pass_like_the_report_at_that_tolerance() {
    let mut compared = 0;
    for_each_fixture_column(&[(0.0, 0.0), (7.0, -3.0)], |label, _, stack| {
        compared += compare_candidates_at(stack, &options(0.5, 10.0), label, ToleranceScale::PowerOfTwo);
    });
    let plan = planned_channels();
    compared += compare_candidates_at(&placements(&plan), &options(0.5, 10.0), "channels", ToleranceScale::PowerOfTwo);
    assert!(compared >= 60, "only {compared} candidates compared");
    // a column of 1 mm cubes: every diagonal up to the next power of two (the rounding is exact)
    let cube = box_part("cube", DVec3::splat(1.0));
    let column: Vec<PlacedPart<'_>> = (0..9).map(|k| at(&cube, DVec3::new(0.0, 0.0, k as f64))).collect();
    let mut growing =
        GrowingStack::new(&options(0.5, 0.5)).expect("options").with_tolerance_scale(ToleranceScale::PowerOfTwo);
    for (k, &candidate) in column.iter().enumerate() {
        let diagonal = (2.0 + ((k + 1) * (k + 1)) as f64).sqrt();
        let expected = 1e-9 * 2f64.powf(diagonal.log2().ceil());
        let tol = growing.tolerance_for(&candidate).expect("pose");
        assert!((tol - expected).abs() <= 1e-24, "{k}: {tol} vs {expected}");
        assert!(tol >= 1e-9 * diagonal && tol < 2e-9 * diagonal);
        growing.push(candidate).expect("push");
    }
}

#[test]
fn candidates_fail_and_pass_like_the_added_part_report_on_the_planned_channel_stack() {
    let plan = planned_channels();
    let stack = placements(&plan);
    for mu in [0.5, 0.1] {
        let compared = compare_candidates(&stack, &options(mu, 10.0), "planned channels");
        assert!(compared >= 2);
    }
}

#[test]
fn candidates_fail_and_pass_like_the_added_part_report_on_brick_walls() {
    let brick = box_part("brick", DVec3::new(40.0, 20.0, 10.0));
    let mut compared = 0;
    for (offset, overhang) in [(20.0, 0.0), (10.0, 0.0), (20.0, 35.0), (5.0, 90.0)] {
        let mut positions = Vec::new();
        for r in 0..4 {
            let shift = if r % 2 == 1 { offset } else { 0.0 } + if r == 3 { overhang } else { 0.0 };
            for k in 0..4 {
                positions.push(DVec3::new(40.0 * k as f64 + shift, 0.0, 10.0 * r as f64));
            }
        }
        let stack: Vec<PlacedPart<'_>> = positions.iter().map(|&p| at(&brick, p)).collect();
        compared += compare_candidates(&stack, &options(0.5, 10.0), &format!("wall {offset} {overhang}"));
    }
    assert!(compared >= 40, "only {compared} candidates compared");
}

/// Copies of a part at the same rotation and other positions share the grasp memo; a tilted copy (no upward face
/// for a large cup) and a cup just below and just above the largest radius are decided like the full report.
#[test]
fn the_grasp_memo_decides_like_the_grasp_at_each_pose() {
    let plank = box_part("plank", DVec3::new(60.0, 30.0, 5.0));
    let on_floor = |x: f64| at(&plank, DVec3::new(x, 0.0, 0.0));
    // the largest inscribed radius of the 60 x 30 top face is 15
    for cup in [29.0, 30.0 - 1e-9, 30.0, 30.0 + 1e-9, 31.0] {
        let o = options(0.5, cup);
        let mut growing = GrowingStack::new(&o).expect("options");
        let mut stack = Vec::new();
        for k in 0..4 {
            let candidate = on_floor(100.0 * k as f64 + 0.1 * k as f64);
            stack.push(candidate);
            let report = check_added_part(&stack, &o).expect("added");
            let tested = growing.check_candidate(candidate).expect("candidate");
            assert_eq!(tested.map(|a| a.grasp_radius.to_bits()), expected(&report).map(f64::to_bits), "cup {cup}");
            growing.push(candidate).expect("push");
        }
    }
    // tipped on its side: the top face is 60 x 5
    let side = PlacedPart {
        part: &plank,
        pose: Pose {
            rotation: DMat3::from_rotation_x(std::f64::consts::FRAC_PI_2),
            position: DVec3::new(0.0, 5.0, 0.0),
        },
    };
    let o = options(0.5, 10.0);
    let report = check_added_part(&[side], &o).expect("added");
    assert!(!report.graspable);
    let mut growing = GrowingStack::new(&o).expect("options");
    assert_eq!(growing.check_candidate(side).expect("candidate"), Err(Rejection::NotGraspable));
    let moved =
        PlacedPart { pose: Pose { position: side.pose.position + DVec3::new(3.0, 0.0, 0.0), ..side.pose }, ..side };
    assert_eq!(growing.check_candidate(moved).expect("candidate"), Err(Rejection::NotGraspable));
}

/// The memo of candidates found not stable on their supports: the same candidate is answered alike while no part
/// placed since comes near it, and tested again once one does (here a plank put under its overhang, on which it then
/// rests). Every answer is compared with a fresh stack's (no memo) and with `check_added_part`'s report; the parts
/// placed lie inside the first box, so the tolerance does not change and only the box test decides.
#[test]
fn a_candidate_found_not_stable_is_tested_again_once_a_part_placed_since_comes_near_it() {
    let plank = box_part("plank", DVec3::new(60.0, 30.0, 5.0));
    let o = options(0.5, 10.0);
    let base = at(&plank, DVec3::ZERO);
    let corner = at(&plank, DVec3::new(200.0, 100.0, 0.0));
    // on the base, its c.g. 10 mm beyond the base's edge: it tips over
    let overhanging = at(&plank, DVec3::new(40.0, 0.0, 5.0));
    // 20 mm beside the candidate: no contact with it
    let beside = at(&plank, DVec3::new(0.0, 50.0, 0.0));
    // under the overhang, 2 mm from the base: the candidate rests on both
    let under = at(&plank, DVec3::new(62.0, 0.0, 0.0));
    let mut growing = GrowingStack::new(&o).expect("options");
    let mut stack = vec![base, corner];
    for p in &stack {
        growing.push(*p).expect("push");
    }
    let tol = growing.tolerance_for(&overhanging).expect("pose");
    let first = growing.check_candidate(overhanging).expect("candidate");
    assert!(matches!(first, Err(Rejection::NotStable(_))), "{first:?}");
    for (added, stable) in [(beside, false), (under, true)] {
        stack.push(added);
        growing.push(added).expect("push");
        assert_eq!(growing.tolerance_for(&overhanging).expect("pose").to_bits(), tol.to_bits());
        let memoised = growing.check_candidate(overhanging).expect("candidate");
        let mut fresh = GrowingStack::new(&o).expect("options");
        for p in &stack {
            fresh.push(*p).expect("push");
        }
        assert_eq!(memoised, fresh.check_candidate(overhanging).expect("candidate"));
        let mut with = stack.clone();
        with.push(overhanging);
        let report =
            check_added_part(&with, &CheckOptions { contact_tolerance: Some(tol), ..o.clone() }).expect("added");
        assert_eq!(memoised.as_ref().err(), expected(&report).as_ref().err());
        assert_eq!(memoised.is_ok(), stable, "{memoised:?}");
    }
}

/// The memos key a part by its geometry, not by its address: a part dropped and another one built in its place
/// (with the allocator's reuse, usually at the same address), tested at the same pose and tolerance, is tested
/// afresh. A 100 mm plank overhanging the base is not stable; a 40 mm one at the same pose is.
#[test]
fn the_memos_answer_only_for_the_part_they_were_made_for() {
    let o = options(0.5, 10.0);
    let base_part = box_part("base", DVec3::new(60.0, 30.0, 5.0));
    let base = at(&base_part, DVec3::ZERO);
    // both candidates' boxes with the base's have a diagonal that rounds up to 128 mm: the same tolerance
    let mut growing = GrowingStack::new(&o).expect("options").with_tolerance_scale(ToleranceScale::PowerOfTwo);
    growing.push(base).expect("push");
    let mut fresh = GrowingStack::new(&o).expect("options").with_tolerance_scale(ToleranceScale::PowerOfTwo);
    fresh.push(base).expect("push");
    let pose = DVec3::new(20.0, 0.0, 5.0);
    for round in 0..8 {
        let long = Box::new(box_part("plank", DVec3::new(100.0, 30.0, 5.0)));
        let tol = growing.tolerance_for(&at(&long, pose)).expect("pose");
        let first = growing.check_candidate(at(&long, pose)).expect("candidate");
        assert!(matches!(first, Err(Rejection::NotStable(_))), "round {round}: {first:?}");
        drop(long);
        let short = Box::new(box_part("plank", DVec3::new(40.0, 30.0, 5.0)));
        assert_eq!(growing.tolerance_for(&at(&short, pose)).expect("pose").to_bits(), tol.to_bits());
        let tested = growing.check_candidate(at(&short, pose)).expect("candidate");
        assert_eq!(tested, fresh.check_candidate(at(&short, pose)).expect("candidate"), "round {round}");
        assert!(tested.is_ok(), "round {round}: {tested:?}");
    }
}

#[test]
fn options_a_growing_stack_cannot_honour_are_errors() {
    let mut o = options(0.5, 10.0);
    o.release_drops = vec![1.0];
    assert!(GrowingStack::new(&o).is_err());
    let mut o = options(0.5, 10.0);
    o.grasp.cup_diameter = f64::NAN;
    assert!(GrowingStack::new(&o).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig { cases: common::cases(16), ..ProptestConfig::default() })]

    /// Random box columns (two or three, placed layer by layer) with an optional plank bridging them on top.
    #[test]
    fn candidates_fail_and_pass_like_the_added_part_report_on_random_box_stacks(
        columns in 2usize..=3,
        layers in box_layers(10.0f64..30.0, 15.0, 30.0f64..70.0),
        bridge in prop::option::of((-30.0f64..30.0, 5.0f64..20.0)),
        mu in 0.1f64..1.0,
    ) {
        let mut boxes: Vec<(DVec3, DVec3)> = build(&layers, columns).into_iter().map(|(_, lo, size)| (lo, size)).collect();
        let z = boxes.iter().map(|(lo, size)| lo.z + size.z).fold(0.0, f64::max);
        if let Some((dx, thickness)) = bridge {
            let length = 200.0 * (columns - 1) as f64 + 40.0;
            boxes.push((DVec3::new(dx - 20.0, -10.0, z), DVec3::new(length, 20.0, thickness)));
        }
        let parts: Vec<stackplan_geom::Part> = boxes.iter().map(|(_, size)| box_part("box", *size)).collect();
        let stack: Vec<PlacedPart<'_>> = parts.iter().zip(&boxes).map(|(p, (lo, _))| at(p, *lo)).collect();
        compare_candidates(&stack, &options(mu, 10.0), "random boxes");
    }
}
