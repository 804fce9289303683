//! The inputs of a placement (\[A\] section II-C, problem (2)): the new part and its candidate orientations, the
//! stack, the floor volume `Sigma` (or a fixed `p_z`), the clearance, the cost, the insertion option and `k`.
//!
//! Validation ([`PlacementRequest::validate`]) is O(size of the floor polygon + number of orientations) and turns every
//! bad option into a [`PlacementError`] naming the offending value, so the search itself never meets bad input.

use glam::{DMat3, DVec2, DVec3};
use serde::{Deserialize, Serialize};
use stackplan_geom::{Part, Pose};
use stackplan_stability::world::PlacedPart;

/// The floor volume `Sigma`: a convex floor polygon (counter-clockwise seen from above, in the plane `z = 0`) times
/// `[0, height]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FloorVolume {
    /// Corners of the convex floor polygon, counter-clockwise seen from above (mm).
    pub polygon: Vec<DVec2>,
    /// Maximum stack height (mm).
    pub height: f64,
}

impl FloorVolume {
    /// The rectangle `[x0, x1] x [y0, y1]` times `[0, height]`.
    pub fn rectangle(x0: f64, y0: f64, x1: f64, y1: f64, height: f64) -> Self {
        Self { polygon: vec![DVec2::new(x0, y0), DVec2::new(x1, y0), DVec2::new(x1, y1), DVec2::new(x0, y1)], height }
    }

    /// The vertex centroid of the floor polygon at `z = 0` (the default origin `(x0, y0, z0)` of cost (1)).
    pub fn centre(&self) -> DVec3 {
        let n = self.polygon.len().max(1) as f64;
        let s = self.polygon.iter().fold(DVec2::ZERO, |a, b| a + *b) / n;
        DVec3::new(s.x, s.y, 0.0)
    }

    /// Outward unit normals and offsets of the polygon's sides: `n . (x, y) <= d` inside; side `k` runs from corner
    /// `k` to corner `k + 1`.
    pub fn side_planes(&self) -> Vec<(DVec2, f64)> {
        polygon_side_planes(&self.polygon)
    }
}

/// Outward unit normals and offsets of the sides of a convex polygon, counter-clockwise seen from above: `n . (x, y)
/// <= d` inside; side `k` runs from corner `k` to corner `k + 1`. O(corners).
pub fn polygon_side_planes(polygon: &[DVec2]) -> Vec<(DVec2, f64)> {
    let n = polygon.len();
    (0..n)
        .map(|k| {
            let (a, b) = (polygon[k], polygon[(k + 1) % n]);
            let e = b - a;
            let normal = DVec2::new(e.y, -e.x).normalize();
            (normal, normal.dot(a))
        })
        .collect()
}

/// The cost minimised over positions at each orientation; both are separable convex quadratics in `p`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Cost {
    /// The new part's term of \[A\] eq. (1) with the rotated part's bounding-box extents and c.g. height
    /// (`docs/algorithms.md`, "Free space and the placement QP"): `w [(p_x + x_max - x0)^2 + (p_x + x_min - x0)^2 +
    /// (p_y + y_max - y0)^2 + (p_y + y_min - y0)^2] + 4 (1 - w) (p_z + z_c - z0)^2`.
    Stacking {
        /// Weight of floor-space use against c.g. height, in `[0, 1]`.
        w: f64,
        /// `(x0, y0, z0)`: the centre or a corner of the floor area.
        origin: DVec3,
    },
    /// The squared distance of the part's c.g. to a desired position (\[A\] section 7.1).
    Target {
        /// Desired c.g. position (mm).
        target: DVec3,
    },
}

