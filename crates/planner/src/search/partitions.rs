//! The partitioned search: the setup of one search per partition of the orientations and the k-way merge of their
//! placements in rounds ("Partitions" in the module documentation of [`crate::search`]).

use super::round_end::RoundEnd;
use super::*;
use crate::detect::SweepAxes;
use crate::orientation::Orientation;
use crate::request::{FloorVolume, PlacementError, PlacementRequest};
use crate::symmetry::{is_uniform_full_turn, period_length, rotational_order};
use rayon::prelude::*;
use stackplan_cspace::ObstacleCache;
use stackplan_geom::Tolerance;
use std::sync::Arc;

/// Orientations per block dealt to the partitions in turn ([`lane_of`]).
pub(super) const LANE_BLOCK: usize = 4;

/// The partition of orientation `i` among `lanes` partitions: blocks of [`LANE_BLOCK`] consecutive orientations
/// dealt round-robin (neighbouring angles cost about the same to search, so the partitions' work is balanced, and a
/// block keeps some constant-topology intervals inside one partition).
pub(super) fn lane_of(i: usize, lanes: usize) -> usize {
    (i / LANE_BLOCK) % lanes
}

/// The search's setup: validation, orientations (one symmetry period per resting pose), the scene, the
/// statistics' constants, and the shared caches adopted (their contents move into the searches until
/// [`Search::give_back`]); one search per partition of the orientations.
pub(super) fn prepare<'r, 'a>(
    request: &'r PlacementRequest<'a>,
    cache: &'r ObstacleCache,
    caches: &mut SearchCaches,
) -> Result<Vec<Search<'r, 'a>>, PlacementError> {
    request.validate()?;
    let part = request.part;
    let scale = request
        .stack
        .iter()
        .map(|s| {
            let (lo, hi) = s.part.aabb();
            (hi - lo).length()
        })
        .fold(
            {
                let (lo, hi) = part.aabb();
                (hi - lo).length()
            },
            f64::max,
        );
    let tol = Tolerance::for_scale(scale);
    // orientations, one symmetry period per resting pose
    let n_theta = request.thetas.len();
    let uniform = is_uniform_full_turn(&request.thetas);
    let mut orientations = Vec::new();
    let mut symmetry_orders = Vec::new();
    for (rest, r) in request.resting_rotations.iter().enumerate() {
        let order =
            if request.tuning.use_symmetry { rotational_order(part, *r, 10.0 * part.tolerance().linear) } else { 1 };
        symmetry_orders.push(order);
        let count = if uniform { period_length(n_theta, order) } else { n_theta };
        for (ti, &theta) in request.thetas.iter().enumerate().take(count) {
            orientations.push((rest, ti, theta, *r));
        }
    }
    // the heap key packs the orientation index in 24 bits (`HeapKey`)
    if orientations.len() >= 1 << (64 - ID_BITS) {
        return Err(PlacementError::BadOption(format!(
            "{} orientations (resting poses x theta values) are more than the search handles ({})",
            orientations.len(),
            (1u64 << (64 - ID_BITS)) - 1
        )));
    }
    let mut orientations: Vec<Orientation> = orientations
        .into_par_iter()
        .enumerate()
        .map(|(i, (rest, ti, theta, r))| Orientation::without_components(part, i, rest, ti, theta, r, &request.cost))
        .collect();
    let keys = scene_keys(&request.stack);
    // the obstacle cache's keys name parts by index: refuse a cache built for another part or another stack
    let moving = part.fingerprint();
    let fixed: Vec<u64> = keys
        .iter()
        .map(|key| {
            use std::hash::{Hash, Hasher};
            let mut hasher = std::collections::hash_map::DefaultHasher::new();
            key.hash(&mut hasher);
            hasher.finish()
        })
        .collect();
    if !cache.claim(moving, &fixed) {
        return Err(PlacementError::ForeignCache);
    }
    let scene = caches.scene(request, &keys);
    // rotated components and sweep axes are built when an orientation is first expanded
    let sweeps: Vec<Option<Arc<SweepAxes>>> = vec![None; orientations.len()];
    let stats = PlacementStats {
        orientations_requested: request.resting_rotations.len() * n_theta,
        orientations_searched: orientations.len(),
        symmetry_orders,
        part_components: part.components().len(),
        stack_components: scene.components.len(),
        total_pairs: (part.components().len() * scene.components.len() * request.resting_rotations.len() * n_theta)
            as u64,
        total_pairs_searched: (part.components().len() * scene.components.len() * orientations.len()) as u64,
        ..Default::default()
    };
    caches.adopt(CacheSignature {
        rotations: orientations.iter().map(|o| o.rotation.to_cols_array().map(f64::to_bits)).collect(),
        clearance: request.clearance.to_bits(),
        insertion: request.insertion,
        horizontal: request.horizontal_clearance,
        extrapolate: request.tuning.extrapolate,
        merge_plates: request.tuning.merge_plates,
        partitions: request.tuning.partitions,
        moving,
        stack: keys,
    });
    let n_orientations = orientations.len();
    let lanes = request.tuning.partitions;
    let mut searches = Vec::with_capacity(lanes);
    let caches_events = caches.events.clone();
    let moving_plate_of: Arc<[Option<u32>]> = crate::plates::moving_plates(request).into();
    for (lane, lane_caches) in caches.lanes.iter_mut().enumerate() {
        // the pairs earlier searches built, by orientation (one pass over the shared derived obstacles); caches that
        // carry frontiers keep the obstacle table itself (carried cells name obstacles by id)
        let mut shared_pairs = vec![Vec::new(); n_orientations];
        let mut table = ObstacleTable::default();
        if caches.carry {
            table = std::mem::take(&mut lane_caches.table);
        } else {
            for &(oi, moving, fixed) in lane_caches.derived.keys() {
                if let Some(list) = shared_pairs.get_mut(oi) {
                    list.push((moving, fixed));
                }
            }
        }
        table.by_orientation.resize_with(n_orientations, KnownObstacles::default);
        searches.push(Search {
            request,
            lane,
            lanes,
            // the last partition takes the list itself (one partition: no copy)
            orientations: if lane + 1 == lanes { std::mem::take(&mut orientations) } else { orientations.clone() },
            sweeps: sweeps.clone(),
            scene: Arc::clone(&scene),
            tol,
            cache,
            obstacles: table.obstacles,
            obstacle_ids: table.ids,
            by_orientation: table.by_orientation,
            shared_pairs,
            elsewhere: vec![None; n_orientations],
            detect_scratch: std::mem::take(&mut lane_caches.detect_scratch),
            rotated: std::mem::take(&mut lane_caches.rotated),
            derived: std::mem::take(&mut lane_caches.derived),
            intervals: {
                let mut intervals = std::mem::take(&mut lane_caches.intervals);
                intervals.share_events(&caches_events);
                intervals
            },
            moving_plate_of: Arc::clone(&moving_plate_of),
            stats: stats.clone(),
            rounds: 0,
        });
    }
    Ok(searches)
}

