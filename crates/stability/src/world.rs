//! Placed parts in world coordinates: the common input of contacts, equilibrium, insertion and the stack check.
//!
//! A [`PlacedPart`] is a part with a rigid pose `world = R v + p`. [`WorldPart::new`] transforms every convex
//! component once (O(total size)) and caches what the separating-axis tests need: bounding boxes and the face-normal
//! and edge directions of each component, deduplicated up to sign.

use crate::StabilityError;
use glam::{DMat3, DVec3};
use stackplan_geom::{ConvexPolytope, Tolerance};

pub use stackplan_geom::PlacedPart;

/// One convex component in world coordinates with the data the separating-axis test needs.
#[derive(Debug, Clone)]
pub struct WorldComponent {
    /// The polytope in world coordinates.
    pub polytope: ConvexPolytope,
    /// Axis-aligned bounding box `(min, max)`.
    pub aabb: (DVec3, DVec3),
    /// Unit face normals, deduplicated up to sign.
    pub normals: Vec<DVec3>,
    /// Unit edge directions, deduplicated up to sign.
    pub edge_directions: Vec<DVec3>,
}

impl WorldComponent {
    /// Prepares a world-coordinate polytope.
    pub fn new(polytope: ConvexPolytope) -> Self {
        let aabb = polytope.aabb();
        let normals = dedup_directions(polytope.faces().iter().map(|f| f.plane.normal));
        let v = polytope.vertices();
        let edge_directions = dedup_directions(
            polytope.edges().iter().map(|e| (v[e.vertices[1]] - v[e.vertices[0]]).normalize_or_zero()),
        );
        Self { polytope, aabb, normals, edge_directions }
    }
}

/// Keeps one representative of every direction class `{d, -d}` (directions closer than 1e-12 rad are merged).
fn dedup_directions(dirs: impl Iterator<Item = DVec3>) -> Vec<DVec3> {
    let mut out: Vec<DVec3> = Vec::new();
    for d in dirs {
        if d == DVec3::ZERO || !d.is_finite() {
            continue;
        }
        if out.iter().all(|o| o.cross(d).length() > 1e-12) {
            out.push(d);
        }
    }
    out
}

/// A placed part in world coordinates.
#[derive(Debug, Clone)]
pub struct WorldPart {
    /// Name of the part.
    pub name: String,
    /// Components in world coordinates.
    pub components: Vec<WorldComponent>,
    /// Centre of gravity in world coordinates.
    pub center_of_gravity: DVec3,
    /// Mass (the part's mass unit).
    pub mass: f64,
    /// Bounding box of all components.
    pub aabb: (DVec3, DVec3),
}

/// Checks that `rotation` is a proper rotation within 1e-9 (orthonormal columns, determinant +1).
pub fn check_rotation(rotation: DMat3, part: usize) -> Result<(), StabilityError> {
    let should_be_identity = rotation.transpose() * rotation;
    let err = (should_be_identity - DMat3::IDENTITY).to_cols_array().iter().fold(0.0f64, |m, x| m.max(x.abs()));
    // written so that NaN entries fail the check
    let proper = err <= 1e-9 && (rotation.determinant() - 1.0).abs() <= 1e-9;
    if !proper {
        return Err(StabilityError::NotARotation { part });
    }
    Ok(())
}

/// The errors of a placed part (index `index` in its stack) that [`WorldPart::new`] and [`WorldPart::aabb_of`]
/// refuse: a rotation that is not one, a position that is not finite, a part without components.
fn check_placed(placed: &PlacedPart<'_>, index: usize) -> Result<(), StabilityError> {
    check_rotation(placed.pose.rotation, index)?;
    if !placed.pose.position.is_finite() {
        return Err(StabilityError::NonFinitePosition { part: index });
    }
    if placed.part.components().is_empty() {
        return Err(StabilityError::EmptyPart { part: index });
    }
    Ok(())
}

