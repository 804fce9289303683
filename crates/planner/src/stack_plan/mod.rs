//! The stacking planner for n identical parts (\[A\] section II-B, "generate and test"; `docs/algorithms.md`,
//! "Placement search" and "Stability, grasp and insertion").
//!
//! Parts are added one at a time; the parts already placed never move. For each new part:
//!
//! 1. candidate orientations: the part's stable resting poses that present an upward face holding the suction cup
//!    ([`stackplan_stability::resting_poses`](fn@stackplan_stability::resting_poses),
//!    [`stackplan_stability::grasp`]; at most [`PlanOptions::max_resting_poses`], lowest c.g. first) x the discrete
//!    theta set;
//! 2. the best-first placement search ([`crate::search::PlacementSearch`]) gives interference-free positions one at
//!    a time in the order of the part's term of cost (1), one per free-space cell, up to
//!    [`PlanTuning::candidates`] per stage (the search stops at the first that passes step 3, so later ones are
//!    never searched for); with `insertion` every candidate can be lowered straight down into place (insertion
//!    obstacles). The searches of a plan carry their open cells to the next part's search with the same floor
//!    (or a floor that grew: stage 1's footprint), [`crate::search::SearchCaches::carrying_frontiers`];
//! 3. the candidates are settled (`settle.rs`) and tested in cost order on the stack placed so far
//!    ([`stackplan_stability::growing::GrowingStack`]: the verdicts of [`stackplan_stability::check_added_part`],
//!    the new part's report of [`stackplan_stability::check::check_stack`], without re-checking the parts that
//!    passed before, up to the first that fails, with the placed parts' contacts and the memos kept from candidate
//!    to candidate): the new part statically stable on its supports (friction cones), the whole stack stable, a
//!    suction face for the cup, insertable from above, and (with a clearance) the horizontal clearance at the release
//!    position as `stackplan check` measures it ([`GrowingStack::keeps_clearance`]: the search guarantees it up to its
//!    tolerance along obstacle face normals, a few 1e-5 mm horizontally next to faces tilted by about 1e-5 rad); the
//!    first that passes is taken;
//! 4. the seed's two stages: stage 1 searches within the stack's current floor footprint (its bounding rectangle
//!    grown by `nest_allowance`, clipped to the floor), so the stack's bounding box is not enlarged, or only
//!    slightly to nest; stage 2 searches the whole floor, and when stage 1 accepted a part it searches only outside
//!    stage 1's region ([`crate::request::SearchTuning::searched_elsewhere`]: the positions at which the part lies inside that
//!    region were stage 1's, whose candidates cheaper than its part all failed the checks, so stage 2 does not search
//!    the stack's footprint a second time). Stage 1's part is taken unless stage 2's is strictly
//!    cheaper (the seed takes stage 1 whenever it succeeds; with `w = 0` that would stack parts on top of each other
//!    instead of spreading them on the floor as its own Fig. 2 shows, so here the footprint limit breaks ties and
//!    near-ties of cost (1) in favour of a compact stack, and never overrides the cost). So that it never does,
//!    stage 2 after an accepted stage 1 tests every candidate cheaper than stage 1's part (up to
//!    [`PlanTuning::max_candidates`]), not only [`PlanTuning::candidates`]: with 8, Complex at `w 0.1` put its
//!    9th part on top of the stack at cost 134 304 while a floor position at 45 758 passed;
//! 5. the floor as a bound: when the last stage's first [`PlanTuning::candidates`] candidates have all failed, the
//!    cheapest position on the floor itself that passes is searched (per resting pose a 2-D search at the height
//!    where the pose rests on the floor, \[A\] VII-A-2, its first candidates tested; `part.rs`, `FloorSearch`). A
//!    part resting on the floor in a stable pose is stable by itself, so this position bounds the rest of the stage:
//!    the stage tests only candidates strictly cheaper than it, and takes it when none of them passes or
//!    [`PlanTuning::max_candidates`] is reached. On a stack of bent parts most of the cheapest 3-D positions are
//!    perched on rims and edges and fail the stability test, thousands in a row, while the floor beside the stack is
//!    free (and a cell whose optimum is perched can hold floor positions that its optimum hides): without the bound,
//!    15-part plans of the real parts `bendfm_0` and `bendfm_1` (`fixtures/realparts/`) ended after 8 and 9 parts.
//!
//! A part that fits nowhere ends the plan with the reason; the plan keeps the parts placed so far.
//! Cost: O(n) placements, each the search of [`crate::search`] plus at most `candidates` stack checks.

mod candidate;
pub(crate) mod floor;
mod part;

use crate::request::{FloorVolume, PlacementError, thetas_with_step};
use crate::search::{Contact, SearchCaches};
use glam::{DMat3, DVec2, DVec3};
use part::Planner;
use serde::{Deserialize, Serialize};
use stackplan_cspace::cache::ObstacleCache;
use stackplan_geom::{Part, Pose, Tolerance};
use stackplan_stability::check::{CheckOptions, check_stack};
use stackplan_stability::grasp::{GraspOptions, grasp_faces, is_graspable};
use stackplan_stability::growing::{GrowingStack, ToleranceScale};
use stackplan_stability::world::PlacedPart;

