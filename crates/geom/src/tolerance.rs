//! The tolerance policy: the few decisions that cannot be exact.
//!
//! Combinatorial structure that comes straight from input coordinates (hulls, coplanar facet merging, convexity of
//! input pieces) is decided with the exact predicates of [`crate::predicates`] and needs no tolerance. Quantities that
//! are *computed* (rotated vertices, Minkowski sums of rotated parts, contact distances, solver outputs) carry rounding
//! error, and the questions asked of them — "are these two parts touching or penetrating?", "is this point on the
//! face?" — are answered with one length tolerance per problem:
//!
//! `linear = RELATIVE * scale`, where `scale` is the characteristic length of the problem (the largest bounding-box
//! diagonal of the parts involved, at least 1 mm) and `RELATIVE = 1e-9`.
//!
//! With `f64` coordinates of sheet-metal parts (up to a few metres, in millimetres) rounding errors of rotations and
//! Minkowski sums are around `1e-13 * scale`, four orders of magnitude below the tolerance; real contacts that a user
//! cares about (robot clearances, sheet thickness) are at least `1e-3` mm, six orders above it. A gap or penetration
//! smaller than `linear` is reported as *touching*.

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// The relative tolerance of the policy.
pub const RELATIVE: f64 = 1e-9;

/// The smallest characteristic length used to derive a tolerance (millimetres).
pub const MIN_SCALE: f64 = 1.0;

/// A length tolerance derived from the characteristic size of a problem.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Tolerance {
    /// Distances with absolute value at most `linear` count as zero (touching, on the plane).
    pub linear: f64,
}

impl Tolerance {
    /// The policy's tolerance for a problem whose characteristic length is `scale` (millimetres).
    pub fn for_scale(scale: f64) -> Self {
        let scale = if scale.is_finite() { scale.max(MIN_SCALE) } else { MIN_SCALE };
        Self { linear: RELATIVE * scale }
    }

    /// The policy's tolerance for a set of points: scale = the diagonal of their bounding box.
    pub fn for_points(points: &[DVec3]) -> Self {
        Self::for_scale(bounding_diagonal(points))
    }

    /// `value` classified against zero: -1 (below -linear), 0 (within), +1 (above +linear).
    #[inline]
    pub fn sign(&self, value: f64) -> i8 {
        if value > self.linear {
            1
        } else if value < -self.linear {
            -1
        } else {
            0
        }
    }

    /// Whether `value` counts as zero.
    #[inline]
    pub fn is_zero(&self, value: f64) -> bool {
        value.abs() <= self.linear
    }
}

/// Length of the diagonal of the axis-aligned bounding box of `points` (0 for an empty set).
pub fn bounding_diagonal(points: &[DVec3]) -> f64 {
    let Some(first) = points.first() else {
        return 0.0;
    };
    let (lo, hi) = points.iter().fold((*first, *first), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    (hi - lo).length()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn policy() {
        let t = Tolerance::for_scale(1000.0);
        assert!((t.linear - 1e-6).abs() < 1e-20);
        assert_eq!(t.sign(2e-6), 1);
        assert_eq!(t.sign(-2e-6), -1);
        assert_eq!(t.sign(5e-7), 0);
        assert_eq!(Tolerance::for_scale(f64::NAN).linear, RELATIVE * MIN_SCALE);
        assert_eq!(Tolerance::for_scale(0.001).linear, RELATIVE * MIN_SCALE);
        let pts = [DVec3::ZERO, DVec3::new(3.0, 4.0, 0.0)];
        assert_eq!(bounding_diagonal(&pts), 5.0);
    }
}
