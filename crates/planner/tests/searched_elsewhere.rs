//! A search that leaves a region to another search ([`SearchTuning::searched_elsewhere`](stackplan_planner::request::SearchTuning::searched_elsewhere), the stacking planner's
//! stage 2 outside stage 1's region): its placements never lie inside the region, and together with a search of the
//! region it finds the exact optimum of the whole floor; also when both carry their frontiers into a growing stack
//! and a growing region, as the planner's searches do.

use crate::common;

use common::growing_stack_request;
use glam::DVec2;
use stackplan_cspace::ObstacleCache;
use stackplan_geom::examples::part_by_name;
use stackplan_geom::sheet_metal::Decomposition;
use stackplan_geom::{Part, Pose};
use stackplan_planner::reference::violations;
use stackplan_planner::{
    FloorVolume, PlacedPart, Placement, PlacementError, PlacementRequest, PlacementSearch, SearchCaches,
    place_with_caches,
};

/// Steps into a growing stack, each with a growing inner region `R` and the whole floor: a carried search of `R`
/// (as stage 1) and a carried search of the whole floor outside `R` (as stage 2). The better of their first
/// placements costs what a fresh search of the whole floor finds (the exact optimum); no placement of the outside
/// search has the part's shadow inside `R` by more than the tolerance; every placement is valid by the independent
/// all-pairs check, in cost order.
#[test]
fn a_region_and_the_floor_outside_it_find_the_whole_floors_optimum() {
    let part = part_by_name("l-corner", Decomposition::ConvexMerge).expect("example");
    let whole = FloorVolume::rectangle(-200.0, -200.0, 200.0, 200.0, 300.0);
    let cache = ObstacleCache::new();
    let mut carrying = SearchCaches::carrying_frontiers();
    let mut poses: Vec<Pose> = Vec::new();
    let mut outside_found = 0;
    for step in 0..6 {
        let stack: Vec<PlacedPart<'_>> = poses.iter().map(|&pose| PlacedPart { part: &part, pose }).collect();
        let grow = 90.0 + 20.0 * step as f64;
        let region = FloorVolume::rectangle(-grow, -grow, grow, grow, 300.0);
        let fresh_whole = place_with_caches(
            &growing_stack_request(&part, stack.clone(), whole.clone()),
            &ObstacleCache::new(),
            &mut SearchCaches::new(),
        )
        .expect("search");
        let inner =
            carried_placements(&growing_stack_request(&part, stack.clone(), region.clone()), &cache, &mut carrying);
        let mut outer_request = growing_stack_request(&part, stack.clone(), whole.clone());
        outer_request.tuning.searched_elsewhere = Some(region.polygon.clone());
        let outer = carried_placements(&outer_request, &cache, &mut carrying);
        outside_found += outer.len();
        let best = inner.iter().chain(&outer).map(|p| p.cost).fold(f64::INFINITY, f64::min);
        let exact = fresh_whole.placements.first().map_or(f64::INFINITY, |p| p.cost);
        assert!(
            best == exact || (best - exact).abs() <= 1e-9 * (1.0 + exact.abs()),
            "step {step}: region and outside give {best}, the whole floor {exact}"
        );
        let tol = tolerance(&part);
        for p in &outer {
            let pose = p.pose();
            let inside = region.side_planes().iter().all(|&(n, d)| {
                part.all_vertices().map(|v| n.dot(pose.apply(v).truncate())).fold(f64::NEG_INFINITY, f64::max) < d - tol
            });
            assert!(!inside, "step {step}: the outside search placed the part inside the region: {p:?}");
        }
        for w in outer.windows(2) {
            assert!(w[0].cost <= w[1].cost + 1e-9 * (1.0 + w[1].cost.abs()), "cost order");
        }
        let unspaced = PlacementRequest { clearance: 0.0, horizontal_clearance: false, ..outer_request.clone() };
        for p in inner.iter().chain(&outer) {
            let pose = p.pose();
            let v = violations(&part, pose.rotation, pose.position, &stack, &unspaced, 1e-6, 2.0);
            assert!(v.is_empty(), "step {step}: {v:?} at {p:?}");
        }
        poses.push(fresh_whole.placements.first().expect("room on the floor").pose());
    }
    assert!(outside_found > 0, "the outside searches found placements");
}

/// A region that is not a convex counter-clockwise polygon is a typed error naming it, not a panic.
#[test]
fn a_bad_region_is_a_typed_error() {
    let part = part_by_name("l-corner", Decomposition::ConvexMerge).expect("example");
    let floor = FloorVolume::rectangle(-200.0, -200.0, 200.0, 200.0, 300.0);
    let bad = [
        vec![DVec2::ZERO, DVec2::X],
        vec![DVec2::ZERO, DVec2::new(f64::NAN, 0.0), DVec2::Y],
        vec![DVec2::ZERO, DVec2::Y, DVec2::X],
    ];
    for polygon in bad {
        let mut req = growing_stack_request(&part, Vec::new(), floor.clone());
        req.tuning.searched_elsewhere = Some(polygon.clone());
        match place_with_caches(&req, &ObstacleCache::new(), &mut SearchCaches::new()) {
            Err(PlacementError::BadOption(msg)) => assert!(msg.contains("searched-elsewhere"), "{msg}"),
            other => panic!("{polygon:?}: expected a bad-option error, got {other:?}"),
        }
    }
}

/// All placements (up to `k`) of a search through the carrying caches.
fn carried_placements(req: &PlacementRequest<'_>, cache: &ObstacleCache, caches: &mut SearchCaches) -> Vec<Placement> {
    let mut search = PlacementSearch::new(req, cache, caches).expect("search");
    let mut found = Vec::new();
    while found.len() < req.k {
        match search.next_placements(1).expect("step").placements.pop() {
            Some(p) => found.push(p),
            None => break,
        }
    }
    found
}

/// The search's tolerance (of the largest part's diagonal; all parts are this one).
fn tolerance(part: &Part) -> f64 {
    let (lo, hi) = part.aabb();
    stackplan_geom::Tolerance::for_scale((hi - lo).length()).linear
}
