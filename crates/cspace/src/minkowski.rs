//! Translational c-space obstacle of a convex pair: `C(A, B) = B (+) (-R A)` with full provenance.
//!
//! Paper: Ayyadevara et al. 2002 (\[A\]) Appendix B, eq. 12: `C(A, B) = ConvexHull{ V_j^B - R V_i^A }`; \[A\] VI-A-2
//! (section 6.1.2 of the manuscript) asks for both an H-representation and a face-based one. The moving component `A`
//! is placed by `x -> R x + p`; `p` interferes with the fixed component `B` iff `p` lies in the interior of `C`
//! (touching is not interference, \[A\] App. A).
//!
//! # Algorithm: overlay of the two Gauss maps
//!
//! Every face of a Minkowski sum of convex polytopes has an outer normal `u` and is the sum of the support sets of the
//! summands in direction `u` (`F_u(P + Q) = F_u(P) + F_u(Q)`). The face normals of the sum are the vertices of the
//! overlay of the two normal fans on the unit sphere:
//! 1. a face normal of `B` (then the face is that face of `B` plus the support feature of `-RA`: normally a vertex,
//!    an edge when the normal lies on an edge arc of `-RA`, a face when the two faces are parallel),
//! 2. a face normal of `-RA` (`-R n_f^A`), likewise,
//! 3. a proper crossing of an edge arc of `-RA` with an edge arc of `B` (a parallelogram spanned by the two edges).
//!
//! The arc of an edge is the great-circle arc between the normals of its two faces; its circle has the edge direction as
//! normal. Every decision on the sphere goes through one number per (arc, face normal) pair, `c_e . n_f`, classified
//! with the angular tolerance [`ANGULAR_TOLERANCE`]: the same numbers decide "normal lies on arc" (degenerate faces) and
//! "arcs cross properly" (edge-edge faces), so the two decisions cannot disagree. Two face normals closer than half the
//! tolerance are the same direction: the faces are parallel and give ONE merged face (exactly what prisms and boxes
//! produce all the time). A face polygon is built from the generating features: a face of `B` translated by a vertex
//! keeps `B`'s vertex cycle, a face of `A` keeps `A`'s (reversed by the point reflection), an edge pair gives a
//! parallelogram; only the degenerate merged faces need a 2-D convex sum `F + G` of the two generating polygons (a face,
//! or an edge as a 2-gon). It is the classic O(|F| + |G|) merge of the two edge sequences by angle (the edges of a sum
//! of convex polygons are the summands' edges in angular order), on vertex labels, without coordinates: an edge of `F`
//! and an edge of `G` are ONE edge of the sum (their middle corner is not a corner) when the faces across them are
//! merged too, or when their unit directions point the same way within half the tolerance (`|c_a x c_b| <= tol / 2`,
//! the threshold of merged face normals, so that a rotation about a face normal by less than it merges the faces and
//! their edges alike). Every other decision of the merge is the sign of `(v x w) . u` for two edge directions that
//! are not parallel, which rounding cannot flip; a face plus an edge (most merged faces of sheet metal rotated about
//! `z`) takes a one-pass form of the same rule (`face_plus_segment`). A labelled 2-D hull of the `|F| |G|` rounded sum
//! points, with duplicates and corners within a *length* tolerance removed, gives the same faces on every input away
//! from the tolerance band, but within it its length rule can contradict the angle rule of the unmerged side faces.
//!
//! Why a tolerance and not exact predicates: the input to this step is a *rotated* polytope whose coordinates are
//! already rounded (`cos(pi / 2)` is not 0 in `f64`), so exact parallelism of a rotated face with a fixed one cannot be
//! decided from the data; the tolerance (1e-9 rad, the policy's [`stackplan_geom::tolerance::RELATIVE`]) is six orders
//! above rounding noise and merging faces closer than it moves vertices by less than `1e-9 * size`, inside the
//! policy's length tolerance. Rotations about `z` keep `z` components exact, so horizontal faces merge exactly.
//!
//! The result is assembled into a [`ConvexPolytope`] with an edge table that is checked while it is built (every edge
//! shared by exactly two consistently oriented faces; `edge_table.rs`, exactly geom's table); Euler's formula is
//! checked too. If the overlay was inconsistent (only possible for input
//! within the tolerance of a degenerate configuration, not at one) the obstacle is built by the exact-predicate hull of
//! the `nA * nB` difference points instead ([`obstacle_by_hull`]), and the route is recorded in [`Obstacle::route`].
//!
//! Complexity: O(FA FB + EA EB + (FA + FB)(EA + EB) + output); with at most 64 arcs of `B` the arc crossings are
//! found as bit sets, O(EA (FB + crossings)) instead of O(EA EB); the pair loops are a few flops each, which for the
//! small components of sheet-metal parts beats the O(nA + nB + output) sweep of a true overlay (CGAL's
//! `Gaussian_map`); each merged face costs O(|F| + |G|). The face count is at most `4 m n - 9 m - 9 n + 26` for `m`
//! and `n` facets.
//!
//! Two z-prisms turned about `z` (sheet-metal plates under the planner's rotations) skip the sign tables and the
//! crossing pass: for them those numbers are exact zeros by the data, and `z_prism.rs` builds the same face list
//! (bit for bit the same obstacle) in O(FA FB + FB EA + FA EB) with far fewer products; for a *tame* such pair (the
//! usual one, away from quarter turns) it builds the obstacle in one pass over the merged pole chains of the two
//! cross-sections (`prism_merge.rs`: face cycles, numbering, offsets and edge table from the chain positions) instead
//! of merging polygons and the general assembly's half-edge table, with the same result; when that pass refuses, it
//! reads every face cycle off the features (`z_prism::derived_cycles`) and numbers, offsets and links them from the
//! prism structure (`prism_assembly.rs`).

use glam::{DMat3, DVec3};
use serde::{Deserialize, Serialize};
use stackplan_geom::polytope::{Containment, ConvexPolytope, Face, Plane, PolytopeError};
use stackplan_geom::tolerance::{RELATIVE, Tolerance};
use stackplan_geom::{HullError, VertexCycle, convex_hull};

use crate::edge_table::{self, EdgeScratch};
use crate::{prism_assembly, prism_merge, z_prism};

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

/// The c-space obstacle of a convex pair with provenance. See the module documentation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Obstacle {
    polytope: ConvexPolytope,
    vertex_pairs: Vec<[usize; 2]>,
    face_kinds: Vec<FaceKind>,
    rotation: DMat3,
    route: Route,
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

/// The facet bound `4 m n - 9 m - 9 n + 26` of a Minkowski sum of 3-polytopes with `m` and `n` facets.
pub fn facet_bound(m: usize, n: usize) -> usize {
    (4 * m * n + 26).saturating_sub(9 * m + 9 * n)
}

