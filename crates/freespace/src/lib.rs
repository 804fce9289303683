//! # stackplan-freespace
//!
//! Free space for one part at a fixed orientation (\[A\] = Ayyadevara, Bourne, Shimada, Sturges, *Interference-free
//! polyhedral configurations for stacking*, IEEE T-RA 2002, section VI-A): with the orientation fixed, c-space
//! obstacles and free regions are polyhedral; free space is a set of disjoint convex cells; the cost is a separable
//! convex quadratic minimised per cell; the optima of all cells, sorted by cost, are the candidate list.
//!
//! * [`cell`]: convex H-polytopes in 2 or 3 variables with provenance tags; emptiness, Chebyshev centre,
//!   redundancy removal, membership ([`vertices`] enumerates their vertices and faces);
//! * [`outer_box`](mod@outer_box): a box around a cell by bound propagation, and the emptiness test it gives for a
//!   cell cut by one more half-space (the placement search's children);
//! * [`omega`](mod@omega): the permissible set Omega(R) of \[A\] eq. (3) and its 2-D variant at fixed `p_z`;
//! * [`subtract`](mod@subtract): subtraction of a convex obstacle (optionally grown by a clearance) from a cell
//!   (\[A\] Fig. 13);
//! * [`cost`]: the stacking cost (1) of \[A\] and the squared distance to a desired position, as separable quadratics;
//! * [`qp`]: the exact active-set QP (hot path, KKT-verified, deterministic tie-break) and clarabel's QP;
//! * [`ranking`]: one optimum per cell, sorted by cost;
//! * [`active_set`]: the small exact solver behind all LPs and QPs of the crate.

pub mod active_set;
pub mod cell;
pub mod cost;
pub mod omega;
pub mod outer_box;
pub mod qp;
pub mod ranking;
pub mod subtract;
pub mod vertices;

pub use active_set::ActiveSetError;
pub use cell::{Cell, CellError, CellShape, Halfspace, Tag};
pub use cost::{CostError, RotatedExtents, SeparableCost, SeparableQuadratic, desired_position_cost, stacking_cost};
pub use omega::{FloorVolume, OmegaError, omega, omega_fixed_z, omega_for_part};
pub use qp::{QpError, QpSolution, ShortList, minimize, minimize_clarabel, verify_kkt};
pub use ranking::{Placement, RankedPlacements, ranked_placements};
pub use subtract::{Obstacle, SubtractError, SubtractOptions, Subtraction, subtract, subtract_from_all};
pub use vertices::CellPolyhedron;
