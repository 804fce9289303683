//! Obstacle sweeps over discrete orientations: build at interval starts, extrapolate elsewhere.
//!
//! Paper: Ayyadevara et al. 2002 (\[A\]) section IV-B (manuscript 4.2) and Table I (constructions vs extrapolations);
//! `docs/algorithms.md`, "Critical orientations and extrapolation". A [`PairSweep`] holds one convex pair, its event
//! bands over the full turn ([`PairEvents`], computed once in O(F_B E_A + F_A E_B)), and the structures built so far.
//! Asked for the obstacle at angle index `k` it extrapolates from a cached structure whose interval covers the angle
//! (O(size)), or builds the obstacle from scratch (the Gauss-map construction) and caches its structure with its
//! interval (O(bands)). Counters and timers record constructions and extrapolations.

use crate::critical::PairEvents;
use crate::extrapolate::{ExtrapolateError, ExtrapolatedGeometry, ObstacleStructure, rotation_z};
use serde::{Deserialize, Serialize};
use stackplan_cspace::minkowski::{Obstacle, obstacle};
use stackplan_geom::polytope::ConvexPolytope;
use std::f64::consts::TAU;
use std::time::{Duration, Instant};

/// Counters and timers of a sweep (\[A\] Table I).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct SweepStats {
    /// Obstacles built from scratch.
    pub constructions: u64,
    /// Obstacles extrapolated.
    pub extrapolations: u64,
    /// Constructions that could not be extrapolated from (hull-route obstacles): every angle near them is built.
    pub unextrapolable: u64,
    /// Time spent building (including recording the structure and its interval).
    pub construction_time: Duration,
    /// Time spent extrapolating.
    pub extrapolation_time: Duration,
    /// Time spent computing the pair's event bands.
    pub event_time: Duration,
}

impl SweepStats {
    /// Extrapolations per construction.
    pub fn extrapolations_per_construction(&self) -> f64 {
        self.extrapolations as f64 / (self.constructions.max(1)) as f64
    }
}

/// `n` equally spaced angles `k * 2 pi / n`, `k = 0..n` (360 one-degree steps by default).
pub fn uniform_angles(n: usize) -> Vec<f64> {
    (0..n).map(|k| TAU * k as f64 / n as f64).collect()
}

/// Angles every `step_deg` degrees over a full turn, starting at 0 (`step_deg` must be positive and finite; otherwise
/// the single angle 0).
pub fn degree_steps(step_deg: f64) -> Vec<f64> {
    if !(step_deg.is_finite() && step_deg > 0.0) {
        return vec![0.0];
    }
    let n = (360.0 / step_deg).round().max(1.0) as usize;
    (0..n).map(|k| (k as f64 * step_deg).to_radians()).collect()
}

/// A per-pair obstacle sweep over a list of angles, queried lazily by index. See the module documentation.
#[derive(Debug, Clone)]
pub struct PairSweep {
    moving: ConvexPolytope,
    fixed: ConvexPolytope,
    angles: Vec<f64>,
    events: PairEvents,
    structures: Vec<ObstacleStructure>,
    last_used: Option<usize>,
    stats: SweepStats,
}

impl PairSweep {
    /// A sweep of `moving` (rotated about `z`) against the placed `fixed` over `angles` (radians).
    pub fn new(moving: ConvexPolytope, fixed: ConvexPolytope, angles: Vec<f64>) -> Self {
        let start = Instant::now();
        let events = PairEvents::new(&moving, &fixed);
        let stats = SweepStats { event_time: start.elapsed(), ..SweepStats::default() };
        Self { moving, fixed, angles, events, structures: Vec::new(), last_used: None, stats }
    }

    /// A sweep over 360 one-degree steps.
    pub fn one_degree(moving: ConvexPolytope, fixed: ConvexPolytope) -> Self {
        Self::new(moving, fixed, degree_steps(1.0))
    }

    /// The angles.
    pub fn angles(&self) -> &[f64] {
        &self.angles
    }

