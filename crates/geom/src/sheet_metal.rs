//! The sheet-metal part model of \[A\] V-A-1: planar mid-surface polygons (with holes) plus a thickness.
//!
//! Each face of the zero-thickness model is extruded by the sheet thickness (symmetrically about the mid-surface,
//! `thickness / 2` to each side) into convex prisms: a convex face without holes gives one prism; a concave face or a
//! face with holes is first decomposed into convex polygons (see [`Decomposition`]).
//!
//! Pipeline per face (details, tolerances and limits in `crates/geom/README-sheet.md`):
//! 1. validation with located errors ([`SheetMetalError`]): finite coordinates, at least three distinct vertices,
//!    non-zero area, planarity within [`crate::polygon::PLANARITY_FACTOR`] policy tolerances of the outline's plane,
//!    simple rings, holes strictly inside and pairwise disjoint ([`crate::polygon`], exact 2-D predicates on the
//!    input coordinates after dropping the dominant normal axis);
//! 2. removal of straight and nearly straight vertices ([`crate::polygon::simplify_ring`]);
//! 3. triangulation with holes (Eberly's bridging and ear clipping, then constrained-Delaunay flips:
//!    [`crate::triangulate`]) and, for [`Decomposition::ConvexMerge`], Hertel-Mehlhorn merging
//!    ([`crate::convex_merge`]);
//! 4. extrusion of every convex polygon into a prism with explicit faces, checked by
//!    [`ConvexPolytope::validate`]. All prisms of a face share lifted vertices, so cuts are bit-identical faces.
//!
//! Cost: O(n log n + k) validation (k = edge pairs with overlapping x-ranges), O(n^2) typical triangulation and
//! merging, O(n) extrusion, per face of n vertices.

use crate::convex_merge::merge_convex;
use crate::part::{Part, PartError, PartOrigin};
use crate::plate::Plate;
use crate::polygon::{
    FacePlane, RingDefect, check_rings, drop_collinear, is_convex_ccw, ring_orientation, simplify_ring,
};
use crate::polytope::{ConvexPolytope, PolytopeError, newell_normal};
use crate::predicates::orient2d;
use crate::tolerance::{Tolerance, bounding_diagonal};
use crate::triangulate::{TriangulationError, triangulate_avoiding_slivers};
use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};
use std::cmp::Ordering;

/// A zero-thickness sheet-metal model: planar faces with holes, and the sheet thickness.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SheetMetal {
    /// Sheet thickness (mm), > 0.
    pub thickness: f64,
    /// Planar mid-surface faces.
    pub faces: Vec<SheetFace>,
}

/// One planar mid-surface face: an outline and holes, all coplanar.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SheetFace {
    /// Outer boundary (either orientation; normalised when building).
    pub outline: Vec<DVec3>,
    /// Holes strictly inside the outline.
    #[serde(default)]
    pub holes: Vec<Vec<DVec3>>,
}

/// How concave faces and faces with holes are split into convex polygons before extrusion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Decomposition {
    /// Triangulate, then merge triangles into larger convex polygons (Hertel-Mehlhorn): few components.
    #[default]
    ConvexMerge,
    /// The plain triangulation of \[A\]: reproduces the seed's component counts (Channel 3, Triangle 6, Complex 79).
    Triangulation,
}

/// Which ring of a face an error refers to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Ring {
    /// The outer boundary.
    Outline,
    /// Hole `k` (index into [`SheetFace::holes`]).
    Hole(usize),
}

impl std::fmt::Display for Ring {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Ring::Outline => write!(f, "outline"),
            Ring::Hole(k) => write!(f, "hole {k}"),
        }
    }
}

impl Ring {
    fn from_index(r: usize) -> Self {
        if r == 0 { Ring::Outline } else { Ring::Hole(r - 1) }
    }
}

