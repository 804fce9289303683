//! `check_added_part` (the planner's per-candidate test) against the whole-stack check: for every prefix
//! `stack[..=i]` whose stack without its last part is stable (the precondition), the report of the added part equals
//! `check_stack(&stack[..=i]).parts[i]` field for field (verdicts identical, margins within 1e-6 relative, forces
//! within the solver's tolerance). Stacks: columns of every fixture part (`fixtures/parts/*.json`) in its two lowest
//! resting poses, nested and shifted; the planned 15-part Channel stack; staggered brick walls (side contacts between
//! neighbours: one group for the whole wall, cyclic support graphs, overhangs that tip); random box columns with
//! planks, with and without clearance. (The whole check runs with `prefix_stability`, so that its `removable` reads
//! the stability of the stack left behind, which the precondition gives the added part's check.)

use crate::common;

use common::{at, box_layers, box_part, build, for_each_fixture_column, placements, planned_channels, same_margin};
use glam::DVec3;
use proptest::prelude::*;
use stackplan_stability::check::{CheckOptions, PartCheck, check_stack};
use stackplan_stability::check_added_part;
use stackplan_stability::equilibrium::ContactForce;
use stackplan_stability::world::PlacedPart;

fn options(mu: f64, margin_directions: usize, clearance: f64) -> CheckOptions {
    let mut o = CheckOptions { mu, margin_directions, clearance, prefix_stability: true, ..CheckOptions::default() };
    o.grasp.cup_diameter = 5.0;
    o
}

fn same_forces(a: &[ContactForce], b: &[ContactForce], weight: f64) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(f, g)| (f.patch, f.point) == (g.patch, g.point))
        && a.iter().zip(b).all(|(f, g)| (f.force - g.force).length() <= 1e-3 * weight)
}

/// The report of the added part equals the whole check's (see the module documentation).
fn assert_same_report(added: &PartCheck, whole: &PartCheck, weight: f64, what: &str) {
    assert_eq!(
        (added.index, &added.name, added.interference, &added.interferes_with),
        (whole.index, &whole.name, whole.interference, &whole.interferes_with),
        "{what}: interference"
    );
    assert_eq!(
        (added.min_horizontal_clearance, added.clearance_met),
        (whole.min_horizontal_clearance, whole.clearance_met),
        "{what}: clearance"
    );
    assert_eq!(added.stable, whole.stable, "{what}: stable on its supports");
    assert!(same_margin(added.margin, whole.margin), "{what}: margin {:?} vs {:?}", added.margin, whole.margin);
    assert!(same_forces(&added.forces, &whole.forces, weight), "{what}: forces");
    assert_eq!(added.stack_stable.is_stable(), whole.stack_stable.is_stable(), "{what}: stack verdict");
    if added.stack_stable.is_stable() || whole.stack_stable.is_stable() {
        assert_eq!(added.stack_stable, whole.stack_stable, "{what}: stack verdict");
    }
    // the whole check analyses the grasp once per class of translated copies (equal up to rounding)
    assert!(
        added.grasp_radius == whole.grasp_radius
            || (added.grasp_radius - whole.grasp_radius).abs() <= 1e-9 * (1.0 + whole.grasp_radius),
        "{what}: grasp radius {} vs {}",
        added.grasp_radius,
        whole.grasp_radius
    );
    assert_eq!(
        (added.graspable, added.insertable, &added.insertion_obstruction),
        (whole.graspable, whole.insertable, &whole.insertion_obstruction),
        "{what}: grasp and insertion"
    );
    assert_eq!((added.removable, added.ok), (whole.removable, whole.ok), "{what}: removable, ok");
}

