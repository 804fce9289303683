//! One part added to the stack: the seed's two stages (\[A\] II-B), each a placement search whose candidates are
//! tested in cost order until one passes, and the choice between the stages' parts (module documentation of
//! [`crate::stack_plan`], steps 2-4).
//!
//! Cost: per stage one search ([`crate::search`], continued from the plan's carried frontier) and at most
//! `max_candidates` candidate tests ([`super::candidate`]).

use super::candidate::{Candidate, Verdict};
use super::floor::{clip_to_rectangle, footprint};
use super::{PlanError, PlanOptions, PlanStats, PlannedPart, Rejections};
use crate::orientation::Orientation;
use crate::request::{Cost, FloorVolume, PlacementError, PlacementRequest};
use crate::search::{NoPlacement, Placement, PlacementSearch, SearchCaches};
use glam::{DMat3, DVec2, DVec3};
use stackplan_cspace::cache::ObstacleCache;
use stackplan_geom::{Part, Pose};
use stackplan_stability::growing::GrowingStack;
use stackplan_stability::world::PlacedPart;
use std::time::Instant;

/// The state a plan keeps from part to part: the stack so far, the caches its searches share and the stack as the
/// candidate tests see it.
pub(super) struct Planner<'p> {
    pub(super) part: &'p Part,
    pub(super) options: &'p PlanOptions,
    /// The resting poses searched (graspable ones, lowest c.g. first).
    pub(super) rests: Vec<DMat3>,
    pub(super) thetas: Vec<f64>,
    /// `(x0, y0, z0)` of cost (1).
    pub(super) origin: DVec3,
    /// The searches' linear tolerance.
    pub(super) tol: f64,
    /// Shared by every search of the plan: the stack only grows and its parts never move.
    pub(super) cache: ObstacleCache,
    pub(super) caches: SearchCaches,
    /// One per resting pose: the caches of the searches on the floor itself ([`FloorSearch::run`]), whose
    /// orientations and fixed height differ from the stages' (sharing would clear their carried frontier).
    pub(super) floor_caches: Vec<SearchCaches>,
    /// The stack as the candidate tests see it: its parts in world coordinates, their contacts and the memos of the
    /// tests, kept from candidate to candidate and from part to part.
    pub(super) growing: GrowingStack<'p>,
    pub(super) placed: Vec<Pose>,
    pub(super) planned: Vec<PlannedPart>,
    pub(super) stats: PlanStats,
    pub(super) started: Instant,
    pub(super) deadline: Option<Instant>,
}

/// A stage's first candidate that passed every test.
#[derive(Debug, Clone)]
struct Accepted {
    stage: u8,
    candidate: Placement,
    release_drop: f64,
    /// Candidates of the stage rejected before it.
    rejected: usize,
    grasp_radius: f64,
}

/// What the search on the floor itself found ([`FloorSearch::run`]).
enum FloorEnd {
    /// The cheapest floor position that passed.
    Found(Accepted),
    /// None cheaper than the bound passed among the first candidates of each resting pose.
    None,
    /// A search limit (node budget or time) ended the plan, for the reason given.
    Limit(String),
}

/// How a stage's candidate loop ended.
enum StageEnd {
    /// The stage is done (a part accepted or not); the next stage may run.
    Done,
    /// A search limit (node budget or time) ended the plan, for the reason given.
    Limit(String),
}

