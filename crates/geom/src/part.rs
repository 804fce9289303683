//! Rigid parts: convex components, mass properties and the boundary faces of the whole part.
//!
//! A part is the union of convex components with pairwise disjoint interiors (the seed's decomposition, [A] V-A-1).
//! Everything interference analysis needs lives in the components; resting poses, grasp and contact analysis need the
//! boundary of the union, kept as planar polygons with holes in [`Part::boundary`].

use crate::mass::{MassProperties, Moments};
use crate::polytope::{ConvexPolytope, Plane};
use crate::tolerance::Tolerance;
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

/// A planar face of a part's boundary: an outer polygon (counter-clockwise seen from outside) with holes (clockwise).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BoundaryFace {
    /// Outer boundary, counter-clockwise seen from outside (from the tip of the normal).
    pub outline: Vec<DVec3>,
    /// Holes, each clockwise seen from outside.
    pub holes: Vec<Vec<DVec3>>,
    /// The supporting plane with outward unit normal.
    pub plane: Plane,
    /// The component this face lies on (the first one, when a face spans several).
    pub component: usize,
}

/// How a part was made, kept for reports.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum PartOrigin {
    /// Given directly as convex pieces.
    ConvexPieces,
    /// A sheet-metal mid-surface model extruded by `thickness`.
    SheetMetal {
        /// Sheet thickness (mm).
        thickness: f64,
    },
    /// A mesh file whose shells/objects were checked to be convex.
    Mesh,
    /// A mesh decomposed by an approximate convex decomposition (VHACD): the components only approximate the input.
    ApproximateDecomposition,
}

/// Why a set of components does not make a part.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PartError {
    /// No components at all.
    #[error("the part has no components")]
    Empty,
    /// Density is not a positive finite number.
    #[error("density must be positive and finite, got {0}")]
    BadDensity(f64),
    /// A component has no positive volume.
    #[error("component {0} has no volume")]
    ZeroVolume(usize),
}

/// A rigid part: convex components with disjoint interiors, mass properties and boundary faces.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Part {
    /// Name of the part (from the file).
    pub name: String,
    /// Convex components, in the part's own coordinates.
    pub components: Vec<ConvexPolytope>,
    /// Boundary faces of the union of the components.
    pub boundary: Vec<BoundaryFace>,
    /// Mass properties (uniform density).
    pub mass: MassProperties,
    /// Density used for the mass (1.0 when the file gives none: mass = volume).
    pub density: f64,
    /// How the part was made.
    pub origin: PartOrigin,
}

impl Part {
    /// Builds a part from its convex components. O(total size) plus a hash of faces for the boundary.
    pub fn from_components(
        name: impl Into<String>,
        components: Vec<ConvexPolytope>,
        density: f64,
        origin: PartOrigin,
    ) -> Result<Self, PartError> {
        if components.is_empty() {
            return Err(PartError::Empty);
        }
        if !(density > 0.0 && density.is_finite()) {
            return Err(PartError::BadDensity(density));
        }
        let mut total = Moments::default();
        for (i, c) in components.iter().enumerate() {
            let m = Moments::of_polytope(c);
            if !(m.volume > 0.0) {
                return Err(PartError::ZeroVolume(i));
            }
            total.add(&m);
        }
        let mass = total.properties(density).ok_or(PartError::ZeroVolume(0))?;
        let boundary = boundary_faces(&components);
        Ok(Self { name: name.into(), components, boundary, mass, density, origin })
    }

    /// Axis-aligned bounding box of the part `(min, max)`.
    pub fn aabb(&self) -> (DVec3, DVec3) {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for c in &self.components {
            let (a, b) = c.aabb();
            lo = lo.min(a);
            hi = hi.max(b);
        }
        (lo, hi)
    }

