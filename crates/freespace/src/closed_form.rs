//! The closed-form active-set iterations in 2 or 3 variables: the phase 1 of a cell (`Problem::seek_small`, a
//! linear objective) and the strictly convex QP.
//!
//! **Strictly convex fast path** (`Problem::solve_strictly_convex`, the placement QP of cost (1) with
//! `0.002 <= w <= 0.9995` and the desired-position cost): when every `h_i > 0` in 2 or 3 variables (and
//! `min h / max h >= 1e-3`, so that no direction is nearly flat), `F` is empty, the
//! minimiser is unique and the tie-break stages are moot, so the same iteration (same start, same working-set
//! rules, ratio test, multiplier test and anti-cycling) runs with its linear algebra in closed form: the Newton step
//! in the null space of `A_W` is `-H^-1 grad` (no working row), `-(z . grad) / (z^T H z) z` for a one-dimensional
//! null space `z = a_1 x a_2` (2 rows in 3-D; `a_1` turned by 90 degrees in 2-D), a 2x2 reduced system on an
//! orthonormal basis `a x e / |.|`, `a x z_1 / |.|` of the plane (1 row in 3-D), and zero at a vertex; the
//! multipliers `A_W^T lambda = -grad` come from the Gram system of order <= 2 or Cramer's rule with cross products.
//! About 0.1 µs of linear algebra per iteration instead of about 0.3-0.5 µs for the Gram-Schmidt split with Cholesky
//! factors and lexicographic stages. A numerically singular system or the iteration limit hands the problem to the
//! general method (and [`crate::qp::minimize`] falls back to it too when the KKT check rejects the result).
//!
//! The phase 1 (`Problem::seek_small`) is [`Problem::seek`] with the move `-P g` (the projection of the objective on
//! the null space of at most two working rows) by a cross product or one projection and the multipliers by Cramer's
//! rule or a 2 x 2 Gram system. Both paths keep the general method's start, working-set rules, ratio test and
//! anti-cycling ([`crate::active_set`]); O(m) per iteration (the ratio test) plus O(1).

use crate::active_set::{FAST_PATH_MIN_CURVATURE_RATIO, MULT_TOL, Outcome, Problem, Seek, WorkSet, record_move};
use crate::linalg::{MAX_N, V4, axpy, cross3, dot4, norm4, normalized, unit};

