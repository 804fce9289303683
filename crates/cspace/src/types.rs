//! The obstacle's types and the constants shared by the overlay's routes: a leaf module (it imports no other module
//! of this crate), so that `minkowski.rs`, `z_prism.rs` and `planar.rs` import it and not each other.
//!
//! Paper: Ayyadevara et al. 2002 (\[A\]) Appendix B, eq. 12: `C(A, B) = ConvexHull{ V_j^B - R V_i^A }` with the vertex
//! provenance `[i, j]` of every vertex; the face kinds are the generating feature pairs of the faces of a Minkowski
//! sum (`F_u(P + Q) = F_u(P) + F_u(Q)`; `docs/algorithms.md`, "C-space obstacle of a convex pair"). O(1) per
//! accessor; [`Obstacle::structure`] is O(size log size).

use glam::{DMat3, DVec3};
use serde::{Deserialize, Serialize};
use stackplan_geom::HullError;
use stackplan_geom::polytope::{Containment, ConvexPolytope, Plane, PolytopeError};
use stackplan_geom::tolerance::{RELATIVE, Tolerance};

/// Angular tolerance (radians) of the Gauss-map decisions: a face normal within this of an arc's circle lies on it;
/// two face normals within half of it are the same direction.
pub const ANGULAR_TOLERANCE: f64 = RELATIVE;

/// A feature (vertex, edge or face index) of one of the two polytopes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(tag = "feature", content = "index", rename_all = "snake_case")]
pub enum Feature {
    /// A vertex index.
    Vertex(usize),
    /// An edge index (into [`ConvexPolytope::edges`]).
    Edge(usize),
    /// A face index.
    Face(usize),
}

/// What generated a face of the obstacle. Indices refer to the moving polytope `A` (vertices, edges, faces of `A` in
/// its own coordinates) and the fixed polytope `B`.
///
/// The first three kinds are the generic ones (\[A\] App. B; `docs/algorithms.md`, "C-space obstacle of a convex
/// pair"). The last three are the merged faces of degenerate configurations (parallel faces, a face parallel to an
/// edge): they are exactly one face of the sum and name both generating features.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum FaceKind {
    /// Face `face_b` of `B` translated by vertex `vertex_a` of `-RA`: normal = that face's normal.
    FixedFace {
        /// Face of `B`.
        face_b: usize,
        /// Vertex of `A`.
        vertex_a: usize,
    },
    /// Face `face_a` of `-RA` translated by vertex `vertex_b` of `B`: normal = `-R n_A`.
    MovingFace {
        /// Face of `A`.
        face_a: usize,
        /// Vertex of `B`.
        vertex_b: usize,
    },
    /// Parallelogram spanned by edge `edge_a` of `-RA` and edge `edge_b` of `B`: normal orthogonal to both.
    EdgeEdge {
        /// Edge of `A`.
        edge_a: usize,
        /// Edge of `B`.
        edge_b: usize,
    },
    /// Degenerate: face `face_b` of `B` plus a parallel edge `edge_a` of `-RA`.
    FixedFaceMovingEdge {
        /// Face of `B`.
        face_b: usize,
        /// Edge of `A`.
        edge_a: usize,
    },
    /// Degenerate: face `face_a` of `-RA` plus a parallel edge `edge_b` of `B`.
    MovingFaceFixedEdge {
        /// Face of `A`.
        face_a: usize,
        /// Edge of `B`.
        edge_b: usize,
    },
    /// Degenerate: face `face_b` of `B` and the parallel face `face_a` of `-RA` (opposite normals in `A`'s frame).
    FaceFace {
        /// Face of `A`.
        face_a: usize,
        /// Face of `B`.
        face_b: usize,
    },
    /// Only from the hull route on input within rounding of a degenerate configuration: the face's vertex provenance
    /// does not name a pair of features that can generate a face.
    Unclassified,
}

