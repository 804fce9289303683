//! The search at a fixed `p_z` (the seed's 2-D `Omega`, \[A\] VI-A and 7.1.2) against brute force: a dense grid of
//! positions `(x, y, fixed_z)` inside the 2-D permissible set of every orientation, each checked for penetration
//! pair by pair (`stackplan-cspace`'s all-pairs narrow phase, independent of the search's obstacles and cells). No
//! free sample may beat the search's optimum; when the search finds nothing, no sample may be free; every returned
//! placement lies at `fixed_z`, inside the floor volume and free of interference.

use crate::common;

use glam::{DMat3, DVec3};
use proptest::prelude::*;
use stackplan_cspace::interference::{PairContact, PlacedScene};
use stackplan_geom::{Part, Pose};
use stackplan_planner::orientation::Orientation;
use stackplan_planner::reference::violations;
use stackplan_planner::{Cost, FloorVolume, NoPlacement, PlacedPart, PlacementRequest, place, uniform_thetas};

/// A box or an L of two boxes (concave, two components).
fn part_strategy() -> impl Strategy<Value = Part> {
    common::box_or_l(10.0..35.0, 5.0..25.0, 5.0..15.0)
}

#[derive(Debug)]
struct Case {
    part: Part,
    stack_parts: Vec<Part>,
    poses: Vec<Pose>,
    w: Option<f64>,
    n_theta: usize,
    fixed_z: f64,
}

const FLOOR: (f64, f64, f64, f64, f64) = (-10.0, -10.0, 90.0, 90.0, 120.0);

fn case_strategy() -> impl Strategy<Value = Case> {
    (
        part_strategy(),
        prop::collection::vec((part_strategy(), 0.0f64..55.0, 0.0f64..55.0, 0usize..8, 0.0f64..10.0), 1..4),
        prop::option::of(0.05f64..0.95),
        2usize..6,
        0.0f64..20.0,
    )
        .prop_map(|(part, stack, w, n_theta, fixed_z)| {
            let mut stack_parts = Vec::new();
            let mut poses = Vec::new();
            for (p, x, y, k, z) in stack {
                poses.push(Pose { rotation: DMat3::from_rotation_z(k as f64 * 0.4), position: DVec3::new(x, y, z) });
                stack_parts.push(p);
            }
            Case { part, stack_parts, poses, w, n_theta, fixed_z }
        })
}

fn request<'a>(c: &'a Case) -> PlacementRequest<'a> {
    let stack: Vec<PlacedPart<'a>> =
        c.stack_parts.iter().zip(&c.poses).map(|(p, pose)| PlacedPart { part: p, pose: *pose }).collect();
    let (x0, y0, x1, y1, h) = FLOOR;
    let mut req = PlacementRequest::new(&c.part, stack, FloorVolume::rectangle(x0, y0, x1, y1, h));
    req.thetas = uniform_thetas(c.n_theta);
    req.tuning.use_symmetry = false;
    req.fixed_z = Some(c.fixed_z);
    req.cost = match c.w {
        Some(w) => Cost::Stacking { w, origin: DVec3::new(40.0, 40.0, 0.0) },
        None => Cost::Target { target: DVec3::new(40.0, 40.0, 5.0) },
    };
    req.k = 3;
    req
}

/// Whether the part at (rotation, p) is free of penetration deeper than `tol` (pair by pair).
fn free(scene: &PlacedScene, part: &Part, r: DMat3, p: DVec3, tol: f64) -> bool {
    !scene
        .interference_pairs_brute_force(part, r, p, 0.0)
        .iter()
        .any(|x| matches!(x.contact, PairContact::Penetrating { depth } if depth > tol))
}

proptest! {
    #[test]
    fn fixed_z_optimum_beats_every_free_sample(c in case_strategy()) {
        let req = request(&c);
        let res = place(&req).expect("search");
        for w in res.placements.windows(2) {
            prop_assert!(w[0].cost <= w[1].cost + 1e-9);
        }
        for p in &res.placements {
            prop_assert!((p.position[2] - c.fixed_z).abs() <= 1e-12, "p_z {} != {}", p.position[2], c.fixed_z);
            let pose = p.pose();
            let v = violations(&c.part, pose.rotation, pose.position, &req.stack, &req, 1e-6, 2.0);
            prop_assert!(v.is_empty(), "{:?}", v);
        }
        let scene = PlacedScene::new(&req.stack);
        let best = res.placements.first().map_or(f64::INFINITY, |b| b.cost);
        let (x0, y0, x1, y1, h) = FLOOR;
        let mut any_omega = false;
        for (ti, &theta) in req.thetas.iter().enumerate() {
            let o = Orientation::new(&c.part, ti, 0, ti, theta, DMat3::IDENTITY, &req.cost);
            // the 2-D permissible set of a rectangle: a box of (x, y), empty when z leaves [0, H]
            if c.fixed_z + o.lo.z < -1e-9 || c.fixed_z + o.hi.z > h + 1e-9 {
                continue;
            }
            let lo = DVec3::new(x0 - o.lo.x, y0 - o.lo.y, c.fixed_z);
            let hi = DVec3::new(x1 - o.hi.x, y1 - o.hi.y, c.fixed_z);
            if lo.x > hi.x || lo.y > hi.y {
                continue;
            }
            any_omega = true;
            let n = 40;
            for i in 0..=n {
                for j in 0..=n {
                    let p = DVec3::new(
                        lo.x + (hi.x - lo.x) * i as f64 / n as f64,
                        lo.y + (hi.y - lo.y) * j as f64 / n as f64,
                        c.fixed_z,
                    );
                    let cost = o.quadratic.value(&p.to_array());
                    if cost < best - 1e-6 * (1.0 + best.abs()) && free(&scene, &c.part, o.rotation, p, 1e-6) {
                        prop_assert!(
                            false,
                            "free sample {p} at theta {theta} costs {cost} < search optimum {best} ({:?}, {:?})",
                            res.exhausted,
                            res.stats
                        );
                    }
                }
            }
        }
        if !any_omega {
            prop_assert!(res.placements.is_empty());
            prop_assert_eq!(res.exhausted, Some(NoPlacement::EmptyOmega));
        }
    }
}
