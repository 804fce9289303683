//! # stackplan-planner
//!
//! Placement of one part in a stack of stationary parts by best-first search over partial c-space obstacles
//! (Ayyadevara et al. 2002, \[A\] sections V-VI; `docs/algorithms.md`, "Placement search").
//!
//! * [`request`]: inputs (part, resting poses, theta set, stack, floor volume or fixed `p_z`, clearance, cost,
//!   insertion, `k`) and their validation;
//! * [`orientation`]: per orientation the permissible set `Omega` (\[A\] eq. 3) and the cost as a separable quadratic;
//! * [`symmetry`]: rotational symmetry about z in a resting pose (one period searched);
//! * [`detect`]: interference pairs at a configuration (broad phase + exact narrow phase, insertion sweeps);
//! * [`interval_obstacles`]: obstacles constructed at interval starts and extrapolated inside (\[A\] IV-B);
//! * [`obstacles`]: the pair obstacles cut out (plain, insertion, clearance) with face provenance;
//! * `plates.rs` (private): one obstacle for two parallel sheet-metal plates where that is exact;
//! * [`dary_heap`]: the 4-ary heap of the search's open nodes;
//! * [`qp`]: the QP on a free-space cell with its active constraints;
//! * [`search`]: the best-first search and its statistics (\[A\] Tables I-II);
//! * [`settle`]: the vertical drop of a part released above its supports (clearance on inclined faces);
//! * [`reference`](mod@reference): the brute-force reference (complete obstacles, complete free space) used by the
//!   tests;
//! * [`regress`]: the scenarios of \[A\] Figs. 15-17 for `cargo xtask regress`;
//! * [`stack_plan`]: the stacking planner for n identical parts (\[A\] II-B): placement, then stability, grasp and
//!   insertion checks, in the seed's two stages.

pub mod dary_heap;
pub mod detect;
pub mod interval_obstacles;
pub mod obstacles;
pub mod orientation;
mod plates;
pub mod qp;
pub mod reference;
pub mod regress;
pub mod request;
mod round_end;
pub mod search;
pub mod settle;
pub mod stack_plan;
pub mod symmetry;

pub use request::{
    Cost, FloorVolume, PlacementError, PlacementRequest, StackPart, polygon_side_planes, thetas_with_step,
    uniform_thetas,
};
pub use search::{
    Contact, NoPlacement, Placement, PlacementResult, PlacementSearch, PlacementStats, SearchCaches, place,
    place_with_cache, place_with_caches,
};
pub use stack_plan::{DEFAULT_MAX_CANDIDATES, Plan, PlanError, PlanOptions, PlannedPart, plan_stack};
