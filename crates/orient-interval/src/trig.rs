//! Closed-form solution of the event equations `alpha cos(theta) + beta sin(theta) + gamma = 0`.
//!
//! Paper: Ayyadevara et al. 2002 (\[A\]) Appendix C, eq. 14-16. Every event function of a rotation about `z` is a
//! trigonometric polynomial of degree one, because every product of two rotated vectors reduces through
//! `Ra . Rb = a . b` and `Ra x Rb = R (a x b)`. \[A\] substitutes `t = tan(theta / 2)` and solves a quadratic (eq. 16);
//! here the equivalent phase form is used: with `h = hypot(alpha, beta)` and `phi = atan2(beta, alpha)`,
//! `f(theta) = h cos(theta - phi) + gamma`, so the roots are `theta = phi +- acos(-gamma / h)` (no division by a
//! vanishing leading coefficient at `theta = pi`, which the tangent form has). The set where `|f| <= tol` (the
//! tolerance band in which the c-space construction treats the configuration as degenerate) is likewise at most two
//! arcs of the circle, with ends `phi +- acos((+-tol - gamma) / h)`. O(1) per function; never bisection.

use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};

/// `alpha cos(theta) + beta sin(theta) + gamma`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Trig {
    /// Coefficient of `cos(theta)`.
    pub alpha: f64,
    /// Coefficient of `sin(theta)`.
    pub beta: f64,
    /// Constant term.
    pub gamma: f64,
}

/// An arc `[lo, hi]` of the angle circle (`lo` in `[0, 2 pi)`, `lo <= hi < lo + 2 pi`) with a representative angle
/// `root` inside it (the exact root of `f` when there is one, else the point of smallest `|f|`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AngleArc {
    /// Start (radians, in `[0, 2 pi)`).
    pub lo: f64,
    /// End (radians, `lo <= hi < lo + 2 pi`).
    pub hi: f64,
    /// A representative angle in `[lo, hi]`, reduced to `[0, 2 pi)`.
    pub root: f64,
}

/// Where `|f| <= tol` on the circle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Band {
    /// Nowhere.
    Empty,
    /// Everywhere: the function vanishes identically within the tolerance (a permanently degenerate family).
    Whole,
    /// One arc.
    One(AngleArc),
    /// Two disjoint arcs.
    Two(AngleArc, AngleArc),
}

/// `x` reduced to `[0, 2 pi)`.
#[inline]
pub fn wrap(x: f64) -> f64 {
    let r = x.rem_euclid(TAU);
    if r >= TAU { 0.0 } else { r }
}

/// `x` reduced to `[-pi, pi)`.
#[inline]
pub fn wrap_signed(x: f64) -> f64 {
    let r = wrap(x + PI) - PI;
    if r >= PI { r - TAU } else { r }
}

impl std::ops::Add for Trig {
    type Output = Self;
    /// The sum of two functions.
    #[inline]
    fn add(self, o: Self) -> Self {
        Self { alpha: self.alpha + o.alpha, beta: self.beta + o.beta, gamma: self.gamma + o.gamma }
    }
}

impl Trig {
    /// The function `theta -> u . (R(theta) v)` with `R` the rotation about `z`:
    /// `R v = (c v_x - s v_y, s v_x + c v_y, v_z)`, so `alpha = u_x v_x + u_y v_y`, `beta = u_y v_x - u_x v_y`,
    /// `gamma = u_z v_z`.
    #[inline]
    pub fn rotated_dot(u: DVec3, v: DVec3) -> Self {
        Self { alpha: u.x * v.x + u.y * v.y, beta: u.y * v.x - u.x * v.y, gamma: u.z * v.z }
    }

    /// A constant function.
    #[inline]
    pub fn constant(gamma: f64) -> Self {
        Self { alpha: 0.0, beta: 0.0, gamma }
    }

    /// The function times `k`.
    #[inline]
    pub fn scale(self, k: f64) -> Self {
        Self { alpha: self.alpha * k, beta: self.beta * k, gamma: self.gamma * k }
    }

    /// Value at `theta`.
    #[inline]
    pub fn eval(&self, theta: f64) -> f64 {
        let (s, c) = theta.sin_cos();
        self.alpha * c + self.beta * s + self.gamma
    }

    /// `hypot(alpha, beta)`: the amplitude of the varying part.
    #[inline]
    pub fn amplitude(&self) -> f64 {
        self.alpha.hypot(self.beta)
    }

    /// The roots in `[0, 2 pi)` (none, one double root, or two), in the phase form.
    pub fn roots(&self) -> Vec<f64> {
        let h = self.amplitude();
        if h == 0.0 {
            return Vec::new();
        }
        let c = -self.gamma / h;
        if !(-1.0..=1.0).contains(&c) {
            return Vec::new();
        }
        let phi = self.beta.atan2(self.alpha);
        let x = c.acos();
        if x == 0.0 || x == PI { vec![wrap(phi + x)] } else { vec![wrap(phi + x), wrap(phi - x)] }
    }

