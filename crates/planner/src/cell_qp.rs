//! The placement QP on one free-space cell (\[A\] VI-A-1; `docs/algorithms.md`, "Free space and the placement QP"):
//! an adapter over `stackplan-freespace`'s exact active-set solver ([`stackplan_freespace::minimize`], KKT-verified,
//! lexicographic tie-break "lowest z, then y, then x" when the Hessian is singular, e.g. `w = 0` or `w = 1` in
//! cost (1)).
//!
//! The planner writes costs as `constant + sum_i h_i (p_i - c_i)^2` ([`Quadratic`]). For cost (1) of \[A\] with the
//! extents `x_min, x_max` of the rotated vertices `R v`: `(p_x + x_max - x0)^2 + (p_x + x_min - x0)^2 =
//! 2 (p_x - c_x)^2 + (x_max - x_min)^2 / 2` with `c_x = x0 - (x_max + x_min) / 2`, so `h_x = 2 w`, likewise `y`, and
//! `h_z = 4 (1 - w)`, `c_z = z0 - z_c` (`z_c` the height of the rotated c.g.); for the target cost (\[A\] VII-A)
//! `h = (1, 1, 1)` and `c = target - R g` ([`Quadratic::of_cost`]). freespace's form is
//! `1/2 sum H_i p_i^2 + g . p + c0`, so `H_i = 2 h_i`, `g_i = -2 h_i c_i`, `c0 = constant + sum_i h_i c_i^2`.
//! Should the exact solver report a failed KKT check (numerical trouble on a nearly degenerate cell), clarabel's
//! interior-point solution is taken instead (some minimiser, no tie-break) and the event is logged.
//! Cost: O(m) per active-set iteration, a handful of iterations in 2-3 variables.

use crate::request::Cost;
use glam::DVec3;
use stackplan_freespace::{Cell, QpError, SeparableCost, minimize, minimize_clarabel};

/// The optimum of the QP on a cell.
#[derive(Debug, Clone, PartialEq)]
pub struct QpOptimum<const D: usize> {
    /// The minimiser.
    pub point: [f64; D],
    /// The cost there.
    pub value: f64,
    /// Indices (into the cell's inequalities) of every constraint tight at the minimiser, within the tolerance.
    pub active: Vec<usize>,
    /// What the optimality conditions at `point` prove about the cost elsewhere in the cell (for
    /// [`Quadratic::lower_bound_beyond`]); `None` only if it came out non-finite.
    pub certificate: Option<Certificate>,
}

/// The first-order conditions at an optimum over a cell: `grad f(p*) = -sum_j lambda_j a_j + r` over the working
/// set (unit normals `a_j`, `lambda_j > 0`; a multiplier at or below zero is folded into the residual `r`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Certificate {
    /// `sum_j lambda_j` over the positive multipliers.
    pub multiplier_sum: f64,
    /// `|r|`.
    pub residual: f64,
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

impl Quadratic<3> {
    /// The cost `cost` (module documentation) for a part whose rotated vertices span `[lo, hi]` (relative to the
    /// position) and whose rotated c.g. offset is `cg`. O(1).
    pub fn of_cost(cost: &Cost, lo: DVec3, hi: DVec3, cg: DVec3) -> Self {
        match *cost {
            Cost::Stacking { w, origin } => {
                let hz = 4.0 * (1.0 - w);
                Self {
                    h: [2.0 * w, 2.0 * w, hz],
                    c: [origin.x - 0.5 * (hi.x + lo.x), origin.y - 0.5 * (hi.y + lo.y), origin.z - cg.z],
                    constant: 0.5 * w * ((hi.x - lo.x).powi(2) + (hi.y - lo.y).powi(2)),
                }
            }
            Cost::Target { target } => Self { h: [1.0; 3], c: (target - cg).to_array(), constant: 0.0 },
        }
    }
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

    /// A lower bound of the minimum of `f` over the box `[lo, hi]` (bounds may be infinite): `f` is separable, so the
    /// minimum is `constant + sum_i h_i dist(c_i, [lo_i, hi_i])^2`, attained at `c` clamped to the box. Shrunk by a
    /// relative `1e-9` against rounding, as the other bounds. The constant for an empty, non-finite or NaN box
    /// (a valid bound of any cost). O(D).
    pub fn box_lower_bound(&self, lo: &[f64; D], hi: &[f64; D]) -> f64 {
        if (0..D).any(|i| lo[i].is_nan() || hi[i].is_nan() || lo[i] > hi[i]) {
            return self.constant;
        }
        let mut rise = 0.0;
        for i in 0..D {
            if self.h[i].is_nan() || self.h[i] <= 0.0 {
                continue;
            }
            let gap = (lo[i] - self.c[i]).max(self.c[i] - hi[i]).max(0.0);
            rise += self.h[i] * gap * gap;
        }
        let rise = rise * (1.0 - 1e-9);
        if rise.is_finite() { self.constant + rise } else { self.constant }
    }

