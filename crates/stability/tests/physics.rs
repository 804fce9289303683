//! Physics cross-check with rapier3d-f64: stacks the check calls stable stay put for 3 simulated seconds (no point of
//! any part moves more than 1 mm); stacks it calls unstable move.
//!
//! The simulation runs in millimetres (gravity 9810 mm/s^2, rapier's `length_unit` = 100 so its internal slops suit
//! parts of about 100 mm), one dynamic body per part with a convex-hull collider per component, friction `mu` on
//! every collider (rapier averages the two coefficients, so every contact gets `mu`),
//! time step 1/480 s, contact springs stiffened to 200 Hz (400 Hz against the floor) so that the elastic sag and tilt of a
//! column stays well below the 1 mm threshold, contact recycling off (with it, light boxes on top of a column creep
//! sideways by millimetres), the floor a large fixed slab.

mod common;

use common::{at, box_part, wedge_part};
use glam::{DMat3, DQuat, DVec3};
use proptest::prelude::*;
use rapier3d_f64::prelude::*;
use stackplan_stability::check::{CheckOptions, check_stack};
use stackplan_stability::equilibrium::Verdict;
use stackplan_stability::world::{PlacedPart, world_stack};

/// Largest displacement (mm) of any part after `seconds` of simulation: horizontal c.g. displacement plus rotation
/// angle times the part's radius about its c.g. (an upper bound of any point's displacement, vertical sag excluded).
fn simulate(stack: &[PlacedPart<'_>], mu: f64, seconds: f64) -> f64 {
    let parts = world_stack(stack).expect("world");
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::new(0.0, 0.0, -9810.0);
    world.integration_parameters.length_unit = 100.0;
    world.integration_parameters.dt = 1.0 / 480.0;
    world.integration_parameters.num_solver_iterations = 8;
    world.integration_parameters.contact_recycling = false;
    // stiffer contacts than rapier's defaults (30 Hz / 60 Hz against fixed bodies): the default springs let a
    // three-box column sag by more than a millimetre under its own weight
    world.integration_parameters.contact_softness = SpringCoefficients::new(200.0, 10.0);
    world.integration_parameters.static_contact_softness = SpringCoefficients::new(400.0, 10.0);
    let ground = world.insert_body(RigidBodyBuilder::fixed());
    // the floor: a large fixed slab with its top face at z = 0
    world.insert_collider(
        ColliderBuilder::cuboid(5000.0, 5000.0, 50.0).translation(Vector::new(0.0, 0.0, -50.0)).friction(mu),
        Some(ground),
    );
    let mut bodies = Vec::new();
    for p in &parts {
        let cg = p.center_of_gravity;
        let body = world.insert_body(RigidBodyBuilder::dynamic().translation(cg).can_sleep(false));
        let mut radius: f64 = 0.0;
        for c in &p.components {
            let local: Vec<Vector> = c.polytope.vertices().iter().map(|v| *v - cg).collect();
            radius = local.iter().fold(radius, |r, v| r.max(v.length()));
            let collider = ColliderBuilder::convex_hull(&local).expect("hull").friction(mu).density(1e-6);
            world.insert_collider(collider, Some(body));
        }
        bodies.push((body, cg, radius));
    }
    let steps = (seconds / world.integration_parameters.dt).round() as usize;
    for _ in 0..steps {
        world.step();
    }
    bodies
        .iter()
        .map(|&(h, cg, radius)| {
            let b = &world.bodies[h];
            // vertical sag of rapier's compliant contacts is not motion in the sense of the check: measure the
            // horizontal displacement of the c.g. plus the largest displacement that the rotation causes
            let d = b.translation() - cg;
            let moved = (d.x * d.x + d.y * d.y).sqrt();
            let q: DQuat = *b.rotation();
            let angle = q.angle_between(DQuat::IDENTITY);
            moved + angle * radius
        })
        .fold(0.0, f64::max)
}

fn opts(mu: f64) -> CheckOptions {
    let mut o = CheckOptions { mu, margin_directions: 0, ..CheckOptions::default() };
    o.grasp.cup_diameter = 5.0;
    o
}

#[test]
fn boxes_on_boxes_stay_put() {
    let a = box_part("a", DVec3::new(100.0, 80.0, 30.0));
    let b = box_part("b", DVec3::new(60.0, 60.0, 40.0));
    let c = box_part("c", DVec3::new(50.0, 30.0, 20.0));
    let stack = [at(&a, DVec3::ZERO), at(&b, DVec3::new(30.0, 10.0, 30.0)), at(&c, DVec3::new(45.0, 20.0, 70.0))];
    let report = check_stack(&stack, &opts(0.5)).expect("check");
    assert_eq!(report.stack.verdict, Verdict::Stable);
    let moved = simulate(&stack, 0.5, 3.0);
    assert!(moved < 1.0, "a stable stack moved {moved} mm");
}

#[test]
fn overhanging_box_falls() {
    let a = box_part("a", DVec3::new(100.0, 100.0, 20.0));
    let b = box_part("b", DVec3::new(100.0, 100.0, 20.0));
    let stack = [at(&a, DVec3::ZERO), at(&b, DVec3::new(60.0, 0.0, 20.0))];
    let report = check_stack(&stack, &opts(0.5)).expect("check");
    assert_eq!(report.stack.verdict, Verdict::Unstable);
    let moved = simulate(&stack, 0.5, 3.0);
    assert!(moved > 1.0, "an unstable stack moved only {moved} mm");
}

#[test]
fn incline_sticks_or_slides_as_predicted() {
    let beta = 25f64.to_radians();
    let length = 200.0;
    let wedge = wedge_part("wedge", length, length * beta.tan(), 80.0);
    let cube = box_part("cube", DVec3::splat(40.0));
    let up_slope = DVec3::new(-beta.cos(), 0.0, beta.sin());
    let stack = [
        at(&wedge, DVec3::ZERO),
        PlacedPart {
            part: &cube,
            rotation: DMat3::from_rotation_y(beta),
            position: DVec3::new(length, 20.0, 0.0) + up_slope * 120.0,
        },
    ];
    for (factor, stable) in [(1.3, true), (0.6, false)] {
        let mu = beta.tan() * factor;
        let report = check_stack(&stack, &opts(mu)).expect("check");
        assert_eq!(report.stack.verdict.is_stable(), stable, "mu factor {factor}");
        let moved = simulate(&stack, mu, 3.0);
        if stable {
            assert!(moved < 1.0, "mu factor {factor}: moved {moved} mm");
        } else {
            assert!(moved > 1.0, "mu factor {factor}: moved only {moved} mm");
        }
    }
}

#[test]
fn seesaw_tips() {
    let fulcrum = box_part("fulcrum", DVec3::new(40.0, 60.0, 40.0));
    let plank = box_part("plank", DVec3::new(300.0, 60.0, 10.0));
    let weight = box_part("weight", DVec3::new(40.0, 40.0, 40.0));
    let stack = [
        at(&fulcrum, DVec3::new(-20.0, -30.0, 0.0)),
        at(&plank, DVec3::new(-150.0, -30.0, 40.0)),
        at(&weight, DVec3::new(90.0, -20.0, 50.0)),
    ];
    let report = check_stack(&stack, &opts(0.5)).expect("check");
    assert!(report.parts[2].stable.is_stable());
    assert_eq!(report.stack.verdict, Verdict::Unstable);
    assert!(simulate(&stack, 0.5, 3.0) > 1.0);
    // without the weight the plank balances
    assert!(check_stack(&stack[..2], &opts(0.5)).expect("check").stack.verdict.is_stable());
    assert!(simulate(&stack[..2], 0.5, 3.0) < 1.0);
}

/// Analytic stability of a column of axis-aligned boxes, each resting on the previous one: for every level, the
/// combined c.g. of everything above must lie inside the contact rectangle. Returns the smallest signed distance
/// (positive inside) over the levels.
fn column_margin(boxes: &[(DVec3, DVec3)]) -> f64 {
    let mut worst = f64::INFINITY;
    for k in 1..boxes.len() {
        let (lo, hi) = (boxes[k - 1].0.max(boxes[k].0), boxes[k - 1].1.min(boxes[k].1));
        let mut m = 0.0;
        let mut moment = DVec3::ZERO;
        for (blo, bhi) in &boxes[k..] {
            let size = *bhi - *blo;
            let mass = size.x * size.y * size.z;
            m += mass;
            moment += (*blo + *bhi) * 0.5 * mass;
        }
        let c = moment / m;
        let d = (c.x - lo.x).min(hi.x - c.x).min(c.y - lo.y).min(hi.y - c.y);
        worst = worst.min(d);
    }
    worst
}

proptest! {
    #![proptest_config(ProptestConfig { cases: std::env::var("PROPTEST_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(16), ..ProptestConfig::default() })]

    /// Random columns of 2-4 boxes with random offsets: the check agrees with the analytic criterion; the simulation
    /// stays put when the check finds a robustness margin of at least 0.5 (a column that resists a sideways push of
    /// 50 % of its weight: below about 0.3, rapier's compliant contacts tilt columns with off-centre loads by more
    /// than 1 mm while they settle), and moves
    /// when the combined c.g. above some level lies more than 3 mm outside its support.
    #[test]
    fn random_columns_agree_with_physics(
        sizes in prop::collection::vec((30.0f64..80.0, 30.0f64..80.0, 10.0f64..30.0), 2..=4),
        offsets in prop::collection::vec((-25.0f64..25.0, -25.0f64..25.0), 3),
    ) {
        let mut boxes = Vec::new();
        let mut z = 0.0;
        let mut centre = (0.0, 0.0);
        for (k, &(sx, sy, sz)) in sizes.iter().enumerate() {
            if k > 0 {
                centre.0 += offsets[k - 1].0;
                centre.1 += offsets[k - 1].1;
            }
            let lo = DVec3::new(centre.0 - sx / 2.0, centre.1 - sy / 2.0, z);
            boxes.push((lo, lo + DVec3::new(sx, sy, sz)));
            z += sz;
        }
        // keep only columns where consecutive boxes overlap (otherwise there is no contact at all)
        let overlapping = boxes.windows(2).all(|w| {
            let lo = w[0].0.max(w[1].0);
            let hi = w[0].1.min(w[1].1);
            hi.x - lo.x > 1.0 && hi.y - lo.y > 1.0
        });
        prop_assume!(overlapping);
        let parts: Vec<_> = boxes.iter().enumerate().map(|(k, (lo, hi))| box_part(&format!("b{k}"), *hi - *lo)).collect();
        let stack: Vec<PlacedPart<'_>> = parts.iter().zip(&boxes).map(|(p, (lo, _))| at(p, *lo)).collect();
        let report = check_stack(&stack, &CheckOptions { margin_directions: 8, ..opts(0.6) }).expect("check");
        let margin = column_margin(&boxes);
        if margin.abs() > 1e-6 {
            prop_assert_eq!(report.stack.verdict.is_stable(), margin > 0.0, "margin {}", margin);
        }
        if report.stack.margin.is_some_and(|alpha| alpha >= 0.5) {
            let moved = simulate(&stack, 0.6, 3.0);
            prop_assert!(moved < 1.0, "stable column moved {} mm", moved);
        } else if margin < -3.0 {
            let moved = simulate(&stack, 0.6, 3.0);
            prop_assert!(moved > 1.0, "unstable column moved only {} mm", moved);
        }
    }
}
