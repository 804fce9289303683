//! Exact primal active-set solver for tiny convex problems: at most four variables, any number of inequalities.
//!
//! Solves the lexicographic problem
//!
//! ```text
//! lex-min ( f(p), p[tie[0]], p[tie[1]], ... )   subject to   a_j . p <= b_j  (j = 1..m)
//! f(p) = 1/2 sum_i h_i p_i^2 + g . p,  h_i >= 0
//! ```
//!
//! i.e. minimise the separable convex quadratic `f` (an LP when `h = 0`) and break ties among its minimisers by the
//! lowest coordinate in the order `tie`. This is the hot path of \[A\] VI-A-1/VI-A-4 (Ayyadevara et al. 2002: "use a
//! closed-form method to compute the optimal position for each convex component") and, with `h = 0` and one more
//! variable, the LP behind the Chebyshev centre, emptiness, redundancy and touching tests of a cell.
//!
//! Method (Nocedal & Wright, *Numerical Optimization*, 2nd ed., Alg. 16.3, extended to a positive *semi*-definite
//! diagonal Hessian and a lexicographic objective): keep a feasible point `p` and a working set `W` of linearly
//! independent tight constraints. In the null space `N` of `A_W` split off the flat subspace
//! `F = N ∩ {d : d_i = 0 for h_i > 0}` (where `f` is linear) from its complement `C` (where `f` is strictly convex):
//!
//! 1. if `f` decreases along `F` (`P_F grad f != 0`) move along the ray `-P_F grad f`;
//! 2. else take the Newton step in `C` (`M_C t = -C^T grad f`, `M_C = C^T H C` positive definite, Cholesky);
//! 3. else (the point minimises `f` on the affine subspace) follow the tie-break: the first `e_tie[k]` with a
//!    non-zero projection on `F` gives the ray `-P_F e_tie[k]` (on `F`, `f` is constant);
//! 4. each move stops at the first blocking constraint (ratio test), which joins `W`; an unblocked ray means the
//!    problem is unbounded (reported, never looped on);
//! 5. at a stationary point, compute lexicographic multipliers (`f` stage, then each tie stage: the perturbation
//!    `f + e1 p[tie0] + e2 p[tie1] + ...` with `e1 >> e2 >> ... > 0` infinitesimal gives the multiplier
//!    `lambda_0 + e1 mu_1 + ...`, compared lexicographically with 0). If one is lexicographically negative, drop that
//!    constraint; otherwise `p` is optimal.
//!
//! Linear objectives (`h = 0`, every LP of the crate) skip the flat/curved split (the whole null space is flat; the
//! shortcut gives the general split's bits), and the orthonormal basis of the working rows is extended by one
//! Gram-Schmidt step as a row joins instead of being recomputed. The phase 1 in 2-3 variables
//! (`Problem::seek_small`) runs with its linear algebra in closed form (cross products, Cramer's rule).
//!
//! Anti-cycling: after `4 m + 20` iterations both choices switch to Bland's rule (lowest index); a hard iteration
//! limit returns an error instead of looping. Cost per iteration O(m) (the ratio test) plus O(1) linear algebra on
//! at most 4x4 matrices; in three variables the number of iterations is usually at most 4-8.
//!
//! The closed-form variants for 2-3 variables (the phase 1 of a cell and the strictly convex QP) are in
//! [`crate::closed_form`].

use crate::linalg::{Basis, MAX_N, V4, axpy, cholesky, cholesky_solve, dot_first, dot4, norm4, unit};

/// Relative size below which a vector is linearly dependent on a working set (Gram-Schmidt residual).
const RANK_TOL: f64 = 1e-12;
/// A constraint blocks a move only if its normal has at least this component along the unit move direction.
/// Larger than [`RANK_TOL`], so a blocking constraint is always independent of the working set.
const BLOCK_TOL: f64 = 1e-11;
/// A direction of the null space whose curved components are below this is flat (curvature below 1e-16 relative).
const FLAT_TOL: f64 = 1e-8;
/// A tie-break direction is followed only if its projection on the flat subspace exceeds this.
const TIE_TOL: f64 = 1e-9;
/// Relative tolerance of multipliers.
pub(crate) const MULT_TOL: f64 = 1e-10;
/// The strictly convex fast path runs only when `min h / max h` is at least this (cost (1): `0.002 < w < 0.9995`).
/// A nearly flat direction makes the minimiser ill-determined within the multiplier tolerance (with
/// `min h / max h = 1e-9` the two methods' points differ by millimetres, both KKT points within tolerance); those
/// problems keep the general method's answer.
pub(crate) const FAST_PATH_MIN_CURVATURE_RATIO: f64 = 1e-3;