    /// A lower bound of the minimum of `f` over the points `p` of `cell`'s subset `{p : a . p >= b - slack |a|}`
    /// (`slack >= 0`, as [`Quadratic::halfspace_lower_bound`]), from `optimum`, the minimum of `f` over the cell
    /// (`tol`: the cell's tolerance; the subset's points may violate the cell's inequalities by up to `tol`).
    ///
    /// With `u = p - p*`, exactly `f(p) = f(p*) + grad f(p*) . u + sum_i h_i u_i^2`. By the certificate
    /// `grad f(p*) . u = -sum_j lambda_j a_j . u + r . u`, and `a_j . u <= 2 tol` (`a_j . p <= b_j + tol`, the working
    /// set is tight at `p*` within `tol`), so `f(p) >= f(p*) - 2 tol Lambda + Q(u) - |r| |u|` with `Q = sum h_i u_i^2`.
    /// On the half-space `Q >= Q0 = s^2 / sum_i (a_i^2 / h_i)`, `s = b - slack |a| - a . p*` (Cauchy-Schwarz, as
    /// [`Quadratic::halfspace_lower_bound`] around `p*`), and `|u| <= sqrt(Q / h_min)`; `Q - |r| sqrt(Q / h_min)`
    /// increases for `Q >= Q1 = |r|^2 / (4 h_min)`, so the rise is at least `Q0 - |r| sqrt(Q0 / h_min)` when
    /// `Q0 >= Q1`, and `-Q1` otherwise. The result is shrunk by a relative `1e-9` against rounding. Unlike the bound
    /// around the cost's centre this one grows with the distance of the half-space from the optimum (a child of a
    /// split lies beyond a face of an obstacle whose interior holds `p*`). `-inf` when no certificate is known or some
    /// `h_i` is not positive. O(D).
    pub fn lower_bound_beyond(&self, optimum: &QpOptimum<D>, a: &[f64; D], b: f64, slack: f64, tol: f64) -> f64 {
        let Some(cert) = optimum.certificate else {
            return f64::NEG_INFINITY;
        };
        let h_min = self.h.iter().copied().fold(f64::INFINITY, f64::min);
        if !(h_min > 0.0 && h_min.is_finite()) {
            return f64::NEG_INFINITY;
        }
        let norm = a.iter().map(|x| x * x).sum::<f64>().sqrt();
        let s = b - slack * norm - (0..D).map(|i| a[i] * optimum.point[i]).sum::<f64>();
        let denominator: f64 = (0..D).map(|i| a[i] * a[i] / self.h[i]).sum();
        let q0 = if s > 0.0 && denominator > 0.0 { s * s / denominator } else { 0.0 };
        let r = cert.residual;
        let q1 = r * r / (4.0 * h_min);
        let rise = if q0 >= q1 { q0 - r * (q0 / h_min).sqrt() } else { -q1 };
        let base = optimum.value - 2.0 * tol * cert.multiplier_sum;
        let bound = base + rise;
        let bound = bound - 1e-9 * (optimum.value.abs() + rise.abs() + 2.0 * tol * cert.multiplier_sum);
        if bound.is_finite() { bound } else { f64::NEG_INFINITY }
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
            match minimize_clarabel(cell, &cost) {
                Ok(s) => s,
                // a cell thinner than the tolerance with nearly opposite planes: clarabel on the tolerance-grown
                // cell, where the inequalities have a common point (its answer lies within twice the tolerance of
                // the cell's inequalities)
                Err(e2) => cell
                    .grown_by_tolerance()
                    .map_err(|e3| e3.to_string())
                    .and_then(|grown| minimize_clarabel(&grown, &cost).map_err(|e3| e3.to_string()))
                    .map_err(|e3| format!("{e}; clarabel: {e2}; clarabel on the grown cell: {e3}"))?,
            }
        }
    };
    // the certificate: r = grad f(p*) + sum_j lambda_j a_j over the positive multipliers of the working set (the
    // identity holds for any multipliers; those of the working set, tight at p* within the tolerance by the KKT
    // check, make r small; clarabel's answer has none, so r = grad f(p*), still a valid, weaker certificate)
    let mut residual: [f64; D] = std::array::from_fn(|i| 2.0 * q.h[i] * (sol.point[i] - q.c[i]));
    let mut multiplier_sum = 0.0;
    for (&j, &l) in sol.active.iter().zip(&sol.multipliers) {
        if l > 0.0 {
            multiplier_sum += l;
            let n = cell.halfspaces()[j].normal;
            for i in 0..D {
                residual[i] += l * n[i];
            }
        }
    }
    let residual = residual.iter().map(|x| x * x).sum::<f64>().sqrt();
    let certificate =
        (multiplier_sum.is_finite() && residual.is_finite()).then_some(Certificate { multiplier_sum, residual });
    Ok(Some(QpOptimum { point: sol.point, value: q.value(&sol.point), active: sol.tight, certificate }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use stackplan_freespace::{Halfspace, Tag};
    use stackplan_geom::Tolerance;

    /// A deterministic generator of numbers in `[0, 1)` (xorshift64).
    fn xorshift(mut state: u64) -> impl FnMut() -> f64 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// The box bound against the cost at the grid points of the box (never above any of them) and at the centre
    /// clamped to the box (equal up to the relative shrink), on random costs (some curvatures zero) and boxes (some
    /// sides infinite, some empty).
    #[test]
    fn box_bound_is_the_minimum_over_the_box() {
        let mut rnd = xorshift(0x9e37_79b9_7f4a_7c15);
        for _ in 0..500 {
            let q = Quadratic::<3> {
                h: std::array::from_fn(|_| if rnd() < 0.2 { 0.0 } else { 4.0 * rnd() }),
                c: std::array::from_fn(|_| 200.0 * rnd() - 100.0),
                constant: 50.0 * rnd(),
            };
            let mut lo: [f64; 3] = std::array::from_fn(|_| 200.0 * rnd() - 100.0);
            let mut hi: [f64; 3] = std::array::from_fn(|i| lo[i] + 50.0 * rnd());
            if rnd() < 0.2 {
                lo[0] = f64::NEG_INFINITY;
            }
            if rnd() < 0.2 {
                hi[1] = f64::INFINITY;
            }
            let bound = q.box_lower_bound(&lo, &hi);
            if rnd() < 0.1 {
                // an empty box: the constant, a bound of every cost
                let empty = [hi[0] + 1.0, lo[1], lo[2]];
                assert_eq!(q.box_lower_bound(&empty, &hi), q.constant);
            }
            let clamp: [f64; 3] = std::array::from_fn(|i| q.c[i].clamp(lo[i], hi[i]));
            let at_clamp = q.value(&clamp);
            assert!(bound <= at_clamp && bound >= at_clamp - 1e-8 * at_clamp.abs(), "{bound} against {at_clamp}");
            for k in 0..27 {
                let p: [f64; 3] = std::array::from_fn(|i| {
                    let (a, b) = (lo[i].max(-1e3), hi[i].min(1e3));
                    a + (b - a) * [0.0, 0.5, 1.0][(k / 3usize.pow(i as u32)) % 3]
                });
                assert!(q.value(&p) >= bound, "{} below the bound {bound} at {p:?}", q.value(&p));
            }
        }
    }

    /// The bound from the optimality conditions against the true minimum over the cell cut by the half-space, on
    /// random cells (a box cut by random planes), random costs (centre inside or outside) and random half-spaces;
    /// and it is useful: above the parent's cost for half-spaces away from the optimum.
    #[test]
    fn bound_beyond_is_below_the_minimum_over_the_cut_cell() {
        let mut rnd = xorshift(0x2545_f491_4f6c_dd1d);
        let tol = Tolerance::for_scale(200.0);
        let (mut checked, mut useful) = (0, 0);
        for _ in 0..200 {
            let mut hs = Vec::new();
            for i in 0..3 {
                let mut n = [0.0; 3];
                n[i] = 1.0;
                hs.push(Halfspace::new(n, 100.0, Tag::User(0)));
                n[i] = -1.0;
                hs.push(Halfspace::new(n, 100.0, Tag::User(0)));
            }
            for _ in 0..4 {
                let n = [rnd() - 0.5, rnd() - 0.5, rnd() - 0.5];
                hs.push(Halfspace::new(n, 10.0 + 30.0 * rnd(), Tag::User(1)));
            }
            let Ok(cell) = Cell::new(hs, tol) else { continue };
            let q = Quadratic {
                h: [0.2 + rnd(), 0.2 + rnd(), 0.2 + 2.0 * rnd()],
                c: [300.0 * (rnd() - 0.5), 300.0 * (rnd() - 0.5), 300.0 * (rnd() - 0.5)],
                constant: 10.0 * rnd(),
            };
            let Ok(Some(opt)) = minimise(&cell, &q) else { continue };
            assert!(opt.certificate.is_some());
            for _ in 0..10 {
                let a = [rnd() - 0.5, rnd() - 0.5, rnd() - 0.5];
                let b = (0..3).map(|i| a[i] * opt.point[i]).sum::<f64>() + 40.0 * (rnd() - 0.3);
                let bound = q.lower_bound_beyond(&opt, &a, b, 2.0 * tol.linear, tol.linear);
                let outside = Halfspace::new(a, b, Tag::User(2)).flipped(Tag::User(2));
                let Ok(cut) = cell.with_halfspaces([outside]) else { continue };
                let Ok(Some(cut_opt)) = minimise(&cut, &q) else { continue };
                checked += 1;
                assert!(
                    bound <= cut_opt.value + 1e-9 * (1.0 + cut_opt.value.abs()),
                    "bound {bound} above the minimum {} over the cut cell (parent {})",
                    cut_opt.value,
                    opt.value
                );
                if bound > opt.value {
                    useful += 1;
                }
            }
        }
        assert!(checked > 200, "{checked} cut cells checked");
        assert!(useful > checked / 10, "bound above the parent's cost in only {useful} of {checked}");
    }

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
