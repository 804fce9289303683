//! # stackplan-freespace
//!
//! Free space for one part at a fixed orientation (\[A\] = Ayyadevara, Bourne, Shimada, Sturges, *Interference-free
//! polyhedral configurations for stacking*, IEEE T-RA 2002, section VI-A): with the orientation fixed, c-space
//! obstacles and free regions are polyhedral; free space is a set of convex cells; the cost is a separable convex
//! quadratic minimised per cell. The planner (`stackplan-planner`) builds the cells (the permissible set Omega and
//! the cuts of its best-first search) and the costs; this crate gives the cells and their exact solvers.
//!
//! * [`cell`]: convex H-polytopes in 2 or 3 variables of tagged [`Halfspace`]s; emptiness, Chebyshev centre,
//!   redundancy removal, membership, children built from a known point ([`vertices`] enumerates their vertices);
//! * [`outer_box`](mod@outer_box): a box around a cell by bound propagation, the emptiness test it gives for a cell
//!   cut by one more half-space, and the inequalities it proves redundant;
//! * [`qp`]: the exact placement QP (active set, KKT-verified, deterministic tie-break) and clarabel's QP, over a
//!   [`SeparableCost`], answering a [`QpSolution`].
//!
//! Modules depend on each other in one direction only: `linalg`, `halfspace`, `clarabel` (leaves) <- `active_set` <-
//! `closed_form`, `phase_one` <- `cell` <- `vertices`, `outer_box` <- `solution` <- `kkt` <- `enumerate` <- `qp`.

mod active_set;
pub mod cell;
mod clarabel;
mod closed_form;
pub mod cost;
mod enumerate;
pub mod halfspace;
mod kkt;
mod linalg;
pub mod outer_box;
mod phase_one;
pub mod qp;
pub mod solution;
pub mod vertices;

pub use active_set::ActiveSetError;
pub use cell::{Cell, CellError, CellShape};
pub use cost::{CostError, SeparableCost};
pub use halfspace::{Halfspace, Tag};
pub use kkt::verify_kkt;
pub use qp::{minimize, minimize_clarabel};
pub use solution::{QpError, QpSolution, ShortList};
pub use vertices::CellPolyhedron;