    /// The pair's event bands.
    pub fn events(&self) -> &PairEvents {
        &self.events
    }

    /// Counters and timers so far.
    pub fn stats(&self) -> SweepStats {
        self.stats
    }

    /// The structures built so far.
    pub fn structures(&self) -> &[ObstacleStructure] {
        &self.structures
    }

    /// The moving polytope.
    pub fn moving(&self) -> &ConvexPolytope {
        &self.moving
    }

    /// The fixed polytope.
    pub fn fixed(&self) -> &ConvexPolytope {
        &self.fixed
    }

    fn covering(&self, theta: f64) -> Option<usize> {
        if let Some(k) = self.last_used.filter(|&k| self.structures[k].covers(theta)) {
            return Some(k);
        }
        self.structures.iter().position(|s| s.covers(theta))
    }

    /// The obstacle at angle index `k` (`None` if `k` is out of range).
    pub fn obstacle_at(&mut self, k: usize) -> Option<Result<Obstacle, ExtrapolateError>> {
        let theta = *self.angles.get(k)?;
        Some(self.obstacle_at_angle(theta))
    }

    /// The obstacle at any angle: extrapolated when a cached structure covers it, built (and cached) otherwise.
    pub fn obstacle_at_angle(&mut self, theta: f64) -> Result<Obstacle, ExtrapolateError> {
        if let Some(s) = self.covering(theta) {
            let start = Instant::now();
            let o = self.structures[s].extrapolate(&self.moving, &self.fixed, theta)?;
            self.stats.extrapolation_time += start.elapsed();
            self.stats.extrapolations += 1;
            self.last_used = Some(s);
            return Ok(o);
        }
        let start = Instant::now();
        let built = obstacle(&self.moving, rotation_z(theta), &self.fixed)?;
        let interval = self.events.interval_around(theta);
        match ObstacleStructure::from_obstacle(built.clone(), &self.moving, &self.fixed, theta, interval) {
            Ok(s) => {
                self.structures.push(s);
                self.last_used = Some(self.structures.len() - 1);
            }
            Err(e) => {
                tracing::debug!(theta, error = %e, "obstacle cannot be extrapolated from; not cached");
                self.stats.unextrapolable += 1;
            }
        }
        self.stats.construction_time += start.elapsed();
        self.stats.constructions += 1;
        Ok(built)
    }

    /// Vertices and planes at angle index `k` into `out` (the fast path: no polytope assembly when extrapolating).
    /// Returns whether the result was extrapolated (`false`: built from scratch).
    pub fn geometry_at(&mut self, k: usize, out: &mut ExtrapolatedGeometry) -> Option<Result<bool, ExtrapolateError>> {
        let theta = *self.angles.get(k)?;
        if let Some(s) = self.covering(theta) {
            let start = Instant::now();
            let r = self.structures[s].extrapolate_geometry(&self.moving, &self.fixed, theta, out);
            self.stats.extrapolation_time += start.elapsed();
            self.stats.extrapolations += 1;
            self.last_used = Some(s);
            return Some(r.map(|()| true));
        }
        Some(self.obstacle_at_angle(theta).map(|o| {
            out.vertices.clear();
            out.vertices.extend_from_slice(o.polytope().vertices());
            out.planes.clear();
            out.planes.extend(o.polytope().planes().copied());
            false
        }))
    }

    /// Every obstacle, in angle order.
    pub fn all(&mut self) -> Result<Vec<Obstacle>, ExtrapolateError> {
        (0..self.angles.len()).map(|k| self.obstacle_at_angle(self.angles[k])).collect()
    }
}

/// Every obstacle of the pair over `angles`, with the sweep's counters.
pub fn sweep(
    moving: &ConvexPolytope,
    fixed: &ConvexPolytope,
    angles: &[f64],
) -> Result<(Vec<Obstacle>, SweepStats), ExtrapolateError> {
    let mut s = PairSweep::new(moving.clone(), fixed.clone(), angles.to_vec());
    let all = s.all()?;
    Ok((all, s.stats()))
}
