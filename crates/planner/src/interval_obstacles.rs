//! Obstacles over the discrete orientations: constructed where no stored structure holds, extrapolated inside the
//! constant-topology intervals of those that do (\[A\] IV-B and App. C, eq. 4; `docs/algorithms.md`, "Critical
//! orientations and extrapolation"; the seed's Table I counts the two).
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
//!   pairs met at a single angle never pay for them) and both obstacles become structures with their intervals. The
//!   events depend on the stack component only up to translation (normals and edge directions), so they are
//!   computed from the component turned but not moved ([`StackComponent::turned`]) and shared by every stack
//!   component with the same bits there (the copies of a piece in the same rotation: in the 15-part Complex plan
//!   1 180 computations became 362, see docs/benchmarks.md);
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
use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};
use std::sync::{Arc, Mutex, PoisonError};

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
    /// The pair's event bands (computed at the second construction, shared between copies).
    events: Option<Arc<PairEvents>>,
    /// Structures with their intervals.
    structures: Vec<ObstacleStructure>,
}

/// The store; see the module documentation. Keys: (moving component, resting pose index, stack component index), so
/// a store serves the searches of one part at fixed resting rotations into one (growing) stack, as the search caches
/// that own it ensure; the shared pair events are keyed by bits and serve any.
#[derive(Debug, Default)]
pub struct IntervalObstacles {
    pairs: HashMap<(usize, usize, usize), PairIntervals>,
    /// Pair events by the bits of both polytopes they were computed from; shared with the other partitions' stores
    /// ([`Self::share_events`]).
    events: EventStore,
}

/// Pair events by the hashes of the bits of the moving component in its resting pose and of the turned stack
/// component, with both polytopes (compared bit for bit on a hit: the events are keyed by everything they depend on).
type SharedEvents = HashMap<(u64, u64), Vec<(ConvexPolytope, Arc<ConvexPolytope>, Arc<PairEvents>)>>;

/// Pair events shared by the stores of a search's partitions: a pure function of the moving component in its resting
/// pose and the turned stack component, so which partition computes an entry first changes nothing.
#[derive(Debug, Default, Clone)]
pub struct EventStore(Arc<Mutex<SharedEvents>>);

impl EventStore {
    /// Drops every entry.
    pub fn clear(&self) {
        self.0.lock().unwrap_or_else(PoisonError::into_inner).clear();
    }
}

/// The events of a moving component in its resting pose (`moving_rest`) against a stack component turned as
/// `turned`: computed once per pair of bit patterns.
fn shared_events(store: &EventStore, moving_rest: &ConvexPolytope, turned: &Arc<ConvexPolytope>) -> Arc<PairEvents> {
    let key = (polytope_bits_hash(moving_rest), polytope_bits_hash(turned));
    let find = |map: &SharedEvents| {
        map.get(&key)?
            .iter()
            .find(|(m, t, _)| (Arc::ptr_eq(t, turned) || same_bits(t, turned)) && same_bits(m, moving_rest))
            .map(|(_, _, events)| Arc::clone(events))
    };
    if let Some(events) = find(&store.0.lock().unwrap_or_else(PoisonError::into_inner)) {
        return events;
    }
    // computed outside the lock; another partition may have stored the same (equal) events meanwhile
    let events = Arc::new(PairEvents::new(moving_rest, turned));
    let mut map = store.0.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some(stored) = find(&map) {
        return stored;
    }
    map.entry(key).or_default().push((moving_rest.clone(), Arc::clone(turned), Arc::clone(&events)));
    events
}

/// A hash of every bit of a polytope (vertices, face planes and cycles, edges).
fn polytope_bits_hash(p: &ConvexPolytope) -> u64 {
    let mut h = DefaultHasher::new();
    for v in p.vertices() {
        v.to_array().map(f64::to_bits).hash(&mut h);
    }
    for f in p.faces() {
        f.plane.normal.to_array().map(f64::to_bits).hash(&mut h);
        f.plane.offset.to_bits().hash(&mut h);
        f.vertices[..].hash(&mut h);
    }
    for e in p.edges() {
        e.vertices.hash(&mut h);
        e.faces.hash(&mut h);
    }
    h.finish()
}

