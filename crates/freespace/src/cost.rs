//! Separable convex quadratic costs of a position: the stacking cost (1) of \[A\] and the squared distance to a desired
//! position (\[A\] VII-A).
//!
//! Convention: `f(p) = 1/2 sum_i h_i p_i^2 + sum_i g_i p_i + c` with `h_i >= 0` (the diagonal of the Hessian).
//!
//! **Cost (1) of \[A\]** (Ayyadevara et al. 2002, section 2.1) for one part at a fixed orientation `R`, with the
//! part's extents after rotation `xmax = max_v (R v)_x`, `xmin`, `ymax`, `ymin` and the height of its centre of
//! gravity above the position, `zc = (R c)_z` (`c` the c.g. in part coordinates; a vertex sits at `R v + p`):
//!
//! ```text
//! f(p) = w [ (p_x + xmax - x0)^2 + (p_x + xmin - x0)^2 + (p_y + ymax - y0)^2 + (p_y + ymin - y0)^2 ]
//!        + 4 (1 - w) (p_z + zc - z0)^2
//! ```
//!
//! Expanding `(p + a)^2 + (p + b)^2 = 2 p^2 + 2 (a + b) p + a^2 + b^2` gives, per axis,
//! `h_x = 4 w`, `g_x = 2 w (a_x + b_x)`, `c += w (a_x^2 + b_x^2)` with `a_x = xmax - x0`, `b_x = xmin - x0` (same for
//! y), and `h_z = 8 (1 - w)`, `g_z = 8 (1 - w) e`, `c += 4 (1 - w) e^2` with `e = zc - z0`. `w = 1` leaves `z` free
//! (`h_z = 0`), `w = 0` leaves `x, y` free. The reference `(x0, y0, z0)` defaults to the centroid of the floor
//! polygon and `z0 = 0` (the floor).
//!
//! **Desired position** (\[A\] VII-A): `f(p) = |p + R c - p_d|^2`: `h = 2`, `g = 2 (R c - p_d)`, `c = |R c - p_d|^2`.
//!
//! Evaluation and gradient are O(D).

use geom::{DMat3, DVec3, Part};
use stackplan_geom as geom;

/// Any separable convex quadratic `1/2 sum h_i p_i^2 + g . p + c` with `h_i >= 0`.
pub trait SeparableQuadratic<const D: usize> {
    /// Diagonal of the Hessian (all `>= 0`).
    fn hessian_diagonal(&self) -> [f64; D];
    /// Linear term `g`.
    fn linear(&self) -> [f64; D];
    /// Constant term.
    fn constant(&self) -> f64;

    /// The value at `p`.
    fn evaluate(&self, p: &[f64; D]) -> f64 {
        let h = self.hessian_diagonal();
        let g = self.linear();
        let mut f = self.constant();
        for i in 0..D {
            f += (0.5 * h[i] * p[i] + g[i]) * p[i];
        }
        f
    }

    /// The gradient at `p`.
    fn gradient(&self, p: &[f64; D]) -> [f64; D] {
        let h = self.hessian_diagonal();
        let g = self.linear();
        let mut out = [0.0; D];
        for i in 0..D {
            out[i] = h[i] * p[i] + g[i];
        }
        out
    }
}

/// Why a cost cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CostError {
    /// The weight is outside [0, 1].
    #[error("weight w = {0} is outside [0, 1]")]
    BadWeight(f64),
    /// A coefficient is negative (Hessian) or not finite.
    #[error("coefficient {index} is invalid: h = {h}, g = {g} (need h >= 0 and finite values)")]
    BadCoefficient {
        /// Variable index.
        index: usize,
        /// Hessian entry.
        h: f64,
        /// Linear entry.
        g: f64,
    },
    /// The constant is not finite.
    #[error("the constant term is not finite")]
    BadConstant,
    /// The part has no vertices (or non-finite ones).
    #[error("the part has no finite vertices")]
    BadPart,
}

/// A separable convex quadratic given by its coefficients.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SeparableCost<const D: usize> {
    h: [f64; D],
    g: [f64; D],
    c: f64,
}

impl<const D: usize> SeparableCost<D> {
    /// `1/2 sum h_i p_i^2 + g . p + c`; checks `h_i >= 0` and finiteness.
    pub fn new(h: [f64; D], g: [f64; D], c: f64) -> Result<Self, CostError> {
        for i in 0..D {
            if !(h[i] >= 0.0 && h[i].is_finite() && g[i].is_finite()) {
                return Err(CostError::BadCoefficient { index: i, h: h[i], g: g[i] });
            }
        }
        if !c.is_finite() {
            return Err(CostError::BadConstant);
        }
        Ok(Self { h, g, c })
    }

    /// The coefficients of any separable quadratic.
    pub fn from_quadratic(q: &impl SeparableQuadratic<D>) -> Result<Self, CostError> {
        Self::new(q.hessian_diagonal(), q.linear(), q.constant())
    }
}

impl<const D: usize> SeparableQuadratic<D> for SeparableCost<D> {
    fn hessian_diagonal(&self) -> [f64; D] {
        self.h
    }
    fn linear(&self) -> [f64; D] {
        self.g
    }
    fn constant(&self) -> f64 {
        self.c
    }
}

impl SeparableCost<3> {
    /// The cost with `p_z` fixed, as a cost in `(p_x, p_y)` (for the 2-D Omega of \[A\] VII-A-2).
    pub fn with_fixed_z(&self, pz: f64) -> SeparableCost<2> {
        SeparableCost {
            h: [self.h[0], self.h[1]],
            g: [self.g[0], self.g[1]],
            c: self.c + (0.5 * self.h[2] * pz + self.g[2]) * pz,
        }
    }
}

