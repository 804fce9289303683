//! Searches into a growing stack that carry their open cells to the next search ([`SearchCaches::carrying_frontiers`],
//! the stacking planner's caches): the first placement of every search is the exact optimum a fresh search finds,
//! also on a floor that grew since the carried search (stage 1's footprint).

use crate::common;

use common::growing_stack_request;
use stackplan_cspace::ObstacleCache;
use stackplan_geom::Pose;
use stackplan_geom::examples::part_by_name;
use stackplan_geom::sheet_metal::Decomposition;
use stackplan_planner::{FloorVolume, PlacedPart, PlacementRequest, PlacementSearch, SearchCaches, place_with_caches};

/// Searches into a growing stack through caches that carry their frontiers (as the stacking planner's): at every
/// step the first placement costs what a fresh search's does (the exact optimum), also on a floor that grew since the
/// last search with it (the carried cells plus the new strip); every placement is valid by the independent all-pairs
/// check and they come in cost order.
#[test]
fn carried_frontiers_find_the_exact_best_placement_into_a_growing_stack() {
    use stackplan_planner::reference::violations;
    let part = part_by_name("l-corner", Decomposition::ConvexMerge).expect("example");
    let whole = FloorVolume::rectangle(-200.0, -200.0, 200.0, 200.0, 300.0);
    let cache = ObstacleCache::new();
    let mut carrying = SearchCaches::carrying_frontiers();
    let mut poses: Vec<Pose> = Vec::new();
    let mut widened = 0;
    for step in 0..6 {
        let stack: Vec<PlacedPart<'_>> = poses.iter().map(|&pose| PlacedPart { part: &part, pose }).collect();
        // a footprint-like floor that grows with the steps (as stage 1's), then the whole floor (as stage 2's)
        let grow = 90.0 + 20.0 * step as f64;
        let floors = [FloorVolume::rectangle(-grow, -grow, grow, grow, 300.0), whole.clone()];
        let mut next_pose = None;
        for floor in floors {
            let req = growing_stack_request(&part, stack.clone(), floor);
            let fresh = place_with_caches(&req, &ObstacleCache::new(), &mut SearchCaches::new()).expect("search");
            let mut carried = Vec::new();
            {
                let mut search = PlacementSearch::new(&req, &cache, &mut carrying).expect("search");
                while carried.len() < req.k {
                    match search.next_placements(1).expect("step").placements.pop() {
                        Some(p) => carried.push(p),
                        None => break,
                    }
                }
                widened += usize::from(step > 0 && search.stats().qp_solves > 0);
            }
            assert_eq!(carried.is_empty(), fresh.placements.is_empty(), "step {step}");
            // the stack grows by the whole floor's best placement (the last floor searched)
            next_pose = fresh.placements.first().map(|p| p.pose());
            let (Some(a), Some(b)) = (carried.first(), fresh.placements.first()) else { continue };
            assert!((a.cost - b.cost).abs() <= 1e-9 * (1.0 + b.cost.abs()), "step {step}: {} vs {}", a.cost, b.cost);
            for w in carried.windows(2) {
                assert!(w[0].cost <= w[1].cost + 1e-9 * (1.0 + w[1].cost.abs()), "cost order");
            }
            // interference, floor volume and insertion (the reference check's clearance is not horizontal: parts
            // resting on each other touch)
            let unspaced = PlacementRequest { clearance: 0.0, horizontal_clearance: false, ..req.clone() };
            for p in &carried {
                let pose = p.pose();
                let v = violations(&part, pose.rotation, pose.position, &stack, &unspaced, 1e-6, 2.0);
                assert!(v.is_empty(), "step {step}: {v:?} at {p:?}");
            }
        }
        poses.push(next_pose.expect("room on the floor"));
    }
    assert!(widened > 0, "the growing floor was widened from a carried frontier");
}

/// Search caches reused for a stack that does not extend the last search's (a part moved, a shorter stack) search
/// that stack: the scene the caches keep is built again, and every search's placements are a fresh search's. With a
/// scene kept by the number of parts alone, the moved part's old place would be searched around. (The obstacle cache
/// is keyed by stack part index, so it is new for every stack, as its documentation asks.)
#[test]
fn caches_reused_for_another_stack_search_that_stack() {
    let part = part_by_name("l-corner", Decomposition::ConvexMerge).expect("example");
    let floor = FloorVolume::rectangle(-150.0, -150.0, 150.0, 150.0, 300.0);
    let at = |x: f64, y: f64| Pose { rotation: glam::DMat3::IDENTITY, position: glam::DVec3::new(x, y, 0.0) };
    let stacks = [vec![at(0.0, 0.0)], vec![at(40.0, -30.0)], vec![at(40.0, -30.0), at(-60.0, 50.0)], vec![]];
    for mut caches in [SearchCaches::new(), SearchCaches::carrying_frontiers()] {
        for poses in &stacks {
            let stack: Vec<PlacedPart<'_>> = poses.iter().map(|&pose| PlacedPart { part: &part, pose }).collect();
            let req = growing_stack_request(&part, stack, floor.clone());
            let fresh = place_with_caches(&req, &ObstacleCache::new(), &mut SearchCaches::new()).expect("fresh");
            let reused = place_with_caches(&req, &ObstacleCache::new(), &mut caches).expect("reused caches");
            assert_eq!(reused.stats.stack_components, fresh.stats.stack_components);
            let (Some(a), Some(b)) = (reused.placements.first(), fresh.placements.first()) else {
                panic!("room on the floor for stack {poses:?}");
            };
            assert!((a.cost - b.cost).abs() <= 1e-9 * (1.0 + b.cost.abs()), "{poses:?}: {} vs {}", a.cost, b.cost);
            assert!((a.pose().position - b.pose().position).length() <= 1e-6, "{poses:?}: {a:?} vs {b:?}");
        }
    }
}