/// Everything a placement needs. See the module documentation; [`PlacementRequest::new`] gives the defaults.
#[derive(Debug, Clone)]
pub struct PlacementRequest<'a> {
    /// The new part.
    pub part: &'a Part,
    /// Candidate resting poses as rotations `R(phi, psi)` applied before `R_z(theta)` (default: the identity, the
    /// part as it lies in its file).
    pub resting_rotations: Vec<DMat3>,
    /// The discrete rotation angles about world `z` (radians; default 1-degree steps over a full turn).
    pub thetas: Vec<f64>,
    /// The stack: parts already placed, which never move during a placement.
    pub stack: Vec<PlacedPart<'a>>,
    /// The floor volume `Sigma`.
    pub floor: FloorVolume,
    /// `Some(z)`: the 2-D permissible set at `p_z = z` (\[A\] VII-A-2); `None`: the 3-D one.
    pub fixed_z: Option<f64>,
    /// Minimum distance between the new part's components and the stack's (mm); obstacles grown by it (\[A\] eq.
    /// 10-11).
    pub clearance: f64,
    /// Measure the clearance in the horizontal plane only (\[A\] VII-B: "the parts are separated in the plane by at
    /// least 5 mm"): each obstacle is grown by a horizontal disc of radius `clearance` (face offsets
    /// `clearance |n_xy|`, mitred), so a part may rest on another while keeping `clearance` sideways. `false`: the
    /// distance in space (every face offset by `clearance`).
    pub horizontal_clearance: bool,
    /// The cost.
    pub cost: Cost,
    /// Require the final position to be reachable by a straight vertical descent from above (insertion obstacles).
    pub insertion: bool,
    /// How many placements (best first, one per free-space cell).
    pub k: usize,
    /// When the search gives up with [`PlacementError::TimeLimit`] (checked every 1024 nodes); `None`: never.
    pub deadline: Option<std::time::Instant>,
    /// How the search runs: switches of the reference routes and limits that do not change its results (apart
    /// from where it gives up). [`SearchTuning::default`].
    #[doc(hidden)]
    pub tuning: SearchTuning,
}

/// How a placement search runs, apart from what it searches for: the switches of its reference routes (the results do
/// not depend on them), its limits, and the region the stacking planner's stage 2 leaves to stage 1. The defaults
/// are what every user wants; tests and benchmarks turn the switches off to compare the routes.
#[doc(hidden)]
#[derive(Debug, Clone, PartialEq)]
pub struct SearchTuning {
    /// A region another search covers: a convex polygon (counter-clockwise seen from above). Positions at which the
    /// part's shadow lies inside it by more than the tolerance (the interior of the permissible set `Omega(theta)`
    /// of this polygon's prism, which has the floor volume's height) are not searched; positions on its boundary
    /// and outside are. `None` (the default): the whole floor volume. The stacking planner's stage 2 leaves stage
    /// 1's region to stage 1 ([`crate::stack_plan`]).
    pub searched_elsewhere: Option<Vec<DVec2>>,
    /// Search one period of the part's rotational symmetry about z only (when the theta set allows it).
    pub use_symmetry: bool,
    /// Extrapolate obstacles within their constant-topology intervals instead of constructing each one
    /// (`interval_obstacles.rs`, \[A\] IV-B). Off: every obstacle is constructed (the reference route).
    pub extrapolate: bool,
    /// Let the pieces of a sheet-metal plate stand for its filled outline where that is exact (two parallel plates,
    /// [`stackplan_geom::plate::merges_exactly`]; a plate against a component none of whose slices fits into its
    /// holes, [`stackplan_geom::plate::slices_clear_holes`]; the planner's `plates.rs`): one obstacle instead of one
    /// per pair of pieces, the same free positions (with a clearance, grown by other planes near corners). A contact
    /// with such an obstacle lists the pieces that touch. Default on; off: every pair of pieces has its own obstacle
    /// (the reference route).
    pub merge_plates: bool,
    /// Largest number of search nodes popped before giving up with [`PlacementError::NodeBudget`] (per partition
    /// of the orientations: each partition counts its own pops).
    pub node_budget: usize,
    /// Into how many partitions the search splits the orientations (blocks of a few consecutive orientations dealt
    /// round-robin, searched in parallel and merged in the search's total order, [`crate::search`]'s "Partitions";
    /// 1: the sequential search). The results depend on this number, never on the thread count. Default
    /// [`DEFAULT_PARTITIONS`].
    pub partitions: usize,
}

impl Default for SearchTuning {
    fn default() -> Self {
        Self {
            searched_elsewhere: None,
            use_symmetry: true,
            extrapolate: true,
            merge_plates: true,
            node_budget: DEFAULT_NODE_BUDGET,
            partitions: DEFAULT_PARTITIONS,
        }
    }
}

/// The default [`SearchTuning::partitions`]: the two cores of the machines the planner is built for (a fixed
/// number, not the thread count, so that results do not depend on the machine).
pub const DEFAULT_PARTITIONS: usize = 2;

/// The largest [`SearchTuning::partitions`] accepted.
pub const MAX_PARTITIONS: usize = 64;

/// The default of [`SearchTuning::node_budget`]: about 2-4 GB of search state at its end for parts of a few
/// hundred pieces, so that a search that cannot finish stops before it exhausts a 24 GB machine.
pub const DEFAULT_NODE_BUDGET: usize = 2_000_000;

/// `n` angles `0, 2 pi / n, ...` (a full turn in equal steps).
pub fn uniform_thetas(n: usize) -> Vec<f64> {
    (0..n).map(|k| k as f64 * std::f64::consts::TAU / n as f64).collect()
}

