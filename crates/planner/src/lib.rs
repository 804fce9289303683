//! # stackplan-planner
//!
//! Placement of one part in a stack of stationary parts by best-first search over partial c-space obstacles
//! (Ayyadevara et al. 2002, \[A\] sections V-VI; `docs/algorithms.md`, "Placement search"), and the stacking planner
//! for n identical parts built on it (\[A\] II-B).
//!
//! The public API:
//! * [`request`]: the inputs of one placement (part, resting poses, theta set, stack, floor volume or fixed `p_z`,
//!   clearance, cost, insertion, `k`) and their validation;
//! * [`search`]: the best-first search ([`place`], the continuable [`PlacementSearch`]) and its statistics (\[A\]
//!   Tables I-II);
//! * [`stack_plan`]: the stacking planner ([`plan_stack`]): placement, then stability, grasp and insertion checks,
//!   in the seed's two stages.
//!
//! Inside (hidden from the documentation, public only for the tests, benches and `cargo xtask`): `orientation`
//! (`Omega` and the cost per orientation), `detect` (interference pairs at a configuration), `interval_obstacles`
//! (obstacles extrapolated within constant-topology intervals, \[A\] IV-B), `reference` (the brute-force reference
//! the tests compare with) and `paper_scenarios` (the scenarios of \[A\] Figs. 15-17). Private: `obstacles` (the pair
//! obstacles cut out), `plates` (one obstacle for two parallel plates where that is exact), `cell_qp` (the QP on a cell),
//! `settle` (the vertical drop of a released part) and `symmetry` (rotational symmetry about z).

mod cell_qp;
#[doc(hidden)]
pub mod detect;
#[doc(hidden)]
pub mod interval_obstacles;
mod obstacles;
#[doc(hidden)]
pub mod orientation;
#[doc(hidden)]
pub mod paper_scenarios;
mod plates;
#[doc(hidden)]
pub mod reference;
pub mod request;
pub mod search;
mod settle;
pub mod stack_plan;
mod symmetry;

pub use request::{
    Cost, FloorVolume, PlacementError, PlacementRequest, polygon_side_planes, thetas_with_step, uniform_thetas,
};
pub use search::{
    Contact, NoPlacement, Placement, PlacementResult, PlacementSearch, PlacementStats, SearchCaches, place,
    place_with_cache, place_with_caches,
};
pub use stack_plan::{
    DEFAULT_MAX_CANDIDATES, Plan, PlanError, PlanOptions, PlanStats, PlannedPart, Rejections, plan_stack,
    plan_stack_with_progress,
};
pub use stackplan_stability::world::PlacedPart;