/// Options of a stacking plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanOptions {
    /// Number of parts to stack (at least 1).
    pub count: usize,
    /// Floor volume `Sigma` (floor polygon x [0, max height]).
    pub floor: FloorVolume,
    /// Weight `w` of cost (1) in `[0, 1]`.
    pub w: f64,
    /// `(x0, y0, z0)` of cost (1); `None`: the floor polygon's centroid at `z0 = 0`.
    pub origin: Option<DVec3>,
    /// Horizontal clearance between parts (mm), for the robot's positioning error (\[A\] eq. 10-11; "separated in the
    /// plane by at least 5 mm", \[A\] VII-B); parts may still rest on each other.
    pub clearance: f64,
    /// Step of the discrete rotation about z (radians).
    pub dtheta: f64,
    /// Coulomb friction coefficient for the stability check.
    pub mu: f64,
    /// Suction cup diameter (mm).
    pub cup_diameter: f64,
    /// Require top-down insertion (insertion obstacles in the search, and the check).
    pub insertion: bool,
    /// Resting poses considered (lowest c.g. first).
    pub max_resting_poses: usize,
    /// How far stage 1 may grow the stack's footprint to nest a part (mm).
    pub nest_allowance: f64,
    /// Seconds the whole plan may take: past them the plan ends with the parts placed so far and says why. `None`:
    /// no limit.
    #[serde(default)]
    pub time_limit: Option<f64>,
    /// Largest tilt from level of a face that holds the suction cup (radians;
    /// [`stackplan_stability::grasp::GraspOptions::max_tilt`]). [`PlanOptions::new`]:
    /// [`stackplan_stability::grasp::DEFAULT_MAX_TILT`]; a plan file without it was made with level faces only (0).
    #[serde(default)]
    pub grasp_tilt: f64,
    /// How the planner searches: candidate counts and the search's limits and partitions ([`PlanTuning`]; written
    /// into plan files beside the other options).
    #[doc(hidden)]
    #[serde(flatten)]
    pub tuning: PlanTuning,
}

/// How the stacking planner searches: limits and counts that decide how much work it does before it gives up, and
/// the partitions that the plan depends on (never on the thread count). [`PlanTuning::default`] is what the
/// command line uses unless told otherwise.
#[doc(hidden)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanTuning {
    /// Interference-free candidates per part and stage, tested in cost order (a stage 2 after an accepted stage 1
    /// tests every candidate cheaper than stage 1's part, up to `max_candidates`).
    pub candidates: usize,
    /// When every candidate of the last stage fails the checks (and no stage accepted one), the search there
    /// continues with more candidates, up to this many in all: a part fits nowhere only when the search is exhausted
    /// or this limit is reached. Equal to `candidates`: no continuation. [`PlanOptions::new`]:
    /// [`DEFAULT_MAX_CANDIDATES`]; a plan file without it was made with 1024.
    #[serde(default = "legacy_max_candidates")]
    pub max_candidates: usize,
    /// Partitions of the orientations each placement search splits into, searched in parallel
    /// ([`crate::request::SearchTuning::partitions`]; the plan depends on this number, never on the thread
    /// count; 1: the sequential search).
    #[serde(default = "default_partitions")]
    pub partitions: usize,
    /// Largest number of nodes one placement search may pop (per partition): past it the plan ends with the parts
    /// placed so far and says why. [`crate::request::DEFAULT_NODE_BUDGET`].
    #[serde(default = "default_node_budget")]
    pub node_budget: usize,
}

impl Default for PlanTuning {
    fn default() -> Self {
        Self {
            candidates: 8,
            max_candidates: DEFAULT_MAX_CANDIDATES,
            partitions: default_partitions(),
            node_budget: default_node_budget(),
        }
    }
}

fn default_node_budget() -> usize {
    crate::request::DEFAULT_NODE_BUDGET
}

/// The default of [`PlanTuning::max_candidates`]. Some plans reject more than 1024 candidates in a row while the
/// floor beside the stack is free: candidates on and around a full-height column at `w = 1`, or the 13th part of
/// the `plan-l-corner-w0.1` scenario, which passes at its 1109th candidate. With candidates found not stable
/// remembered (`GrowingStack`), a repeated one costs a few µs.
pub const DEFAULT_MAX_CANDIDATES: usize = 4096;

/// [`PlanTuning::max_candidates`] of a plan file written before the field existed.
fn legacy_max_candidates() -> usize {
    1024
}

fn default_partitions() -> usize {
    crate::request::DEFAULT_PARTITIONS
}

impl PlanOptions {
    /// Defaults of the seed's examples: w = 0.5, 5 mm clearance, 1-degree steps, mu = 0.5, 10 mm cup, insertion,
    /// 8 candidates (up to [`DEFAULT_MAX_CANDIDATES`] when all fail), 3 resting poses, 5 mm nesting allowance, 2
    /// search partitions.
    pub fn new(count: usize, floor: FloorVolume) -> Self {
        Self {
            count,
            floor,
            w: 0.5,
            origin: None,
            clearance: 5.0,
            dtheta: 1f64.to_radians(),
            mu: 0.5,
            cup_diameter: 10.0,
            insertion: true,
            max_resting_poses: 3,
            nest_allowance: 5.0,
            time_limit: None,
            grasp_tilt: stackplan_stability::grasp::DEFAULT_MAX_TILT,
            tuning: PlanTuning::default(),
        }
    }
}