impl WorldPart {
    /// Transforms the part `placed` (index `index` in its stack, used in errors).
    pub fn new(placed: &PlacedPart<'_>, index: usize) -> Result<Self, StabilityError> {
        check_placed(placed, index)?;
        let components: Vec<WorldComponent> = placed
            .part
            .components()
            .iter()
            .map(|c| WorldComponent::new(c.transformed(placed.pose.rotation, placed.pose.position)))
            .collect();
        let aabb =
            components.iter().fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(lo, hi), c| {
                (lo.min(c.aabb.0), hi.max(c.aabb.1))
            });
        Ok(Self {
            name: placed.part.name.clone(),
            components,
            center_of_gravity: placed.pose.rotation * placed.part.mass().center_of_gravity + placed.pose.position,
            mass: placed.part.mass().mass,
            aabb,
        })
    }

    /// The bounding box [`WorldPart::new`] gives `placed`, bit for bit (the same transformed vertices; a minimum
    /// and a maximum do not round), without building its components; the same errors. O(vertices).
    pub fn aabb_of(placed: &PlacedPart<'_>, index: usize) -> Result<(DVec3, DVec3), StabilityError> {
        check_placed(placed, index)?;
        Ok(placed.part.components().iter().flat_map(|c| c.vertices()).fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), v| {
                // `ConvexPolytope::transformed`'s arithmetic
                let w = placed.pose.rotation * *v + placed.pose.position;
                (lo.min(w), hi.max(w))
            },
        ))
    }

    /// Bounding-box diagonal.
    pub fn diagonal(&self) -> f64 {
        (self.aabb.1 - self.aabb.0).length()
    }
}

/// Transforms a whole stack.
pub fn world_stack(stack: &[PlacedPart<'_>]) -> Result<Vec<WorldPart>, StabilityError> {
    stack.iter().enumerate().map(|(i, p)| WorldPart::new(p, i)).collect()
}

/// The tolerance policy for a stack: scale = the diagonal of the bounding box of the whole stack.
pub fn stack_tolerance(parts: &[WorldPart]) -> Tolerance {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for p in parts {
        lo = lo.min(p.aabb.0);
        hi = hi.max(p.aabb.1);
    }
    Tolerance::for_scale((hi - lo).length())
}

/// Whether two boxes overlap after enlarging by `margin`.
#[inline]
pub fn aabb_overlap(a: &(DVec3, DVec3), b: &(DVec3, DVec3), margin: f64) -> bool {
    a.0.x <= b.1.x + margin
        && b.0.x <= a.1.x + margin
        && a.0.y <= b.1.y + margin
        && b.0.y <= a.1.y + margin
        && a.0.z <= b.1.z + margin
        && b.0.z <= a.1.z + margin
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::EulerRot;
    use stackplan_geom::Pose;

    /// `aabb_of` is the box `WorldPart::new` builds, bit for bit, at turned poses far from the origin; and it fails
    /// where `new` fails.
    #[test]
    fn the_box_without_the_components_is_the_world_parts_box() {
        let part = stackplan_geom::examples::l_corner_part();
        for k in 0..50 {
            let t = k as f64;
            let rotation = DMat3::from_euler(EulerRot::ZYX, 0.37 * t, 0.11 * t - 2.0, 0.05 * t);
            let position = DVec3::new(1e5 * (t - 25.0).sin(), 13.7 * t, -0.3 * t);
            let placed = PlacedPart { part: &part, pose: Pose { rotation, position } };
            let boxed = WorldPart::aabb_of(&placed, k).expect("pose");
            let built = WorldPart::new(&placed, k).expect("pose").aabb;
            assert_eq!(boxed.0.to_array().map(f64::to_bits), built.0.to_array().map(f64::to_bits), "{k}");
            assert_eq!(boxed.1.to_array().map(f64::to_bits), built.1.to_array().map(f64::to_bits), "{k}");
        }
        let bad = PlacedPart {
            part: &part,
            pose: Pose { rotation: DMat3::from_diagonal(DVec3::new(1.0, 1.0, -1.0)), position: DVec3::ZERO },
        };
        assert!(WorldPart::aabb_of(&bad, 3).is_err() && WorldPart::new(&bad, 3).is_err());
        let nan = PlacedPart {
            part: &part,
            pose: Pose { rotation: DMat3::IDENTITY, position: DVec3::new(f64::NAN, 0.0, 0.0) },
        };
        assert!(WorldPart::aabb_of(&nan, 3).is_err() && WorldPart::new(&nan, 3).is_err());
    }
}