/// The most angles a theta set may hold ([`PlacementRequest::thetas`]): steps of 0.01 degree. Every angle is an
/// orientation of the search per resting pose, with its own obstacles, so memory and time grow with the count.
pub const MAX_THETAS: usize = 36_000;

/// Angles `0, step, 2 step, ...` below a full turn (`step` in radians).
///
/// # Errors
/// [`PlacementError::BadOption`] when `step` is not positive and finite, or so small that the turn would take more
/// than [`MAX_THETAS`] angles (a step below 0.01 degree).
pub fn thetas_with_step(step: f64) -> Result<Vec<f64>, PlacementError> {
    if !(step > 0.0 && step.is_finite()) {
        return Err(PlacementError::BadOption(format!("the theta step must be positive and finite, got {step} rad")));
    }
    let n = (std::f64::consts::TAU / step - 1e-9).ceil().max(1.0);
    if n > MAX_THETAS as f64 {
        return Err(PlacementError::BadOption(format!(
            "a theta step of {} degrees makes {n:.0} angles per turn; at most {MAX_THETAS} are supported (a step of at \
             least 0.01 degree)",
            step.to_degrees()
        )));
    }
    Ok((0..n as usize).map(|k| k as f64 * step).collect())
}

/// Checks that `poly` (named `what` in the message) is a convex polygon, counter-clockwise seen from above, with at
/// least 3 finite corners, no two consecutive ones equal, and some area.
fn check_convex_polygon(poly: &[DVec2], what: &str) -> Result<(), String> {
    if poly.len() < 3 {
        return Err(format!("the {what} polygon has {} corners, needs at least 3", poly.len()));
    }
    if let Some(i) = poly.iter().position(|c| !c.is_finite()) {
        return Err(format!("{what} corner {i} is not finite"));
    }
    let n = poly.len();
    let mut area2 = 0.0;
    for k in 0..n {
        let (a, b, c) = (poly[k], poly[(k + 1) % n], poly[(k + 2) % n]);
        area2 += a.perp_dot(b);
        if (b - a).length() == 0.0 {
            return Err(format!("{what} corners {k} and {} coincide", (k + 1) % n));
        }
        if (b - a).perp_dot(c - b) < 0.0 {
            return Err(format!("the {what} polygon is not convex and counter-clockwise at corner {}", (k + 1) % n));
        }
    }
    if area2.is_nan() || area2 <= 0.0 {
        return Err(format!("the {what} polygon has no area (or is clockwise)"));
    }
    Ok(())
}

impl<'a> PlacementRequest<'a> {
    /// Defaults: the part as it lies, 1-degree steps, no clearance, cost (1) with `w = 0.5` about the floor centre,
    /// no insertion, `k = 1`, 3-D permissible set, [`SearchTuning::default`].
    pub fn new(part: &'a Part, stack: Vec<PlacedPart<'a>>, floor: FloorVolume) -> Self {
        let origin = floor.centre();
        Self {
            part,
            resting_rotations: vec![DMat3::IDENTITY],
            thetas: uniform_thetas(360),
            stack,
            floor,
            fixed_z: None,
            clearance: 0.0,
            horizontal_clearance: false,
            cost: Cost::Stacking { w: 0.5, origin },
            insertion: false,
            k: 1,
            deadline: None,
            tuning: SearchTuning::default(),
        }
    }

