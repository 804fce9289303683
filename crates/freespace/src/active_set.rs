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

/// Largest number of variables.
pub(crate) const MAX_N: usize = 4;

/// A vector in up to four variables; unused components are zero.
pub(crate) type V4 = [f64; MAX_N];

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
const MULT_TOL: f64 = 1e-10;
/// The strictly convex fast path runs only when `min h / max h` is at least this (cost (1): `0.002 < w < 0.9995`).
/// A nearly flat direction makes the minimiser ill-determined within the multiplier tolerance (with
/// `min h / max h = 1e-9` the two methods' points differ by millimetres, both KKT points within tolerance); those
/// problems keep the general method's answer.
pub(crate) const FAST_PATH_MIN_CURVATURE_RATIO: f64 = 1e-3;

#[inline]
pub(crate) fn dot4(a: &V4, b: &V4) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
}

/// `a . b` over the first `K` lanes, summed in the order of [`dot4`] (which is `dot_first::<4>`).
#[inline]
pub(crate) fn dot_first<const K: usize>(a: &V4, b: &V4) -> f64 {
    let mut s = a[0] * b[0];
    for i in 1..K {
        s += a[i] * b[i];
    }
    s
}

#[inline]
fn norm4(a: &V4) -> f64 {
    dot4(a, a).sqrt()
}

#[inline]
fn unit(i: usize) -> V4 {
    let mut e = [0.0; MAX_N];
    e[i] = 1.0;
    e
}

#[inline]
fn axpy(y: &mut V4, alpha: f64, x: &V4) {
    for i in 0..MAX_N {
        y[i] += alpha * x[i];
    }
}

/// Anti-cycling bookkeeping after a move of length `moved` blocked by `blocking`: a real move (longer than 1e-13 of
/// the length scale) clears the banned constraints; a null move blocked by the constraint just dropped bans that
/// constraint (dropping and re-adding it would cycle). The last drop is forgotten either way.
#[inline]
fn record_move(
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

/// An orthonormal set of at most four vectors.
#[derive(Debug, Clone, Copy)]
struct Basis {
    v: [V4; MAX_N],
    len: usize,
}

impl Basis {
    fn new() -> Self {
        Self { v: [[0.0; MAX_N]; MAX_N], len: 0 }
    }

    fn vectors(&self) -> &[V4] {
        &self.v[..self.len]
    }

    /// The part of `x` orthogonal to the basis (two Gram-Schmidt passes).
    fn residual(&self, x: &V4) -> V4 {
        let mut w = *x;
        for _ in 0..2 {
            for q in self.vectors() {
                let c = dot4(&w, q);
                axpy(&mut w, -c, q);
            }
        }
        w
    }

    /// Adds the normalised residual of `x` if it is at least `rel_tol |x|`; returns whether it was added.
    fn try_add(&mut self, x: &V4, rel_tol: f64) -> bool {
        let n0 = norm4(x);
        if n0.is_nan() || n0 <= 0.0 || self.len == MAX_N {
            return false;
        }
        let w = self.residual(x);
        let nw = norm4(&w);
        if nw > rel_tol * n0 {
            self.v[self.len] = w.map(|c| c / nw);
            self.len += 1;
            true
        } else {
            false
        }
    }

    /// An orthonormal basis of the orthogonal complement of `self` in `R^n` (greedy: most independent unit vector).
    fn complement(&self, n: usize) -> Basis {
        let mut all = *self;
        let mut out = Basis::new();
        while all.len < n {
            let mut best = (-1.0, [0.0; MAX_N]);
            for i in 0..n {
                let w = all.residual(&unit(i));
                let r = norm4(&w);
                if r > best.0 {
                    best = (r, w);
                }
            }
            // the residual of the best unit vector is at least sqrt((n - len) / n) > 0.5
            let w = best.1.map(|c| c / best.0);
            all.v[all.len] = w;
            all.len += 1;
            out.v[out.len] = w;
            out.len += 1;
        }
        out
    }
}

/// Cholesky factorisation of a symmetric positive (semi)definite matrix of order `k <= 4`, in place (lower).
/// Pivots that rounding made non-positive are floored at a tiny positive value (the step then becomes long and the
/// ratio test cuts it).
pub(crate) fn cholesky(a: &mut [[f64; MAX_N]; MAX_N], k: usize) {
    for j in 0..k {
        let mut d = a[j][j];
        for l in 0..j {
            d -= a[j][l] * a[j][l];
        }
        let d = if d > 1e-280 { d.sqrt() } else { 1e-140 };
        a[j][j] = d;
        for i in j + 1..k {
            let mut s = a[i][j];
            for l in 0..j {
                s -= a[i][l] * a[j][l];
            }
            a[i][j] = s / d;
        }
    }
}

/// Solves `L L^T x = b` for the factor of [`cholesky`].
pub(crate) fn cholesky_solve(l: &[[f64; MAX_N]; MAX_N], k: usize, b: &V4) -> V4 {
    let mut y = [0.0; MAX_N];
    for i in 0..k {
        let mut s = b[i];
        for j in 0..i {
            s -= l[i][j] * y[j];
        }
        y[i] = s / l[i][i];
    }
    let mut x = [0.0; MAX_N];
    for i in (0..k).rev() {
        let mut s = y[i];
        for j in i + 1..k {
            s -= l[j][i] * x[j];
        }
        x[i] = s / l[i][i];
    }
    x
}

/// The working set: indices of constraints, in the order they joined.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct WorkSet {
    idx: [usize; MAX_N],
    len: usize,
}

impl WorkSet {
    pub(crate) fn as_slice(&self) -> &[usize] {
        &self.idx[..self.len]
    }
    fn contains(&self, j: usize) -> bool {
        self.as_slice().contains(&j)
    }
    fn push(&mut self, j: usize) {
        if self.len < MAX_N {
            self.idx[self.len] = j;
            self.len += 1;
        }
    }
    fn remove_at(&mut self, k: usize) {
        for i in k..self.len - 1 {
            self.idx[i] = self.idx[i + 1];
        }
        self.len -= 1;
    }
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
    fn enabled(&self, j: usize) -> bool {
        self.mask.is_none_or(|m| m[j])
    }

    fn gradient(&self, p: &V4) -> V4 {
        let mut gr = [0.0; MAX_N];
        for i in 0..self.n {
            gr[i] = self.h[i] * p[i] + self.g[i];
        }
        gr
    }

    /// Typical size of the gradient over the problem's region (for relative thresholds).
    fn gradient_scale(&self) -> f64 {
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
    fn ratio_test(&self, w: &WorkSet, p: &V4, dir: &V4, len: f64, alpha0: f64) -> (f64, Option<usize>) {
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

fn normalized(x: &V4) -> Option<V4> {
    let l = norm4(x);
    if l > 0.0 && l.is_finite() { Some(x.map(|c| c / l)) } else { None }
}

#[inline]
fn cross3(a: &V4, b: &V4) -> V4 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0], 0.0]
}

#[cfg(test)]
mod tests {
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

    fn random_problem(seed: u64, n: usize, kind: u8, cuts: usize) -> (Vec<V4>, Vec<f64>, V4, V4, V4) {
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
