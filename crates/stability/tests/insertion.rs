//! Insertion straight down, removal straight up.

use crate::common;
use stackplan_geom::Pose;

use common::{at, box_part, boxes_part};
use glam::DVec3;
use stackplan_stability::check::{CheckOptions, check_stack};
use stackplan_stability::insertion::{insertion_obstruction, liftable_from_full_stack};
use stackplan_stability::world::world_stack;

#[test]
fn box_on_box_is_insertable_and_box_under_a_table_is_not() {
    let table = boxes_part(
        "table",
        &[
            (DVec3::ZERO, DVec3::new(5.0, 40.0, 30.0)),
            (DVec3::new(55.0, 0.0, 0.0), DVec3::new(60.0, 40.0, 30.0)),
            (DVec3::new(0.0, 0.0, 30.0), DVec3::new(60.0, 40.0, 35.0)),
        ],
    );
    let small = box_part("small", DVec3::new(20.0, 20.0, 10.0));
    let parts_data =
        [at(&table, DVec3::ZERO), at(&small, DVec3::new(20.0, 10.0, 0.0)), at(&small, DVec3::new(20.0, 10.0, 35.0))];
    let parts = world_stack(&parts_data).expect("world");
    let tol = 1e-9;
    assert!(insertion_obstruction(&parts, 0, tol).is_ok());
    let blocked = insertion_obstruction(&parts, 1, tol).expect_err("under the table top");
    assert_eq!(blocked.part, 0);
    assert_eq!(blocked.component, 2);
    assert!(insertion_obstruction(&parts, 2, tol).is_ok(), "resting on top is allowed (touching)");
    // lifting out of the full stack: the small box under the table is trapped by the table and the box above
    assert!(liftable_from_full_stack(&parts, 1, tol).is_err());
    assert!(liftable_from_full_stack(&parts, 2, tol).is_ok());
    assert!(liftable_from_full_stack(&parts, 0, tol).is_err());
}

#[test]
fn sliding_down_along_walls_is_allowed() {
    // a box that fits exactly into a U-shaped tray touches both walls on the way down
    let tray = boxes_part(
        "tray",
        &[
            (DVec3::ZERO, DVec3::new(50.0, 30.0, 5.0)),
            (DVec3::new(0.0, 0.0, 5.0), DVec3::new(5.0, 30.0, 20.0)),
            (DVec3::new(45.0, 0.0, 5.0), DVec3::new(50.0, 30.0, 20.0)),
        ],
    );
    let fitting = box_part("fit", DVec3::new(40.0, 20.0, 10.0));
    let stack = [at(&tray, DVec3::ZERO), at(&fitting, DVec3::new(5.0, 5.0, 5.0))];
    let mut options = CheckOptions::default();
    options.grasp.cup_diameter = 4.0;
    let report = check_stack(&stack, &options).expect("check");
    assert!(report.parts[1].insertable && report.parts[1].removable, "{:?}", report.parts[1]);
    assert_eq!(report.parts[1].interference, 0.0);
    assert!(report.ok, "{report:#?}");
    // with a 2 mm clearance the walls are too close
    let options = CheckOptions { clearance: 2.0, ..options };
    let report = check_stack(&stack, &options).expect("check");
    assert!(!report.parts[1].clearance_met);
    assert_eq!(report.parts[1].min_horizontal_clearance, Some(0.0));
    assert!(!report.ok);
    // a slightly wider box interferes and cannot be inserted
    let wide = box_part("wide", DVec3::new(41.0, 20.0, 10.0));
    let stack = [at(&tray, DVec3::ZERO), at(&wide, DVec3::new(4.5, 5.0, 5.0))];
    let report = check_stack(&stack, &CheckOptions::default()).expect("check");
    assert!((report.parts[1].interference - 0.5).abs() < 1e-9);
    assert!(!report.parts[1].insertable);
}

#[test]
fn horizontal_clearance_between_neighbours() {
    let a = box_part("a", DVec3::new(10.0, 10.0, 10.0));
    for (gap, met) in [(3.0, false), (5.0, true), (8.0, true)] {
        let stack = [at(&a, DVec3::ZERO), at(&a, DVec3::new(10.0 + gap, 2.0, 0.0))];
        let options = CheckOptions { clearance: 5.0, ..CheckOptions::default() };
        let report = check_stack(&stack, &options).expect("check");
        assert_eq!(report.parts[0].clearance_met, met, "gap {gap}");
        assert_eq!(report.parts[1].clearance_met, met, "gap {gap}");
        if !met {
            let d = report.parts[0].min_horizontal_clearance.expect("distance");
            assert!((d - gap).abs() < 1e-6, "{d}");
        }
    }
    // stacked parts are exempt: a box on top of another is not a clearance violation
    let stack = [at(&a, DVec3::ZERO), at(&a, DVec3::new(0.0, 0.0, 10.0))];
    let options = CheckOptions { clearance: 5.0, ..CheckOptions::default() };
    assert!(check_stack(&stack, &options).expect("check").parts[1].clearance_met);
}

#[test]
fn horizontal_distance_of_interlocking_wedges_needs_the_socp() {
    use glam::DMat3;
    use stackplan_geom::{Part, PartOrigin, convex_hull};
    use stackplan_stability::clearance::horizontal_distance;
    use stackplan_stability::world::PlacedPart;
    // A: triangle (0,0), (L,0), (0,H) in xz; B: triangle (L+g,0), (L+g,H), (g,H): at every height B starts g after A
    let (l, h, g) = (40.0, 20.0, 3.0);
    let prism = |tri: [DVec3; 3]| {
        let pts: Vec<DVec3> = tri.iter().flat_map(|&p| [p, p + DVec3::Y * 10.0]).collect();
        Part::from_components("w", vec![convex_hull(&pts).expect("prism").polytope], 1.0, PartOrigin::ConvexPieces)
            .expect("part")
    };
    let a = prism([DVec3::ZERO, DVec3::new(l, 0.0, 0.0), DVec3::new(0.0, 0.0, h)]);
    let b = prism([DVec3::new(l + g, 0.0, 0.0), DVec3::new(l + g, 0.0, h), DVec3::new(g, 0.0, h)]);
    let stack = [
        PlacedPart { part: &a, pose: Pose { rotation: DMat3::IDENTITY, position: DVec3::ZERO } },
        PlacedPart { part: &b, pose: Pose { rotation: DMat3::IDENTITY, position: DVec3::ZERO } },
    ];
    let parts = world_stack(&stack).expect("world");
    let d = horizontal_distance(&parts[0].components[0], &parts[1].components[0]).expect("solved");
    assert!((d - g).abs() < 1e-5, "{d}");
    let options = CheckOptions { clearance: 5.0, ..CheckOptions::default() };
    let report = check_stack(&stack, &options).expect("check");
    assert!(!report.parts[0].clearance_met);
    let options = CheckOptions { clearance: 2.5, ..CheckOptions::default() };
    assert!(check_stack(&stack, &options).expect("check").parts[0].clearance_met);
}