/// The obstacle of moving `A` (rotation `rotation`) against fixed `B`: Gauss-map overlay, hull fallback.
pub fn obstacle(moving: &ConvexPolytope, rotation: DMat3, fixed: &ConvexPolytope) -> Result<Obstacle, ObstacleError> {
    if !rotation.is_finite() {
        return Err(ObstacleError::NonFiniteRotation);
    }
    match gauss_map_obstacle(moving, rotation, fixed) {
        Ok(o) => Ok(o),
        Err(reason) => {
            tracing::debug!(?reason, "Gauss-map overlay inconsistent; building the obstacle by the exact hull");
            obstacle_by_hull(moving, rotation, fixed)
        }
    }
}

/// The obstacle as the exact-predicate hull of the `nA * nB` difference points `b[j] - R a[i]`, with face kinds
/// inferred from the vertex provenance. O(nA nB log(nA nB)) expected. The reference route and the fallback.
pub fn obstacle_by_hull(
    moving: &ConvexPolytope,
    rotation: DMat3,
    fixed: &ConvexPolytope,
) -> Result<Obstacle, ObstacleError> {
    if !rotation.is_finite() {
        return Err(ObstacleError::NonFiniteRotation);
    }
    let ra: Vec<DVec3> = moving.vertices().iter().map(|a| rotation * *a).collect();
    let nb = fixed.vertices().len();
    let mut points = Vec::with_capacity(ra.len() * nb);
    for r in &ra {
        for b in fixed.vertices() {
            points.push(*b - *r);
        }
    }
    let hull = convex_hull(&points)?;
    let vertex_pairs: Vec<[usize; 2]> = hull.source.iter().map(|&k| [k / nb, k % nb]).collect();
    let face_kinds = hull
        .polytope
        .faces()
        .iter()
        .map(|f| {
            let mut is: Vec<usize> = f.vertices.iter().map(|&v| vertex_pairs[v][0]).collect();
            let mut js: Vec<usize> = f.vertices.iter().map(|&v| vertex_pairs[v][1]).collect();
            let moving_feature = identify_feature(moving, &mut is);
            let fixed_feature = identify_feature(fixed, &mut js);
            match (fixed_feature, moving_feature) {
                (Some(b), Some(a)) => FaceKind::from_features(b, a).unwrap_or(FaceKind::Unclassified),
                _ => FaceKind::Unclassified,
            }
        })
        .collect();
    Ok(Obstacle { polytope: hull.polytope, vertex_pairs, face_kinds, rotation, route: Route::Hull })
}

/// The smallest feature of `p` whose vertex set contains all of `ids` (sorted and deduplicated in place).
fn identify_feature(p: &ConvexPolytope, ids: &mut Vec<usize>) -> Option<Feature> {
    ids.sort_unstable();
    ids.dedup();
    match ids.len() {
        0 => None,
        1 => Some(Feature::Vertex(ids[0])),
        2 => p
            .edges()
            .iter()
            .position(|e| {
                let mut v = e.vertices;
                v.sort_unstable();
                v == [ids[0], ids[1]]
            })
            .map(Feature::Edge),
        _ => p.faces().iter().position(|f| ids.iter().all(|i| f.vertices.contains(i))).map(Feature::Face),
    }
}

/// Why the overlay could not be assembled (then [`obstacle`] takes the hull route).
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

#[derive(Clone, Copy)]
struct Arc {
    /// Unit circle normal, oriented so that the arc runs counter-clockwise about it from `from` to `to`.
    circle: DVec3,
    /// Face at the start of the arc.
    from: usize,
    /// Face at the end of the arc.
    to: usize,
}

/// Arcs of a polytope whose vertices are `vertices` and face normals `normals` (edge topology from `p`), into `out`.
fn arcs(p: &ConvexPolytope, vertices: &[DVec3], normals: &[DVec3], out: &mut Vec<Arc>) {
    out.clear();
    out.extend(p.edges().iter().map(|e| {
        let d = (vertices[e.vertices[1]] - vertices[e.vertices[0]]).normalize();
        let (n0, n1) = (normals[e.faces[0]], normals[e.faces[1]]);
        let circle = if n0.cross(n1).dot(d) >= 0.0 { d } else { -d };
        Arc { circle, from: e.faces[0], to: e.faces[1] }
    }));
}

#[inline]
fn tol_sign(v: f64) -> i8 {
    // branch-free: 1 above the tolerance, -1 below minus it, 0 within it (and for NaN)
    i8::from(v > ANGULAR_TOLERANCE) - i8::from(v < -ANGULAR_TOLERANCE)
}

/// `out[e * normals.len() + f]`: the side of `normals[f]` w.r.t. the circle of `arcs[e]` ([`tol_sign`]).
fn sign_table(arcs: &[Arc], normals: &[DVec3], out: &mut Vec<i8>) {
    out.clear();
    out.resize(arcs.len() * normals.len(), 0);
    if normals.is_empty() {
        return;
    }
    for (row, arc) in out.chunks_exact_mut(normals.len()).zip(arcs) {
        for (sign, n) in row.iter_mut().zip(normals) {
            *sign = tol_sign(arc.circle.dot(*n));
        }
    }
}

/// Whether `u` (already known to lie on the arc's circle) lies strictly inside the arc.
#[inline]
fn strictly_inside_arc(arc: &Arc, normals: &[DVec3], u: DVec3) -> bool {
    normals[arc.from].cross(u).dot(arc.circle) > 0.0 && u.cross(normals[arc.to]).dot(arc.circle) > 0.0
}

/// Working buffers of one overlay, kept per thread between calls: the overlay itself allocates nothing once they
/// have grown; only the result's own vectors are allocated.
#[derive(Default)]
struct Scratch {
    ra: Vec<DVec3>,
    neg_ra: Vec<DVec3>,
    am: Vec<DVec3>,
    bn: Vec<DVec3>,
    a_arcs: Vec<Arc>,
    b_arcs: Vec<Arc>,
    s_ab: Vec<i8>,
    s_ba: Vec<i8>,
    merged_with_b: Vec<Option<usize>>,
    merged_with_a: Vec<Option<usize>>,
    /// `from_mask[g]` / `to_mask[g]`: the B arcs (at most 64) starting / ending at B's face `g`, as bits.
    from_mask: Vec<u64>,
    to_mask: Vec<u64>,
    specs: Vec<FaceSpec>,
    index_of: Vec<u32>,
    cycle: Vec<[usize; 2]>,
    planar: PlanarScratch,
    edges: EdgeScratch,
    prism: z_prism::Scratch,
    direct: prism_assembly::Scratch,
    merge: prism_merge::Scratch,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
}