/// The part-dependent constants of cost (1) at one orientation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RotatedExtents {
    /// `max_v (R v)_x`.
    pub x_max: f64,
    /// `min_v (R v)_x`.
    pub x_min: f64,
    /// `max_v (R v)_y`.
    pub y_max: f64,
    /// `min_v (R v)_y`.
    pub y_min: f64,
    /// Rotated centre of gravity `R c` (its z is `zc`).
    pub center_of_gravity: DVec3,
}

impl RotatedExtents {
    /// Extents of rotated points with the rotated c.g. `R c`.
    pub fn from_points(rotated: impl IntoIterator<Item = DVec3>, rotated_cg: DVec3) -> Result<Self, CostError> {
        let mut e = Self {
            x_max: f64::NEG_INFINITY,
            x_min: f64::INFINITY,
            y_max: f64::NEG_INFINITY,
            y_min: f64::INFINITY,
            center_of_gravity: rotated_cg,
        };
        for v in rotated {
            if !v.is_finite() {
                return Err(CostError::BadPart);
            }
            e.x_max = e.x_max.max(v.x);
            e.x_min = e.x_min.min(v.x);
            e.y_max = e.y_max.max(v.y);
            e.y_min = e.y_min.min(v.y);
        }
        let finite = e.x_max.is_finite() && e.x_min.is_finite() && e.y_max.is_finite() && e.y_min.is_finite();
        if !finite || !rotated_cg.is_finite() {
            return Err(CostError::BadPart);
        }
        Ok(e)
    }

    /// Extents of `part` rotated by `rotation` (uniform density c.g. from the part's mass properties).
    pub fn of_part(part: &Part, rotation: DMat3) -> Result<Self, CostError> {
        Self::from_points(part.all_vertices().map(|v| rotation * v), rotation * part.mass().center_of_gravity)
    }
}

/// Cost (1) of \[A\] at a fixed orientation: see the module documentation. `reference = (x0, y0, z0)`.
pub fn stacking_cost(w: f64, extents: &RotatedExtents, reference: DVec3) -> Result<SeparableCost<3>, CostError> {
    if !(0.0..=1.0).contains(&w) {
        return Err(CostError::BadWeight(w));
    }
    let ax = extents.x_max - reference.x;
    let bx = extents.x_min - reference.x;
    let ay = extents.y_max - reference.y;
    let by = extents.y_min - reference.y;
    let e = extents.center_of_gravity.z - reference.z;
    let h = [4.0 * w, 4.0 * w, 8.0 * (1.0 - w)];
    let g = [2.0 * w * (ax + bx), 2.0 * w * (ay + by), 8.0 * (1.0 - w) * e];
    let c = w * (ax * ax + bx * bx + ay * ay + by * by) + 4.0 * (1.0 - w) * e * e;
    SeparableCost::new(h, g, c)
}

/// Squared distance of the part's c.g. (at `p + R c`) to a desired position `desired` (\[A\] VII-A).
pub fn desired_position_cost(rotated_cg: DVec3, desired: DVec3) -> Result<SeparableCost<3>, CostError> {
    let o = rotated_cg - desired;
    SeparableCost::new([2.0; 3], [2.0 * o.x, 2.0 * o.y, 2.0 * o.z], o.length_squared())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn direct(w: f64, e: &RotatedExtents, r: DVec3, p: [f64; 3]) -> f64 {
        let sq = |x: f64| x * x;
        w * (sq(p[0] + e.x_max - r.x) + sq(p[0] + e.x_min - r.x) + sq(p[1] + e.y_max - r.y) + sq(p[1] + e.y_min - r.y))
            + 4.0 * (1.0 - w) * sq(p[2] + e.center_of_gravity.z - r.z)
    }

    #[test]
    fn expansion_matches_the_definition() {
        let e = RotatedExtents {
            x_max: 3.0,
            x_min: -1.0,
            y_max: 2.5,
            y_min: 0.5,
            center_of_gravity: DVec3::new(0.2, 0.1, 0.7),
        };
        let r = DVec3::new(10.0, -4.0, 0.5);
        for w in [0.0, 0.3, 0.9, 1.0] {
            let f = stacking_cost(w, &e, r).expect("cost");
            for p in [[0.0, 0.0, 0.0], [1.5, -2.0, 3.0], [-7.0, 11.0, 0.25]] {
                let a = f.evaluate(&p);
                let b = direct(w, &e, r, p);
                assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0), "w {w}: {a} vs {b}");
                // gradient by central differences (exact for a quadratic up to rounding)
                let g = f.gradient(&p);
                for i in 0..3 {
                    let mut q = p;
                    q[i] += 1e-3;
                    let mut s = p;
                    s[i] -= 1e-3;
                    let fd = (f.evaluate(&q) - f.evaluate(&s)) / 2e-3;
                    assert!((fd - g[i]).abs() < 1e-6 * g[i].abs().max(1.0));
                }
            }
            let f2 = f.with_fixed_z(1.25);
            assert!((f2.evaluate(&[1.5, -2.0]) - f.evaluate(&[1.5, -2.0, 1.25])).abs() < 1e-12);
        }
        assert_eq!(stacking_cost(1.5, &e, r), Err(CostError::BadWeight(1.5)));
        assert!(SeparableCost::<2>::new([-1.0, 0.0], [0.0; 2], 0.0).is_err());
        let d = desired_position_cost(DVec3::new(1.0, 2.0, 3.0), DVec3::new(0.0, 0.0, 1.0)).expect("cost");
        assert!((d.evaluate(&[0.5, 0.5, 0.5]) - (1.5f64 * 1.5 + 2.5 * 2.5 + 2.5 * 2.5)).abs() < 1e-12);
    }
}
