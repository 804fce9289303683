//! Best-first search over (orientation, free-space cell) nodes: the placement of one part (\[A\] V-A..C;
//! `docs/algorithms.md`, "Placement search").
//!
//! A node is an orientation `theta_k`, a convex cell `K` of positions (an H-polytope, \[A\] VI-A-1) and the optimum
//! `p*` of the cost over `K` (`f(p*)` is the key). The roots are `(theta_k, Omega(theta_k))`. Loop:
//!
//! 1. pop the cheapest node (costs compared rounded to about `1e-12` relative, so that exact ties do not depend
//!    on the optima's last bits; ties: lower orientation index, then lower cell id — deterministic);
//! 2. if the request leaves a region to another search ([`crate::request::SearchTuning::searched_elsewhere`]) and `p*` lies in
//!    its interior at `theta_k` (not applied on the node's path), take that region as the obstacle
//!    (`DerivedObstacle::searched_elsewhere`); else if an obstacle of `theta_k` built earlier holds `p*` in its
//!    interior by more than the tolerance (not one applied on the node's path), take the deepest such (any obstacle
//!    holding `p*` gives a valid split; this one needs no detection, which halves the detections of the Triangle
//!    scenario; in a plan the obstacles earlier searches built at `theta_k` are known from the orientation's first
//!    expansion); otherwise detect the interfering component pairs at `(theta_k, p*)` (`detect.rs`);
//! 3. take the first of them (deepest violation first) whose obstacle (`obstacles.rs`) contains `p*` in its
//!    interior by more than the tolerance, and split `K` into the children
//!    `K n {n_k . p >= d_k} n {n_j . p <= d_j, j < k}` (\[A\] VI-A-3). Children are pushed *lazily* keyed by a lower
//!    bound of their cost: the largest of the parent's cost, the minimum of the cost over the half-space
//!    `n_k . p >= d_k` alone (closed form, `Quadratic::halfspace_lower_bound`) and the bound that the parent's
//!    optimality conditions give over the part of `K` beyond that plane (`Quadratic::lower_bound_beyond`: it grows
//!    with the plane's distance from `p*`, which lies inside the obstacle; it halves the children solved in the
//!    Channel and Triangle searches and leaves the solved nodes' order alone). A box around the parent cell (bound
//!    propagation, [`stackplan_freespace::outer_box`]) is computed at the split: a child whose outside half-space
//!    misses it is empty and is not pushed (about 95 % of the empty children; its id is still taken, so the others'
//!    ids and order are unchanged). The same box drops the inequalities it proves redundant from the cell the
//!    children are built from (`outer_box::grown_outer_box_pruned`: the same set; about 14 of 20 inequalities of a
//!    split cell in the 15-part Complex plan, inherited from cells cut before) and the inside cuts `n_j . p <= d_j`
//!    it proves redundant from each child's list (the same test as the outside child's, recorded at the split as a
//!    mask of the faces, `InsideCuts`). Each child's own box (the parent's tightened by its kept inside cuts and
//!    its outside half-space, grown by the tolerance: [`stackplan_freespace::outer_box::tighten_box`]) then drops
//!    the children it proves empty (their ids taken too) and adds the cost's minimum over it to the key
//!    (`Quadratic::box_lower_bound`; in a 15-part Complex plan about one child in eight past the first test is
//!    dropped, and the key rises for two in five). When a pushed child is popped its
//!    emptiness is decided by a
//!    phase 1 from the parent's optimum (`Cell::is_empty_with`: the optimum violates only
//!    `n_k . p >= d_k`, so this is usually one LP move); a non-empty child's cell is built from a second phase 1 on
//!    the exact cell (`Cell::with_halfspaces_from`, no Chebyshev LP) and its QP solved (`cell_qp.rs`), and it is
//!    pushed back with its own cost — so children that never become the cheapest are never solved. The keys only decide
//!    *when* a pending child is solved, never the order of the solved nodes (a total order by (cost, orientation, id)
//!    that a valid lower bound cannot overtake), so the search pops the same solved nodes in the same order as with the
//!    parent's cost as key;
//! 4. if there is none, `p*` is free: it is the next placement (one per cell, in cost order, \[A\] VI-A-4).
//!
//! **Exactness.** The children cover `K` minus the obstacle's interior and each lies in `K`, so no child costs less
//! than its parent; a position is free iff it lies in no pair's obstacle interior. Hence the first free optimum popped
//! is the minimum of the cost over the free positions of all discrete orientations (\[A\] eq. 9 and section 5.3); the
//! next pops give the next best cells. Orientations whose root is never popped before the `k`-th solution are never
//! expanded, and only the obstacles of pairs met at popped optima are built.
//!
//! **Touching.** The QP's optimum lies on the planes of its active constraints; the obstacle test, the cell
//! membership and the narrow phase all use the one tolerance of the problem ([`stackplan_geom::Tolerance`], the
//! largest part's diagonal), so a point on an obstacle face is free and a popped node is never split by an obstacle it
//! was already cut from (this is also checked explicitly: each node carries the obstacles applied on its path).
//!
//! **Termination.** A node is split only by an obstacle whose interior holds its optimum; children lie outside that
//! interior, so along a path each (orientation, pair) obstacle is applied at most once and every path is finite. A
//! node budget guards against numerical trouble with a typed error.
//!
//! **Cost.** One QP per node; per popped node one interference detection (O(m_part m_stack) box tests plus the
//! narrow phase on overlapping boxes) and at most one obstacle construction. Root QPs run in parallel (rayon).
//!
//! **Partitions** ([`crate::request::SearchTuning::partitions`] = `P`, default 2). Every node belongs to one orientation, and
//! what the loop learns is per orientation (the known obstacles, the derived obstacles, the found points), so the
//! orientations are split into `P` fixed partitions, blocks of `LANE_BLOCK` consecutive orientations dealt
//! round-robin (`lane_of`; `P` is a number of the request, never the thread count), and each partition runs the
//! loop above on its own state: heap, node ids, obstacle table and known obstacles, derived obstacles, the
//! constant-topology structures (`IntervalObstacles`), the carried frontier and the detection's scratch
//! (`Search` and `RunState` per partition; the obstacle cache is shared, it is `Sync` and a pure function). The
//! placements are merged in the heap's total order (rounded cost, orientation, id; the orientations of two
//! partitions differ, so the ids of two partitions are never compared): the next placement of the whole search is
//! the cheapest of the partitions' next placements, and it is known once every other partition's next key pops
//! after it. Each partition keeps the placements it found but the merge has not returned (a look-ahead queue, at
//! most `LOOK_AHEAD`), which a later call returns first; a cost limit
//! ([`PlacementSearch::next_placements_within`]) stops each partition at its own keys. So the placements, their
//! order and their values are the sequential loop's over the same obstacles, and the first placement of every
//! search is the exact optimum.
//!
//! *Rounds and determinism.* The partitions advance in rounds on rayon, each at most `ROUND_POPS` pops: a
//! partition without a found placement whose next key pops before the best found one (of any partition, fixed at the
//! round's start) searches on up to that key; the others, while one such partition runs, look ahead for their next
//! placements (the caller often asks for more: the stacking planner rejects candidates; the work stays in the carried
//! frontier either way). A partition that finishes its round first waits, spinning briefly, for the others
//! (`round_end.rs`: the next round then finds both threads awake; timing only). A partition that runs alone runs
//! without rounds (nothing can change its bound). The bound is
//! exchanged only between rounds and every round's work is a function of the states at its start, so the states
//! after each call, hence the carried frontiers, the later candidates and the plans, depend on `P` but never on the
//! thread count or the timing (a shared atomic "best so far" would make them timing-dependent). `P = 1` is the
//! sequential loop itself, bit for bit.
//!
//! *What changes with `P`.* The placements, in the same order, up to which obstacles exist: a partition
//! extrapolates an obstacle only from structures it built itself (`interval_obstacles.rs`: an obstacle's
//! last bits depend on the angle its structure was built at), and the partitions search past the merge's current
//! placement (up to a round, and the look-ahead), so the carried frontiers are further along and a later placement
//! can lie in another cell of the same free space (another contact listed at the same position, or, rarely, another
//! later candidate). The statistics ([`PlacementStats`]) are sums over the partitions (`orientations_considered`
//! too: each orientation is in one partition; the node budget applies to each partition's pops).