impl Problem<'_> {
    /// [`Problem::seek`] for a linear objective in 2 or 3 variables with the linear algebra in closed form: the
    /// same iteration (same start, working-set rules, ratio test, level test, multiplier test and anti-cycling) but
    /// the move is minus the projection of `g` on the null space of the working rows, `-g` (no row),
    /// `-(g - (g . a) a / |a|^2)` (one row in 3-D), `-(g . z) z / |z|^2` on a line `z = a_1 x a_2` (two rows in 3-D;
    /// `a_1` turned by 90 degrees in 2-D), none at a vertex; the multipliers come from
    /// [`Problem::multipliers`] (a Gram system of order <= 2 or Cramer's rule). No Gram-Schmidt split, no Cholesky
    /// factors: O(m) per iteration (the ratio test) plus O(1).
    ///
    /// Rounding differs from [`Problem::seek`] in the last bits, so the point returned may too; its *decision*
    /// (level reached or not) is the same except when the minimum is within rounding of the target. `None` (the
    /// caller then runs [`Problem::seek`]) when the path does not apply (`h != 0`, `n` not 2 or 3), a system is
    /// numerically singular, or the iteration limit is reached.
    pub(crate) fn seek_small(&self, start: V4, target: f64) -> Option<Seek> {
        let n = self.n;
        if !(2..=3).contains(&n) || self.h.iter().any(|&x| x != 0.0) {
            return None;
        }
        let m = self.rows.len();
        let bland_after = 4 * m + 20;
        let limit = 40 * (m + 5);
        let gradient_scale = self.gradient_scale();
        let flat_tol = 1e-10 * gradient_scale;
        let mult_tol = MULT_TOL * gradient_scale;
        let g = self.g;
        let mut p = start;
        let mut w = WorkSet::default();
        let mut banned: Vec<usize> = Vec::new();
        let mut last_dropped: Option<usize> = None;
        for iter in 0..limit {
            let level = dot4(&g, &p);
            if level <= target {
                return Some(Seek::Reached(p));
            }
            let dir = self.lp_projected_descent(&w)?;
            let len = norm4(&dir);
            if !len.is_finite() {
                return None;
            }
            if len <= flat_tol {
                // stationary: drop the most negative multiplier (Bland's rule late), or stop at the minimum
                let lambda = self.multipliers(&w, &g)?;
                let choice = most_negative_multiplier(&lambda, &w, &banned, iter >= bland_after, mult_tol);
                match choice {
                    Some(a) => {
                        last_dropped = Some(w.idx[a]);
                        w.remove_at(a);
                        continue;
                    }
                    None => return Some(Seek::Minimum { point: p, value: level }),
                }
            }
            let (alpha, blocking) = self.ratio_test(&w, &p, &dir, len, f64::INFINITY);
            let descent = dot4(&g, &dir);
            if descent < 0.0 {
                let to_level = (target - level) / descent;
                if to_level <= alpha {
                    axpy(&mut p, to_level, &dir);
                    return Some(Seek::Reached(p));
                }
            }
            let j = blocking?;
            axpy(&mut p, alpha, &dir);
            record_move(alpha * len, self.length_scale, blocking, &mut last_dropped, &mut banned);
            if w.len >= n {
                return None;
            }
            w.push(j);
        }
        None
    }

    /// `-P g`: minus the projection of the (linear) objective `g` on the null space of the working rows, in closed
    /// form for `n` = 2 or 3 (see [`Problem::seek_small`]). `None` when the rows are numerically dependent.
    fn lp_projected_descent(&self, w: &WorkSet) -> Option<V4> {
        let n = self.n;
        let g = &self.g;
        let row = |a: usize| &self.rows[w.idx[a]];
        let along = |z: &V4| {
            let zz = dot4(z, z);
            if !(zz > 0.0 && zz.is_finite()) {
                return None;
            }
            let t = -dot4(z, g) / zz;
            Some(z.map(|c| c * t))
        };
        match (n, w.len) {
            (_, 0) => Some(g.map(|c| -c)),
            (2, 1) => {
                let a = row(0);
                along(&[-a[1], a[0], 0.0, 0.0])
            }
            (3, 1) => {
                let a = row(0);
                let aa = dot4(a, a);
                if !(aa > 0.0 && aa.is_finite()) {
                    return None;
                }
                let t = dot4(a, g) / aa;
                let mut d = [0.0; MAX_N];
                for i in 0..3 {
                    d[i] = -(g[i] - t * a[i]);
                }
                Some(d)
            }
            (3, 2) => along(&cross3(row(0), row(1))),
            _ => Some([0.0; MAX_N]),
        }
    }
}