impl<'p> Planner<'p> {
    /// Places part `index` (0-based): `Ok(None)` when it was placed, `Ok(Some(reason))` when the plan ends here.
    pub(super) fn place_part(&mut self, index: usize) -> Result<Option<String>, PlanError> {
        let options = self.options;
        if self.deadline.is_some_and(|d| Instant::now() >= d) {
            return Ok(Some(format!(
                "the time limit of {} s was reached after {index} of {} parts",
                options.time_limit.unwrap_or(0.0),
                options.count
            )));
        }
        let mut last_reason = String::from("no interference-free position");
        let before = Rejections::of(&self.stats);
        let mut accepted: Vec<Accepted> = Vec::new();
        let stages = self.stages();
        let last_stage = stages.last().map_or(2, |s| s.0);
        let mut stage_one_region: Option<Vec<DVec2>> = None;
        for (stage, floor) in stages {
            let end = self.search_stage(
                index,
                stage,
                floor,
                stage == last_stage,
                &mut accepted,
                &mut stage_one_region,
                &mut last_reason,
            )?;
            if let StageEnd::Limit(reason) = end {
                return Ok(Some(reason));
            }
        }
        let Some(best) = choose(&accepted) else {
            return Ok(Some(format!("part {} of {} could not be placed: {last_reason}", index + 1, options.count)));
        };
        let (part, candidate) = (self.part, &best.candidate);
        let pose = candidate.pose();
        self.placed.push(pose);
        self.growing.push(PlacedPart { part, pose }).map_err(|e| PlanError::Check(e.to_string()))?;
        self.planned.push(PlannedPart {
            position: candidate.position,
            rotation: candidate.rotation,
            index,
            theta_deg: candidate.theta_deg,
            resting_pose: candidate.resting_pose,
            stage: best.stage,
            cost: candidate.cost,
            contacts: candidate.contacts.clone(),
            release_drop: best.release_drop,
            rejected_candidates: best.rejected,
            rejections: Rejections::of(&self.stats).minus(&before),
            cg_height: pose.apply(part.mass().center_of_gravity).z,
            stability_margin: None,
            grasp_radius: best.grasp_radius,
        });
        tracing::info!(index, stage = best.stage, cost = candidate.cost, "placed part");
        Ok(None)
    }

    /// The stages of the next part: stage 1 within the stack's footprint grown by the nesting allowance (clipped to
    /// the floor; none for the first part or a degenerate clip), stage 2 the whole floor.
    fn stages(&self) -> Vec<(u8, FloorVolume)> {
        let options = self.options;
        let mut stages = Vec::with_capacity(2);
        if !self.placed.is_empty() {
            let (lo, hi) = footprint(self.part, &self.placed);
            let a = DVec2::splat(options.nest_allowance);
            let polygon = clip_to_rectangle(&options.floor.polygon, lo - a, hi + a);
            if polygon.len() >= 3 {
                stages.push((1, FloorVolume { polygon, height: options.floor.height }));
            }
        }
        stages.push((2, options.floor.clone()));
        stages
    }

