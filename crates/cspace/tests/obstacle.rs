//! Property tests of the obstacle construction against independent oracles: an LP (clarabel) decides whether the
//! interiors of `R A + p` and `B` intersect; a QP gives Euclidean distances to the hull of the difference points; the
//! exact-predicate hull of the differences gives the reference volume and vertex set.

use crate::common;

use common::*;
use glam::{DMat3, DVec2, DVec3};
use proptest::prelude::*;
use stackplan_cspace::minkowski::{FaceKind, Feature, Obstacle, Route, facet_bound, obstacle, obstacle_by_hull};
use stackplan_cspace::offset::{clearance, insertion, slice};
use stackplan_geom::polytope::Containment;
use stackplan_geom::{ConvexPolytope, Tolerance, convex_hull, convex_hull_merged};

fn any_pair() -> impl Strategy<Value = (ConvexPolytope, ConvexPolytope)> {
    prop_oneof![(dyadic_cloud(4..14), dyadic_cloud(4..14)), (any_box(), any_box()), prism_pair(), prism_pair(),]
}

fn is_exact_rotation(r: &DMat3) -> bool {
    r.to_cols_array().iter().all(|x| *x == 0.0 || x.abs() == 1.0)
}

/// Structure, provenance and face kinds of `o`, and agreement with the hull route.
fn check_structure(a: &ConvexPolytope, r: DMat3, b: &ConvexPolytope, o: &Obstacle) -> Result<(), TestCaseError> {
    if o.route() != Route::GaussMap {
        let reason = stackplan_cspace::minkowski::gauss_map_obstacle(a, r, b).err();
        return Err(TestCaseError::fail(format!("hull route taken: {reason:?}; r = {r:?}")));
    }
    let c = o.polytope();
    prop_assert!(c.validate().is_ok(), "invalid obstacle: {:?}", c.validate());
    prop_assert!(c.faces().len() <= facet_bound(a.faces().len(), b.faces().len()));
    for (v, &[i, j]) in o.vertex_pairs().iter().enumerate() {
        let expected = b.vertices()[j] - r * a.vertices()[i];
        prop_assert_eq!(c.vertices()[v], expected, "vertex {} provenance", v);
    }
    for (fi, (face, kind)) in c.faces().iter().zip(o.face_kinds()).enumerate() {
        let n = face.plane.normal;
        let pairs: Vec<[usize; 2]> = face.vertices.iter().map(|&v| o.vertex_pairs()[v]).collect();
        let fixed = kind.fixed_feature();
        let moving = kind.moving_feature();
        prop_assert!(fixed.is_some() && moving.is_some(), "face {} unclassified", fi);
        match fixed {
            Some(Feature::Face(g)) => {
                prop_assert_eq!(n, b.faces()[g].plane.normal, "fixed face normal of face {}", fi);
                prop_assert!(pairs.iter().all(|p| b.faces()[g].vertices.contains(&p[1])));
            }
            Some(Feature::Edge(e)) => {
                let ev = b.edges()[e].vertices;
                let d = (b.vertices()[ev[1]] - b.vertices()[ev[0]]).normalize();
                prop_assert!(n.dot(d).abs() < 1e-9, "face {} not parallel to B edge {}", fi, e);
                prop_assert!(pairs.iter().all(|p| ev.contains(&p[1])));
            }
            Some(Feature::Vertex(j)) => prop_assert!(pairs.iter().all(|p| p[1] == j)),
            None => {}
        }
        match moving {
            Some(Feature::Face(f)) => {
                let m = -(r * a.faces()[f].plane.normal).normalize();
                prop_assert!((n - m).length() <= 1e-9, "moving face normal of face {}", fi);
                if matches!(kind, FaceKind::MovingFace { .. }) {
                    prop_assert_eq!(n, m);
                }
                prop_assert!(pairs.iter().all(|p| a.faces()[f].vertices.contains(&p[0])));
            }
            Some(Feature::Edge(e)) => {
                let ev = a.edges()[e].vertices;
                let d = (r * (a.vertices()[ev[1]] - a.vertices()[ev[0]])).normalize();
                prop_assert!(n.dot(d).abs() < 1e-9, "face {} not parallel to A edge {}", fi, e);
                prop_assert!(pairs.iter().all(|p| ev.contains(&p[0])));
            }
            Some(Feature::Vertex(i)) => prop_assert!(pairs.iter().all(|p| p[0] == i)),
            None => {}
        }
    }
    let h = obstacle_by_hull(a, r, b).map_err(|e| TestCaseError::fail(e.to_string()))?;
    let (vo, vh) = (c.volume(), h.polytope().volume());
    prop_assert!((vo - vh).abs() <= 1e-9 * vh.abs().max(1.0), "volume {} vs hull {}", vo, vh);
    if is_exact_rotation(&r) {
        let key = |p: &ConvexPolytope| {
            let mut v: Vec<[u64; 3]> =
                p.vertices().iter().map(|x| [x.x.to_bits(), x.y.to_bits(), x.z.to_bits()]).collect();
            v.sort_unstable();
            v
        };
        prop_assert_eq!(key(c), key(h.polytope()), "vertex sets differ from the exact hull");
        prop_assert_eq!(c.faces().len(), h.polytope().faces().len());
    }
    Ok(())
}

