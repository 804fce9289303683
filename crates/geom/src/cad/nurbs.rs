//! Non-uniform rational B-spline curves and surfaces: validation of their knots, poles and weights, and evaluation
//! of points and first derivatives.
//!
//! Reference: L. Piegl, W. Tiller, *The NURBS Book*, 2nd ed., Springer 1997: the knot span by binary search
//! (algorithm A2.1), the non-vanishing basis functions (A2.2) and their derivatives (A2.3); points of a rational
//! curve (A4.1) and surface (A4.3) as the B-spline of the weighted poles `(w P, w)` in homogeneous space, projected;
//! first derivatives of the rational forms by the quotient rule (equations 4.8 and 4.20). The entity definitions are
//! those of ISO 10303-42 (`B_SPLINE_CURVE_WITH_KNOTS`, `B_SPLINE_SURFACE_WITH_KNOTS` and their rational forms): knots
//! given once each with their multiplicities, `n + p + 2` knots in all (counted with multiplicity) for `n + 1` poles
//! of degree `p`; the curve is defined on `[u_p, u_{n+1}]`.
//!
//! Complexity: a span search is O(log k) for k knots; a point or a point with its first derivatives costs O(p^2) for
//! a curve of degree p and O(p^2 + q^2 + p q) for a surface of degrees (p, q).

use glam::{DVec3, DVec4};

/// Why knots, poles or weights do not make a B-spline.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NurbsError {
    /// A degree below 1.
    #[error("degree {0} is not at least 1")]
    Degree(i64),
    /// Knot values and multiplicities of different lengths.
    #[error("{values} knot values but {multiplicities} multiplicities")]
    KnotLists {
        /// Number of knot values.
        values: usize,
        /// Number of multiplicities.
        multiplicities: usize,
    },
    /// A multiplicity below 1 or above `degree + 1`.
    #[error("knot {index} has multiplicity {multiplicity}, not from 1 to {}", degree + 1)]
    Multiplicity {
        /// 0-based knot index.
        index: usize,
        /// Its multiplicity.
        multiplicity: i64,
        /// The degree.
        degree: usize,
    },
    /// Knot values that are not finite or not strictly increasing.
    #[error("knot values are not finite and strictly increasing at knot {index}")]
    KnotOrder {
        /// 0-based index of the first offending knot.
        index: usize,
    },
    /// The knot count does not match the poles and degree.
    #[error("{knots} knots (with multiplicity) for {poles} poles of degree {degree}: they need {}", poles + degree + 1)]
    KnotCount {
        /// Knots counted with multiplicity.
        knots: usize,
        /// Poles in this direction.
        poles: usize,
        /// The degree.
        degree: usize,
    },
    /// Fewer poles than `degree + 1`, or rows of different lengths.
    #[error("the control net is not a {rows} x {columns} grid of at least degree + 1 poles each way")]
    Poles {
        /// Rows found.
        rows: usize,
        /// Columns of the first row.
        columns: usize,
    },
    /// A weight list that does not match the poles, or a weight that is not positive and finite.
    #[error("weights must match the poles and be positive and finite")]
    Weights,
    /// A pole with a coordinate that is not finite.
    #[error("a pole is not finite")]
    NonFinite,
}

/// A knot vector expanded with multiplicities, with its degree.
#[derive(Debug, Clone, PartialEq)]
pub struct Knots {
    degree: usize,
    values: Vec<f64>,
}

impl Knots {
    /// Knots from distinct values and their multiplicities, for `poles` poles of degree `degree`.
    pub fn new(degree: i64, multiplicities: &[i64], values: &[f64], poles: usize) -> Result<Self, NurbsError> {
        if degree < 1 {
            return Err(NurbsError::Degree(degree));
        }
        let p = degree as usize;
        if multiplicities.len() != values.len() {
            return Err(NurbsError::KnotLists { values: values.len(), multiplicities: multiplicities.len() });
        }
        let mut expanded = Vec::new();
        for (index, (&m, &u)) in multiplicities.iter().zip(values).enumerate() {
            if m < 1 || m as usize > p + 1 {
                return Err(NurbsError::Multiplicity { index, multiplicity: m, degree: p });
            }
            if !u.is_finite() || expanded.last().is_some_and(|&last: &f64| u <= last) {
                return Err(NurbsError::KnotOrder { index });
            }
            expanded.extend(std::iter::repeat_n(u, m as usize));
            if expanded.len() > poles + p + 1 {
                break;
            }
        }
        if poles < p + 1 || expanded.len() != poles + p + 1 {
            return Err(NurbsError::KnotCount { knots: expanded.len(), poles, degree: p });
        }
        if expanded[p] >= expanded[poles] {
            // the domain [u_p, u_{n+1}] is empty: every interior span has zero length
            return Err(NurbsError::KnotOrder { index: values.len().saturating_sub(1) });
        }
        Ok(Knots { degree: p, values: expanded })
    }

