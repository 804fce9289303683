//! The horizontal distance by the slice of the Minkowski difference (`clearance::horizontal_distance_by_slice`, the
//! filter that spares the SOCP) against the SOCP (`clearance::horizontal_distance`) on random pairs of convex hulls:
//! random points, boxes tilted by up to a few degrees and slivers, placed so that their z-ranges overlap.

mod common;

use glam::{DMat3, DVec3};
use proptest::prelude::*;
use stackplan_geom::{Part, PartOrigin, convex_hull};
use stackplan_stability::PlacedPart;
use stackplan_stability::clearance::{horizontal_distance, horizontal_distance_by_slice};
use stackplan_stability::world::world_stack;

fn hull_part(points: &[DVec3]) -> Option<Part> {
    let hull = convex_hull(points).ok()?;
    Part::from_components("h", vec![hull.polytope], 1.0, PartOrigin::ConvexPieces).ok()
}

fn points() -> impl Strategy<Value = Vec<DVec3>> {
    prop_oneof![
        // a random hull of 4-10 points
        prop::collection::vec((-10.0f64..10.0, -10.0f64..10.0, 0.0f64..15.0), 4..10)
            .prop_map(|v| v.into_iter().map(|(x, y, z)| DVec3::new(x, y, z)).collect()),
        // a box, a sliver (one side 1e-4 .. 1e-2 mm) or a plate
        (1.0f64..20.0, 1e-4f64..20.0, 1.0f64..15.0).prop_map(|(a, b, c)| {
            (0..8)
                .map(|k| {
                    DVec3::new(
                        if k & 1 == 0 { 0.0 } else { a },
                        if k & 2 == 0 { 0.0 } else { b },
                        if k & 4 == 0 { 0.0 } else { c },
                    )
                })
                .collect()
        }),
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
            PlacedPart { part: &a, rotation: DMat3::IDENTITY, position: DVec3::ZERO },
            PlacedPart { part: &b, rotation, position: DVec3::new(shift.0, shift.1, shift.2) },
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
        }
    }
}
