//! Rigid parts: convex components, mass properties and the boundary faces of the whole part.
//!
//! A part is the union of convex components with pairwise disjoint interiors (the seed's decomposition, \[A\] V-A-1).
//! Everything interference analysis needs lives in the components; resting poses, grasp and contact analysis need the
//! boundary of the union, kept as planar polygons with holes in [`Part::boundary`].

use crate::mass::{MassProperties, Moments};
use crate::plate::Plate;
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
    ApproximateDecomposition {
        /// The enclosed volume of the mesh (mm^3), when known: the components' volume is the part's.
        #[serde(default)]
        mesh_volume: Option<f64>,
    },
    /// A solid from CAD (a STEP B-rep or one closed mesh) recognised as sheet metal and decomposed conservatively
    /// ([`crate::cad::recognise`]): the components contain the solid and stand outside it by at most
    /// `max_deviation`.
    RecognisedSheet {
        /// Sheet thickness (mm).
        thickness: f64,
        /// Number of plates.
        plates: usize,
        /// Number of bends.
        bends: usize,
        /// The solid's volume (mm^3); the components' volume is the part's.
        solid_volume: f64,
        /// The largest distance by which a component stands outside the solid (mm).
        max_deviation: f64,
    },
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

/// A rigid part: convex components with disjoint interiors, mass properties and boundary faces. The components are
/// fixed at construction and everything derived from them (boundary, mass, plates, and the cache keys built from
/// them) is read through accessors, so it cannot drift from them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Part {
    /// Name of the part (from the file).
    pub name: String,
    /// Convex components, in the part's own coordinates.
    pub(crate) components: Vec<ConvexPolytope>,
    /// Boundary faces of the union of the components.
    pub(crate) boundary: Vec<BoundaryFace>,
    /// Mass properties (uniform density).
    pub(crate) mass: MassProperties,
    /// Density used for the mass (1.0 when the file gives none: mass = volume).
    pub(crate) density: f64,
    /// How the part was made.
    pub origin: PartOrigin,
    /// Flat plates: the components that came from one sheet-metal face with a convex outline (empty for other
    /// parts). A search may let a plate's pieces stand for its filled outline where that is exact
    /// ([`crate::plate::merges_exactly`], [`crate::plate::slices_clear_holes`]); nothing else depends on them.
    #[serde(default)]
    pub(crate) plates: Vec<Plate>,
}

/// The point a part's moments are summed about (see `mass`: about the origin, a part far from it loses digits of
/// its inertia): the centre of the components' bounding box rounded to a multiple of the smallest power of two at least
/// the box's largest side. A part within about its size of the origin is summed about the origin itself, as it always
/// was (its c.g. and inertia unchanged to the bit; the cancellation costs it at most about one digit); a part farther
/// away about a point within its size of it.
fn moment_reference(components: &[ConvexPolytope]) -> DVec3 {
    let (lo, hi) = components
        .iter()
        .flat_map(|c| c.vertices())
        .fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let size = (hi - lo).max_element();
    if !(size > 0.0 && lo.is_finite() && hi.is_finite()) {
        return DVec3::ZERO;
    }
    let step = 2f64.powi(size.log2().ceil() as i32);
    let reference = ((0.5 * lo + 0.5 * hi) / step).round() * step;
    if reference.is_finite() { reference } else { DVec3::ZERO }
}

impl Part {
    /// The convex components, in the part's own coordinates.
    pub fn components(&self) -> &[ConvexPolytope] {
        &self.components
    }

    /// The boundary faces of the union of the components.
    pub fn boundary(&self) -> &[BoundaryFace] {
        &self.boundary
    }

    /// The mass properties (uniform density).
    pub fn mass(&self) -> &MassProperties {
        &self.mass
    }

    /// The density the mass was computed with (1.0 when the file gives none: mass = volume).
    pub fn density(&self) -> f64 {
        self.density
    }

