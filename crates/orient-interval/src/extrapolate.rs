//! Extrapolation of a c-space obstacle within its constant-structure interval.
//!
//! Paper: Ayyadevara et al. 2002 (\[A\]) section IV-B (manuscript 4.2) and eq. 4; `docs/algorithms.md`, "Critical
//! orientations and extrapolation". While the structure (faces, edges, vertex provenance `[i, j]`, face kinds) stays
//! constant, the obstacle at a new angle is obtained by moving every vertex to `V_j^B - R(theta) V_i^A` (eq. 4) and
//! recomputing each face plane from its generating features ([`NormalRecipe`]: a face of `B` keeps `n^B`; a face of
//! `-RA` gets `-R n^A`; an edge-edge parallelogram gets `sign * (e^B x R e^A)` normalised, the sign fixed at
//! construction; the offset is the largest `n . v` over the face's vertices, as the construction does). O(size of the
//! obstacle) and no hull.
//!
//! Two outputs: [`ObstacleStructure::extrapolate`] returns a full [`Obstacle`] (it copies the template's face and
//! edge tables through `ConvexPolytope::with_geometry`: no search, but one allocation per face), and
//! [`ObstacleStructure::extrapolate_geometry`] writes only the vertices and planes into caller buffers (no allocation,
//! the fast path for callers that need the H-representation).

use crate::critical::{Interval, NormalRecipe, PairEvents};
use glam::{DMat3, DVec3};
use stackplan_cspace::minkowski::{Obstacle, ObstacleError, Route, obstacle};
use stackplan_geom::VertexCycle;
use stackplan_geom::polytope::{ConvexPolytope, Plane, PolytopeError};

/// Why an obstacle could not be extrapolated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExtrapolateError {
    /// The requested angle is outside the structure's constant interval.
    #[error(
        "angle {theta} rad is outside the constant-structure interval [{start}, {end}] rad of the obstacle built at {built_at} rad"
    )]
    OutsideInterval {
        /// Requested angle.
        theta: f64,
        /// Where the structure was built.
        built_at: f64,
        /// Interval start.
        start: f64,
        /// Interval end.
        end: f64,
    },
    /// The obstacle was built by the hull fallback or has an unclassified face (face `face`): no normal recipe.
    #[error("face {face} of the obstacle has no generating features (hull-route obstacle); it cannot be extrapolated")]
    NoRecipe {
        /// Face index.
        face: usize,
    },
    /// The extrapolated vertex or plane count differs from the template's (an internal inconsistency).
    #[error("the extrapolated geometry does not match the template's topology")]
    TopologyMismatch,
    /// Building the obstacle failed.
    #[error("building the obstacle failed: {0}")]
    Build(#[from] ObstacleError),
    /// The extrapolated boundary is not a polytope (cannot happen inside the interval; reported, not panicked).
    #[error("the extrapolated obstacle is not a polytope: {0}")]
    Polytope(#[from] PolytopeError),
}

/// Vertices and planes of an extrapolated obstacle (the topology is the structure's).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ExtrapolatedGeometry {
    /// Vertex positions, indexed like the structure's obstacle.
    pub vertices: Vec<DVec3>,
    /// Face planes, indexed like the structure's obstacle.
    pub planes: Vec<Plane>,
}

/// The structure of an obstacle built at one angle, valid over its constant-structure interval.
#[derive(Debug, Clone, PartialEq)]
pub struct ObstacleStructure {
    built_at: f64,
    interval: Interval,
    template: Obstacle,
    faces: Vec<VertexCycle>,
    recipes: Vec<NormalRecipe>,
}

/// The rotation about `z` by `theta` used everywhere in this crate (the same matrix the construction receives).
#[inline]
pub fn rotation_z(theta: f64) -> DMat3 {
    DMat3::from_rotation_z(theta)
}

impl ObstacleStructure {
    /// Builds the obstacle of `moving` rotated by `theta` about `z` against `fixed` from scratch and records its
    /// structure and interval (from `events`, the pair's event bands).
    pub fn build(
        moving: &ConvexPolytope,
        fixed: &ConvexPolytope,
        theta: f64,
        events: &PairEvents,
    ) -> Result<Self, ExtrapolateError> {
        let built = obstacle(moving, rotation_z(theta), fixed)?;
        Self::from_obstacle(built, moving, fixed, theta, events.interval_around(theta))
    }

