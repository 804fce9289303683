//! Separating-axis test for convex polytopes, optionally swept along a vector.
//!
//! For two convex polytopes the separating-axis theorem (S. Gottschalk, M. Lin, D. Manocha, *OBBTree*, SIGGRAPH
//! 1996; C. Ericson, *Real-Time Collision Detection*, 2005, 5.2.1) needs only the face normals of each and the cross
//! products of their edge directions: these are exactly the face normals of the Minkowski difference `B (+) (-A)`
//! (\[A\] App. B). The largest signed separation over these axes is
//!
//! * positive iff the polytopes are disjoint (and then a lower bound of their distance),
//! * minus the exact penetration depth (the minimum translation distance) when they overlap,
//!
//! because the Minkowski difference is the intersection of its face half-spaces and the penetration depth is the
//! distance from the origin to its boundary. A polytope swept along `s` is `C (+) [0, s]`: its faces are C's faces
//! and parallelograms spanned by C's edges and `s`, its edges C's edges and `s`, and its support interval on an axis
//! `n` is C's interval extended by `min(0, n.s)` and `max(0, n.s)` — so sweeps (insertion from above, \[A\] condition
//! (iv)) need no hull construction. Cost: O((F_A + F_B + E_A E_B) (V_A + V_B)) with directions deduplicated up to sign.

use crate::world::WorldComponent;
use glam::DVec3;

/// The result of the separating-axis test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Separation {
    /// Largest signed separation over the candidate axes: `> 0` disjoint (a lower bound of the distance), `< 0` minus
    /// the penetration depth.
    pub distance: f64,
    /// The unit axis achieving it, pointing from the first shape to the second.
    pub axis: DVec3,
}

/// A convex shape for the test: a world component, optionally swept along `sweep`.
#[derive(Debug, Clone, Copy)]
pub struct Shape<'a> {
    /// The component.
    pub component: &'a WorldComponent,
    /// Sweep vector (zero for none).
    pub sweep: DVec3,
}

impl<'a> Shape<'a> {
    /// The component itself.
    pub fn of(component: &'a WorldComponent) -> Self {
        Self { component, sweep: DVec3::ZERO }
    }

    /// Support interval `[min, max]` of `n . x` over the shape.
    #[inline]
    pub fn interval(&self, n: DVec3) -> (f64, f64) {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for v in self.component.polytope.vertices() {
            let d = n.dot(*v);
            lo = lo.min(d);
            hi = hi.max(d);
        }
        let s = n.dot(self.sweep);
        (lo + s.min(0.0), hi + s.max(0.0))
    }
}

/// Signed separation of `a` and `b` along `n` (either orientation), with the oriented axis.
#[inline]
pub(crate) fn separation_along(a: &Shape<'_>, b: &Shape<'_>, n: DVec3) -> (f64, DVec3) {
    let (alo, ahi) = a.interval(n);
    let (blo, bhi) = b.interval(n);
    let forward = blo - ahi;
    let backward = alo - bhi;
    if forward >= backward { (forward, n) } else { (backward, -n) }
}

/// The separating-axis test of the module documentation.
///
/// Ties between axes keep the first one found in the order: faces of `a`, faces of `b`, sweep faces, edge crosses —
/// so a face contact is reported with the face's normal. (A contact's normal is chosen again among the axes tied
/// within the contact tolerance, [`crate::contacts::contact_axis`].)
pub fn separation(a: &Shape<'_>, b: &Shape<'_>) -> Separation {
    let mut best = Separation { distance: f64::NEG_INFINITY, axis: DVec3::Z };
    // a tie within this relative amount keeps the earlier (face) axis
    let consider = |n: DVec3, best: &mut Separation| {
        let (d, axis) = separation_along(a, b, n);
        if d > best.distance + 1e-12 * d.abs().max(1.0) {
            *best = Separation { distance: d, axis };
        }
    };
    for &n in &a.component.normals {
        consider(n, &mut best);
    }
    for &n in &b.component.normals {
        consider(n, &mut best);
    }
    let mut edges_a: Vec<DVec3> = a.component.edge_directions.clone();
    let mut edges_b: Vec<DVec3> = b.component.edge_directions.clone();
    if a.sweep != DVec3::ZERO {
        let s = a.sweep.normalize();
        for &e in &a.component.edge_directions {
            let n = e.cross(s);
            if n.length() > 1e-9 {
                consider(n.normalize(), &mut best);
            }
        }
        edges_a.push(s);
    }
    if b.sweep != DVec3::ZERO {
        let s = b.sweep.normalize();
        for &e in &b.component.edge_directions {
            let n = e.cross(s);
            if n.length() > 1e-9 {
                consider(n.normalize(), &mut best);
            }
        }
        edges_b.push(s);
    }
    for &ea in &edges_a {
        for &eb in &edges_b {
            let n = ea.cross(eb);
            if n.length() > 1e-9 {
                consider(n.normalize(), &mut best);
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use stackplan_geom::convex_hull;

    pub(crate) fn cuboid(lo: DVec3, hi: DVec3) -> WorldComponent {
        let pts: Vec<DVec3> = (0..8)
            .map(|i| {
                DVec3::new(
                    if i & 1 == 0 { lo.x } else { hi.x },
                    if i & 2 == 0 { lo.y } else { hi.y },
                    if i & 4 == 0 { lo.z } else { hi.z },
                )
            })
            .collect();
        WorldComponent::new(convex_hull(&pts).expect("box").polytope)
    }

    #[test]
    fn boxes() {
        let a = cuboid(DVec3::ZERO, DVec3::ONE);
        let b = cuboid(DVec3::new(0.5, 0.2, 1.0), DVec3::new(1.5, 0.8, 2.0));
        let s = separation(&Shape::of(&a), &Shape::of(&b));
        assert!(s.distance.abs() < 1e-15);
        assert!((s.axis - DVec3::Z).length() < 1e-12);
        let c = cuboid(DVec3::new(0.8, 0.0, 0.9), DVec3::new(2.0, 1.0, 2.0));
        let s = separation(&Shape::of(&a), &Shape::of(&c));
        assert!((s.distance + 0.1).abs() < 1e-12, "{s:?}");
        let d = cuboid(DVec3::new(3.0, 0.0, 0.0), DVec3::new(4.0, 1.0, 1.0));
        let s = separation(&Shape::of(&a), &Shape::of(&d));
        assert!((s.distance - 2.0).abs() < 1e-12);
        assert!((s.axis - DVec3::X).length() < 1e-12);
    }

    #[test]
    fn sweep_hits_what_is_above() {
        let a = cuboid(DVec3::ZERO, DVec3::ONE);
        let above = cuboid(DVec3::new(0.5, 0.5, 5.0), DVec3::new(2.0, 2.0, 6.0));
        assert!(separation(&Shape::of(&a), &Shape::of(&above)).distance > 1.0);
        let swept = Shape { component: &a, sweep: DVec3::Z * 10.0 };
        let s = separation(&swept, &Shape::of(&above));
        assert!((s.distance + 0.5).abs() < 1e-12, "{s:?}");
    }
}