/// One planned part.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlannedPart {
    /// Position of the part (world vertex = rotation . v + position).
    pub position: [f64; 3],
    /// Rotation matrix rows.
    pub rotation: [[f64; 3]; 3],
    /// Order in the stack (0 = first placed).
    pub index: usize,
    /// Angle about z (degrees).
    pub theta_deg: f64,
    /// Index of the resting pose (into [`Plan::resting_poses`]).
    pub resting_pose: usize,
    /// Stage that placed it: 1 (within the stack's footprint) or 2 (the whole floor).
    pub stage: u8,
    /// The part's term of cost (1).
    pub cost: f64,
    /// What it touches: the active constraints at the search's optimum or, after a drop, what stopped the drop.
    pub contacts: Vec<Contact>,
    /// How far the part drops after the robot releases it (mm): the search's position with the horizontal clearance
    /// floats this far above an inclined support (`settle.rs`); `position` is where it comes to rest and the
    /// robot releases it at `position + release_drop z`. 0 for a part that rests where it is released.
    #[serde(default)]
    pub release_drop: f64,
    /// Interference-free candidates tested before this one passed in its stage (0 = the cheapest passed).
    pub rejected_candidates: usize,
    /// Every candidate rejected while this part was placed (in every stage and the floor search), by reason.
    #[serde(default)]
    pub rejections: Rejections,
    /// Height of the c.g. (mm).
    pub cg_height: f64,
    /// Robustness margin of the finished stack for this part (largest horizontal load factor resisted), if computed.
    pub stability_margin: Option<f64>,
    /// Radius of the largest suction disc on its grasp face (mm).
    pub grasp_radius: f64,
}

/// Candidates rejected while one part was placed, by the check that failed (the per-part share of the
/// `rejected_*` counters of [`PlanStats`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Rejections {
    /// Not stable on its supports.
    pub not_stable: usize,
    /// The stack with it would not be stable.
    pub stack_not_stable: usize,
    /// No face holds the suction cup.
    pub not_graspable: usize,
    /// It cannot be lowered straight down into place.
    pub not_insertable: usize,
    /// Closer to another part than the clearance at its release position.
    pub clearance: usize,
}

impl Rejections {
    fn of(stats: &PlanStats) -> Self {
        Self {
            not_stable: stats.rejected_not_stable,
            stack_not_stable: stats.rejected_stack_not_stable,
            not_graspable: stats.rejected_not_graspable,
            not_insertable: stats.rejected_not_insertable,
            clearance: stats.rejected_clearance,
        }
    }

    fn minus(&self, before: &Self) -> Self {
        Self {
            not_stable: self.not_stable - before.not_stable,
            stack_not_stable: self.stack_not_stable - before.stack_not_stable,
            not_graspable: self.not_graspable - before.not_graspable,
            not_insertable: self.not_insertable - before.not_insertable,
            clearance: self.clearance - before.clearance,
        }
    }

    /// The sum over the reasons.
    pub fn total(&self) -> usize {
        self.not_stable + self.stack_not_stable + self.not_graspable + self.not_insertable + self.clearance
    }
}

impl PlannedPart {
    /// Its pose: world vertex = `rotation . v + position`.
    pub fn pose(&self) -> Pose {
        Pose { rotation: DMat3::from_cols_array_2d(&self.rotation).transpose(), position: DVec3::from(self.position) }
    }
}

/// Counters and timings of a plan.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PlanStats {
    /// Placement searches run (parts x stages tried).
    pub searches: usize,
    /// Interference-free candidates checked for stability, grasp and insertion.
    pub candidates_checked: usize,
    /// Searches continued past `candidates` candidates because every candidate failed the checks (the last stage when
    /// no stage accepted a part, or stage 2 below the cost of stage 1's part).
    #[serde(default)]
    pub repeated_searches: usize,
    /// Candidates rejected as not stable on their supports.
    #[serde(default)]
    pub rejected_not_stable: usize,
    /// Candidates rejected because the stack with them would not be stable.
    #[serde(default)]
    pub rejected_stack_not_stable: usize,
    /// Candidates rejected for want of a suction face.
    #[serde(default)]
    pub rejected_not_graspable: usize,
    /// Candidates rejected because they cannot be lowered straight down into place.
    #[serde(default)]
    pub rejected_not_insertable: usize,
    /// Candidates that passed every other test but not the horizontal clearance at their release position as
    /// `stackplan check` measures it (the search guarantees it up to its tolerance, which near faces tilted by about
    /// 1e-5 rad is a few 1e-5 mm horizontally; see the planner README).
    #[serde(default)]
    pub rejected_clearance: usize,
    /// Of the rejections as not stable (on its supports, or the stack with it), those where the equilibrium solver
    /// ended undecided ([`stackplan_stability::Verdict::Unknown`], read as not stable) instead of proving instability.
    #[serde(default)]
    pub undecided_verdicts: usize,
    /// Component pairs whose obstacle was built, over all searches.
    pub pairs_evaluated: u64,
    /// Obstacles constructed (cache misses).
    pub obstacles_constructed: u64,
    /// Obstacles extrapolated within a constant-topology interval (`interval_obstacles.rs`).
    #[serde(default)]
    pub obstacles_extrapolated: u64,
    /// Free-space cells whose QP no solver could solve, skipped ([`crate::search::PlacementStats::cells_unsolved`]):
    /// when not 0, a part's position is the cheapest of the cells solved, not proven the cheapest of all.
    #[serde(default)]
    pub cells_unsolved: u64,
    /// Seconds in the placement searches.
    pub seconds_search: f64,
    /// Seconds in the stack checks.
    pub seconds_checks: f64,
}

