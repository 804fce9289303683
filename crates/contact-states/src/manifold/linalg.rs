//! Small dense linear algebra of the manifold computations: a 6x6 Cholesky solve, the symmetric 6x6 eigen-
//! decomposition (cyclic Jacobi) and the projection onto a null space.

/// Solves the symmetric positive definite 6x6 system `a x = b` (Cholesky); `None` if not positive definite.
pub(super) fn solve_spd6(a: &[[f64; 6]; 6], b: &[f64; 6]) -> Option<[f64; 6]> {
    let mut l = [[0.0; 6]; 6];
    for i in 0..6 {
        for j in 0..=i {
            let mut s = a[i][j];
            for k in 0..j {
                s -= l[i][k] * l[j][k];
            }
            if i == j {
                if s <= 0.0 || !s.is_finite() {
                    return None;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    let mut y = [0.0; 6];
    for i in 0..6 {
        let mut s = b[i];
        for k in 0..i {
            s -= l[i][k] * y[k];
        }
        y[i] = s / l[i][i];
    }
    let mut x = [0.0; 6];
    for i in (0..6).rev() {
        let mut s = y[i];
        for k in i + 1..6 {
            s -= l[k][i] * x[k];
        }
        x[i] = s / l[i][i];
    }
    Some(x)
}

/// Eigenvalues and eigenvectors (the columns of the returned matrix) of the symmetric 6x6 matrix `a` (cyclic Jacobi
/// rotations; converges quadratically, a dozen sweeps at most for 6x6).
pub(super) fn symmetric_eigen6(mut a: [[f64; 6]; 6]) -> ([f64; 6], [[f64; 6]; 6]) {
    let mut v = [[0.0; 6]; 6];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for _ in 0..50 {
        let off: f64 = (0..6).flat_map(|p| (p + 1..6).map(move |q| (p, q))).map(|(p, q)| a[p][q] * a[p][q]).sum();
        let diag: f64 = (0..6).map(|p| a[p][p] * a[p][p]).sum();
        if off <= 1e-30 * diag || off == 0.0 {
            break;
        }
        for p in 0..6 {
            for q in p + 1..6 {
                if a[p][q] == 0.0 {
                    continue;
                }
                // the rotation that zeroes a[p][q] (Golub & Van Loan, 8.5.2)
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..6 {
                    let (akp, akq) = (a[k][p], a[k][q]);
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for k in 0..6 {
                    let (apk, aqk) = (a[p][k], a[q][k]);
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for row in v.iter_mut() {
                    let (vp, vq) = (row[p], row[q]);
                    row[p] = c * vp - s * vq;
                    row[q] = s * vp + c * vq;
                }
            }
        }
    }
    (std::array::from_fn(|i| a[i][i]), v)
}

/// The projection of `goal` onto the common null space of `rows` (each normalised) and of the unit vectors of the
/// variables in `fixed`: the part of `goal` that keeps every row's value to first order (eigenvectors of
/// `sum r r^T + sum e_j e_j^T` with eigenvalue at most `1e-9` of the largest, so nearly dependent rows are harmless).
pub(super) fn null_space_projection(goal: &[f64; 6], rows: &[[f64; 6]], fixed: &[bool; 6]) -> [f64; 6] {
    let mut a = [[0.0; 6]; 6];
    for row in rows {
        let norm = row.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm <= 0.0 || !norm.is_finite() {
            continue;
        }
        for p in 0..6 {
            for q in 0..6 {
                a[p][q] += row[p] * row[q] / (norm * norm);
            }
        }
    }
    for j in (0..6).filter(|&j| fixed[j]) {
        a[j][j] += 1.0;
    }
    let (values, vectors) = symmetric_eigen6(a);
    let largest = values.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    let mut d = [0.0; 6];
    for i in (0..6).filter(|&i| values[i].abs() <= 1e-9 * largest) {
        let along: f64 = (0..6).map(|p| vectors[p][i] * goal[p]).sum();
        for p in 0..6 {
            d[p] += along * vectors[p][i];
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eigen_decomposition_and_null_space() {
        // a symmetric matrix with a known spectrum: Q diag(0, 0, 1, 2, 3, 4) Q^T for a rotation Q in the (0, 1), (2,
        // 5) and (3, 4) planes
        let (c, s) = (0.6, 0.8);
        let mut q = [[0.0; 6]; 6];
        for (i, row) in q.iter_mut().enumerate() {
            row[i] = 1.0;
        }
        for (p, r) in [(0, 1), (2, 5), (3, 4)] {
            q[p][p] = c;
            q[r][r] = c;
            q[p][r] = -s;
            q[r][p] = s;
        }
        let diag = [0.0, 0.0, 1.0, 2.0, 3.0, 4.0];
        let a: [[f64; 6]; 6] =
            std::array::from_fn(|i| std::array::from_fn(|j| (0..6).map(|m| q[i][m] * diag[m] * q[j][m]).sum()));
        let (values, vectors) = symmetric_eigen6(a);
        let mut sorted = values;
        sorted.sort_by(f64::total_cmp);
        for (x, y) in sorted.iter().zip(diag) {
            assert!((x - y).abs() < 1e-12, "{values:?}");
        }
        for i in 0..6 {
            // A v = lambda v
            for p in 0..6 {
                let av: f64 = (0..6).map(|m| a[p][m] * vectors[m][i]).sum();
                assert!((av - values[i] * vectors[p][i]).abs() < 1e-12);
            }
        }
        // the null space of two rows and one fixed variable: what is left of the goal is orthogonal to all three
        let rows = [[1.0, 1.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 2.0, 0.0, 0.0, 0.0]];
        let mut fixed = [false; 6];
        fixed[5] = true;
        let d = null_space_projection(&[1.0, 0.0, 1.0, 1.0, 0.0, 1.0], &rows, &fixed);
        let expected = [0.5, -0.5, 0.0, 1.0, 0.0, 0.0];
        assert!(d.iter().zip(expected).all(|(x, y)| (x - y).abs() < 1e-12), "{d:?}");
    }
}
