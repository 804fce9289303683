//! Analytic cases of the issue: box on the floor, overhang, incline vs friction angle, seesaw.

use crate::common;
use stackplan_geom::Pose;

use common::{at, box_part, wedge_part};
use glam::{DMat3, DVec3};
use stackplan_stability::check::{CheckOptions, check_stack};
use stackplan_stability::contacts::analyse_contacts;
use stackplan_stability::equilibrium::{EquilibriumOptions, Verdict, solve_equilibrium};
use stackplan_stability::resting_poses::resting_poses;
use stackplan_stability::world::{PlacedPart, stack_tolerance, world_stack};

fn options(mu: f64) -> CheckOptions {
    let mut o = CheckOptions { mu, ..CheckOptions::default() };
    o.grasp.cup_diameter = 5.0;
    o
}

#[test]
fn box_on_floor_is_stable_with_margin_half_the_smaller_side() {
    let part = box_part("box", DVec3::new(4.0, 6.0, 2.0));
    let poses = resting_poses(&part).expect("poses");
    assert_eq!(poses.len(), 6);
    // lowest c.g. first: lying on the 4 x 6 face, margin = half the smaller side
    assert!((poses[0].cg_height - 1.0).abs() < 1e-12);
    assert!((poses[0].margin - 2.0).abs() < 1e-12, "{}", poses[0].margin);
    assert!((poses[5].cg_height - 3.0).abs() < 1e-12);
    assert!((poses[5].margin - 1.0).abs() < 1e-12);

    let mut o = options(0.5);
    o.grasp.cup_diameter = 3.0;
    let report = check_stack(&[at(&part, DVec3::ZERO)], &o).expect("check");
    assert!(report.ok, "{report:#?}");
    let p = &report.parts[0];
    assert_eq!(p.stable, Verdict::Stable);
    // 4 floor contact points carrying the weight (mass = volume = 48)
    let total: DVec3 = p.forces.iter().map(|f| f.force).sum();
    assert!((total - DVec3::new(0.0, 0.0, 48.0)).length() < 1e-5 * 48.0, "{total}");
    // horizontal load margin: sliding limits it to mu (tipping would need 2 / 1 = 2)
    let margin = p.margin.expect("margin");
    assert!((margin - 0.5).abs() < 1e-5, "{margin}");
}

/// The same box written turned by a general rotation, as a part file exported in another orientation: its faces are
/// planar only to rounding (the exact hull splits them, and the c.g. projects onto a crease), yet it has the same six
/// resting poses with the same margins. Before the poses were taken from the hull with its creases merged, the turned
/// box had none, and the built-in Triangle's bottom face a margin of 56.4 mm instead of 65.0.
#[test]
fn a_box_turned_in_its_file_rests_on_its_six_faces() {
    let turn = DMat3::from_euler(glam::EulerRot::ZYX, 0.17, 0.35, 0.52);
    let corners: Vec<DVec3> = (0..8)
        .map(|i| {
            let c = |bit: usize, e: f64| if i & bit == 0 { 0.0 } else { e };
            turn * DVec3::new(c(1, 4.0), c(2, 6.0), c(4, 2.0)) + DVec3::new(100.0, -30.0, 7.0)
        })
        .collect();
    let text = format!(
        r#"{{"name": "turned", "convex_pieces": [[{}]]}}"#,
        corners.iter().map(|v| format!("[{:?}, {:?}, {:?}]", v.x, v.y, v.z)).collect::<Vec<_>>().join(", ")
    );
    let part =
        stackplan_geom::io::parse_part_json(text.as_bytes(), std::path::Path::new("turned.json"), &Default::default())
            .expect("a turned box");
    let poses = resting_poses(&part).expect("poses");
    let mut margins: Vec<f64> = poses.iter().map(|p| p.margin).collect();
    margins.sort_by(f64::total_cmp);
    let expected = [1.0, 1.0, 1.0, 1.0, 2.0, 2.0]; // 4 x 2 and 6 x 2 sides: 1; the 4 x 6 sides: 2
    assert_eq!(margins.len(), 6, "{margins:?}");
    for (m, e) in margins.iter().zip(expected) {
        assert!((m - e).abs() < 1e-9, "margins {margins:?}");
    }
    // the built-in Triangle: its bottom face holds the c.g. 65 mm inside (the seed's Fig. 14(b) part lying flat)
    let triangle = stackplan_geom::examples::part_by_name("triangle", Default::default()).expect("triangle");
    let poses = resting_poses(&triangle).expect("poses");
    assert!(
        poses.iter().any(|p| (p.margin - 65.0).abs() < 1e-6),
        "{:?}",
        poses.iter().map(|p| p.margin).collect::<Vec<_>>()
    );
}

#[test]
fn tall_box_margin_is_limited_by_tipping() {
    // base 2 x 4, c.g. height 5: tipping at alpha = min(1, 2) / 5 = 0.2 < mu
    let part = box_part("tall", DVec3::new(2.0, 4.0, 10.0));
    let report = check_stack(&[at(&part, DVec3::ZERO)], &options(0.8)).expect("check");
    let margin = report.parts[0].margin.expect("margin");
    assert!((margin - 0.2).abs() < 1e-5, "{margin}");
    let whole = report.stack.margin.expect("stack margin");
    assert!((whole - 0.2).abs() < 1e-5, "{whole}");
}