    /// All component vertices (with repetitions across components).
    pub fn all_vertices(&self) -> impl Iterator<Item = DVec3> + '_ {
        self.components.iter().flat_map(|c| c.vertices().iter().copied())
    }

    /// The policy tolerance for this part (scale = bounding-box diagonal).
    pub fn tolerance(&self) -> Tolerance {
        let (lo, hi) = self.aabb();
        Tolerance::for_scale((hi - lo).length())
    }

    /// Total number of vertices over all components.
    pub fn vertex_count(&self) -> usize {
        self.components.iter().map(|c| c.vertices().len()).sum()
    }
}

/// Boundary faces of a union of convex components whose shared faces coincide exactly.
///
/// A component face is internal when another component has a face with exactly the same vertex coordinates in the
/// opposite order (two prisms of one decomposed sheet sharing a cut). Internal faces are dropped; every other face is
/// kept as its own boundary polygon. O(total face size) with hashing of exact coordinates.
pub fn boundary_faces(components: &[ConvexPolytope]) -> Vec<BoundaryFace> {
    type Key = Vec<[u64; 3]>;
    fn key(points: impl Iterator<Item = DVec3>) -> Key {
        let mut k: Key = points.map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]).collect();
        // canonical rotation: start at the smallest coordinate triple
        if let Some(m) = (0..k.len()).min_by_key(|&i| k[i]) {
            k.rotate_left(m);
        }
        k
    }
    let mut count: HashMap<Key, usize> = HashMap::new();
    for c in components {
        for f in c.faces() {
            *count.entry(key(f.vertices.iter().map(|&v| c.vertices()[v]))).or_default() += 1;
        }
    }
    let mut out = Vec::new();
    for (ci, c) in components.iter().enumerate() {
        for f in c.faces() {
            let reversed = key(f.vertices.iter().rev().map(|&v| c.vertices()[v]));
            if count.contains_key(&reversed) {
                continue;
            }
            out.push(BoundaryFace {
                outline: f.vertices.iter().map(|&v| c.vertices()[v]).collect(),
                holes: Vec::new(),
                plane: f.plane,
                component: ci,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hull::convex_hull;

    fn cuboid(lo: DVec3, hi: DVec3) -> ConvexPolytope {
        let pts: Vec<DVec3> = (0..8)
            .map(|i| {
                DVec3::new(
                    if i & 1 == 0 { lo.x } else { hi.x },
                    if i & 2 == 0 { lo.y } else { hi.y },
                    if i & 4 == 0 { lo.z } else { hi.z },
                )
            })
            .collect();
        convex_hull(&pts).expect("box").polytope
    }

    #[test]
    fn two_boxes_share_a_face() {
        let a = cuboid(DVec3::ZERO, DVec3::new(1.0, 1.0, 1.0));
        let b = cuboid(DVec3::new(1.0, 0.0, 0.0), DVec3::new(3.0, 1.0, 1.0));
        let p = Part::from_components("two", vec![a, b], 2.0, PartOrigin::ConvexPieces).expect("part");
        assert_eq!(p.boundary.len(), 10);
        assert!((p.mass.volume - 3.0).abs() < 1e-12);
        assert!((p.mass.mass - 6.0).abs() < 1e-12);
        assert!((p.mass.center_of_gravity - DVec3::new(1.5, 0.5, 0.5)).length() < 1e-12);
        assert_eq!(p.aabb(), (DVec3::ZERO, DVec3::new(3.0, 1.0, 1.0)));
    }

    #[test]
    fn bad_parts() {
        assert_eq!(Part::from_components("e", vec![], 1.0, PartOrigin::ConvexPieces), Err(PartError::Empty));
        let a = cuboid(DVec3::ZERO, DVec3::ONE);
        let r = Part::from_components("d", vec![a.clone()], -1.0, PartOrigin::ConvexPieces);
        assert_eq!(r, Err(PartError::BadDensity(-1.0)));
        assert!(matches!(
            Part::from_components("d", vec![a], f64::NAN, PartOrigin::ConvexPieces),
            Err(PartError::BadDensity(_))
        ));
    }
}