#[cfg(test)]
thread_local! {
    /// Tests: take the one-by-one crossing test even for at most 64 B arcs.
    static ONE_BY_ONE_CROSSINGS: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    /// Tests: take the general overlay even for a z-prism pair (`z_prism.rs`).
    pub(crate) static GENERAL_ROUTE_ONLY: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    /// Tests: assemble a tame z-prism pair by the polygon merges too (`z_prism::derived_cycles`).
    pub(crate) static NO_DERIVED_CYCLES: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    /// Tests: search the support of every side normal of a z-prism pair through all arcs (`z_prism::face_specs`).
    pub(crate) static ALL_ARCS: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    /// Tests: find the parallel faces of a z-prism pair by `z_prism::parallel_faces` first (not the poles alone).
    pub(crate) static NO_POLE_MERGES_FIRST: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    /// Tests: assemble the derived cycles of a tame z-prism pair by the general assembly (`prism_assembly.rs`).
    pub(crate) static NO_DIRECT_ASSEMBLY: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    /// Tests: build a tame z-prism pair from its derived cycles (`z_prism::derived_cycles`, `prism_assembly.rs`), not
    /// from the merged chains (`prism_merge.rs`).
    pub(crate) static NO_MERGED_CHAINS: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Whether the test switch `$switch` (a thread-local above) is on; always `false` outside the tests.
macro_rules! test_switch {
    ($switch:ident) => {{
        #[cfg(test)]
        let on = $switch.with(std::cell::Cell::get);
        #[cfg(not(test))]
        let on = false;
        on
    }};
}

/// The Gauss-map route alone, without the hull fallback (for tests and benchmarks).
pub fn gauss_map_obstacle(
    moving: &ConvexPolytope,
    rotation: DMat3,
    fixed: &ConvexPolytope,
) -> Result<Obstacle, OverlayFailure> {
    // the per-thread buffers, or fresh ones when they are in use (re-entrant call) or gone (thread exit)
    SCRATCH
        .try_with(|cell| match cell.try_borrow_mut() {
            Ok(mut scratch) => Some(overlay(moving, rotation, fixed, &mut scratch)),
            Err(_) => None,
        })
        .ok()
        .flatten()
        .unwrap_or_else(|| overlay(moving, rotation, fixed, &mut Scratch::default()))
}

fn overlay(
    moving: &ConvexPolytope,
    rotation: DMat3,
    fixed: &ConvexPolytope,
    scratch: &mut Scratch,
) -> Result<Obstacle, OverlayFailure> {
    let Scratch {
        ra,
        neg_ra,
        am,
        bn,
        a_arcs,
        b_arcs,
        s_ab,
        s_ba,
        merged_with_b,
        merged_with_a,
        from_mask,
        to_mask,
        specs: faces,
        index_of,
        cycle,
        planar,
        edges,
        prism,
        direct,
        merge,
    } = scratch;
    ra.clear();
    ra.extend(moving.vertices().iter().map(|a| rotation * *a));
    // -RA: vertices -ra, normals -R n; edge arcs computed from -ra.
    neg_ra.clear();
    neg_ra.extend(ra.iter().map(|r| -*r));
    am.clear();
    am.extend(moving.faces().iter().map(|f| -(rotation * f.plane.normal).normalize()));
    let bv = fixed.vertices();
    bn.clear();
    bn.extend(fixed.faces().iter().map(|f| f.plane.normal));
    let (fa, fb) = (am.len(), bn.len());

    // two z-prisms turned about z (sheet metal): the same faces without sign tables or crossings (`z_prism.rs`)
    let z_prisms = !test_switch!(GENERAL_ROUTE_ONLY)
        && z_prism::vertical_arcs(moving, neg_ra, am, &mut prism.a_classes, &mut prism.a, &mut prism.wide[0])
        && z_prism::vertical_arcs(fixed, bv, bn, &mut prism.b_classes, &mut prism.b, &mut prism.wide[1]);
    // (tests: the supports searched through all arcs)
    let wide = if test_switch!(ALL_ARCS) { [false; 2] } else { prism.wide };

    // parallel faces: merged_with_b[f] = Some(g) when -R n_f == n_g within half the tolerance.
    merged_with_b.clear();
    merged_with_b.resize(fa, None);
    merged_with_a.clear();
    merged_with_a.resize(fb, None);
    faces.clear();

    if z_prisms {
        #[cfg(test)]
        z_prism::TAKEN.with(|c| c.set(c.get() + 1));
        // a tame pair merges only its poles: take that for granted, and confirm it by the supports' margin (every side
        // normal well inside an arc of the other summand is far from all its side normals, `z_prism::pole_merges`)
        let mut margin = f64::INFINITY;
        let mut by_class = !test_switch!(NO_POLE_MERGES_FIRST)
            && z_prism::pole_merges(am, bn, &prism.a_classes, &prism.b_classes, merged_with_a, merged_with_b)
            && z_prism::face_specs(
                am,
                bn,
                &prism.a,
                &prism.b,
                wide,
                neg_ra,
                bv,
                merged_with_a,
                merged_with_b,
                faces,
                &mut margin,
                true,
            )
            .is_ok()
            && margin > z_prism::MARGIN;
        if !by_class {
            // else as the general route: all parallel pairs (within a class when the poles are far from the sides)
            merged_with_b.fill(None);
            merged_with_a.fill(None);
            by_class =
                z_prism::parallel_faces(am, bn, &prism.a_classes, &prism.b_classes, merged_with_a, merged_with_b);
            if !by_class {
                all_parallel_faces(am, bn, merged_with_a, merged_with_b);
            }
            faces.clear();
            margin = f64::INFINITY;
            z_prism::face_specs(
                am,
                bn,
                &prism.a,
                &prism.b,
                wide,
                neg_ra,
                bv,
                merged_with_a,
                merged_with_b,
                faces,
                &mut margin,
                false,
            )?;
        }
        // a tame pair: every cycle without the polygon merges, in one pass over the merged pole chains
        // (`prism_merge.rs`), else from the derived cycles (`z_prism::derived_cycles`)
        let tame = by_class && margin > z_prism::MARGIN && !test_switch!(NO_DERIVED_CYCLES);
        if tame
            && !test_switch!(NO_MERGED_CHAINS)
            && let Some(result) =
                prism_merge::obstacle(moving, fixed, rotation, ra, neg_ra, am, bn, faces, prism, merge)
        {
            #[cfg(test)]
            z_prism::MERGED.with(|c| c.set(c.get() + 1));
            return result;
        }
        let derived = tame && z_prism::derived_cycles(moving, fixed, neg_ra, am, bn, faces, prism);
        #[cfg(test)]
        if derived {
            z_prism::DERIVED.with(|c| c.set(c.get() + 1));
        }
        // their vertex numbering, offsets and edge table from the prism structure (`prism_assembly.rs`)
        if derived && !test_switch!(NO_DIRECT_ASSEMBLY) {
            let (cycles, starts) = (prism.cycles.as_slice(), prism.starts.as_slice());
            let b_levels = prism.b_levels.as_slice();
            if let Some(result) =
                prism_assembly::assemble(fixed, rotation, ra, faces, cycles, starts, b_levels, index_of, direct)
            {
                #[cfg(test)]
                z_prism::DIRECT.with(|c| c.set(c.get() + 1));
                return result;
            }
        }
        // the merged pole faces need no faces across their edges when no side face of -RA is merged (`z_prism.rs`)
        let pole_faces_alone = by_class && z_prism::no_side_merged(&prism.a_classes, merged_with_b);
        let plain = if pole_faces_alone { Some(prism.b_classes.as_slice()) } else { None };
        let cycles = if derived { Some((prism.cycles.as_slice(), prism.starts.as_slice())) } else { None };
        let buffers = AssemblyBuffers { index_of, cycle, planar, merged_with_b, neg_ra, edges, plain, cycles };
        return assemble(moving, fixed, rotation, ra, faces, buffers);
    }

    all_parallel_faces(am, bn, merged_with_a, merged_with_b);
    arcs(moving, neg_ra, am, a_arcs);
    arcs(fixed, bv, bn, b_arcs);
    let (am, bn, a_arcs, b_arcs) = (&*am, &*bn, &*a_arcs, &*b_arcs);

    // sides: s_ab[e * fb + g] = side of B's normal g w.r.t. the circle of A-arc e; s_ba[e * fa + f] likewise.
    sign_table(a_arcs, bn, s_ab);
    sign_table(b_arcs, am, s_ba);
    let (s_ab, s_ba) = (&*s_ab, &*s_ba);

    // 1. faces of B
    for (g, &u) in bn.iter().enumerate() {
        let moving_feature = if let Some(f) = merged_with_a[g] {
            Feature::Face(f)
        } else {
            let mut found = None;
            for (e, arc) in a_arcs.iter().enumerate() {
                if s_ab[e * fb + g] == 0 && strictly_inside_arc(arc, am, u) {
                    if found.is_some() {
                        return Err(OverlayFailure::AmbiguousSupport);
                    }
                    found = Some(e);
                }
            }
            match found {
                Some(e) => Feature::Edge(e),
                None => Feature::Vertex(argmax(neg_ra, u)),
            }
        };
        faces.push(FaceSpec { normal: u, fixed: Feature::Face(g), moving: moving_feature });
    }
    // 2. faces of -RA not parallel to a face of B
    for (f, &u) in am.iter().enumerate() {
        if merged_with_b[f].is_some() {
            continue;
        }
        let mut found = None;
        for (e, arc) in b_arcs.iter().enumerate() {
            if s_ba[e * fa + f] == 0 && strictly_inside_arc(arc, bn, u) {
                if found.is_some() {
                    return Err(OverlayFailure::AmbiguousSupport);
                }
                found = Some(e);
            }
        }
        let fixed_feature = match found {
            Some(e) => Feature::Edge(e),
            None => Feature::Vertex(argmax(bv, u)),
        };
        faces.push(FaceSpec { normal: u, fixed: fixed_feature, moving: Feature::Face(f) });
    }
    // 3. proper arc crossings, in (A arc, B arc) order. The B arcs whose end normals lie strictly on opposite sides of
    // an A arc's circle: all B arcs tested one by one, or (at most 64 B arcs) as bit sets: with `from_mask[g]` /
    // `to_mask[g]` the B arcs starting / ending at B's face g, the arcs from a face on the positive side to one on the
    // negative side are `(OR of from_mask over positive g) & (OR of to_mask over negative g)`, and vice versa; the
    // same pairs as the one-by-one test (the same signs), visited in the same order.
    let small = b_arcs.len() <= 64 && !test_switch!(ONE_BY_ONE_CROSSINGS);
    if small {
        from_mask.clear();
        from_mask.resize(fb, 0);
        to_mask.clear();
        to_mask.resize(fb, 0);
        for (eb, b_arc) in b_arcs.iter().enumerate() {
            from_mask[b_arc.from] |= 1 << eb;
            to_mask[b_arc.to] |= 1 << eb;
        }
    }
    for (ea, a_arc) in a_arcs.iter().enumerate() {
        let row = &s_ab[ea * fb..(ea + 1) * fb];
        let mut crossing = |eb: usize, b_arc: &Arc| {
            let (sa0, sa1) = (s_ba[eb * fa + a_arc.from], s_ba[eb * fa + a_arc.to]);
            if sa0 == 0 || sa0 != -sa1 {
                return;
            }
            let mut x = a_arc.circle.cross(b_arc.circle);
            if x.dot(am[a_arc.from] + am[a_arc.to]) < 0.0 {
                x = -x;
            }
            if x.dot(bn[b_arc.from] + bn[b_arc.to]) <= 0.0 {
                return;
            }
            faces.push(FaceSpec { normal: x.normalize(), fixed: Feature::Edge(eb), moving: Feature::Edge(ea) });
        };
        if small {
            let (mut from_pos, mut from_neg, mut to_pos, mut to_neg) = (0u64, 0u64, 0u64, 0u64);
            for ((&sign, &from), &to) in row.iter().zip(from_mask.iter()).zip(to_mask.iter()) {
                // all ones where the sign is +1 (resp. -1), else zero
                let (pos, neg) = (0u64.wrapping_sub(u64::from(sign == 1)), 0u64.wrapping_sub(u64::from(sign == -1)));
                from_pos |= from & pos;
                from_neg |= from & neg;
                to_pos |= to & pos;
                to_neg |= to & neg;
            }
            let mut candidates = (from_pos & to_neg) | (from_neg & to_pos);
            while candidates != 0 {
                let eb = candidates.trailing_zeros() as usize;
                candidates &= candidates - 1;
                crossing(eb, &b_arcs[eb]);
            }
        } else {
            for (eb, b_arc) in b_arcs.iter().enumerate() {
                let (sb0, sb1) = (row[b_arc.from], row[b_arc.to]);
                if sb0 == 0 || sb0 != -sb1 {
                    continue;
                }
                crossing(eb, b_arc);
            }
        }
    }
    let buffers = AssemblyBuffers { index_of, cycle, planar, merged_with_b, neg_ra, edges, plain: None, cycles: None };
    assemble(moving, fixed, rotation, ra, faces, buffers)
}

/// The parallel faces of `-RA` (normals `am`) and `B` (normals `bn`): every pair whose unit normals are within half
/// the angular tolerance, in (face of `-RA`, face of `B`) order, the last match kept.
fn all_parallel_faces(
    am: &[DVec3],
    bn: &[DVec3],
    merged_with_a: &mut [Option<usize>],
    merged_with_b: &mut [Option<usize>],
) {
    for (f, m) in am.iter().enumerate() {
        for (g, n) in bn.iter().enumerate() {
            if (*m - *n).length_squared() <= PARALLEL_SQ {
                merged_with_b[f] = Some(g);
                merged_with_a[g] = Some(f);
            }
        }
    }
}

pub(crate) struct FaceSpec {
    pub(crate) normal: DVec3,
    pub(crate) fixed: Feature,
    pub(crate) moving: Feature,
}

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

/// One polygon of a merged face: its corners (vertex indices of its polytope), and per edge `k` (corner `k` to `k + 1`)
/// the direction, its squared length and its half-plane relative to the reference direction (see [`planar_merge`]),
/// and the face of the polytope across that edge (`usize::MAX` for an edge feature).
#[derive(Default)]
struct Polygon {
    corners: Vec<usize>,
    edges: Vec<(DVec3, f64, u8)>,
    across: Vec<usize>,
}

impl Polygon {
    /// The polygon of `feature` of `p` (whose vertices, as summed, are `points`): a face's vertex cycle,
    /// counter-clockwise about its outward normal (reversed when `reflect`, for `-RA`, whose faces are the point
    /// reflections of `A`'s); an edge as the 2-gon `[v0, v1]`. The half-planes are taken relative to `reference`, or
    /// to this polygon's edge 0 when `None`; returns the reference. The faces across the edges only `with_across`.
    /// Not called for vertices.
    #[allow(clippy::too_many_arguments)]
    fn build(
        &mut self,
        p: &ConvexPolytope,
        feature: Feature,
        reflect: bool,
        points: &[DVec3],
        normal: DVec3,
        reference: Option<DVec3>,
        with_across: bool,
    ) -> DVec3 {
        let Self { corners, edges, across } = self;
        corners.clear();
        edges.clear();
        across.clear();
        match feature {
            Feature::Vertex(v) => corners.push(v),
            Feature::Edge(e) => corners.extend_from_slice(&p.edges()[e].vertices),
            Feature::Face(f) => {
                let cycle = &p.faces()[f].vertices;
                if reflect {
                    corners.extend(cycle.iter().rev());
                } else {
                    corners.extend_from_slice(cycle);
                }
                if with_across {
                    let face_edges = p.face_edges(f);
                    let other = |e: usize| {
                        let [f0, f1] = p.edges()[e].faces;
                        if f0 == f { f1 } else { f0 }
                    };
                    if reflect {
                        // reversed cycle: corner k is cycle[n - 1 - k]; the edge to corner k + 1 joins cycle[n - 1 - k]
                        // and cycle[n - 2 - k], i.e. face_edges[n - 2 - k]; the closing edge is face_edges[n - 1]
                        let n = cycle.len();
                        across.extend(face_edges[..n - 1].iter().rev().map(|&e| other(e)));
                        across.push(other(face_edges[n - 1]));
                    } else {
                        across.extend(face_edges.iter().map(|&e| other(e)));
                    }
                }
            }
        }
        let n = corners.len();
        let first = points[corners[0]];
        let r = reference.unwrap_or_else(|| points[corners[1]] - first);
        let mut current = first;
        edges.reserve(n);
        for k in 1..=n {
            let next = if k == n { first } else { points[corners[k]] };
            let d = next - current;
            current = next;
            // 0 for angles in [0, pi) from r about the normal, 1 for [pi, 2 pi)
            let s = r.cross(d).dot(normal);
            edges.push((d, d.length_squared(), u8::from(!(s > 0.0 || (s == 0.0 && r.dot(d) > 0.0)))));
        }
        r
    }
}

/// Buffers reused by every merged face (no allocation per face): `B`'s polygon and `-RA`'s.
#[derive(Default)]
struct PlanarScratch {
    b: Polygon,
    a: Polygon,
    /// The edge classes of [`face_plus_segment`].
    classes: Vec<u8>,
}

/// The scratch buffers [`assemble`] works in.
struct AssemblyBuffers<'a> {
    /// `index_of[i * nB + j]`: the obstacle vertex of the pair `(i, j)`, `u32::MAX` if none yet.
    index_of: &'a mut Vec<u32>,
    /// The vertex-pair cycle of the face being built.
    cycle: &'a mut Vec<[usize; 2]>,
    planar: &'a mut PlanarScratch,
    /// `merged_with_b[f] = Some(g)`: face `f` of `-RA` and face `g` of `B` are parallel (one face of the sum).
    merged_with_b: &'a [Option<usize>],
    /// The vertices of `-RA`.
    neg_ra: &'a [DVec3],
    /// The edge table's buffers.
    edges: &'a mut EdgeScratch,
    /// `Some(classes of B's faces)` when the merged faces of two poles (`z_prism.rs`) need no faces across their
    /// edges: the test that reads them cannot succeed (see `z_prism::no_side_merged`).
    plain: Option<&'a [u8]>,
    /// `Some((cycles, starts))`: the vertex-pair cycle of face `s` is `cycles[starts[s]..starts[s + 1]]`, derived
    /// without the polygon merges (`z_prism::derived_cycles`).
    cycles: Option<(&'a [[usize; 2]], &'a [usize])>,
}