/// Points to classify: vertices, face centroids, and those pushed in and out by `eps`.
fn probe_points(o: &Obstacle, eps: f64) -> Vec<(DVec3, Containment)> {
    let c = o.polytope();
    let centre = c.vertex_centroid();
    let mut out = Vec::new();
    for (k, f) in c.faces().iter().enumerate().take(8) {
        let centroid = f.vertices.iter().map(|&v| c.vertices()[v]).sum::<DVec3>() / f.vertices.len() as f64;
        out.push((centroid, Containment::Boundary));
        out.push((centroid + f.plane.normal * eps, Containment::Exterior));
        out.push((centroid - f.plane.normal * eps, Containment::Interior));
        let v = c.vertices()[f.vertices[k % f.vertices.len()]];
        out.push((v, Containment::Boundary));
        out.push((v + (centre - v).normalize() * eps, Containment::Interior));
        out.push((v - (centre - v).normalize() * eps, Containment::Exterior));
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases(64)))]

    /// p strictly inside C iff the interiors intersect (LP), on the boundary iff they touch.
    #[test]
    fn obstacle_matches_lp_oracle(
        (a, b) in any_pair(),
        r in any_rotation(),
        samples in prop::collection::vec((0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0), 8),
    ) {
        let o = obstacle(&a, r, &b).map_err(|e| TestCaseError::fail(e.to_string()))?;
        check_structure(&a, r, &b, &o)?;
        let tol = o.polytope().tolerance();
        for (p, expected) in probe_points(&o, 1e-3) {
            prop_assert_eq!(o.classify(p, tol), expected, "probe {:?}", p);
            let Some(t) = overlap_slack(&a, r, p, &b) else { continue };
            match expected {
                Containment::Interior => prop_assert!(t > 1e-8, "inside C but LP slack {} at {:?}", t, p),
                Containment::Exterior => prop_assert!(t < -1e-8, "outside C but LP slack {} at {:?}", t, p),
                Containment::Boundary => prop_assert!(t.abs() <= 1e-7, "boundary but LP slack {} at {:?}", t, p),
            }
        }
        let (lo, hi) = o.polytope().aabb();
        let (lo, hi) = (lo - DVec3::splat(0.5), hi + DVec3::splat(0.5));
        for (u, v, w) in samples {
            let p = lo + (hi - lo) * DVec3::new(u, v, w);
            let margin = o.polytope().planes().map(|pl| pl.signed_distance(p)).fold(f64::NEG_INFINITY, f64::max);
            if margin.abs() < 1e-4 {
                continue;
            }
            let Some(t) = overlap_slack(&a, r, p, &b) else { continue };
            prop_assert_eq!(margin < 0.0, t > 0.0, "p {:?}: margin {} LP slack {}", p, margin, t);
            prop_assert!(t.abs() > 1e-9);
        }
    }

    /// Clearance: within delta of C (Euclidean) implies inside the grown obstacle; the planes are supporting planes
    /// (plane distance <= Euclidean distance); over a face interior the offset is exact.
    #[test]
    fn clearance_is_conservative_and_exact_on_faces(
        (a, b) in any_pair(),
        r in any_rotation(),
        delta in prop_oneof![Just(0.1f64), Just(0.5f64)],
        samples in prop::collection::vec((0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0), 6),
    ) {
        let o = obstacle(&a, r, &b).map_err(|e| TestCaseError::fail(e.to_string()))?;
        let grown = clearance(&o, delta);
        let pts = differences(&a, r, &b);
        let (lo, hi) = o.polytope().aabb();
        let (lo, hi) = (lo - DVec3::splat(2.0 * delta), hi + DVec3::splat(2.0 * delta));
        for (u, v, w) in samples {
            let p = lo + (hi - lo) * DVec3::new(u, v, w);
            let Some(d) = distance_to_hull(&pts, p) else { continue };
            let violation = o.polytope().planes().map(|pl| pl.signed_distance(p)).fold(f64::NEG_INFINITY, f64::max);
            if d > 1e-6 {
                prop_assert!(violation <= d + 1e-6, "plane distance {} exceeds Euclidean {}", violation, d);
            }
            if d < delta - 1e-6 {
                prop_assert!(grown.max_violation(p) <= 1e-9, "within delta ({}) but outside the grown obstacle", d);
            }
            if grown.max_violation(p) > 1e-6 {
                prop_assert!(d > delta, "outside the grown obstacle but only {} away", d);
            }
        }
        let c = o.polytope();
        for f in c.faces().iter().take(6) {
            let centroid = f.vertices.iter().map(|&v| c.vertices()[v]).sum::<DVec3>() / f.vertices.len() as f64;
            let p = centroid + f.plane.normal * delta;
            prop_assert!(grown.max_violation(p).abs() <= 1e-9);
            if let Some(d) = distance_to_hull(&pts, p) {
                prop_assert!((d - delta).abs() <= 1e-6, "face offset point at distance {} not {}", d, delta);
            }
        }
    }

    /// Insertion: p is inside the insertion obstacle iff the vertical path from above is blocked (sampled).
    #[test]
    fn insertion_obstacle_matches_vertical_path(
        (a, b) in any_pair(),
        r in any_rotation(),
        samples in prop::collection::vec((0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0), 10),
    ) {
        let o = obstacle(&a, r, &b).map_err(|e| TestCaseError::fail(e.to_string()))?;
        let ins = insertion(o.polytope());
        let tol = Tolerance::for_scale(1.0);
        let (lo, hi) = o.polytope().aabb();
        let (lo, hi) = (lo - DVec3::new(0.5, 0.5, 2.0), hi + DVec3::splat(0.5));
        const STEPS: usize = 4000;
        for (u, v, w) in samples {
            let p = lo + (hi - lo) * DVec3::new(u, v, w);
            let m = ins.max_violation(p);
            if m.abs() < 0.02 {
                continue;
            }
            let top = o.polytope().aabb().1.z;
            let blocked = (0..=STEPS).any(|k| {
                let q = DVec3::new(p.x, p.y, p.z + (top - p.z).max(0.0) * k as f64 / STEPS as f64);
                o.classify(q, tol) == Containment::Interior
            });
            prop_assert_eq!(m < 0.0, blocked, "p {:?}: insertion margin {} but sampled path blocked = {}", p, m, blocked);
        }
    }

    /// Slices: a point of the plane is in the polygon iff it is in the obstacle.
    #[test]
    fn slices_agree_with_the_obstacle(
        (a, b) in any_pair(),
        r in any_rotation(),
        h in 0.0f64..1.0,
        samples in prop::collection::vec((0.0f64..1.0, 0.0f64..1.0), 12),
    ) {
        let o = obstacle(&a, r, &b).map_err(|e| TestCaseError::fail(e.to_string()))?;
        let (lo, hi) = o.polytope().aabb();
        let z = lo.z + (hi.z - lo.z) * h;
        let poly = slice(o.polytope(), z);
        prop_assert!(poly.len() >= 3 || h == 0.0);
        for q in &poly {
            let m = o.polytope().planes().map(|pl| pl.signed_distance(q.extend(z))).fold(f64::NEG_INFINITY, f64::max);
            prop_assert!(m.abs() <= 1e-9, "slice vertex off the boundary by {}", m);
        }
        let inside_2d = |x: DVec2| -> f64 {
            (0..poly.len())
                .map(|k| {
                    let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
                    (b - a).perp_dot(x - a) / (b - a).length()
                })
                .fold(f64::INFINITY, f64::min)
        };
        for (u, v) in samples {
            let x = lo.truncate() + (hi.truncate() - lo.truncate()) * DVec2::new(u, v);
            let m3 = o.polytope().planes().map(|pl| pl.signed_distance(x.extend(z))).fold(f64::NEG_INFINITY, f64::max);
            let d2 = if poly.len() >= 3 { inside_2d(x) } else { -1.0 };
            if m3.abs() < 1e-6 || d2.abs() < 1e-6 {
                continue;
            }
            prop_assert_eq!(m3 < 0.0, d2 > 0.0, "slice disagrees at {:?}", x);
        }
    }
}

