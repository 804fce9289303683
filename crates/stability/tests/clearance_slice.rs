//! The horizontal distance by the slice of the Minkowski difference (`clearance::horizontal_distance_by_slice`, the
//! filter that spares the SOCP) against the SOCP (`clearance::horizontal_distance`) on random pairs of convex hulls:
//! random points, boxes tilted by up to a few degrees and slivers, placed so that their z-ranges overlap; and the
//! separating axes' lower bound (`clearance::horizontal_distance_bound_by_axes`) against both.

use crate::common;
use stackplan_geom::Pose;

use glam::{DMat3, DVec3};
use proptest::prelude::*;
use stackplan_geom::polytope::ConvexPolytope;
use stackplan_geom::{Part, PartOrigin, convex_hull};
use stackplan_stability::PlacedPart;
use stackplan_stability::clearance::{
    horizontal_distance, horizontal_distance_bound_by_axes, horizontal_distance_by_slice,
};
use stackplan_stability::world::world_stack;

fn hull_part(points: &[DVec3]) -> Option<Part> {
    let hull = convex_hull(points).ok()?;
    Part::from_components("h", vec![hull.polytope], 1.0, PartOrigin::ConvexPieces).ok()
}

/// The corners of the box `[lo, hi]`.
fn cube(lo: DVec3, hi: DVec3) -> Vec<DVec3> {
    ConvexPolytope::cuboid(lo, hi).expect("box").vertices().to_vec()
}

fn points() -> impl Strategy<Value = Vec<DVec3>> {
    prop_oneof![
        // a random hull of 4-10 points
        prop::collection::vec((-10.0f64..10.0, -10.0f64..10.0, 0.0f64..15.0), 4..10)
            .prop_map(|v| v.into_iter().map(|(x, y, z)| DVec3::new(x, y, z)).collect()),
        // a box, a sliver (one side 1e-4 .. 1e-2 mm) or a plate
        (1.0f64..20.0, 1e-4f64..20.0, 1.0f64..15.0).prop_map(|(a, b, c)| cube(DVec3::ZERO, DVec3::new(a, b, c))),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(common::cases(64)))]

    #[test]
    fn the_slice_equals_the_socp(
        pa in points(),
        pb in points(),
        tilt in prop_oneof![Just(0.0), -1e-4f64..1e-4, -0.05f64..0.05],
        turn in 0.0f64..std::f64::consts::TAU,
        shift in (-25.0f64..25.0, -25.0f64..25.0, -5.0f64..5.0),
    ) {
        let (Some(a), Some(b)) = (hull_part(&pa), hull_part(&pb)) else { return Ok(()) };
        let rotation = DMat3::from_rotation_z(turn) * DMat3::from_rotation_x(tilt);
        let stack = [
            PlacedPart { part: &a, pose: Pose { rotation: DMat3::IDENTITY, position: DVec3::ZERO } },
            PlacedPart { part: &b, pose: Pose { rotation, position: DVec3::new(shift.0, shift.1, shift.2) } },
        ];
        let parts = world_stack(&stack).expect("world");
        let (ca, cb) = (&parts[0].components[0], &parts[1].components[0]);
        let sliced = horizontal_distance_by_slice(ca, cb, 1e-9);
        // the slice is empty iff the z-ranges do not meet (away from touching)
        let (za, zb) = (ca.aabb, cb.aabb);
        let overlap = za.1.z.min(zb.1.z) - za.0.z.max(zb.0.z);
        if overlap < -1e-6 {
            prop_assert!(sliced.is_none(), "z-ranges {} apart, slice {:?}", -overlap, sliced);
        }
        if overlap > 1e-6 {
            let s = sliced.expect("the z-ranges meet: a slice");
            let d = horizontal_distance(ca, cb).expect("the SOCP solves");
            prop_assert!((s - d).abs() <= 1e-6 * (1.0 + d), "slice {} against the SOCP {}", s, d);
            // the separating axes' bound never exceeds the distance (by both exact methods)
            let bound = horizontal_distance_bound_by_axes(ca, cb, 1e-9);
            prop_assert!(bound <= d + 1e-6 * (1.0 + d) && bound <= s + 1e-9 * (1.0 + s),
                "axes {} above the SOCP {} / slice {}", bound, d, s);
        }
    }
}

/// Two components of a stack of two hull parts (the second turned by `turn` about z and moved by `shift`).
fn pair_distances(pa: &[DVec3], pb: &[DVec3], turn: f64, shift: DVec3) -> (f64, f64) {
    let (a, b) = (hull_part(pa).expect("hull"), hull_part(pb).expect("hull"));
    let stack = [
        PlacedPart { part: &a, pose: Pose { rotation: DMat3::IDENTITY, position: DVec3::ZERO } },
        PlacedPart { part: &b, pose: Pose { rotation: DMat3::from_rotation_z(turn), position: shift } },
    ];
    let parts = world_stack(&stack).expect("world");
    let (ca, cb) = (&parts[0].components[0], &parts[1].components[0]);
    (horizontal_distance_bound_by_axes(ca, cb, 1e-9), horizontal_distance(ca, cb).expect("the SOCP solves"))
}

#[test]
fn the_axes_bound_is_the_distance_to_an_edge_of_the_slice_and_below_it_at_a_vertex() {
    let a = cube(DVec3::ZERO, DVec3::splat(10.0));
    // side by side, 3 mm apart in x, z-ranges overlapping: the nearest point of the slice is on an edge (x axis)
    let (bound, d) =
        pair_distances(&a, &cube(DVec3::new(13.0, 0.0, 5.0), DVec3::new(20.0, 10.0, 15.0)), 0.0, DVec3::ZERO);
    assert!((d - 3.0).abs() < 1e-6 && (bound - 3.0).abs() < 1e-8, "bound {bound}, distance {d}");
    // a diamond (a square turned 45 degrees) beside the square: the slice `B - A` is an octagon, and the diamond is
    // placed so that the octagon's vertex `V` (its east corner plus the corner (0, 0) of `-A`) is the nearest point,
    // 12 mm away in the direction 22.5 degrees between the normals of the two edges at `V`: each edge's line is
    // 12 cos(22.5 deg) away, and that is the bound
    let diamond = cube(DVec3::new(-5.0, -5.0, 2.0), DVec3::new(5.0, 5.0, 8.0));
    let direction = DVec3::new(22.5f64.to_radians().cos(), 22.5f64.to_radians().sin(), 0.0);
    let corner = -12.0 * direction;
    let shift = corner - DVec3::new(50f64.sqrt(), 0.0, 0.0);
    let (bound, d) = pair_distances(&a, &diamond, std::f64::consts::FRAC_PI_4, shift);
    assert!((d - 12.0).abs() < 1e-6, "distance {d}");
    assert!((bound - 12.0 * 22.5f64.to_radians().cos()).abs() < 1e-8, "bound {bound}");
}