/// A stacking plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// The options it was made with.
    pub options: PlanOptions,
    /// Resting-pose rotations considered (rows), in the order `resting_pose` indexes.
    pub resting_poses: Vec<[[f64; 3]; 3]>,
    /// The placed parts in stacking order.
    pub parts: Vec<PlannedPart>,
    /// Why the plan ended early (`None` when all `count` parts were placed).
    pub stopped: Option<String>,
    /// Sum of the parts' cost terms (cost (1) of the whole stack).
    pub total_cost: f64,
    /// Floor footprint of the stack `[[x_min, y_min], [x_max, y_max]]`.
    pub footprint: [[f64; 2]; 2],
    /// Height of the stack's top (mm).
    pub height: f64,
    /// Whether the finished stack passed the whole-stack check.
    pub stack_stable: bool,
    /// Counters and timings.
    pub stats: PlanStats,
}

impl Plan {
    /// The planned parts as a stack of copies of `part` (the part the plan was made for), in placing order: the
    /// input of [`check_stack`].
    pub fn stack<'a>(&self, part: &'a Part) -> Vec<PlacedPart<'a>> {
        self.parts.iter().map(|p| PlacedPart::new(part, p.pose())).collect()
    }

    /// The options that check this plan as `stackplan check` does: its friction, clearance, suction cup and grasp
    /// tilt, each part raised by its release drop, with robustness margins and every intermediate stack checked.
    pub fn check_options(&self) -> CheckOptions {
        let o = &self.options;
        CheckOptions {
            mu: o.mu,
            clearance: o.clearance,
            grasp: GraspOptions { cup_diameter: o.cup_diameter, max_tilt: o.grasp_tilt, ..GraspOptions::default() },
            release_drops: self.parts.iter().map(|p| p.release_drop).collect(),
            ..CheckOptions::default()
        }
    }
}

/// Why no plan could be made at all.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// A bad option.
    #[error("{0}")]
    BadOption(String),
    /// The part has no stable resting pose.
    #[error("the part has no stable resting pose: {0}")]
    NoRestingPose(String),
    /// The part rests stably, but no resting pose presents an upward face that holds the suction cup.
    #[error(
        "none of the part's {poses} stable resting poses presents an upward face within {tilt_deg} degrees of level \
         that holds a {cup_diameter} mm suction cup: {}",
        tried.join("; ")
    )]
    NoGraspablePose {
        /// Number of stable resting poses the part has.
        poses: usize,
        /// The cup diameter asked for (mm).
        cup_diameter: f64,
        /// The largest tilt of a grasp face from level (degrees).
        tilt_deg: f64,
        /// Each pose tried, lowest c.g. first, and why it failed: no upward face within the tilt (with the tilt of the
        /// most level upward face), or the largest cup that fits.
        tried: Vec<String>,
    },
    /// The placement search failed.
    #[error(transparent)]
    Placement(#[from] PlacementError),
    /// The stability check failed to run.
    #[error("stability check: {0}")]
    Check(String),
}

fn rows(m: DMat3) -> [[f64; 3]; 3] {
    m.transpose().to_cols_array_2d()
}

/// Plans a stack of `options.count` copies of `part`. See the module documentation.
pub fn plan_stack(part: &Part, options: &PlanOptions) -> Result<Plan, PlanError> {
    plan_stack_with_progress(part, options, &mut |_, _| {})
}

/// [`plan_stack`] calling `progress(parts placed, count)` after every part.
///
/// The plan runs on a thread of rayon's current pool (the calling thread when it is one): the searches' rounds
/// ([`crate::search`]) are then parallel loops started from a worker, which hands the other partition to the other
/// worker directly instead of queueing the whole loop from outside and sleeping until it ends (a wake-up per
/// round). The plan does not depend on it, nor on the number of threads.
pub fn plan_stack_with_progress(
    part: &Part,
    options: &PlanOptions,
    progress: &mut (dyn FnMut(usize, usize) + Send),
) -> Result<Plan, PlanError> {
    rayon::scope(|_| plan_stack_here(part, options, progress))
}

/// [`plan_stack_with_progress`] on the calling thread: the options checked, the graspable resting poses, then the
/// parts one at a time ([`part`]) and the finished stack checked once with robustness margins.
fn plan_stack_here(
    part: &Part,
    options: &PlanOptions,
    progress: &mut (dyn FnMut(usize, usize) + Send),
) -> Result<Plan, PlanError> {
    validate(options)?;
    let thetas = thetas_with_step(options.dtheta).map_err(|e| PlanError::BadOption(format!("dtheta: {e}")))?;
    let grasp =
        GraspOptions { cup_diameter: options.cup_diameter, max_tilt: options.grasp_tilt, ..GraspOptions::default() };
    let rests = graspable_rests(part, options, &grasp)?;
    let rests_count = rests.len();
    let check_options = CheckOptions {
        mu: options.mu,
        clearance: 0.0,
        grasp,
        margin_directions: 0,
        contact_tolerance: None,
        prefix_stability: false,
        release_drops: Vec::new(),
    };
    // the candidates' tolerance: the box diagonal rounded up to a power of two, so that candidates widening the box
    // share the placed parts' contact analysis (ToleranceScale::PowerOfTwo)
    let growing = GrowingStack::new(&check_options)
        .map_err(|e| PlanError::Check(e.to_string()))?
        .with_tolerance_scale(ToleranceScale::PowerOfTwo);
    let started = std::time::Instant::now();
    let mut planner = Planner {
        part,
        options,
        rests,
        thetas,
        origin: options.origin.unwrap_or_else(|| options.floor.centre()),
        // the searches' tolerance (every part of the stack is this part, so the scale is its diagonal)
        tol: {
            let (lo, hi) = part.aabb();
            Tolerance::for_scale((hi - lo).length()).linear
        },
        cache: ObstacleCache::new(),
        caches: SearchCaches::carrying_frontiers(),
        floor_caches: (0..rests_count).map(|_| SearchCaches::carrying_frontiers()).collect(),
        growing,
        placed: Vec::new(),
        planned: Vec::new(),
        stats: PlanStats::default(),
        started,
        deadline: options
            .time_limit
            .filter(|t| t.is_finite() && *t >= 0.0)
            .map(|t| started + std::time::Duration::from_secs_f64(t.min(1e9))),
    };
    let mut stopped = None;
    for index in 0..options.count {
        stopped = planner.place_part(index)?;
        if stopped.is_some() {
            break;
        }
        progress(planner.planned.len(), options.count);
    }
    finish(planner, &check_options, stopped)
}

