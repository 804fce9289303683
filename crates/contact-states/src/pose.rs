//! Relative configurations `t = (x, y, z, rx, ry, rz)` and the bounded-misalignment box (\[P\] eq. 6-7).
//!
//! Convention: the moving part's own coordinates `p` map to the fixed part's coordinates by
//! `T(p) = R p + (x, y, z)` with `R = Rz(rz) Ry(ry) Rx(rx)` (rotations about the fixed axes x, then y, then z, all
//! about the moving part's own origin, its *reference point*). Lengths in millimetres, angles in radians.

use serde::{Deserialize, Serialize};
use stackplan_geom::{DMat3, DVec3};

/// A configuration `t = (x, y, z, rx, ry, rz)`.
pub type Config = [f64; 6];

/// Names of the six configuration variables.
pub const VARIABLE_NAMES: [&str; 6] = ["x", "y", "z", "rx", "ry", "rz"];

/// A rigid transform from a configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Rotation `Rz Ry Rx`.
    pub rotation: DMat3,
    /// Translation.
    pub translation: DVec3,
}

impl Pose {
    /// The pose of configuration `t`.
    pub fn from_config(t: &Config) -> Self {
        let rotation = DMat3::from_rotation_z(t[5]) * DMat3::from_rotation_y(t[4]) * DMat3::from_rotation_x(t[3]);
        Self { rotation, translation: DVec3::new(t[0], t[1], t[2]) }
    }

    /// Image of a point.
    #[inline]
    pub fn apply(&self, p: DVec3) -> DVec3 {
        self.rotation * p + self.translation
    }

    /// Image of a direction.
    #[inline]
    pub fn apply_vector(&self, v: DVec3) -> DVec3 {
        self.rotation * v
    }

    /// Pre-image of a point (fixed-part coordinates to moving-part coordinates).
    #[inline]
    pub fn inverse_apply(&self, p: DVec3) -> DVec3 {
        self.rotation.transpose() * (p - self.translation)
    }

    /// Pre-image of a direction.
    #[inline]
    pub fn inverse_apply_vector(&self, v: DVec3) -> DVec3 {
        self.rotation.transpose() * v
    }
}

/// Box bounds `t_min <= t <= t_max` on the configuration (\[P\] eq. 7).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ConfigBox {
    /// Lower bounds.
    pub min: Config,
    /// Upper bounds.
    pub max: Config,
}

/// Why bounds are not a box.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BoxError {
    /// A bound is not finite or a lower bound exceeds the upper one.
    #[error("bounds of variable {variable} are invalid: [{min}, {max}]")]
    Invalid {
        /// Variable name.
        variable: &'static str,
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
}

impl ConfigBox {
    /// A box; checks finiteness and order.
    pub fn new(min: Config, max: Config) -> Result<Self, BoxError> {
        for k in 0..6 {
            if !(min[k].is_finite() && max[k].is_finite() && min[k] <= max[k]) {
                return Err(BoxError::Invalid { variable: VARIABLE_NAMES[k], min: min[k], max: max[k] });
            }
        }
        Ok(Self { min, max })
    }

    /// Width of variable `k`.
    pub fn width(&self, k: usize) -> f64 {
        self.max[k] - self.min[k]
    }

    /// Clamps `t` into the box.
    pub fn clamp(&self, t: &mut Config) {
        for k in 0..6 {
            t[k] = t[k].clamp(self.min[k], self.max[k]);
        }
    }

    /// Whether `t` is inside (inclusive).
    pub fn contains(&self, t: &Config) -> bool {
        (0..6).all(|k| self.min[k] <= t[k] && t[k] <= self.max[k])
    }

    /// Intersection, or `None` when empty.
    pub fn intersect(&self, other: &Self) -> Option<Self> {
        let mut out = *self;
        for k in 0..6 {
            out.min[k] = self.min[k].max(other.min[k]);
            out.max[k] = self.max[k].min(other.max[k]);
            if out.min[k] > out.max[k] {
                return None;
            }
        }
        Some(out)
    }

    /// Smallest box containing both.
    pub fn hull(&self, other: &Self) -> Self {
        let mut out = *self;
        for k in 0..6 {
            out.min[k] = self.min[k].min(other.min[k]);
            out.max[k] = self.max[k].max(other.max[k]);
        }
        out
    }

    /// The box grown by `fraction` of `reference`'s widths on every side and clipped to `reference`.
    pub fn widened_within(&self, reference: &Self, fraction: f64) -> Self {
        let mut out = *self;
        for k in 0..6 {
            let m = fraction * reference.width(k);
            out.min[k] = (self.min[k] - m).max(reference.min[k]);
            out.max[k] = (self.max[k] + m).min(reference.max[k]);
        }
        out
    }

    /// An upper bound on the rotation angle of any `R = Rz Ry Rx` in the box (sum of the largest `|angle|` per axis,
    /// by the triangle inequality of the rotation angle metric), capped at pi.
    pub fn max_rotation_angle(&self) -> f64 {
        let s: f64 = (3..6).map(|k| self.min[k].abs().max(self.max[k].abs())).sum();
        s.min(std::f64::consts::PI)
    }

    /// Volume ratio of this box to `reference` (product over the variables with positive reference width).
    pub fn volume_ratio(&self, reference: &Self) -> f64 {
        (0..6).filter(|&k| reference.width(k) > 0.0).map(|k| self.width(k) / reference.width(k)).product()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_order_is_z_y_x() {
        let t = [1.0, 2.0, 3.0, std::f64::consts::FRAC_PI_2, 0.0, std::f64::consts::FRAC_PI_2];
        let pose = Pose::from_config(&t);
        // Rx(90) takes y to z; then Rz(90) leaves z alone
        let p = pose.apply(DVec3::Y);
        assert!((p - DVec3::new(1.0, 2.0, 4.0)).length() < 1e-12);
        // Rx(90) leaves x alone; Rz(90) takes x to y
        let q = pose.apply(DVec3::X);
        assert!((q - DVec3::new(1.0, 3.0, 3.0)).length() < 1e-12);
        assert!((pose.inverse_apply(q) - DVec3::X).length() < 1e-12);
    }

    #[test]
    fn boxes() {
        let a = ConfigBox::new([0.0; 6], [1.0; 6]).expect("box");
        let b = ConfigBox::new([0.5; 6], [2.0; 6]).expect("box");
        let i = a.intersect(&b).expect("overlap");
        assert_eq!(i.min, [0.5; 6]);
        assert_eq!(a.hull(&b).max, [2.0; 6]);
        assert!(ConfigBox::new([0.0; 6], [-1.0; 6]).is_err());
        let c = ConfigBox::new([3.0; 6], [4.0; 6]).expect("box");
        assert!(a.intersect(&c).is_none());
        assert!((i.volume_ratio(&a) - 0.5f64.powi(6)).abs() < 1e-15);
    }
}