impl FaceKind {
    /// The kind from the two generating features (`None` if they cannot generate a face).
    pub fn from_features(fixed: Feature, moving: Feature) -> Option<Self> {
        Some(match (fixed, moving) {
            (Feature::Face(face_b), Feature::Vertex(vertex_a)) => Self::FixedFace { face_b, vertex_a },
            (Feature::Vertex(vertex_b), Feature::Face(face_a)) => Self::MovingFace { face_a, vertex_b },
            (Feature::Edge(edge_b), Feature::Edge(edge_a)) => Self::EdgeEdge { edge_a, edge_b },
            (Feature::Face(face_b), Feature::Edge(edge_a)) => Self::FixedFaceMovingEdge { face_b, edge_a },
            (Feature::Edge(edge_b), Feature::Face(face_a)) => Self::MovingFaceFixedEdge { face_a, edge_b },
            (Feature::Face(face_b), Feature::Face(face_a)) => Self::FaceFace { face_a, face_b },
            _ => return None,
        })
    }

    /// The generating feature of `B` (`None` for [`FaceKind::Unclassified`]).
    pub fn fixed_feature(&self) -> Option<Feature> {
        Some(match *self {
            Self::FixedFace { face_b, .. }
            | Self::FixedFaceMovingEdge { face_b, .. }
            | Self::FaceFace { face_b, .. } => Feature::Face(face_b),
            Self::MovingFace { vertex_b, .. } => Feature::Vertex(vertex_b),
            Self::EdgeEdge { edge_b, .. } | Self::MovingFaceFixedEdge { edge_b, .. } => Feature::Edge(edge_b),
            Self::Unclassified => return None,
        })
    }

    /// The generating feature of `A` (`None` for [`FaceKind::Unclassified`]).
    pub fn moving_feature(&self) -> Option<Feature> {
        Some(match *self {
            Self::FixedFace { vertex_a, .. } => Feature::Vertex(vertex_a),
            Self::MovingFace { face_a, .. }
            | Self::MovingFaceFixedEdge { face_a, .. }
            | Self::FaceFace { face_a, .. } => Feature::Face(face_a),
            Self::EdgeEdge { edge_a, .. } | Self::FixedFaceMovingEdge { edge_a, .. } => Feature::Edge(edge_a),
            Self::Unclassified => return None,
        })
    }

    /// The snake-case name used in JSON (`fixed_face`, `moving_face`, `edge_edge`, ...).
    pub fn name(&self) -> &'static str {
        match self {
            Self::FixedFace { .. } => "fixed_face",
            Self::MovingFace { .. } => "moving_face",
            Self::EdgeEdge { .. } => "edge_edge",
            Self::FixedFaceMovingEdge { .. } => "fixed_face_moving_edge",
            Self::MovingFaceFixedEdge { .. } => "moving_face_fixed_edge",
            Self::FaceFace { .. } => "face_face",
            Self::Unclassified => "unclassified",
        }
    }
}

/// How an obstacle was built.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Route {
    /// Gauss-map overlay (the normal route).
    GaussMap,
    /// Exact-predicate hull of the difference points (fallback on inconsistent near-degenerate overlays).
    Hull,
}

/// Why an obstacle could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ObstacleError {
    /// The rotation has a non-finite entry.
    #[error("the rotation matrix has a non-finite entry")]
    NonFiniteRotation,
    /// The difference points have no 3-D hull (a flat or empty component).
    #[error("the difference points have no 3-D hull: {0}")]
    Hull(#[from] HullError),
    /// The assembled boundary is not a polytope (a bug or non-convex input).
    #[error("the assembled obstacle is not a polytope: {0}")]
    Polytope(#[from] PolytopeError),
}

/// The c-space obstacle of a convex pair with provenance. See the documentation of [`crate::minkowski`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Obstacle {
    pub(crate) polytope: ConvexPolytope,
    pub(crate) vertex_pairs: Vec<[usize; 2]>,
    pub(crate) face_kinds: Vec<FaceKind>,
    pub(crate) rotation: DMat3,
    pub(crate) route: Route,
}

impl Obstacle {
    /// The obstacle as a polytope: vertices, faces (counter-clockwise from outside, unit-normal planes
    /// `n . p <= d` inside), edges.
    pub fn polytope(&self) -> &ConvexPolytope {
        &self.polytope
    }

    /// `vertex_pairs()[v] = [i, j]`: vertex `v` is `V_j^B - R V_i^A` (`i` a vertex of the moving `A`, `j` of `B`),
    /// computed as `b[j] - (R * a[i])`.
    pub fn vertex_pairs(&self) -> &[[usize; 2]] {
        &self.vertex_pairs
    }