/// Compares every addition of `stack` whose precondition holds; returns how many were compared.
fn compare_additions(stack: &[PlacedPart<'_>], options: &CheckOptions, weight: f64, what: &str) -> usize {
    let mut compared = 0;
    for i in 0..stack.len() {
        let before_stable = i == 0 || check_stack(&stack[..i], options).expect("check").stack.verdict.is_stable();
        if !before_stable {
            continue;
        }
        let whole = check_stack(&stack[..=i], options).expect("check");
        let added = check_added_part(&stack[..=i], options).expect("added");
        assert_same_report(&added, &whole.parts[i], weight, &format!("{what}, part {i}"));
        compared += 1;
    }
    compared
}

#[test]
fn added_parts_report_like_the_whole_check_on_fixture_columns() {
    let mut compared = 0;
    for_each_fixture_column(&[(0.0, 0.0), (7.0, -3.0), (40.0, 0.0)], |label, part, stack| {
        for (mu, directions, clearance) in [(0.4, 8, 0.0), (0.8, 0, 5.0)] {
            let what = format!("{label} mu {mu}");
            compared += compare_additions(stack, &options(mu, directions, clearance), part.mass().mass, &what);
        }
    });
    assert!(compared >= 100, "only {compared} additions compared");
}

#[test]
fn added_parts_report_like_the_whole_check_on_the_planned_channel_stack() {
    let plan = planned_channels();
    let stack = placements(&plan);
    let compared = compare_additions(&stack, &options(0.5, 0, 0.0), plan.part.mass().mass, "planned channels");
    assert_eq!(compared, stack.len());
}

/// A staggered wall of `rows` rows of `per_row` bricks (size 40 x 20 x 10), every other row shifted by `offset`;
/// neighbours in a row touch. The last row may be pushed out by `overhang` (it tips when the overhang is large).
fn brick_wall(rows: usize, per_row: usize, offset: f64, overhang: f64) -> Vec<DVec3> {
    let mut out = Vec::new();
    for r in 0..rows {
        let shift = if r % 2 == 1 { offset } else { 0.0 } + if r + 1 == rows { overhang } else { 0.0 };
        for k in 0..per_row {
            out.push(DVec3::new(40.0 * k as f64 + shift, 0.0, 10.0 * r as f64));
        }
    }
    out
}

#[test]
fn added_parts_report_like_the_whole_check_on_brick_walls() {
    let brick = box_part("brick", DVec3::new(40.0, 20.0, 10.0));
    let mut compared = 0;
    for (offset, overhang) in [(20.0, 0.0), (10.0, 0.0), (20.0, 35.0), (5.0, 90.0)] {
        let positions = brick_wall(4, 4, offset, overhang);
        let stack: Vec<PlacedPart<'_>> = positions.iter().map(|&p| at(&brick, p)).collect();
        let what = format!("wall offset {offset} overhang {overhang}");
        compared += compare_additions(&stack, &options(0.5, 0, 0.0), brick.mass().mass, &what);
    }
    assert!(compared >= 40, "only {compared} additions compared");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: common::cases(16), ..ProptestConfig::default() })]

    /// Random box columns (two or three, placed layer by layer) with an optional plank bridging them on top.
    #[test]
    fn added_parts_report_like_the_whole_check_on_random_box_stacks(
        columns in 2usize..=3,
        layers in box_layers(10.0f64..30.0, 15.0, 30.0f64..70.0),
        bridge in prop::option::of((-30.0f64..30.0, 5.0f64..20.0)),
        mu in 0.1f64..1.0,
        clearance in prop::sample::select(vec![0.0, 3.0, 60.0]),
    ) {
        let mut boxes: Vec<(DVec3, DVec3)> = build(&layers, columns).into_iter().map(|(_, lo, size)| (lo, size)).collect();
        let z = boxes.iter().map(|(lo, size)| lo.z + size.z).fold(0.0, f64::max);
        if let Some((dx, thickness)) = bridge {
            let length = 200.0 * (columns - 1) as f64 + 40.0;
            boxes.push((DVec3::new(dx - 20.0, -10.0, z), DVec3::new(length, 20.0, thickness)));
        }
        let parts: Vec<stackplan_geom::Part> =
            boxes.iter().map(|(_, size)| box_part("box", *size)).collect();
        let stack: Vec<PlacedPart<'_>> = parts.iter().zip(&boxes).map(|(p, (lo, _))| at(p, *lo)).collect();
        let weight = parts.iter().map(|p| p.mass().mass).fold(0.0, f64::max);
        compare_additions(&stack, &options(mu, 4, clearance), weight, "random boxes");
    }
}