/// Anti-cycling bookkeeping after a move of length `moved` blocked by `blocking`: a real move (longer than 1e-13 of
/// the length scale) clears the banned constraints; a null move blocked by the constraint just dropped bans that
/// constraint (dropping and re-adding it would cycle). The last drop is forgotten either way.
#[inline]
pub(crate) fn record_move(
    moved: f64,
    length_scale: f64,
    blocking: Option<usize>,
    last_dropped: &mut Option<usize>,
    banned: &mut Vec<usize>,
) {
    if moved > 1e-13 * length_scale {
        banned.clear();
    } else if blocking.is_some() && blocking == *last_dropped {
        banned.extend(blocking);
    }
    *last_dropped = None;
}

/// The working set: indices of constraints, in the order they joined.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct WorkSet {
    pub(crate) idx: [usize; MAX_N],
    pub(crate) len: usize,
}

impl WorkSet {
    pub(crate) fn as_slice(&self) -> &[usize] {
        &self.idx[..self.len]
    }
    pub(crate) fn contains(&self, j: usize) -> bool {
        self.as_slice().contains(&j)
    }
    pub(crate) fn push(&mut self, j: usize) {
        if self.len < MAX_N {
            self.idx[self.len] = j;
            self.len += 1;
        }
    }
    pub(crate) fn remove_at(&mut self, k: usize) {
        for i in k..self.len - 1 {
            self.idx[i] = self.idx[i + 1];
        }
        self.len -= 1;
    }
}

/// The default tie-break order: lowest z, then y, then x (D = 3); lowest y then x (D = 2).
pub(crate) fn default_tie(d: usize) -> [usize; MAX_N] {
    if d == 3 { [2, 1, 0, 3] } else { [1, 0, 2, 3] }
}

/// A problem instance. Rows are constraint normals in the first `n` components (the rest zero).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Problem<'a> {
    /// Number of variables (1..=4).
    pub n: usize,
    /// Constraint normals.
    pub rows: &'a [V4],
    /// Constraint offsets: `rows[j] . p <= offsets[j]`.
    pub offsets: &'a [f64],
    /// Constraints with `mask[j] == false` are ignored.
    pub mask: Option<&'a [bool]>,
    /// Diagonal of the Hessian (>= 0).
    pub h: V4,
    /// Linear term.
    pub g: V4,
    /// Tie-break order of the coordinates (first `n` entries used).
    pub tie: [usize; MAX_N],
    /// Characteristic length of the problem (>= 1): thresholds of step lengths are relative to it.
    pub length_scale: f64,
}

/// How a solve ended.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Outcome {
    /// The lexicographic optimum with its working set and the `f`-stage multipliers (in working-set order).
    Optimal { point: V4, working: WorkSet, multipliers: V4, iterations: usize },
    /// A ray along which the objective (stage 0) or a tie-break coordinate (stage k >= 1) decreases without bound.
    Unbounded { point: V4, stage: usize },
}

/// How [`Problem::seek`] ended.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Seek {
    /// A feasible point with `g . p <= target`.
    Reached(V4),
    /// The minimum of `g . p` over the feasible set is above the target.
    Minimum {
        /// The minimiser.
        point: V4,
        /// `g . point`.
        value: f64,
    },
}

/// The solver gave up.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum ActiveSetError {
    /// The iteration limit was reached (cycling or a numerical breakdown).
    #[error("active-set iteration limit {limit} reached")]
    IterationLimit {
        /// The limit.
        limit: usize,
    },
}

/// The null space of the working set, split into flat and curved parts.
struct Subspace {
    flat: Basis,
    curved: Basis,
    /// Cholesky factor of `M_C = C^T H C`.
    chol: [[f64; MAX_N]; MAX_N],
}

impl Subspace {
    fn new(prob: &Problem<'_>, w: &WorkSet) -> Self {
        Self::build(prob, &Self::row_basis(prob, w), true)
    }

    /// The orthonormal basis of the working rows: Gram-Schmidt in working-set order (a row dependent on the earlier
    /// ones is skipped). Adding a row to the working set extends it by one `try_add` of that row, bit for bit.
    fn row_basis(prob: &Problem<'_>, w: &WorkSet) -> Basis {
        let mut rows = Basis::new();
        for &j in w.as_slice() {
            rows.try_add(&prob.rows[j], RANK_TOL);
        }
        rows
    }