impl Problem<'_> {
    /// Whether the closed-form path applies: `n` is 2 or 3, every `h_i > 0` (finite) and
    /// `min h / max h >= FAST_PATH_MIN_CURVATURE_RATIO`.
    fn strictly_convex(&self) -> bool {
        let h = &self.h[..self.n];
        let hi = h.iter().fold(0.0_f64, |a, &x| a.max(x));
        (2..=3).contains(&self.n)
            && h.iter().all(|&x| x > 0.0 && x.is_finite())
            && h.iter().all(|&x| x >= FAST_PATH_MIN_CURVATURE_RATIO * hi)
    }

    /// The Newton step `d` of `f` at `p` within the null space of the working rows, `min f(p + d)` subject to
    /// `a_w . d = 0`, in closed form (positive diagonal Hessian, `n` = 2 or 3):
    ///
    /// * no working row: `d = -H^-1 grad`;
    /// * a null space of dimension 1 spanned by `z` (`a_1 x a_2` in 3-D, `a_1` turned by 90 degrees in 2-D):
    ///   `d = -(z . grad) / (z^T H z) z`;
    /// * one row in 3-D: an orthonormal basis `z_1 = a x e / |.|` (`e` the coordinate axis least aligned with `a`),
    ///   `z_2 = a x z_1 / |.|` of the plane and the 2x2 system `(Z^T H Z) t = -Z^T grad`, `d = Z t`;
    /// * `n` rows: `d = 0`.
    ///
    /// The step lies in the null space up to the rounding of a few products, as the general method's does, so the
    /// iterate stays on its working planes. `None` when a reduced Hessian is not positive (underflow).
    fn null_space_step(&self, w: &WorkSet, grad: &V4) -> Option<V4> {
        let n = self.n;
        let k = w.len;
        let row = |a: usize| &self.rows[w.idx[a]];
        let mut d = [0.0; MAX_N];
        if k == 0 {
            for i in 0..n {
                d[i] = -grad[i] / self.h[i];
            }
            return Some(d);
        }
        if k >= n {
            return Some(d);
        }
        let along = |z: &V4| {
            let mut zhz = 0.0;
            for i in 0..n {
                zhz += self.h[i] * z[i] * z[i];
            }
            if !(zhz > 0.0 && zhz.is_finite()) {
                return None;
            }
            let t = -dot4(z, grad) / zhz;
            Some(z.map(|c| c * t))
        };
        if n == 2 {
            let a = row(0);
            return along(&[-a[1], a[0], 0.0, 0.0]);
        }
        if k == 2 {
            return along(&cross3(row(0), row(1)));
        }
        // n = 3, one working row
        let a = row(0);
        let axis = if a[0].abs() <= a[1].abs() && a[0].abs() <= a[2].abs() {
            0
        } else if a[1].abs() <= a[2].abs() {
            1
        } else {
            2
        };
        let z1 = normalized(&cross3(a, &unit(axis)))?;
        let z2 = normalized(&cross3(a, &z1))?;
        let (mut m11, mut m12, mut m22) = (0.0, 0.0, 0.0);
        for i in 0..3 {
            m11 += self.h[i] * z1[i] * z1[i];
            m12 += self.h[i] * z1[i] * z2[i];
            m22 += self.h[i] * z2[i] * z2[i];
        }
        let det = m11 * m22 - m12 * m12;
        if !(det > 0.0 && det.is_finite()) {
            return None;
        }
        let (r1, r2) = (-dot4(&z1, grad), -dot4(&z2, grad));
        let t1 = (r1 * m22 - r2 * m12) / det;
        let t2 = (r2 * m11 - r1 * m12) / det;
        for i in 0..3 {
            d[i] = t1 * z1[i] + t2 * z2[i];
        }
        Some(d)
    }

    /// Multipliers of the working rows at a stationary point: the least-squares solution of `A_W^T lambda = -r`
    /// (`r` the gradient at the stationary point), by the Gram system of order `k <= 2` or, for `n` rows, Cramer's
    /// rule (cross products in 3-D). `None` when the rows are numerically dependent.
    fn multipliers(&self, w: &WorkSet, r: &V4) -> Option<V4> {
        let n = self.n;
        let k = w.len;
        let row = |a: usize| &self.rows[w.idx[a]];
        let mut lambda = [0.0; MAX_N];
        let ok = |x: f64| x.abs() > 0.0 && x.is_finite();
        match k {
            0 => {}
            1 => {
                let a = row(0);
                let aa = dot4(a, a);
                if !ok(aa) {
                    return None;
                }
                lambda[0] = -dot4(a, r) / aa;
            }
            2 if n == 2 => {
                let (a1, a2) = (row(0), row(1));
                let det = a1[0] * a2[1] - a1[1] * a2[0];
                if !ok(det) {
                    return None;
                }
                lambda[0] = -(r[0] * a2[1] - r[1] * a2[0]) / det;
                lambda[1] = -(a1[0] * r[1] - a1[1] * r[0]) / det;
            }
            2 => {
                let (a1, a2) = (row(0), row(1));
                let (g11, g12, g22) = (dot4(a1, a1), dot4(a1, a2), dot4(a2, a2));
                let det = g11 * g22 - g12 * g12;
                if !(det > 0.0 && det.is_finite()) {
                    return None;
                }
                let (r1, r2) = (-dot4(a1, r), -dot4(a2, r));
                lambda[0] = (r1 * g22 - r2 * g12) / det;
                lambda[1] = (r2 * g11 - r1 * g12) / det;
            }
            _ => {
                // n = 3 rows in 3-D: the inverse of A_W^T has the rows (a_2 x a_3, a_3 x a_1, a_1 x a_2) / det
                let (a1, a2, a3) = (row(0), row(1), row(2));
                let c23 = cross3(a2, a3);
                let det = dot4(a1, &c23);
                if !ok(det) {
                    return None;
                }
                lambda[0] = -dot4(r, &c23) / det;
                lambda[1] = -dot4(r, &cross3(a3, a1)) / det;
                lambda[2] = -dot4(r, &cross3(a1, a2)) / det;
            }
        }
        Some(lambda)
    }

    /// The fast path of [`Problem::solve`] for a strictly convex objective (every `h_i > 0`, `n` = 2 or 3,
    /// `min h / max h >= FAST_PATH_MIN_CURVATURE_RATIO`): the same
    /// primal active-set iteration from `start` (working-set rules, ratio test, multiplier test, anti-cycling), with
    /// the null-space Newton step and the multipliers in closed form ([`Problem::null_space_step`],
    /// [`Problem::multipliers`]) instead of a Gram-Schmidt split with Cholesky factors and lexicographic stages. The
    /// tie-break is moot (the minimiser is unique), so only the objective's multipliers are tested. O(m) per
    /// iteration (the ratio test) plus O(1).
    ///
    /// Returns `None` (the caller then runs the general [`Problem::solve`]) when the path does not apply, a system
    /// becomes numerically singular, or the iteration limit is reached; it never reports unboundedness (a strictly
    /// convex quadratic is bounded below).
    pub(crate) fn solve_strictly_convex(&self, start: V4) -> Option<Outcome> {
        if !self.strictly_convex() {
            return None;
        }
        let n = self.n;
        let m = self.rows.len();
        let bland_after = 4 * m + 20;
        let limit = 40 * (m + 5);
        let stationary = 1e-12 * self.length_scale;
        let mult_tol = MULT_TOL * self.gradient_scale();
        let mut p = start;
        let mut w = WorkSet::default();
        let mut banned: Vec<usize> = Vec::new();
        let mut last_dropped: Option<usize> = None;
        for iter in 0..limit {
            let grad = self.gradient(&p);
            let dir = self.null_space_step(&w, &grad)?;
            let len = norm4(&dir);
            if !len.is_finite() {
                return None;
            }
            if len <= stationary {
                // the multiplier test at the gradient of the subspace minimiser p + dir
                let mut r = grad;
                for i in 0..n {
                    r[i] += self.h[i] * dir[i];
                }
                let lambda = self.multipliers(&w, &r)?;
                let choice = most_negative_multiplier(&lambda, &w, &banned, iter >= bland_after, mult_tol);
                match choice {
                    Some(a) => {
                        last_dropped = Some(w.idx[a]);
                        w.remove_at(a);
                    }
                    None => {
                        return Some(Outcome::Optimal {
                            point: p,
                            working: w,
                            multipliers: lambda,
                            iterations: iter + 1,
                        });
                    }
                }
                continue;
            }
            let (alpha, blocking) = self.ratio_test(&w, &p, &dir, len, 1.0);
            axpy(&mut p, alpha, &dir);
            record_move(alpha * len, self.length_scale, blocking, &mut last_dropped, &mut banned);
            if let Some(j) = blocking {
                if w.len >= n {
                    return None;
                }
                w.push(j);
            }
        }
        None
    }
}

