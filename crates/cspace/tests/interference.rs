//! Interference pairs (BVH broad phase + separating axes) against an independent all-pairs LP classification, on
//! random box stacks with exact quarter-turn and random rotations and grid positions (touching is frequent).

use crate::common;

use common::*;
use glam::{DMat3, DVec3};
use proptest::prelude::*;
use stackplan_cspace::interference::{PairContact, PlacedConvex, PlacedScene, classify_pair};
use stackplan_geom::{ConvexPolytope, Part, PartOrigin};
use stackplan_geom::{PlacedPart, Pose};

fn box_part() -> impl Strategy<Value = Part> {
    prop::collection::vec(any_box(), 1..4)
        .prop_map(|c| Part::from_components("boxes", c, 1.0, PartOrigin::ConvexPieces).expect("part"))
}

fn z_rotation() -> impl Strategy<Value = DMat3> {
    prop_oneof![
        (0usize..4).prop_map(|k| {
            let (c, s) = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)][k];
            DMat3::from_cols(DVec3::new(c, s, 0.0), DVec3::new(-s, c, 0.0), DVec3::Z)
        }),
        (-3.2f64..3.2).prop_map(DMat3::from_rotation_z),
    ]
}

fn grid_position() -> impl Strategy<Value = DVec3> {
    (-4i32..4, -4i32..4, -2i32..2).prop_map(|(x, y, z)| DVec3::new(x as f64, y as f64, z as f64) * 0.5)
}

/// `Some(contact)` by the LP: +1 penetrating, 0 touching, -1 separated; `None` if the solver is unsure or the slack
/// is too close to a threshold to call.
fn lp_contact(a: &ConvexPolytope, r: DMat3, p: DVec3, b: &ConvexPolytope) -> Option<(i8, f64)> {
    let t = overlap_slack(a, r, p, b)?;
    if t > 1e-6 {
        Some((1, t))
    } else if t.abs() <= 1e-8 {
        Some((0, t))
    } else if t < -1e-6 {
        Some((-1, t))
    } else {
        None
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases(64)))]

    #[test]
    fn pairs_equal_all_pairs_lp(
        fixed in prop::collection::vec((box_part(), z_rotation(), grid_position()), 1..5),
        moving in box_part(),
        r in z_rotation(),
        p in grid_position(),
        clearance in prop_oneof![Just(0.0f64), Just(0.3f64)],
    ) {
        let placements: Vec<PlacedPart<'_>> =
            fixed.iter().map(|(part, rot, pos)| PlacedPart::new(part, Pose { rotation: *rot, position: *pos })).collect();
        let scene = PlacedScene::new(&placements);
        let found = scene.interference_pairs(&moving, r, p, clearance);
        let brute = scene.interference_pairs_brute_force(&moving, r, p, clearance);
        prop_assert_eq!(&found, &brute, "BVH result differs from the brute-force SAT");
        for (mi, a) in moving.components().iter().enumerate() {
            for (fp, (part, rot, pos)) in fixed.iter().enumerate() {
                for (fi, b) in part.components().iter().enumerate() {
                    let world_b = b.transformed(*rot, *pos);
                    let Some((expected, t)) = lp_contact(a, r, p, &world_b) else { continue };
                    let hit = found.iter().find(|x| x.moving_piece == mi && x.fixed_part == fp && x.fixed_piece == fi);
                    match (expected, hit.map(|h| h.contact)) {
                        (1, Some(PairContact::Penetrating { depth })) => {
                            prop_assert!(depth >= 2.0 * t - 1e-7, "depth {} below twice the LP slack {}", depth, t);
                        }
                        (0, Some(PairContact::Touching { .. })) => {}
                        (-1, None) => {}
                        (-1, Some(PairContact::Separated { gap })) => {
                            prop_assert!(clearance > 0.0 && gap < clearance);
                            let d = distance_between(a, r, p, &world_b);
                            // (the QP oracle solves for the squared distance to about 1e-8 relative on an objective
                            // of order |p|^2 <= 20: a distance of a few micrometres is only resolved to its square)
                            if let Some(d) = d {
                                prop_assert!(
                                    (d - gap).abs() < 1e-6 || (d * d - gap * gap).abs() < 1e-6,
                                    "gap {} vs QP distance {}", gap, d
                                );
                            }
                        }
                        (e, h) => prop_assert!(false, "pair ({}, {}, {}): LP says {} (slack {}), found {:?}", mi, fp, fi, e, t, h),
                    }
                    if expected == -1 && clearance > 0.0 && hit.is_none()
                        && let Some(d) = distance_between(a, r, p, &world_b)
                    {
                        prop_assert!(d >= clearance - 1e-6, "pair at distance {} < clearance missed", d);
                    }
                }
            }
        }
    }
}

/// Euclidean distance between `R a + p` and `b` as the distance from the origin to the hull of their differences.
fn distance_between(a: &ConvexPolytope, r: DMat3, p: DVec3, b: &ConvexPolytope) -> Option<f64> {
    // x in (R a + p) and y in b: distance = min |y - x| = dist(p, hull{b_j - R a_i})
    distance_to_hull(&differences(a, r, b), p)
}

#[test]
fn touching_and_penetrating_boxes() {
    let a = cuboid(DVec3::ZERO, DVec3::ONE);
    let b = cuboid(DVec3::ZERO, DVec3::ONE);
    let tol = 1e-9;
    let pa = PlacedConvex::new(&a, DMat3::IDENTITY, DVec3::ZERO);
    // face contact
    let pb = PlacedConvex::new(&b, DMat3::IDENTITY, DVec3::new(1.0, 0.3, 0.2));
    assert!(matches!(classify_pair(&pa, &pb, tol, 0.0), PairContact::Touching { .. }));
    // a vertical edge of a box turned by 45 degrees on the face x = 1
    let r = DMat3::from_rotation_z(std::f64::consts::FRAC_PI_4);
    let leftmost = (r * DVec3::Y).x;
    let pb = PlacedConvex::new(&b, r, DVec3::new(1.0 - leftmost, 0.0, 0.0));
    let c = classify_pair(&pa, &pb, tol, 0.0);
    assert!(matches!(c, PairContact::Touching { .. }), "{c:?}");
    let pb = PlacedConvex::new(&b, r, DVec3::new(1.0 - leftmost - 1e-3, 0.0, 0.0));
    assert!(matches!(classify_pair(&pa, &pb, tol, 0.0), PairContact::Penetrating { .. }));
    // penetration by 0.25 along x
    let pb = PlacedConvex::new(&b, DMat3::IDENTITY, DVec3::new(0.75, 0.0, 0.0));
    match classify_pair(&pa, &pb, tol, 0.0) {
        PairContact::Penetrating { depth } => assert!((depth - 0.25).abs() < 1e-12),
        other => panic!("{other:?}"),
    }
    // separated by 0.5: with clearance 1 the exact distance is reported
    let pb = PlacedConvex::new(&b, DMat3::IDENTITY, DVec3::new(1.3, 1.4, 0.0));
    match classify_pair(&pa, &pb, tol, 1.0) {
        PairContact::Separated { gap } => assert!((gap - 0.5).abs() < 1e-9, "{gap}"),
        other => panic!("{other:?}"),
    }
}