    /// The split of the null space of the working rows (`rows`: their [`Subspace::row_basis`]); `lp_shortcut`: take
    /// the bit-identical shortcut for a linear objective (`false` only in the test that checks it).
    fn build(prob: &Problem<'_>, rows: &Basis, lp_shortcut: bool) -> Self {
        let n = prob.n;
        let null = if rows.len == 0 {
            let mut id = Basis::new();
            for i in 0..n {
                id.v[i] = unit(i);
            }
            id.len = n;
            id
        } else {
            rows.complement(n)
        };
        let r = null.len;
        if (0..n).all(|i| prob.h[i] > 0.0) {
            // strictly convex: no flat directions, the whole null space is curved
            return Self::with_bases(prob, Basis::new(), null);
        }
        if lp_shortcut && (0..n).all(|i| prob.h[i] == 0.0) {
            // a linear objective (every LP of the crate): no curved coordinate, the whole null space is flat. The
            // general construction below would take the complement of an empty basis in t-space (the identity) and
            // lift it, `0 + 1 * v_k` plus zero products: `v_k` itself except that a `-0.0` becomes `+0.0`. This is
            // that result, bit for bit, without the Gram-Schmidt work.
            let mut flat = null;
            for v in &mut flat.v[..flat.len] {
                *v = v.map(|c| c + 0.0);
            }
            return Self { flat, curved: Basis::new(), chol: [[0.0; MAX_N]; MAX_N] };
        }
        // rows of the null-space basis matrix restricted to the curved coordinates, in t-space
        let mut curved_t = Basis::new();
        for i in 0..n {
            if prob.h[i] > 0.0 {
                let mut b = [0.0; MAX_N];
                for (k, v) in null.vectors().iter().enumerate() {
                    b[k] = v[i];
                }
                if norm4(&b) > FLAT_TOL {
                    curved_t.try_add(&b, FLAT_TOL);
                }
            }
        }
        let flat_t = curved_t.complement(r);
        let lift = |t: &V4| {
            let mut x = [0.0; MAX_N];
            for (k, v) in null.vectors().iter().enumerate() {
                axpy(&mut x, t[k], v);
            }
            x
        };
        let mut flat = Basis::new();
        for t in flat_t.vectors() {
            flat.v[flat.len] = lift(t);
            flat.len += 1;
        }
        let mut curved = Basis::new();
        for t in curved_t.vectors() {
            curved.v[curved.len] = lift(t);
            curved.len += 1;
        }
        Self::with_bases(prob, flat, curved)
    }

    fn with_bases(prob: &Problem<'_>, flat: Basis, curved: Basis) -> Self {
        let n = prob.n;
        let mut chol = [[0.0; MAX_N]; MAX_N];
        for a in 0..curved.len {
            for b in 0..=a {
                let mut s = 0.0;
                for i in 0..n {
                    s += prob.h[i] * curved.v[a][i] * curved.v[b][i];
                }
                chol[a][b] = s;
            }
        }
        cholesky(&mut chol, curved.len);
        Self { flat, curved, chol }
    }

    /// `-P_F x`: minus the projection on the flat subspace.
    fn flat_descent(&self, x: &V4) -> V4 {
        let mut d = [0.0; MAX_N];
        for f in self.flat.vectors() {
            axpy(&mut d, -dot4(x, f), f);
        }
        d
    }

    /// The Newton step `-C M_C^{-1} C^T x` of a gradient `x`.
    fn newton(&self, x: &V4) -> V4 {
        let k = self.curved.len;
        let mut rhs = [0.0; MAX_N];
        for (a, c) in self.curved.vectors().iter().enumerate() {
            rhs[a] = -dot4(x, c);
        }
        let t = cholesky_solve(&self.chol, k, &rhs);
        let mut s = [0.0; MAX_N];
        for (a, c) in self.curved.vectors().iter().enumerate() {
            axpy(&mut s, t[a], c);
        }
        s
    }
}

enum Step {
    Move { dir: V4, bounded: bool, stage: usize },
    Stationary,
}