#[inline]
/// The working-set slot whose constraint to drop in the closed-form paths ([`Problem::seek_small`],
/// [`Problem::solve_strictly_convex`]): the most negative multiplier below `-mult_tol` (or, under Bland's rule, the
/// lowest constraint index among them), skipping `banned` constraints; `None` at a minimum. O(|W| |banned|).
fn most_negative_multiplier(lambda: &V4, w: &WorkSet, banned: &[usize], bland: bool, mult_tol: f64) -> Option<usize> {
    let mut choice: Option<usize> = None;
    for a in 0..w.len {
        if lambda[a] < -mult_tol && !banned.contains(&w.idx[a]) {
            choice = match choice {
                None => Some(a),
                Some(c) => {
                    let better = if bland { w.idx[a] < w.idx[c] } else { lambda[a] < lambda[c] };
                    Some(if better { a } else { c })
                }
            };
        }
    }
    choice
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::active_set::tests::random_problem;

    proptest::proptest! {

        /// The closed-form phase 1 (`seek_small`) against the general `seek` (the oracle): the same decision (level
        /// reached or the minimum above it) unless the minimum is within 1e-9 of the target, the same minimum value,
        /// and a returned point that satisfies every enabled row and reaches the level. Random cells with duplicate
        /// rows, flat pairs and apexes of 4-5 planes; random masks; targets below, near and above the minimum.
        #[test]
        fn closed_form_phase_one_agrees_with_the_general_one(
            seed in proptest::prelude::any::<u64>(), n in 2usize..4, kind in 0u8..4, cuts in 0usize..10,
            masked in proptest::prelude::any::<u32>(), frac in -0.5f64..1.5,
        ) {
            let (rows, b, _, g, c) = random_problem(seed, n, kind, cuts);
            // disabled rows: only cuts (the box stays, so the LP stays bounded)
            let mask: Vec<bool> = (0..rows.len()).map(|j| j < 2 * n || (masked >> (j % 32)) & 1 == 0).collect();
            let prob = Problem {
                n, rows: &rows, offsets: &b, mask: Some(&mask), h: [0.0; MAX_N], g, tie: [2, 1, 0, 3], length_scale: 10.0,
            };
            let Ok(Seek::Minimum { value: min, .. }) = prob.seek(c, f64::NEG_INFINITY) else {
                return Err(proptest::test_runner::TestCaseError::fail("general seek to -inf must end at the minimum"));
            };
            let fast_min = prob.seek_small(c, f64::NEG_INFINITY);
            let Some(Seek::Minimum { value: fmin, point: fp }) = fast_min else {
                return Err(proptest::test_runner::TestCaseError::fail(format!("fast seek to -inf: {fast_min:?}")));
            };
            let scale = 1e-9 * (1.0 + min.abs());
            proptest::prop_assert!((fmin - min).abs() <= scale, "minimum {fmin} vs {min}");
            proptest::prop_assert!((dot4(&g, &fp) - fmin).abs() <= scale);
            let start_level = dot4(&g, &c);
            let target = min + frac * (start_level - min);
            let general = prob.seek(c, target).expect("general");
            let fast = prob.seek_small(c, target).expect("closed form");
            let point = match (fast, general) {
                (Seek::Reached(p), Seek::Reached(_)) => p,
                (Seek::Minimum { point, value }, Seek::Minimum { value: v, .. }) => {
                    proptest::prop_assert!((value - v).abs() <= scale);
                    point
                }
                (f, _) => {
                    proptest::prop_assert!((target - min).abs() <= scale, "decisions differ away from the minimum: {f:?}");
                    return Ok(());
                }
            };
            for (j, a) in rows.iter().enumerate() {
                if mask[j] {
                    proptest::prop_assert!(dot4(a, &point) - b[j] <= 1e-9, "row {j} violated");
                }
            }
            if let Seek::Reached(_) = fast {
                proptest::prop_assert!(dot4(&g, &point) <= target + scale);
            }
        }

        /// The closed-form path on its own (no fallback): it must finish, and agree with the general method.
        #[test]
        fn strictly_convex_path_agrees_with_the_general_method(
            seed in proptest::prelude::any::<u64>(), n in 2usize..4, kind in 0u8..4, cuts in 0usize..10,
        ) {
            let (rows, b, h, g, c) = random_problem(seed, n, kind, cuts);
            let prob = Problem { n, rows: &rows, offsets: &b, mask: None, h, g, tie: [2, 1, 0, 3], length_scale: 10.0 };
            let fast = prob.solve_strictly_convex(c);
            let (lo, hi) = (0..n).fold((f64::INFINITY, 0.0_f64), |(lo, hi), i| (lo.min(h[i]), hi.max(h[i])));
            if lo < FAST_PATH_MIN_CURVATURE_RATIO * hi {
                proptest::prop_assert!(fast.is_none(), "ill-conditioned Hessians take the general method");
                return Ok(());
            }
            let general = prob.solve(c).expect("general");
            let (Some(Outcome::Optimal { point: pf, working: wf, multipliers: lf, .. }), Outcome::Optimal { point: pg, .. }) =
                (fast, general)
            else {
                return Err(proptest::test_runner::TestCaseError::fail(format!("fast {fast:?} general {general:?}")));
            };
            for i in 0..n {
                proptest::prop_assert!((pf[i] - pg[i]).abs() <= 1e-9, "{pf:?} vs {pg:?}");
            }
            // KKT of the fast path's own answer: feasible, working rows tight, multipliers >= 0, stationary
            for (j, a) in rows.iter().enumerate() {
                proptest::prop_assert!(dot4(a, &pf) - b[j] <= 1e-9);
            }
            let mut r = prob.gradient(&pf);
            for (k, &j) in wf.as_slice().iter().enumerate() {
                proptest::prop_assert!((dot4(&rows[j], &pf) - b[j]).abs() <= 1e-9);
                proptest::prop_assert!(lf[k] >= -1e-9 * prob.gradient_scale());
                axpy(&mut r, lf[k], &rows[j]);
            }
            proptest::prop_assert!(norm4(&r) <= 1e-9 * prob.gradient_scale(), "residual {r:?}");
        }
    }
}