/// Why a sheet-metal model cannot be turned into a part. Face, ring and vertex indices refer to the input (vertex
/// indices count the ring's points as given, before consecutive duplicates are removed).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SheetMetalError {
    /// The thickness is not a positive finite number.
    #[error("sheet thickness must be positive and finite, got {0}")]
    BadThickness(f64),
    /// There are no faces.
    #[error("the sheet-metal model has no faces")]
    NoFaces,
    /// A face index beyond the model's faces was asked for.
    #[error("face {face} does not exist: the model has {count} faces")]
    NoSuchFace {
        /// The requested face.
        face: usize,
        /// Number of faces.
        count: usize,
    },
    /// A coordinate is NaN or infinite.
    #[error("face {face}, {ring}, vertex {vertex}: coordinate is not finite")]
    NonFinite {
        /// Face index.
        face: usize,
        /// Ring.
        ring: Ring,
        /// Vertex index in the ring.
        vertex: usize,
    },
    /// A ring has fewer than three distinct vertices.
    #[error("face {face}, {ring}: only {count} distinct vertices, a polygon needs at least 3")]
    TooFewVertices {
        /// Face index.
        face: usize,
        /// Ring.
        ring: Ring,
        /// Distinct vertices (after removing consecutive duplicates).
        count: usize,
    },
    /// A ring has zero area (all its vertices are collinear, or its area cancels out).
    #[error("face {face}, {ring}: zero area")]
    ZeroArea {
        /// Face index.
        face: usize,
        /// Ring.
        ring: Ring,
    },
    /// A vertex is farther from the face's fitted plane than the planarity tolerance.
    #[error(
        "face {face} is not planar: {ring} vertex {vertex} is {distance:e} mm from the fitted plane (tolerance {tolerance:e} mm)"
    )]
    NonPlanar {
        /// Face index.
        face: usize,
        /// Ring.
        ring: Ring,
        /// Vertex index in the ring.
        vertex: usize,
        /// Distance from the plane (mm).
        distance: f64,
        /// The planarity tolerance used (mm).
        tolerance: f64,
    },
    /// A ring intersects itself (edge `k` joins vertex `k` and the next distinct vertex).
    #[error("face {face}, {ring}: edges {edge_a} and {edge_b} intersect (the polygon is not simple)")]
    SelfIntersecting {
        /// Face index.
        face: usize,
        /// Ring.
        ring: Ring,
        /// First edge (index of its start vertex in the input ring).
        edge_a: usize,
        /// Second edge.
        edge_b: usize,
    },
    /// A hole touches, crosses or lies outside the outline.
    #[error("face {face}: hole {hole} is not strictly inside the outline")]
    HoleNotInside {
        /// Face index.
        face: usize,
        /// Hole index.
        hole: usize,
    },
    /// Two holes touch, cross or nest.
    #[error("face {face}: holes {hole_a} and {hole_b} overlap or touch")]
    HolesOverlap {
        /// Face index.
        face: usize,
        /// First hole.
        hole_a: usize,
        /// Second hole.
        hole_b: usize,
    },
    /// Triangulation failed (an internal error: validation should have caught the cause).
    #[error("face {face}: triangulation failed: {source}")]
    Triangulation {
        /// Face index.
        face: usize,
        /// The cause.
        source: TriangulationError,
    },
    /// An extruded piece is not a valid convex polytope (a sliver below the tolerance of the kernel).
    #[error("face {face}, piece {piece}: extruded prism is invalid: {source}")]
    Prism {
        /// Face index.
        face: usize,
        /// Piece index within the face.
        piece: usize,
        /// The cause.
        source: PolytopeError,
    },
    /// The components do not make a part.
    #[error(transparent)]
    Part(#[from] PartError),
}

/// A face after validation: its plane, its points in the exact 2-D projection, and its convex pieces.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceDecomposition {
    /// The fitted plane and projection.
    pub plane: FacePlane,
    /// All distinct vertices of the face (outline first, then holes), projected exactly to 2-D.
    pub points: Vec<DVec2>,
    /// The same points on the fitted plane (lifted back from 2-D).
    pub points_on_plane: Vec<DVec3>,
    /// The outline, counter-clockwise in 2-D, as indices into `points`.
    pub outline: Vec<usize>,
    /// The holes, clockwise in 2-D.
    pub holes: Vec<Vec<usize>>,
    /// Strictly convex counter-clockwise (2-D) polygons tiling the face, straight vertices removed.
    pub pieces: Vec<Vec<usize>>,
    /// The length below which a turn counts as straight for this face (see [`crate::polygon::nearly_straight`]):
    /// `SLIVER_FACTOR` policy tolerances for the face's size plus the thickness.
    pub flat: f64,
}