mod caches;
mod dary_heap;
mod expand;
mod heap;
mod partitions;
mod placement;
mod result;
mod round_end;
mod state;

pub use caches::SearchCaches;
pub use result::{Contact, NoPlacement, Placement, PlacementResult, PlacementStats};

use caches::*;
use heap::*;
use partitions::*;
use state::*;

use crate::detect::StackScene;
use crate::request::{PlacementError, PlacementRequest};
use stackplan_cspace::ObstacleCache;
use std::sync::Arc;
use std::time::Instant;

/// Places the part (see the module documentation) with a fresh obstacle cache.
pub fn place(request: &PlacementRequest<'_>) -> Result<PlacementResult, PlacementError> {
    place_with_cache(request, &ObstacleCache::new())
}

/// Places the part, building obstacles through `cache` (shareable across successive placements into a growing stack
/// whose parts keep their indices and poses: a cached obstacle depends only on the pair and the rotation).
pub fn place_with_cache(
    request: &PlacementRequest<'_>,
    cache: &ObstacleCache,
) -> Result<PlacementResult, PlacementError> {
    place_with_caches(request, cache, &mut SearchCaches::default())
}

/// [`place_with_cache`] sharing `caches` with earlier searches (see [`SearchCaches`]); the stacking planner passes
/// the same caches to every search of a plan.
pub fn place_with_caches(
    request: &PlacementRequest<'_>,
    cache: &ObstacleCache,
    caches: &mut SearchCaches,
) -> Result<PlacementResult, PlacementError> {
    let start = Instant::now();
    let mut searches = prepare(request, cache, caches)?;
    let before = cache.stats();
    if let Some(first) = searches.first_mut() {
        first.stats.time_setup_ms = ms(start);
    }
    let result = match request.fixed_z {
        None => run::<3>(&mut searches, 0.0),
        Some(z) => run::<2>(&mut searches, z),
    };
    let after = cache.stats();
    for (search, lane) in searches.iter_mut().zip(&mut caches.lanes) {
        search.give_back(lane);
    }
    let mut result = result?;
    result.stats.obstacles_constructed = after.constructions - before.constructions;
    result.stats.obstacle_cache_hits = after.hits - before.hits;
    result.stats.time_total_ms = ms(start);
    tracing::info!(
        placements = result.placements.len(),
        nodes = result.stats.nodes_expanded,
        pairs = result.stats.pairs_evaluated,
        total_pairs = result.stats.total_pairs,
        ms = result.stats.time_total_ms,
        "placement search done"
    );
    Ok(result)
}

