//! The filled plates' obstacle against the pieces' ones (`stackplan_geom::plate`, `crate::plates`): for parallel
//! plates with holes that neither outline fits into, every position deep inside the filled plates' c-space obstacle
//! lies inside some pair of pieces' obstacle (no pocket), checked by sampling against obstacles built pair by pair;
//! a plate small enough for a hole leaves a pocket and is not merged; and the placement search finds the same
//! optimum with and without merging, its placements free by an independent all-pairs test.

use glam::{DMat3, DVec3};
use proptest::prelude::*;
use stackplan_cspace::interference::{PairContact, PlacedScene};
use stackplan_cspace::obstacle;
use stackplan_geom::plate::merges_exactly;
use stackplan_geom::sheet_metal::{Decomposition, SheetFace, SheetMetal};
use stackplan_geom::{ConvexPolytope, Part, Pose};
use stackplan_planner::{Cost, FloorVolume, PlacedPart, PlacementRequest, place, uniform_thetas};

/// A flat plate `a x b` (mm, 2 mm thick, in the plane z = 0) with rectangular holes `(x, y, w, h)`.
fn plate(a: f64, b: f64, holes: &[(f64, f64, f64, f64)]) -> Part {
    let rect = |x: f64, y: f64, w: f64, h: f64| {
        vec![DVec3::new(x, y, 0.0), DVec3::new(x + w, y, 0.0), DVec3::new(x + w, y + h, 0.0), DVec3::new(x, y + h, 0.0)]
    };
    let face = SheetFace {
        outline: rect(0.0, 0.0, a, b),
        holes: holes.iter().map(|&(x, y, w, h)| rect(x, y, w, h)).collect(),
    };
    SheetMetal { faces: vec![face], thickness: 2.0 }
        .build_part("plate", 1.0, Decomposition::ConvexMerge)
        .expect("plate")
}

/// How deep `p` lies inside the convex set `planes` (`n . p <= d`): the least slack (negative outside).
fn depth<'a>(planes: impl Iterator<Item = &'a stackplan_geom::Plane>, p: DVec3) -> f64 {
    planes.map(|pl| pl.offset - pl.normal.dot(p)).fold(f64::INFINITY, f64::min)
}

