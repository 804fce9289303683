//! The obstacles the search cuts out: the c-space obstacle of one (moving component, stack component) pair at one
//! orientation (\[A\] App. B, built by `stackplan-cspace`'s Gauss-map overlay through its [`ObstacleCache`], or
//! extrapolated within its constant-topology interval by `interval_obstacles.rs`), turned
//! into the half-spaces the search subtracts:
//!
//! * plain: the obstacle's face planes `n_k . p <= d_k`;
//! * with insertion: the insertion obstacle `C (+) {-t z : t >= 0}` (\[A\] condition 4), whose planes are the faces of
//!   `C` that do not face down plus one vertical plane per silhouette edge;
//! * with clearance `delta`: every plane moved out by `delta` (the mitred offset of \[A\] eq. 10-11, a superset of the
//!   exact `delta`-offset).
//!
//! Each plane keeps its provenance (the face kind of `C`, or "insertion side") so an active constraint at an optimum
//! names the contact. Position `p` *interferes* with the pair iff it lies in the interior of this set by more than
//! the tolerance: `n_k . p < d_k - tol` for every `k` — the same test, with the same tolerance, as the cells'
//! membership, so a point on a face (touching) is free everywhere. O(F) per obstacle after its construction.

use crate::detect::StackScene;
use crate::orientation::Orientation;
use serde::{Deserialize, Serialize};
use stackplan_cspace::minkowski::Obstacle;
use stackplan_cspace::{FaceKind, ObstacleCache, insertion};
use stackplan_geom::Part;
use stackplan_geom::polytope::Plane;

/// Where a plane of a derived obstacle comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum PlaneOrigin {
    /// A face of the c-space obstacle of the pair.
    Face {
        /// The face's kind and generating features.
        face: FaceKind,
    },
    /// A vertical side of the insertion obstacle (through a silhouette edge).
    InsertionSide,
    /// A side of the region another search covers ([`crate::request::SearchTuning::searched_elsewhere`]): a boundary of
    /// the search, never a contact.
    SearchedElsewhere,
}

impl PlaneOrigin {
    /// Short name for reports (`fixed_face`, `moving_face`, `edge_edge`, ..., `insertion_side`).
    pub fn name(&self) -> &'static str {
        match self {
            PlaneOrigin::Face { face } => face.name(),
            PlaneOrigin::InsertionSide => "insertion_side",
            PlaneOrigin::SearchedElsewhere => "searched_elsewhere",
        }
    }
}

/// An obstacle ready for subtraction.
#[derive(Debug, Clone)]
pub struct DerivedObstacle {
    /// Moving component (`usize::MAX` for [`DerivedObstacle::searched_elsewhere`]'s region, which is no pair's).
    pub moving: usize,
    /// Stack component (index into the scene; `usize::MAX` for the region of
    /// [`DerivedObstacle::searched_elsewhere`]).
    pub fixed: usize,
    /// `p` is in the obstacle iff `normal . p <= offset` for all planes.
    pub planes: Vec<Plane>,
    /// Provenance of each plane.
    pub origins: Vec<PlaneOrigin>,
    /// The moving part's plate whose filled outline stands for its pieces in this obstacle (the planner's
    /// `plates.rs`; `moving` then names the plate's first piece), or `None`.
    pub moving_plate: Option<usize>,
    /// The stack part's plate whose filled outline stands for its pieces (`fixed` then names its first piece), or
    /// `None`.
    pub fixed_plate: Option<usize>,
    /// With insertion: the planes of the pair's c-space obstacle `C` that face down, which the insertion obstacle
    /// drops (grown like the others). A position on the insertion obstacle's boundary that violates one of them
    /// lies below `C`, on its downward sweep: the part does not touch the stack component there. Empty otherwise.
    pub below: Vec<Plane>,
}

impl DerivedObstacle {
    /// Builds the obstacle of a pair (see the module documentation), constructing the pair's c-space obstacle
    /// through `cache`. `Err` carries the builder's message.
    #[allow(clippy::too_many_arguments)]
    pub fn build(
        part: &Part,
        orientation: &Orientation,
        moving: usize,
        scene: &StackScene,
        fixed: usize,
        cache: &ObstacleCache,
        clearance: f64,
        horizontal_clearance: bool,
        with_insertion: bool,
    ) -> Result<Self, String> {
        let sc = &scene.components[fixed];
        let raw = cache
            .get_or_build(moving, sc.part, sc.piece, &part.components()[moving], orientation.rotation, &sc.world)
            .map_err(|e| e.to_string())?;
        Ok(Self::from_obstacle(&raw, moving, fixed, clearance, horizontal_clearance, with_insertion))
    }