/// The statistics of a partitioned search: the counters and times summed over the partitions, the constants
/// (orientations, components, pairs) of the first.
pub(super) fn merged_stats(searches: &[Search<'_, '_>]) -> PlacementStats {
    let mut stats = searches.first().map(|s| s.stats.clone()).unwrap_or_default();
    for s in searches.iter().skip(1).map(|s| &s.stats) {
        stats.orientations_considered += s.orientations_considered;
        stats.orientations_empty_omega += s.orientations_empty_omega;
        stats.pairs_evaluated += s.pairs_evaluated;
        stats.obstacles_constructed += s.obstacles_constructed;
        stats.obstacles_extrapolated += s.obstacles_extrapolated;
        stats.obstacle_cache_hits += s.obstacle_cache_hits;
        stats.interference_tests += s.interference_tests;
        stats.known_obstacle_cuts += s.known_obstacle_cuts;
        stats.narrow_phase_tests += s.narrow_phase_tests;
        stats.nodes_expanded += s.nodes_expanded;
        stats.nodes_pushed += s.nodes_pushed;
        stats.cells_empty += s.cells_empty;
        stats.cells_unsolved += s.cells_unsolved;
        stats.qp_solves += s.qp_solves;
        stats.time_setup_ms += s.time_setup_ms;
        stats.time_roots_ms += s.time_roots_ms;
        stats.time_interference_ms += s.time_interference_ms;
        stats.time_obstacles_ms += s.time_obstacles_ms;
        stats.time_cells_ms += s.time_cells_ms;
    }
    stats
}

/// How many placements a partition finds ahead of the merge while another partition searches up to the best found
/// one ("Partitions" in the module documentation).
pub(super) const LOOK_AHEAD: usize = 4;

/// Pops per partition between two exchanges of the partitions' next placements ("Partitions" in the module
/// documentation).
pub(super) const ROUND_POPS: u64 = 256;

/// The whole search of [`place_with_caches`]: roots, then `k` placements.
pub(super) fn run<const D: usize>(
    searches: &mut [Search<'_, '_>],
    fixed_z: f64,
) -> Result<PlacementResult, PlacementError> {
    let Some(k) = searches.first().map(|s| s.request.k) else {
        return Err(PlacementError::BadOption("no search partition".into()));
    };
    let Some(mut states) = start_all::<D>(searches, fixed_z)? else {
        return Ok(PlacementResult {
            placements: Vec::new(),
            exhausted: Some(NoPlacement::EmptyOmega),
            stats: merged_stats(searches),
        });
    };
    let (placements, _) = advance_all(searches, &mut states, k, f64::INFINITY)?;
    let exhausted = (placements.len() < k).then_some(NoPlacement::FitsNowhere);
    Ok(PlacementResult { placements, exhausted, stats: merged_stats(searches) })
}