    /// `face_kinds()[f]`: what generated face `f`.
    pub fn face_kinds(&self) -> &[FaceKind] {
        &self.face_kinds
    }

    /// The structure of the obstacle: per face its kind (with the generating features, as `Debug` text) and its cycle
    /// of vertex provenances `[i, j]` rotated to start at the smallest, as a set. Two obstacles with equal structures
    /// have the same faces from the same features (what orientation intervals and extrapolation rely on; the
    /// coordinates may differ). O(size log size).
    pub fn structure(&self) -> std::collections::BTreeSet<(String, Vec<[usize; 2]>)> {
        self.polytope
            .faces()
            .iter()
            .zip(&self.face_kinds)
            .map(|(f, k)| {
                let cycle: Vec<[usize; 2]> = f.vertices.iter().map(|&v| self.vertex_pairs[v]).collect();
                let start = (0..cycle.len()).min_by_key(|&s| cycle[s]).unwrap_or(0);
                let mut canonical = cycle[start..].to_vec();
                canonical.extend_from_slice(&cycle[..start]);
                (format!("{k:?}"), canonical)
            })
            .collect()
    }

    /// The rotation `R` of the moving component.
    pub fn rotation(&self) -> DMat3 {
        self.rotation
    }

    /// How it was built.
    pub fn route(&self) -> Route {
        self.route
    }

    /// The H-representation: `p` is in the obstacle iff `plane.normal . p <= plane.offset` for every plane.
    pub fn planes(&self) -> impl ExactSizeIterator<Item = &Plane> + '_ {
        self.polytope.planes()
    }

    /// Where `p` is: interior = interference, boundary = touching, exterior = free.
    pub fn classify(&self, p: DVec3, tol: Tolerance) -> Containment {
        self.polytope.containment(p, tol)
    }

    /// Whether `p` interferes (strictly inside by more than `tol`).
    pub fn interferes(&self, p: DVec3, tol: Tolerance) -> bool {
        self.classify(p, tol) == Containment::Interior
    }

    /// Assembles an obstacle from parts (used by extrapolation in later crates; checks nothing beyond lengths).
    pub fn from_parts(
        polytope: ConvexPolytope,
        vertex_pairs: Vec<[usize; 2]>,
        face_kinds: Vec<FaceKind>,
        rotation: DMat3,
        route: Route,
    ) -> Option<Self> {
        (polytope.vertices().len() == vertex_pairs.len() && polytope.faces().len() == face_kinds.len())
            .then_some(Self { polytope, vertex_pairs, face_kinds, rotation, route })
    }
}

/// `(ANGULAR_TOLERANCE / 2)^2`: the squared sine below which two edge directions are parallel, and the squared
/// distance below which two unit face normals are the same direction.
pub(crate) const PARALLEL_SQ: f64 = (0.5 * ANGULAR_TOLERANCE) * (0.5 * ANGULAR_TOLERANCE);

/// Why the overlay could not be assembled (then [`crate::minkowski::obstacle`] takes the hull route).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OverlayFailure {
    /// A face normal lies on more than one arc interior of the other polytope.
    #[error("a face normal lies inside two arcs of the other Gauss map")]
    AmbiguousSupport,
    /// A face polygon has fewer than 3 corners.
    #[error("a face of the sum has fewer than three corners")]
    FlatFace,
    /// The faces do not close up into a polytope.
    #[error("the faces do not close up: {0}")]
    Assembly(PolytopeError),
    /// Euler's formula fails.
    #[error("Euler's formula fails")]
    Euler,
}

/// One face of the sum as the overlay finds it: its outer unit normal and its two generating features (the support
/// sets of `B` and of `-RA` in that direction). The assembly turns it into a vertex cycle.
pub(crate) struct FaceSpec {
    pub(crate) normal: DVec3,
    pub(crate) fixed: Feature,
    pub(crate) moving: Feature,
}

/// The index of the point of `points` with the largest `u . p` (the first of equal ones): the support vertex in
/// direction `u`. O(n).
pub(crate) fn argmax(points: &[DVec3], u: DVec3) -> usize {
    let mut best = 0;
    let mut best_value = f64::NEG_INFINITY;
    for (i, p) in points.iter().enumerate() {
        let v = u.dot(*p);
        if v > best_value {
            best_value = v;
            best = i;
        }
    }
    best
}