    /// The derived obstacle of the pair's c-space obstacle `raw` (constructed or extrapolated).
    pub fn from_obstacle(
        raw: &Obstacle,
        moving: usize,
        fixed: usize,
        clearance: f64,
        horizontal_clearance: bool,
        with_insertion: bool,
    ) -> Self {
        let mut below: Vec<Plane> = Vec::new();
        let (mut planes, origins): (Vec<Plane>, Vec<PlaneOrigin>) = if with_insertion {
            let poly = raw.polytope();
            below = poly
                .faces()
                .iter()
                .filter(|f| f.plane.normal.z < -stackplan_cspace::minkowski::ANGULAR_TOLERANCE)
                .map(|f| f.plane)
                .collect();
            let ins = insertion(poly);
            let kept: Vec<PlaneOrigin> = poly
                .faces()
                .iter()
                .zip(raw.face_kinds())
                .filter(|(f, _)| f.plane.normal.z >= -stackplan_cspace::minkowski::ANGULAR_TOLERANCE)
                .map(|(_, k)| PlaneOrigin::Face { face: *k })
                .collect();
            let mut origins = kept;
            origins.resize(ins.planes.len(), PlaneOrigin::InsertionSide);
            (ins.planes, origins)
        } else {
            (raw.planes().copied().collect(), raw.face_kinds().iter().map(|k| PlaneOrigin::Face { face: *k }).collect())
        };
        if clearance > 0.0 {
            for p in planes.iter_mut().chain(&mut below) {
                // support function of the growth set: the ball (clearance) or the horizontal disc (clearance |n_xy|)
                p.offset += if horizontal_clearance {
                    clearance * (1.0 - p.normal.z * p.normal.z).max(0.0).sqrt()
                } else {
                    clearance
                };
            }
        }
        Self { moving, fixed, planes, origins, below, moving_plate: None, fixed_plate: None }
    }

    /// The region of positions at which the part, at `orientation`, lies inside the convex polygon `polygon`
    /// (counter-clockwise seen from above) in the plan view: one vertical plane per side, the sides of
    /// `Omega(theta)` of that polygon ([`Orientation::sides_within`]). Subtracted
    /// like an obstacle, it leaves the region to another search ([`crate::request::SearchTuning::searched_elsewhere`]).
    /// O(sides x part vertices).
    pub fn searched_elsewhere(orientation: &Orientation, polygon: &[glam::DVec2]) -> Self {
        let planes: Vec<Plane> = orientation
            .sides_within(polygon)
            .into_iter()
            .map(|(n, offset)| Plane { normal: glam::DVec3::new(n.x, n.y, 0.0), offset })
            .collect();
        let origins = vec![PlaneOrigin::SearchedElsewhere; planes.len()];
        Self {
            moving: usize::MAX,
            fixed: usize::MAX,
            planes,
            origins,
            below: Vec::new(),
            moving_plate: None,
            fixed_plate: None,
        }
    }

    /// Whether this is the region of [`DerivedObstacle::searched_elsewhere`] (no pair's obstacle).
    pub fn is_searched_elsewhere(&self) -> bool {
        self.origins.first() == Some(&PlaneOrigin::SearchedElsewhere)
    }

    /// Whether `p` lies in the closed set grown by `tol` (`n_k . p <= d_k + tol` for every plane): on a face of the
    /// obstacle rather than on the face plane's extension beyond it. A cell's constraint from face `k` can be active
    /// at a point far outside the obstacle (the cells are cut by the face planes, which reach past the face), so an
    /// active face names a contact only when this holds. O(F).
    pub fn closure_contains(&self, p: glam::DVec3, tol: f64) -> bool {
        self.planes.iter().all(|pl| pl.normal.dot(p) <= pl.offset + tol)
    }

    /// Whether `p` lies below the pair's c-space obstacle, outside one of its down-facing planes by more than `tol`
    /// (only with insertion, see [`DerivedObstacle::below`]): on the insertion obstacle's boundary, such a position is
    /// held by the straight-down path past the stack component, not by touching it. O(F).
    pub fn under_sweep(&self, p: glam::DVec3, tol: f64) -> bool {
        self.below.iter().any(|pl| pl.normal.dot(p) > pl.offset + tol)
    }

    /// Whether `p` lies in the interior by more than `tol` (interference).
    pub fn interior_contains(&self, p: glam::DVec3, tol: f64) -> bool {
        self.planes.iter().all(|pl| pl.normal.dot(p) < pl.offset - tol)
    }
}