/// Every option a plan needs in range, else [`PlanError::BadOption`] naming it.
fn validate(options: &PlanOptions) -> Result<(), PlanError> {
    if options.count == 0 {
        return Err(PlanError::BadOption("the number of parts must be at least 1".into()));
    }
    if !(options.tuning.candidates >= 1 && options.max_resting_poses >= 1) {
        return Err(PlanError::BadOption("candidates and max_resting_poses must be at least 1".into()));
    }
    if options.tuning.max_candidates < options.tuning.candidates {
        return Err(PlanError::BadOption("max_candidates must be at least candidates".into()));
    }
    if !(options.cup_diameter > 0.0 && options.cup_diameter.is_finite()) {
        return Err(PlanError::BadOption(format!(
            "the cup diameter must be positive and finite, got {}",
            options.cup_diameter
        )));
    }
    if !(options.mu >= 0.0 && options.mu.is_finite()) {
        return Err(PlanError::BadOption(format!("mu must be non-negative and finite, got {}", options.mu)));
    }
    if !(options.nest_allowance >= 0.0 && options.nest_allowance.is_finite()) {
        return Err(PlanError::BadOption("the nesting allowance must be non-negative and finite".into()));
    }
    if !(1..=crate::request::MAX_PARTITIONS).contains(&options.tuning.partitions) {
        return Err(PlanError::BadOption(format!(
            "the number of search partitions must lie in 1..={}, got {}",
            crate::request::MAX_PARTITIONS,
            options.tuning.partitions
        )));
    }
    Ok(())
}

/// The candidate orientations' resting poses: the stable ones that present a suction face for the cup (\[A\] II-B
/// condition 3), lowest c.g. first, at most `max_resting_poses`; none is [`PlanError::NoGraspablePose`] with each
/// pose tried and why it failed.
fn graspable_rests(part: &Part, options: &PlanOptions, grasp: &GraspOptions) -> Result<Vec<DMat3>, PlanError> {
    let poses =
        stackplan_stability::resting_poses::resting_poses(part).map_err(|e| PlanError::NoRestingPose(e.to_string()))?;
    if poses.is_empty() {
        return Err(PlanError::NoRestingPose("no face of the hull holds the c.g. strictly inside".into()));
    }
    let rests: Vec<DMat3> = poses
        .iter()
        .filter(|p| is_graspable(&grasp_faces(part, p.rotation, p.position, grasp), grasp))
        .take(options.max_resting_poses)
        .map(|p| p.rotation)
        .collect();
    if rests.is_empty() {
        let tried = poses.iter().enumerate().map(|(k, p)| why_not_graspable(part, k, p, grasp)).collect();
        return Err(PlanError::NoGraspablePose {
            poses: poses.len(),
            cup_diameter: options.cup_diameter,
            tilt_deg: (options.grasp_tilt.to_degrees() * 1e6).round() / 1e6,
            tried,
        });
    }
    Ok(rests)
}

/// The plan: the finished stack checked once with robustness margins (each part's margin), its footprint, height
/// and total cost.
fn finish(planner: Planner<'_>, check_options: &CheckOptions, stopped: Option<String>) -> Result<Plan, PlanError> {
    let Planner { part, options, rests, cache, caches, floor_caches, placed, mut planned, mut stats, .. } = planner;
    let started = std::time::Instant::now();
    let world: Vec<PlacedPart<'_>> = placed.iter().map(|p| PlacedPart { part, pose: *p }).collect();
    let final_check =
        check_stack(&world, &CheckOptions { margin_directions: 8, prefix_stability: true, ..check_options.clone() })
            .map_err(|e| PlanError::Check(e.to_string()))?;
    stats.seconds_checks += started.elapsed().as_secs_f64();
    tracing::debug!(ms = started.elapsed().as_secs_f64() * 1e3, "final stack check (with margins)");
    for (p, c) in planned.iter_mut().zip(&final_check.parts) {
        p.stability_margin = c.margin;
    }
    // the searches' carried frontiers and obstacles (about 200 MB for the 15-part Complex plan) are freed on a thread
    // of the pool while the plan is returned and used: freeing them here took about a tenth of that plan's time
    rayon::spawn(move || drop((caches, floor_caches, cache)));
    let (lo, hi) = if placed.is_empty() { (DVec2::ZERO, DVec2::ZERO) } else { floor::footprint(part, &placed) };
    let height = placed.iter().flat_map(|p| part.all_vertices().map(move |v| p.apply(v).z)).fold(0.0f64, f64::max);
    Ok(Plan {
        options: options.clone(),
        resting_poses: rests.iter().map(|r| rows(*r)).collect(),
        total_cost: planned.iter().map(|p| p.cost).sum(),
        parts: planned,
        stopped,
        footprint: [lo.to_array(), hi.to_array()],
        height,
        stack_stable: final_check.stack.verdict.is_stable(),
        stats,
    })
}