    /// The flat plates: the components that came from one sheet-metal face with a convex outline (empty for other
    /// parts).
    pub fn plates(&self) -> &[Plate] {
        &self.plates
    }

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
        let reference = moment_reference(&components);
        let mut total = Moments::default();
        for (i, c) in components.iter().enumerate() {
            let m = Moments::of_polytope_about(c, reference);
            if m.volume.is_nan() || m.volume <= 0.0 {
                return Err(PartError::ZeroVolume(i));
            }
            total.add(&m);
        }
        let mass = total.properties_about(density, reference).ok_or(PartError::ZeroVolume(0))?;
        let boundary = boundary_faces(&components);
        Ok(Self { name: name.into(), components, boundary, mass, density, origin, plates: Vec::new() })
    }

    /// For each component, the index of the plate it belongs to ([`Part::plates`]), if any. A plate without pieces
    /// or naming a component the part does not have is left out (a part built by hand). O(components + pieces).
    pub fn plate_of_components(&self) -> Vec<Option<u32>> {
        let mut of = vec![None; self.components.len()];
        for (k, plate) in self.plates.iter().enumerate() {
            if plate.pieces.is_empty() || plate.pieces.iter().any(|&i| i >= self.components.len()) {
                continue;
            }
            for &i in &plate.pieces {
                if let Some(slot) = of.get_mut(i) {
                    *slot = Some(k as u32);
                }
            }
        }
        of
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

    /// A 64-bit fingerprint of the part's geometry and mass: its components' vertices (their bits, in order) and
    /// faces (vertex cycles), its mass and its c.g., mixed word by word. For caches and memos keyed by a part: equal
    /// parts give equal fingerprints, and a part built where a dropped one was (the same address) gives another.
    /// O(vertices + face corners).
    pub fn fingerprint(&self) -> u64 {
        let mut h = 0xcbf2_9ce4_8422_2325u64;
        let mut mix = |word: u64| h = (h ^ word).wrapping_mul(0x0000_0100_0000_01b3).rotate_left(29);
        mix(self.components.len() as u64);
        for component in &self.components {
            mix(component.vertices().len() as u64);
            for v in component.vertices() {
                v.to_array().map(f64::to_bits).into_iter().for_each(&mut mix);
            }
            // the faces' partition of the boundary too (a face split in two offers a suction cup smaller discs)
            for face in component.faces() {
                mix(face.vertices.len() as u64);
                face.vertices.iter().for_each(|&v| mix(v as u64));
            }
        }
        // the plates (which pieces stand for a filled outline in a search's cache)
        mix(self.plates.len() as u64);
        for plate in &self.plates {
            mix(plate.pieces.len() as u64);
            plate.pieces.iter().for_each(|&i| mix(i as u64));
            plate.normal.to_array().map(f64::to_bits).into_iter().for_each(&mut mix);
            mix(plate.outline_diameter.to_bits());
            mix(plate.hole_diameter.to_bits());
        }
        mix(self.mass.mass.to_bits());
        self.mass.center_of_gravity.to_array().map(f64::to_bits).into_iter().for_each(&mut mix);
        h
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

/// Boundary faces of a union of convex components with disjoint interiors.
///
/// 1. A component face is internal when another component has a face with exactly the same vertex coordinates in
///    the opposite order (two prisms of one decomposed sheet sharing a cut). O(total face size) with hashing of exact
///    coordinates.
/// 2. A remaining face `f` may still be covered, wholly or in part, by opposite coplanar faces of other components
///    (a T-junction: a cut whose two sides were split at different vertices, or touching user pieces). Every face
///    `g` with the opposite normal (within `1e-12`) on the same plane (within the policy tolerance of the part) and
///    an overlapping bounding box is subtracted from `f` by convex clipping (Sutherland-Hodgman against each edge
///    line of `g`: `f \ g` is the union over the edges `k` of `f` inside edges `0..k` and outside edge `k`). Pieces
///    with area below `tolerance x diameter` are dropped. A face left whole is kept as it is; a partly covered face
///    is replaced by its uncovered convex pieces; a fully covered face is dropped. O(F^2) candidate pairs in the
///    worst case, with a cheap bounding-box rejection.
///
/// Faces are not merged across components: coplanar boundary polygons of neighbouring components stay separate
/// polygons (without holes).
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
    // step 1: exact matches
    let mut kept: Vec<(usize, Vec<DVec3>, Plane)> = Vec::new();
    for (ci, c) in components.iter().enumerate() {
        for f in c.faces() {
            let reversed = key(f.vertices.iter().rev().map(|&v| c.vertices()[v]));
            if count.contains_key(&reversed) {
                continue;
            }
            kept.push((ci, f.vertices.iter().map(|&v| c.vertices()[v]).collect(), f.plane));
        }
    }
    // step 2: partial or inexact coverage by opposite coplanar faces of other components
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for c in components {
        for v in c.vertices() {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
    }
    let tol = Tolerance::for_scale((hi - lo).length()).linear;
    let boxes: Vec<(DVec3, DVec3)> = kept
        .iter()
        .map(|(_, pts, _)| {
            pts.iter().fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(a, b), p| {
                (a.min(*p), b.max(*p))
            })
        })
        .collect();
    let mut out = Vec::with_capacity(kept.len());
    for (i, (ci, polygon, plane)) in kept.iter().enumerate() {
        let mut pieces: Vec<Vec<DVec3>> = vec![polygon.clone()];
        let mut touched = false;
        for (j, (cj, other, other_plane)) in kept.iter().enumerate() {
            if cj == ci
                || plane.normal.dot(other_plane.normal) > -1.0 + 1e-12
                || (plane.offset + other_plane.offset).abs() > tol
                || (0..3).any(|k| boxes[i].0[k] > boxes[j].1[k] + tol || boxes[j].0[k] > boxes[i].1[k] + tol)
            {
                continue;
            }
            let mut next = Vec::new();
            for piece in &pieces {
                match subtract_convex(piece, other, other_plane.normal, tol) {
                    Some(rest) => {
                        touched = true;
                        next.extend(rest);
                    }
                    None => next.push(piece.clone()),
                }
            }
            pieces = next;
            if pieces.is_empty() {
                break;
            }
        }
        if !touched {
            out.push(BoundaryFace { outline: polygon.clone(), holes: Vec::new(), plane: *plane, component: *ci });
            continue;
        }
        for piece in pieces {
            out.push(BoundaryFace { outline: piece, holes: Vec::new(), plane: *plane, component: *ci });
        }
    }
    out
}

/// `polygon \ other` for two convex coplanar polygons (`other` counter-clockwise about `other_normal`), as convex
/// pieces with area above `tol x diameter`; `None` when they do not overlap by more than the tolerance.
fn subtract_convex(polygon: &[DVec3], other: &[DVec3], other_normal: DVec3, tol: f64) -> Option<Vec<Vec<DVec3>>> {
    let area = |p: &[DVec3]| crate::polytope::newell_normal(p.iter().copied()).length() / 2.0;
    let diameter =
        |p: &[DVec3]| p.iter().flat_map(|a| p.iter().map(move |b| (*a - *b).length())).fold(0.0f64, f64::max);
    let significant = |p: &[DVec3]| p.len() >= 3 && area(p) > tol * diameter(p).max(tol);
    let n = other.len();
    let mut rest: Vec<DVec3> = polygon.to_vec();
    let mut pieces = Vec::new();
    for k in 0..n {
        let (a, b) = (other[k], other[(k + 1) % n]);
        let len = (b - a).length();
        if len.is_nan() || len <= 0.0 {
            continue;
        }
        // signed distance in the plane: positive inside `other` (left of a -> b seen from its normal)
        let inside = |p: DVec3| (b - a).cross(p - a).dot(other_normal) / len;
        let outside_part = clip(&rest, |p| -inside(p), tol);
        let inside_part = clip(&rest, inside, tol);
        if significant(&outside_part) {
            if !significant(&inside_part) {
                // entirely outside this edge: no overlap at all
                return None;
            }
            pieces.push(outside_part);
        }
        rest = inside_part;
        if !significant(&rest) {
            // what is left of `polygon` inside edges 0..=k is negligible: no overlap
            return None;
        }
    }
    Some(pieces)
}

/// Sutherland-Hodgman: the part of a convex polygon where `distance >= 0` (points within `tol` count as on the line).
fn clip(polygon: &[DVec3], distance: impl Fn(DVec3) -> f64, tol: f64) -> Vec<DVec3> {
    let m = polygon.len();
    let mut out = Vec::with_capacity(m + 1);
    for i in 0..m {
        let p = polygon[i];
        let q = polygon[(i + 1) % m];
        let (dp, dq) = (distance(p), distance(q));
        if dp >= -tol {
            out.push(p);
        }
        if (dp > tol && dq < -tol) || (dp < -tol && dq > tol) {
            let t = dp / (dp - dq);
            out.push(p + (q - p) * t);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cuboid(lo: DVec3, hi: DVec3) -> ConvexPolytope {
        ConvexPolytope::cuboid(lo, hi).expect("box")
    }

    /// Equal parts fingerprint alike; a vertex moved by an ulp, another density (mass) or the components in
    /// another order do not.
    #[test]
    fn fingerprints_tell_parts_apart_by_geometry_and_mass() {
        let boxes = |h: f64| {
            vec![cuboid(DVec3::ZERO, DVec3::new(60.0, 30.0, 2.0)), cuboid(DVec3::ZERO, DVec3::new(2.0, 30.0, h))]
        };
        let part = |components, density| {
            Part::from_components("l", components, density, PartOrigin::ConvexPieces).expect("part")
        };
        let l = part(boxes(40.0), 1.0);
        assert_eq!(l.fingerprint(), part(boxes(40.0), 1.0).fingerprint());
        assert_eq!(l.fingerprint(), l.clone().fingerprint());
        let others = [
            part(boxes(f64::from_bits(40f64.to_bits() + 1)), 1.0),
            part(boxes(40.0), 2.0),
            part(boxes(40.0).into_iter().rev().collect(), 1.0),
        ];
        for other in &others {
            assert_ne!(l.fingerprint(), other.fingerprint());
        }
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
