//! Exactness of the best-first search against brute force (\[A\] eq. 9): the complete obstacle of every pair at every
//! orientation subtracted from Omega, minimised over every cell; a dense sample of positions checked pair by pair;
//! every returned placement checked by an independent all-pairs test.

use crate::common;
use common::boxes;

use glam::{DMat3, DVec3};
use proptest::prelude::*;
use stackplan_cspace::interference::{PairContact, PlacedScene};
use stackplan_geom::{Part, Pose};
use stackplan_planner::orientation::Orientation;
use stackplan_planner::reference::{complete_optimum, violations};
use stackplan_planner::{Cost, FloorVolume, PlacedPart, PlacementRequest, place, uniform_thetas};

/// A box or an L of two boxes (concave, two components).
fn part_strategy() -> impl Strategy<Value = Part> {
    common::box_or_l(10.0..40.0, 5.0..30.0, 5.0..20.0)
}

#[derive(Debug)]
struct Case {
    part: Part,
    stack_parts: Vec<Part>,
    poses: Vec<Pose>,
    w: Option<f64>,
    n_theta: usize,
}

fn case_strategy() -> impl Strategy<Value = Case> {
    (
        part_strategy(),
        prop::collection::vec((part_strategy(), 0.0f64..60.0, 0.0f64..60.0, 0usize..8), 1..3),
        prop::option::of(0.05f64..0.95),
        3usize..6,
    )
        .prop_map(|(part, stack, w, n_theta)| {
            let mut stack_parts = Vec::new();
            let mut poses = Vec::new();
            for (p, x, y, k) in stack {
                poses.push(Pose { rotation: DMat3::from_rotation_z(k as f64 * 0.4), position: DVec3::new(x, y, 0.0) });
                stack_parts.push(p);
            }
            Case { part, stack_parts, poses, w, n_theta }
        })
}

fn request<'a>(c: &'a Case) -> PlacementRequest<'a> {
    let stack: Vec<PlacedPart<'a>> =
        c.stack_parts.iter().zip(&c.poses).map(|(p, pose)| PlacedPart { part: p, pose: *pose }).collect();
    let floor = FloorVolume::rectangle(-20.0, -20.0, 100.0, 100.0, 150.0);
    let mut req = PlacementRequest::new(&c.part, stack, floor);
    req.thetas = uniform_thetas(c.n_theta);
    req.tuning.use_symmetry = false;
    req.cost = match c.w {
        Some(w) => Cost::Stacking { w, origin: DVec3::new(40.0, 40.0, 0.0) },
        None => Cost::Target { target: DVec3::new(40.0, 40.0, 5.0) },
    };
    req.k = 4;
    req
}

/// Whether the part at (rotation, p) is free of penetration (pair by pair).
fn free(scene: &PlacedScene, part: &Part, r: DMat3, p: DVec3, tol: f64) -> bool {
    !scene
        .interference_pairs_brute_force(part, r, p, 0.0)
        .iter()
        .any(|x| matches!(x.contact, PairContact::Penetrating { depth } if depth > tol))
}