/// Why resting pose `k` offers no grasp: no upward face within the grasp tilt of level (and how far the most level
/// upward face of the part's boundary is tilted), or the largest cup that fits on one.
fn why_not_graspable(
    part: &Part,
    k: usize,
    pose: &stackplan_stability::resting_poses::RestingPose,
    grasp: &GraspOptions,
) -> String {
    let faces = grasp_faces(part, pose.rotation, pose.position, grasp);
    let head = format!("pose {} (c.g. at {:.1} mm)", k + 1, pose.cg_height);
    match faces.iter().map(|f| f.inscribed_radius).reduce(f64::max) {
        Some(r) => format!("{head}: the largest cup that fits is {:.1} mm", 2.0 * r),
        None => {
            let up = part
                .boundary()
                .iter()
                .map(|f| (pose.rotation * f.plane.normal).z)
                .filter(|z| *z > 0.0)
                .fold(f64::NEG_INFINITY, f64::max);
            if up > 0.0 {
                format!("{head}: no such face, the most level is tilted {:.1} degrees", up.min(1.0).acos().to_degrees())
            } else {
                format!("{head}: no upward face")
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use stackplan_geom::part::PartOrigin;
    use stackplan_geom::{Pose, convex_hull};

    fn block(x: f64, y: f64, z: f64) -> Part {
        let pts: Vec<DVec3> = (0..8)
            .map(|i| {
                DVec3::new(
                    if i & 1 == 0 { 0.0 } else { x },
                    if i & 2 == 0 { 0.0 } else { y },
                    if i & 4 == 0 { 0.0 } else { z },
                )
            })
            .collect();
        let hull = convex_hull(&pts).expect("box").polytope;
        Part::from_components("block", vec![hull], 1.0, PartOrigin::ConvexPieces).expect("part")
    }

    fn options(count: usize, w: f64, floor: FloorVolume) -> PlanOptions {
        PlanOptions {
            w,
            clearance: 0.0,
            dtheta: 90f64.to_radians(),
            cup_diameter: 10.0,
            max_resting_poses: 1,
            ..PlanOptions::new(count, floor)
        }
    }

    #[test]
    fn a_search_limit_ends_the_plan_with_the_parts_placed_so_far_and_the_reason() {
        let part = block(40.0, 40.0, 20.0);
        let floor = FloorVolume::rectangle(0.0, 0.0, 400.0, 400.0, 500.0);
        let full = plan_stack(&part, &options(6, 0.5, floor.clone())).expect("plan");
        assert_eq!(full.parts.len(), 6, "{:?}", full.stopped);
        // a node budget below what the later parts need
        let mut tight = options(6, 0.5, floor.clone());
        tight.tuning.node_budget = 1;
        let plan = plan_stack(&part, &tight).expect("a limit is no error");
        assert!(plan.parts.len() < 6);
        let reason = plan.stopped.as_deref().unwrap_or_default();
        assert!(reason.contains("node budget of 1 nodes") && reason.contains("are kept"), "{reason}");
        assert_eq!(plan.parts[..], full.parts[..plan.parts.len()], "the parts placed before the limit are the same");
        // a time limit already over: nothing placed, and the plan says why
        let none = plan_stack(&part, &PlanOptions { time_limit: Some(0.0), ..options(6, 0.5, floor) }).expect("plan");
        assert!(none.parts.is_empty());
        assert!(none.stopped.as_deref().is_some_and(|s| s.contains("time limit of 0 s")), "{:?}", none.stopped);
    }

    #[test]
    fn w_zero_spreads_on_the_floor_and_w_one_makes_a_column() {
        let part = block(40.0, 40.0, 20.0);
        let floor = FloorVolume::rectangle(0.0, 0.0, 400.0, 400.0, 500.0);
        let flat = plan_stack(&part, &options(4, 0.0, floor.clone())).expect("plan");
        assert_eq!(flat.parts.len(), 4, "{:?}", flat.stopped);
        for p in &flat.parts {
            assert!((p.cg_height - 10.0).abs() < 1e-6, "w = 0 keeps every part on the floor: {}", p.cg_height);
        }
        let column = plan_stack(&part, &options(4, 1.0, floor)).expect("plan");
        assert_eq!(column.parts.len(), 4, "{:?}", column.stopped);
        assert!((column.height - 80.0).abs() < 1e-6, "w = 1 stacks a column: height {}", column.height);
        assert!(column.footprint[1][0] - column.footprint[0][0] <= 40.0 + 1e-6);
        assert!(column.stack_stable);
        // every plan is interference-free and passes the whole-stack check
        for plan in [&flat, &column] {
            assert_rests_without_interference(&part, plan);
        }
    }

    /// Every part of `plan` is interference-free and stable on its supports (the whole-stack check at rest).
    fn assert_rests_without_interference(part: &Part, plan: &Plan) {
        let world: Vec<PlacedPart<'_>> = plan
            .parts
            .iter()
            .map(|p| {
                let pose = Pose::from_rows(p.rotation, DVec3::from_array(p.position)).expect("a proper rotation");
                PlacedPart { part, pose }
            })
            .collect();
        let report = check_stack(&world, &CheckOptions::default()).expect("check");
        assert!(report.parts.iter().all(|c| c.interference <= 1e-6 && c.stable.is_stable()), "{report:?}");
    }

    /// The L-corner part at w = 0.9 with one candidate per search: the fourth part's cheapest interference-free
    /// position is not stable on its supports. Without the repeated search the plan stops there; with it the fourth
    /// part finds a stable position further down the list.
    #[test]
    fn a_repeated_search_finds_a_stable_position_when_every_candidate_fails() {
        let part =
            stackplan_geom::examples::part_by_name("l-corner", stackplan_geom::sheet_metal::Decomposition::ConvexMerge)
                .expect("example");
        let floor = FloorVolume::rectangle(-200.0, -200.0, 200.0, 200.0, 400.0);
        let mut options = PlanOptions { w: 0.9, dtheta: 15f64.to_radians(), ..PlanOptions::new(4, floor) };
        options.tuning.candidates = 1;
        options.tuning.max_candidates = 1;
        let once = plan_stack(&part, &options).expect("plan");
        assert_eq!(once.parts.len(), 3, "the cheapest candidate of the fourth part fails");
        assert!(once.stopped.as_deref().is_some_and(|r| r.contains("part 4 of 4")), "{:?}", once.stopped);
        options.tuning.max_candidates = 1024;
        let repeated = plan_stack(&part, &options).expect("plan");
        assert_eq!(repeated.parts.len(), 4, "{:?}", repeated.stopped);
        assert!(repeated.stats.repeated_searches >= 1);
        assert!(repeated.parts[3].rejected_candidates >= options.tuning.candidates);
        assert_eq!(&repeated.parts[..3], &once.parts[..3]);
        // the rejections are proofs of instability, not solver failures
        assert!(repeated.stats.rejected_not_stable + repeated.stats.rejected_stack_not_stable >= 1);
        assert_eq!(repeated.stats.undecided_verdicts, 0);
        // each part's rejections by reason are its share of the plan's: the fourth part's include the failures
        // of its stage, and the shares add up to the plan's counters reason by reason
        let fourth = repeated.parts[3].rejections;
        assert!(fourth.total() >= repeated.parts[3].rejected_candidates, "{fourth:?}");
        let sum = |f: fn(&Rejections) -> usize| repeated.parts.iter().map(|p| f(&p.rejections)).sum::<usize>();
        let st = &repeated.stats;
        assert_eq!(sum(|r| r.not_stable), st.rejected_not_stable);
        assert_eq!(sum(|r| r.stack_not_stable), st.rejected_stack_not_stable);
        assert_eq!(sum(|r| r.not_graspable), st.rejected_not_graspable);
        assert_eq!(sum(|r| r.not_insertable), st.rejected_not_insertable);
        assert_eq!(sum(|r| r.clearance), st.rejected_clearance);
    }

    /// L-corner at w = 0.9 (columns) with a limit of two candidates: from the fourth part on, the two cheapest
    /// candidates (on the column) fail the checks, and with `max_candidates = 1` the plan ends at part 4. The
    /// cheapest floor position that passes bounds the search and places each of them on the floor: the plan is
    /// complete, those parts rest on the floor at their pose's resting height, and the finished stack passes the
    /// whole-stack check.
    #[test]
    fn the_floor_places_a_part_whose_cheaper_candidates_all_fail() {
        let part =
            stackplan_geom::examples::part_by_name("l-corner", stackplan_geom::sheet_metal::Decomposition::ConvexMerge)
                .expect("example");
        let floor = FloorVolume::rectangle(-300.0, -300.0, 300.0, 300.0, 400.0);
        let mut options = PlanOptions { w: 0.9, dtheta: 15f64.to_radians(), ..PlanOptions::new(8, floor) };
        options.tuning.candidates = 1;
        options.tuning.max_candidates = 1;
        let cut = plan_stack(&part, &options).expect("plan");
        assert!(cut.stopped.as_deref().is_some_and(|r| r.contains("part 4 of 8")), "{:?}", cut.stopped);
        options.tuning.max_candidates = 2;
        let plan = plan_stack(&part, &options).expect("plan");
        assert!(plan.stopped.is_none() && plan.parts.len() == 8 && plan.stack_stable, "{:?}", plan.stopped);
        assert_eq!(&plan.parts[..3], &cut.parts[..3]);
        let on_floor: Vec<&PlannedPart> = plan.parts.iter().filter(|p| p.rejected_candidates == 2).collect();
        assert!(on_floor.len() >= 3, "{:?}", plan.parts.iter().map(|p| p.rejected_candidates).collect::<Vec<_>>());
        for p in on_floor {
            assert!(p.contacts.contains(&Contact::Floor), "part {}: {:?}", p.index, p.contacts);
            let pose = Pose::from_rows(p.rotation, DVec3::from_array(p.position)).expect("a proper rotation");
            let lowest = part.all_vertices().map(|v| pose.apply(v).z).fold(f64::INFINITY, f64::min);
            assert!(lowest.abs() < 1e-9, "part {} rests {lowest} mm above the floor", p.index);
        }
    }

    /// Channel at w = 0.9 with one candidate per stage: the seventh part's stage 1 accepts a position on the stack
    /// (cost 42 306.7) while stage 2's cheapest position fails the checks and its second passes at 40 490.1. Stage 2
    /// tests every candidate cheaper than stage 1's part, so the budget of one candidate does not decide the plan:
    /// it is the plan with a budget of eight, where stage 2's second candidate is within the budget anyway.
    #[test]
    fn stage_two_tests_every_candidate_cheaper_than_stage_one_part() {
        let part =
            stackplan_geom::examples::part_by_name("channel", stackplan_geom::sheet_metal::Decomposition::ConvexMerge)
                .expect("example");
        let floor = FloorVolume::rectangle(-305.0, -305.0, 305.0, 305.0, 612.0);
        let mut options = PlanOptions { w: 0.9, dtheta: 15f64.to_radians(), ..PlanOptions::new(8, floor) };
        options.tuning.candidates = 1;
        let one = plan_stack(&part, &options).expect("plan");
        options.tuning.candidates = 8;
        let eight = plan_stack(&part, &options).expect("plan");
        assert_eq!(one.parts.len(), 8, "{:?}", one.stopped);
        let beyond_budget: Vec<&PlannedPart> =
            one.parts.iter().filter(|p| p.stage == 2 && p.rejected_candidates >= 1).collect();
        assert!(!beyond_budget.is_empty(), "a stage 2 part found past the budget of one candidate");
        assert!(one.stats.repeated_searches >= 1);
        for (a, b) in one.parts.iter().zip(&eight.parts) {
            assert_eq!((a.stage, a.position, a.theta_deg), (b.stage, b.position, b.theta_deg));
        }
        assert_eq!(one.total_cost, eight.total_cost);
        assert_rests_without_interference(&part, &one);
    }

    /// The Triangle part with the seed's 5 mm horizontal clearance nests (\[A\] Fig. 19): the search's position floats
    /// above the first part's inclined walls (the clearance lifts them), and the part drops onto them.
    #[test]
    fn triangle_parts_with_clearance_drop_into_the_nest() {
        let part =
            stackplan_geom::examples::part_by_name("triangle", stackplan_geom::sheet_metal::Decomposition::ConvexMerge)
                .expect("example");
        let floor = FloorVolume::rectangle(-340.0, -340.0, 340.0, 340.0, 400.0);
        let options = PlanOptions { w: 0.9, dtheta: 5f64.to_radians(), ..PlanOptions::new(3, floor) };
        assert_eq!(options.clearance, 5.0);
        let plan = plan_stack(&part, &options).expect("plan");
        assert_eq!(plan.parts.len(), 3, "{:?}", plan.stopped);
        let (lo, hi) = part.aabb();
        let part_height = (hi - lo).z.min((hi - lo).x).min((hi - lo).y);
        assert!(plan.height < 2.0 * part_height, "nested: height {} vs part {}", plan.height, part_height);
        assert_eq!(plan.parts[0].release_drop, 0.0);
        for p in &plan.parts[1..] {
            assert!(p.release_drop > 1.0, "dropped into the nest: {}", p.release_drop);
            assert!(p.contacts.iter().all(|c| matches!(c, Contact::Stack { .. })), "{:?}", p.contacts);
        }
        // at rest every part touches and nothing penetrates
        assert_rests_without_interference(&part, &plan);
        assert!(plan.stack_stable);
    }

    #[test]
    fn a_floor_too_small_stops_the_plan_with_a_reason() {
        let part = block(40.0, 40.0, 20.0);
        let floor = FloorVolume::rectangle(0.0, 0.0, 50.0, 50.0, 50.0);
        let plan = plan_stack(&part, &options(4, 0.0, floor)).expect("plan");
        // two fit (one on the floor, one on top), the third exceeds the height
        assert_eq!(plan.parts.len(), 2);
        assert!(plan.stopped.as_deref().is_some_and(|s| s.contains("part 3 of 4")), "{:?}", plan.stopped);
        let tiny = FloorVolume::rectangle(0.0, 0.0, 10.0, 10.0, 50.0);
        let plan = plan_stack(&part, &options(1, 0.5, tiny)).expect("plan");
        assert!(plan.parts.is_empty());
        assert!(plan.stopped.as_deref().is_some_and(|s| s.contains("too small")), "{:?}", plan.stopped);
        assert!(matches!(
            plan_stack(&part, &options(0, 0.5, FloorVolume::rectangle(0.0, 0.0, 1.0, 1.0, 1.0))),
            Err(PlanError::BadOption(_))
        ));
        for partitions in [0, crate::request::MAX_PARTITIONS + 1] {
            let mut bad = options(1, 0.5, FloorVolume::rectangle(0.0, 0.0, 50.0, 50.0, 50.0));
            bad.tuning.partitions = partitions;
            let error = plan_stack(&part, &bad);
            assert!(
                matches!(&error, Err(PlanError::BadOption(m)) if m.contains("partitions")),
                "{partitions} partitions: {error:?}"
            );
        }
    }

    #[test]
    fn a_cup_wider_than_every_upward_face_is_a_typed_error() {
        // a 4 mm cube: every face is 4 x 4 mm, so a 10 mm cup fits on none of its 6 resting poses, a 3 mm cup on all
        let part = block(4.0, 4.0, 4.0);
        let floor = FloorVolume::rectangle(-20.0, -20.0, 20.0, 20.0, 20.0);
        let error = plan_stack(&part, &options(2, 0.5, floor.clone())).err();
        assert!(
            matches!(error, Some(PlanError::NoGraspablePose { poses: 6, cup_diameter, .. }) if cup_diameter == 10.0),
            "{error:?}"
        );
        let message = error.map(|e| e.to_string()).unwrap_or_default();
        assert!(message.contains("6 stable resting poses") && message.contains("10 mm"), "{message}");
        let plan = plan_stack(&part, &PlanOptions { cup_diameter: 3.0, ..options(2, 0.5, floor) }).expect("plan");
        assert_eq!(plan.parts.len(), 2);
    }
}