/// A convex piece and a copy of it turned by the same general rotation `Q` and moved: the stack of sheet-metal parts
/// in one orientation (a Triangle nest, or `place` of a part onto a copy of itself), where faces and edges of the two
/// are parallel only up to rounding in directions that are not axes. Returns (A, R, B) with A moving by `R`: either
/// `A = Q P` and `R = I`, or `A = P` and `R = Q` (the planner's split into a resting rotation and a turn).
fn copies_in_one_orientation() -> impl Strategy<Value = (ConvexPolytope, DMat3, ConvexPolytope, bool)> {
    let sheet =
        (5.0f64..60.0, 5.0f64..60.0, 0.5f64..4.0).prop_map(|(x, y, z)| cuboid(DVec3::ZERO, DVec3::new(x, y, z)));
    (
        prop_oneof![sheet, any_box(), dyadic_cloud(5..10)],
        (-3.2f64..3.2, -1.6f64..1.6, -3.2f64..3.2),
        (-80.0f64..80.0, -80.0f64..80.0, -80.0f64..80.0),
        any::<bool>(),
        any::<bool>(),
    )
        .prop_filter_map("a copy without a hull", |(piece, (z, y, x), (tx, ty, tz), turn_by_r, exact)| {
            let q = DMat3::from_euler(glam::EulerRot::ZYX, z, y, x);
            // each copy as a part file gives it: the hull of its turned, rounded vertices with the rounding creases
            // merged (whose face planes are fitted to those points, so the two copies' normals differ by more than
            // the rotation's rounding); `exact` copies are the exact hulls, whose faces are split into facets
            let hull = |t: DVec3| {
                let points: Vec<DVec3> = piece.vertices().iter().map(|v| q * *v + t).collect();
                if exact { convex_hull(&points) } else { convex_hull_merged(&points) }.map(|h| h.polytope)
            };
            let (Ok(turned), Ok(fixed)) = (hull(DVec3::ZERO), hull(DVec3::new(tx, ty, tz))) else {
                return None;
            };
            Some(if turn_by_r { (piece, q, fixed, exact) } else { (turned, DMat3::IDENTITY, fixed, exact) })
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases(64)))]

    /// Whatever route builds it (the overlay, or the exact hull of the differences when the overlay of these nearly
    /// parallel features is inconsistent), the obstacle's planes support every difference point and its interior is
    /// the LP oracle's. Before the hull computed its face planes accurately, the fallback's sliver faces got planes
    /// that cut the obstacle by tens of millimetres (`place` then put a part into its copy), or the hull failed.
    #[test]
    fn copies_in_one_orientation_match_the_lp_oracle(
        (a, r, b, exact) in copies_in_one_orientation(),
        samples in prop::collection::vec((0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0), 10),
    ) {
        let o = obstacle(&a, r, &b).map_err(|e| TestCaseError::fail(e.to_string()))?;
        let c = o.polytope();
        // copies as the readers build them have no creases, and the overlay pairs their parallel faces
        if !exact {
            prop_assert_eq!(o.route(), Route::GaussMap, "{:?}", stackplan_cspace::minkowski::gauss_map_obstacle(&a, r, &b).err());
        }
        let pts = differences(&a, r, &b);
        let scale = stackplan_geom::tolerance::bounding_diagonal(&pts);
        for (k, f) in c.faces().iter().enumerate() {
            let above = pts.iter().map(|p| f.plane.signed_distance(*p)).fold(f64::NEG_INFINITY, f64::max);
            prop_assert!(above <= 1e-9 * scale, "face {} ({:?}): a difference point {} above it", k, o.route(), above);
        }
        let (lo, hi) = c.aabb();
        for (u, v, w) in samples {
            let p = lo + (hi - lo) * DVec3::new(u, v, w);
            let margin = c.planes().map(|pl| pl.signed_distance(p)).fold(f64::NEG_INFINITY, f64::max);
            if margin.abs() < 1e-4 {
                continue;
            }
            let Some(t) = overlap_slack(&a, r, p, &b) else { continue };
            prop_assert_eq!(margin < 0.0, t > 0.0, "p {:?}: margin {} LP slack {} ({:?})", p, margin, t, o.route());
        }
    }
}

