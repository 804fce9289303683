//! Rigid poses: a proper rotation and a translation, `world = rotation . v + position`.
//!
//! This is the placement of a part in a stack (\[A\] section III: a configuration is a position `p` and a rotation
//! `R(theta) R(phi, psi)`). Composition follows function composition: `a.compose(&b)` applies `b` first, then `a`,
//! i.e. `R = R_a R_b`, `p = R_a p_b + p_a`; the inverse is `(R^T, -R^T p)`. All operations are O(1).
//!
//! A pose read from a file is checked to be a proper rotation: `R^T R = I` entry-wise within [`ROTATION_TOLERANCE`]
//! and `det R = +1` within the same tolerance (a reflection has `det = -1` and would turn parts inside out).

use glam::{DMat3, DVec3};
use serde::{Deserialize, Serialize};

/// Tolerance of the orthonormality and determinant checks (absolute, on matrix entries).
pub const ROTATION_TOLERANCE: f64 = 1e-9;

/// An angle given in degrees, reduced modulo one turn, in radians: `(degrees % 360).to_radians()`, what every angle
/// a user gives in degrees to turn a part goes through (the command line's `--theta-deg` and `--extrapolate-from`,
/// the regression scenarios' `theta_deg`).
///
/// The remainder of two doubles is exact and keeps the sign of `degrees`: an angle in `(-360, 360)` is converted as
/// given, bit for bit, and `T` and `T + 360 k` (both doubles, of one sign) give the same radians, so the same
/// rotation. Converting a huge angle directly is off by whole degrees (1e17 degrees turned a part by 4.4 degrees too
/// much, 1e20 by 118): the product with `pi / 180` is rounded to the double's precision before the sine reduces it.
/// A huge angle means the double it is (1e20 is 280 modulo 360). NaN and infinities give NaN.
pub fn radians_mod_turn(degrees: f64) -> f64 {
    (degrees % 360.0).to_radians()
}

/// Why a matrix is not a proper rotation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PoseError {
    /// An entry of the rotation or the position is NaN or infinite.
    #[error("the pose has a non-finite entry")]
    NonFinite,
    /// `R^T R` differs from the identity.
    #[error(
        "the rotation is not orthonormal: |R^T R - I| has an entry of {deviation:e} (tolerance {ROTATION_TOLERANCE:e})"
    )]
    NotOrthonormal {
        /// Largest absolute entry of `R^T R - I`.
        deviation: f64,
    },
    /// The determinant is not +1 (a reflection).
    #[error("the rotation has determinant {determinant}, not +1 (a reflection)")]
    NotProper {
        /// The determinant.
        determinant: f64,
    },
}

/// A rigid pose. See the module documentation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Proper rotation matrix.
    pub rotation: DMat3,
    /// Translation (mm).
    pub position: DVec3,
}

impl Default for Pose {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Pose {
    /// The identity pose.
    pub const IDENTITY: Pose = Pose { rotation: DMat3::IDENTITY, position: DVec3::ZERO };

    /// A checked pose.
    pub fn new(rotation: DMat3, position: DVec3) -> Result<Self, PoseError> {
        let pose = Pose { rotation, position };
        pose.check()?;
        Ok(pose)
    }

    /// A checked pose from rotation rows (`rows[i][j]` is row `i`, column `j`) and a position.
    pub fn from_rows(rows: [[f64; 3]; 3], position: DVec3) -> Result<Self, PoseError> {
        Self::new(DMat3::from_cols_array_2d(&rows).transpose(), position)
    }

    /// The rotation's rows (`rows[i][j]` is row `i`, column `j`), as written in stack files.
    pub fn rows(&self) -> [[f64; 3]; 3] {
        self.rotation.transpose().to_cols_array_2d()
    }

    /// A pure translation.
    pub fn from_translation(position: DVec3) -> Self {
        Pose { rotation: DMat3::IDENTITY, position }
    }

