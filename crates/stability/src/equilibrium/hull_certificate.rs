//! The vertical-force certificate of one rigid body on its contact points, for verdicts only (`docs/algorithms.md`,
//! "Stability, grasp and insertion"; \[A\] II-B (ii)): the closed-form test "c.g. over the support polygon" generalised
//! to inclined contacts that admit a vertical push.
//!
//! A rigid body of weight `m g` (c.g. `c`) on contact points `p_k` with normals `n_k` (pointing into the body) is in
//! equilibrium when *some* admissible force distribution balances it ([`super`]'s equations with `alpha = 0`). A
//! vertical force `f_k z` with `f_k >= 0` lies in the friction cone of `n_k` when `n_k` lies in the cone of the
//! vertical, `|n_k,xy| <= mu n_k,z` (its normal component is `f_k n_k,z`, its tangential one `f_k |n_k,xy|`), and
//! when `n_k` is vertical (within 1e-12, as the closed forms of [`super::tree`] count it). With vertical forces only
//! the horizontal force rows and the torsion row vanish identically, and the remaining three rows read
//! `sum f_k = m`, `sum f_k (p_k - c)_xy = 0`: a convex combination of the points' projections equal to `c_xy`.
//! So when `c_xy` lies in the convex hull of the admitted points' projections, the body is in equilibrium
//! (Carathéodory: three points of the hull suffice; the fan triangle of the hull holding `c_xy` gives them with
//! its barycentric weights). The test asks for `c_xy` strictly inside, by more than the body's tolerance
//! (`Rigid::tolerance`), so that the SOCP it replaces has a strictly feasible point of the same problem and
//! reports `Solved`; an equilibrium that needs friction, or a c.g. on or near the hull's boundary, is left to the
//! SOCP (the certificate is sufficient, never necessary, and never declares instability).
//!
//! Used for the support-tree edges of a verdict-only solve (`EquilibriumOptions::verdict_only`: the new part on its
//! supports in the planner's candidate test, and the edges of a step group): there it replaces the minimum-norm SOCP
//! whose forces are not wanted. Cost: O(K log K) for K points (one planar hull and one point-in-polygon test).

use super::{Point, Rigid};
use crate::polygon2d::{convex_hull_2d, cross, signed_boundary_distance};
use glam::{DVec2, DVec3};

/// Whether a vertical push (along `sign(n_z) z`) at the point lies in its friction cone (see the module
/// documentation).
pub(super) fn admits_vertical_force(p: &Point, mu: f64) -> bool {
    let n = p.frame[0];
    n.z.abs() >= 1.0 - 1e-12 || (n.z != 0.0 && n.x.hypot(n.y) <= mu * n.z.abs())
}