    /// The degree.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// The parameter domain `[u_p, u_{n+1}]`.
    pub fn domain(&self) -> (f64, f64) {
        (self.values[self.degree], self.values[self.values.len() - 1 - self.degree])
    }

    /// The distinct knot values inside the domain, ends included.
    pub fn breaks(&self) -> Vec<f64> {
        let (a, b) = self.domain();
        let mut out: Vec<f64> = Vec::new();
        for &u in &self.values {
            if (a..=b).contains(&u) && out.last() != Some(&u) {
                out.push(u);
            }
        }
        out
    }

    /// Number of poles.
    fn poles(&self) -> usize {
        self.values.len() - self.degree - 1
    }

    /// The span `i` with `u_i <= u < u_{i+1}` (the last non-empty one at the domain's end): A2.1. `u` is clamped to
    /// the domain.
    fn span(&self, u: f64) -> usize {
        let (p, n) = (self.degree, self.poles() - 1);
        let k = &self.values;
        if u >= k[n + 1] {
            return n;
        }
        if u <= k[p] {
            return p;
        }
        let (mut low, mut high) = (p, n + 1);
        let mut mid = (low + high) / 2;
        while u < k[mid] || u >= k[mid + 1] {
            if u < k[mid] {
                high = mid;
            } else {
                low = mid;
            }
            mid = (low + high) / 2;
        }
        mid
    }

    /// The `p + 1` non-vanishing basis functions at `u` in span `i` and their first derivatives: A2.2 and A2.3 (for
    /// the first derivative only).
    fn basis(&self, i: usize, u: f64) -> (Vec<f64>, Vec<f64>) {
        let p = self.degree;
        let k = &self.values;
        // ndu[j][r]: basis functions (upper triangle with j >= r) and knot differences (lower)
        let mut ndu = vec![vec![0.0; p + 1]; p + 1];
        let mut left = vec![0.0; p + 1];
        let mut right = vec![0.0; p + 1];
        ndu[0][0] = 1.0;
        for j in 1..=p {
            left[j] = u - k[i + 1 - j];
            right[j] = k[i + j] - u;
            let mut saved = 0.0;
            for r in 0..j {
                ndu[j][r] = right[r + 1] + left[j - r];
                let temp = if ndu[j][r] != 0.0 { ndu[r][j - 1] / ndu[j][r] } else { 0.0 };
                ndu[r][j] = saved + right[r + 1] * temp;
                saved = left[j - r] * temp;
            }
            ndu[j][j] = saved;
        }
        let values: Vec<f64> = (0..=p).map(|j| ndu[j][p]).collect();
        // first derivatives: N'_{i-p+r,p} = p (N_{i-p+r,p-1} / (u_{i+r} - u_{i-p+r}) - N_{i-p+r+1,p-1} / (...))
        let derivative: Vec<f64> = (0..=p)
            .map(|r| {
                let mut d = 0.0;
                if r >= 1 {
                    let den = ndu[p][r - 1];
                    if den != 0.0 {
                        d += ndu[r - 1][p - 1] / den;
                    }
                }
                if r < p {
                    let den = ndu[p][r];
                    if den != 0.0 {
                        d -= ndu[r][p - 1] / den;
                    }
                }
                d * p as f64
            })
            .collect();
        (values, derivative)
    }
}

/// A (possibly rational) B-spline curve.
#[derive(Debug, Clone, PartialEq)]
pub struct BSplineCurve {
    knots: Knots,
    /// Weighted poles `(w P, w)`.
    poles: Vec<DVec4>,
}

