//! Exact geometric predicates: the one place where orientation and coplanarity are decided.
//!
//! Every combinatorial decision of the kernel (which side of a plane a point is on, whether four points are
//! coplanar, whether three points are collinear) goes through this module. It wraps Shewchuk's adaptive exact
//! `orient2d`/`orient3d` (J. R. Shewchuk, *Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric
//! Predicates*, Discrete Comput. Geom. 18, 1997) from the `robust` crate: the sign returned is the sign of the
//! exact determinant of the given `f64` coordinates, never a rounded approximation. Cost: O(1), a few
//! floating-point operations in the common case, more only when the determinant is close to zero.
//!
//! Sign conventions used throughout stackplan:
//! * [`side`]`(a, b, c, p) > 0` iff `p` is strictly on the side of the plane through `a, b, c` that the normal
//!   `(b - a) x (c - a)` points to ("above" a counter-clockwise triangle seen from outside).

use glam::{DVec2, DVec3};
use std::cmp::Ordering;

fn c3(p: DVec3) -> robust::Coord3D<f64> {
    robust::Coord3D { x: p.x, y: p.y, z: p.z }
}

fn c2(x: f64, y: f64) -> robust::Coord<f64> {
    robust::Coord { x, y }
}

/// Exact side of `p` relative to the oriented plane through `a, b, c` (normal `(b - a) x (c - a)`).
///
/// Returns [`Ordering::Greater`] when `p` is strictly above (on the normal's side), [`Ordering::Less`] when strictly
/// below and [`Ordering::Equal`] when the four points are exactly coplanar (or `a, b, c` are collinear).
#[inline]
pub fn side(a: DVec3, b: DVec3, c: DVec3, p: DVec3) -> Ordering {
    // robust::orient3d is positive when p lies *below* the plane of a, b, c (counter-clockwise seen from above).
    let det = robust::orient3d(c3(a), c3(b), c3(c), c3(p));
    0.0f64.partial_cmp(&det).unwrap_or(Ordering::Equal)
}

/// The adaptive-exact determinant behind [`side`], with its sign: positive when `p` is above.
///
/// Its magnitude is six times the signed volume of the tetrahedron (a, b, c, p); only the sign is exact.
#[inline]
pub fn side_value(a: DVec3, b: DVec3, c: DVec3, p: DVec3) -> f64 {
    -robust::orient3d(c3(a), c3(b), c3(c), c3(p))
}

/// Exact 2-D orientation: `Greater` when `a, b, c` turn counter-clockwise, `Less` clockwise, `Equal` collinear.
#[inline]
pub fn orient2d(a: DVec2, b: DVec2, c: DVec2) -> Ordering {
    let det = robust::orient2d(c2(a.x, a.y), c2(b.x, b.y), c2(c.x, c.y));
    det.partial_cmp(&0.0).unwrap_or(Ordering::Equal)
}

/// Exactly whether three points in space are collinear (including coincident points).
///
/// Three points are collinear iff their projections onto the three coordinate planes are all collinear; each
/// projection is decided with the exact `orient2d`.
#[inline]
pub fn collinear(a: DVec3, b: DVec3, c: DVec3) -> bool {
    let xy = robust::orient2d(c2(a.x, a.y), c2(b.x, b.y), c2(c.x, c.y));
    if xy != 0.0 {
        return false;
    }
    let yz = robust::orient2d(c2(a.y, a.z), c2(b.y, b.z), c2(c.y, c.z));
    if yz != 0.0 {
        return false;
    }
    let zx = robust::orient2d(c2(a.z, a.x), c2(b.z, b.x), c2(c.z, c.x));
    zx == 0.0
}

/// Exactly whether four points are coplanar.
#[inline]
pub fn coplanar(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> bool {
    side(a, b, c, d) == Ordering::Equal
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn side_convention() {
        let a = DVec3::ZERO;
        let b = DVec3::X;
        let c = DVec3::Y;
        assert_eq!(side(a, b, c, DVec3::Z), Ordering::Greater);
        assert_eq!(side(a, b, c, -DVec3::Z), Ordering::Less);
        assert_eq!(side(a, b, c, DVec3::new(3.0, -7.0, 0.0)), Ordering::Equal);
        assert!(side_value(a, b, c, DVec3::Z) > 0.0);
    }

    #[test]
    fn exact_where_floats_are_not() {
        // Points on the plane x + y + z = 0.3 that floating-point evaluation of the plane equation gets wrong:
        // the exact predicate must still report a definite side for a point nudged by one ulp.
        let a = DVec3::new(0.1, 0.1, 0.1);
        let b = DVec3::new(0.2, 0.05, 0.05);
        let c = DVec3::new(0.05, 0.2, 0.05);
        let p = DVec3::new(0.1, 0.1, f64::from_bits(0.1f64.to_bits() + 1));
        let q = DVec3::new(0.1, 0.1, f64::from_bits(0.1f64.to_bits() - 1));
        assert_ne!(side(a, b, c, p), side(a, b, c, q));
        assert_eq!(side(a, b, c, a), Ordering::Equal);
    }

    #[test]
    fn collinearity() {
        let a = DVec3::new(1.0, 2.0, 3.0);
        let d = DVec3::new(0.5, -0.25, 2.0);
        assert!(collinear(a, a + d, a + d * 4.0));
        assert!(collinear(a, a, a));
        let far = a + d * 4.0;
        let nudged = DVec3::new(far.x, far.y, f64::from_bits(far.z.to_bits() + 1));
        assert!(!collinear(a, a + d, nudged));
        assert_eq!(orient2d(DVec2::ZERO, DVec2::X, DVec2::Y), Ordering::Greater);
    }
}