#[allow(clippy::too_many_arguments)]
fn assemble(
    moving: &ConvexPolytope,
    fixed: &ConvexPolytope,
    rotation: DMat3,
    ra: &[DVec3],
    specs: &[FaceSpec],
    buffers: AssemblyBuffers<'_>,
) -> Result<Obstacle, OverlayFailure> {
    let AssemblyBuffers {
        index_of,
        cycle,
        planar: scratch,
        merged_with_b,
        neg_ra,
        edges: edge_scratch,
        plain,
        cycles: derived,
    } = buffers;
    let bv = fixed.vertices();
    let nb = bv.len();
    index_of.clear();
    index_of.resize(ra.len() * nb, u32::MAX);
    let mut vertices: Vec<DVec3> = Vec::with_capacity(specs.len() * 2);
    let mut vertex_pairs: Vec<[usize; 2]> = Vec::with_capacity(specs.len() * 2);
    let mut faces: Vec<Face> = Vec::with_capacity(specs.len());
    let mut kinds: Vec<FaceKind> = Vec::with_capacity(specs.len());
    edge_scratch.clear();
    // one face from its vertex-pair cycle: number its new vertices, its offset, its vertex list
    macro_rules! add_face {
        ($spec:expr, $corners:expr) => {{
            let (spec, corners): (&FaceSpec, &[[usize; 2]]) = ($spec, $corners);
            if corners.len() < 3 {
                return Err(OverlayFailure::FlatFace);
            }
            let mut face = VertexCycle::with_capacity(corners.len());
            let mut offset = f64::NEG_INFINITY;
            for &[i, j] in corners {
                let slot = &mut index_of[i * nb + j];
                if *slot == u32::MAX {
                    *slot = vertices.len() as u32;
                    vertices.push(bv[j] - ra[i]);
                    vertex_pairs.push([i, j]);
                    edge_scratch.vertex();
                }
                let v = *slot as usize;
                edge_scratch.corner(v);
                offset = offset.max(spec.normal.dot(vertices[v]));
                face.push(v);
            }
            faces.push(Face { vertices: face, plane: Plane { normal: spec.normal, offset } });
            kinds.push(FaceKind::from_features(spec.fixed, spec.moving).unwrap_or(FaceKind::Unclassified));
        }};
    }
    if let Some((cycles, starts)) = derived {
        for (spec, range) in specs.iter().zip(starts.windows(2)) {
            add_face!(spec, &cycles[range[0]..range[1]]);
        }
    } else {
        for spec in specs {
            cycle.clear();
            face_cycle(moving, fixed, ra, neg_ra, spec, merged_with_b, plain, scratch, cycle);
            add_face!(spec, cycle);
        }
    }
    let (v, f) = (vertices.len(), faces.len());
    // every face has a positive area by construction (a translated face of `A` or `B`, a sum containing one, or a
    // parallelogram of two edges that cross properly, i.e. are not parallel): only the edge table is checked. It is
    // built from the faces in the reused buffers; when it does not exist, geom's own table reports the same error.
    let polytope = match edge_table::build(v, &faces, edge_scratch) {
        Some((edges, face_edges)) => ConvexPolytope::from_faces_and_edges(vertices, faces, edges, face_edges),
        None => ConvexPolytope::from_faces_with_area(vertices, faces),
    }
    .map_err(OverlayFailure::Assembly)?;
    if v + f != polytope.edges().len() + 2 {
        return Err(OverlayFailure::Euler);
    }
    Ok(Obstacle { polytope, vertex_pairs, face_kinds: kinds, rotation, route: Route::GaussMap })
}