/// The search's state in 2 or 3 variables, one per partition of the orientations.
#[derive(Clone)]
enum States {
    Two(Vec<RunState<2>>),
    Three(Vec<RunState<3>>),
}

impl std::fmt::Debug for States {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (dimensions, open, free) = match self {
            States::Two(s) => {
                (2, s.iter().map(|s| s.heap.len()).sum::<usize>(), s.iter().map(|s| s.free_nodes.len()).sum::<usize>())
            }
            States::Three(s) => {
                (3, s.iter().map(|s| s.heap.len()).sum::<usize>(), s.iter().map(|s| s.free_nodes.len()).sum::<usize>())
            }
        };
        f.debug_struct("States")
            .field("dimensions", &dimensions)
            .field("open_entries", &open)
            .field("free_nodes", &free)
            .finish()
    }
}

/// A placement search that can be continued: the same search as [`place_with_caches`], whose heap (and every other
/// part of its state) is kept between calls of [`PlacementSearch::next_placements`], so asking for `a` placements
/// and then for `b` more gives the same placements, in the same order and with the same values, as one search with
/// `k = a + b` (the request's `k` is not used). The stacking planner, which asks for more candidates when all of the
/// first ones fail its stability checks, continues instead of starting again with a larger `k`.
///
/// The shared caches are held until the search is dropped (then handed back, as [`place_with_caches`] does).
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use glam::DVec3;
/// use stackplan_cspace::ObstacleCache;
/// use stackplan_geom::{ConvexPolytope, Part, PartOrigin, Pose};
/// use stackplan_planner::{FloorVolume, PlacementRequest, PlacementSearch, SearchCaches, PlacedPart, uniform_thetas};
///
/// let block = ConvexPolytope::cuboid(DVec3::ZERO, DVec3::new(40.0, 20.0, 10.0))?;
/// let part = Part::from_components("block", vec![block], 1.0, PartOrigin::ConvexPieces)?;
/// let stack = vec![PlacedPart { part: &part, pose: Pose::IDENTITY }];
/// let mut request = PlacementRequest::new(&part, stack, FloorVolume::rectangle(-50.0, -50.0, 90.0, 70.0, 100.0));
/// request.thetas = uniform_thetas(8);
/// let (cache, mut caches) = (ObstacleCache::new(), SearchCaches::new());
/// let mut search = PlacementSearch::new(&request, &cache, &mut caches)?;
/// let first = search.next_placements(2)?; // the 2 best
/// let more = search.next_placements(3)?; // the next 3: places 3..5 of a search with k = 5
/// assert!(first.placements[first.placements.len() - 1].cost <= more.placements[0].cost);
/// drop(search); // hands the caches back
/// request.k = 5;
/// let once = stackplan_planner::place_with_caches(&request, &ObstacleCache::new(), &mut SearchCaches::new())?;
/// assert_eq!([first.placements, more.placements].concat(), once.placements);
/// # Ok(())
/// # }
/// ```
pub struct PlacementSearch<'r, 'a, 'c> {
    /// One per partition of the orientations.
    searches: Vec<Search<'r, 'a>>,
    caches: &'c mut SearchCaches,
    /// `None`: Omega is empty at every orientation.
    state: Option<States>,
    cache: &'r ObstacleCache,
    /// Obstacle-cache constructions and hits during this search's own calls (the cache is shared: the caller may
    /// build obstacles through it between two calls).
    cache_counts: (u64, u64),
    /// Time spent in the calls so far (ms).
    elapsed_ms: f64,
    /// Set when the caches carry frontiers and no call failed: the state goes back to the caches on drop.
    signature: Option<FrontierSignature>,
    /// The stack's scene (shared with the partitions and the caches).
    scene: Arc<StackScene>,
}