/// A plate 120-200 x 80-140 mm with one to four holes of 10-30 mm, in a 2 x 2 grid of cells (holes apart and inside).
fn plate_strategy() -> impl Strategy<Value = Part> {
    (120.0f64..200.0, 80.0f64..140.0, prop::collection::vec((any::<bool>(), 10.0f64..30.0, 10.0f64..30.0), 4)).prop_map(
        |(a, b, cells)| {
            let mut holes = Vec::new();
            for (k, (on, w, h)) in cells.into_iter().enumerate() {
                // cell k of the 2 x 2 grid, the hole centred in it
                let (cx, cy) = ((k % 2) as f64 * a / 2.0 + a / 4.0, (k / 2) as f64 * b / 2.0 + b / 4.0);
                if on || k == 0 {
                    holes.push((cx - w / 2.0, cy - h / 2.0, w, h));
                }
            }
            plate(a, b, &holes)
        },
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn the_filled_plates_obstacle_is_the_union_of_the_pieces_obstacles(
        moving in plate_strategy(),
        fixed in plate_strategy(),
        turn in 0.0f64..6.3,
        flip in any::<bool>(),
        seed in 0u64..1_000_000,
    ) {
        // the moving plate turned about z (and possibly upside down: still parallel)
        let rotation = if flip { DMat3::from_rotation_x(std::f64::consts::PI) } else { DMat3::IDENTITY }
            * DMat3::from_rotation_z(turn);
        let (a, b) = (&moving.plates()[0], &fixed.plates()[0]);
        prop_assert!(a.pieces.len() >= 2 && b.pieces.len() >= 2, "plates with holes have several pieces");
        prop_assert!(merges_exactly(a, rotation, b, DMat3::IDENTITY, 1e-6));
        let filled = obstacle(&a.filled, rotation, &b.filled).expect("filled obstacle");
        let pairs: Vec<_> = moving
            .components()
            .iter()
            .flat_map(|m| fixed.components().iter().map(move |f| obstacle(m, rotation, f).expect("pair obstacle")))
            .collect();
        // positions in the filled obstacle's box, in the slab where the plates overlap (|z| < 2)
        let (lo, hi) = filled.polytope().aabb();
        let mut state = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        let mut next = || {
            state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut deep = 0;
        for _ in 0..400 {
            let p = DVec3::new(lo.x + (hi.x - lo.x) * next(), lo.y + (hi.y - lo.y) * next(), -1.9 + 3.8 * next());
            let in_filled = depth(filled.planes(), p);
            let in_pieces = pairs.iter().map(|o| depth(o.planes(), p)).fold(f64::NEG_INFINITY, f64::max);
            // the pieces' obstacles lie in the filled one (the least slack is a depth inside a set, not a distance
            // outside it, so only positions inside a pair's obstacle are compared)
            if in_pieces > 1e-7 {
                prop_assert!(in_filled > -1e-7, "a pair's obstacle reaches outside the filled one at {p}");
            }
            if in_filled > 1e-3 {
                deep += 1;
                // no pocket: a position inside the filled obstacle is inside some pair's
                prop_assert!(in_pieces > -1e-7, "pocket at {p}: {in_filled} inside the filled plates, {in_pieces} outside every pair");
            }
        }
        prop_assert!(deep > 0, "some samples inside");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

    #[test]
    fn a_plate_against_a_piece_whose_slices_clear_its_holes_is_the_union_of_its_pieces(
        moving in plate_strategy(),
        size in (20.0f64..120.0, 1.0f64..20.0, 5.0f64..80.0),
        tilt in (0.0f64..6.3, prop_oneof![Just(0.0), Just(std::f64::consts::FRAC_PI_2), 0.0f64..1.6], 0.0f64..6.3),
        seed in 0u64..1_000_000,
    ) {
        // a box turned anyhow against the plate: where no slice of it by a slab parallel to the plate fits into a
        // hole, the filled plate's obstacle against it is the union of the pieces' (and otherwise it is not tested)
        let b = ConvexPolytope::cuboid(DVec3::ZERO, DVec3::new(size.0, size.1, size.2)).expect("box");
        let turn = DMat3::from_rotation_z(tilt.0) * DMat3::from_rotation_x(tilt.1) * DMat3::from_rotation_z(tilt.2);
        let fixed = b.transformed(turn, DVec3::new(60.0, 40.0, 0.0));
        let plate = &moving.plates()[0];
        let clear = stackplan_geom::plate::slices_clear_holes(fixed.vertices(), plate.normal, plate.hole_diameter, 1e-6);
        let filled = obstacle(&plate.filled, DMat3::IDENTITY, &fixed).expect("filled obstacle");
        let pairs: Vec<_> =
            moving.components().iter().map(|m| obstacle(m, DMat3::IDENTITY, &fixed).expect("pair obstacle")).collect();
        let (lo, hi) = filled.polytope().aabb();
        let mut state = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        let mut next = || {
            state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..400 {
            let p = lo + (hi - lo) * DVec3::new(next(), next(), next());
            let in_filled = depth(filled.planes(), p);
            let in_pieces = pairs.iter().map(|o| depth(o.planes(), p)).fold(f64::NEG_INFINITY, f64::max);
            if in_pieces > 1e-7 {
                prop_assert!(in_filled > -1e-7, "a pair's obstacle reaches outside the filled one at {p}");
            }
            if clear && in_filled > 1e-3 {
                prop_assert!(in_pieces > -1e-7, "pocket at {p}: {in_filled} inside the filled plate, {in_pieces} outside every pair");
            }
        }
    }
}

#[test]
fn a_plate_that_fits_into_a_hole_leaves_a_pocket_and_is_not_merged() {
    // a 40 x 30 plate with a 10 x 10 hole above a 200 x 140 plate with a 60 x 50 hole: the small plate fits into the
    // big one's hole, where the filled plates overlap and no pieces do
    let small = plate(40.0, 30.0, &[(15.0, 10.0, 10.0, 10.0)]);
    let big = plate(200.0, 140.0, &[(70.0, 45.0, 60.0, 50.0)]);
    let (a, b) = (&small.plates()[0], &big.plates()[0]);
    assert!(!merges_exactly(a, DMat3::IDENTITY, b, DMat3::IDENTITY, 1e-6));
    let filled = obstacle(&a.filled, DMat3::IDENTITY, &b.filled).expect("filled");
    let pocket = DVec3::new(80.0, 55.0, 0.0); // the small plate at (80..120, 55..85), inside the hole (70..130, 45..95)
    assert!(depth(filled.planes(), pocket) > 1.0);
    for m in small.components() {
        for f in big.components() {
            let o = obstacle(m, DMat3::IDENTITY, f).expect("pair");
            assert!(depth(o.planes(), pocket) < 0.0, "the pocket is free of every pair");
        }
    }
}

fn free(part: &Part, stack: &[(&Part, Pose)], r: DMat3, p: DVec3, tol: f64) -> bool {
    let placements: Vec<stackplan_geom::PlacedPart<'_>> =
        stack.iter().map(|(part, pose)| stackplan_geom::PlacedPart::new(part, *pose)).collect();
    let scene = PlacedScene::new(&placements);
    !scene
        .interference_pairs_brute_force(part, r, p, 0.0)
        .iter()
        .any(|x| matches!(x.contact, PairContact::Penetrating { depth } if depth > tol))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    #[test]
    fn the_search_finds_the_same_optimum_with_and_without_merged_plates(
        part in plate_strategy(),
        x in 0.0f64..80.0,
        y in 0.0f64..60.0,
        turn in 0usize..6,
        w in 0.2f64..0.9,
    ) {
        // two plates on the floor, the new one placed over them (flat, turned in 30-degree steps)
        let poses = [
            Pose { rotation: DMat3::IDENTITY, position: DVec3::new(0.0, 0.0, 1.0) },
            Pose { rotation: DMat3::from_rotation_z(turn as f64 * 0.5), position: DVec3::new(x + 150.0, y, 1.0) },
        ];
        let stack: Vec<PlacedPart<'_>> = poses.iter().map(|pose| PlacedPart { part: &part, pose: *pose }).collect();
        let floor = FloorVolume::rectangle(-100.0, -100.0, 400.0, 300.0, 60.0);
        let mut req = PlacementRequest::new(&part, stack, floor);
        req.thetas = uniform_thetas(12);
        req.cost = Cost::Stacking { w, origin: DVec3::new(150.0, 60.0, 0.0) };
        req.k = 3;
        let merged = place(&req).expect("merged search");
        req.tuning.merge_plates = false;
        let pieces = place(&req).expect("search by pieces");
        let (m, p) = (merged.placements.first().expect("placed"), pieces.placements.first().expect("placed"));
        prop_assert!((m.cost - p.cost).abs() <= 1e-9 * p.cost.abs().max(1.0), "optimum {} against {}", m.cost, p.cost);
        let scene: Vec<(&Part, Pose)> = poses.iter().map(|pose| (&part, *pose)).collect();
        for q in &merged.placements {
            let pose = q.pose();
            prop_assert!(free(&part, &scene, pose.rotation, pose.position, 1e-6), "placement {:?} interferes", q.position);
            // every contact names pieces that touch (within the tolerance)
            for c in &q.contacts {
                if let stackplan_planner::Contact::Stack { our_component, stack_part, stack_component, .. } = c {
                    let ours: &ConvexPolytope = &part.components()[*our_component];
                    let placed = stackplan_cspace::PlacedConvex::new(ours, pose.rotation, pose.position);
                    let theirs = stackplan_cspace::PlacedConvex::new(
                        &part.components()[*stack_component],
                        poses[*stack_part].rotation,
                        poses[*stack_part].position,
                    );
                    let gap = stackplan_cspace::interference::sat_gap(&placed, &theirs, 1.0);
                    prop_assert!(gap <= 1e-6, "contact {c:?} at a gap of {gap}");
                }
            }
        }
    }
}