/// The vertex-pair cycle of the face `spec` into `cycle` (cleared by the caller), from its generating features.
#[allow(clippy::too_many_arguments)]
fn face_cycle(
    moving: &ConvexPolytope,
    fixed: &ConvexPolytope,
    ra: &[DVec3],
    neg_ra: &[DVec3],
    spec: &FaceSpec,
    merged_with_b: &[Option<usize>],
    plain: Option<&[u8]>,
    scratch: &mut PlanarScratch,
    cycle: &mut Vec<[usize; 2]>,
) {
    let bv = fixed.vertices();
    match (spec.fixed, spec.moving) {
        (Feature::Face(g), Feature::Vertex(i)) => {
            cycle.extend(fixed.faces()[g].vertices.iter().map(|&j| [i, j]));
        }
        (Feature::Vertex(j), Feature::Face(f)) => {
            cycle.extend(moving.faces()[f].vertices.iter().rev().map(|&i| [i, j]));
        }
        (Feature::Edge(eb), Feature::Edge(ea)) => {
            let [j0, j1] = fixed.edges()[eb].vertices;
            let [i0, i1] = moving.edges()[ea].vertices;
            // p00 -> p01 runs along B's edge, p01 -> p11 along -RA's edge
            let d_b = bv[j1] - bv[j0];
            let d_a = ra[i0] - ra[i1];
            if d_b.cross(d_a).dot(spec.normal) > 0.0 {
                cycle.extend([[i0, j0], [i0, j1], [i1, j1], [i1, j0]]);
            } else {
                cycle.extend([[i0, j0], [i1, j0], [i1, j1], [i0, j1]]);
            }
        }
        (Feature::Face(g), Feature::Edge(ea)) => {
            let corners = &fixed.faces()[g].vertices;
            let [i0, i1] = moving.edges()[ea].vertices;
            face_plus_segment::<true>(corners, bv, [i0, i1], neg_ra, spec.normal, &mut scratch.classes, cycle);
        }
        (Feature::Edge(eb), Feature::Face(f)) => {
            let corners = &mut scratch.a.corners;
            corners.clear();
            corners.extend(moving.faces()[f].vertices.iter().rev());
            let [j0, j1] = fixed.edges()[eb].vertices;
            face_plus_segment::<false>(corners, neg_ra, [j0, j1], bv, spec.normal, &mut scratch.classes, cycle);
        }
        (fixed_feature, moving_feature) => {
            let n = spec.normal;
            let both_faces = match (fixed_feature, moving_feature) {
                (Feature::Face(g), Feature::Face(_)) => !plain.is_some_and(|c| z_prism::is_pole(c[g])),
                _ => false,
            };
            let r = scratch.b.build(fixed, fixed_feature, false, bv, n, None, both_faces);
            scratch.a.build(moving, moving_feature, true, neg_ra, n, Some(r), both_faces);
            planar_merge(merged_with_b, n, both_faces, scratch, cycle);
        }
    }
}