impl std::fmt::Debug for PlacementSearch<'_, '_, '_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PlacementSearch")
            .field("empty_omega", &self.state.is_none())
            .field("stats", &merged_stats(&self.searches))
            .finish_non_exhaustive()
    }
}

impl<'r, 'a, 'c> PlacementSearch<'r, 'a, 'c> {
    /// Prepares the search and solves the roots (the setup and root phases of [`place_with_caches`]).
    pub fn new(
        request: &'r PlacementRequest<'a>,
        cache: &'r ObstacleCache,
        caches: &'c mut SearchCaches,
    ) -> Result<Self, PlacementError> {
        let start = Instant::now();
        let before = cache.stats();
        let mut searches = prepare(request, cache, caches)?;
        if let Some(first) = searches.first_mut() {
            first.stats.time_setup_ms = ms(start);
        }
        // the state of the newest search with this floor that this one continues, else of the newest one whose
        // floor lies inside this one's (widened); a state widened right after it was searched (the stacking
        // planner's stage 2 continuing its stage 1 when that accepted nothing) is copied, the original kept for the
        // next search of its own floor
        let signature = caches.carry.then(|| FrontierSignature::of(request));
        let carried = signature.as_ref().and_then(|sig| {
            let at = caches
                .frontiers
                .iter()
                .rposition(|(s, _)| s.floor == sig.floor && s.continues_into(sig))
                .or_else(|| caches.frontiers.iter().rposition(|(s, _)| s.continues_into(sig)))?;
            let widens = caches.frontiers[at].0.floor != request.floor;
            if widens && at + 1 == caches.frontiers.len() {
                let (old, state) = &caches.frontiers[at];
                return Some((state.clone(), Some(old.floor.clone())));
            }
            let (old, state) = caches.frontiers.remove(at);
            Some((state, widens.then_some(old.floor)))
        });
        let state = match (carried, request.fixed_z) {
            (Some((States::Three(s), old)), None) => {
                widen_all(&mut searches, s, old.as_ref()).map(|s| Some(States::Three(s)))
            }
            (Some((States::Two(s), old)), Some(_)) => {
                widen_all(&mut searches, s, old.as_ref()).map(|s| Some(States::Two(s)))
            }
            (_, None) => start_all::<3>(&mut searches, 0.0).map(|s| s.map(States::Three)),
            (_, Some(z)) => start_all::<2>(&mut searches, z).map(|s| s.map(States::Two)),
        };
        let state = match state {
            Ok(state) => state,
            Err(e) => {
                for (search, lane) in searches.iter_mut().zip(&mut caches.lanes) {
                    search.give_back(lane);
                }
                // the obstacle table the kept states name by id is lost with the search
                caches.frontiers.clear();
                return Err(e);
            }
        };
        let after = cache.stats();
        let cache_counts = (after.constructions - before.constructions, after.hits - before.hits);
        // (every partition holds the same scene; there is at least one partition, `validate`)
        let scene = searches.first().map_or_else(|| Arc::new(StackScene::new(&[])), |s| Arc::clone(&s.scene));
        Ok(Self { searches, caches, state, cache, cache_counts, elapsed_ms: ms(start), signature, scene })
    }

