//! The placement QP over a small cell by enumeration of its faces: the last resort of [`crate::qp::minimize`] on
//! degenerate cells, where the active-set iteration divides by the sine of the angle between nearly opposite planes.
//! O(C(m, <= D) D^3) for `m <= 16` inequalities.

use crate::cell::Cell;
use crate::cost::SeparableCost;
use crate::halfspace::Halfspace;
use crate::kkt::verify_kkt_dual;
use crate::linalg::{MAX_N, cholesky, cholesky_solve};
use crate::solution::{QpSolution, ShortList, tight_set};

/// A candidate of [`minimize_enumerated`]: cost, point, subset and multipliers.
type Candidate<const D: usize> = (f64, [f64; D], Vec<usize>, Vec<f64>);

/// The most inequalities [`minimize_enumerated`] takes (C(16, <= 3) = 697 systems).
const ENUMERATE_MAX: usize = 16;

/// The minimum of a convex separable `cost` over a small `cell` by enumeration, the last resort of [`crate::qp::minimize`] on
/// degenerate cells: for every set `S` of at most `D` inequalities, the minimiser of the cost on
/// `a_j . p = b_j (j in S)` by the null-space method ([`equality_qp`]); the cheapest
/// that satisfies every inequality within the tolerance is the optimum (a convex QP's minimiser is the minimiser on
/// the affine hull of the face it lies in, and that face is cut out by at most `D` of its tight inequalities). Its
/// multipliers are those of its system when they pass the KKT check, else none (the caller's certificate is then
/// the gradient alone). Unlike the active-set iteration this never divides by the sine of the angle between two
/// nearly opposite planes to choose a step: an ill-conditioned system costs accuracy in its own multipliers only.
///
/// **Singular Hessians** (`w = 0` or `w = 1` in cost (1), some `h_i = 0`): the minimisers form a face, and the
/// answer is its lexicographic minimum, lowest `p_{D-1}` first (z, then y, then x), as [`crate::qp::minimize`]'s. That point is
/// among the candidates: take for `S` a basis of the inequalities tight there; a direction of `S`'s affine hull along
/// which the cost were flat would lead, both ways, to other minimisers (the inequalities not in `S` are slack or
/// constant on the hull), one of them lexicographically lower. So the cost is strictly convex on that hull and its
/// minimiser there is the point. Two candidates are ties when their curved coordinates (`h_i > 0`; every minimiser
/// has the same) agree within `1e-9` of the cell's length scale and their costs differ by no more than moving that
/// far changes them; the lexicographically lowest of the ties is taken. Otherwise the cheaper wins, by the cost
/// difference computed from the two points (near an interior minimum the difference is second order in their
/// distance, and the values' constant terms would round it away).
///
/// `None`: more than [`ENUMERATE_MAX`] inequalities, or no feasible candidate. O(C(m, <= D) D^3).
pub(crate) fn minimize_enumerated<const D: usize>(cell: &Cell<D>, cost: &SeparableCost<D>) -> Option<QpSolution<D>> {
    let (h, g) = (cost.hessian_diagonal(), cost.linear());
    let m = cell.len();
    if m > ENUMERATE_MAX {
        return None;
    }
    let hs = cell.halfspaces();
    let tol = cell.tolerance().linear;
    let scale = cell.length_scale();
    // coordinates within `same` compare equal; two candidates whose curved coordinates (h_i > 0) are equal so and
    // whose costs differ by at most what moving by `same` changes are ties (minimisers of a flat cost); the cost
    // difference is computed from the two points, f(p) - f(q) = sum (p_i - q_i) (h_i (p_i + q_i) / 2 + g_i), not from
    // the two values, whose constant terms would round it away near the minimum (where it is second order in the
    // distance)
    let same = 1e-9 * scale;
    let tie = same * (0..D).map(|i| h[i] * scale + g[i].abs()).sum::<f64>();
    let difference =
        |p: &[f64; D], q: &[f64; D]| (0..D).map(|i| (p[i] - q[i]) * (0.5 * h[i] * (p[i] + q[i]) + g[i])).sum::<f64>();
    // lexicographically lower: the last coordinate first (z, then y, then x)
    let lower = |a: &[f64; D], b: &[f64; D]| {
        for i in (0..D).rev() {
            if a[i] < b[i] - same {
                return true;
            }
            if a[i] > b[i] + same {
                return false;
            }
        }
        false
    };
    // (cost, point, subset, multipliers)
    let mut best: Option<Candidate<D>> = None;
    let mut subset: Vec<usize> = Vec::with_capacity(D);
    // every subset of at most D inequalities, in lexicographic order (an odometer over sorted index lists)
    loop {
        if let Some((p, lambda)) = equality_qp(hs, &h, &g, &subset) {
            let feasible = hs.iter().all(|x| x.excess(&p) <= tol);
            let value = cost.evaluate(&p);
            let better = |b: &Candidate<D>| {
                let d = difference(&p, &b.1);
                let close = (0..D).all(|i| h[i] == 0.0 || (p[i] - b.1[i]).abs() <= same);
                if close && d.abs() <= tie { lower(&p, &b.1) } else { d < 0.0 }
            };
            if feasible && value.is_finite() && best.as_ref().is_none_or(better) {
                best = Some((value, p, subset.clone(), lambda));
            }
        }
        // next subset: extend, else advance the last index, else drop it and advance the one before
        if subset.len() < D && subset.last().map_or(0, |&j| j + 1) < m {
            subset.push(subset.last().map_or(0, |&j| j + 1));
            continue;
        }
        loop {
            match subset.pop() {
                None => break,
                Some(j) if j + 1 < m => {
                    subset.push(j + 1);
                    break;
                }
                Some(_) => {}
            }
        }
        if subset.is_empty() {
            break;
        }
    }
    let (value, point, active, lambda) = best?;
    let mut order: Vec<usize> = (0..active.len()).collect();
    order.sort_by_key(|&k| active[k]);
    let active: Vec<usize> = order.iter().map(|&k| active[k]).collect();
    let lambda: Vec<f64> = order.iter().map(|&k| lambda[k]).collect();
    let mut sol = QpSolution {
        point,
        cost: value,
        active: ShortList::from_slice(&active),
        multipliers: ShortList::from_slice(&lambda),
        tight: tight_set(cell, &point),
        iterations: 0,
    };
    if verify_kkt_dual(cell, &h, &g, &sol).is_err() {
        sol.multipliers = ShortList::default();
        sol.active = ShortList::default();
    }
    Some(sol)
}