/// `(ANGULAR_TOLERANCE / 2)^2`: the squared sine below which two edge directions are parallel, and the squared
/// distance below which two unit face normals are the same direction.
pub(crate) const PARALLEL_SQ: f64 = (0.5 * ANGULAR_TOLERANCE) * (0.5 * ANGULAR_TOLERANCE);

/// The convex polygon `F + G` of a merged face with outward normal `normal`, where `F` is `B`'s polygon
/// (`scratch.pj`/`pe`) and `G` is `-RA`'s (`scratch.qi`/`qe`), both counter-clockwise about `normal` (a face, or an
/// edge as a 2-gon), as the vertex-pair cycle of its corners into `out`, counter-clockwise about `normal`.
///
/// The classic O(|F| + |G|) merge of the two edge sequences by angle (the sum's edges are the summands' edges in
/// angular order): starting at `F`'s edge 0 and the corner of `G` whose outgoing edge comes first at or after it, the
/// walk advances in the polygon whose next edge turns first. An edge `p` of `F` and an edge `q` of `G` that point the
/// same way (`p . q > 0`) are one edge of the sum (both advance; their middle corner is not a corner) when the sine of
/// their angle is at most half the tolerance (`|p x q|^2 <= (tol / 2)^2 |p|^2 |q|^2`), or when the faces of `B` and
/// `A` across them are merged. Both tests see the same vectors (up to an exact sign) for the same pair of edges in
/// every face, so neighbouring faces agree. All other order decisions are signs of `(v x w) . normal` for
/// non-parallel `v`, `w`, which the rounding of the inputs cannot flip. No coordinates are sorted or compared, so no
/// length tolerance enters. O(|F| + |G|), no allocation (the scratch buffers are reused).
fn planar_merge(
    merged_with_b: &[Option<usize>],
    normal: DVec3,
    faces: bool,
    scratch: &PlanarScratch,
    out: &mut Vec<[usize; 2]>,
) {
    let (pj, pd, pn) = (&scratch.b.corners, &scratch.b.edges, &scratch.b.across);
    let (qi, qd, qn) = (&scratch.a.corners, &scratch.a.edges, &scratch.a.across);
    let (m, n) = (pj.len(), qi.len());
    let r = pd[0].0;
    // one edge of the sum: pointing the same way, and the faces across both edges are merged (then so are the edges,
    // whatever their rounded directions say: the neighbouring merged face decides the same way) or the sine of their
    // angle is at most half the tolerance (`c = p x q`; the same vectors up to sign in every face, so the same answer)
    let same = |k: usize, l: usize, c: DVec3| {
        let ((p, p2, _), (q, q2, _)) = (pd[k], qd[l]);
        p.dot(q) > 0.0
            && (c.length_squared() <= PARALLEL_SQ * p2 * q2 || (faces && merged_with_b[qn[l]] == Some(pn[k])))
    };
    // G's first edge: the one parallel to r, else the first in angular order
    let mut l0 = 0;
    if !same(0, 0, r.cross(qd[0].0)) {
        for l in 1..n {
            if same(0, l, r.cross(qd[l].0)) {
                l0 = l;
                break;
            }
            let ((v, _, hv), (w, _, hw)) = (qd[l], qd[l0]);
            if hv < hw || (hv == hw && v.cross(w).dot(normal) > 0.0) {
                l0 = l;
            }
        }
    }
    let (mut k, mut l) = (0, 0);
    while k < m || l < n {
        let lq = if l0 + l >= n { l0 + l - n } else { l0 + l };
        out.push([qi[lq], pj[if k == m { 0 } else { k }]]);
        if k == m {
            l += 1;
        } else if l == n {
            k += 1;
        } else {
            let ((p, _, hp), (q, _, hq)) = (pd[k], qd[lq]);
            let c = p.cross(q);
            if same(k, lq, c) {
                k += 1;
                l += 1;
            } else if hp < hq || (hp == hq && c.dot(normal) > 0.0) {
                k += 1;
            } else {
                l += 1;
            }
        }
    }
}

