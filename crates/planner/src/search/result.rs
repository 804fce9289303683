//! What a placement search returns: placements with their contacts, why the search ran dry, and its counters.

use glam::{DMat3, DVec3};
use serde::{Deserialize, Serialize};
use stackplan_geom::Pose;

/// What the new part touches at a placement (from the active constraints of its cell).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "with", rename_all = "snake_case")]
pub enum Contact {
    /// A component of a stack part, through the obstacle face of the given kind.
    Stack {
        /// Component of the new part.
        our_component: usize,
        /// Stack part index.
        stack_part: usize,
        /// Its component.
        stack_component: usize,
        /// Face kind of the c-space obstacle (`fixed_face`: a face of the stack component against one of our
        /// vertices; `moving_face`: one of our faces against a stack vertex; `edge_edge`; the degenerate merged kinds
        /// `face_face`, `fixed_face_moving_edge`, `moving_face_fixed_edge`; `insertion_side`).
        face_kind: String,
    },
    /// The part rests on the floor.
    Floor,
    /// The part touches the maximum height.
    Ceiling,
    /// The part touches side `side` of the floor polygon (from corner `side` to `side + 1`).
    FloorSide {
        /// The side.
        side: u32,
    },
}

/// One placement of the new part.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Placement {
    /// Position `p` (mm): world vertex = rotation . v + position.
    pub position: [f64; 3],
    /// Rotation matrix rows `R_z(theta) R_rest`.
    pub rotation: [[f64; 3]; 3],
    /// Angle about z (radians).
    pub theta: f64,
    /// Angle about z (degrees).
    pub theta_deg: f64,
    /// Index of the resting pose (into the request's list).
    pub resting_pose: usize,
    /// The cost (the new part's term of cost (1), or the squared c.g. distance to the target).
    pub cost: f64,
    /// What it touches.
    pub contacts: Vec<Contact>,
}

impl Placement {
    /// The pose.
    pub fn pose(&self) -> Pose {
        Pose {
            rotation: DMat3::from_cols_array_2d(&self.rotation).transpose(),
            position: DVec3::from_array(self.position),
        }
    }
}

/// Counters and timings of a search, as \[A\] Tables I-II.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PlacementStats {
    /// Resting poses x theta values asked for.
    pub orientations_requested: usize,
    /// Orientations in the search after symmetry reduction.
    pub orientations_searched: usize,
    /// Symmetry order about z of each resting pose (1 = none).
    pub symmetry_orders: Vec<usize>,
    /// Orientations whose root was popped at least once ("considered").
    pub orientations_considered: usize,
    /// Orientations whose permissible set was empty.
    pub orientations_empty_omega: usize,
    /// Components of the new part.
    pub part_components: usize,
    /// Components of the stack.
    pub stack_components: usize,
    /// m_part x m_stack x orientations requested (the seed's "total pairs").
    pub total_pairs: u64,
    /// m_part x m_stack x orientations searched.
    pub total_pairs_searched: u64,
    /// Distinct (orientation, component pair) whose obstacle was built or extrapolated (an obstacle that stands for
    /// the pairs of a merged plate's pieces, [`crate::request::SearchTuning::merge_plates`], counts once).
    pub pairs_evaluated: u64,
    /// Obstacles constructed from scratch (Gauss-map overlay).
    pub obstacles_constructed: u64,
    /// Obstacles extrapolated within a constant-topology interval (`interval_obstacles.rs`; 0 with
    /// `SearchTuning::extrapolate` off).
    pub obstacles_extrapolated: u64,
    /// Obstacle lookups answered by the cache.
    pub obstacle_cache_hits: u64,
    /// Interference detections (configurations tested).
    pub interference_tests: u64,
    /// Popped optima cut by an obstacle of their orientation built earlier, without an interference detection.
    #[serde(default)]
    pub known_obstacle_cuts: u64,
    /// Exact narrow-phase pair tests.
    pub narrow_phase_tests: u64,
    /// Solved nodes popped (each tested for interference).
    pub nodes_expanded: u64,
    /// Nodes pushed (roots and children; a child's cell is built and solved only when it is popped).
    pub nodes_pushed: u64,
    /// Children found empty.
    pub cells_empty: u64,
    /// Children whose cell could not be built (its LPs failed) or whose QP failed every solver (the exact active set,
    /// the grown and reduced cell, clarabel): skipped with a warning, so the search no longer proves that what it returns is the cheapest (0 on well-formed parts;
    /// parts whose faces are planar only to single precision can have c-space faces parallel to the last bit).
    #[serde(default)]
    pub cells_unsolved: u64,
    /// QPs solved.
    pub qp_solves: u64,
    /// Setup time (orientations, scene), ms.
    pub time_setup_ms: f64,
    /// Root QPs, ms.
    pub time_roots_ms: f64,
    /// Interference detection, ms.
    pub time_interference_ms: f64,
    /// Obstacle construction, ms.
    pub time_obstacles_ms: f64,
    /// Cell subtraction and child QPs, ms.
    pub time_cells_ms: f64,
    /// Whole search, ms.
    pub time_total_ms: f64,
}

/// Why no placement was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NoPlacement {
    /// The part does not fit in the floor volume at any orientation (Omega is empty).
    EmptyOmega,
    /// Every free-space cell of every orientation was exhausted: the part fits nowhere.
    FitsNowhere,
    /// Every placement not yet returned costs more than the limit given to
    /// [`super::PlacementSearch::next_placements_within`] (the search stopped there and can go on).
    CostLimit,
}

/// The result of a placement search.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlacementResult {
    /// The best placements, cheapest first (at most `k`).
    pub placements: Vec<Placement>,
    /// Set when fewer than `k` were found: why the search ran dry.
    pub exhausted: Option<NoPlacement>,
    /// Counters and timings.
    pub stats: PlacementStats,
}
