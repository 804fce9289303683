//! The placement QP on one free-space cell ([A] VI-A-1, DESIGN.md section 5): an adapter over
//! `stackplan-freespace`'s exact active-set solver ([`stackplan_freespace::minimize`], KKT-verified, lexicographic
//! tie-break "lowest z, then y, then x" when the Hessian is singular, e.g. `w = 0` or `w = 1` in cost (1)).
//!
//! The planner writes costs as `constant + sum_i h_i (p_i - c_i)^2`; freespace's form is
//! `1/2 sum H_i p_i^2 + g . p + c0`, so `H_i = 2 h_i`, `g_i = -2 h_i c_i`, `c0 = constant + sum_i h_i c_i^2`.
//! Should the exact solver report a failed KKT check (numerical trouble on a nearly degenerate cell), clarabel's
//! interior-point solution is taken instead (some minimiser, no tie-break) and the event is logged.
//! Cost: O(m) per active-set iteration, a handful of iterations in 2-3 variables.

use stackplan_freespace::cell::Cell;
use stackplan_freespace::{QpError, SeparableCost, minimize, minimize_clarabel};

/// The optimum of the QP on a cell.
#[derive(Debug, Clone, PartialEq)]
pub struct QpOptimum<const D: usize> {
    /// The minimiser.
    pub point: [f64; D],
    /// The cost there.
    pub value: f64,
    /// Indices (into the cell's inequalities) of every constraint tight at the minimiser, within the tolerance.
    pub active: Vec<usize>,
}

/// `f(p) = constant + sum_i h_i (p_i - c_i)^2`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quadratic<const D: usize> {
    /// Curvatures (>= 0).
    pub h: [f64; D],
    /// Centres.
    pub c: [f64; D],
    /// Constant.
    pub constant: f64,
}

impl<const D: usize> Quadratic<D> {
    /// The value at `p`.
    pub fn value(&self, p: &[f64; D]) -> f64 {
        self.constant + (0..D).map(|i| self.h[i] * (p[i] - self.c[i]).powi(2)).sum::<f64>()
    }

    fn as_freespace(&self) -> Result<SeparableCost<D>, String> {
        let hh: [f64; D] = std::array::from_fn(|i| 2.0 * self.h[i]);
        let g: [f64; D] = std::array::from_fn(|i| -2.0 * self.h[i] * self.c[i]);
        let c0 = self.constant + (0..D).map(|i| self.h[i] * self.c[i] * self.c[i]).sum::<f64>();
        SeparableCost::new(hh, g, c0).map_err(|e| e.to_string())
    }
}

/// Minimises `q` over `cell`. `Ok(None)` when the cell is empty; `Err` when both solvers fail.
pub fn minimise<const D: usize>(cell: &Cell<D>, q: &Quadratic<D>) -> Result<Option<QpOptimum<D>>, String> {
    if cell.is_empty() {
        return Ok(None);
    }
    let cost = q.as_freespace()?;
    let sol = match minimize(cell, &cost) {
        Ok(s) => s,
        Err(QpError::EmptyCell) => return Ok(None),
        Err(e) => {
            tracing::warn!(error = %e, "exact placement QP failed; using clarabel");
            minimize_clarabel(cell, &cost).map_err(|e2| format!("{e}; clarabel: {e2}"))?
        }
    };
    Ok(Some(QpOptimum { point: sol.point, value: q.value(&sol.point), active: sol.tight }))
}
