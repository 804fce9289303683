//! The placement scenarios of \[A\] section 7.1 (Figs. 15-17, Tables I-II) for regression runs.
//!
//! * `channel`: a Channel part added to a 3-part Channel stack, 3-D `Omega`;
//! * `triangle`: a Triangle part added to a 3-part Triangle stack, 3-D `Omega`;
//! * `complex`: a Complex part added to a 1-part Complex stack, 2-D `Omega` at a fixed `p_z`.
//!
//! The seed gives neither dimensions nor the stacks' poses ("chosen at random"), so the stacks are built here, part
//! by part, with this crate's own placement: the first part on the floor at the floor's centre turned by 30 degrees,
//! the next ones placed at the desired position `p_d` (c.g. at the centroid of the first part's base face, \[A\] 7.1:
//! "the new part lies at the bottom of the stack") by the same search. Channel parts alternate upright and flipped
//! (the seed nests them "by flipping alternate parts"); Triangle parts keep one resting pose (they nest as they are).
//! All parts use the seed's plain triangulation (3, 6 and 79 components). 1-degree steps, no clearance.

use crate::PlacedPart;
use crate::request::{Cost, FloorVolume, PlacementError, PlacementRequest, uniform_thetas};
use crate::search::{PlacementResult, place};
use glam::{DMat3, DVec3};
use serde::{Deserialize, Serialize};
use stackplan_geom::sheet_metal::Decomposition;
use stackplan_geom::{Part, Pose, examples};

/// The names of the scenarios.
pub const SCENARIOS: [&str; 3] = ["channel", "triangle", "complex"];

/// A prepared scenario: the part, the stack and the request parameters.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// Name.
    pub name: &'static str,
    /// The part (also the stack's part).
    pub part: Part,
    /// Poses of the stack parts.
    pub stack: Vec<Pose>,
    /// Resting rotation of the new part.
    pub rest: DMat3,
    /// Desired c.g. position `p_d`.
    pub target: DVec3,
    /// Fixed `p_z` (2-D `Omega`) or `None`.
    pub fixed_z: Option<f64>,
    /// Floor volume.
    pub floor: FloorVolume,
}

/// The outcome of a scenario, for goldens.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ScenarioReport {
    /// Scenario name.
    pub name: String,
    /// Stack size.
    pub stack_parts: usize,
    /// The placement found (if any).
    pub placement: Option<crate::search::Placement>,
    /// Height of the new part's lowest point above the highest stack part's lowest point (nesting indicator, mm).
    pub height_above_previous: Option<f64>,
    /// The part's own height in its pose (mm).
    pub part_height: f64,
    /// Pairs evaluated / total pairs.
    pub fraction_evaluated: f64,
    /// The seed's figure for comparison (pairs evaluated, total) where it gives one.
    pub seed_pairs: Option<(u64, u64)>,
    /// Search statistics.
    pub stats: crate::search::PlacementStats,
}

fn flip() -> DMat3 {
    DMat3::from_rotation_x(std::f64::consts::PI)
}

/// Rotated part's lowest z and c.g.
fn lowest_z(part: &Part, r: DMat3) -> f64 {
    part.all_vertices().map(|v| (r * v).z).fold(f64::INFINITY, f64::min)
}

fn request_for<'a>(sc: &'a Scenario, part: &'a Part, stack: &[Pose], rest: DMat3) -> PlacementRequest<'a> {
    let stack_parts: Vec<PlacedPart<'a>> = stack.iter().map(|p| PlacedPart { part, pose: *p }).collect();
    let mut req = PlacementRequest::new(part, stack_parts, sc.floor.clone());
    req.resting_rotations = vec![rest];
    req.thetas = uniform_thetas(360);
    req.cost = Cost::Target { target: sc.target };
    req.fixed_z = sc.fixed_z;
    req
}

impl Scenario {
    /// The scenario's placement request: its part onto its stack in its resting pose, 1-degree steps of theta, the
    /// cost of distance to its target, its fixed height if any (the request [`run`] searches; callers change `k`,
    /// partitions and the like on it).
    pub fn request(&self) -> PlacementRequest<'_> {
        request_for(self, &self.part, &self.stack, self.rest)
    }
}