    /// The request of a stage's search.
    fn request(&self, floor: FloorVolume, searched_elsewhere: Option<Vec<DVec2>>) -> PlacementRequest<'p> {
        let p = Planned { part: self.part, options: self.options, placed: &self.placed, rests: &self.rests };
        p.request(&self.thetas, self.origin, self.deadline, floor, searched_elsewhere)
    }

    /// One stage: its search's candidates in cost order, each tested until one passes (pushed to `accepted`).
    ///
    /// A stage tests `candidates` candidates; the last one, when nothing at all was accepted, continues the same
    /// search up to `max_candidates`; a stage after one that accepted a part tests every candidate cheaper than that
    /// part (up to `max_candidates`; the cost limit ends the search), so no cheaper stage-2 candidate that passes is
    /// left behind a budget of failed ones. Stage 2 after an accepted stage 1 searches outside stage 1's region.
    #[allow(clippy::too_many_arguments)]
    fn search_stage(
        &mut self,
        index: usize,
        stage: u8,
        floor: FloorVolume,
        last: bool,
        accepted: &mut Vec<Accepted>,
        stage_one_region: &mut Option<Vec<DVec2>>,
        last_reason: &mut String,
    ) -> Result<StageEnd, PlanError> {
        let options = self.options;
        let polygon = (stage == 1).then(|| floor.polygon.clone());
        // stage 1 accepted a part: its region holds nothing cheaper that passes, so stage 2 searches outside it
        let elsewhere = if stage == 2 && !accepted.is_empty() { stage_one_region.take() } else { None };
        let request = self.request(floor, elsewhere);
        // `beaten_at` is set iff a part was accepted, so both cases of the longer limit are "last stage, or beaten"
        let beaten_at = accepted.iter().map(|a| a.candidate.cost).reduce(f64::min);
        let limit = if last || beaten_at.is_some() { options.tuning.max_candidates } else { options.tuning.candidates };
        let started = Instant::now();
        let mut search = match PlacementSearch::new(&request, &self.cache, &mut self.caches) {
            Ok(search) => search,
            // stage 1's clipped floor may be malformed (a sliver): fall through to stage 2
            Err(PlacementError::BadFloor(msg)) if stage == 1 => {
                tracing::debug!(index, "stage 1 floor rejected: {msg}");
                return Ok(StageEnd::Done);
            }
            Err(e @ (PlacementError::NodeBudget { .. } | PlacementError::TimeLimit { .. })) => {
                return Ok(StageEnd::Limit(limit_reason(index, options, &e, self.started)));
            }
            Err(e) => return Err(e.into()),
        };
        self.stats.seconds_search += started.elapsed().as_secs_f64();
        self.stats.searches += 1;
        // the cheapest floor position that passes, searched once the last stage's first candidates have all failed:
        // its cost bounds the rest of the stage, and it is taken when nothing cheaper passes
        let mut on_floor: Option<Accepted> = None;
        let mut bound = beaten_at.unwrap_or(f64::INFINITY);
        let mut tested = 0;
        // candidates one at a time: the search stops at the first that passes
        while tested < limit {
            // the checks of many rejected candidates can take longer than the searches
            if self.deadline.is_some_and(|d| Instant::now() >= d) {
                let e = PlacementError::TimeLimit { found: tested };
                return Ok(StageEnd::Limit(limit_reason(index, options, &e, self.started)));
            }
            if tested == options.tuning.candidates {
                self.stats.repeated_searches += 1;
                tracing::debug!(index, "every candidate failed the checks: searching for more");
                if last {
                    let floor_search = FloorSearch {
                        planned: Planned { part: self.part, options, placed: &self.placed, rests: &self.rests },
                        thetas: &self.thetas,
                        origin: self.origin,
                        tol: self.tol,
                        cache: &self.cache,
                        caches: &mut self.floor_caches,
                        growing: &mut self.growing,
                        stats: &mut self.stats,
                        started: self.started,
                        deadline: self.deadline,
                    };
                    match floor_search.run(index, &request.cost, bound)? {
                        FloorEnd::Found(found) => {
                            bound = found.candidate.cost;
                            on_floor = Some(found);
                        }
                        FloorEnd::None => {}
                        FloorEnd::Limit(reason) => return Ok(StageEnd::Limit(reason)),
                    }
                }
            }
            let started = Instant::now();
            // a later stage's part is taken only when strictly cheaper than an earlier stage's ([`choose`]): past
            // the cheapest accepted cost the search has nothing left that could be taken
            let next = match search.next_placements_within(1, bound) {
                Ok(next) => next,
                Err(e @ (PlacementError::NodeBudget { .. } | PlacementError::TimeLimit { .. })) => {
                    return Ok(StageEnd::Limit(limit_reason(index, options, &e, self.started)));
                }
                Err(e) => return Err(e.into()),
            };
            self.stats.seconds_search += started.elapsed().as_secs_f64();
            let Some(found) = next.placements.first().filter(|c| bound == f64::INFINITY || cheaper(c.cost, bound))
            else {
                if tested == 0 {
                    *last_reason = match next.exhausted {
                        Some(NoPlacement::EmptyOmega) => "the floor volume is too small for the part".into(),
                        _ => "no interference-free position inside the floor volume".into(),
                    };
                }
                break;
            };
            let started = Instant::now();
            self.stats.candidates_checked += 1;
            let tested_candidate = Candidate {
                part: self.part,
                rests: &self.rests,
                options,
                cache: &self.cache,
                tol: self.tol,
                cost: &request.cost,
                searched_floor: polygon.as_ref().map(|_| &request.floor),
            }
            .test(found, search.scene(), &mut self.growing, &mut self.stats)?;
            self.stats.seconds_checks += started.elapsed().as_secs_f64();
            tracing::trace!(
                index,
                stage,
                tested,
                cost = tested_candidate.placement.cost,
                theta_deg = tested_candidate.placement.theta_deg,
                resting_pose = tested_candidate.placement.resting_pose,
                position = ?tested_candidate.placement.position,
                nodes = search.stats().nodes_expanded,
                verdict = ?tested_candidate.verdict,
                "candidate tested"
            );
            match tested_candidate.verdict {
                Verdict::Passed { grasp_radius } => {
                    accepted.push(Accepted {
                        stage,
                        candidate: tested_candidate.placement,
                        release_drop: tested_candidate.release_drop,
                        rejected: tested,
                        grasp_radius,
                    });
                    on_floor = None;
                    break;
                }
                Verdict::Rejected(reason) => *last_reason = reason,
            }
            tested += 1;
        }
        if let Some(mut found) = on_floor {
            // nothing cheaper passed (or the candidates ran out first): the floor position, after the `tested`
            // candidates of the stage that failed
            tracing::debug!(index, tested, cost = found.candidate.cost, "placed on the floor after failed candidates");
            found.rejected = tested;
            accepted.push(found);
        }
        if polygon.is_some() {
            *stage_one_region = polygon;
        }
        let searched = search.stats();
        self.stats.pairs_evaluated += searched.pairs_evaluated;
        self.stats.obstacles_constructed += searched.obstacles_constructed;
        self.stats.obstacles_extrapolated += searched.obstacles_extrapolated;
        self.stats.cells_unsolved += searched.cells_unsolved;
        tracing::debug!(
            index,
            stage,
            nodes = searched.nodes_expanded,
            pairs = searched.pairs_evaluated,
            known_cuts = searched.known_obstacle_cuts,
            detections = searched.interference_tests,
            pushed = searched.nodes_pushed,
            qps = searched.qp_solves,
            orientations = searched.orientations_considered,
            ms_detect = searched.time_interference_ms,
            ms_obstacles = searched.time_obstacles_ms,
            ms_cells = searched.time_cells_ms,
            ms = searched.time_total_ms,
            "stage searched"
        );
        Ok(StageEnd::Done)
    }
}

