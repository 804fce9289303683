//! The normal `(b - a) x (c - a)` of the plane through three points, accurate to a few units in the last place of the
//! result even when the triangle is a sliver.
//!
//! In plain `f64` each component of the cross product is a difference of two products that nearly cancel for a thin
//! triangle, so its rounding error is about `eps |b - a| |c - a|` whatever the component's own size: a triangle only
//! a few ulps wide (the facets the exact hull leaves between points that rounding moved off a common plane) gets a
//! normal pointing anywhere, and its plane cuts through the hull by tens of millimetres. Here the differences and the
//! products are carried exactly with error-free transformations (Knuth's two-sum, the fused-multiply-add two-product;
//! T. Ogita, S. M. Rump, S. Oishi, *Accurate sum and dot product*, SIAM J. Sci. Comput. 26(6), 2005) in double-double
//! arithmetic, and only the final sum is rounded: the error of each component is about `1e-32 |b - a| |c - a|`, far
//! below anything a triangle of `f64` vertices can produce as a non-zero exact value. O(1), about 150 flops.

use glam::DVec3;

/// A double-double number `hi + lo` with `|lo| <= ulp(hi) / 2`.
#[derive(Debug, Clone, Copy)]
struct Dd {
    hi: f64,
    lo: f64,
}

/// `a + b` exactly, as a rounded sum and its error (Knuth's two-sum).
#[inline]
fn two_sum(a: f64, b: f64) -> Dd {
    let s = a + b;
    let bb = s - a;
    Dd { hi: s, lo: (a - (s - bb)) + (b - bb) }
}

/// `a * b` exactly, as a rounded product and its error (one fused multiply-add).
#[inline]
fn two_product(a: f64, b: f64) -> Dd {
    let p = a * b;
    Dd { hi: p, lo: a.mul_add(b, -p) }
}

/// `x * y` in double-double: the exact product of the leading parts plus the cross terms, whose own rounding is of
/// the order of `eps^2 |x y|`.
#[inline]
fn mul(x: Dd, y: Dd) -> Dd {
    let p = two_product(x.hi, y.hi);
    let tail = p.lo + (x.hi * y.lo + x.lo * y.hi) + x.lo * y.lo;
    two_sum(p.hi, tail)
}

/// `x - y` in double-double.
#[inline]
fn sub(x: Dd, y: Dd) -> Dd {
    let s = two_sum(x.hi, -y.hi);
    let tail = s.lo + (x.lo - y.lo);
    two_sum(s.hi, tail)
}

/// The un-normalised normal `(b - a) x (c - a)`, each component rounded once from its double-double value (see the
/// module documentation). Zero exactly when the three points are exactly collinear (or a component's true value is
/// below about `1e-32 |b - a| |c - a|`).
pub fn accurate_cross(a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let d1 = [two_sum(b.x, -a.x), two_sum(b.y, -a.y), two_sum(b.z, -a.z)];
    let d2 = [two_sum(c.x, -a.x), two_sum(c.y, -a.y), two_sum(c.z, -a.z)];
    let component = |i: usize, j: usize| {
        let v = sub(mul(d1[i], d2[j]), mul(d1[j], d2[i]));
        v.hi + v.lo
    };
    DVec3::new(component(1, 2), component(2, 0), component(0, 1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::predicates::side;
    use std::cmp::Ordering;

    #[test]
    fn equals_the_plain_cross_product_on_exact_input() {
        let (a, b, c) = (DVec3::new(1.0, 2.0, 3.0), DVec3::new(4.0, -1.0, 0.5), DVec3::new(-2.0, 0.25, 8.0));
        assert_eq!(accurate_cross(a, b, c), (b - a).cross(c - a));
    }

    #[test]
    fn collinear_points_give_zero() {
        // (exactly representable sums: the three points are exactly collinear)
        let (a, d) = (DVec3::new(0.5, 1.25, -3.0), DVec3::new(1.0, 3.0, -2.0));
        assert_eq!(accurate_cross(a, a + d, a + 4.0 * d), DVec3::ZERO);
    }

    /// A sliver a few ulps wide: the plain cross product's direction is off by far more than the accurate one's, and
    /// the accurate plane agrees with the exact orientation of points just off it.
    #[test]
    fn a_sliver_gets_its_exact_plane() {
        let a = DVec3::new(12.345678901234567, -30.447213595499935, 0.4472135954999581);
        let b = DVec3::new(85.82794370920239, -50.447213595499925, 40.44721359549996);
        // c: the midpoint of a and b moved by about one ulp across the segment
        let m = 0.5 * (a + b);
        let c = DVec3::new(m.x, f64::from_bits(m.y.to_bits() + 3), m.z);
        let n = accurate_cross(a, b, c);
        assert!(n.length() > 0.0);
        let u = n.normalize();
        // points a millimetre above and below the accurate plane are exactly above and below the triangle's plane
        let centre = (a + b + c) / 3.0;
        assert_eq!(side(a, b, c, centre + u * 1e-3), Ordering::Greater);
        assert_eq!(side(a, b, c, centre - u * 1e-3), Ordering::Less);
        // every vertex lies on the accurate plane within a few ulps of the coordinates
        let d = u.dot(a);
        for v in [a, b, c] {
            assert!((u.dot(v) - d).abs() < 1e-12, "{}", u.dot(v) - d);
        }
    }
}
