//! The planner's obstacles through constant-topology intervals (\[A\] IV-B, `interval_obstacles`): every extrapolated
//! obstacle equals the one constructed from scratch at its angle (same structure and provenance, coordinates within
//! 1e-9 relative), and searches with extrapolation find what searches that construct every obstacle find.

use crate::common;
use common::{box_or_l, boxes};

use glam::{DMat3, DVec3};
use proptest::prelude::*;
use stackplan_cspace::ObstacleCache;
use stackplan_cspace::minkowski::obstacle;
use stackplan_geom::{Part, Pose};
use stackplan_orient_interval::structure::relative_difference;
use stackplan_planner::detect::StackScene;
use stackplan_planner::interval_obstacles::{IntervalObstacles, ObstacleRoute};
use stackplan_planner::{Cost, FloorVolume, PlacedPart, PlacementRequest, place, thetas_with_step};

/// A wedge (a prism with an inclined face): extrapolation of edge-edge and inclined faces, not only boxes.
fn wedge(a: f64, b: f64, h: f64) -> Part {
    let pts: Vec<DVec3> = [(0.0, 0.0), (a, 0.0), (0.0, h)]
        .iter()
        .flat_map(|&(x, z)| [DVec3::new(x, 0.0, z), DVec3::new(x, b, z)])
        .collect();
    let hull = stackplan_geom::convex_hull(&pts).expect("wedge").polytope;
    Part::from_components("wedge", vec![hull], 1.0, stackplan_geom::PartOrigin::ConvexPieces).expect("part")
}

fn part_strategy() -> impl Strategy<Value = Part> {
    prop_oneof![
        box_or_l(10.0..40.0, 5.0..30.0, 5.0..20.0),
        (10.0f64..40.0, 10.0f64..40.0, 5.0f64..30.0).prop_map(|(a, b, h)| wedge(a, b, h)),
    ]
}

/// A resting rotation: as the part lies, or on its side.
fn rest_strategy() -> impl Strategy<Value = DMat3> {
    prop_oneof![Just(DMat3::IDENTITY), Just(DMat3::from_rotation_x(std::f64::consts::FRAC_PI_2))]
}

proptest! {
    #[test]
    fn extrapolated_obstacles_equal_constructed_ones(
        moving in part_strategy(),
        fixed in part_strategy(),
        rest in rest_strategy(),
        turn in 0.0f64..6.3,
        step_deg in 1.0f64..7.0,
    ) {
        let stack = [(&fixed, Pose { rotation: DMat3::from_rotation_z(turn), position: DVec3::new(15.0, -5.0, 0.0) })];
        let scene = StackScene::new(&stack);
        let cache = ObstacleCache::new();
        let mut store = IntervalObstacles::new();
        let mut extrapolated = 0;
        for k in 0..(90.0 / step_deg) as usize {
            let theta = (k as f64 * step_deg).to_radians();
            let rotation = DMat3::from_rotation_z(theta) * rest;
            for mi in 0..moving.components().len() {
                for (fi, sc) in scene.components.iter().enumerate() {
                    let (got, route) = store
                        .obstacle(&moving, mi, 0, rest, theta, rotation, fi, sc, &cache)
                        .expect("obstacle");
                    let built = obstacle(&moving.components()[mi], rotation, &sc.world).expect("constructed");
                    let difference = relative_difference(&got, &built);
                    prop_assert!(
                        difference.is_some_and(|d| d <= 1e-9),
                        "theta {theta} ({route:?}): structure or coordinates differ: {difference:?}"
                    );
                    if route == ObstacleRoute::Constructed {
                        // a construction is the cache's, bit for bit
                        prop_assert_eq!(got.polytope().vertices(), built.polytope().vertices());
                    } else {
                        extrapolated += 1;
                    }
                }
            }
        }
        // boxes about z keep one structure between alignments: at steps below 7 degrees most angles extrapolate
        prop_assert!(extrapolated > 0, "nothing extrapolated");
    }

    #[test]
    fn searches_agree_with_and_without_extrapolation(
        part in part_strategy(),
        stack_part in part_strategy(),
        x in 0.0f64..60.0,
        y in 0.0f64..60.0,
        turn in 0usize..8,
        w in 0.1f64..0.9,
    ) {
        let pose = Pose { rotation: DMat3::from_rotation_z(turn as f64 * 0.4), position: DVec3::new(x, y, 0.0) };
        let floor = FloorVolume::rectangle(-20.0, -20.0, 100.0, 100.0, 150.0);
        let mut request = PlacementRequest::new(&part, vec![PlacedPart { part: &stack_part, pose }], floor);
        request.thetas = thetas_with_step(5f64.to_radians()).expect("step");
        request.cost = Cost::Stacking { w, origin: DVec3::new(40.0, 40.0, 0.0) };
        request.k = 3;
        let with = place(&request).expect("search");
        request.tuning.extrapolate = false;
        let without = place(&request).expect("search");
        prop_assert_eq!(without.stats.obstacles_extrapolated, 0);
        prop_assert_eq!(with.placements.len(), without.placements.len());
        for (a, b) in with.placements.iter().zip(&without.placements) {
            // equal costs (ties between equal-cost cells may come in either order, so positions are not compared)
            prop_assert!((a.cost - b.cost).abs() <= 1e-9 * (1.0 + a.cost.abs()), "{} vs {}", a.cost, b.cost);
        }
        prop_assert_eq!(
            with.stats.obstacles_constructed + with.stats.obstacles_extrapolated,
            without.stats.obstacles_constructed
        );
    }
}

/// A wedge placed on a tray at 1-degree steps: most obstacles are extrapolated, and the placements
/// cost what constructing every obstacle gives.
#[test]
fn most_obstacles_of_a_fine_theta_set_are_extrapolated() {
    let stack_part = boxes("tray", &[(DVec3::ZERO, DVec3::new(60.0, 40.0, 5.0))]);
    let part = wedge(30.0, 20.0, 15.0);
    let pose = Pose { rotation: DMat3::IDENTITY, position: DVec3::ZERO };
    let floor = FloorVolume::rectangle(-10.0, -10.0, 70.0, 50.0, 100.0);
    let mut request = PlacementRequest::new(&part, vec![PlacedPart { part: &stack_part, pose }], floor);
    request.thetas = thetas_with_step(1f64.to_radians()).expect("step");
    request.cost = Cost::Target { target: DVec3::new(30.0, 20.0, 0.0) };
    request.k = 5;
    let with = place(&request).expect("search");
    request.tuning.extrapolate = false;
    let without = place(&request).expect("search");
    assert!(
        with.stats.obstacles_extrapolated > with.stats.obstacles_constructed,
        "constructed {} extrapolated {}",
        with.stats.obstacles_constructed,
        with.stats.obstacles_extrapolated
    );
    assert_eq!(with.placements.len(), without.placements.len());
    for (a, b) in with.placements.iter().zip(&without.placements) {
        assert!((a.cost - b.cost).abs() <= 1e-9 * (1.0 + a.cost.abs()));
    }
}