/// What a plan's stack is made of, for building a search request.
struct Planned<'r, 'p> {
    part: &'p Part,
    options: &'p PlanOptions,
    placed: &'r [Pose],
    rests: &'r [DMat3],
}

impl<'p> Planned<'_, 'p> {
    /// The request of a search of the plan on `floor`: the plan's resting poses, thetas, clearance (horizontal),
    /// cost, insertion, partitions and limits, into the stack placed so far.
    fn request(
        &self,
        thetas: &[f64],
        origin: DVec3,
        deadline: Option<Instant>,
        floor: FloorVolume,
        searched_elsewhere: Option<Vec<DVec2>>,
    ) -> PlacementRequest<'p> {
        let (part, options) = (self.part, self.options);
        let stack: Vec<PlacedPart<'p>> = self.placed.iter().map(|&pose| PlacedPart { part, pose }).collect();
        let mut request = PlacementRequest::new(part, stack, floor);
        request.tuning.searched_elsewhere = searched_elsewhere;
        request.resting_rotations = self.rests.to_vec();
        request.thetas = thetas.to_vec();
        request.clearance = options.clearance;
        request.horizontal_clearance = true;
        request.cost = Cost::Stacking { w: options.w, origin };
        request.insertion = options.insertion;
        request.tuning.partitions = options.tuning.partitions;
        request.tuning.node_budget = options.tuning.node_budget;
        request.deadline = deadline;
        request
    }
}

/// The search on the floor itself ([`FloorSearch::run`]), with the parts of the plan it uses.
struct FloorSearch<'r, 'p> {
    planned: Planned<'r, 'p>,
    thetas: &'r [f64],
    origin: DVec3,
    tol: f64,
    cache: &'r ObstacleCache,
    /// One per resting pose: the caches of the searches on the floor, whose orientations and fixed height differ
    /// from the stages' (sharing would clear their carried frontier).
    caches: &'r mut [SearchCaches],
    growing: &'r mut GrowingStack<'p>,
    stats: &'r mut PlanStats,
    started: Instant,
    deadline: Option<Instant>,
}