/// Vertical forces (world vectors on the body, in the order of `points`, zero at all but at most three points) that
/// balance the rigid `body` on `points` (each acting on the body: `b == 0`, no `a`), when the certificate of the
/// module documentation exists; `None` otherwise.
pub(super) fn hull_certificate(body: &Rigid, points: &[Point], mu: f64) -> Option<Vec<DVec3>> {
    if !points.iter().all(|p| p.b == 0 && p.a.is_none()) {
        return None;
    }
    let tol = body.tolerance();
    // upward pushes only: a downward one cannot help hold the body's weight in a convex combination
    let admitted: Vec<usize> =
        (0..points.len()).filter(|&k| points[k].frame[0].z > 0.0 && admits_vertical_force(&points[k], mu)).collect();
    if admitted.len() < 3 {
        return None;
    }
    let xy = |k: usize| DVec2::new(points[k].p.x, points[k].p.y);
    let projected: Vec<DVec2> = admitted.iter().map(|&k| xy(k)).collect();
    let hull = convex_hull_2d(&projected, tol);
    let c = DVec2::new(body.cg.x, body.cg.y);
    if hull.len() < 3 || signed_boundary_distance(c, &hull) <= tol {
        return None;
    }
    // the hull's vertices are input points: back to their indices
    let index_of = |v: DVec2| admitted.iter().copied().find(|&k| xy(k) == v);
    for k in 1..hull.len() - 1 {
        let (a, b, d) = (hull[0], hull[k], hull[k + 1]);
        let twice_area = cross(a, b, d);
        if twice_area <= 0.0 {
            continue;
        }
        let weights = [cross(b, d, c) / twice_area, cross(d, a, c) / twice_area, cross(a, b, c) / twice_area];
        if !weights.iter().all(|w| *w >= -1e-12) {
            continue;
        }
        let clamped = weights.map(|w| w.max(0.0));
        let total: f64 = clamped.iter().sum();
        let mut forces = vec![DVec3::ZERO; points.len()];
        for (v, w) in [a, b, d].into_iter().zip(clamped) {
            forces[index_of(v)?] += DVec3::Z * (body.mass * w / total);
        }
        return Some(forces);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::super::test_point as point;
    use super::super::{Problem, verdict_of};
    use super::*;
    use proptest::prelude::*;

    fn body(cg: DVec3) -> Rigid {
        Rigid { mass: 2.5, cg, aabb: (DVec3::new(-60.0, -60.0, 0.0), DVec3::new(60.0, 60.0, 40.0)) }
    }

    /// The certificate's forces balance the body (force and moment rows) and are vertical, nonnegative.
    fn assert_balances(body: &Rigid, points: &[Point], forces: &[DVec3]) {
        let total: DVec3 = forces.iter().sum();
        assert!((total - DVec3::Z * body.mass).length() <= 1e-9 * body.mass, "{total}");
        let moment: DVec3 = points.iter().zip(forces).map(|(p, f)| (p.p - body.cg).cross(*f)).sum();
        assert!(moment.length() <= 1e-9 * body.mass * 100.0, "{moment}");
        assert!(forces.iter().all(|f| f.x == 0.0 && f.y == 0.0 && f.z >= 0.0));
    }

    #[test]
    fn a_body_over_its_inclined_supports_is_certified_and_one_beside_them_is_not() {
        let tilt = |x: f64, y: f64| DVec3::new(x, y, 1.0);
        let points = vec![
            point(DVec3::new(-20.0, -20.0, 5.0), tilt(0.3, 0.0)),
            point(DVec3::new(20.0, -20.0, 8.0), tilt(-0.3, 0.1)),
            point(DVec3::new(0.0, 25.0, 2.0), tilt(0.0, -0.4)),
        ];
        let inside = body(DVec3::new(1.0, 0.0, 30.0));
        let forces = hull_certificate(&inside, &points, 0.5).expect("certified");
        assert_balances(&inside, &points, &forces);
        assert!(hull_certificate(&body(DVec3::new(40.0, 0.0, 30.0)), &points, 0.5).is_none());
        // a friction too small for the inclined normals: no vertical push is admissible
        assert!(hull_certificate(&inside, &points, 0.2).is_none());
    }

    /// A deterministic sample of bodies on 3-8 tilted points: many are certified, and each of those is stable by
    /// the SOCP.
    #[test]
    fn certified_bodies_of_a_sample_are_stable_by_the_socp() {
        let mut next = super::super::test_uniform(0x2545_f491_4f6c_dd1du64);
        let mut certified = 0;
        for _ in 0..300 {
            let k = next(3.0, 9.0) as usize;
            let points: Vec<Point> = (0..k)
                .map(|_| {
                    let p = DVec3::new(next(-50.0, 50.0), next(-50.0, 50.0), next(0.0, 20.0));
                    point(p, DVec3::new(next(-0.6, 0.6), next(-0.6, 0.6), 1.0))
                })
                .collect();
            let b = body(DVec3::new(next(-30.0, 30.0), next(-30.0, 30.0), next(25.0, 40.0)));
            let mu = next(0.3, 1.0);
            if let Some(forces) = hull_certificate(&b, &points, mu) {
                certified += 1;
                assert_balances(&b, &points, &forces);
                let refs: Vec<&Point> = points.iter().collect();
                let (status, _) = Problem::new(&[b], &[0], &refs, mu).solve(None).expect("solve");
                assert!(verdict_of(status).is_stable(), "{status:?}");
            }
        }
        assert!(certified >= 30, "only {certified} of 300 certified");
    }

    proptest! {
        /// Whenever the certificate exists, the SOCP of the same rigid-body problem ends `Solved` (the verdict does
        /// not change), and the certificate's forces balance the body.
        #[test]
        fn a_certified_body_is_stable_by_the_socp(
            raw in prop::collection::vec(((-50.0f64..50.0, -50.0f64..50.0, 0.0f64..20.0), (-0.8f64..0.8, -0.8f64..0.8)), 3..9),
            cg in (-40.0f64..40.0, -40.0f64..40.0, 25.0f64..40.0),
            mu in 0.05f64..1.2,
        ) {
            let points: Vec<Point> = raw
                .iter()
                .map(|&((x, y, z), (nx, ny))| point(DVec3::new(x, y, z), DVec3::new(nx, ny, 1.0)))
                .collect();
            let b = body(DVec3::new(cg.0, cg.1, cg.2));
            if let Some(forces) = hull_certificate(&b, &points, mu) {
                assert_balances(&b, &points, &forces);
                let refs: Vec<&Point> = points.iter().collect();
                let (status, _) = Problem::new(&[b], &[0], &refs, mu).solve(None).expect("solve");
                prop_assert!(verdict_of(status).is_stable(), "{status:?}");
            }
        }
    }
}
