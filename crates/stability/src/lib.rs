//! # stackplan-stability
//!
//! Conditions (ii)-(iv) of a stacking configuration (Ayyadevara et al. 2002, \[A\] II-B; `docs/algorithms.md`,
//! "Stability, grasp and insertion"):
//!
//! * [`resting_poses`](mod@resting_poses): the faces of a part's convex hull it rests on stably, with rotation
//!   (phi, psi), margin and c.g. height — the planner's candidate orientations;
//! * [`grasp`]: upward horizontal faces holding a suction cup (largest inscribed disc; cup patterns);
//! * [`contacts`]: contact patches between parts and with the floor;
//! * [`equilibrium`]: static equilibrium with Coulomb friction cones (SOCP, clarabel) and a robustness margin;
//! * [`insertion`]: lowering straight down / lifting straight up;
//! * [`clearance`]: horizontal clearance for robot positioning error;
//! * [`check`]: everything for every part of a stack;
//! * [`addition`]: the same for a part added to a stack that passed;
//! * [`growing`]: a stack that grows one part at a time and the verdict on a candidate for its next part (the
//!   planner's per-candidate test).
//!
//! Building blocks: [`sat`] (separating-axis test with sweeps), [`polygon2d`] (planar hulls and clipping), [`world`]
//! (placed parts in world coordinates). Lengths in millimetres, angles in radians, forces in mass units times g.

pub mod addition;
pub mod check;
pub mod clearance;
pub mod contacts;
pub mod equilibrium;
pub mod grasp;
pub mod growing;
pub mod insertion;
pub mod polygon2d;
pub mod resting_poses;
pub mod sat;
mod union_find;
pub mod world;

pub use addition::check_added_part;
pub use check::{CheckOptions, PartCheck, StackCheck, check_stack, check_stack_reference};
pub use contacts::{Body, ContactAnalysis, ContactPatch, analyse_contacts};
pub use equilibrium::{
    Equilibrium, EquilibriumOptions, MAX_MARGIN_DIRECTIONS, SolveCache, Verdict, solve_equilibrium,
    solve_equilibrium_with,
};
pub use grasp::{GraspFace, GraspOptions, grasp_faces};
pub use growing::{Accepted, GrowingStack, Rejection, ToleranceScale};
pub use resting_poses::{RestingPose, resting_poses};
pub use world::{PlacedPart, WorldPart, world_stack};

/// Errors of the stability analysis, naming the part concerned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StabilityError {
    /// A pose's rotation is not a proper rotation matrix.
    #[error("part {part}: the rotation is not a proper rotation (orthonormal, determinant +1)")]
    NotARotation {
        /// Index of the part in the stack.
        part: usize,
    },
    /// A pose's position is NaN or infinite.
    #[error("part {part}: the position is not finite")]
    NonFinitePosition {
        /// Index of the part in the stack.
        part: usize,
    },
    /// A part has no components.
    #[error("part {part} has no components")]
    EmptyPart {
        /// Index of the part in the stack.
        part: usize,
    },
    /// The convex hull of a part failed.
    #[error("convex hull of the part failed: {0}")]
    Hull(String),
    /// An option is out of range.
    #[error("invalid option: {0}")]
    BadOption(String),
    /// The equilibrium problem could not be set up.
    #[error(transparent)]
    Equilibrium(#[from] equilibrium::EquilibriumError),
}