impl FloorSearch<'_, '_> {
    /// The cheapest position on the floor itself that passes the tests and costs less than `bound`, over the resting
    /// poses: per pose a 2-D search at the height where the pose rests on the floor (\[A\] VII-A-2, `p_z` fixed),
    /// its first `candidates` candidates tested in cost order.
    ///
    /// Why: on a stack of bent parts, the cheapest positions of the 3-D search are mostly perched on rims and edges,
    /// and thousands of them can fail the stability test before the search reaches the floor beside the stack (a
    /// cell whose optimum is perched may also hold floor positions that its optimum hides). A part resting on the
    /// floor in a stable pose is stable by itself, so the floor's cheapest passing position bounds the 3-D search:
    /// nothing dearer needs to be tested, and when nothing cheaper passes it is the part's place.
    fn run(self, index: usize, cost: &Cost, bound: f64) -> Result<FloorEnd, PlanError> {
        let (part, options) = (self.planned.part, self.planned.options);
        let mut best: Option<Accepted> = None;
        for (rest_index, &rest) in self.planned.rests.iter().enumerate() {
            // the pose rests on the floor where its lowest vertex is at z = 0: `p_z = -min_v (R v)_z`, the bits of
            // the search's own floor constraint (a turn about z does not change z)
            let lo_z = Orientation::without_components(part, 0, rest_index, 0, 0.0, rest, cost).lo.z;
            let mut request =
                self.planned.request(self.thetas, self.origin, self.deadline, options.floor.clone(), None);
            request.resting_rotations = vec![rest];
            request.fixed_z = Some(-lo_z);
            let limit = best.as_ref().map_or(bound, |b| b.candidate.cost);
            let started = Instant::now();
            let mut search = match PlacementSearch::new(&request, self.cache, &mut self.caches[rest_index]) {
                Ok(search) => search,
                Err(e @ (PlacementError::NodeBudget { .. } | PlacementError::TimeLimit { .. })) => {
                    return Ok(FloorEnd::Limit(limit_reason(index, options, &e, self.started)));
                }
                Err(e) => return Err(e.into()),
            };
            self.stats.searches += 1;
            self.stats.seconds_search += started.elapsed().as_secs_f64();
            for tested in 0..options.tuning.candidates {
                let started = Instant::now();
                let next = match search.next_placements_within(1, limit) {
                    Ok(next) => next,
                    Err(e @ (PlacementError::NodeBudget { .. } | PlacementError::TimeLimit { .. })) => {
                        return Ok(FloorEnd::Limit(limit_reason(index, options, &e, self.started)));
                    }
                    Err(e) => return Err(e.into()),
                };
                self.stats.seconds_search += started.elapsed().as_secs_f64();
                let Some(found) = next.placements.first().filter(|c| limit == f64::INFINITY || cheaper(c.cost, limit))
                else {
                    break;
                };
                // the request's only resting pose is the plan's `rest_index`
                let found = Placement { resting_pose: rest_index, ..found.clone() };
                let started = Instant::now();
                self.stats.candidates_checked += 1;
                let tested_candidate = Candidate {
                    part,
                    rests: self.planned.rests,
                    options,
                    cache: self.cache,
                    tol: self.tol,
                    cost,
                    searched_floor: None,
                }
                .test(&found, search.scene(), self.growing, self.stats)?;
                self.stats.seconds_checks += started.elapsed().as_secs_f64();
                tracing::trace!(index, rest_index, tested, cost = found.cost, verdict = ?tested_candidate.verdict, "floor candidate tested");
                if let Verdict::Passed { grasp_radius } = tested_candidate.verdict {
                    best = Some(Accepted {
                        stage: 2,
                        candidate: tested_candidate.placement,
                        release_drop: tested_candidate.release_drop,
                        rejected: 0,
                        grasp_radius,
                    });
                    break;
                }
            }
        }
        Ok(best.map_or(FloorEnd::None, FloorEnd::Found))
    }
}

/// The part taken among the stages' accepted ones: stage 1 (compact) wins unless stage 2 is strictly cheaper, so
/// ties and near-ties keep the stack compact.
fn choose(accepted: &[Accepted]) -> Option<&Accepted> {
    accepted.iter().min_by(|a, b| {
        let (ca, cb) = (a.candidate.cost, b.candidate.cost);
        if cheaper(ca, cb) {
            std::cmp::Ordering::Less
        } else if cheaper(cb, ca) {
            std::cmp::Ordering::Greater
        } else {
            a.stage.cmp(&b.stage)
        }
    })
}

/// Whether cost `a` beats cost `b` outright: cheaper by more than a near-tie (`1e-9` relative), which keeps the
/// earlier (more compact) stage's part.
fn cheaper(a: f64, b: f64) -> bool {
    b - a > 1e-9 * (1.0 + a.abs().max(b.abs()))
}

/// Why a plan ended at part `index` on a search limit (node budget or time), with the parts it keeps.
fn limit_reason(index: usize, options: &PlanOptions, e: &PlacementError, started: Instant) -> String {
    let limit = match e {
        PlacementError::TimeLimit { .. } => {
            format!("the time limit of {} s was reached", options.time_limit.unwrap_or(0.0))
        }
        _ => format!("the search exceeded its node budget of {} nodes", options.tuning.node_budget),
    };
    format!(
        "part {} of {} could not be placed: {limit} after {:.1} s; the {index} parts placed before it are kept",
        index + 1,
        options.count,
        started.elapsed().as_secs_f64()
    )
}