    /// The structure of an obstacle already built at `theta`, valid over `interval`.
    pub fn from_obstacle(
        template: Obstacle,
        moving: &ConvexPolytope,
        fixed: &ConvexPolytope,
        theta: f64,
        interval: Interval,
    ) -> Result<Self, ExtrapolateError> {
        let mut recipes = Vec::with_capacity(template.face_kinds().len());
        for face in 0..template.face_kinds().len() {
            if template.route() != Route::GaussMap {
                return Err(ExtrapolateError::NoRecipe { face });
            }
            recipes.push(NormalRecipe::of(&template, face, moving, fixed).ok_or(ExtrapolateError::NoRecipe { face })?);
        }
        let faces = template.polytope().faces().iter().map(|f| f.vertices.clone()).collect();
        Ok(Self { built_at: theta, interval, template, faces, recipes })
    }

    /// The angle it was built at.
    pub fn built_at(&self) -> f64 {
        self.built_at
    }

    /// Its constant-structure interval.
    pub fn interval(&self) -> &Interval {
        &self.interval
    }

    /// The obstacle it was built from.
    pub fn template(&self) -> &Obstacle {
        &self.template
    }

    /// Whether the structure is valid at `theta`.
    pub fn covers(&self, theta: f64) -> bool {
        self.interval.contains(theta)
    }

    fn check(&self, theta: f64) -> Result<(), ExtrapolateError> {
        if self.covers(theta) {
            Ok(())
        } else {
            Err(ExtrapolateError::OutsideInterval {
                theta,
                built_at: self.built_at,
                start: self.interval.start,
                end: self.interval.end,
            })
        }
    }

    /// Vertices and planes at `theta` into `out` (cleared first). O(size), no allocation once `out` has capacity.
    pub fn extrapolate_geometry(
        &self,
        moving: &ConvexPolytope,
        fixed: &ConvexPolytope,
        theta: f64,
        out: &mut ExtrapolatedGeometry,
    ) -> Result<(), ExtrapolateError> {
        self.check(theta)?;
        let rotation = rotation_z(theta);
        let (av, bv) = (moving.vertices(), fixed.vertices());
        out.vertices.clear();
        out.vertices.extend(self.template.vertex_pairs().iter().map(|&[i, j]| bv[j] - rotation * av[i]));
        out.planes.clear();
        for (face, recipe) in self.faces.iter().zip(&self.recipes) {
            let normal = recipe.normal(&rotation);
            let offset = face.iter().map(|&v| normal.dot(out.vertices[v])).fold(f64::NEG_INFINITY, f64::max);
            out.planes.push(Plane { normal, offset });
        }
        Ok(())
    }

    /// The obstacle at `theta` (same faces, edges and provenance as the template). O(size), no hull.
    pub fn extrapolate(
        &self,
        moving: &ConvexPolytope,
        fixed: &ConvexPolytope,
        theta: f64,
    ) -> Result<Obstacle, ExtrapolateError> {
        let mut geometry = ExtrapolatedGeometry::default();
        self.extrapolate_geometry(moving, fixed, theta, &mut geometry)?;
        // same topology as the template: reuse its edge table instead of rebuilding it (O(size), no sort)
        let polytope = self
            .template
            .polytope()
            .with_geometry(geometry.vertices, geometry.planes)
            .ok_or(ExtrapolateError::TopologyMismatch)?;
        Obstacle::from_parts(
            polytope,
            self.template.vertex_pairs().to_vec(),
            self.template.face_kinds().to_vec(),
            rotation_z(theta),
            Route::GaussMap,
        )
        .ok_or(ExtrapolateError::NoRecipe { face: 0 })
    }
}

/// The obstacle at `theta` extrapolated from the one built at `theta0` — what `stackplan cspace --theta-deg T
/// --extrapolate-from T0` prints. An error if `theta` is outside `theta0`'s constant-structure interval. Builds
/// the event bands of the pair (O(F_B E_A + F_A E_B)), one obstacle, and one extrapolation.
pub fn extrapolate_from(
    moving: &ConvexPolytope,
    fixed: &ConvexPolytope,
    theta0: f64,
    theta: f64,
) -> Result<(Obstacle, Interval), ExtrapolateError> {
    let events = PairEvents::new(moving, fixed);
    let structure = ObstacleStructure::build(moving, fixed, theta0, &events)?;
    let o = structure.extrapolate(moving, fixed, theta)?;
    Ok((o, *structure.interval()))
}