/// Whether two polytopes are the same bits (vertices, face planes and cycles, edges).
fn same_bits(a: &ConvexPolytope, b: &ConvexPolytope) -> bool {
    let bits = |v: &glam::DVec3| v.to_array().map(f64::to_bits);
    a.vertices().len() == b.vertices().len()
        && a.faces().len() == b.faces().len()
        && a.edges() == b.edges()
        && a.vertices().iter().zip(b.vertices()).all(|(x, y)| bits(x) == bits(y))
        && a.faces().iter().zip(b.faces()).all(|(f, g)| {
            bits(&f.plane.normal) == bits(&g.plane.normal)
                && f.plane.offset.to_bits() == g.plane.offset.to_bits()
                && f.vertices[..] == g.vertices[..]
        })
}

impl IntervalObstacles {
    /// An empty store.
    pub fn new() -> Self {
        Self::default()
    }

    /// Drops every stored structure (and the shared events).
    pub fn clear(&mut self) {
        self.pairs.clear();
        self.events.clear();
    }

    /// Shares `events` (the pair events of every partition of a search) instead of this store's own.
    pub fn share_events(&mut self, events: &EventStore) {
        self.events = events.clone();
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
        let component = &part.components()[moving];
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
            let events = shared_events(&self.events, &entry.moving_rest, &fixed.turned);
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

#[cfg(test)]
mod tests {
    use super::*;
    use stackplan_geom::{Decomposition, examples::part_by_name};

    /// The events of a pair depend on the stack component only up to translation: copies of a piece in one
    /// rotation share one computation, and the events from the turned piece give the intervals of the events from
    /// each placed copy (band ends to rounding, the same degenerate angles at every planner angle).
    #[test]
    fn translated_copies_share_the_events_of_the_turned_piece() {
        let part = part_by_name("complex", Decomposition::ConvexMerge).expect("example");
        let rest = DMat3::from_rotation_x(std::f64::consts::PI);
        let pose = DMat3::from_rotation_z(std::f64::consts::FRAC_PI_2);
        let store = EventStore::default();
        let mut computed = 0;
        for (moving, fixed) in [(0, 0), (3, 7), (12, 25), (29, 1)] {
            let moving_rest = part.components()[moving].transformed(rest, DVec3::ZERO);
            let turned = Arc::new(part.components()[fixed].transformed(pose, DVec3::ZERO));
            let mut shared = Vec::new();
            for offset in [DVec3::ZERO, DVec3::new(317.5, -81.25, 31.0), DVec3::new(-1003.0, 945.0, 364.0)] {
                // each copy has its own turned polytope (the scene builds one per stack component)
                let own = Arc::new(part.components()[fixed].transformed(pose, DVec3::ZERO));
                shared.push(shared_events(&store, &moving_rest, &own));
                let world = part.components()[fixed].transformed(pose, offset);
                let direct = PairEvents::new(&moving_rest, &world);
                let from_turned = &shared[shared.len() - 1];
                assert_eq!(direct.bands().len(), from_turned.bands().len(), "pair {moving}-{fixed} at {offset}");
                for (a, b) in direct.bands().iter().zip(from_turned.bands()) {
                    assert!((a.lo - b.lo).abs() <= 1e-9 && (a.hi - b.hi).abs() <= 1e-9, "{a:?} vs {b:?}");
                }
                for k in 0..72 {
                    let theta = (k as f64 * 5.0).to_radians();
                    let (a, b) = (direct.interval_around(theta), from_turned.interval_around(theta));
                    assert_eq!(a.degenerate, b.degenerate, "pair {moving}-{fixed}, theta {k} x 5 degrees");
                    assert!((a.start - b.start).abs() <= 1e-9 && (a.end - b.end).abs() <= 1e-9);
                }
            }
            assert!(shared.windows(2).all(|w| Arc::ptr_eq(&w[0], &w[1])), "one computation per turned piece");
            assert!(Arc::ptr_eq(&shared[0], &shared_events(&store, &moving_rest, &turned)));
            computed += 1;
        }
        let entries: usize = store.0.lock().expect("lock").values().map(Vec::len).sum();
        assert_eq!(entries, computed);
        // another rotation of the same piece is another entry, and so is another moving component against it
        let other = Arc::new(part.components()[0].transformed(DMat3::IDENTITY, DVec3::ZERO));
        let moving_rest = part.components()[0].transformed(rest, DVec3::ZERO);
        shared_events(&store, &moving_rest, &other);
        shared_events(&store, &part.components()[5].transformed(rest, DVec3::ZERO), &other);
        let entries: usize = store.0.lock().expect("lock").values().map(Vec::len).sum();
        assert_eq!(entries, computed + 2);
        store.clear();
        assert!(store.0.lock().expect("lock").is_empty());
    }
}
