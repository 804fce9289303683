//! The pruned separating-axis test (`sat_gap`: own-normal extents precomputed, cross axes parallel to a face normal
//! skipped) against the complete axis set (`sat_gap_all_axes`) and an independent LP: prisms sharing face directions,
//! boxes, random clouds; rotations about z (exact quarter turns and random angles) and general ones; positions on a
//! grid, so touching and parallel faces are frequent.

use crate::common;

use common::*;
use glam::{DMat3, DVec3};
use proptest::prelude::*;
use stackplan_cspace::interference::{
    PairContact, PlacedConvex, classify_pair, classify_pair_all_axes, cross_axis, is_upright_prism, project, sat_gap,
    sat_gap_all_axes,
};
use stackplan_geom::ConvexPolytope;

const TOL: f64 = 1e-9;

fn z_or_general_rotation() -> impl Strategy<Value = DMat3> {
    prop_oneof![
        (0i32..4).prop_map(|k| DMat3::from_rotation_z(k as f64 * std::f64::consts::FRAC_PI_2)),
        (-3.2f64..3.2).prop_map(DMat3::from_rotation_z),
        any_rotation(),
    ]
}

fn grid_position() -> impl Strategy<Value = DVec3> {
    (-8i32..8, -8i32..8, -6i32..6).prop_map(|(x, y, z)| DVec3::new(x as f64, y as f64, z as f64) * 0.25)
}

fn pair() -> impl Strategy<Value = (ConvexPolytope, ConvexPolytope)> {
    prop_oneof![prism_pair(), (any_box(), any_box()), (dyadic_cloud(4..12), dyadic_cloud(4..12))]
}

/// A pair, its rotations and the first one's position (the second stays at the origin).
fn case() -> impl Strategy<Value = ((ConvexPolytope, ConvexPolytope), DMat3, DMat3, DVec3)> {
    (pair(), z_or_general_rotation(), z_or_general_rotation(), grid_position())
}

