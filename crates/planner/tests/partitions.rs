//! The partitioned search ([`SearchTuning::partitions`](stackplan_planner::request::SearchTuning::partitions), "Partitions" in `search.rs`): the orientations split
//! into fixed partitions searched in rounds on rayon and merged in the heap's order give the sequential search's
//! placements (bit for bit when every obstacle is constructed, to rounding when obstacles are extrapolated from
//! structures each partition builds itself), whatever the thread count; a cost limit applies to every partition and
//! a later call continues where the limited one stopped.

use glam::DVec3;
use stackplan_cspace::ObstacleCache;
use stackplan_geom::examples::part_by_name;
use stackplan_geom::sheet_metal::Decomposition;
use stackplan_planner::paper_scenarios::{SCENARIOS, Scenario, scenario};
use stackplan_planner::search::{PlacementSearch, SearchCaches, place_with_caches};
use stackplan_planner::{
    FloorVolume, NoPlacement, PlacementError, PlacementRequest, PlacementResult, PlanOptions, plan_stack,
};

fn request<'a>(sc: &'a Scenario, k: usize, partitions: usize, extrapolate: bool) -> PlacementRequest<'a> {
    let mut req = sc.request();
    req.k = k;
    req.tuning.partitions = partitions;
    req.tuning.extrapolate = extrapolate;
    req
}

fn place(req: &PlacementRequest<'_>) -> PlacementResult {
    place_with_caches(req, &ObstacleCache::new(), &mut SearchCaches::new()).expect("search")
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("thread pool").install(f)
}

/// With every obstacle constructed (no extrapolation) each orientation's search is the same whatever the partition,
/// so the merged placements are the sequential search's bit for bit, for 2, 3 and 5 partitions; with extrapolation
/// (each partition's structures its own) the same placements to rounding.
#[test]
fn partitioned_search_returns_the_sequential_placements() {
    for name in SCENARIOS {
        let sc = scenario(name).expect("scenario").expect("known scenario");
        let k = 8;
        let sequential = place(&request(&sc, k, 1, false));
        assert!(sequential.placements.len() >= 3, "{name}: too few placements to compare");
        for partitions in [2, 3, 5] {
            let merged = place(&request(&sc, k, partitions, false));
            assert_eq!(merged.placements, sequential.placements, "{name}: {partitions} partitions");
            assert_eq!(merged.exhausted, sequential.exhausted);
            assert_eq!(merged.stats.orientations_searched, sequential.stats.orientations_searched);
        }
        let sequential = place(&request(&sc, k, 1, true));
        let merged = place(&request(&sc, k, 2, true));
        assert_eq!(merged.placements.len(), sequential.placements.len(), "{name}");
        // a symmetric part has several optima of one cost in one orientation (the Triangle's three-fold symmetry):
        // where rounding orders them differently, a placement at another position must be one of the sequential
        // search's own, of the same cost, found when it is asked for more
        let more = place(&request(&sc, 2 * k, 1, true));
        for (a, b) in merged.placements.iter().zip(&sequential.placements) {
            assert_eq!((a.theta, a.resting_pose), (b.theta, b.resting_pose), "{name}");
            assert!((a.cost - b.cost).abs() <= 1e-9 * (1.0 + b.cost.abs()), "{name}: {} vs {}", a.cost, b.cost);
            let same_place = |x: &stackplan_planner::search::Placement| {
                let d = DVec3::from_array(a.position) - DVec3::from_array(x.position);
                (x.theta, x.resting_pose) == (a.theta, a.resting_pose)
                    && (a.cost - x.cost).abs() <= 1e-9 * (1.0 + x.cost.abs())
                    && d.abs().max_element() <= 1e-6
            };
            assert!(
                same_place(b) || more.placements.iter().any(same_place),
                "{name}: {:?} (cost {}) is none of the sequential search's placements of that cost; {:?}",
                a.position,
                a.cost,
                b.position
            );
        }
    }
}