impl BSplineCurve {
    /// A curve of `degree` through the knot values with their multiplicities, poles and optional weights.
    pub fn new(
        degree: i64,
        multiplicities: &[i64],
        values: &[f64],
        poles: &[DVec3],
        weights: Option<&[f64]>,
    ) -> Result<Self, NurbsError> {
        let knots = Knots::new(degree, multiplicities, values, poles.len())?;
        Ok(BSplineCurve { knots, poles: homogeneous(poles, weights)? })
    }

    /// The parameter domain.
    pub fn domain(&self) -> (f64, f64) {
        self.knots.domain()
    }

    /// The distinct knots within the domain (the curve is smooth between them).
    pub fn breaks(&self) -> Vec<f64> {
        self.knots.breaks()
    }

    /// The degree.
    pub fn degree(&self) -> usize {
        self.knots.degree()
    }

    /// The point at `u` (clamped to the domain) and the first derivative there.
    pub fn eval(&self, u: f64) -> (DVec3, DVec3) {
        let (a, b) = self.domain();
        let u = u.clamp(a, b);
        let p = self.knots.degree;
        let span = self.knots.span(u);
        let (n, dn) = self.knots.basis(span, u);
        let (mut h, mut dh) = (DVec4::ZERO, DVec4::ZERO);
        for j in 0..=p {
            let pole = self.poles[span - p + j];
            h += n[j] * pole;
            dh += dn[j] * pole;
        }
        project(h, dh)
    }

    /// The point at `u`.
    pub fn point(&self, u: f64) -> DVec3 {
        self.eval(u).0
    }
}

/// A (possibly rational) B-spline surface; poles are indexed `[i][j]` with `i` along u.
#[derive(Debug, Clone, PartialEq)]
pub struct BSplineSurface {
    knots_u: Knots,
    knots_v: Knots,
    /// Weighted poles, row `i` (along u) after row.
    poles: Vec<DVec4>,
    columns: usize,
}

impl BSplineSurface {
    /// A surface of degrees `(degree_u, degree_v)` with its knots, its control net (rows along u, each along v) and
    /// optional weights of the same shape.
    pub fn new(
        degree: (i64, i64),
        multiplicities: (&[i64], &[i64]),
        values: (&[f64], &[f64]),
        net: &[Vec<DVec3>],
        weights: Option<&[Vec<f64>]>,
    ) -> Result<Self, NurbsError> {
        let rows = net.len();
        let columns = net.first().map_or(0, Vec::len);
        if rows == 0 || columns == 0 || net.iter().any(|r| r.len() != columns) {
            return Err(NurbsError::Poles { rows, columns });
        }
        let knots_u = Knots::new(degree.0, multiplicities.0, values.0, rows)?;
        let knots_v = Knots::new(degree.1, multiplicities.1, values.1, columns)?;
        let flat: Vec<DVec3> = net.iter().flatten().copied().collect();
        let flat_weights: Option<Vec<f64>> = match weights {
            Some(w) => {
                if w.len() != rows || w.iter().any(|r| r.len() != columns) {
                    return Err(NurbsError::Weights);
                }
                Some(w.iter().flatten().copied().collect())
            }
            None => None,
        };
        let poles = homogeneous(&flat, flat_weights.as_deref())?;
        Ok(BSplineSurface { knots_u, knots_v, poles, columns })
    }

    /// The parameter domain: `((u0, u1), (v0, v1))`.
    pub fn domain(&self) -> ((f64, f64), (f64, f64)) {
        (self.knots_u.domain(), self.knots_v.domain())
    }

    /// The distinct knots within the domain in u and in v.
    pub fn breaks(&self) -> (Vec<f64>, Vec<f64>) {
        (self.knots_u.breaks(), self.knots_v.breaks())
    }