/// Builds the named scenario (one of [`SCENARIOS`]) with its stack. `None` for an unknown name.
pub fn scenario(name: &str) -> Result<Option<Scenario>, PlacementError> {
    let (ex, stack_len, alternate, fixed) = match name {
        "channel" => ("channel", 3, true, false),
        "triangle" => ("triangle", 3, false, false),
        "complex" => ("complex", 1, false, true),
        _ => return Ok(None),
    };
    let Some(part) = examples::part_by_name(ex, Decomposition::Triangulation) else {
        return Ok(None);
    };
    let name: &'static str = SCENARIOS.iter().find(|s| **s == name).copied().unwrap_or("unknown");
    let floor = FloorVolume::rectangle(-500.0, -500.0, 500.0, 500.0, 1000.0);
    // first part: turned by 30 degrees, c.g. above the origin, on the floor
    let r0 = DMat3::from_rotation_z(30f64.to_radians());
    let g0 = r0 * part.mass().center_of_gravity;
    let first = Pose { rotation: r0, position: DVec3::new(-g0.x, -g0.y, -lowest_z(&part, r0)) };
    // desired position: c.g. at the centroid of the first part's base face (its lowest horizontal face)
    let target = DVec3::new(0.0, 0.0, 0.0);
    let rest_of = |i: usize| if alternate && i % 2 == 1 { flip() } else { DMat3::IDENTITY };
    let mut sc = Scenario {
        name,
        part: part.clone(),
        stack: vec![first],
        rest: rest_of(stack_len),
        target,
        fixed_z: None,
        floor,
    };
    for i in 1..stack_len {
        let stack = sc.stack.clone();
        let req = request_for(&sc, &part, &stack, rest_of(i));
        let result = place(&req)?;
        let Some(best) = result.placements.first() else {
            return Err(PlacementError::BadOption(format!("scenario {name}: stack part {i} fits nowhere")));
        };
        sc.stack.push(best.pose());
    }
    if fixed {
        // the new Complex part lies at the height of the first part's short flanges (2-D Omega, [A] 7.1.2)
        let top_of_short_flange = 30.0 + examples::THICKNESS / 2.0;
        sc.fixed_z = Some(top_of_short_flange - lowest_z(&part, sc.rest));
    }
    Ok(Some(sc))
}

/// Runs a prepared scenario.
pub fn run(sc: &Scenario) -> Result<(PlacementResult, ScenarioReport), PlacementError> {
    let result = place(&sc.request())?;
    let placement = result.placements.first().cloned();
    let part_height = {
        let zs: Vec<f64> = sc.part.all_vertices().map(|v| (sc.rest * v).z).collect();
        zs.iter().copied().fold(f64::NEG_INFINITY, f64::max) - zs.iter().copied().fold(f64::INFINITY, f64::min)
    };
    let height_above_previous = placement.as_ref().and_then(|p| {
        let last = sc.stack.last()?;
        let prev_low = sc.part.all_vertices().map(|v| last.apply(v).z).fold(f64::INFINITY, f64::min);
        let pose = p.pose();
        let low = sc.part.all_vertices().map(|v| pose.apply(v).z).fold(f64::INFINITY, f64::min);
        Some(low - prev_low)
    });
    let seed_pairs = match sc.name {
        "channel" => Some((6960, 9720)),
        "triangle" => Some((9951, 38880)),
        _ => None,
    };
    let stats = result.stats.clone();
    let report = ScenarioReport {
        name: sc.name.to_string(),
        stack_parts: sc.stack.len(),
        placement,
        height_above_previous,
        part_height,
        fraction_evaluated: stats.pairs_evaluated as f64 / stats.total_pairs.max(1) as f64,
        seed_pairs,
        stats,
    };
    Ok((result, report))
}

/// All scenarios as JSON for `cargo xtask regress`: `{"channel": {...}, "triangle": {...}, "complex": {...}}`, each a
/// [`ScenarioReport`] or `{"error": "..."}`.
pub fn regress_place() -> serde_json::Value {
    let mut map = serde_json::Map::new();
    for name in SCENARIOS {
        let value = match scenario(name).and_then(|s| s.map(|s| run(&s)).transpose()) {
            Ok(Some((_, report))) => {
                serde_json::to_value(report).unwrap_or_else(|e| serde_json::json!({"error": e.to_string()}))
            }
            Ok(None) => serde_json::json!({"error": "unknown scenario"}),
            Err(e) => serde_json::json!({"error": e.to_string()}),
        };
        map.insert(name.to_string(), value);
    }
    serde_json::Value::Object(map)
}