impl Problem<'_> {
    #[inline]
    pub(crate) fn enabled(&self, j: usize) -> bool {
        self.mask.is_none_or(|m| m[j])
    }

    pub(crate) fn gradient(&self, p: &V4) -> V4 {
        let mut gr = [0.0; MAX_N];
        for i in 0..self.n {
            gr[i] = self.h[i] * p[i] + self.g[i];
        }
        gr
    }

    /// Typical size of the gradient over the problem's region (for relative thresholds).
    pub(crate) fn gradient_scale(&self) -> f64 {
        let mut s: f64 = 0.0;
        for i in 0..self.n {
            s = s.max(self.h[i] * self.length_scale + self.g[i].abs());
        }
        s.max(f64::MIN_POSITIVE)
    }

    fn step(&self, sub: &Subspace, p: &V4) -> Step {
        let grad = self.gradient(p);
        let ray = sub.flat_descent(&grad);
        if norm4(&ray) > 1e-10 * self.gradient_scale() {
            return Step::Move { dir: ray, bounded: false, stage: 0 };
        }
        let s = sub.newton(&grad);
        if norm4(&s) > 1e-12 * self.length_scale {
            return Step::Move { dir: s, bounded: true, stage: 0 };
        }
        for k in 0..self.n {
            let ray = sub.flat_descent(&unit(self.tie[k]));
            if norm4(&ray) > TIE_TOL {
                return Step::Move { dir: ray, bounded: false, stage: k + 1 };
            }
        }
        Step::Stationary
    }

    /// Lexicographic multipliers of the working set: `mult[stage][k]` for the k-th working constraint.
    /// Returns the index (into the working set) of the constraint to drop, if any, and the stage-0 multipliers.
    fn drop_choice(&self, sub: &Subspace, w: &WorkSet, p: &V4, bland: bool, banned: &[usize]) -> (Option<usize>, V4) {
        self.drop_choice_to(sub, w, p, bland, banned, self.n)
    }

    /// [`Problem::drop_choice`] considering the stages `0..=last_stage` only.
    fn drop_choice_to(
        &self,
        sub: &Subspace,
        w: &WorkSet,
        p: &V4,
        bland: bool,
        banned: &[usize],
        last_stage: usize,
    ) -> (Option<usize>, V4) {
        let k = w.len;
        let mut lambda0 = [0.0; MAX_N];
        if k == 0 {
            return (None, lambda0);
        }
        let mut gram = [[0.0; MAX_N]; MAX_N];
        for a in 0..k {
            for b in 0..=a {
                gram[a][b] = dot4(&self.rows[w.idx[a]], &self.rows[w.idx[b]]);
            }
        }
        cholesky(&mut gram, k);
        let mut undecided = [true; MAX_N];
        for a in 0..k {
            undecided[a] = !banned.contains(&w.idx[a]);
        }
        for stage in 0..=last_stage {
            let gvec = if stage == 0 { self.gradient(p) } else { unit(self.tie[stage - 1]) };
            let sc = sub.newton(&gvec);
            let mut r = gvec;
            for i in 0..self.n {
                r[i] += self.h[i] * sc[i];
            }
            let mut rhs = [0.0; MAX_N];
            for a in 0..k {
                rhs[a] = -dot4(&self.rows[w.idx[a]], &r);
            }
            let mu = cholesky_solve(&gram, k, &rhs);
            if stage == 0 {
                lambda0 = mu;
            }
            let tol = MULT_TOL * if stage == 0 { self.gradient_scale() } else { 1.0 };
            let mut choice: Option<usize> = None;
            for a in 0..k {
                if undecided[a] && mu[a] < -tol {
                    choice = match choice {
                        None => Some(a),
                        Some(c) => {
                            let better = if bland { w.idx[a] < w.idx[c] } else { mu[a] < mu[c] };
                            Some(if better { a } else { c })
                        }
                    };
                }
            }
            if choice.is_some() {
                return (choice, lambda0);
            }
            let mut any = false;
            for a in 0..k {
                if undecided[a] && mu[a].abs() > tol {
                    undecided[a] = false;
                }
                any |= undecided[a];
            }
            if !any {
                break;
            }
        }
        (None, lambda0)
    }

    /// The ratio test of a move `p + t dir` (`len = |dir|`, `t <= alpha0`): the first enabled constraint outside the
    /// working set that blocks it (normal component along the unit direction above `BLOCK_TOL`; slack clamped at
    /// zero, so a constraint violated by rounding blocks at once) and the step length. O(m); the cheap component test
    /// comes first, the mask and working-set tests only for the rows that pass it.
    ///
    /// The component `a . dir` is summed over the first `n` lanes only ([`dot_first`]): the rows are zero beyond
    /// them, so the remaining terms are zeros, which change a non-zero sum not at all, and a zero sum never passes
    /// the test (`BLOCK_TOL * len >= 0`); the outcome is the one of the full [`dot4`], bit for bit.
    #[inline]
    pub(crate) fn ratio_test(&self, w: &WorkSet, p: &V4, dir: &V4, len: f64, alpha0: f64) -> (f64, Option<usize>) {
        match self.n {
            2 => self.ratio_test_in::<2>(w, p, dir, len, alpha0),
            3 => self.ratio_test_in::<3>(w, p, dir, len, alpha0),
            _ => self.ratio_test_in::<MAX_N>(w, p, dir, len, alpha0),
        }
    }

    /// [`Problem::ratio_test`] with the components over the first `K` lanes.
    #[inline]
    fn ratio_test_in<const K: usize>(
        &self,
        w: &WorkSet,
        p: &V4,
        dir: &V4,
        len: f64,
        alpha0: f64,
    ) -> (f64, Option<usize>) {
        let threshold = BLOCK_TOL * len;
        let mut alpha = alpha0;
        let mut blocking = None;
        for (j, a) in self.rows.iter().enumerate() {
            let ad = dot_first::<K>(a, dir);
            if ad > threshold && self.enabled(j) && !w.contains(j) {
                let slack = (self.offsets[j] - dot4(a, p)).max(0.0);
                let t = slack / ad;
                if t < alpha {
                    alpha = t;
                    blocking = Some(j);
                }
            }
        }
        (alpha, blocking)
    }

    /// Phase 1 towards one more constraint: the LP `min g . p` (with `h = 0`, no tie-break) run from `start`
    /// (feasible for the enabled constraints, or infeasible only by rounding) and stopped as soon as
    /// `g . p <= target`: on the move that crosses the level the point stops exactly there. Returns
    /// [`Seek::Reached`] with that point, or [`Seek::Minimum`] with the LP's optimum when the level is never reached.
    /// The same iterations as [`Problem::solve`] (O(m) each), usually far fewer: the first move often crosses.
    pub(crate) fn seek(&self, start: V4, target: f64) -> Result<Seek, ActiveSetError> {
        let m = self.rows.len();
        let bland_after = 4 * m + 20;
        let limit = 40 * (m + 5);
        let mut p = start;
        let mut w = WorkSet::default();
        let mut banned: Vec<usize> = Vec::new();
        let mut last_dropped: Option<usize> = None;
        for iter in 0..limit {
            let level = dot4(&self.g, &p);
            if level <= target {
                return Ok(Seek::Reached(p));
            }
            // with no working constraint the objective is linear on the whole space: the move is `-g` (what
            // `Subspace::new` and `step` give, without their Gram-Schmidt work)
            let (sub, step) = if w.len == 0 {
                (None, Step::Move { dir: self.g.map(|c| -c), bounded: false, stage: 0 })
            } else {
                let sub = Subspace::new(self, &w);
                let step = self.step(&sub, &p);
                (Some(sub), step)
            };
            match step {
                Step::Move { dir, bounded, stage: 0 } => {
                    let len = norm4(&dir);
                    let (alpha, blocking) =
                        self.ratio_test(&w, &p, &dir, len, if bounded { 1.0 } else { f64::INFINITY });
                    let descent = dot4(&self.g, &dir);
                    if descent < 0.0 {
                        let to_level = (target - level) / descent;
                        if to_level <= alpha {
                            axpy(&mut p, to_level, &dir);
                            return Ok(Seek::Reached(p));
                        }
                    }
                    if blocking.is_none() && !bounded {
                        // unblocked descent ray that never reaches the level: cannot happen (descent < 0)
                        return Ok(Seek::Reached(p));
                    }
                    axpy(&mut p, alpha, &dir);
                    record_move(alpha * len, self.length_scale, blocking, &mut last_dropped, &mut banned);
                    if let Some(j) = blocking {
                        w.push(j);
                    }
                }
                // stationary for the objective (a tie-break move or none): drop a constraint on a negative
                // objective multiplier, or stop at the minimum
                _ => {
                    let sub = sub.unwrap_or_else(|| Subspace::new(self, &w));
                    let (drop, _) = self.drop_choice_to(&sub, &w, &p, iter >= bland_after, &banned, 0);
                    match drop {
                        Some(k) => {
                            last_dropped = Some(w.idx[k]);
                            w.remove_at(k);
                        }
                        None => return Ok(Seek::Minimum { point: p, value: level }),
                    }
                }
            }
        }
        Err(ActiveSetError::IterationLimit { limit })
    }

    /// Runs the active-set method from `start` (feasible, or infeasible only by rounding).
    pub(crate) fn solve(&self, start: V4) -> Result<Outcome, ActiveSetError> {
        let m = self.rows.len();
        let bland_after = 4 * m + 20;
        let limit = 40 * (m + 5);
        let mut p = start;
        let mut w = WorkSet::default();
        // constraints dropped on a multiplier that rounding made negative: the next move is blocked at once by the
        // same constraint. They stay in the working set until the point moves.
        let mut banned: Vec<usize> = Vec::new();
        let mut last_dropped: Option<usize> = None;
        // the working rows' orthonormal basis, extended as rows join and rebuilt when one leaves
        let mut row_basis = Basis::new();
        for iter in 0..limit {
            debug_assert!(
                row_basis
                    .vectors()
                    .iter()
                    .map(|v| v.map(f64::to_bits))
                    .eq(Subspace::row_basis(self, &w).vectors().iter().map(|v| v.map(f64::to_bits))),
                "the maintained row basis is the recomputed one, bit for bit"
            );
            let sub = Subspace::build(self, &row_basis, true);
            match self.step(&sub, &p) {
                Step::Move { dir, bounded, stage } => {
                    let len = norm4(&dir);
                    let (alpha, blocking) =
                        self.ratio_test(&w, &p, &dir, len, if bounded { 1.0 } else { f64::INFINITY });
                    match blocking {
                        None if !bounded => return Ok(Outcome::Unbounded { point: p, stage }),
                        _ => {}
                    }
                    axpy(&mut p, alpha, &dir);
                    record_move(alpha * len, self.length_scale, blocking, &mut last_dropped, &mut banned);
                    if let Some(j) = blocking
                        && w.len < MAX_N
                    {
                        w.push(j);
                        row_basis.try_add(&self.rows[j], RANK_TOL);
                    }
                }
                Step::Stationary => {
                    let (drop, multipliers) = self.drop_choice(&sub, &w, &p, iter >= bland_after, &banned);
                    match drop {
                        Some(k) => {
                            last_dropped = Some(w.idx[k]);
                            w.remove_at(k);
                            row_basis = Subspace::row_basis(self, &w);
                        }
                        None => {
                            return Ok(Outcome::Optimal { point: p, working: w, multipliers, iterations: iter + 1 });
                        }
                    }
                }
            }
        }
        Err(ActiveSetError::IterationLimit { limit })
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    fn rows3(v: &[[f64; 3]]) -> Vec<V4> {
        v.iter().map(|r| [r[0], r[1], r[2], 0.0]).collect()
    }

    fn unit_box() -> (Vec<V4>, Vec<f64>) {
        let rows = rows3(&[[1., 0., 0.], [-1., 0., 0.], [0., 1., 0.], [0., -1., 0.], [0., 0., 1.], [0., 0., -1.]]);
        (rows, vec![1.0, 0.0, 1.0, 0.0, 1.0, 0.0])
    }

    fn problem<'a>(rows: &'a [V4], b: &'a [f64], h: V4, g: V4) -> Problem<'a> {
        Problem { n: 3, rows, offsets: b, mask: None, h, g, tie: [2, 1, 0, 3], length_scale: 1.0 }
    }

    fn optimal(o: Outcome) -> (V4, Vec<usize>) {
        match o {
            Outcome::Optimal { point, working, .. } => {
                let mut w = working.as_slice().to_vec();
                w.sort_unstable();
                (point, w)
            }
            Outcome::Unbounded { .. } => panic!("unexpectedly unbounded"),
        }
    }

    #[test]
    fn projection_onto_a_box_corner() {
        let (rows, b) = unit_box();
        // f = |p - (2, 2, -1)|^2 / 2 * 2
        let prob = problem(&rows, &b, [2.0, 2.0, 2.0, 0.0], [-4.0, -4.0, 2.0, 0.0]);
        let (p, w) = optimal(prob.solve([0.5, 0.5, 0.5, 0.0]).expect("solve"));
        assert!((p[0] - 1.0).abs() < 1e-14 && (p[1] - 1.0).abs() < 1e-14 && p[2].abs() < 1e-14);
        assert_eq!(w, vec![0, 2, 5]);
    }

    #[test]
    fn interior_optimum_has_empty_working_set() {
        let (rows, b) = unit_box();
        let prob = problem(&rows, &b, [1.0, 1.0, 1.0, 0.0], [-0.3, -0.4, -0.5, 0.0]);
        let (p, w) = optimal(prob.solve([0.9, 0.1, 0.2, 0.0]).expect("solve"));
        assert!((p[0] - 0.3).abs() < 1e-14 && (p[1] - 0.4).abs() < 1e-14 && (p[2] - 0.5).abs() < 1e-14);
        assert!(w.is_empty());
    }

    #[test]
    fn singular_hessian_takes_lowest_z_then_y_then_x() {
        let (rows, b) = unit_box();
        // only x is curved, optimum x = 0.25; y and z free: tie-break lowest z (0) then lowest y (0)
        let prob = problem(&rows, &b, [1.0, 0.0, 0.0, 0.0], [-0.25, 0.0, 0.0, 0.0]);
        let (p, w) = optimal(prob.solve([0.5, 0.5, 0.5, 0.0]).expect("solve"));
        assert!((p[0] - 0.25).abs() < 1e-14 && p[1].abs() < 1e-14 && p[2].abs() < 1e-14, "{p:?}");
        assert_eq!(w, vec![3, 5]);
        // zero objective: the lowest z, then y, then x of the box
        let prob = problem(&rows, &b, [0.0; 4], [0.0; 4]);
        let (p, _) = optimal(prob.solve([0.5, 0.5, 0.5, 0.0]).expect("solve"));
        assert!(p[0].abs() < 1e-14 && p[1].abs() < 1e-14 && p[2].abs() < 1e-14, "{p:?}");
    }

    #[test]
    fn lp_and_unbounded_ray() {
        let rows = rows3(&[[0., 0., -1.]]);
        let b = [0.0];
        // minimise z over z >= 0: z = 0 and then the tie-break on y runs away
        let prob = problem(&rows, &b, [0.0; 4], [0.0, 0.0, 1.0, 0.0]);
        match prob.solve([0.0, 0.0, 3.0, 0.0]).expect("solve") {
            Outcome::Unbounded { point, stage, .. } => {
                assert_eq!(stage, 2);
                assert!(point[2].abs() < 1e-14);
            }
            Outcome::Optimal { .. } => panic!("must be unbounded"),
        }
    }

    #[test]
    fn flat_cell_two_opposite_constraints() {
        let (mut rows, mut b) = unit_box();
        rows.extend(rows3(&[[1.0, 1.0, 0.0], [-1.0, -1.0, 0.0]]));
        b.extend([1.0, -1.0]);
        let prob = problem(&rows, &b, [2.0, 2.0, 2.0, 0.0], [0.0; 4]);
        let (p, w) = optimal(prob.solve([0.5, 0.5, 0.5, 0.0]).expect("solve"));
        assert!((p[0] - 0.5).abs() < 1e-12 && (p[1] - 0.5).abs() < 1e-12 && p[2].abs() < 1e-14, "{p:?}");
        assert!(w.contains(&6) ^ w.contains(&7));
    }

    /// A random bounded problem around a centre `c` (inside): a box, cuts, and by `kind` duplicate rows, a flat pair
    /// (a face), or an apex where 4-5 planes meet, with a random strictly convex diagonal Hessian.
    /// The ratio test over the first `n` lanes blocks at the same constraint with the same step, bit for bit, as
    /// the same test over all four lanes (the definition), on random problems in 2, 3 and 4 variables, from points
    /// inside and on the boundary, along directions whose unused lanes are `+0` or `-0` (as `-g` makes them), with
    /// and without working constraints and masks.
    #[test]
    fn ratio_test_over_the_used_lanes_is_the_full_one() {
        let reference = |prob: &Problem<'_>, w: &WorkSet, p: &V4, dir: &V4, len: f64, alpha0: f64| {
            let threshold = BLOCK_TOL * len;
            let (mut alpha, mut blocking) = (alpha0, None);
            for (j, a) in prob.rows.iter().enumerate() {
                let ad = dot4(a, dir);
                if ad > threshold && prob.enabled(j) && !w.contains(j) {
                    let t = (prob.offsets[j] - dot4(a, p)).max(0.0) / ad;
                    if t < alpha {
                        alpha = t;
                        blocking = Some(j);
                    }
                }
            }
            (alpha, blocking)
        };
        let mut state = 3u64;
        let mut next = move || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 11) as f64) / ((1u64 << 53) as f64)
        };
        let mut blocked = 0;
        for seed in 0..600u64 {
            let n = 2 + (seed % 3) as usize;
            let (rows, b, _, _, c) = random_problem(seed, n, (seed / 3) as u8, 2 + (seed % 5) as usize);
            let mask: Vec<bool> = (0..rows.len()).map(|j| !(j + seed as usize).is_multiple_of(4)).collect();
            let mut prob = problem(&rows, &b, [0.0; MAX_N], [0.0; MAX_N]);
            prob.n = n;
            prob.mask = seed.is_multiple_of(2).then_some(&mask[..]);
            let mut w = WorkSet::default();
            if seed % 3 == 1 {
                w.push((seed as usize) % rows.len());
            }
            // the centre, or a point on the first row's boundary
            let mut p = c;
            if seed % 4 == 2 {
                let t = b[0] - dot4(&rows[0], &p);
                axpy(&mut p, t, &rows[0]);
            }
            let mut dir = [if seed.is_multiple_of(5) { -0.0 } else { 0.0 }; MAX_N];
            for x in dir.iter_mut().take(n) {
                *x = 2.0 * next() - 1.0;
            }
            if seed.is_multiple_of(7) {
                dir[0] = 0.0;
            }
            let len = norm4(&dir);
            for alpha0 in [1.0, f64::INFINITY] {
                let (a, j) = prob.ratio_test(&w, &p, &dir, len, alpha0);
                let (ra, rj) = reference(&prob, &w, &p, &dir, len, alpha0);
                assert_eq!((a.to_bits(), j), (ra.to_bits(), rj), "seed {seed}");
                blocked += usize::from(j.is_some());
            }
        }
        assert!(blocked > 600, "{blocked}");
    }

    pub(crate) fn random_problem(seed: u64, n: usize, kind: u8, cuts: usize) -> (Vec<V4>, Vec<f64>, V4, V4, V4) {
        let mut state = seed;
        let mut next = move || {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        };
        let unit_row = |next: &mut dyn FnMut() -> f64| loop {
            let mut v = [0.0; MAX_N];
            for x in v.iter_mut().take(n) {
                *x = 2.0 * next() - 1.0;
            }
            let l = norm4(&v);
            if l > 0.2 && l <= 1.0 {
                return v.map(|x| x / l);
            }
        };
        let mut c = [0.0; MAX_N];
        for x in c.iter_mut().take(n) {
            *x = 10.0 * next() - 5.0;
        }
        let (mut rows, mut b) = (Vec::new(), Vec::new());
        for i in 0..n {
            rows.push(unit(i));
            b.push(c[i] + 1.0 + 5.0 * next());
            rows.push(unit(i).map(|x| -x));
            b.push(-c[i] + 1.0 + 5.0 * next());
        }
        for _ in 0..cuts {
            let a = unit_row(&mut next);
            b.push(dot4(&a, &c) + 0.3 + 3.0 * next());
            rows.push(a);
        }
        match kind % 4 {
            1 => {
                let j = (next() * rows.len() as f64) as usize % rows.len();
                rows.push(rows[j]);
                b.push(b[j]);
            }
            2 => {
                let a = unit_row(&mut next);
                rows.push(a);
                b.push(dot4(&a, &c));
                rows.push(a.map(|x| -x));
                b.push(-dot4(&a, &c));
            }
            3 => {
                // planes through q = c + 0.5 (1, ..) whose normals surround the axis (1, 1, ..)/sqrt(n)
                let mut q = c;
                for x in q.iter_mut().take(n) {
                    *x += 0.5;
                }
                for k in 0..(2 + n) {
                    let mut a = [0.0; MAX_N];
                    for i in 0..n {
                        a[i] = 1.0 + 0.9 * ((k * 7 + i * 3) as f64 * 1.3).sin();
                    }
                    let a = a.map(|x| x / norm4(&a));
                    rows.push(a);
                    b.push(dot4(&a, &q));
                }
            }
            _ => {}
        }
        let mut h = [0.0; MAX_N];
        let mut g = [0.0; MAX_N];
        for i in 0..n {
            h[i] = 10f64.powf(3.5 * next() - 2.0);
            g[i] = 60.0 * next() - 30.0;
        }
        (rows, b, h, g, c)
    }

    proptest::proptest! {
        /// The linear-objective shortcut of `Subspace::new` gives the general construction's bases bit for bit, for
        /// working sets of 0..=n rows (random, duplicate, opposite and nearly parallel rows), in 2, 3 and 4
        /// variables (the Chebyshev LP has 4).
        #[test]
        fn lp_subspace_shortcut_is_bit_identical(
            seed in proptest::prelude::any::<u64>(), n in 2usize..5, kind in 0u8..4, k in 0usize..5,
        ) {
            let (mut rows, b, _, g, _) = random_problem(seed, n, kind, 6);
            // a row nearly parallel to the first cut, and exact zeros of both signs
            let mut near = rows[2 * n];
            near[0] += 1e-9;
            rows.push(near);
            let mut signed = rows[0].map(|c| if c == 0.0 { -0.0 } else { c });
            signed[n - 1] = -0.0;
            rows.push(signed);
            let offsets: Vec<f64> = b.iter().copied().chain([0.0, 0.0]).collect();
            let prob = Problem { n, rows: &rows, offsets: &offsets, mask: None, h: [0.0; MAX_N], g, tie: [2, 1, 0, 3], length_scale: 1.0 };
            let mut w = WorkSet::default();
            let mut pick = seed;
            for _ in 0..k.min(n) {
                pick = pick.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
                let j = (pick >> 33) as usize % rows.len();
                if !w.contains(j) {
                    w.push(j);
                }
            }
            let rows_basis = Subspace::row_basis(&prob, &w);
            let fast = Subspace::build(&prob, &rows_basis, true);
            let general = Subspace::build(&prob, &rows_basis, false);
            let bits = |b: &Basis| b.vectors().iter().map(|v| v.map(f64::to_bits)).collect::<Vec<_>>();
            proptest::prop_assert_eq!(bits(&fast.flat), bits(&general.flat));
            proptest::prop_assert_eq!(bits(&fast.curved), bits(&general.curved));
            let chol_bits = |s: &Subspace| s.chol.map(|r| r.map(f64::to_bits));
            proptest::prop_assert_eq!(chol_bits(&fast), chol_bits(&general));
        }
    }
}