    /// The point at `(u, v)` (clamped to the domain) and the partial derivatives `S_u`, `S_v` there.
    pub fn eval(&self, u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
        let ((u0, u1), (v0, v1)) = self.domain();
        let (u, v) = (u.clamp(u0, u1), v.clamp(v0, v1));
        let (p, q) = (self.knots_u.degree, self.knots_v.degree);
        let (su, sv) = (self.knots_u.span(u), self.knots_v.span(v));
        let (nu, dnu) = self.knots_u.basis(su, u);
        let (nv, dnv) = self.knots_v.basis(sv, v);
        let (mut h, mut hu, mut hv) = (DVec4::ZERO, DVec4::ZERO, DVec4::ZERO);
        for k in 0..=p {
            let row = (su - p + k) * self.columns;
            let (mut t, mut tv) = (DVec4::ZERO, DVec4::ZERO);
            for l in 0..=q {
                let pole = self.poles[row + sv - q + l];
                t += nv[l] * pole;
                tv += dnv[l] * pole;
            }
            h += nu[k] * t;
            hu += dnu[k] * t;
            hv += nu[k] * tv;
        }
        let (point, du) = project(h, hu);
        let (_, dv) = project(h, hv);
        (point, du, dv)
    }

    /// The point at `(u, v)`.
    pub fn point(&self, u: f64, v: f64) -> DVec3 {
        self.eval(u, v).0
    }
}

/// Poles with weights in homogeneous form `(w P, w)`; unit weights when none are given.
fn homogeneous(poles: &[DVec3], weights: Option<&[f64]>) -> Result<Vec<DVec4>, NurbsError> {
    if poles.iter().any(|p| !p.is_finite()) {
        return Err(NurbsError::NonFinite);
    }
    match weights {
        None => Ok(poles.iter().map(|p| p.extend(1.0)).collect()),
        Some(w) => {
            if w.len() != poles.len() || w.iter().any(|x| !(x.is_finite() && *x > 0.0)) {
                return Err(NurbsError::Weights);
            }
            Ok(poles.iter().zip(w).map(|(p, &x)| (*p * x).extend(x)).collect())
        }
    }
}