    /// Checks every option; see [`PlacementError`].
    pub fn validate(&self) -> Result<(), PlacementError> {
        check_convex_polygon(&self.floor.polygon, "floor").map_err(PlacementError::BadFloor)?;
        if let Some(region) = &self.tuning.searched_elsewhere {
            check_convex_polygon(region, "searched-elsewhere").map_err(PlacementError::BadOption)?;
        }
        if !(self.floor.height > 0.0 && self.floor.height.is_finite()) {
            return Err(PlacementError::BadFloor(format!(
                "the maximum height must be positive and finite, got {}",
                self.floor.height
            )));
        }
        if self.thetas.is_empty() {
            return Err(PlacementError::BadOption("the theta set is empty".into()));
        }
        if self.thetas.len() > MAX_THETAS {
            return Err(PlacementError::BadOption(format!(
                "the theta set has {} angles; at most {MAX_THETAS} are supported",
                self.thetas.len()
            )));
        }
        if let Some(i) = self.thetas.iter().position(|t| !t.is_finite()) {
            return Err(PlacementError::BadOption(format!("theta {i} is not finite")));
        }
        if self.resting_rotations.is_empty() {
            return Err(PlacementError::BadOption("no resting pose given".into()));
        }
        for (i, r) in self.resting_rotations.iter().enumerate() {
            if Pose::new(*r, DVec3::ZERO).is_err() {
                return Err(PlacementError::BadOption(format!("resting pose {i} is not a proper rotation")));
            }
        }
        for (i, s) in self.stack.iter().enumerate() {
            if s.pose.check().is_err() {
                return Err(PlacementError::BadOption(format!("stack part {i} has an invalid pose")));
            }
        }
        if !(self.clearance >= 0.0 && self.clearance.is_finite()) {
            return Err(PlacementError::BadOption(format!(
                "the clearance must be non-negative and finite, got {}",
                self.clearance
            )));
        }
        if self.k == 0 {
            return Err(PlacementError::BadOption("k must be at least 1".into()));
        }
        if !(1..=MAX_PARTITIONS).contains(&self.tuning.partitions) {
            return Err(PlacementError::BadOption(format!(
                "the number of search partitions must lie in 1..={MAX_PARTITIONS}, got {}",
                self.tuning.partitions
            )));
        }
        if self.tuning.node_budget == 0 {
            return Err(PlacementError::BadOption("the node budget must be at least 1".into()));
        }
        match self.cost {
            Cost::Stacking { w, origin } => {
                if !(0.0..=1.0).contains(&w) {
                    return Err(PlacementError::BadOption(format!("w must lie in [0, 1], got {w}")));
                }
                if !origin.is_finite() {
                    return Err(PlacementError::BadOption("the cost origin is not finite".into()));
                }
            }
            Cost::Target { target } => {
                if !target.is_finite() {
                    return Err(PlacementError::BadOption("the target is not finite".into()));
                }
            }
        }
        if self.fixed_z.is_some_and(|z| !z.is_finite()) {
            return Err(PlacementError::BadOption("the fixed p_z is not finite".into()));
        }
        Ok(())
    }
}

/// Why a placement could not be computed. "Fits nowhere" is not an error: it is an empty
/// [`crate::search::Placement`] list with [`crate::search::NoPlacement`] as the reason.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlacementError {
    /// The floor volume is malformed.
    #[error("bad floor volume: {0}")]
    BadFloor(String),
    /// An option is out of range or contradictory.
    #[error("bad option: {0}")]
    BadOption(String),
    /// An obstacle could not be built for a component pair.
    #[error(
        "obstacle of moving component {moving_piece} against stack part {fixed_part} component {fixed_piece}: {reason}"
    )]
    Obstacle {
        /// Component of the new part.
        moving_piece: usize,
        /// Stack part.
        fixed_part: usize,
        /// Its component.
        fixed_piece: usize,
        /// The obstacle builder's message.
        reason: String,
    },
    /// The placement QP or a cell LP failed numerically.
    #[error("free-space cell of orientation {orientation}: {reason}")]
    FreeSpace {
        /// Orientation index.
        orientation: usize,
        /// The solver's message.
        reason: String,
    },
    /// The obstacle cache passed in holds obstacles of another moving part, or of another stack at the same part
    /// indices ([`stackplan_cspace::ObstacleCache::claim`]): one cache serves one part placed into one (growing)
    /// stack.
    #[error(
        "the obstacle cache was built for another part or another stack (use one cache per part and growing stack)"
    )]
    ForeignCache,
    /// The search ran past its deadline ([`PlacementRequest::deadline`]).
    #[error("the search ran out of time after finding {found} placement(s)")]
    TimeLimit {
        /// Placements found before giving up.
        found: usize,
    },
    /// The search popped more nodes than allowed (a safeguard; the search always terminates in exact arithmetic).
    #[error("the search exceeded its node budget of {budget} nodes after finding {found} placement(s)")]
    NodeBudget {
        /// The budget.
        budget: usize,
        /// Placements found before giving up.
        found: usize,
    },
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn theta_steps_are_checked_before_anything_is_allocated() {
        let five = thetas_with_step(5f64.to_radians()).expect("5 degrees");
        assert_eq!(five.len(), 72);
        assert_eq!(thetas_with_step(0.01f64.to_radians()).expect("the finest step").len(), MAX_THETAS);
        assert_eq!(thetas_with_step(std::f64::consts::TAU).expect("a whole turn"), vec![0.0]);
        // a step a little finer than 0.01 degree, and one that used to overflow the vector's capacity (a panic)
        for step in [0.0099f64.to_radians(), 1e-300, 0.0, -1.0, f64::NAN, f64::INFINITY] {
            let err = thetas_with_step(step).expect_err("not a supported step");
            assert!(matches!(err, PlacementError::BadOption(_)), "{step}: {err}");
        }
    }
}
