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

    /// A lower bound of the minimum of `f` over the half-space `{p : a . p >= b - slack |a|}` (`slack >= 0`: how
    /// far a solver's point may violate the constraint, the cell tolerance).
    ///
    /// With `u = p - c` and `s = b - slack |a| - a . c`: when `s <= 0` the centre `c` is feasible and the bound is
    /// the constant; when some `h_i = 0` has `a_i != 0` the quadratic is flat along a direction that reaches the
    /// half-space, so again the constant; otherwise the minimum of `sum h_i u_i^2` subject to `a . u >= s` is
    /// `s^2 / sum_i (a_i^2 / h_i)` (Cauchy-Schwarz, attained at `u_i = s a_i / (h_i sum_j a_j^2 / h_j)`). The value
    /// is shrunk by a relative `1e-9` so that rounding never lifts it above the true minimum. O(D).
    pub fn halfspace_lower_bound(&self, a: &[f64; D], b: f64, slack: f64) -> f64 {
        let norm = a.iter().map(|x| x * x).sum::<f64>().sqrt();
        let s = b - slack * norm - (0..D).map(|i| a[i] * self.c[i]).sum::<f64>();
        if s.is_nan() || s <= 0.0 {
            return self.constant;
        }
        let mut denominator = 0.0;
        for i in 0..D {
            if a[i] != 0.0 {
                if self.h[i].is_nan() || self.h[i] <= 0.0 {
                    return self.constant;
                }
                denominator += a[i] * a[i] / self.h[i];
            }
        }
        if !(denominator > 0.0 && denominator.is_finite()) {
            return self.constant;
        }
        let rise = s * s / denominator * (1.0 - 1e-9);
        if rise.is_finite() { self.constant + rise.max(0.0) } else { self.constant }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed-form bound against a dense search over the half-space's boundary plane (where the minimum lies
    /// when the centre is outside) and the centre itself.
    #[test]
    fn halfspace_bound_is_the_minimum_over_the_halfspace() {
        let q = Quadratic { h: [2.0, 0.5, 1.0], c: [1.0, -2.0, 3.0], constant: 7.0 };
        let cases: [([f64; 3], f64); 4] =
            [([1.0, 0.0, 0.0], 4.0), ([1.0, 1.0, 0.0], 2.0), ([0.3, -0.4, 0.8], 5.0), ([0.0, 0.0, -1.0], -10.0)];
        for (a, b) in cases {
            let bound = q.halfspace_lower_bound(&a, b, 0.0);
            let inside_centre = (0..3).map(|i| a[i] * q.c[i]).sum::<f64>() >= b;
            // brute force: the minimum over a grid of the plane a . p = b (or the centre when it is feasible)
            let mut best = f64::INFINITY;
            if inside_centre {
                best = q.constant;
            } else {
                let k = (0..3).max_by(|&i, &j| a[i].abs().total_cmp(&a[j].abs())).expect("3 axes");
                let (u, v) = ((k + 1) % 3, (k + 2) % 3);
                for iu in -400..=400 {
                    for iv in -400..=400 {
                        let mut p = [0.0; 3];
                        p[u] = q.c[u] + iu as f64 * 0.02;
                        p[v] = q.c[v] + iv as f64 * 0.02;
                        p[k] = (b - a[u] * p[u] - a[v] * p[v]) / a[k];
                        best = best.min(q.value(&p));
                    }
                }
            }
            assert!(bound <= best + 1e-9, "bound {bound} above the minimum {best} for {a:?} >= {b}");
            assert!(bound >= best - 1e-3 * (1.0 + best), "bound {bound} far below the minimum {best} for {a:?} >= {b}");
        }
        // a flat direction reaching the half-space gives only the constant; slack moves the plane towards the centre
        let flat = Quadratic { h: [0.0, 1.0, 1.0], c: [0.0; 3], constant: 1.0 };
        assert_eq!(flat.halfspace_lower_bound(&[1.0, 1.0, 0.0], 5.0, 0.0), 1.0);
        let round = Quadratic { h: [1.0; 3], c: [0.0; 3], constant: 0.0 };
        assert!((round.halfspace_lower_bound(&[2.0, 0.0, 0.0], 6.0, 0.0) - 9.0).abs() < 1e-6);
        assert!((round.halfspace_lower_bound(&[2.0, 0.0, 0.0], 6.0, 0.5) - 6.25).abs() < 1e-6);
    }
}