/// The point and derivative of the projection of a homogeneous point `h` with derivative `dh`: `A / w` and
/// `(A' - w' C) / w`.
fn project(h: DVec4, dh: DVec4) -> (DVec3, DVec3) {
    let w = h.w;
    let point = h.truncate() / w;
    (point, (dh.truncate() - dh.w * point) / w)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_2};

    fn quarter_circle() -> BSplineCurve {
        let poles = [DVec3::new(1.0, 0.0, 0.0), DVec3::new(1.0, 1.0, 0.0), DVec3::new(0.0, 1.0, 0.0)];
        BSplineCurve::new(2, &[3, 3], &[0.0, 1.0], &poles, Some(&[1.0, FRAC_1_SQRT_2, 1.0])).expect("valid")
    }

    #[test]
    fn the_rational_quadratic_quarter_circle_lies_on_the_circle_with_the_right_tangent() {
        let c = quarter_circle();
        for k in 0..=20 {
            let u = k as f64 / 20.0;
            let (p, d) = c.eval(u);
            assert!((p.length() - 1.0).abs() < 1e-15, "{u}: {p}");
            // the tangent is perpendicular to the radius, and the derivative matches a central difference
            assert!(p.dot(d).abs() < 1e-14 * d.length());
            let h = 1e-6;
            if (h..=1.0 - h).contains(&u) {
                let fd = (c.point(u + h) - c.point(u - h)) / (2.0 * h);
                assert!((fd - d).length() < 1e-7 * d.length(), "{u}: {fd} vs {d}");
            }
        }
        assert!((c.point(0.5) - DVec3::new(FRAC_1_SQRT_2, FRAC_1_SQRT_2, 0.0)).length() < 1e-15);
    }

    #[test]
    fn a_cubic_with_interior_knots_is_a_partition_of_unity_and_reproduces_a_line() {
        // poles evenly spaced on a line with a uniform interior knot vector: the curve is that line, u -> 3u / 4 ...
        let poles: Vec<DVec3> = (0..6).map(|k| DVec3::new(k as f64, 2.0 * k as f64, -1.0)).collect();
        let c = BSplineCurve::new(3, &[4, 1, 1, 4], &[0.0, 1.0, 2.0, 3.0], &poles, None).expect("valid");
        for k in 0..=30 {
            let u = 3.0 * k as f64 / 30.0;
            let (p, d) = c.eval(u);
            // on the line through the poles
            assert!((p.y - 2.0 * p.x).abs() < 1e-12 && (p.z + 1.0).abs() < 1e-12, "{u}: {p}");
            assert!((d.y - 2.0 * d.x).abs() < 1e-12 && d.z.abs() < 1e-12, "{u}: {d}");
            let span = c.knots.span(u);
            let (n, dn) = c.knots.basis(span, u);
            assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-14);
            assert!(dn.iter().sum::<f64>().abs() < 1e-12);
        }
        assert_eq!(c.point(0.0), poles[0]);
        assert!((c.point(3.0) - poles[5]).length() < 1e-14);
    }

    #[test]
    fn a_bilinear_net_is_its_plane_and_a_rational_net_is_its_cylinder() {
        let net = vec![
            vec![DVec3::new(0.0, 0.0, 1.0), DVec3::new(0.0, 5.0, 1.0)],
            vec![DVec3::new(3.0, 0.0, 1.0), DVec3::new(3.0, 5.0, 1.0)],
        ];
        let plane =
            BSplineSurface::new((1, 1), (&[2, 2], &[2, 2]), (&[0.0, 1.0], &[0.0, 1.0]), &net, None).expect("valid");
        let (p, du, dv) = plane.eval(0.25, 0.5);
        assert!((p - DVec3::new(0.75, 2.5, 1.0)).length() < 1e-15);
        assert!((du - DVec3::new(3.0, 0.0, 0.0)).length() < 1e-15 && (dv - DVec3::new(0.0, 5.0, 0.0)).length() < 1e-15);
        // a quarter cylinder of radius 2 about the z axis, from z = 0 to z = 4
        let arc = [DVec3::new(2.0, 0.0, 0.0), DVec3::new(2.0, 2.0, 0.0), DVec3::new(0.0, 2.0, 0.0)];
        let net: Vec<Vec<DVec3>> = arc.iter().map(|p| vec![*p, *p + DVec3::new(0.0, 0.0, 4.0)]).collect();
        let w = [1.0, FRAC_1_SQRT_2, 1.0];
        let weights: Vec<Vec<f64>> = w.iter().map(|x| vec![*x, *x]).collect();
        let cylinder =
            BSplineSurface::new((2, 1), (&[3, 3], &[2, 2]), (&[0.0, FRAC_PI_2], &[0.0, 4.0]), &net, Some(&weights))
                .expect("valid");
        for i in 0..=8 {
            for j in 0..=4 {
                let (u, v) = (FRAC_PI_2 * i as f64 / 8.0, j as f64);
                let (p, su, sv) = cylinder.eval(u, v);
                assert!((p.truncate().length() - 2.0).abs() < 1e-14, "{u} {v}: {p}");
                assert!((p.z - v).abs() < 1e-14);
                assert!((sv - DVec3::Z).length() < 1e-14);
                assert!(su.dot(p.with_z(0.0)).abs() < 1e-13 && su.z.abs() < 1e-14);
            }
        }
    }

    #[test]
    fn inconsistent_knots_poles_and_weights_are_errors() {
        let poles: Vec<DVec3> = (0..4).map(|k| DVec3::new(k as f64, 0.0, 0.0)).collect();
        type Case = (i64, Vec<i64>, Vec<f64>, Option<Vec<f64>>);
        let cases: [Case; 7] = [
            (0, vec![1, 1], vec![0.0, 1.0], None),
            (3, vec![4, 3], vec![0.0, 1.0], None),
            (3, vec![4, 4], vec![1.0, 0.0], None),
            (3, vec![4, 5], vec![0.0, 1.0], None),
            (3, vec![4, 4], vec![0.0, f64::NAN], None),
            (3, vec![4, 4], vec![0.0, 1.0], Some(vec![1.0, -1.0, 1.0, 1.0])),
            (3, vec![4], vec![0.0, 1.0], None),
        ];
        for (degree, mult, values, weights) in cases {
            let e = BSplineCurve::new(degree, &mult, &values, &poles, weights.as_deref());
            assert!(e.is_err(), "{degree} {mult:?} {values:?} {weights:?}");
        }
        assert!(BSplineCurve::new(3, &[4, 4], &[0.0, 1.0], &poles, None).is_ok());
        let ragged = vec![vec![DVec3::ZERO, DVec3::X], vec![DVec3::Y]];
        let e = BSplineSurface::new((1, 1), (&[2, 2], &[2, 2]), (&[0.0, 1.0], &[0.0, 1.0]), &ragged, None);
        assert!(matches!(e, Err(NurbsError::Poles { .. })));
    }
}