/// The audit's case: the Triangle part's inclined pieces against themselves, turned by 1e-9 to 1e-5 rad about `z`
/// from the critical orientations 0 and 90 degrees, where their faces and edges are nearly parallel: every obstacle's
/// planes support its difference points within the tolerance. Planes fitted to the pieces' points (planar only to
/// rounding) are off by up to 1e-7 rad instead of the hull's accurate ones, and then the obstacle of pair (2, 2) at
/// 1e-7 degree has a difference point 8.4e-4 mm (over 2000 tolerances) above an edge-edge face: `place` would report
/// a position penetrating by that much as touching.
#[test]
fn triangle_pieces_just_off_critical_orientations() {
    let part = stackplan_geom::examples::part_by_name("triangle", stackplan_geom::Decomposition::default())
        .expect("the Triangle example");
    let mut worst: f64 = 0.0;
    for base in [0.0, std::f64::consts::FRAC_PI_2] {
        for turn in [1e-9, 1e-8, 1e-7f64.to_radians(), 1e-7, 1e-6, 1e-5, -1e-7, -1e-6] {
            let r = DMat3::from_rotation_z(base + turn);
            for a in part.components() {
                for b in part.components() {
                    let o = obstacle(a, r, b).expect("obstacle");
                    let pts = differences(a, r, b);
                    let tol = Tolerance::for_scale(stackplan_geom::tolerance::bounding_diagonal(&pts)).linear;
                    for f in o.polytope().faces() {
                        let above = pts.iter().map(|p| f.plane.signed_distance(*p)).fold(f64::NEG_INFINITY, f64::max);
                        worst = worst.max(above / tol);
                    }
                }
            }
        }
    }
    assert!(worst <= 1.0, "a difference point {worst} tolerances above a face plane");
}