proptest! {
    #[test]
    fn optimum_equals_brute_force(c in case_strategy()) {
        let req = request(&c);
        let res = place(&req).expect("search");
        let reference = complete_optimum(&req).expect("reference");
        match (&reference, res.placements.first()) {
            (None, None) => {}
            (Some((cost, ti, at)), Some(best)) => {
                let rot = DMat3::from_rotation_z(req.thetas[*ti]);
                let why = violations(&c.part, rot, *at, &req.stack, &req, 1e-6, 2.0);
                prop_assert!(
                    (best.cost - cost).abs() <= 1e-6 * (1.0 + cost.abs()),
                    "search {} at {:?} theta {} vs brute force {} at {} theta {}; brute-force point violates {:?}; stats {:?}",
                    best.cost, best.position, best.theta, cost, at, req.thetas[*ti], why, res.stats
                );
            }
            (r, b) => prop_assert!(false, "reference {:?} vs search {:?}", r, b.map(|b| b.cost)),
        }
        // sorted, distinct, valid
        for w in res.placements.windows(2) {
            prop_assert!(w[0].cost <= w[1].cost + 1e-9);
            prop_assert!(w[0].position != w[1].position || w[0].theta != w[1].theta);
        }
        for p in &res.placements {
            let pose = p.pose();
            let v = violations(&c.part, pose.rotation, pose.position, &req.stack, &req, 1e-6, 2.0);
            prop_assert!(v.is_empty(), "{:?}", v);
        }
        // dense sample: no free position of any orientation beats the optimum
        let placements: Vec<stackplan_geom::PlacedPart<'_>> =
            req.stack.to_vec();
        let scene = PlacedScene::new(&placements);
        let best = res.placements.first().map(|b| b.cost).unwrap_or(f64::INFINITY);
        for (ti, &theta) in req.thetas.iter().enumerate() {
            let o = Orientation::new(&c.part, ti, 0, ti, theta, DMat3::IDENTITY, &req.cost);
            let lo = DVec3::new(-20.0 - o.lo.x, -20.0 - o.lo.y, -o.lo.z);
            let hi = DVec3::new(100.0 - o.hi.x, 100.0 - o.hi.y, 150.0 - o.hi.z);
            let n = 14;
            for i in 0..=n {
                for j in 0..=n {
                    for k in 0..=6 {
                        let p = DVec3::new(
                            lo.x + (hi.x - lo.x) * i as f64 / n as f64,
                            lo.y + (hi.y - lo.y) * j as f64 / n as f64,
                            lo.z + (hi.z - lo.z) * (k as f64 / 6.0).powi(2),
                        );
                        let cost = o.quadratic.value(&p.to_array());
                        if cost < best - 1e-6 * (1.0 + best.abs()) && free(&scene, &c.part, o.rotation, p, 1e-6) {
                            prop_assert!(false, "sample {p} at theta {theta} costs {cost} < optimum {best}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn clearance_and_insertion_are_respected(c in case_strategy(), delta in 0.5f64..4.0, insertion in any::<bool>()) {
        let mut req = request(&c);
        req.clearance = delta;
        req.insertion = insertion;
        let res = place(&req).expect("search");
        let mut plain = request(&c);
        plain.k = 1;
        let base = place(&plain).expect("search");
        if let (Some(b), Some(p)) = (base.placements.first(), res.placements.first()) {
            prop_assert!(p.cost >= b.cost - 1e-6 * (1.0 + b.cost.abs()), "constrained {} < unconstrained {}", p.cost, b.cost);
        }
        for p in &res.placements {
            let pose = p.pose();
            let v = violations(&c.part, pose.rotation, pose.position, &req.stack, &req, 1e-6, 1.0);
            prop_assert!(v.is_empty(), "{:?}", v);
        }
    }
}

#[test]
fn deterministic_across_thread_counts() {
    let part = boxes(
        "l",
        &[(DVec3::ZERO, DVec3::new(30.0, 8.0, 10.0)), (DVec3::new(0.0, 8.0, 0.0), DVec3::new(8.0, 30.0, 10.0))],
    );
    let stack_part = boxes("box", &[(DVec3::ZERO, DVec3::new(40.0, 25.0, 20.0))]);
    let c = Case {
        part,
        stack_parts: vec![stack_part.clone(), stack_part],
        poses: vec![
            Pose { rotation: DMat3::from_rotation_z(0.3), position: DVec3::new(30.0, 30.0, 0.0) },
            Pose { rotation: DMat3::IDENTITY, position: DVec3::new(10.0, 60.0, 0.0) },
        ],
        w: Some(0.5),
        n_theta: 36,
    };
    let req = request(&c);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
        pool.install(|| place(&req).expect("search"))
    };
    let a = run(1);
    let b = run(2);
    assert_eq!(a.placements, b.placements);
    assert_eq!(a.stats.nodes_expanded, b.stats.nodes_expanded);
    assert_eq!(a.stats.pairs_evaluated, b.stats.pairs_evaluated);
    assert!(!a.placements.is_empty());
}