impl FaceDecomposition {
    /// Area of the face in its plane (outline minus holes; mm^2).
    pub fn area(&self) -> f64 {
        let ring_area = |ring: &[usize]| {
            let pts: Vec<DVec3> = ring.iter().map(|&i| self.points_on_plane[i]).collect();
            newell_normal(pts.iter().copied()).length() / 2.0
        };
        ring_area(&self.outline) - self.holes.iter().map(|h| ring_area(h)).sum::<f64>()
    }

    /// The 3-D polygon of piece `k` on the mid-plane, counter-clockwise about the plane normal.
    pub fn piece_polygon(&self, k: usize) -> Vec<DVec3> {
        let mut cycle: Vec<DVec3> = self.pieces[k].iter().map(|&i| self.points_on_plane[i]).collect();
        if !self.plane.projection_keeps_orientation() {
            cycle.reverse();
        }
        cycle
    }
}

impl SheetMetal {
    /// Checks the whole model (thickness and every face) without building prisms. See [`SheetMetalError`].
    pub fn validate(&self) -> Result<(), SheetMetalError> {
        self.check_thickness()?;
        for (i, face) in self.faces.iter().enumerate() {
            prepare_face(i, face, self.thickness)?;
        }
        Ok(())
    }

    fn check_thickness(&self) -> Result<(), SheetMetalError> {
        if !(self.thickness > 0.0 && self.thickness.is_finite()) {
            return Err(SheetMetalError::BadThickness(self.thickness));
        }
        if self.faces.is_empty() {
            return Err(SheetMetalError::NoFaces);
        }
        Ok(())
    }

    /// Validates face `face` and splits it into convex polygons (one when it is convex without holes).
    pub fn decompose_face(
        &self,
        face: usize,
        decomposition: Decomposition,
    ) -> Result<FaceDecomposition, SheetMetalError> {
        self.check_thickness()?;
        let Some(f) = self.faces.get(face) else {
            return Err(SheetMetalError::NoSuchFace { face, count: self.faces.len() });
        };
        let mut prepared = prepare_face(face, f, self.thickness)?;
        let outline_pts: Vec<DVec2> = prepared.outline.iter().map(|&i| prepared.points[i]).collect();
        let raw_pieces = if prepared.holes.is_empty() && is_convex_ccw(&outline_pts) {
            vec![prepared.outline.clone()]
        } else {
            let sliver = prepared.flat;
            let triangles = triangulate_avoiding_slivers(&prepared.points, &prepared.outline, &prepared.holes, sliver)
                .map_err(|source| SheetMetalError::Triangulation { face, source })?;
            match decomposition {
                Decomposition::Triangulation => triangles.iter().map(|t| t.to_vec()).collect(),
                Decomposition::ConvexMerge => merge_convex(&prepared.points, &triangles, prepared.flat),
            }
        };
        prepared.pieces = raw_pieces.iter().map(|p| drop_collinear(p, &prepared.points)).collect();
        tracing::debug!(face, pieces = prepared.pieces.len(), ?decomposition, "decomposed sheet-metal face");
        Ok(prepared)
    }

    /// The convex prisms of every face, grouped by face: each convex polygon extruded by `thickness / 2` to both
    /// sides of the face plane. Every prism passes [`ConvexPolytope::validate`].
    pub fn decompose(&self, decomposition: Decomposition) -> Result<Vec<Vec<ConvexPolytope>>, SheetMetalError> {
        Ok(self.decompose_with_faces(decomposition)?.into_iter().map(|(_, prisms)| prisms).collect())
    }