    /// The next `more` placements (fewer, with `exhausted` set, when the free space runs out); statistics over the
    /// whole search so far.
    pub fn next_placements(&mut self, more: usize) -> Result<PlacementResult, PlacementError> {
        self.next_placements_within(more, f64::INFINITY)
    }

    /// The next `more` placements that cost at most `max_cost`: as [`Self::next_placements`], but the search stops
    /// (fewer returned, `exhausted` = [`NoPlacement::CostLimit`]) as soon as every open node's key exceeds
    /// `max_cost`; the keys are lower bounds of the costs of every placement still to come, so none of those costs
    /// `max_cost` or less. The placements returned are those of [`Self::next_placements`] up to the first dearer
    /// than `max_cost` (to the keys' rounding, `quantised_cost`: one may cost up to `2^-40` relative more), and a
    /// later call, with any limit, continues exactly where this one stopped. Use: a caller that needs only
    /// placements cheaper than one it already has (the stacking planner's stage 2 against stage 1's part).
    pub fn next_placements_within(&mut self, more: usize, max_cost: f64) -> Result<PlacementResult, PlacementError> {
        let start = Instant::now();
        let before = self.cache.stats();
        let placements = match &mut self.state {
            None => {
                return Ok(PlacementResult {
                    placements: Vec::new(),
                    exhausted: (more > 0).then_some(NoPlacement::EmptyOmega),
                    stats: self.stats(),
                });
            }
            Some(States::Two(states)) => advance_all(&mut self.searches, states, more, max_cost),
            Some(States::Three(states)) => advance_all(&mut self.searches, states, more, max_cost),
        };
        let after = self.cache.stats();
        self.cache_counts.0 += after.constructions - before.constructions;
        self.cache_counts.1 += after.hits - before.hits;
        self.elapsed_ms += ms(start);
        if placements.is_err() {
            // a failed call may have lost a popped node: this state is not carried on
            self.signature = None;
        }
        let (placements, limited) = placements?;
        let exhausted = (placements.len() < more).then_some(if limited {
            NoPlacement::CostLimit
        } else {
            NoPlacement::FitsNowhere
        });
        Ok(PlacementResult { placements, exhausted, stats: self.stats() })
    }

    /// The stack's components placed in the world, as this search sees them (the scene the caches keep; the
    /// stacking planner settles its candidates among them).
    pub fn scene(&self) -> &StackScene {
        &self.scene
    }

    /// The statistics of the search so far.
    pub fn stats(&self) -> PlacementStats {
        let mut stats = merged_stats(&self.searches);
        (stats.obstacles_constructed, stats.obstacle_cache_hits) = self.cache_counts;
        stats.time_total_ms = self.elapsed_ms;
        stats
    }

    /// The statistics of each partition of the orientations so far (one entry per
    /// [`crate::request::SearchTuning::partitions`]; [`Self::stats`] sums them): the balance of the partitioned search.
    pub fn partition_stats(&self) -> Vec<PlacementStats> {
        self.searches.iter().map(|s| s.stats.clone()).collect()
    }
}

impl Drop for PlacementSearch<'_, '_, '_> {
    fn drop(&mut self) {
        if self.searches.len() > 1 {
            tracing::debug!(
                nodes = ?self.searches.iter().map(|s| s.stats.nodes_expanded).collect::<Vec<_>>(),
                pushed = ?self.searches.iter().map(|s| s.stats.nodes_pushed).collect::<Vec<_>>(),
                rounds = self.searches.first().map_or(0, |s| s.rounds),
                "partitioned search: nodes per partition"
            );
        }
        for (search, lane) in self.searches.iter_mut().zip(&mut self.caches.lanes) {
            search.give_back(lane);
            if self.caches.carry {
                lane.table = ObstacleTable {
                    obstacles: std::mem::take(&mut search.obstacles),
                    ids: std::mem::take(&mut search.obstacle_ids),
                    by_orientation: std::mem::take(&mut search.by_orientation),
                };
            }
        }
        if self.caches.carry
            && let (Some(signature), Some(state)) = (self.signature.take(), self.state.take())
        {
            self.caches.frontiers.retain(|(s, _)| *s != signature);
            self.caches.frontiers.push((signature, state));
            if self.caches.frontiers.len() > CARRIED_FRONTIERS {
                self.caches.frontiers.remove(0);
            }
        }
    }
}

fn ms(since: Instant) -> f64 {
    since.elapsed().as_secs_f64() * 1e3
}