/// The decision of a gap with tolerance `TOL`: -1 separated, 0 touching, 1 penetrating.
fn decision(gap: f64) -> i8 {
    if gap < -TOL {
        1
    } else if gap <= TOL {
        0
    } else {
        -1
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases(256)))]

    /// Same maximum gap as the complete axis set up to rounding, the same decision away from the thresholds, and
    /// the LP's decision where it is clear.
    #[test]
    fn pruned_gap_equals_the_complete_axis_set(
        ((a, b), ra, rb, pa) in case(),
    ) {
        let (placed_a, placed_b) = (PlacedConvex::new(&a, ra, pa), PlacedConvex::new(&b, rb, DVec3::ZERO));
        let full = sat_gap_all_axes(&placed_a, &placed_b, f64::INFINITY);
        let pruned = sat_gap(&placed_a, &placed_b, f64::INFINITY);
        prop_assert!((full - pruned).abs() <= 1e-11, "full {} pruned {}", full, pruned);
        if (full.abs() - TOL).abs() > 1e-10 {
            prop_assert_eq!(decision(full), decision(pruned));
            let c = classify_pair(&placed_a, &placed_b, TOL, 0.0);
            let cf = classify_pair_all_axes(&placed_a, &placed_b, TOL, 0.0);
            prop_assert_eq!(std::mem::discriminant(&c), std::mem::discriminant(&cf));
        }
        // an early stop still reports a gap above the stop value iff the complete maximum is above it
        for stop in [-0.3, 0.0, TOL, 0.4] {
            if (full - stop).abs() > 1e-10 {
                prop_assert_eq!(sat_gap(&placed_a, &placed_b, stop) > stop, full > stop);
            }
        }
        // the LP: interiors overlap by a clear margin iff penetrating
        let world_b = b.transformed(rb, DVec3::ZERO);
        if let Some(t) = overlap_slack(&a, ra, pa, &world_b) {
            if t > 1e-6 {
                prop_assert!(pruned < -TOL, "LP slack {} but gap {}", t, pruned);
            } else if t < -1e-6 {
                prop_assert!(pruned > TOL, "LP slack {} but gap {}", t, pruned);
            }
        }
    }

    /// Two upright prisms (the flag): every cross axis is a duplicate, as `is_upright_prism` proves, so skipping them
    /// all gives the gap of the scan that forms each one, bit for bit; z-prisms turned about z are always flagged.
    #[test]
    fn upright_prisms_have_only_duplicate_cross_axes(
        ((a, b), ra, rb, pa) in case(),
    ) {
        let (placed_a, placed_b) = (PlacedConvex::new(&a, ra, pa), PlacedConvex::new(&b, rb, DVec3::ZERO));
        for placed in [&placed_a, &placed_b] {
            prop_assert_eq!(placed.upright_prism, is_upright_prism(&placed.normal_axes, &placed.edge_directions));
            prop_assert_eq!(placed.translated(pa).upright_prism, placed.upright_prism);
        }
        let z_prism = |p: &ConvexPolytope| p.faces().iter().filter(|f| f.plane.normal.z != 0.0).count() == 2
            && p.faces().iter().all(|f| f.plane.normal.z == 0.0 || (f.plane.normal.x == 0.0 && f.plane.normal.y == 0.0));
        let about_z = |r: &DMat3| r.z_axis == DVec3::Z && r.x_axis.z == 0.0 && r.y_axis.z == 0.0;
        if z_prism(&a) && about_z(&ra) {
            prop_assert!(placed_a.upright_prism);
        }
        if placed_a.upright_prism && placed_b.upright_prism {
            for (&da, &ma) in placed_a.edge_directions.iter().zip(&placed_a.edge_normal_masks) {
                for (&db, &mb) in placed_b.edge_directions.iter().zip(&placed_b.edge_normal_masks) {
                    prop_assert!(cross_axis(da, ma, &placed_a.normal_axes, db, mb, &placed_b.normal_axes).is_none());
                }
            }
        }
        let (mut plain_a, mut plain_b) = (placed_a.clone(), placed_b.clone());
        plain_a.upright_prism = false;
        plain_b.upright_prism = false;
        for stop in [f64::INFINITY, -0.3, 0.0, TOL] {
            prop_assert_eq!(sat_gap(&placed_a, &placed_b, stop).to_bits(), sat_gap(&plain_a, &plain_b, stop).to_bits());
        }
    }

    /// `translated` shifts the extents by `u . p`: equal to projecting the moved vertices up to rounding.
    #[test]
    fn translated_extents_match_projections((a, _b) in pair(), r in z_or_general_rotation(), p in grid_position()) {
        let placed = PlacedConvex::new(&a, r, DVec3::ZERO).translated(p * 37.0);
        let fresh = PlacedConvex::new(&a, r, p * 37.0);
        for (k, u) in placed.normal_axes.iter().enumerate() {
            let (lo, hi) = placed.normal_extents[k];
            let (plo, phi) = project(&placed.vertices, *u);
            prop_assert!((lo - plo).abs() <= 1e-12 && (hi - phi).abs() <= 1e-12);
            prop_assert_eq!(fresh.normal_extents[k], (plo, phi));
        }
        prop_assert_eq!(placed.edge_normal_masks, fresh.edge_normal_masks);
    }
}

