//! Obstacles over the discrete orientations: constructed where no stored structure holds, extrapolated inside the
//! constant-topology intervals of those that do (\[A\] IV-B and App. C, eq. 4; DESIGN.md section 4; the seed's Table I
//! counts the two).
//!
//! The planner's orientations are `R = R_z(theta) R_rest`. For one moving component in one resting pose and one stack
//! component, the obstacle keeps its face/edge/vertex structure over intervals of `theta`
//! ([`stackplan_orient_interval::PairEvents`]); inside an interval the obstacle at another angle is the stored
//! structure with its vertices moved (`V_j^B - R_z(theta) R_rest V_i^A`) and its planes recomputed from their
//! generating features ([`ObstacleStructure::extrapolate`]), with no hull and the same provenance.
//!
//! Per (moving component, resting pose, stack component):
//! * the first obstacle is constructed through the shared [`ObstacleCache`] (bit for bit what a plain construction
//!   gives) and remembered;
//! * at the second construction the pair's events are computed (O(F_B E_A + F_A E_B), about 2-4 constructions, so
//!   pairs met at a single angle never pay for them) and both obstacles become structures with their intervals;
//! * from then on an angle inside a stored interval is extrapolated (O(size of the obstacle)), any other is
//!   constructed and stored with its interval. An angle on an event (an exact alignment: 0 and 90 degrees for boxes)
//!   has a one-angle interval, so it is always constructed. Hull-route obstacles (no generating features) are
//!   never extrapolated.
//!
//! Extrapolated coordinates agree with a construction to about 1e-15 relative (rounding), not bit for bit; the
//! search's results are exact up to that rounding (tests compare both routes). Which angles are constructed depends
//! on the order they are asked for, which the sequential search loop fixes, so results stay deterministic.

use crate::detect::StackComponent;
use glam::{DMat3, DVec3};
use stackplan_cspace::ObstacleCache;
use stackplan_cspace::minkowski::Obstacle;
use stackplan_geom::Part;
use stackplan_geom::polytope::ConvexPolytope;
use stackplan_orient_interval::{ObstacleStructure, PairEvents, rotation_z};
use std::collections::HashMap;
use std::sync::Arc;

/// How an obstacle was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ObstacleRoute {
    /// Constructed (or found in the [`ObstacleCache`]).
    Constructed,
    /// Extrapolated from a stored structure.
    Extrapolated,
}

/// The stored structures of one (moving component, resting pose, stack component).
#[derive(Debug)]
struct PairIntervals {
    /// The moving component in its resting pose (the polytope that turns about z).
    moving_rest: ConvexPolytope,
    /// The first construction, kept until the events are computed.
    first: Option<(f64, Arc<Obstacle>)>,
    /// The pair's event bands (computed at the second construction).
    events: Option<PairEvents>,
    /// Structures with their intervals.
    structures: Vec<ObstacleStructure>,
}

/// The store; see the module documentation. Keys: (moving component, resting pose index, stack component index).
#[derive(Debug, Default)]
pub struct IntervalObstacles {
    pairs: HashMap<(usize, usize, usize), PairIntervals>,
}

impl IntervalObstacles {
    /// An empty store.
    pub fn new() -> Self {
        Self::default()
    }

    /// Drops every stored structure.
    pub fn clear(&mut self) {
        self.pairs.clear();
    }

    /// The obstacle of `part`'s component `moving` turned by `R_z(theta) rest_rotation` (`rotation`, the search's
    /// bit pattern) against the stack component `fixed` (index `fixed_index` in the scene), constructed through
    /// `cache` or extrapolated. `Err` carries the builder's message.
    #[allow(clippy::too_many_arguments)]
    pub fn obstacle(
        &mut self,
        part: &Part,
        moving: usize,
        rest: usize,
        rest_rotation: DMat3,
        theta: f64,
        rotation: DMat3,
        fixed_index: usize,
        fixed: &StackComponent,
        cache: &ObstacleCache,
    ) -> Result<(Arc<Obstacle>, ObstacleRoute), String> {
        let component = &part.components[moving];
        let entry = self.pairs.entry((moving, rest, fixed_index)).or_insert_with(|| PairIntervals {
            moving_rest: component.transformed(rest_rotation, DVec3::ZERO),
            first: None,
            events: None,
            structures: Vec::new(),
        });
        if let Some(s) = entry.structures.iter().find(|s| s.covers(theta)) {
            let extrapolated = s.extrapolate(&entry.moving_rest, &fixed.world, theta).map_err(|e| e.to_string())?;
            return Ok((Arc::new(extrapolated), ObstacleRoute::Extrapolated));
        }
        let built = cache
            .get_or_build(moving, fixed.part, fixed.piece, component, rotation, &fixed.world)
            .map_err(|e| e.to_string())?;
        if entry.events.is_none() {
            let Some(first) = entry.first.take() else {
                entry.first = Some((theta, Arc::clone(&built)));
                return Ok((built, ObstacleRoute::Constructed));
            };
            let events = PairEvents::new(&entry.moving_rest, &fixed.world);
            entry.store(&events, &fixed.world, first.0, &first.1);
            entry.events = Some(events);
        }
        if let Some(events) = entry.events.take() {
            entry.store(&events, &fixed.world, theta, &built);
            entry.events = Some(events);
        }
        Ok((built, ObstacleRoute::Constructed))
    }
}

impl PairIntervals {
    /// Stores the structure of `obstacle` (built at `theta`) with its interval, unless it cannot be extrapolated
    /// (hull route) or its interval is the single angle.
    fn store(&mut self, events: &PairEvents, fixed: &ConvexPolytope, theta: f64, obstacle: &Obstacle) {
        let interval = events.interval_around(theta);
        if interval.length() <= 0.0 {
            return;
        }
        // the structure turns the resting-pose component by R_z alone: the template must say so (its recipes
        // read the rotation, e.g. the sign of an edge-edge normal), while its coordinates stay the construction's
        let Some(template) = Obstacle::from_parts(
            obstacle.polytope().clone(),
            obstacle.vertex_pairs().to_vec(),
            obstacle.face_kinds().to_vec(),
            rotation_z(theta),
            obstacle.route(),
        ) else {
            return;
        };
        match ObstacleStructure::from_obstacle(template, &self.moving_rest, fixed, theta, interval) {
            Ok(s) => self.structures.push(s),
            Err(e) => tracing::debug!(theta, "obstacle not extrapolable: {e}"),
        }
    }
}