    /// A rotation by `theta` radians about the z axis (counter-clockwise seen from +z), no translation.
    pub fn from_z_rotation(theta: f64) -> Self {
        Pose { rotation: DMat3::from_rotation_z(theta), position: DVec3::ZERO }
    }

    /// Maps a point of the part's frame to the world: `rotation . v + position`.
    #[inline]
    pub fn apply(&self, v: DVec3) -> DVec3 {
        self.rotation * v + self.position
    }

    /// Rotates a direction (no translation).
    #[inline]
    pub fn apply_vector(&self, v: DVec3) -> DVec3 {
        self.rotation * v
    }

    /// `self` after `inner`: `(self.compose(inner)).apply(v) == self.apply(inner.apply(v))`.
    pub fn compose(&self, inner: &Pose) -> Pose {
        Pose { rotation: self.rotation * inner.rotation, position: self.rotation * inner.position + self.position }
    }

    /// The inverse pose (`R^T`, `-R^T p`), exact up to rounding for a proper rotation.
    pub fn inverse(&self) -> Pose {
        let rt = self.rotation.transpose();
        Pose { rotation: rt, position: -(rt * self.position) }
    }

    /// Checks that the rotation is proper (orthonormal, det +1) and everything is finite.
    pub fn check(&self) -> Result<(), PoseError> {
        if !self.rotation.is_finite() || !self.position.is_finite() {
            return Err(PoseError::NonFinite);
        }
        let gram = self.rotation.transpose() * self.rotation - DMat3::IDENTITY;
        let deviation = gram.to_cols_array().iter().fold(0.0f64, |m, x| m.max(x.abs()));
        if deviation > ROTATION_TOLERANCE {
            return Err(PoseError::NotOrthonormal { deviation });
        }
        let determinant = self.rotation.determinant();
        if (determinant - 1.0).abs() > ROTATION_TOLERANCE {
            return Err(PoseError::NotProper { determinant });
        }
        Ok(())
    }
}

/// The stack-file form of a pose: `{"position": [x, y, z], "rotation": [[row 0], [row 1], [row 2]]}`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PoseRecord {
    /// Position (mm).
    pub position: [f64; 3],
    /// Rotation rows.
    pub rotation: [[f64; 3]; 3],
}

impl From<&Pose> for PoseRecord {
    fn from(p: &Pose) -> Self {
        PoseRecord { position: p.position.to_array(), rotation: p.rows() }
    }
}

impl TryFrom<PoseRecord> for Pose {
    type Error = PoseError;
    fn try_from(r: PoseRecord) -> Result<Self, PoseError> {
        Pose::from_rows(r.rotation, DVec3::from_array(r.position))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn angles_are_reduced_modulo_a_turn_exactly() {
        // as given inside (-360, 360)
        for t in [0.0, 30.0, -30.0, 17.3, -359.75, 1e-300] {
            assert_eq!(radians_mod_turn(t).to_bits(), t.to_radians().to_bits(), "{t}");
        }
        // T and T + 360 k of one sign, k up to 2^40 (every sum a double: T has few fraction bits)
        for t in [17.25f64, 359.5, 0.125, 90.0] {
            for k in [1.0f64, 7.0, 1e6, 2f64.powi(40)] {
                let (up, down) = (t + 360.0 * k, -t - 360.0 * k);
                assert_eq!(up - 360.0 * k, t, "T + 360 k must be a double");
                assert_eq!(radians_mod_turn(up).to_bits(), radians_mod_turn(t).to_bits(), "{t} + 360 * {k}");
                assert_eq!(radians_mod_turn(down).to_bits(), radians_mod_turn(-t).to_bits(), "-{t} - 360 * {k}");
                // of opposite signs: the same rotation to rounding
                let r = DMat3::from_rotation_z(radians_mod_turn(t - 360.0 * k));
                let expected = DMat3::from_rotation_z(radians_mod_turn(t));
                assert!(r.abs_diff_eq(expected, 1e-15), "{t} - 360 * {k}");
            }
        }
        // the doubles 1e17 and 1e20 are 280 modulo 360 (100 000 000 000 000 000 000 = 277 777 777 777 777 777 * 360 + 280)
        for t in [1e17, 1e20, -1e20] {
            let r = DMat3::from_rotation_z(radians_mod_turn(t));
            let expected = DMat3::from_rotation_z(280f64.copysign(t).to_radians());
            assert!(r.abs_diff_eq(expected, 1e-15), "{t}: {r}");
        }
        assert!(radians_mod_turn(f64::NAN).is_nan() && radians_mod_turn(f64::INFINITY).is_nan());
    }

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() <= 1e-9 * (1.0 + a.length().max(b.length()))
    }