/// Two plates turned about z against each other: every non-zero edge cross product is parallel to a face normal of
/// one of them, so no cross axis is tested; face-to-face contact is touching, a slight overlap penetrating.
#[test]
fn boxes_turned_about_z_need_no_cross_axes() {
    let plate = ConvexPolytope::cuboid(DVec3::ZERO, DVec3::new(100.0, 50.0, 2.0)).expect("box");
    for theta in [0.0, 0.3, std::f64::consts::FRAC_PI_2, 1.0, -2.5] {
        let a = PlacedConvex::new(&plate, DMat3::IDENTITY, DVec3::ZERO);
        let b = PlacedConvex::new(&plate, DMat3::from_rotation_z(theta), DVec3::new(20.0, 10.0, 2.0));
        for (&da, &ma) in a.edge_directions.iter().zip(&a.edge_normal_masks) {
            for (&db, &mb) in b.edge_directions.iter().zip(&b.edge_normal_masks) {
                assert!(cross_axis(da, ma, &a.normal_axes, db, mb, &b.normal_axes).is_none(), "theta {theta}");
            }
        }
        // stacked face to face: touching, by the pruned and the complete test alike
        for c in [classify_pair(&a, &b, TOL, 0.0), classify_pair_all_axes(&a, &b, TOL, 0.0)] {
            assert!(matches!(c, PairContact::Touching { .. }), "theta {theta}: {c:?}");
        }
        let sunk = PlacedConvex::new(&plate, DMat3::from_rotation_z(theta), DVec3::new(20.0, 10.0, 1.5));
        match classify_pair(&a, &sunk, TOL, 0.0) {
            PairContact::Penetrating { depth } => assert!((depth - 0.5).abs() < 1e-12, "theta {theta}: {depth}"),
            other => panic!("theta {theta}: {other:?}"),
        }
    }
}

/// The flag's conditions on hand-made axes: an exactly vertical normal axis is needed, a horizontal edge needs a
/// horizontal normal perpendicular to it within `1e-13`, a tilted edge or a witness beyond the first 64 normals fails.
#[test]
fn upright_prism_conditions() {
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    assert!(is_upright_prism(&[z, x, y], &[x, y, z]));
    assert!(!is_upright_prism(&[x, y], &[x, y, z]), "no vertical normal axis");
    assert!(!is_upright_prism(&[z, x], &[x, y, z]), "no horizontal normal perpendicular to x");
    assert!(!is_upright_prism(&[z, x, y], &[x, y, DVec3::new(0.0, 1e-20, 1.0)]), "a tilted edge");
    let off = DVec3::new(1e-12, 1.0, 0.0).normalize();
    assert!(!is_upright_prism(&[z, off], &[x]), "perpendicular only within 1e-12");
    let near = DVec3::new(1e-14, 1.0, 0.0).normalize();
    assert!(is_upright_prism(&[z, near], &[x]));
    let mut many: Vec<DVec3> = (0..64).map(|k| DVec3::new((k as f64).cos(), (k as f64).sin(), 0.0)).collect();
    many[0] = z;
    many.push(y);
    assert!(!is_upright_prism(&many, &[x]), "the witness is normal 64, beyond the masks");
    assert!(!is_upright_prism(&[z, y], &[DVec3::new(f64::NAN, 0.0, 0.0)]));
}

/// Edge-on-edge contact of two tilted boxes (the separating axis is a genuine cross product, which is kept):
/// touching at the contact, separated just above it, penetrating just below, as the complete axis set says.
#[test]
fn edge_on_edge_keeps_the_cross_axis() {
    let cube = ConvexPolytope::cuboid(DVec3::splat(-1.0), DVec3::splat(1.0)).expect("cube");
    // a cube standing on an edge along x, and one on an edge along y above it: their edges cross at one point
    let lower_r = DMat3::from_rotation_x(std::f64::consts::FRAC_PI_4);
    let upper_r = DMat3::from_rotation_y(std::f64::consts::FRAC_PI_4);
    let a = PlacedConvex::new(&cube, lower_r, DVec3::ZERO);
    let h = 2.0 * std::f64::consts::SQRT_2;
    for (dz, expected) in [(0.0, 0i8), (1e-3, -1), (-1e-3, 1)] {
        let b = PlacedConvex::new(&cube, upper_r, DVec3::new(0.0, 0.0, h + dz));
        let full = sat_gap_all_axes(&a, &b, f64::INFINITY);
        let pruned = sat_gap(&a, &b, f64::INFINITY);
        assert!((full - pruned).abs() <= 1e-12, "{full} vs {pruned}");
        assert_eq!(decision(pruned), expected, "dz {dz}: gap {pruned}");
    }
}
