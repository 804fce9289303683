//! Placement of one part: golden cases by hand, errors, symmetry, determinism.

use glam::{DMat3, DVec3};
use stackplan_geom::{ConvexPolytope, Part, PartOrigin, Pose};
use stackplan_planner::reference::violations;
use stackplan_planner::{
    Contact, Cost, FloorVolume, NoPlacement, PlacedPart, PlacementError, PlacementRequest, place, uniform_thetas,
};

fn cuboid_part(lo: DVec3, hi: DVec3) -> Part {
    let component = ConvexPolytope::cuboid(lo, hi).expect("box");
    Part::from_components("box", vec![component], 1.0, PartOrigin::ConvexPieces).expect("part")
}

#[test]
fn box_goes_on_top_of_a_box() {
    let base = cuboid_part(DVec3::ZERO, DVec3::new(100.0, 100.0, 50.0));
    let small = cuboid_part(DVec3::ZERO, DVec3::new(50.0, 50.0, 50.0));
    let floor = FloorVolume::rectangle(-200.0, -200.0, 300.0, 300.0, 400.0);
    let stack = vec![PlacedPart { part: &base, pose: Pose::IDENTITY }];
    let mut req = PlacementRequest::new(&small, stack.clone(), floor);
    req.thetas = uniform_thetas(4);
    req.cost = Cost::Target { target: DVec3::new(50.0, 50.0, 0.0) };
    req.k = 3;
    let res = place(&req).expect("placement");
    assert!(!res.placements.is_empty());
    let best = &res.placements[0];
    assert!((best.cost - 75.0 * 75.0).abs() < 1e-6, "cost {}", best.cost);
    let pose = best.pose();
    let cg = pose.apply(small.mass().center_of_gravity);
    assert!((cg - DVec3::new(50.0, 50.0, 75.0)).length() < 1e-6, "c.g. {cg}");
    assert!(best.contacts.iter().any(|c| matches!(c, Contact::Stack { stack_part: 0, .. })), "{:?}", best.contacts);
    // sorted, and every one valid by the independent all-pairs check
    for w in res.placements.windows(2) {
        assert!(w[0].cost <= w[1].cost + 1e-9);
    }
    for p in &res.placements {
        let pose = p.pose();
        let v = violations(&small, pose.rotation, pose.position, &stack, &req, 1e-6, 5.0);
        assert!(v.is_empty(), "{v:?}");
    }
    // symmetry of a square box: one quarter turn searched
    assert_eq!(res.stats.symmetry_orders, vec![4]);
    assert_eq!(res.stats.orientations_searched, 1);
}

#[test]
fn w_zero_puts_it_on_the_floor_beside() {
    let base = cuboid_part(DVec3::ZERO, DVec3::new(100.0, 100.0, 50.0));
    let small = cuboid_part(DVec3::ZERO, DVec3::new(40.0, 20.0, 10.0));
    let floor = FloorVolume::rectangle(0.0, 0.0, 200.0, 100.0, 300.0);
    let stack = vec![PlacedPart { part: &base, pose: Pose::IDENTITY }];
    let mut req = PlacementRequest::new(&small, stack, floor);
    req.thetas = uniform_thetas(8);
    req.cost = Cost::Stacking { w: 0.0, origin: DVec3::ZERO };
    let res = place(&req).expect("placement");
    let best = &res.placements[0];
    // w = 0: only the c.g. height counts; on the floor beside the box: c.g. at z = 5, cost 4 * 25
    assert!((best.cost - 100.0).abs() < 1e-6, "cost {}", best.cost);
    assert!(best.position[2].abs() < 1e-6);
    assert!(best.contacts.contains(&Contact::Floor));
}

