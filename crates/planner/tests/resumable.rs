//! The resumable search ([`PlacementSearch`]): asking for placements in several calls gives the placements of one
//! search with the summed `k`, in the same order, with the same values and the same counters; the shared caches are
//! handed back when it is dropped.

use stackplan_cspace::ObstacleCache;
use stackplan_planner::paper_scenarios::{Scenario, scenario};
use stackplan_planner::search::{PlacementSearch, SearchCaches, place_with_caches};
use stackplan_planner::{NoPlacement, PlacementRequest};

fn request<'a>(sc: &'a Scenario, k: usize) -> PlacementRequest<'a> {
    let mut req = sc.request();
    req.k = k;
    req
}

fn check(name: &str, chunks: &[usize]) {
    let sc = scenario(name).expect("scenario").expect("known scenario");
    let total: usize = chunks.iter().sum();
    let whole =
        place_with_caches(&request(&sc, total), &ObstacleCache::new(), &mut SearchCaches::new()).expect("one search");
    assert!(whole.placements.len() > chunks[0], "{name}: too few placements to compare");
    let req = request(&sc, 1);
    let cache = ObstacleCache::new();
    let mut caches = SearchCaches::new();
    let mut got = Vec::new();
    let mut last = None;
    {
        let mut search = PlacementSearch::new(&req, &cache, &mut caches).expect("prepared");
        for &more in chunks {
            let part = search.next_placements(more).expect("continued");
            assert!(part.placements.len() <= more);
            if part.placements.len() < more {
                assert!(part.exhausted.is_some(), "{name}: fewer than asked without a reason");
            }
            got.extend(part.placements.iter().cloned());
            last = Some(part);
        }
    }
    assert_eq!(got, whole.placements, "{name}: chunks {chunks:?}");
    let (a, b) = (last.expect("one call").stats, whole.stats);
    assert_eq!(
        (a.nodes_expanded, a.nodes_pushed, a.qp_solves, a.cells_empty, a.pairs_evaluated, a.interference_tests),
        (b.nodes_expanded, b.nodes_pushed, b.qp_solves, b.cells_empty, b.pairs_evaluated, b.interference_tests),
        "{name}: counters"
    );
    assert_eq!(a.orientations_considered, b.orientations_considered);
    // the caches came back: a following search with them answers as a fresh one
    let again = place_with_caches(&request(&sc, 2), &cache, &mut caches).expect("after");
    let fresh = place_with_caches(&request(&sc, 2), &ObstacleCache::new(), &mut SearchCaches::new()).expect("fresh");
    assert_eq!(again.placements.len(), fresh.placements.len());
    for (x, y) in again.placements.iter().zip(&fresh.placements) {
        assert!((x.cost - y.cost).abs() <= 1e-9 * (1.0 + y.cost.abs()), "{name}: {} vs {}", x.cost, y.cost);
    }
}

#[test]
fn continued_triangle_search_equals_one_search() {
    check("triangle", &[1, 3, 0, 5]);
}

#[test]
fn continued_complex_search_equals_one_search() {
    check("complex", &[2, 4]);
}

/// A search stopped by a cost limit returns exactly the placements of the unlimited search that cost at most the
/// limit, says why it stopped ([`NoPlacement::CostLimit`]), and a later call without the limit goes on with the
/// rest, as one search would.
#[test]
fn cost_limited_calls_return_the_cheap_prefix_and_continue() {
    let sc = scenario("triangle").expect("scenario").expect("known scenario");
    let whole = place_with_caches(&request(&sc, 8), &ObstacleCache::new(), &mut SearchCaches::new()).expect("one");
    assert!(whole.placements.len() == 8, "too few placements to compare");
    // a limit between two distinct costs of the sequence
    let split = (1..whole.placements.len())
        .rev()
        .find(|&i| whole.placements[i].cost > whole.placements[i - 1].cost * (1.0 + 1e-9))
        .expect("two distinct costs");
    let limit = 0.5 * (whole.placements[split - 1].cost + whole.placements[split].cost);
    let req = request(&sc, 1);
    let (cache, mut caches) = (ObstacleCache::new(), SearchCaches::new());
    let mut search = PlacementSearch::new(&req, &cache, &mut caches).expect("prepared");
    let cheap = search.next_placements_within(100, limit).expect("limited");
    assert_eq!(cheap.placements, whole.placements[..split], "the placements within the limit");
    assert_eq!(cheap.exhausted, Some(NoPlacement::CostLimit));
    // nothing more within the same limit
    let none = search.next_placements_within(1, limit).expect("again");
    assert!(none.placements.is_empty());
    assert_eq!(none.exhausted, Some(NoPlacement::CostLimit));
    let rest = search.next_placements(whole.placements.len() - split).expect("continued");
    assert_eq!(rest.placements, whole.placements[split..], "the rest after the limit");
}