    /// The roots from \[A\] eq. 16: with `t = tan(theta / 2)`, `(gamma - alpha) t^2 + 2 beta t + (alpha + gamma) = 0`,
    /// solved with the cancellation-free quadratic formula; a vanishing leading coefficient means a root at
    /// `theta = pi`. Kept as an independent check of [`Trig::roots`].
    pub fn roots_tan_half(&self) -> Vec<f64> {
        let (a, b, c) = (self.gamma - self.alpha, 2.0 * self.beta, self.alpha + self.gamma);
        let mut out = Vec::new();
        let scale = self.alpha.abs().max(self.beta.abs()).max(self.gamma.abs());
        if scale == 0.0 {
            return out;
        }
        if a.abs() <= 1e-15 * scale {
            out.push(PI);
            if b != 0.0 {
                out.push(wrap(2.0 * (-c / b).atan()));
            }
            return out;
        }
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            return out;
        }
        let q = -0.5 * (b + b.signum() * disc.sqrt());
        let q = if q == 0.0 { -0.5 * disc.sqrt() } else { q };
        let t1 = q / a;
        out.push(wrap(2.0 * t1.atan()));
        if q != 0.0 {
            out.push(wrap(2.0 * (c / q).atan()));
        } else {
            out.push(wrap(2.0 * t1.atan()));
        }
        out
    }

    /// Where `|f| <= tol` (closed arcs; see [`Band`]). The arcs are widened by a few rounding units so that they are
    /// never narrower than the exact set.
    pub fn band(&self, tol: f64) -> Band {
        let h = self.amplitude();
        let g = self.gamma;
        if h <= 1e-300 {
            return if g.abs() <= tol { Band::Whole } else { Band::Empty };
        }
        let slack = 4.0 * f64::EPSILON * (1.0 + g.abs() / h);
        let c_lo = (-tol - g) / h - slack;
        let c_hi = (tol - g) / h + slack;
        if c_lo > 1.0 || c_hi < -1.0 {
            return Band::Empty;
        }
        if c_lo <= -1.0 && c_hi >= 1.0 {
            return Band::Whole;
        }
        let phi = self.beta.atan2(self.alpha);
        let pad = 4.0 * f64::EPSILON * TAU;
        let a1 = if c_hi >= 1.0 { 0.0 } else { (c_hi.acos() - pad).max(0.0) };
        let a2 = if c_lo <= -1.0 { PI } else { (c_lo.acos() + pad).min(PI) };
        let c_root = (-g / h).clamp(-1.0, 1.0);
        let x_root = c_root.acos().clamp(a1, a2);
        let arc = |lo: f64, hi: f64, root: f64| AngleArc { lo: wrap(lo), hi: wrap(lo) + (hi - lo), root: wrap(root) };
        if a1 == 0.0 && a2 == PI {
            Band::Whole
        } else if a1 == 0.0 {
            Band::One(arc(phi - a2, phi + a2, phi + x_root))
        } else if a2 == PI {
            Band::One(arc(phi + a1, phi + TAU - a1, phi + x_root))
        } else {
            Band::Two(arc(phi + a1, phi + a2, phi + x_root), arc(phi - a2, phi - a1, phi - x_root))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roots_satisfy_the_equation_and_match_the_tangent_form() {
        let cases = [
            Trig { alpha: 1.0, beta: 0.0, gamma: 0.0 },
            Trig { alpha: 0.3, beta: -0.7, gamma: 0.2 },
            Trig { alpha: -2.0, beta: 1.0, gamma: 1.5 },
            Trig { alpha: 1.0, beta: 0.0, gamma: 1.0 },
        ];
        for t in cases {
            let r = t.roots();
            assert!(!r.is_empty());
            for &x in &r {
                assert!(t.eval(x).abs() < 1e-12, "{t:?} at {x}: {}", t.eval(x));
            }
            let mut q = t.roots_tan_half();
            q.sort_by(f64::total_cmp);
            for &x in &r {
                assert!(q.iter().any(|y| wrap_signed(x - y).abs() < 1e-7), "{t:?}: {r:?} vs {q:?}");
            }
        }
        assert!(Trig { alpha: 1.0, beta: 1.0, gamma: 2.0 }.roots().is_empty());
    }

    #[test]
    fn band_contains_exactly_the_small_values() {
        let t = Trig { alpha: 0.6, beta: -0.8, gamma: 0.1 };
        let tol = 0.05;
        let band = t.band(tol);
        let arcs = match band {
            Band::Two(a, b) => vec![a, b],
            other => panic!("expected two arcs, got {other:?}"),
        };
        for k in 0..100_000 {
            let x = TAU * k as f64 / 100_000.0;
            let inside = arcs.iter().any(|a| wrap(x - a.lo) <= a.hi - a.lo);
            assert_eq!(inside, t.eval(x).abs() <= tol, "at {x}: f = {}", t.eval(x));
        }
        for a in &arcs {
            assert!(t.eval(a.root).abs() < 1e-12);
        }
        assert_eq!(Trig::constant(0.0).band(1e-9), Band::Whole);
        assert_eq!(Trig::constant(1.0).band(1e-9), Band::Empty);
        assert!(matches!(Trig { alpha: 1.0, beta: 0.0, gamma: 1.0 }.band(0.01), Band::One(_)));
    }

    #[test]
    fn rotated_dot_matches_the_matrix() {
        let u = DVec3::new(0.3, -1.2, 0.7);
        let v = DVec3::new(-0.4, 0.9, 2.0);
        let t = Trig::rotated_dot(u, v);
        for k in 0..16 {
            let th = k as f64 * 0.41;
            let direct = u.dot(glam::DMat3::from_rotation_z(th) * v);
            assert!((t.eval(th) - direct).abs() < 1e-14);
        }
    }
}