    /// [`SheetMetal::decompose`] with each face's decomposition beside its prisms.
    fn decompose_with_faces(
        &self,
        decomposition: Decomposition,
    ) -> Result<Vec<(FaceDecomposition, Vec<ConvexPolytope>)>, SheetMetalError> {
        self.check_thickness()?;
        (0..self.faces.len())
            .map(|face| {
                let d = self.decompose_face(face, decomposition)?;
                let prisms = extrude(face, &d, self.thickness)?;
                Ok((d, prisms))
            })
            .collect()
    }

    /// Builds the rigid part: validation, decomposition, extrusion, mass properties and boundary faces.
    /// Every face with a convex outline is a [`Plate`] of the part (its prisms' indices, normal, filled outline and
    /// the diameters of its outline and largest hole).
    pub fn build_part(&self, name: &str, density: f64, decomposition: Decomposition) -> Result<Part, SheetMetalError> {
        Ok(self.build_part_counted(name, density, decomposition)?.0)
    }

    /// [`SheetMetal::build_part`], with the number of prisms of each face (the part's components are the faces'
    /// prisms in face order).
    pub fn build_part_counted(
        &self,
        name: &str,
        density: f64,
        decomposition: Decomposition,
    ) -> Result<(Part, Vec<usize>), SheetMetalError> {
        let mut components: Vec<ConvexPolytope> = Vec::new();
        let mut plates: Vec<Plate> = Vec::new();
        let mut counts: Vec<usize> = Vec::with_capacity(self.faces.len());
        for (d, prisms) in self.decompose_with_faces(decomposition)? {
            counts.push(prisms.len());
            let corners = |ring: &[usize]| ring.iter().map(|&i| d.points_on_plane[i]).collect::<Vec<DVec3>>();
            let outline_2d: Vec<DVec2> = d.outline.iter().map(|&i| d.points[i]).collect();
            if !prisms.is_empty() && is_convex_ccw(&outline_2d) {
                let holes: Vec<Vec<DVec3>> = d.holes.iter().map(|h| corners(h)).collect();
                let pieces = (components.len()..components.len() + prisms.len()).collect();
                plates.extend(Plate::new(pieces, &prisms, d.plane.normal, &corners(&d.outline), &holes));
            }
            components.extend(prisms);
        }
        let mut part =
            Part::from_components(name, components, density, PartOrigin::SheetMetal { thickness: self.thickness })?;
        part.plates = plates;
        tracing::debug!(
            name,
            components = part.components.len(),
            plates = part.plates.len(),
            volume = part.mass.volume,
            "built sheet-metal part"
        );
        Ok((part, counts))
    }
}

/// Multiple of the policy tolerance below which a vertex counts as nearly straight (see [`flat_vertex`]).
const SLIVER_FACTOR: f64 = 4.0;

/// Extrudes the pieces of one face: `q -/+ n t/2` for every point `q` on the plane, shared by all pieces (so pieces
/// that share a cut have bit-identical side faces).
///
/// Pieces are strictly convex in exact arithmetic, but input that is only nearly collinear (a collinear run after a
/// rotation) leaves vertices whose turn is below the kernel's tolerance, and [`ConvexPolytope::validate`] would
/// reject the prism as not strictly convex. Such vertices are removed (moving the piece's boundary by less than
/// `SLIVER_FACTOR` policy tolerances), and a piece that is a needle below the tolerance is dropped (its volume is
/// below `SLIVER_FACTOR * tolerance * length * thickness`).
fn extrude(face: usize, d: &FaceDecomposition, thickness: f64) -> Result<Vec<ConvexPolytope>, SheetMetalError> {
    let half = d.plane.normal * (thickness / 2.0);
    let below: Vec<DVec3> = d.points_on_plane.iter().map(|q| *q - half).collect();
    let above: Vec<DVec3> = d.points_on_plane.iter().map(|q| *q + half).collect();
    let keep = d.plane.projection_keeps_orientation();
    let mut prisms = Vec::with_capacity(d.pieces.len());
    for (piece, cycle) in d.pieces.iter().enumerate() {
        let mut cycle = cycle.clone();
        if !keep {
            cycle.reverse();
        }
        let flat = d.flat;
        while cycle.len() >= 3 {
            let m = cycle.len();
            let Some(k) = (0..m).find(|&k| {
                let (u, v, w) = (cycle[(k + m - 1) % m], cycle[k], cycle[(k + 1) % m]);
                flat_vertex(d.points_on_plane[u], d.points_on_plane[v], d.points_on_plane[w], flat)
            }) else {
                break;
            };
            cycle.remove(k);
        }
        if cycle.len() < 3 {
            tracing::debug!(face, piece, "dropped a needle piece thinner than the tolerance");
            continue;
        }
        let prism = prism(&cycle, &below, &above)
            .and_then(|p| p.validate().map(|()| p))
            .map_err(|source| SheetMetalError::Prism { face, piece, source })?;
        prisms.push(prism);
    }
    Ok(prisms)
}

