//! The vertical-force certificate of a group's stability as a small QP (`docs/algorithms.md`, "Stability, grasp and
//! insertion"; \[A\] II-B (ii)), for verdicts only.
//!
//! A group of movable parts is stable when *some* admissible force distribution exists. Vertical forces `f_k >= 0` at
//! the contact points whose normal is vertical or lies in the friction cone of the vertical (`|n_xy| <= mu |n_z|`,
//! [`super::hull_certificate`]), and none at the others, are admissible (inside every friction cone).
//! [`super::tree::vertical_certificate`] tries the least-squares distribution of such forces (closed form); when that
//! one has a negative force — common in staggered walls and offset stacks of blocks, whose supports form cycles —
//! a nonnegative one may still exist. This module looks for it: the minimum-norm nonnegative vertical distribution,
//!
//! ```text
//! minimise 1/2 sum f_k^2   subject to   A f = b,  f >= 0,
//! ```
//!
//! with per movable part `i` the three rows of [`super::tree::parallel_certificate`] (vertical force balance
//! `sum s n_z f_k = m_i`, moments about the two horizontal axes through `c_i`; scaled by the group's weight and size)
//! and one unknown per vertical point. Clarabel (interior point, `ZeroConeT` + `NonnegativeConeT`) with `K_v`
//! unknowns and `3 M + K_v` constraint rows, against the full problem's `3 K` unknowns in `K` second-order cones: for
//! block stacks about a third of the points are vertical and the solve is several times cheaper. `Solved` certifies
//! stability with the same trust in the solver's status as the SOCP; any other status (infeasible: friction may be
//! needed) leaves the decision to the SOCP. Cost: one interior-point solve, O(iterations x factorisation of a sparse
//! (K_v + 3M)-square KKT system).

use super::{EquilibriumError, Point, Rigid};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus, ZeroConeT};
use glam::DVec3;

/// Vertical forces (world vectors, the force of each point's `a` on its `b`, in the order of `points`; zero at the
/// points that are not vertical) that balance every movable part of the group, when the QP finds them (`Solved`);
/// `None` otherwise.
pub(super) fn vertical_qp_certificate(
    bodies: &[Rigid],
    movers: &[usize],
    points: &[&Point],
    mu: f64,
) -> Result<Option<Vec<DVec3>>, EquilibriumError> {
    let vertical = |p: &Point| super::hull_certificate::admits_vertical_force(p, mu);
    let (e1, e2) = crate::contacts::plane_basis(DVec3::Z);
    let rows = 3 * movers.len();
    let union = Rigid::union(movers.iter().map(|&i| bodies[i]));
    let scale = (union.aabb.1 - union.aabb.0).length().max(1.0);
    let weight = union.mass.max(f64::MIN_POSITIVE);
    // triplets of A: the equality rows, then -I for the sign constraints (clarabel: A x + s = b, s in the cones)
    let (mut ri, mut ci, mut vi) = (Vec::new(), Vec::new(), Vec::new());
    let mut unknown_of: Vec<Option<usize>> = Vec::with_capacity(points.len());
    let mut n = 0usize;
    for p in points {
        if !vertical(p) {
            unknown_of.push(None);
            continue;
        }
        for (r, value) in super::tree::certificate_column(bodies, movers, p, (e1, e2), scale) {
            if value != 0.0 {
                ri.push(r);
                ci.push(n);
                vi.push(value);
            }
        }
        unknown_of.push(Some(n));
        n += 1;
    }
    if n == 0 {
        return Ok(None);
    }
    for k in 0..n {
        ri.push(rows + k);
        ci.push(k);
        vi.push(-1.0);
    }
    let a = CscMatrix::new_from_triplets(rows + n, n, ri, ci, vi);
    let mut b = vec![0.0; rows + n];
    for (m, &i) in movers.iter().enumerate() {
        b[3 * m] = bodies[i].mass / weight;
    }
    let diag: Vec<usize> = (0..n).collect();
    let p = CscMatrix::new_from_triplets(n, n, diag.clone(), diag, vec![1.0; n]);
    let q = vec![0.0; n];
    let cones = [ZeroConeT(rows), NonnegativeConeT(n)];
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .build()
        .map_err(|e| EquilibriumError::Solver(format!("{e:?}")))?;
    let mut solver =
        DefaultSolver::new(&p, &q, &a, &b, &cones, settings).map_err(|e| EquilibriumError::Solver(format!("{e:?}")))?;
    solver.solve();
    tracing::debug!(status = ?solver.solution.status, parts = movers.len(), points = points.len(), "vertical QP");
    if solver.solution.status != SolverStatus::Solved {
        tracing::trace!(status = ?solver.solution.status, parts = movers.len(), "no vertical certificate");
        return Ok(None);
    }
    let x = &solver.solution.x;
    Ok(Some(
        points
            .iter()
            .zip(&unknown_of)
            .map(|(p, u)| match u {
                Some(j) => DVec3::Z * (p.frame[0].z.signum() * x[*j].max(0.0) * weight),
                None => DVec3::ZERO,
            })
            .collect(),
    ))
}