    fn pose_strategy() -> impl Strategy<Value = Pose> {
        (-3.2f64..3.2, -1.6f64..1.6, -3.2f64..3.2, prop::array::uniform3(-100.0f64..100.0)).prop_map(|(a, b, c, p)| {
            Pose { rotation: DMat3::from_euler(glam::EulerRot::ZYX, a, b, c), position: DVec3::from_array(p) }
        })
    }

    proptest! {
        #[test]
        fn compose_and_inverse(a in pose_strategy(), b in pose_strategy(), v in prop::array::uniform3(-50.0f64..50.0)) {
            let v = DVec3::from_array(v);
            prop_assert!(close(a.compose(&b).apply(v), a.apply(b.apply(v))));
            prop_assert!(close(a.inverse().apply(a.apply(v)), v));
            prop_assert!(close(a.compose(&a.inverse()).apply(v), v));
            prop_assert!(a.check().is_ok());
            prop_assert!(a.compose(&b).check().is_ok());
            let back = Pose::try_from(PoseRecord::from(&a)).expect("a proper rotation round-trips");
            prop_assert_eq!(back, a);
        }
    }

    #[test]
    fn z_rotation_and_rows() {
        let p = Pose::from_z_rotation(std::f64::consts::FRAC_PI_2);
        assert!(close(p.apply(DVec3::X), DVec3::Y));
        let rows = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        let q = Pose::from_rows(rows, DVec3::new(1.0, 2.0, 3.0)).expect("rotation");
        // row 0 is (0, -1, 0): x' = -y
        assert_eq!(q.apply(DVec3::new(5.0, 7.0, 0.0)), DVec3::new(-7.0 + 1.0, 5.0 + 2.0, 3.0));
        assert_eq!(q.rows(), rows);
    }

    #[test]
    fn rejects_bad_rotations() {
        let reflection = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]];
        assert!(
            matches!(Pose::from_rows(reflection, DVec3::ZERO), Err(PoseError::NotProper { determinant }) if determinant == -1.0)
        );
        let scaled = [[2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(matches!(Pose::from_rows(scaled, DVec3::ZERO), Err(PoseError::NotOrthonormal { .. })));
        let slightly = [[1.0 + 1e-7, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(matches!(Pose::from_rows(slightly, DVec3::ZERO), Err(PoseError::NotOrthonormal { .. })));
        let within = [[1.0 + 1e-12, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(Pose::from_rows(within, DVec3::ZERO).is_ok());
        assert_eq!(Pose::from_rows([[f64::NAN; 3]; 3], DVec3::ZERO), Err(PoseError::NonFinite));
        assert_eq!(Pose::new(DMat3::IDENTITY, DVec3::new(f64::INFINITY, 0.0, 0.0)), Err(PoseError::NonFinite));
    }
}

/// A part at a pose: a part in a stack, or a part placed in a scene (`world = pose.rotation . v + pose.position`).
#[derive(Debug, Clone, Copy)]
pub struct PlacedPart<'a> {
    /// The part, in its own coordinates.
    pub part: &'a crate::Part,
    /// Its pose (a proper rotation, and the translation in mm).
    pub pose: Pose,
}

impl<'a> PlacedPart<'a> {
    /// `part` at `pose`.
    pub fn new(part: &'a crate::Part, pose: Pose) -> Self {
        Self { part, pose }
    }
}