/// The minimiser of `1/2 sum h_i p_i^2 + g . p` on `a_j . p = b_j (j in subset)` and its multipliers, by the
/// null-space method: the subset's normals orthonormalised by modified Gram-Schmidt (`a_j = sum_{i <= j} r_ji q_i`;
/// a normal whose residual is below 1e-12 of its length is dependent: `None`, the face is another subset's), the
/// point `Q^T c` with `R c = b` on the constraints, the basis `Z` of their orthogonal complement completed from the
/// axes, and the reduced system `Z^T H Z y = -Z^T (H p0 + g)` (the active set's Cholesky factor); the multipliers
/// from `R^T lambda = -Q (H p + g)`.
/// Nearly opposite normals (1e-9 rad) are independent here and give an accurate point: only the multipliers, which
/// divide by the small residual, lose accuracy. `None` also when a result is not finite.
fn equality_qp<const D: usize>(
    hs: &[Halfspace<D>],
    h: &[f64; D],
    g: &[f64; D],
    subset: &[usize],
) -> Option<([f64; D], Vec<f64>)> {
    let k = subset.len();
    let dot = |a: &[f64; D], b: &[f64; D]| (0..D).map(|i| a[i] * b[i]).sum::<f64>();
    // orthonormal rows q and the lower-triangular r with a_j = sum_i r[j][i] q_i
    let mut q = [[0.0f64; D]; D];
    let mut r = [[0.0f64; D]; D];
    for (j, &row) in subset.iter().enumerate() {
        let mut v = hs[row].normal;
        let length = dot(&v, &v).sqrt();
        for i in 0..j {
            let c = dot(&v, &q[i]);
            r[j][i] = c;
            for t in 0..D {
                v[t] -= c * q[i][t];
            }
        }
        let rest = dot(&v, &v).sqrt();
        if rest.is_nan() || rest <= 1e-12 * length {
            return None;
        }
        r[j][j] = rest;
        q[j] = v.map(|x| x / rest);
    }
    // c from R c = b (forward substitution), p0 = Q^T c
    let mut c = [0.0f64; D];
    for j in 0..k {
        let tail: f64 = (0..j).map(|i| r[j][i] * c[i]).sum();
        c[j] = (hs[subset[j]].offset - tail) / r[j][j];
    }
    let mut p = [0.0f64; D];
    for j in 0..k {
        for t in 0..D {
            p[t] += c[j] * q[j][t];
        }
    }
    // Z: the axes orthogonalised against Q (and each other), the D - k longest residuals
    let mut basis: Vec<[f64; D]> = q[..k].to_vec();
    let mut z: Vec<[f64; D]> = Vec::new();
    for axis in 0..D {
        if basis.len() == D {
            break;
        }
        let mut v = [0.0f64; D];
        v[axis] = 1.0;
        for b in &basis {
            let c = dot(&v, b);
            for t in 0..D {
                v[t] -= c * b[t];
            }
        }
        let n = dot(&v, &v).sqrt();
        if n > 1e-6 {
            let v = v.map(|x| x / n);
            basis.push(v);
            z.push(v);
        }
    }
    if k + z.len() != D {
        return None;
    }
    // the reduced system over y: (Z^T H Z) y = -Z^T (H p0 + g), positive definite for a strictly convex cost; where
    // the cost is flat along a direction of the hull, `cholesky` clamps the pivot, and the point is some point of the
    // hull (the gradient has no component along a direction flat as in cost (1)) or one far outside the cell or not
    // finite (a linear cost): the caller keeps only feasible candidates and compares their costs
    let nz = z.len();
    let mut m = [[0.0f64; MAX_N]; MAX_N];
    let mut rhs = [0.0f64; MAX_N];
    for a in 0..nz {
        for b in 0..nz {
            m[a][b] = (0..D).map(|t| z[a][t] * h[t] * z[b][t]).sum();
        }
        rhs[a] = -(0..D).map(|t| z[a][t] * (h[t] * p[t] + g[t])).sum::<f64>();
    }
    cholesky(&mut m, nz);
    let y = cholesky_solve(&m, nz, &rhs);
    for a in 0..nz {
        for t in 0..D {
            p[t] += y[a] * z[a][t];
        }
    }
    // multipliers: R^T lambda = -Q grad (back substitution, R^T upper-triangular)
    let grad: [f64; D] = std::array::from_fn(|t| h[t] * p[t] + g[t]);
    let mut lambda = vec![0.0f64; k];
    for j in (0..k).rev() {
        let tail: f64 = (j + 1..k).map(|i| r[i][j] * lambda[i]).sum();
        lambda[j] = (-dot(&q[j], &grad) - tail) / r[j][j];
    }
    (p.iter().all(|v| v.is_finite()) && lambda.iter().all(|v| v.is_finite())).then_some((p, lambda))
}
