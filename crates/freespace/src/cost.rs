//! The objective of the placement QP: a separable convex quadratic of a position.
//!
//! `f(p) = 1/2 sum_i h_i p_i^2 + sum_i g_i p_i + c` with `h_i >= 0` (the diagonal of the Hessian). The costs of \[A\]
//! (Ayyadevara et al. 2002: the stacking cost (1) and the squared distance to a desired position of section VII-A)
//! are of this form at a fixed orientation; the planner derives their coefficients (`stackplan-planner`'s
//! `qp::Quadratic`, `docs/algorithms.md`, "Free space and the placement QP") and hands them to [`crate::qp`] as a
//! [`SeparableCost`]. Evaluation and gradient are O(D).

/// Why a cost cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CostError {
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
}

/// A separable convex quadratic `1/2 sum h_i p_i^2 + g . p + c` given by its coefficients (checked: `h_i >= 0`, all
/// finite).
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

    /// Diagonal of the Hessian (all `>= 0`).
    pub fn hessian_diagonal(&self) -> [f64; D] {
        self.h
    }

    /// Linear term `g`.
    pub fn linear(&self) -> [f64; D] {
        self.g
    }

    /// Constant term.
    pub fn constant(&self) -> f64 {
        self.c
    }

    /// The value at `p`.
    pub fn evaluate(&self, p: &[f64; D]) -> f64 {
        let mut f = self.c;
        for i in 0..D {
            f += (0.5 * self.h[i] * p[i] + self.g[i]) * p[i];
        }
        f
    }

    /// The gradient at `p`.
    pub fn gradient(&self, p: &[f64; D]) -> [f64; D] {
        std::array::from_fn(|i| self.h[i] * p[i] + self.g[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_and_gradient_of_the_coefficients() {
        let f = SeparableCost::new([2.0, 0.0, 4.0], [1.0, -3.0, 0.5], 7.0).expect("cost");
        let p = [1.5, -2.0, 0.25];
        let direct = 0.5 * 2.0 * 1.5 * 1.5 + 0.5 * 4.0 * 0.0625 + 1.5 + 6.0 + 0.125 + 7.0;
        assert!((f.evaluate(&p) - direct).abs() < 1e-12);
        for i in 0..3 {
            let (mut q, mut s) = (p, p);
            q[i] += 1e-3;
            s[i] -= 1e-3;
            let fd = (f.evaluate(&q) - f.evaluate(&s)) / 2e-3;
            assert!((fd - f.gradient(&p)[i]).abs() < 1e-9, "coordinate {i}");
        }
        assert_eq!(
            SeparableCost::<2>::new([-1.0, 0.0], [0.0; 2], 0.0),
            Err(CostError::BadCoefficient { index: 0, h: -1.0, g: 0.0 })
        );
        assert!(SeparableCost::<2>::new([1.0, 0.0], [f64::NAN, 0.0], 0.0).is_err());
        assert_eq!(SeparableCost::<2>::new([1.0, 0.0], [0.0; 2], f64::INFINITY), Err(CostError::BadConstant));
    }
}