/// The partitioned search's placements and counters are the same on one thread and on two (the rounds exchange the
/// partitions' bounds only at fixed points).
#[test]
fn partitioned_search_does_not_depend_on_the_thread_count() {
    for name in SCENARIOS {
        let sc = scenario(name).expect("scenario").expect("known scenario");
        let req = request(&sc, 6, 2, true);
        let one = in_pool(1, || place(&req));
        let two = in_pool(2, || place(&req));
        assert_eq!(one.placements, two.placements, "{name}");
        let counters = |r: &PlacementResult| {
            let s = &r.stats;
            (s.nodes_expanded, s.nodes_pushed, s.qp_solves, s.cells_empty, s.pairs_evaluated, s.interference_tests)
        };
        assert_eq!(counters(&one), counters(&two), "{name}");
    }
}

/// `next_placements_within` on a partitioned search: a limit between the placements' costs returns the cheap prefix
/// with [`NoPlacement::CostLimit`] (every partition stops at its own keys), and the calls after it continue as one
/// unlimited search.
#[test]
fn a_cost_limit_applies_to_every_partition_and_the_search_continues() {
    for name in SCENARIOS {
        let sc = scenario(name).expect("scenario").expect("known scenario");
        let whole = place(&request(&sc, 6, 2, true));
        assert!(whole.placements.len() >= 4, "{name}: too few placements");
        let costs: Vec<f64> = whole.placements.iter().map(|p| p.cost).collect();
        // strictly between the second and the third distinct cost (skip exact ties)
        let Some(i) = (1..costs.len() - 1).find(|&i| costs[i + 1] > costs[i] * (1.0 + 1e-9)) else { continue };
        let limit = 0.5 * (costs[i] + costs[i + 1]);
        let req = request(&sc, 1, 2, true);
        let cache = ObstacleCache::new();
        let mut caches = SearchCaches::new();
        let mut search = PlacementSearch::new(&req, &cache, &mut caches).expect("prepared");
        let cheap = search.next_placements_within(10, limit).expect("limited");
        assert_eq!(cheap.placements, whole.placements[..=i], "{name}: the cheap prefix");
        assert_eq!(cheap.exhausted, Some(NoPlacement::CostLimit), "{name}");
        let again = search.next_placements_within(10, limit).expect("limited again");
        assert!(again.placements.is_empty(), "{name}: nothing more within the limit");
        let rest = search.next_placements(whole.placements.len() - i - 1).expect("continued");
        assert_eq!(rest.placements, whole.placements[i + 1..], "{name}: the rest");
        assert_eq!(search.partition_stats().len(), 2);
    }
}

/// A stacking plan with the default partitions is the same on one thread and on two, and so is one with a single
/// partition; the partitions are checked.
#[test]
fn plans_do_not_depend_on_the_thread_count() {
    let part = part_by_name("l-corner", Decomposition::ConvexMerge).expect("example");
    let floor = FloorVolume::rectangle(-150.0, -150.0, 150.0, 150.0, 300.0);
    for partitions in [1, 2] {
        let mut options = PlanOptions { dtheta: 15f64.to_radians(), ..PlanOptions::new(5, floor.clone()) };
        options.tuning.partitions = partitions;
        let one = in_pool(1, || plan_stack(&part, &options)).expect("plan");
        let two = in_pool(2, || plan_stack(&part, &options)).expect("plan");
        assert!(one.parts.len() >= 3, "{partitions}: placed {}", one.parts.len());
        assert_eq!(one.parts, two.parts, "{partitions} partitions");
        assert_eq!(one.total_cost, two.total_cost);
    }
    let sc = scenario("channel").expect("scenario").expect("known scenario");
    for bad in [0, 10_000] {
        let req = request(&sc, 1, bad, true);
        let err = place_with_caches(&req, &ObstacleCache::new(), &mut SearchCaches::new());
        assert!(matches!(err, Err(PlacementError::BadOption(_))), "{bad} partitions: {err:?}");
    }
}
