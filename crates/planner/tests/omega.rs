//! The permissible set `Omega` of \[A\] eq. (3) as the search builds it ([`Orientation::omega_3d`],
//! [`Orientation::omega_2d`]) against its definition: the part placed at any vertex of `Omega` stays inside the
//! floor volume (a convex floor polygon times `[0, H]`) and touches three of its walls, floor or ceiling (a vertex
//! has three tight inequalities); the 2-D `Omega` at the height where the part rests on the floor is the horizontal
//! slice of the 3-D one.

use glam::{DMat3, DVec2, DVec3};
use proptest::prelude::*;
use stackplan_freespace::Cell;
use stackplan_geom::{Containment, PartOrigin, Tolerance, convex_hull};
use stackplan_planner::orientation::Orientation;
use stackplan_planner::request::polygon_side_planes;
use stackplan_planner::{Cost, FloorVolume};

proptest! {
    #[test]
    fn part_at_any_vertex_of_omega_touches_and_stays_inside(
        sides in 3usize..9,
        angles in prop::collection::vec(0.0f64..std::f64::consts::TAU, 8),
        axes in (4.0f64..15.0, 4.0f64..15.0, 2.0f64..10.0),
        points in prop::collection::vec((-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0), 5..20),
        radius in 0.5f64..3.0,
        turn in (0.0f64..6.3, -1.5f64..1.5),
    ) {
        // a convex floor polygon: points on an ellipse at sorted angles
        let (a, b, height) = axes;
        let mut angles = angles[..sides].to_vec();
        angles.sort_by(f64::total_cmp);
        prop_assume!(angles.windows(2).all(|w| w[1] - w[0] > 1e-3) && angles[sides - 1] - angles[0] < std::f64::consts::TAU - 3e-3);
        let polygon: Vec<DVec2> = angles.iter().map(|t| DVec2::new(1.0 + a * t.cos(), -2.0 + b * t.sin())).collect();
        let floor = FloorVolume { polygon, height };
        // a convex part: the hull of random points in a ball
        let pts: Vec<DVec3> =
            points.iter().map(|&(x, y, z)| DVec3::new(0.3, -0.2, 0.5) + radius * DVec3::new(x, y, z)).collect();
        let Ok(hull) = convex_hull(&pts) else { return Err(TestCaseError::reject("flat hull")) };
        let part = stackplan_geom::Part::from_components("hull", vec![hull.polytope], 1.0, PartOrigin::ConvexPieces)
            .expect("part");
        let rest = DMat3::from_rotation_x(turn.1);
        let cost = Cost::Stacking { w: 0.5, origin: floor.centre() };
        let o = Orientation::new(&part, 0, 0, 0, turn.0, rest, &cost);
        let tolerance = Tolerance::for_scale(2.0 * (a + b + height + radius));
        let om = Cell::new(o.omega_3d(&floor), tolerance).expect("Omega is bounded");
        let tol = tolerance.linear;
        // Sigma: the sides, the floor and the ceiling
        let mut sigma: Vec<([f64; 3], f64)> =
            polygon_side_planes(&floor.polygon).into_iter().map(|(n, d)| ([n.x, n.y, 0.0], d)).collect();
        sigma.push(([0.0, 0.0, -1.0], 0.0));
        sigma.push(([0.0, 0.0, 1.0], height));
        let rotated: Vec<DVec3> = part.all_vertices().map(|v| o.rotation * v).collect();
        let pz = -o.lo.z;
        let slice = o.omega_2d(&floor, pz, tol).map(|hs| Cell::new(hs, tolerance).expect("2-D Omega is bounded"));
        if om.is_empty() {
            // the floor is too small for the part: then no height helps either
            prop_assert!(slice.is_none_or(|s| s.is_empty()));
            return Ok(());
        }
        let poly = om.polyhedron();
        prop_assert!(poly.vertices.len() >= 4 || !om.is_solid());
        for p in &poly.vertices {
            let mut touching = 0;
            for (n, d) in &sigma {
                let worst = rotated
                    .iter()
                    .map(|v| n[0] * (v.x + p[0]) + n[1] * (v.y + p[1]) + n[2] * (v.z + p[2]) - d)
                    .fold(f64::NEG_INFINITY, f64::max);
                prop_assert!(worst <= 10.0 * tol, "a part vertex leaves the floor volume by {}", worst);
                if worst >= -10.0 * tol {
                    touching += 1;
                }
            }
            prop_assert!(touching >= 3, "only {} walls touched at an Omega vertex", touching);
        }
        let slice = slice.expect("the part fits on the floor");
        prop_assert!(!slice.is_empty());
        for q in slice.polygon() {
            prop_assert!(om.contains(&[q[0], q[1], pz]) != Containment::Exterior);
        }
    }
}
