//! The first-order (KKT) conditions of a QP solution over a cell, checked from scratch: for a convex problem they prove
//! global optimality (Nocedal & Wright, *Numerical Optimization*, 2nd ed., Theorem 16.4). O(m D).

use crate::cell::Cell;
use crate::cost::SeparableCost;
use crate::solution::{QpError, QpSolution};

/// Verifies the first-order (KKT) conditions of a solution of [`crate::qp::minimize`], which for a convex problem prove global
/// optimality:
///
/// * primal feasibility: `a_j . p - b_j <= tol` for every `j` (the cell's tolerance);
/// * complementarity: every `j` in `active` is tight, `|a_j . p - b_j| <= tol`;
/// * dual feasibility: `lambda_j >= -eps`;
/// * stationarity: `|grad f(p) + sum_j lambda_j a_j| <= 1e-8 * max(G, T)`,
///
/// with `eps = 1e-8 * G`, `G = max_i (h_i L + |g_i|)` the gradient scale over the cell's length scale `L`, and
/// `T = max_i (|h_i p_i| + |g_i| + sum_j |lambda_j a_ji|)` the size of the terms the residual sums (its rounding
/// scale). `T` exceeds `G` only where the multipliers are huge: at a vertex held by nearly parallel planes (the
/// c-space obstacles of sheet-metal parts whose faces are a few micrometres out of line have faces 1e-7 rad from
/// parallel) they are about `|grad f| / sin(angle)`, and the rounding of the 2 x 2 system that gives them leaves a
/// residual near 1e-10 `T`, far above `1e-8 G` (the test `the_apex_of_a_thin_wedge_passes_the_kkt_check`). A wrong
/// working set leaves a residual of the order of `G`, which ordinary multipliers (`T` about `G`) still reject.
pub fn verify_kkt<const D: usize>(cell: &Cell<D>, cost: &SeparableCost<D>, sol: &QpSolution<D>) -> Result<(), QpError> {
    let tol = cell.tolerance().linear;
    let hs = cell.halfspaces();
    let mut worst = f64::NEG_INFINITY;
    for h in hs {
        worst = worst.max(h.excess(&sol.point));
    }
    if worst > tol {
        return Err(QpError::Kkt { what: "primal feasibility", value: worst, allowed: tol });
    }
    let (h, g) = (cost.hessian_diagonal(), cost.linear());
    verify_kkt_dual(cell, &h, &g, sol)
}

/// The conditions of [`verify_kkt`] other than primal feasibility.
pub(crate) fn verify_kkt_dual<const D: usize>(
    cell: &Cell<D>,
    h: &[f64; D],
    g: &[f64; D],
    sol: &QpSolution<D>,
) -> Result<(), QpError> {
    let tol = cell.tolerance().linear;
    let hs = cell.halfspaces();
    let scale = cell.length_scale();
    let gs = (0..D).map(|i| h[i] * scale + g[i].abs()).fold(f64::MIN_POSITIVE, f64::max);
    let eps = 1e-8 * gs;
    let mut residual = [0.0; D];
    let mut terms = [0.0; D];
    for i in 0..D {
        residual[i] = h[i] * sol.point[i] + g[i];
        terms[i] = (h[i] * sol.point[i]).abs() + g[i].abs();
    }
    for (&j, &l) in sol.active.iter().zip(&sol.multipliers) {
        let e = hs[j].excess(&sol.point).abs();
        if e > tol {
            return Err(QpError::Kkt { what: "complementarity", value: e, allowed: tol });
        }
        if l < -eps {
            return Err(QpError::Kkt { what: "dual feasibility", value: l, allowed: -eps });
        }
        for i in 0..D {
            residual[i] += l * hs[j].normal[i];
            terms[i] += (l * hs[j].normal[i]).abs();
        }
    }
    let r = residual.iter().map(|x| x * x).sum::<f64>().sqrt();
    let allowed = 1e-8 * terms.iter().copied().fold(gs, f64::max);
    // (non-finite multipliers or residual never pass: `allowed` would be infinite too)
    if !(r <= allowed && allowed.is_finite()) {
        return Err(QpError::Kkt { what: "stationarity", value: r, allowed });
    }
    Ok(())
}
