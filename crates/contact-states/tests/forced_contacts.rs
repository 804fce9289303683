//! States that the bounds force several contacts into at once: translation-only and single-rotation boxes, where no
//! single primitive contact holds alone (a vertex on a face is the whole face on it), so the bottom-up growth by one
//! PPC at a time finds nothing and the states come from configurations ([`stackplan_contact_states::discovery`]) and
//! joined hypotheses.
//!
//! Analytic counts:
//! * a cube over a slab, translation only: its bottom face on the slab's top, 1 state;
//! * the block in the L-corner (\[P\] V geometry, shifted by (-20, -20, -20)), translation only: the floor, each
//!   wall, the three pairs and the block pressed into the corner, 7 states, among them the seated block
//!   `{f5-f1, f6-f5, f8-f2}`;
//! * a cube between two walls at a right angle (a corner), turning only about z by at most 30 degrees, z fixed at
//!   mid-height: against each wall a face (rz = 0) or either vertical edge next to it (rz > 0, rz < 0), 3 + 3; both
//!   walls with faces (rz = 0, pushed into the corner), or with an edge each turned either way, 1 + 2; no single
//!   vertex or edge can touch both walls at once without the cube penetrating one of them: 9 states.

use stackplan_contact_states::acsg::{AcsgSettings, generate};
use stackplan_contact_states::criteria::ContactPart;
use stackplan_contact_states::ga::GaSettings;
use stackplan_contact_states::pose::ConfigBox;
use stackplan_geom::{ConvexPolytope, DMat3, DVec3, Part, PartOrigin};

use crate::common;

fn part(name: &str, boxes: &[(DVec3, DVec3)]) -> Part {
    let components = boxes.iter().map(|&(lo, hi)| ConvexPolytope::cuboid(lo, hi).expect("box")).collect();
    Part::from_components(name, components, 1.0, PartOrigin::ConvexPieces).expect("part")
}

fn settings() -> AcsgSettings {
    AcsgSettings {
        ga: GaSettings { population: 20, generations: 10, polish_evaluations: 300, seed: 7 },
        extremal_budget: 100,
        samples: 500,
        ..AcsgSettings::default()
    }
}

/// Generates the graph and checks every feasible state independently at its witness; returns the labels.
fn feasible_labels(fixed: &Part, moving: &Part, bounds: ConfigBox) -> Vec<String> {
    let (a, b) = (ContactPart::from_part(fixed).expect("a"), ContactPart::from_part(moving).expect("b"));
    let g = generate(&a, &b, bounds, settings()).expect("settings");
    let tol = 1e-6 * g.length;
    for s in g.feasible() {
        let w = s.witness.expect("witness");
        if let Err(e) = common::independent_check(&a, fixed, &b, moving, &s.state, &w, tol) {
            panic!("{}: {e}", s.label);
        }
    }
    let mut labels: Vec<String> = g.feasible().map(|s| s.label.clone()).collect();
    labels.sort();
    labels
}

#[test]
fn a_cube_over_a_slab_with_translation_only_has_one_state() {
    let slab = part("slab", &[(DVec3::new(-50.0, -50.0, -10.0), DVec3::new(50.0, 50.0, 0.0))]);
    let cube = part("cube", &[(DVec3::splat(-0.5), DVec3::splat(0.5))]);
    let bounds = ConfigBox::new([-1.0, -1.0, 0.0, 0.0, 0.0, 0.0], [1.0, 1.0, 1.0, 0.0, 0.0, 0.0]).expect("box");
    let labels = feasible_labels(&slab, &cube, bounds);
    assert_eq!(labels.len(), 1, "{labels:?}");
}

#[test]
fn the_block_in_the_l_corner_with_translation_only_has_seven_states() {
    let l = stackplan_geom::examples::l_corner_part();
    let shifted: Vec<_> = l.components().iter().map(|c| c.transformed(DMat3::IDENTITY, DVec3::splat(-20.0))).collect();
    let l = Part::from_components("l-corner", shifted, 1.0, PartOrigin::ConvexPieces).expect("part");
    let block = stackplan_geom::examples::block_part();
    let bounds = ConfigBox::new([-5.0, -5.0, 0.0, 0.0, 0.0, 0.0], [5.0, 5.0, 5.0, 0.0, 0.0, 0.0]).expect("box");
    let labels = feasible_labels(&l, &block, bounds);
    assert_eq!(labels.len(), 7, "{labels:?}");
    assert!(labels.contains(&"{f5-f1, f6-f5, f8-f2}".to_string()), "{labels:?}");
    assert!(labels.contains(&"{f5-f1, f6-f5}".to_string()), "{labels:?}");
}

#[test]
fn a_cube_between_two_walls_turning_about_z_has_nine_states() {
    let walls = part(
        "corner",
        &[
            (DVec3::new(-1.0, 0.0, -1.0), DVec3::new(0.0, 3.0, 2.0)),
            (DVec3::new(-1.0, -1.0, -1.0), DVec3::new(3.0, 0.0, 2.0)),
        ],
    );
    let cube = part("cube", &[(DVec3::splat(-0.5), DVec3::splat(0.5))]);
    let d = 30f64.to_radians();
    let bounds = ConfigBox::new([0.3, 0.3, 0.5, 0.0, 0.0, -d], [2.0, 2.0, 0.5, 0.0, 0.0, d]).expect("box");
    let labels = feasible_labels(&walls, &cube, bounds);
    assert_eq!(labels.len(), 9, "{labels:?}");
}
