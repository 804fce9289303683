//! Exact contact manifolds: projection of a configuration onto the set where a state's PCs hold, strict
//! verification of a state at a configuration, and extremal configurations by a compass search on the manifold
//! (\[P\] II-A, III; the projection and the strict check are ours, see the crate README "Exact feasibility").
//!
//! **Equalities.** Each PC holds on a smooth manifold given by signed lengths (the *intersection conditions* of
//! \[P\] eq. 1 with signs): f-v / v-f the height of the vertex over the face plane (1 equation); e-e the signed
//! distance between the carrier lines, `(b0 - a0).(da x db) / |da x db|` (1); f-e / e-f the heights of both end
//! points (2); f-f the heights of all vertices of the moving face over the fixed face's plane (rank 3). The bounding
//! conditions and non-penetration are inequalities, checked after the projection.
//!
//! **Projection** (Levenberg-Marquardt, K. Levenberg 1944, D. Marquardt 1963): minimise `|r(t)|^2` from `t0` in the
//! scaled variables `u = (x, y, z, L rx, L ry, L rz)` with a central-difference Jacobian `J` (6 columns) and steps
//! `(J^T J + mu I) du = -J^T r`, kept inside the box (variables at a bound whose step points outwards are frozen).
//! With small `mu` the step is the minimum-norm Gauss-Newton step, so the result is close to the nearest point of
//! the manifold; convergence is quadratic near a regular point. Converged when `max |r| <= 1e-11 L`.
//! Cost: about 13 residual evaluations (O(size of the state's elements)) per iteration, 3-6 iterations.
//!
//! **Strict verification** at `t`: inside the box; every PC's full criterion (with the bounding conditions,
//! [`crate::criteria`]) at most `hold`; the penetration term `L d_G` at most `hold`; and the PPCs in contact are
//! exactly the state: with Euclidean distances between the elements (point to planar face
//! `sqrt(height^2 + in-plane distance^2)`, segment to segment in 3-D), the PPCs at distance `<= hold` map to the state
//! by [`crate::ContactState::canonical`], and no PPC lies in the ambiguous band `(hold, clear]`. `hold = 1e-7 L`,
//! `clear = 1e-5 L` by default. Cost O(number of reachable PPCs) distance evaluations.
//!
//! **Interior witness.** A GA witness of eq. 8 can sit where further contacts also hold (closure semantics). The
//! witness is projected; if the strict check fails, seeded random perturbations of growing size
//! (`1e-4 .. 0.1` of the box widths) are projected and checked until one passes.
//!
//! **Extremals** (\[P\] eq. 9-10 solved on the manifold): from a configuration of the state, a local search on `±t_k`
//! whose sweeps try (1) a *tangent move*: the objective's direction projected onto the tangent space of the state's
//! equalities and of the active inequalities it would violate (bounding terms and penetration at their boundary,
//! variables at a box bound), a step limited per variable, restored by the closure projection with `t_k` frozen, or
//! else by the plain closure projection (a gradient projection); (2) *compass moves* of one variable `t_j`, restored by
//! the projection with `t_j` frozen onto the equalities, the bounding terms and non-penetration (a move blocked by a
//! face boundary or another contact is restored by the other variables, e.g. a turn that lets a face slide further over
//! an edge); (3) when that sweep failed, *pair moves* of `t_k` with one other variable, both frozen. A trial is accepted
//! when it improves `±t_k`, stays in the box and satisfies eq. 8 to `hold` (closure: other contacts may hold at an
//! extremal); a trial the projection did not reach to `1e-11 L` is accepted when every PC and the penetration term are
//! within `hold` there ([`Manifolds::holds_at`]). Steps double after a success and shrink to a quarter after a failed
//! sweep, down to `1e-7` of the box width; the search ends at once when `t_k` reaches its bound. Unlike the penalty
//! formulation of eq. 11-12, every accepted point lies on the manifold, so the search does not stop short by the
//! penalty's slack; it is local (it can stop where the extreme lies in another region of the state).

mod boundary;
mod check;
mod extremal_search;
mod linalg;
mod witness;

pub use boundary::{element_point_distance, locate};
pub use check::{EXACT_RESIDUAL, Manifolds, Rejection, StrictTolerances, segment_closest, segment_segment_distance};
pub use witness::other_chart;
