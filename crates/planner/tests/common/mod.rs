//! Test parts shared by the planner's property tests: boxes and L-shapes of boxes.
#![allow(dead_code)]

use glam::DVec3;
use proptest::prelude::*;
use stackplan_geom::{ConvexPolytope, Part, PartOrigin};

/// A part made of the boxes `[lo, hi]`, density 1.
pub fn boxes(name: &str, b: &[(DVec3, DVec3)]) -> Part {
    let components = b.iter().map(|(l, h)| ConvexPolytope::cuboid(*l, *h).expect("box")).collect();
    Part::from_components(name, components, 1.0, PartOrigin::ConvexPieces).expect("part")
}

/// A box `a x b x c`, or an L of two boxes (a concave part with two components) with leg thickness `t`; sides drawn
/// from `side`, heights from `height`, thicknesses from `leg`.
pub fn box_or_l(
    side: std::ops::Range<f64>,
    height: std::ops::Range<f64>,
    leg: std::ops::Range<f64>,
) -> impl Strategy<Value = Part> {
    (side.clone(), side, height, any::<bool>(), leg).prop_map(|(a, b, c, l, t)| {
        if l {
            boxes("l", &[(DVec3::ZERO, DVec3::new(a, t, c)), (DVec3::new(0.0, t, 0.0), DVec3::new(t, t + b, c))])
        } else {
            boxes("box", &[(DVec3::ZERO, DVec3::new(a, b, c))])
        }
    })
}

/// The request of the searches into a growing stack (`carried_frontiers.rs`, `searched_elsewhere.rs`): 30-degree
/// steps, 2 mm horizontal clearance, insertion, cost (1) with `w = 0.3` about the origin, the four best.
pub fn growing_stack_request<'a>(
    part: &'a Part,
    stack: Vec<stackplan_planner::PlacedPart<'a>>,
    floor: stackplan_planner::FloorVolume,
) -> stackplan_planner::PlacementRequest<'a> {
    let mut req = stackplan_planner::PlacementRequest::new(part, stack, floor);
    req.thetas = stackplan_planner::uniform_thetas(12);
    req.cost = stackplan_planner::Cost::Stacking { w: 0.3, origin: DVec3::ZERO };
    req.clearance = 2.0;
    req.horizontal_clearance = true;
    req.insertion = true;
    req.k = 4;
    req
}