#[test]
fn errors_and_empty_results() {
    let big = cuboid_part(DVec3::ZERO, DVec3::new(100.0, 100.0, 50.0));
    let floor = FloorVolume::rectangle(0.0, 0.0, 50.0, 50.0, 300.0);
    let mut req = PlacementRequest::new(&big, vec![], floor.clone());
    req.thetas = uniform_thetas(4);
    let res = place(&req).expect("runs");
    assert!(res.placements.is_empty());
    assert_eq!(res.exhausted, Some(NoPlacement::EmptyOmega));
    // fits nowhere: the floor is fully occupied
    let small = cuboid_part(DVec3::ZERO, DVec3::new(10.0, 10.0, 10.0));
    let blocker = cuboid_part(DVec3::ZERO, DVec3::new(50.0, 50.0, 300.0));
    let mut req =
        PlacementRequest::new(&small, vec![PlacedPart { part: &blocker, pose: Pose::IDENTITY }], floor.clone());
    req.thetas = uniform_thetas(4);
    let res = place(&req).expect("runs");
    assert!(res.placements.is_empty());
    assert_eq!(res.exhausted, Some(NoPlacement::FitsNowhere));
    // bad options
    let mut req = PlacementRequest::new(&small, vec![], floor.clone());
    req.cost = Cost::Stacking { w: 1.5, origin: DVec3::ZERO };
    assert!(matches!(place(&req), Err(PlacementError::BadOption(_))));
    let mut req = PlacementRequest::new(&small, vec![], floor.clone());
    req.k = 0;
    assert!(matches!(place(&req), Err(PlacementError::BadOption(_))));
    let mut req = PlacementRequest::new(&small, vec![], floor.clone());
    req.thetas.clear();
    assert!(matches!(place(&req), Err(PlacementError::BadOption(_))));
    let mut req = PlacementRequest::new(&small, vec![], floor.clone());
    req.clearance = -1.0;
    assert!(matches!(place(&req), Err(PlacementError::BadOption(_))));
    let mut bad = floor.clone();
    bad.polygon.reverse();
    let req = PlacementRequest::new(&small, vec![], bad);
    assert!(matches!(place(&req), Err(PlacementError::BadFloor(_))));
    let mut req = PlacementRequest::new(&small, vec![], floor.clone());
    req.resting_rotations = vec![DMat3::from_diagonal(DVec3::new(1.0, 1.0, -1.0))];
    assert!(matches!(place(&req), Err(PlacementError::BadOption(_))));
    // fixed z outside the height range: empty Omega
    let mut req = PlacementRequest::new(&small, vec![], floor);
    req.fixed_z = Some(-5.0);
    assert_eq!(place(&req).expect("runs").exhausted, Some(NoPlacement::EmptyOmega));
}

/// Searches into a growing stack sharing `SearchCaches` (and one obstacle cache) give exactly the results of fresh
/// searches, also when a search with other settings (clearance, insertion) in between forces the caches to be
/// cleared, and when the stack is replaced by a different one.
#[test]
fn shared_search_caches_change_no_result() {
    use stackplan_cspace::ObstacleCache;
    use stackplan_planner::{SearchCaches, place_with_cache, place_with_caches};
    let part = cuboid_part(DVec3::ZERO, DVec3::new(40.0, 25.0, 15.0));
    let floor = FloorVolume::rectangle(0.0, 0.0, 120.0, 100.0, 200.0);
    let shared_obstacles = ObstacleCache::new();
    let mut caches = SearchCaches::new();
    let mut poses: Vec<Pose> = Vec::new();
    for step in 0..5 {
        let stack: Vec<PlacedPart<'_>> = poses.iter().map(|&pose| PlacedPart { part: &part, pose }).collect();
        let mut req = PlacementRequest::new(&part, stack, floor.clone());
        req.thetas = uniform_thetas(12);
        req.cost = Cost::Stacking { w: 0.6, origin: DVec3::new(60.0, 50.0, 0.0) };
        req.k = 3;
        // every other step: other settings in between (the caches must be dropped, then rebuilt)
        if step % 2 == 1 {
            let mut other = req.clone();
            other.clearance = 2.0;
            other.insertion = true;
            other.horizontal_clearance = true;
            let a = place_with_caches(&other, &shared_obstacles, &mut caches).expect("search");
            let b = place_with_cache(&other, &ObstacleCache::new()).expect("search");
            assert_eq!(a.placements, b.placements);
            assert_eq!(a.stats.pairs_evaluated, b.stats.pairs_evaluated);
        }
        let a = place_with_caches(&req, &shared_obstacles, &mut caches).expect("search");
        let b = place_with_cache(&req, &ObstacleCache::new()).expect("search");
        assert_eq!(a.placements, b.placements, "step {step}");
        assert_eq!(a.stats.nodes_expanded, b.stats.nodes_expanded);
        assert_eq!(a.stats.pairs_evaluated, b.stats.pairs_evaluated);
        let best = a.placements.first().expect("a placement");
        poses.push(best.pose());
    }
    // a different stack (the parts moved): cleared, same answers
    let moved: Vec<PlacedPart<'_>> = poses
        .iter()
        .rev()
        .map(|&pose| PlacedPart { part: &part, pose: Pose { position: pose.position + DVec3::X, ..pose } })
        .collect();
    let mut req = PlacementRequest::new(&part, moved, floor);
    req.thetas = uniform_thetas(12);
    let a = place_with_caches(&req, &ObstacleCache::new(), &mut caches).expect("search");
    let b = place_with_cache(&req, &ObstacleCache::new()).expect("search");
    assert_eq!(a.placements, b.placements);
}