/// Whether the turn `u -> v -> w` is too small for a strictly convex prism under the tolerance `flat`: one
/// neighbour lies within `flat` of the line through `v` and the other (the distances `validate` tests across the
/// side edge at `v`).
fn flat_vertex(u: DVec3, v: DVec3, w: DVec3, flat: f64) -> bool {
    let distance = |p: DVec3, a: DVec3, b: DVec3| {
        let dir = b - a;
        let len = dir.length();
        if len > 0.0 { (p - a).cross(dir).length() / len } else { (p - a).length() }
    };
    distance(w, u, v) <= flat || distance(u, v, w) <= flat
}

/// The prism over a convex cycle (counter-clockwise about the extrusion direction `above - below`).
fn prism(cycle: &[usize], below: &[DVec3], above: &[DVec3]) -> Result<ConvexPolytope, PolytopeError> {
    prism_between(cycle.iter().map(|&i| below[i]).collect(), cycle.iter().map(|&i| above[i]).collect())
}

/// The prism between two translated copies of a convex polygon, `bottom` counter-clockwise about the direction from
/// it to `top` (vertex `k` of `top` above vertex `k` of `bottom`): its caps and one quadrilateral side per edge.
pub(crate) fn prism_between(bottom: Vec<DVec3>, top: Vec<DVec3>) -> Result<ConvexPolytope, PolytopeError> {
    let m = bottom.len();
    let mut vertices = bottom;
    vertices.extend(top);
    let mut faces: Vec<Vec<usize>> = Vec::with_capacity(m + 2);
    faces.push((m..2 * m).collect());
    faces.push((0..m).rev().collect());
    for i in 0..m {
        let j = (i + 1) % m;
        faces.push(vec![i, j, m + j, m + i]);
    }
    ConvexPolytope::new(vertices, faces)
}