/// [`planar_merge`] for a face plus a parallel edge (a 2-gon), in one pass: the face polygon `corners` (points
/// `points`, counter-clockwise about `normal`) plus the segment `segment` (points `segment_points`); `FACE_IS_B` says
/// whether the face is `B`'s (the corner labels are then `[segment vertex, corner]`, else `[corner, segment vertex]`).
///
/// With `d` the segment's direction, every face edge `e` is *parallel* (`e . d > 0`), *antiparallel* (`e . d < 0`)
/// when the sine of their angle is at most half the tolerance (the test of [`planar_merge`], evaluated with the same
/// operands in the same order: `B`'s edge first), else *after* `d` (`(d x e) . normal > 0`) or *before* it. The sum
/// translates the face edges before `d` by the segment's start `s0`, those after it by its end `s1`; a parallel edge
/// runs from `s0` to `s1`, an antiparallel one from `s1` to `s0`. Each corner of the face is one corner of the sum
/// when the edges on both sides translate it alike, else two (the segment's edge `d` or `-d` joins them). Exactly the
/// cycle [`planar_merge`] gives for the 2-gon (up to where it starts), in O(|F|) with one cross product per edge.
#[allow(clippy::too_many_arguments)]
fn face_plus_segment<const FACE_IS_B: bool>(
    corners: &[usize],
    points: &[DVec3],
    segment: [usize; 2],
    segment_points: &[DVec3],
    normal: DVec3,
    classes: &mut Vec<u8>,
    out: &mut Vec<[usize; 2]>,
) {
    const BEFORE: u8 = 0;
    const AFTER: u8 = 1;
    const PARALLEL: u8 = 2;
    const ANTIPARALLEL: u8 = 3;
    let d = segment_points[segment[1]] - segment_points[segment[0]];
    let m = corners.len();
    classes.clear();
    let first = points[corners[0]];
    let mut current = first;
    for k in 1..=m {
        let next = if k == m { first } else { points[corners[k]] };
        let e = next - current;
        current = next;
        // the parallel test with B's edge first, as in `planar_merge` (bit for bit: the same products in the same
        // order); `|c . normal| <= |c|`, so a turn clearly above the tolerance skips the length (the margin 2 covers
        // the rounding of the unit normal)
        let (p, q) = if FACE_IS_B { (e, d) } else { (d, e) };
        let c = p.cross(q);
        let turn = c.dot(normal);
        let tolerance = PARALLEL_SQ * p.length_squared() * q.length_squared();
        let parallel = turn * turn <= 2.0 * tolerance && c.length_squared() <= tolerance;
        // (d x e) . normal is `turn` for an A face and `-turn` for a B face
        classes.push(if parallel {
            if e.dot(d) > 0.0 { PARALLEL } else { ANTIPARALLEL }
        } else if (if FACE_IS_B { -turn } else { turn }) > 0.0 {
            AFTER
        } else {
            BEFORE
        });
    }
    let label = |corner: usize, end: usize| if FACE_IS_B { [segment[end], corner] } else { [corner, segment[end]] };
    for k in 0..m {
        let (incoming, outgoing) = (classes[if k == 0 { m - 1 } else { k - 1 }], classes[k]);
        // the end of the segment by which corner k is translated as the end of the incoming edge, and as the start
        // of the outgoing one
        let end = usize::from(incoming == AFTER || incoming == PARALLEL);
        let start = usize::from(!(outgoing == BEFORE || outgoing == PARALLEL));
        out.push(label(corners[k], end));
        if start != end {
            out.push(label(corners[k], start));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cuboid(lo: DVec3, hi: DVec3) -> ConvexPolytope {
        ConvexPolytope::cuboid(lo, hi).expect("box")
    }

    #[test]
    fn box_box_identity_is_a_box() {
        let a = cuboid(DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0));
        let b = cuboid(DVec3::ZERO, DVec3::new(4.0, 5.0, 6.0));
        let o = obstacle(&a, DMat3::IDENTITY, &b).expect("obstacle");
        assert_eq!(o.route(), Route::GaussMap);
        assert_eq!(o.polytope().vertices().len(), 8);
        assert_eq!(o.polytope().faces().len(), 6);
        o.polytope().validate().expect("valid");
        assert!((o.polytope().volume() - 5.0 * 7.0 * 9.0).abs() < 1e-9);
        assert!(o.face_kinds().iter().all(|k| matches!(k, FaceKind::FaceFace { .. })));
        let (lo, hi) = o.polytope().aabb();
        assert_eq!(lo, DVec3::new(-1.0, -2.0, -3.0));
        assert_eq!(hi, DVec3::new(4.0, 5.0, 6.0));
    }

    #[test]
    fn rotated_boxes_about_z() {
        let a = cuboid(DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0));
        let b = cuboid(DVec3::ZERO, DVec3::new(4.0, 5.0, 6.0));
        let o = obstacle(&a, DMat3::from_rotation_z(0.3), &b).expect("obstacle");
        assert_eq!(o.route(), Route::GaussMap);
        o.polytope().validate().expect("valid");
        // octagonal prism: 8 vertical faces + top + bottom
        assert_eq!(o.polytope().faces().len(), 10);
        assert_eq!(o.polytope().vertices().len(), 16);
        let h = obstacle_by_hull(&a, DMat3::from_rotation_z(0.3), &b).expect("hull");
        assert!((h.polytope().volume() - o.polytope().volume()).abs() < 1e-9);
    }

    /// A polygon for [`planar_merge`] from raw points (what `Polygon::build` computes for a feature).
    fn raw_polygon(points: &[DVec3], corners: &[usize], normal: DVec3, reference: Option<DVec3>) -> (Polygon, DVec3) {
        let n = corners.len();
        let r = reference.unwrap_or(points[corners[1]] - points[corners[0]]);
        let edges = (0..n)
            .map(|k| {
                let d = points[corners[(k + 1) % n]] - points[corners[k]];
                let s = r.cross(d).dot(normal);
                (d, d.length_squared(), u8::from(!(s > 0.0 || (s == 0.0 && r.dot(d) > 0.0))))
            })
            .collect();
        (Polygon { corners: corners.to_vec(), edges, across: vec![usize::MAX; n] }, r)
    }

    fn same_cycle(a: &[[usize; 2]], b: &[[usize; 2]]) -> bool {
        a.len() == b.len() && (0..a.len()).any(|s| (0..a.len()).all(|k| a[(s + k) % a.len()] == b[k]))
    }

    #[test]
    fn face_plus_segment_is_the_general_merge_of_a_2_gon() {
        // convex polygons (regular, rotated, scaled) plus segments in every direction: exactly along an edge, within
        // 0.3 and 0.7 of the tolerance of it, and generic; the face as B's and as A's
        let normal = DVec3::Z;
        let mut cases = 0;
        for sides in 3..9 {
            for turn in [0.0, 0.1, 1.0] {
                let points: Vec<DVec3> = (0..sides)
                    .map(|k| {
                        let t = turn + k as f64 * std::f64::consts::TAU / sides as f64;
                        DVec3::new(3.0 * t.cos() + 1.0, 2.0 * t.sin() - 0.5, 0.25)
                    })
                    .collect();
                let corners: Vec<usize> = (0..sides).collect();
                let mut directions = Vec::new();
                for k in 0..sides {
                    let e = points[(k + 1) % sides] - points[k];
                    let angle = e.y.atan2(e.x);
                    for offset in [0.0, 0.3, -0.3, 0.7, -0.7, 3.0] {
                        let a = angle + offset * ANGULAR_TOLERANCE;
                        directions.push(DVec3::new(a.cos(), a.sin(), 0.0) * 1.5);
                    }
                    directions.push(DVec3::new((angle + 0.4).cos(), (angle + 0.4).sin(), 0.0));
                }
                for d in directions {
                    for face_is_b in [true, false] {
                        // the segment's points: [p, p + d]
                        let seg_points = vec![DVec3::new(0.5, 0.25, 0.0), DVec3::new(0.5, 0.25, 0.0) + d];
                        let mut got = Vec::new();
                        let mut classes = Vec::new();
                        let (c, p, sp) = (&corners, &points, &seg_points);
                        if face_is_b {
                            face_plus_segment::<true>(c, p, [0, 1], sp, normal, &mut classes, &mut got);
                        } else {
                            face_plus_segment::<false>(c, p, [0, 1], sp, normal, &mut classes, &mut got);
                        }
                        let (b_points, b_corners, a_points, a_corners) = if face_is_b {
                            (&points, corners.clone(), &seg_points, vec![0, 1])
                        } else {
                            (&seg_points, vec![0, 1], &points, corners.clone())
                        };
                        let (b, r) = raw_polygon(b_points, &b_corners, normal, None);
                        let (a, _) = raw_polygon(a_points, &a_corners, normal, Some(r));
                        let scratch = PlanarScratch { b, a, classes: Vec::new() };
                        let mut expected = Vec::new();
                        planar_merge(&[], normal, false, &scratch, &mut expected);
                        assert!(
                            same_cycle(&got, &expected),
                            "{sides} sides, d {d}, face_is_b {face_is_b}: {got:?} vs {expected:?}"
                        );
                        cases += 1;
                    }
                }
            }
        }
        assert!(cases > 500);
    }

    #[test]
    fn crossing_bit_sets_equal_the_one_by_one_test() {
        // pairs with edge-edge faces (general rotations, point clouds) and without (boxes and prisms about z)
        let cloud = |n: usize, seed: f64| {
            let pts: Vec<DVec3> = (0..n)
                .map(|k| {
                    let t = k as f64 * 2.399 + seed;
                    let z = 1.0 - 2.0 * (k as f64 + 0.5) / n as f64;
                    let r = (1.0 - z * z).sqrt();
                    DVec3::new(r * t.cos() * 3.0, r * t.sin() * 2.0, z)
                })
                .collect();
            convex_hull(&pts).expect("hull").polytope
        };
        let shapes = [
            cuboid(DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0)),
            cuboid(DVec3::new(-1.0, 0.5, 0.0), DVec3::new(4.0, 5.0, 0.5)),
            cloud(8, 0.0),
            cloud(14, 0.3),
            cloud(24, 0.7),
        ];
        let rotations = [
            DMat3::IDENTITY,
            DMat3::from_rotation_z(0.3),
            DMat3::from_rotation_x(std::f64::consts::FRAC_PI_2),
            DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7),
            DMat3::from_axis_angle(DVec3::new(-0.3, 0.2, 1.0).normalize(), 2.1),
        ];
        let mut edge_edge = 0;
        for a in &shapes {
            for b in &shapes {
                for r in rotations {
                    let bits = gauss_map_obstacle(a, r, b);
                    ONE_BY_ONE_CROSSINGS.with(|c| c.set(true));
                    let one_by_one = gauss_map_obstacle(a, r, b);
                    ONE_BY_ONE_CROSSINGS.with(|c| c.set(false));
                    assert_eq!(format!("{bits:?}"), format!("{one_by_one:?}"));
                    if let Ok(o) = bits {
                        edge_edge += o.face_kinds().iter().filter(|k| matches!(k, FaceKind::EdgeEdge { .. })).count();
                    }
                }
            }
        }
        assert!(edge_edge > 100, "{edge_edge} edge-edge faces");
    }

    #[test]
    fn per_thread_buffers_do_not_leak_between_obstacles() {
        // a large pair between two builds of a small one: the reused buffers must not change the result
        let a = cuboid(DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0));
        let b = cuboid(DVec3::new(-1.0, 0.5, 0.0), DVec3::new(4.0, 5.0, 6.0));
        let r = DMat3::from_rotation_z(0.3);
        let first = gauss_map_obstacle(&a, r, &b).expect("obstacle");
        let pts: Vec<DVec3> = (0..40)
            .map(|k| {
                let t = k as f64 * 0.7;
                DVec3::new(t.cos() * 5.0, t.sin() * 5.0, (k % 7) as f64 - 3.0)
            })
            .collect();
        let big = convex_hull(&pts).expect("hull").polytope;
        let other = gauss_map_obstacle(&big, DMat3::from_rotation_x(0.2), &big).expect("obstacle");
        assert!(other.polytope().vertices().len() > first.polytope().vertices().len());
        let again = gauss_map_obstacle(&a, r, &b).expect("obstacle");
        assert_eq!(format!("{first:?}"), format!("{again:?}"));
    }
}