/// Every partition's roots and state; `None` when Omega is empty at every orientation.
pub(super) fn start_all<const D: usize>(
    searches: &mut [Search<'_, '_>],
    fixed_z: f64,
) -> Result<Option<Vec<RunState<D>>>, PlacementError> {
    let states = searches.iter_mut().map(|s| s.start::<D>(fixed_z)).collect::<Result<Vec<_>, _>>()?;
    Ok(states.iter().any(|s| !s.heap.is_empty()).then_some(states))
}

/// Every partition's carried state reopened and widened (`Search::widen`).
pub(super) fn widen_all<const D: usize>(
    searches: &mut [Search<'_, '_>],
    states: Vec<RunState<D>>,
    old: Option<&FloorVolume>,
) -> Result<Vec<RunState<D>>, PlacementError> {
    searches.iter_mut().zip(states).map(|(s, state)| s.widen(state.reopened(), old)).collect()
}

/// The next `want` placements of the partitioned search ("Partitions" in the module documentation): a k-way merge
/// of the partitions' next placements in the heap's order, the partitions advanced in rounds; one partition is the
/// sequential loop itself ([`Search::advance`]). Returns `true` when it stopped at `max_cost`.
pub(super) fn advance_all<const D: usize>(
    searches: &mut [Search<'_, '_>],
    states: &mut [RunState<D>],
    want: usize,
    max_cost: f64,
) -> Result<(Vec<Placement>, bool), PlacementError> {
    if let ([search], [state]) = (&mut *searches, &mut *states) {
        return search.advance(state, want, max_cost, None, u64::MAX);
    }
    let mut placements = Vec::new();
    if want == 0 {
        return Ok((placements, false));
    }
    // per partition: 0 idle, 1 needed (its next placement may precede every found one), 2 looking ahead
    let mut roles = vec![0u8; states.len()];
    loop {
        // the cheapest found placement of all partitions: every other partition searches up to its key
        let best = states
            .iter()
            .enumerate()
            .filter_map(|(i, s)| s.ahead.front().map(|(key, _)| (i, *key)))
            .reduce(|a, b| if pops_after(b.1, a.1) { a } else { b });
        let bound = best.map(|(_, key)| key);
        for (role, s) in roles.iter_mut().zip(states.iter()) {
            let open = s.heap.peek_key().filter(|top| top.cost() <= max_cost);
            *role = match open {
                Some(top) if s.ahead.is_empty() && bound.is_none_or(|b| pops_after(b, top)) => 1,
                Some(_) if s.ahead.len() < LOOK_AHEAD => 2,
                _ => 0,
            };
        }
        let needed = roles.iter().filter(|r| **r == 1).count();
        if needed == 0 {
            // every partition either holds its next placement or has nothing left before the best one (or within
            // the limit): the best one is the next placement of the whole search
            match best {
                Some((i, key)) if key.cost() <= max_cost => {
                    if let Some((_, placement)) = states[i].ahead.pop_front() {
                        placements.push(placement);
                    }
                    if placements.len() >= want {
                        return Ok((placements, false));
                    }
                    continue;
                }
                _ => {
                    let limited = states.iter().any(|s| !s.ahead.is_empty() || !s.heap.is_empty());
                    return Ok((placements, limited));
                }
            }
        }
        let running = roles.iter().filter(|r| **r != 0).count();
        if running == 1 {
            // alone it cannot learn a new bound from the others: no rounds
            if let Some(i) = roles.iter().position(|r| *r == 1) {
                searches[i].step(&mut states[i], 1, max_cost, bound, u64::MAX)?;
            }
            continue;
        }
        // a round: the needed partitions search for their next placement up to the best one, the others look
        // further ahead (placements the caller may ask for next; the work stays in the state either way)
        // (a partition that finishes its round first waits, spinning, for the others: `RoundEnd`)
        let round_end = RoundEnd::new(roles.len());
        let results: Vec<Result<(), PlacementError>> = searches
            .par_iter_mut()
            .zip(states.par_iter_mut())
            .zip(roles.par_iter())
            .enumerate()
            .map(|(i, ((search, state), &role))| {
                let want = match role {
                    1 => 1,
                    2 => LOOK_AHEAD - state.ahead.len(),
                    _ => return Ok(()),
                };
                round_end.start(i);
                let bound = if role == 1 { bound } else { None };
                let result = search.step(state, want, max_cost, bound, ROUND_POPS);
                round_end.finish(i);
                result
            })
            .collect();
        for result in results {
            result?;
        }
        searches[0].rounds += 1;
    }
}