/// Validates a face and returns it projected, oriented, with no pieces yet.
fn prepare_face(face: usize, f: &SheetFace, thickness: f64) -> Result<FaceDecomposition, SheetMetalError> {
    // rings as given: 0 = outline, k + 1 = hole k
    let rings: Vec<&[DVec3]> =
        std::iter::once(f.outline.as_slice()).chain(f.holes.iter().map(|h| h.as_slice())).collect();
    for (r, ring) in rings.iter().enumerate() {
        if let Some(vertex) = ring.iter().position(|p| !p.is_finite()) {
            return Err(SheetMetalError::NonFinite { face, ring: Ring::from_index(r), vertex });
        }
    }
    // consecutive duplicates removed; keep the input index of every kept vertex
    let mut cleaned: Vec<Vec<(usize, DVec3)>> = Vec::with_capacity(rings.len());
    for (r, ring) in rings.iter().enumerate() {
        let mut kept: Vec<(usize, DVec3)> = Vec::with_capacity(ring.len());
        for (i, p) in ring.iter().enumerate() {
            if kept.last().is_none_or(|(_, q)| q != p) {
                kept.push((i, *p));
            }
        }
        while kept.len() > 1 && kept.first().map(|x| x.1) == kept.last().map(|x| x.1) {
            kept.pop();
        }
        if kept.len() < 3 {
            return Err(SheetMetalError::TooFewVertices { face, ring: Ring::from_index(r), count: kept.len() });
        }
        cleaned.push(kept);
    }
    let outline3: Vec<DVec3> = cleaned[0].iter().map(|x| x.1).collect();
    let all3: Vec<DVec3> = cleaned.iter().flatten().map(|x| x.1).collect();
    let plane = FacePlane::fit(&outline3).ok_or(SheetMetalError::ZeroArea { face, ring: Ring::Outline })?;
    let tolerance = FacePlane::planarity_tolerance(&all3);
    for (r, ring) in cleaned.iter().enumerate() {
        for &(vertex, p) in ring {
            let distance = plane.distance(p);
            if distance.abs() > tolerance || distance.is_nan() {
                return Err(SheetMetalError::NonPlanar {
                    face,
                    ring: Ring::from_index(r),
                    vertex,
                    distance,
                    tolerance,
                });
            }
        }
    }
    let rings2: Vec<Vec<DVec2>> =
        cleaned.iter().map(|ring| ring.iter().map(|x| plane.project(x.1)).collect()).collect();
    for (r, ring) in rings2.iter().enumerate() {
        let all_collinear = (2..ring.len()).all(|k| orient2d(ring[0], ring[1], ring[k]) == Ordering::Equal);
        if all_collinear {
            return Err(SheetMetalError::ZeroArea { face, ring: Ring::from_index(r) });
        }
    }
    // input indices of the ring points, for error reports
    let input_index: Vec<Vec<usize>> = cleaned.iter().map(|ring| ring.iter().map(|x| x.0).collect()).collect();
    let report = |defect: RingDefect, index: &[Vec<usize>]| match defect {
        RingDefect::SelfIntersection { ring, edge_a, edge_b } => SheetMetalError::SelfIntersecting {
            face,
            ring: Ring::from_index(ring),
            edge_a: index[ring][edge_a],
            edge_b: index[ring][edge_b],
        },
        RingDefect::HoleNotInside { ring } => SheetMetalError::HoleNotInside { face, hole: ring - 1 },
        RingDefect::HolesOverlap { ring_a, ring_b } => {
            SheetMetalError::HolesOverlap { face, hole_a: ring_a - 1, hole_b: ring_b - 1 }
        }
    };
    check_rings(&rings2).map_err(|d| report(d, &input_index))?;
    // Remove straight and nearly straight vertices (see `FaceDecomposition::flat`), then check again: a ring that
    // collapses is a sliver, and rings closer than `flat` to each other may now touch.
    let flat = SLIVER_FACTOR * Tolerance::for_scale(bounding_diagonal(&all3) + thickness).linear;
    let mut simplified: Vec<Vec<(usize, DVec2)>> = Vec::with_capacity(rings2.len());
    for (r, (ring, index)) in rings2.iter().zip(&input_index).enumerate() {
        let tagged: Vec<(usize, DVec2)> = index.iter().copied().zip(ring.iter().copied()).collect();
        let kept = simplify_ring(&tagged, flat);
        if kept.len() < 3 {
            return Err(SheetMetalError::ZeroArea { face, ring: Ring::from_index(r) });
        }
        simplified.push(kept);
    }
    let rings2: Vec<Vec<DVec2>> = simplified.iter().map(|r| r.iter().map(|x| x.1).collect()).collect();
    let input_index: Vec<Vec<usize>> = simplified.iter().map(|r| r.iter().map(|x| x.0).collect()).collect();
    check_rings(&rings2).map_err(|d| report(d, &input_index))?;
    // orient: outline counter-clockwise, holes clockwise (in 2-D)
    let mut points: Vec<DVec2> = Vec::with_capacity(all3.len());
    let mut outline = Vec::new();
    let mut holes = Vec::new();
    for (r, ring) in rings2.iter().enumerate() {
        let start = points.len();
        points.extend_from_slice(ring);
        let mut idx: Vec<usize> = (start..points.len()).collect();
        let want = if r == 0 { Ordering::Greater } else { Ordering::Less };
        if ring_orientation(ring) != want {
            idx.reverse();
        }
        if r == 0 {
            outline = idx;
        } else {
            holes.push(idx);
        }
    }
    let points_on_plane = points.iter().map(|q| plane.lift(*q)).collect();
    Ok(FaceDecomposition { plane, points, points_on_plane, outline, holes, pieces: Vec::new(), flat })
}