/// The obstacle cache names parts by index only: reusing one for another moving part, or for another stack at the
/// same indices, is refused (it would return the other pair's obstacles), while a growing stack and the same
/// requests again are served; every answer equals a fresh cache's.
#[test]
fn an_obstacle_cache_serves_one_part_and_one_growing_stack() {
    use stackplan_cspace::ObstacleCache;
    use stackplan_planner::{SearchCaches, place_with_cache, place_with_caches};
    let base = cuboid_part(DVec3::ZERO, DVec3::new(100.0, 100.0, 50.0));
    let small = cuboid_part(DVec3::ZERO, DVec3::new(50.0, 50.0, 50.0));
    let plank = cuboid_part(DVec3::ZERO, DVec3::new(120.0, 30.0, 10.0));
    let floor = FloorVolume::rectangle(-200.0, -200.0, 300.0, 300.0, 400.0);
    let on_base = Pose { rotation: DMat3::IDENTITY, position: DVec3::new(0.0, 0.0, 50.0) };
    let request = |part, stack| {
        let mut req = PlacementRequest::new(part, stack, floor.clone());
        req.thetas = uniform_thetas(4);
        req.k = 2;
        req
    };
    let one = vec![PlacedPart { part: &base, pose: Pose::IDENTITY }];
    let two = vec![PlacedPart { part: &base, pose: Pose::IDENTITY }, PlacedPart { part: &small, pose: on_base }];
    let cache = ObstacleCache::new();
    let fresh = |req: &PlacementRequest<'_>| place(req).expect("placement").placements;
    for req in [request(&small, one.clone()), request(&small, two.clone()), request(&small, one.clone())] {
        assert_eq!(place_with_cache(&req, &cache).expect("placement").placements, fresh(&req));
    }
    // another moving part with the same cache
    let err = place_with_cache(&request(&plank, one.clone()), &cache);
    assert_eq!(err.map(|r| r.placements), Err(PlacementError::ForeignCache));
    // another stack: part 0 moved
    let moved = vec![PlacedPart { part: &base, pose: Pose { rotation: DMat3::IDENTITY, position: DVec3::X } }];
    let err = place_with_cache(&request(&small, moved.clone()), &cache);
    assert_eq!(err.map(|r| r.placements), Err(PlacementError::ForeignCache));
    // once the cache forgets the moved part, it serves the new stack
    cache.invalidate_part(0);
    let req = request(&small, moved);
    assert_eq!(place_with_cache(&req, &cache).expect("placement").placements, fresh(&req));
    // the search caches (derived obstacles, interval structures) are cleared when the part placed changes
    // (two planks: the same symmetry, so the same orientations and rotations)
    let other_plank = cuboid_part(DVec3::ZERO, DVec3::new(90.0, 40.0, 10.0));
    let mut caches = SearchCaches::new();
    for req in [request(&plank, one.clone()), request(&other_plank, one.clone()), request(&plank, two.clone())] {
        let got = place_with_caches(&req, &ObstacleCache::new(), &mut caches).expect("placement").placements;
        assert_eq!(got, fresh(&req));
    }
}
