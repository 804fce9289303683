//! The small dense linear algebra of the solvers, on vectors of at most four variables ([`V4`], unused components
//! zero): dot products, an orthonormal basis grown by two-pass Gram-Schmidt with its greedy complement, a Cholesky
//! factorisation of order <= 4, cross products, and the conversion of `D`-vectors (`D` = 2 or 3) to and from [`V4`].
//! Every operation is O(1) (at most 4 x 4). A leaf module: it imports nothing from the crate.

/// Largest number of variables.
pub(crate) const MAX_N: usize = 4;

/// A vector in up to four variables; unused components are zero.
pub(crate) type V4 = [f64; MAX_N];

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
pub(crate) fn norm4(a: &V4) -> f64 {
    dot4(a, a).sqrt()
}

#[inline]
pub(crate) fn unit(i: usize) -> V4 {
    let mut e = [0.0; MAX_N];
    e[i] = 1.0;
    e
}

#[inline]
pub(crate) fn axpy(y: &mut V4, alpha: f64, x: &V4) {
    for i in 0..MAX_N {
        y[i] += alpha * x[i];
    }
}

/// An orthonormal set of at most four vectors.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Basis {
    pub(crate) v: [V4; MAX_N],
    pub(crate) len: usize,
}

impl Basis {
    pub(crate) fn new() -> Self {
        Self { v: [[0.0; MAX_N]; MAX_N], len: 0 }
    }

    pub(crate) fn vectors(&self) -> &[V4] {
        &self.v[..self.len]
    }

    /// The part of `x` orthogonal to the basis (two Gram-Schmidt passes).
    pub(crate) fn residual(&self, x: &V4) -> V4 {
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
    pub(crate) fn try_add(&mut self, x: &V4, rel_tol: f64) -> bool {
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
    pub(crate) fn complement(&self, n: usize) -> Basis {
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

pub(crate) fn normalized(x: &V4) -> Option<V4> {
    let l = norm4(x);
    if l > 0.0 && l.is_finite() { Some(x.map(|c| c / l)) } else { None }
}

#[inline]
pub(crate) fn cross3(a: &V4, b: &V4) -> V4 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0], 0.0]
}

#[inline]
pub(crate) fn to_v4<const D: usize>(x: &[f64; D]) -> V4 {
    let mut v = [0.0; MAX_N];
    v[..D].copy_from_slice(x);
    v
}

#[inline]
pub(crate) fn from_v4<const D: usize>(x: &V4) -> [f64; D] {
    let mut v = [0.0; D];
    v.copy_from_slice(&x[..D]);
    v
}