#[test]
fn overhang_beyond_half_is_unstable() {
    let support = box_part("support", DVec3::new(10.0, 10.0, 2.0));
    let top = box_part("top", DVec3::new(10.0, 10.0, 2.0));
    for (shift, stable) in [(4.0, true), (4.9, true), (5.5, false), (6.0, false)] {
        let stack = [at(&support, DVec3::ZERO), at(&top, DVec3::new(shift, 0.0, 2.0))];
        let report = check_stack(&stack, &options(0.5)).expect("check");
        assert_eq!(report.parts[1].stable.is_stable(), stable, "shift {shift}: {:?}", report.parts[1].stable);
        assert_eq!(report.stack.verdict.is_stable(), stable, "shift {shift}: {:?}", report.stack.verdict);
        // the SOCP agrees with the pre-check: solve the two-part problem where the pre-check does not apply
        let parts = world_stack(&stack).expect("world");
        let tol = stack_tolerance(&parts).linear;
        let contacts = analyse_contacts(&parts, tol, |_| true);
        let eq =
            solve_equilibrium(&parts, &[true, true], &contacts.patches, &EquilibriumOptions::default()).expect("solve");
        assert!(!eq.decided_by_precheck);
        assert_eq!(eq.verdict.is_stable(), stable, "shift {shift}");
        if !stable {
            assert_eq!(eq.verdict, Verdict::Unstable);
        }
    }
}

/// A 20 mm cube resting on the slope of a wedge inclined by `beta`.
fn incline_case(beta: f64, mu: f64) -> Verdict {
    let length = 100.0;
    let height = length * beta.tan();
    let wedge = wedge_part("wedge", length, height, 40.0);
    let cube = box_part("cube", DVec3::splat(20.0));
    let rotation = DMat3::from_rotation_y(beta);
    let up_slope = DVec3::new(-beta.cos(), 0.0, beta.sin());
    let corner = DVec3::new(length, 10.0, 0.0) + up_slope * 60.0;
    let stack = [at(&wedge, DVec3::ZERO), PlacedPart { part: &cube, pose: Pose { rotation, position: corner } }];
    let report = check_stack(&stack, &options(mu)).expect("check");
    assert_eq!(report.parts[0].stable, Verdict::Stable);
    assert!(report.parts[1].interference == 0.0, "{:?}", report.parts[1]);
    // one polygon contact of the cube's face on the slope
    let slope_patches: Vec<_> = report.contacts.iter().filter(|c| c.b == 1).collect();
    assert_eq!(slope_patches.len(), 1);
    assert_eq!(slope_patches[0].points.len(), 4);
    assert!((slope_patches[0].normal - DVec3::new(beta.sin(), 0.0, beta.cos())).length() < 1e-9);
    assert_eq!(report.parts[1].stable, report.parts[1].stack_stable);
    report.parts[1].stable.clone()
}

#[test]
fn incline_below_and_above_the_friction_angle() {
    let beta = 20f64.to_radians();
    assert_eq!(incline_case(beta, beta.tan() * 1.2), Verdict::Stable);
    assert_eq!(incline_case(beta, beta.tan() * 0.8), Verdict::Unstable);
    let beta = 35f64.to_radians();
    assert_eq!(incline_case(beta, beta.tan() * 1.05), Verdict::Stable);
    assert_eq!(incline_case(beta, beta.tan() * 0.95), Verdict::Unstable);
}

#[test]
fn seesaw_new_part_stable_alone_but_not_the_stack() {
    let fulcrum = box_part("fulcrum", DVec3::new(2.0, 20.0, 10.0));
    let plank = box_part("plank", DVec3::new(100.0, 20.0, 2.0));
    let weight = box_part("weight", DVec3::new(10.0, 10.0, 10.0));
    let stack = [
        at(&fulcrum, DVec3::new(-1.0, -10.0, 0.0)),
        at(&plank, DVec3::new(-50.0, -10.0, 10.0)),
        at(&weight, DVec3::new(30.0, -5.0, 12.0)),
    ];
    let report = check_stack(&stack, &options(0.5)).expect("check");
    for p in &report.parts {
        assert_eq!(p.stable, Verdict::Stable, "part {} on fixed supports", p.index);
    }
    assert_eq!(report.parts[0].stack_stable, Verdict::Stable);
    assert_eq!(report.parts[1].stack_stable, Verdict::Stable);
    assert_eq!(report.parts[2].stack_stable, Verdict::Unstable);
    assert_eq!(report.stack.verdict, Verdict::Unstable);
    assert!(!report.ok && !report.parts[2].ok && report.parts[1].ok);
    // a balancing weight on the other side makes the whole stack stable again
    let counter = box_part("counter", DVec3::new(10.0, 10.0, 10.0));
    let mut balanced = stack.to_vec();
    balanced.push(at(&counter, DVec3::new(-40.0, -5.0, 12.0)));
    let report = check_stack(&balanced, &options(0.5)).expect("check");
    assert_eq!(report.stack.verdict, Verdict::Stable);
    // removing the weight first (reverse order) leaves a stack that tips: not removable
    assert!(!report.parts[3].removable);
}
