//! Test parts: boxes and wedges built with the exact hull.
#![allow(dead_code)]

use glam::{DMat3, DVec3};
use stackplan_geom::{ConvexPolytope, Part, PartOrigin, convex_hull};
use stackplan_stability::PlacedPart;

/// The box `[lo, hi]`.
pub fn cuboid(lo: DVec3, hi: DVec3) -> ConvexPolytope {
    ConvexPolytope::cuboid(lo, hi).expect("box")
}

/// A box part `[0, size]` with density 1.
pub fn box_part(name: &str, size: DVec3) -> Part {
    Part::from_components(name, vec![cuboid(DVec3::ZERO, size)], 1.0, PartOrigin::ConvexPieces).expect("box part")
}

/// A part made of several boxes.
pub fn boxes_part(name: &str, boxes: &[(DVec3, DVec3)]) -> Part {
    let comps = boxes.iter().map(|(lo, hi)| cuboid(*lo, *hi)).collect();
    Part::from_components(name, comps, 1.0, PartOrigin::ConvexPieces).expect("boxes part")
}

/// A wedge: the triangle (0,0), (length,0), (0,height) in xz extruded over y in [0, width]; its sloped face rises
/// towards -x with angle atan(height / length).
pub fn wedge_part(name: &str, length: f64, height: f64, width: f64) -> Part {
    let tri = [DVec3::ZERO, DVec3::new(length, 0.0, 0.0), DVec3::new(0.0, 0.0, height)];
    let pts: Vec<DVec3> = tri.iter().flat_map(|&p| [p, p + DVec3::Y * width]).collect();
    let hull = convex_hull(&pts).expect("wedge").polytope;
    Part::from_components(name, vec![hull], 1.0, PartOrigin::ConvexPieces).expect("wedge part")
}

/// A placement with identity rotation.
pub fn at(part: &Part, position: DVec3) -> PlacedPart<'_> {
    PlacedPart { part, rotation: DMat3::IDENTITY, position }
}