#[test]
fn face_count_bound_and_regressions() {
    assert_eq!(facet_bound(6, 6), 4 * 36 - 54 - 54 + 26);
    let b = cuboid(DVec3::ZERO, DVec3::new(100.0, 50.0, 2.0));
    let a = cuboid(DVec3::ZERO, DVec3::new(80.0, 60.0, 2.0));
    // (theta, vertices, faces, volume)
    let cases = [(0.0, 8, 6, 180.0 * 110.0 * 4.0), (90.0, 8, 6, 160.0 * 130.0 * 4.0)];
    for (deg, nv, nf, vol) in cases {
        let r = if deg == 0.0 { DMat3::IDENTITY } else { axis_rotation_z90() };
        let o = obstacle(&a, r, &b).expect("obstacle");
        assert_eq!((o.polytope().vertices().len(), o.polytope().faces().len()), (nv, nf), "theta {deg}");
        assert!((o.polytope().volume() - vol).abs() < 1e-6 * vol);
    }
    // a generic angle: octagonal prism, 16 vertices, 10 faces; volume = area of the octagon times the height
    let r = DMat3::from_rotation_z(30f64.to_radians());
    let o = obstacle(&a, r, &b).expect("obstacle");
    assert_eq!((o.polytope().vertices().len(), o.polytope().faces().len()), (16, 10));
    let s = slice(o.polytope(), 0.0);
    let area: f64 = (0..s.len()).map(|k| s[k].perp_dot(s[(k + 1) % s.len()])).sum::<f64>() / 2.0;
    assert!((o.polytope().volume() - area * 4.0).abs() < 1e-6 * area);
    let kinds: Vec<&str> = o.face_kinds().iter().map(|k| k.name()).collect();
    assert_eq!(kinds.iter().filter(|k| **k == "face_face").count(), 2);
    assert_eq!(kinds.iter().filter(|k| **k == "fixed_face_moving_edge").count(), 4);
    assert_eq!(kinds.iter().filter(|k| **k == "moving_face_fixed_edge").count(), 4);
    // general rotation: all generic kinds appear and the bound holds
    let r = DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
    let o = obstacle(&a, r, &b).expect("obstacle");
    o.polytope().validate().expect("valid");
    assert!(o.polytope().faces().len() <= facet_bound(6, 6));
    for name in ["fixed_face", "moving_face", "edge_edge"] {
        assert!(o.face_kinds().iter().any(|k| k.name() == name), "no {name} face");
    }
}

fn axis_rotation_z90() -> DMat3 {
    DMat3::from_cols(DVec3::Y, -DVec3::X, DVec3::Z)
}

#[test]
fn flat_input_is_an_error_not_a_panic() {
    let a = cuboid(DVec3::ZERO, DVec3::ONE);
    assert!(obstacle(&a, DMat3::from_cols(DVec3::NAN, DVec3::Y, DVec3::Z), &a).is_err());
}
