//! Best-first search over (orientation, free-space cell) nodes: the placement of one part (\[A\] V-A..C;
//! `docs/algorithms.md`, "Placement search").
//!
//! A node is an orientation `theta_k`, a convex cell `K` of positions (an H-polytope, \[A\] VI-A-1) and the optimum
//! `p*` of the cost over `K` (`f(p*)` is the key). The roots are `(theta_k, Omega(theta_k))`. Loop:
//!
//! 1. pop the cheapest node (costs compared rounded to about `1e-12` relative, so that exact ties do not depend
//!    on the optima's last bits; ties: lower orientation index, then lower cell id — deterministic);
//! 2. if the request leaves a region to another search ([`PlacementRequest::searched_elsewhere`]) and `p*` lies in
//!    its interior at `theta_k` (not applied on the node's path), take that region as the obstacle
//!    ([`DerivedObstacle::searched_elsewhere`]); else if an obstacle of `theta_k` built earlier holds `p*` in its
//!    interior by more than the tolerance (not one applied on the node's path), take the deepest such (any obstacle
//!    holding `p*` gives a valid split; this one needs no detection, which halves the detections of the Triangle
//!    scenario; in a plan the obstacles earlier searches built at `theta_k` are known from the orientation's first
//!    expansion); otherwise detect the interfering component pairs at `(theta_k, p*)` ([`crate::detect`]);
//! 3. take the first of them (deepest violation first) whose obstacle ([`crate::obstacles`]) contains `p*` in its
//!    interior by more than the tolerance, and split `K` into the children
//!    `K n {n_k . p >= d_k} n {n_j . p <= d_j, j < k}` (\[A\] VI-A-3). Children are pushed *lazily* keyed by a lower
//!    bound of their cost: the largest of the parent's cost, the minimum of the cost over the half-space
//!    `n_k . p >= d_k` alone (closed form, [`Quadratic::halfspace_lower_bound`]) and the bound that the parent's
//!    optimality conditions give over the part of `K` beyond that plane ([`Quadratic::lower_bound_beyond`]: it grows
//!    with the plane's distance from `p*`, which lies inside the obstacle; it halves the children solved in the
//!    Channel and Triangle searches and leaves the solved nodes' order alone). A box around the parent cell (bound
//!    propagation, [`stackplan_freespace::outer_box`]) is computed at the split: a child whose outside half-space
//!    misses it is empty and is not pushed (about 95 % of the empty children; its id is still taken, so the others'
//!    ids and order are unchanged). The same box drops the inequalities it proves redundant from the cell the
//!    children are built from (`Cell::grown_outer_box_pruned`: the same set; about 14 of 20 inequalities of a
//!    split cell in the 15-part Complex plan, inherited from cells cut before) and the inside cuts `n_j . p <= d_j`
//!    it proves redundant from each child's list (the same test as the outside child's, recorded at the split as a
//!    mask of the faces, `InsideCuts`). Each child's own box (the parent's tightened by its kept inside cuts and
//!    its outside half-space, grown by the tolerance: [`stackplan_freespace::outer_box::tighten_box`]) then drops
//!    the children it proves empty (their ids taken too) and adds the cost's minimum over it to the key
//!    ([`Quadratic::box_lower_bound`]; in a 15-part Complex plan about one child in eight past the first test is
//!    dropped, and the key rises for two in five). When a pushed child is popped its
//!    emptiness is decided by a
//!    phase 1 from the parent's optimum (`Cell::is_empty_with`: the optimum violates only
//!    `n_k . p >= d_k`, so this is usually one LP move); a non-empty child's cell is built from a second phase 1 on
//!    the exact cell (`Cell::with_halfspaces_from`, no Chebyshev LP) and its QP solved ([`crate::qp`]), and it is
//!    pushed back with its own cost — so children that never become the cheapest are never solved. The keys only decide
//!    *when* a pending child is solved, never the order of the solved nodes (a total order by (cost, orientation, id)
//!    that a valid lower bound cannot overtake), so the search pops the same solved nodes in the same order as with the
//!    parent's cost as key;
//! 4. if there is none, `p*` is free: it is the next placement (one per cell, in cost order, \[A\] VI-A-4).
//!
//! **Exactness.** The children cover `K` minus the obstacle's interior and each lies in `K`, so no child costs less
//! than its parent; a position is free iff it lies in no pair's obstacle interior. Hence the first free optimum popped
//! is the minimum of the cost over the free positions of all discrete orientations (\[A\] eq. 9 and section 5.3); the
//! next pops give the next best cells. Orientations whose root is never popped before the `k`-th solution are never
//! expanded, and only the obstacles of pairs met at popped optima are built.
//!
//! **Touching.** The QP's optimum lies on the planes of its active constraints; the obstacle test, the cell
//! membership and the narrow phase all use the one tolerance of the problem ([`stackplan_geom::Tolerance`], the
//! largest part's diagonal), so a point on an obstacle face is free and a popped node is never split by an obstacle it
//! was already cut from (this is also checked explicitly: each node carries the obstacles applied on its path).
//!
//! **Termination.** A node is split only by an obstacle whose interior holds its optimum; children lie outside that
//! interior, so along a path each (orientation, pair) obstacle is applied at most once and every path is finite. A
//! node budget guards against numerical trouble with a typed error.
//!
//! **Cost.** One QP per node; per popped node one interference detection (O(m_part m_stack) box tests plus the
//! narrow phase on overlapping boxes) and at most one obstacle construction. Root QPs run in parallel (rayon).
//!
//! **Partitions** ([`PlacementRequest::partitions`] = `P`, default 2). Every node belongs to one orientation, and
//! what the loop learns is per orientation (the known obstacles, the derived obstacles, the found points), so the
//! orientations are split into `P` fixed partitions, blocks of `LANE_BLOCK` consecutive orientations dealt
//! round-robin (`lane_of`; `P` is a number of the request, never the thread count), and each partition runs the
//! loop above on its own state: heap, node ids, obstacle table and known obstacles, derived obstacles, the
//! constant-topology structures ([`IntervalObstacles`]), the carried frontier and the detection's scratch
//! (`Search` and `RunState` per partition; the obstacle cache is shared, it is `Sync` and a pure function). The
//! placements are merged in the heap's total order (rounded cost, orientation, id; the orientations of two
//! partitions differ, so the ids of two partitions are never compared): the next placement of the whole search is
//! the cheapest of the partitions' next placements, and it is known once every other partition's next key pops
//! after it. Each partition keeps the placements it found but the merge has not returned (a look-ahead queue, at
//! most `LOOK_AHEAD`), which a later call returns first; a cost limit
//! ([`PlacementSearch::next_placements_within`]) stops each partition at its own keys. So the placements, their
//! order and their values are the sequential loop's over the same obstacles, and the first placement of every
//! search is the exact optimum.
//!
//! *Rounds and determinism.* The partitions advance in rounds on rayon, each at most `ROUND_POPS` pops: a
//! partition without a found placement whose next key pops before the best found one (of any partition, fixed at the
//! round's start) searches on up to that key; the others, while one such partition runs, look ahead for their next
//! placements (the caller often asks for more: the stacking planner rejects candidates; the work stays in the carried
//! frontier either way). A partition that finishes its round first waits, spinning briefly, for the others
//! (`round_end.rs`: the next round then finds both threads awake; timing only). A partition that runs alone runs
//! without rounds (nothing can change its bound). The bound is
//! exchanged only between rounds and every round's work is a function of the states at its start, so the states
//! after each call, hence the carried frontiers, the later candidates and the plans, depend on `P` but never on the
//! thread count or the timing (a shared atomic "best so far" would make them timing-dependent). `P = 1` is the
//! sequential loop itself, bit for bit.
//!
//! *What changes with `P`.* The placements, in the same order, up to which obstacles exist: a partition
//! extrapolates an obstacle only from structures it built itself ([`crate::interval_obstacles`]: an obstacle's
//! last bits depend on the angle its structure was built at), and the partitions search past the merge's current
//! placement (up to a round, and the look-ahead), so the carried frontiers are further along and a later placement
//! can lie in another cell of the same free space (another contact listed at the same position, or, rarely, another
//! later candidate). The statistics ([`PlacementStats`]) are sums over the partitions (`orientations_considered`
//! too: each orientation is in one partition; the node budget applies to each partition's pops).

use crate::dary_heap::DaryHeap;
use crate::detect::{CandidateQueue, DetectCounts, DetectScratch, StackScene, SweepAxes};
use crate::interval_obstacles::{EventStore, IntervalObstacles, ObstacleRoute};
use crate::obstacles::{DerivedObstacle, PlaneOrigin};
use crate::orientation::{Orientation, SeparableQuadratic, rotated_components};
use crate::qp::{QpOptimum, Quadratic, minimise};
use crate::request::{FloorVolume, PlacementError, PlacementRequest, polygon_side_planes};
use crate::round_end::RoundEnd;
use crate::symmetry::{is_uniform_full_turn, period_length, rotational_order};
use glam::{DMat3, DVec3};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use stackplan_cspace::ObstacleCache;
use stackplan_freespace::cell::{Cell, Halfspace, Tag};
use stackplan_freespace::outer_box::{box_is_empty, box_misses_halfspace, tighten_box};
use stackplan_geom::{Pose, Tolerance};
use std::collections::{HashMap, VecDeque};
use std::sync::Arc;
use std::time::Instant;

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
    /// the pairs of a merged plate's pieces, [`PlacementRequest::merge_plates`], counts once).
    pub pairs_evaluated: u64,
    /// Obstacles constructed from scratch (Gauss-map overlay).
    pub obstacles_constructed: u64,
    /// Obstacles extrapolated within a constant-topology interval ([`crate::interval_obstacles`]; 0 with
    /// `PlacementRequest::extrapolate` off).
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
    /// [`PlacementSearch::next_placements_within`] (the search stopped there and can go on).
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

/// A solved node: an orientation, a cell, its optimum and the obstacles applied on its path.
#[derive(Clone)]
struct Node<const D: usize> {
    cost: f64,
    orientation: usize,
    id: u64,
    cell: Arc<Cell<D>>,
    optimum: QpOptimum<D>,
    applied: Arc<[u32]>,
}

/// The pending children of one split: the parent's cell plus the extra inequalities of child `face` of obstacle
/// `obstacle` (rebuilt from the obstacle's planes when the child is popped), the parent's optimum as the start of
/// their phase 1, and per child its key (a lower bound of its cost), id and face. A child is built and solved only
/// when popped. The heap holds one entry per family, keyed by its cheapest remaining child (`children` is sorted
/// so that it is the last): the heap pops the children in the same order as with one entry each (a family's key
/// is the least of its children's, and a total order's least over a union is the least of the least ones), without
/// holding the many children that are never popped. The children live in one arena of the heap
/// ([`NodeHeap::children`]: no allocation per family).
#[derive(Clone)]
struct Family<const D: usize> {
    orientation: usize,
    /// The parent cell; released (`None`) once the last child has been popped, so that a long search (and the
    /// frontiers carried through a plan) holds only the cells of families with children still pending.
    cell: Option<Arc<Cell<D>>>,
    applied: Arc<[u32]>,
    obstacle: u32,
    start: [f64; D],
    /// Which inside cuts the children keep ([`Search::child_inequalities`]).
    cuts: InsideCuts<D>,
    /// The family's children are `NodeHeap::children[first..first + left]` (`(key, id, face)`), the cheapest (by
    /// [`HeapKey`]'s order) last; popping one decrements `left`.
    first: usize,
    left: u32,
}

/// The inside cuts `n_j . p <= d_j` that a family's children keep: those the box around the parent cell
/// (`Cell::grown_outer_box_pruned`, when the obstacle's planes are finite) does not prove redundant. The test is
/// the one that drops the empty outside child of the same face at the split (`box_misses_halfspace` with the same
/// arguments), so the kept cuts are recorded there as a mask; an obstacle with more faces than the mask's bits keeps
/// the box and repeats the test per child.
#[derive(Clone, Copy)]
enum InsideCuts<const D: usize> {
    /// Bit `j`: face `j`'s inside cut is kept (its outside half-space meets the box).
    Kept(u128),
    /// The box (`None`: no finite box, every cut kept).
    Reach(Option<([f64; D], [f64; D])>),
}

/// The state of the search's loop between calls ([`Search::advance`]): the open nodes, the next node id, the
/// orientations expanded so far, the placements found so far (orientation, position) and the pops so far.
#[derive(Clone)]
struct RunState<const D: usize> {
    fixed_z: f64,
    heap: NodeHeap<D>,
    next_id: u64,
    considered: Vec<bool>,
    found_points: Vec<(usize, DVec3)>,
    pops: u64,
    /// Solved nodes whose optimum was found free (placements and their duplicates on shared boundaries): with the
    /// heap they cover every position not inside an obstacle applied so far, so a search into the grown stack can
    /// continue from both ([`SearchCaches::carrying_frontiers`]).
    free_nodes: Vec<Node<D>>,
    /// Lists reused from node to node (no allocation per node once warm).
    buffers: Buffers<D>,
    /// The keys of the nodes of the placements the last [`Search::advance`] returned, in order.
    found_keys: Vec<HeapKey>,
    /// A partition's placements found but not yet returned, cheapest first, with their nodes' keys (the merge's
    /// look-ahead, see "Partitions" in the module documentation); their nodes are in `free_nodes`.
    ahead: VecDeque<(HeapKey, Placement)>,
}

/// The loop's reusable lists: a child's extra inequalities, a split's outside half-spaces and its children's keys.
#[derive(Clone)]
struct Buffers<const D: usize> {
    extra: Vec<Halfspace<D>>,
    outside: Vec<Outside<D>>,
    children: Vec<(f64, u64, u32)>,
}

impl<const D: usize> Default for Buffers<D> {
    fn default() -> Self {
        Self { extra: Vec::new(), outside: Vec::new(), children: Vec::new() }
    }
}

impl<const D: usize> RunState<D> {
    /// The state for a search into the grown stack: the free nodes are open again, nothing is found or considered
    /// yet (the orientations' components are rebuilt when first popped).
    fn reopened(mut self) -> Self {
        for node in std::mem::take(&mut self.free_nodes) {
            self.heap.push(node);
        }
        self.considered.fill(false);
        self.found_points.clear();
        self.pops = 0;
        self.found_keys.clear();
        self.ahead.clear();
        self
    }
}

/// A popped entry: a solved node, or the next child of a family (its id and face; the family by index into
/// [`NodeHeap::families`]).
enum Popped<const D: usize> {
    Solved(Node<D>),
    Pending { family: u32, id: u64, face: u32 },
}

/// Low mantissa bits rounded away by [`quantised_cost`]: 12 of 52, a relative step of `2^-40` (about `1e-12`).
const KEY_ROUND_BITS: u32 = 12;

/// The cost as the heap compares it: rounded to the nearest multiple of `2^-40` of its binade (about `1e-12`
/// relative; half-way cases away from zero), so that costs equal but for rounding in their last bits (mirror-image
/// cells, optima reached from different start points) compare equal and their order falls to (orientation, id),
/// which no rounding moves. Rounding is monotone (`a <= b` implies `q(a) <= q(b)`), so a lower bound of a cost stays
/// a lower bound of its key, and comparing rounded values is a total order (a strict weak order, unlike "within
/// eps"). Non-finite values are kept.
#[inline]
fn quantised_cost(cost: f64) -> f64 {
    if !cost.is_finite() {
        return cost;
    }
    let half = 1u64 << (KEY_ROUND_BITS - 1);
    let mask = !((1u64 << KEY_ROUND_BITS) - 1);
    // sign bit untouched; a carry out of the mantissa moves to the next binade (or to infinity at the very top,
    // which only a cost near f64::MAX could reach)
    f64::from_bits((cost.to_bits().wrapping_add(half)) & mask)
}

/// The key of a node in the heap: its cost (rounded, [`quantised_cost`]), orientation and id (the total order of
/// the search), and its slot in [`NodeHeap`]'s slab, or (with [`FAMILY`] set) its family's index.
///
/// The order is encoded in two integers so that a comparison is two integer compares (a heap walk makes up to four
/// per level): `rank_cost` is the rounded cost's bits mapped monotonically to `u64` (the order of `f64::total_cmp`),
/// `rank_tie` is `orientation << 40 | id`, both complemented so that the max-heap pops the cheapest, then the lowest
/// orientation, then the lowest id. Ids stay below `2^40` (the node budget is far smaller) and orientations below
/// `2^24` (checked when the search is prepared).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct HeapKey {
    rank_cost: u64,
    rank_tie: u64,
    slot: u32,
}

/// Bits of [`HeapKey::rank_tie`] that hold the id.
const ID_BITS: u32 = 40;

impl HeapKey {
    fn new(cost: f64, orientation: usize, id: u64, slot: u32) -> Self {
        debug_assert!(id < 1 << ID_BITS && orientation < 1 << (64 - ID_BITS));
        let bits = quantised_cost(cost).to_bits();
        // negative: all bits flipped; positive: the sign bit set (`total_cmp`'s order as unsigned integers)
        let ordered = if bits >> 63 == 1 { !bits } else { bits | 1 << 63 };
        Self { rank_cost: !ordered, rank_tie: !((orientation as u64) << ID_BITS | id), slot }
    }

    /// The rounded cost.
    fn cost(&self) -> f64 {
        let ordered = !self.rank_cost;
        f64::from_bits(if ordered >> 63 == 1 { ordered & !(1 << 63) } else { !ordered })
    }
}

/// The bit of [`HeapKey::slot`] that marks a family's entry.
const FAMILY: u32 = 1 << 31;

/// The open nodes: a 4-ary heap ([`DaryHeap`]) of small keys (cost, orientation, id) over a slab of the solved nodes
/// (whose cells, optima and paths would otherwise be moved at every sift) and the families of pending children (one
/// entry each, see [`Family`]). Pops in the order (cost, orientation, id).
#[derive(Clone)]
struct NodeHeap<const D: usize> {
    keys: DaryHeap<HeapKey>,
    slab: Vec<Option<Node<D>>>,
    free: Vec<u32>,
    families: Vec<Family<D>>,
    /// The families' children, each family's a contiguous run ([`Family::first`]).
    children: Vec<(f64, u64, u32)>,
}

impl<const D: usize> Default for NodeHeap<D> {
    fn default() -> Self {
        Self { keys: DaryHeap::new(), slab: Vec::new(), free: Vec::new(), families: Vec::new(), children: Vec::new() }
    }
}

impl<const D: usize> NodeHeap<D> {
    fn push(&mut self, node: Node<D>) {
        let (cost, orientation, id) = (node.cost, node.orientation, node.id);
        let slot = match self.free.pop() {
            Some(slot) => {
                self.slab[slot as usize] = Some(node);
                slot
            }
            None => {
                self.slab.push(Some(node));
                (self.slab.len() - 1) as u32
            }
        };
        self.keys.push(HeapKey::new(cost, orientation, id, slot));
    }

    /// Pushes a family with the pending children `children` (`(key, id, face)`; drained; none: nothing to push).
    /// `family.first` and `family.left` are set here.
    fn push_family(&mut self, mut family: Family<D>, children: &mut Vec<(f64, u64, u32)>) {
        // descending in (rounded key, id): the cheapest last
        children.sort_unstable_by(|a, b| quantised_cost(b.0).total_cmp(&quantised_cost(a.0)).then(b.1.cmp(&a.1)));
        family.first = self.children.len();
        family.left = children.len() as u32;
        let Some(&(cost, id, _)) = children.last() else {
            return;
        };
        self.children.append(children);
        let index = self.families.len() as u32;
        self.keys.push(HeapKey::new(cost, family.orientation, id, index | FAMILY));
        self.families.push(family);
    }

    fn pop(&mut self) -> Option<Popped<D>> {
        let top = *self.keys.peek()?;
        if top.slot & FAMILY != 0 {
            let index = top.slot & !FAMILY;
            let family = &mut self.families[index as usize];
            family.left = family.left.checked_sub(1)?;
            let (_, id, face) = self.children[family.first + family.left as usize];
            if family.left > 0 {
                // the family's next child: its key is not less than the popped one's, so it replaces the top
                let (cost, next, _) = self.children[family.first + family.left as usize - 1];
                self.keys.replace_top(HeapKey::new(cost, family.orientation, next, top.slot));
            } else {
                self.keys.pop();
            }
            return Some(Popped::Pending { family: index, id, face });
        }
        let key = self.keys.pop()?;
        self.free.push(key.slot);
        self.slab[key.slot as usize].take().map(Popped::Solved)
    }

    fn len(&self) -> usize {
        self.keys.len()
    }

    /// The key popped next.
    fn peek_key(&self) -> Option<HeapKey> {
        self.keys.peek().copied()
    }

    /// The cheapest key's (rounded) cost: a lower bound of every cost the heap still holds.
    fn peek_cost(&self) -> Option<f64> {
        self.keys.peek().map(HeapKey::cost)
    }

    fn is_empty(&self) -> bool {
        self.keys.is_empty()
    }
}

/// The point of `D` variables in the world (`p_z = fixed_z` when `D = 2`).
fn lift<const D: usize>(p: &[f64; D], fixed_z: f64) -> DVec3 {
    if D == 3 { DVec3::new(p[0], p[1], p[2]) } else { DVec3::new(p[0], p[1], fixed_z) }
}

/// A world plane restricted to the `D` variables: `Ok(halfspace)`, or `Err(holds)` when it does not depend on them
/// (`holds`: satisfied by every point, within `tol`).
fn restrict<const D: usize>(normal: DVec3, offset: f64, fixed_z: f64, tol: f64) -> Result<([f64; D], f64), bool> {
    if D == 3 {
        return Ok((std::array::from_fn(|i| normal[i]), offset));
    }
    let off = offset - normal.z * fixed_z;
    if normal.x.hypot(normal.y) <= 1e-12 {
        return Err(off >= -tol);
    }
    Ok((std::array::from_fn(|i| normal[i]), off))
}

fn restrict_quadratic<const D: usize>(q: &SeparableQuadratic, fixed_z: f64) -> Quadratic<D> {
    let mut constant = q.constant;
    if D == 2 {
        constant += q.h[2] * (fixed_z - q.c[2]).powi(2);
    }
    Quadratic { h: std::array::from_fn(|i| q.h[i]), c: std::array::from_fn(|i| q.c[i]), constant }
}

/// A child of a split: the face's outside half-space `normal . p >= offset` and the face's index.
type Outside<const D: usize> = (([f64; D], f64), u32);

/// The obstacles known at one orientation, their planes stored contiguously (the known-obstacle test of every popped
/// node scans them all; one flat array instead of a pointer chase per obstacle).
#[derive(Debug, Default)]
struct KnownObstacles {
    /// Obstacle ids, in the order they became known.
    ids: Vec<u32>,
    /// `planes[starts[k]..starts[k + 1]]` are obstacle `ids[k]`'s planes `(normal, offset)`.
    starts: Vec<u32>,
    planes: Vec<(DVec3, f64)>,
}

impl KnownObstacles {
    fn push(&mut self, id: u32, obstacle: &DerivedObstacle) {
        if self.starts.is_empty() {
            self.starts.push(0);
        }
        self.ids.push(id);
        self.planes.extend(obstacle.planes.iter().map(|pl| (pl.normal, pl.offset)));
        self.starts.push(self.planes.len() as u32);
    }

    /// [`DerivedObstacle::interior_depth`] of obstacle `ids[k]` (the same arithmetic).
    #[inline]
    fn interior_depth(&self, k: usize, p: DVec3, tol: f64) -> Option<f64> {
        let mut depth = f64::INFINITY;
        for &(normal, offset) in &self.planes[self.starts[k] as usize..self.starts[k + 1] as usize] {
            let slack = offset - tol - normal.dot(p);
            if slack <= 0.0 {
                return None;
            }
            depth = depth.min(slack);
        }
        Some(depth + tol)
    }
}

/// The search state of one partition of the orientations (the whole search when there is one): everything the loop
/// changes, for the orientations `lane_of(i) == lane` (the other orientations' entries stay untouched).
struct Search<'r, 'a> {
    request: &'r PlacementRequest<'a>,
    /// This partition's index and the number of partitions.
    lane: usize,
    lanes: usize,
    orientations: Vec<Orientation>,
    sweeps: Vec<Option<Arc<SweepAxes>>>,
    scene: Arc<StackScene>,
    tol: Tolerance,
    cache: &'r ObstacleCache,
    obstacles: Vec<Arc<DerivedObstacle>>,
    derived: HashMap<(usize, usize, usize), Arc<DerivedObstacle>>,
    obstacle_ids: HashMap<(usize, usize, usize), u32>,
    /// The obstacles built (or taken from the shared caches) for each orientation, in order.
    by_orientation: Vec<KnownObstacles>,
    /// Per orientation, the (moving, stack component) pairs whose derived obstacle an earlier search of the plan
    /// built (indexed once per search; taken when the orientation is first expanded).
    shared_pairs: Vec<Vec<(usize, usize)>>,
    /// Per orientation, the id of this search's region searched elsewhere
    /// ([`PlacementRequest::searched_elsewhere`], [`DerivedObstacle::searched_elsewhere`]), added to the obstacle
    /// table when the orientation is first expanded; it cuts before any known obstacle.
    elsewhere: Vec<Option<u32>>,
    rotated: HashMap<[u64; 9], RotatedComponents>,
    detect_scratch: DetectScratch,
    intervals: IntervalObstacles,
    /// Per moving component, its plate when the request merges plates (`plates.rs`).
    moving_plate_of: Arc<[Option<u32>]>,
    stats: PlacementStats,
    /// Rounds of the partitioned loop run (first partition only; for the debug log).
    rounds: u64,
}

/// Places the part (see the module documentation) with a fresh obstacle cache.
pub fn place(request: &PlacementRequest<'_>) -> Result<PlacementResult, PlacementError> {
    place_with_cache(request, &ObstacleCache::new())
}

/// Places the part, building obstacles through `cache` (shareable across successive placements into a growing stack
/// whose parts keep their indices and poses: a cached obstacle depends only on the pair and the rotation).
pub fn place_with_cache(
    request: &PlacementRequest<'_>,
    cache: &ObstacleCache,
) -> Result<PlacementResult, PlacementError> {
    place_with_caches(request, cache, &mut SearchCaches::default())
}

/// What successive searches into a growing stack share beyond the [`ObstacleCache`]: the derived obstacles (insertion
/// and clearance applied) of each (orientation, pair), keyed by orientation index, the constant-topology structures
/// the obstacles are extrapolated from ([`IntervalObstacles`]) and the detection's scratch lists. They are reused
/// only while the searches place the same part (a fingerprint of its components' vertex bits) with the same
/// orientations (bit-identical rotations), the same clearance, insertion,
/// horizontal-clearance and extrapolation settings, and the previous search's stack components are the first
/// components of the new stack, bit for bit (parts appended, never moved); otherwise they are cleared. The derived
/// obstacles are pure functions of those inputs; an extrapolated obstacle depends (in its last bits) on which angle its
/// structure was built at, so a plan's results depend on its search history, deterministically.
///
/// With several partitions of the orientations ([`PlacementRequest::partitions`]) each partition keeps its own
/// caches (its orientations' derived obstacles, structures and obstacle ids).
#[derive(Debug, Default)]
pub struct SearchCaches {
    signature: Option<CacheSignature>,
    /// Whether searches continue the open frontier of an earlier search ([`SearchCaches::carrying_frontiers`]).
    carry: bool,
    /// One per partition.
    lanes: Vec<LaneCaches>,
    /// The pair events of the constant-topology intervals, shared by the partitions ([`IntervalObstacles`]).
    events: EventStore,
    /// The states of the last searches, by floor and cost, newest last (at most [`CARRIED_FRONTIERS`]).
    frontiers: Vec<(FrontierSignature, States)>,
    /// The last search's scene and its stack's keys: a search whose stack extends that stack places only its new
    /// parts' components (a plan's stack only grows).
    scene: Option<(Vec<SceneKey>, Arc<StackScene>)>,
}

/// A stack part as the caches compare it: a fingerprint of the part's geometry and the bits of its pose.
type SceneKey = (u64, [u64; 12]);

/// The [`SceneKey`]s of a stack (the fingerprint computed once per distinct part).
fn scene_keys(stack: &[crate::request::StackPart<'_>]) -> Vec<SceneKey> {
    let mut fingerprints: Vec<(*const stackplan_geom::Part, u64)> = Vec::new();
    stack
        .iter()
        .map(|s| {
            let at = std::ptr::from_ref(s.part);
            let fingerprint = match fingerprints.iter().find(|(p, _)| *p == at) {
                Some(&(_, f)) => f,
                None => {
                    let f = s.part.fingerprint();
                    fingerprints.push((at, f));
                    f
                }
            };
            let mut pose = [0u64; 12];
            for (slot, x) in
                pose.iter_mut().zip(s.pose.rotation.to_cols_array().into_iter().chain(s.pose.position.to_array()))
            {
                *slot = x.to_bits();
            }
            (fingerprint, pose)
        })
        .collect()
}

/// What one partition of the orientations keeps from search to search ([`SearchCaches`]).
#[derive(Debug, Default)]
struct LaneCaches {
    detect_scratch: DetectScratch,
    /// The part's components rotated, and their sweep axes (with insertion), by rotation (bits of its matrix),
    /// built at an orientation's first expansion in some search: every search of a plan expands many of the same
    /// orientations (the values are those of building them again).
    rotated: HashMap<[u64; 9], RotatedComponents>,
    derived: HashMap<(usize, usize, usize), Arc<DerivedObstacle>>,
    intervals: IntervalObstacles,
    /// The derived obstacles by id (the ids the carried cells' tags and paths name).
    table: ObstacleTable,
}

/// The part's components at one rotation ([`LaneCaches::rotated`]).
#[derive(Debug, Clone)]
struct RotatedComponents {
    components: Arc<[stackplan_cspace::PlacedConvex]>,
    sweep: Option<Arc<SweepAxes>>,
}

/// How many frontiers [`SearchCaches`] keeps: the stacking planner alternates a stage-1 search (a floor that grows
/// with the stack's footprint) and a stage-2 search (the whole floor).
const CARRIED_FRONTIERS: usize = 2;

/// The derived obstacles of a sequence of searches by id, and by orientation.
#[derive(Debug, Default)]
struct ObstacleTable {
    obstacles: Vec<Arc<DerivedObstacle>>,
    ids: HashMap<(usize, usize, usize), u32>,
    by_orientation: Vec<KnownObstacles>,
}

/// What a search's open nodes depend on beyond [`CacheSignature`]: the floor volume, the fixed height and the cost.
#[derive(Debug, Clone, PartialEq)]
struct FrontierSignature {
    floor: FloorVolume,
    searched_elsewhere: Option<Vec<glam::DVec2>>,
    fixed_z: Option<u64>,
    cost: String,
}

impl FrontierSignature {
    fn of(request: &PlacementRequest<'_>) -> Self {
        Self {
            floor: request.floor.clone(),
            searched_elsewhere: request.searched_elsewhere.clone(),
            fixed_z: request.fixed_z.map(f64::to_bits),
            // `Debug` of an f64 round-trips: equal strings iff equal values
            cost: format!("{:?}", request.cost),
        }
    }

    /// Whether a frontier searched under `self` can be continued under `next`: the same cost and fixed height,
    /// `self`'s floor volume inside `next`'s (the same height; every corner of the old polygon inside the new one),
    /// so every old cell lies in the new permissible set and only the difference needs new cells
    /// (`Search::widen`), and `self`'s region searched elsewhere (if any) inside `next`'s (so the old cells cover
    /// everything `next` searches; `next` cuts its larger region out of them as they pop).
    fn continues_into(&self, next: &Self) -> bool {
        // a footprint clipped from a slanted floor side has interpolated corners there, and a grown footprint's side
        // along the same floor side passes them only within rounding: "inside" allows 64 ulps of the polygons' size
        // (the search's own tolerance is 1e-9 of the part's size; a carried cell poking out of the new floor by that
        // much is not seen)
        let inside = |a: &[glam::DVec2], b: &[glam::DVec2]| {
            a == b || {
                let scale = a.iter().chain(b).map(|c| c.abs().max_element()).fold(1.0, f64::max);
                let slack = 64.0 * f64::EPSILON * scale;
                let sides = polygon_side_planes(b);
                a.iter().all(|&c| sides.iter().all(|&(n, d)| n.dot(c) <= d + slack))
            }
        };
        self.fixed_z == next.fixed_z
            && self.cost == next.cost
            && self.floor.height.to_bits() == next.floor.height.to_bits()
            && inside(&self.floor.polygon, &next.floor.polygon)
            && match (&self.searched_elsewhere, &next.searched_elsewhere) {
                (None, _) => true,
                (Some(_), None) => false,
                (Some(old), Some(new)) => inside(old, new),
            }
    }
}

#[derive(Debug, PartialEq)]
struct CacheSignature {
    rotations: Vec<[u64; 9]>,
    clearance: u64,
    insertion: bool,
    horizontal: bool,
    extrapolate: bool,
    merge_plates: bool,
    partitions: usize,
    /// [`stackplan_geom::Part::fingerprint`] of the part placed (the derived obstacles and structures are its components').
    moving: u64,
    stack: Vec<SceneKey>,
}

impl SearchCaches {
    /// Empty caches.
    pub fn new() -> Self {
        Self::default()
    }

    /// Empty caches that also carry each [`PlacementSearch`]'s state, when it is dropped, to the next search with the
    /// same fixed height and cost and a floor volume that contains its floor, into the grown stack: that search
    /// starts from the open cells and the cells found free of the earlier one (and the new strip of a grown floor,
    /// `Search::widen`) instead of the roots. Its first placement is the same exact optimum; the later ones are one
    /// per cell of a different partition of the free space, so they can differ from a fresh search's, as can the
    /// counters (a carried search evaluates only pairs no earlier search did). The stacking planner uses these.
    pub fn carrying_frontiers() -> Self {
        Self { carry: true, ..Self::default() }
    }

    /// The scene of `request`'s stack (`keys`: its [`scene_keys`]): the last search's, with the components of the
    /// parts added since, when the stack extends that search's; otherwise built afresh.
    fn scene(&mut self, request: &PlacementRequest<'_>, keys: &[SceneKey]) -> Arc<StackScene> {
        let mut scene = match self.scene.take() {
            Some((old, scene)) if old.len() <= keys.len() && old[..] == keys[..old.len()] => scene,
            _ => Arc::new(StackScene::new(&[])),
        };
        let placed = scene.parts();
        if placed < request.stack.len() {
            let grown = Arc::make_mut(&mut scene);
            for s in &request.stack[placed..] {
                grown.push_part(s.part, s.pose);
            }
        }
        self.scene = Some((keys.to_vec(), Arc::clone(&scene)));
        scene
    }

    /// Keeps the caches when `next` extends the signature they were built under, clears them otherwise.
    fn adopt(&mut self, next: CacheSignature) {
        let keep = self.signature.as_ref().is_some_and(|old| {
            old.rotations == next.rotations
                && old.clearance == next.clearance
                && old.insertion == next.insertion
                && old.horizontal == next.horizontal
                && old.extrapolate == next.extrapolate
                && old.merge_plates == next.merge_plates
                && old.partitions == next.partitions
                && old.moving == next.moving
                && old.stack.len() <= next.stack.len()
                && old.stack.iter().zip(&next.stack).all(|(a, b)| a == b)
        });
        if !keep {
            self.lanes.clear();
            self.frontiers.clear();
            self.events.clear();
        }
        self.lanes.resize_with(next.partitions, LaneCaches::default);
        self.signature = Some(next);
    }
}

/// Orientations per block dealt to the partitions in turn ([`lane_of`]).
const LANE_BLOCK: usize = 4;

/// The partition of orientation `i` among `lanes` partitions: blocks of [`LANE_BLOCK`] consecutive orientations
/// dealt round-robin (neighbouring angles cost about the same to search, so the partitions' work is balanced, and a
/// block keeps some constant-topology intervals inside one partition).
fn lane_of(i: usize, lanes: usize) -> usize {
    (i / LANE_BLOCK) % lanes
}

/// The search's setup: validation, orientations (one symmetry period per resting pose), the scene, the
/// statistics' constants, and the shared caches adopted (their contents move into the searches until
/// [`Search::give_back`]); one search per partition of the orientations.
fn prepare<'r, 'a>(
    request: &'r PlacementRequest<'a>,
    cache: &'r ObstacleCache,
    caches: &mut SearchCaches,
) -> Result<Vec<Search<'r, 'a>>, PlacementError> {
    request.validate()?;
    let part = request.part;
    let scale = request
        .stack
        .iter()
        .map(|s| {
            let (lo, hi) = s.part.aabb();
            (hi - lo).length()
        })
        .fold(
            {
                let (lo, hi) = part.aabb();
                (hi - lo).length()
            },
            f64::max,
        );
    let tol = Tolerance::for_scale(scale);
    // orientations, one symmetry period per resting pose
    let n_theta = request.thetas.len();
    let uniform = is_uniform_full_turn(&request.thetas);
    let mut orientations = Vec::new();
    let mut symmetry_orders = Vec::new();
    for (rest, r) in request.resting_rotations.iter().enumerate() {
        let order = if request.use_symmetry { rotational_order(part, *r, 10.0 * part.tolerance().linear) } else { 1 };
        symmetry_orders.push(order);
        let count = if uniform { period_length(n_theta, order) } else { n_theta };
        for (ti, &theta) in request.thetas.iter().enumerate().take(count) {
            orientations.push((rest, ti, theta, *r));
        }
    }
    // the heap key packs the orientation index in 24 bits (`HeapKey`)
    if orientations.len() >= 1 << (64 - ID_BITS) {
        return Err(PlacementError::BadOption(format!(
            "{} orientations (resting poses x theta values) are more than the search handles ({})",
            orientations.len(),
            (1u64 << (64 - ID_BITS)) - 1
        )));
    }
    let mut orientations: Vec<Orientation> = orientations
        .into_par_iter()
        .enumerate()
        .map(|(i, (rest, ti, theta, r))| Orientation::without_components(part, i, rest, ti, theta, r, &request.cost))
        .collect();
    let keys = scene_keys(&request.stack);
    // the obstacle cache's keys name parts by index: refuse a cache built for another part or another stack
    let moving = part.fingerprint();
    let fixed: Vec<u64> = keys
        .iter()
        .map(|key| {
            use std::hash::{Hash, Hasher};
            let mut hasher = std::collections::hash_map::DefaultHasher::new();
            key.hash(&mut hasher);
            hasher.finish()
        })
        .collect();
    if !cache.claim(moving, &fixed) {
        return Err(PlacementError::ForeignCache);
    }
    let scene = caches.scene(request, &keys);
    // rotated components and sweep axes are built when an orientation is first expanded
    let sweeps: Vec<Option<Arc<SweepAxes>>> = vec![None; orientations.len()];
    let stats = PlacementStats {
        orientations_requested: request.resting_rotations.len() * n_theta,
        orientations_searched: orientations.len(),
        symmetry_orders,
        part_components: part.components.len(),
        stack_components: scene.components.len(),
        total_pairs: (part.components.len() * scene.components.len() * request.resting_rotations.len() * n_theta)
            as u64,
        total_pairs_searched: (part.components.len() * scene.components.len() * orientations.len()) as u64,
        ..Default::default()
    };
    caches.adopt(CacheSignature {
        rotations: orientations.iter().map(|o| o.rotation.to_cols_array().map(f64::to_bits)).collect(),
        clearance: request.clearance.to_bits(),
        insertion: request.insertion,
        horizontal: request.horizontal_clearance,
        extrapolate: request.extrapolate,
        merge_plates: request.merge_plates,
        partitions: request.partitions,
        moving,
        stack: keys,
    });
    let n_orientations = orientations.len();
    let lanes = request.partitions;
    let mut searches = Vec::with_capacity(lanes);
    let caches_events = caches.events.clone();
    let moving_plate_of: Arc<[Option<u32>]> = crate::plates::moving_plates(request).into();
    for (lane, lane_caches) in caches.lanes.iter_mut().enumerate() {
        // the pairs earlier searches built, by orientation (one pass over the shared derived obstacles); caches that
        // carry frontiers keep the obstacle table itself (carried cells name obstacles by id)
        let mut shared_pairs = vec![Vec::new(); n_orientations];
        let mut table = ObstacleTable::default();
        if caches.carry {
            table = std::mem::take(&mut lane_caches.table);
        } else {
            for &(oi, moving, fixed) in lane_caches.derived.keys() {
                if let Some(list) = shared_pairs.get_mut(oi) {
                    list.push((moving, fixed));
                }
            }
        }
        table.by_orientation.resize_with(n_orientations, KnownObstacles::default);
        searches.push(Search {
            request,
            lane,
            lanes,
            // the last partition takes the list itself (one partition: no copy)
            orientations: if lane + 1 == lanes { std::mem::take(&mut orientations) } else { orientations.clone() },
            sweeps: sweeps.clone(),
            scene: Arc::clone(&scene),
            tol,
            cache,
            obstacles: table.obstacles,
            obstacle_ids: table.ids,
            by_orientation: table.by_orientation,
            shared_pairs,
            elsewhere: vec![None; n_orientations],
            detect_scratch: std::mem::take(&mut lane_caches.detect_scratch),
            rotated: std::mem::take(&mut lane_caches.rotated),
            derived: std::mem::take(&mut lane_caches.derived),
            intervals: {
                let mut intervals = std::mem::take(&mut lane_caches.intervals);
                intervals.share_events(&caches_events);
                intervals
            },
            moving_plate_of: Arc::clone(&moving_plate_of),
            stats: stats.clone(),
            rounds: 0,
        });
    }
    Ok(searches)
}

/// The statistics of a partitioned search: the counters and times summed over the partitions, the constants
/// (orientations, components, pairs) of the first.
fn merged_stats(searches: &[Search<'_, '_>]) -> PlacementStats {
    let mut stats = searches.first().map(|s| s.stats.clone()).unwrap_or_default();
    for s in searches.iter().skip(1).map(|s| &s.stats) {
        stats.orientations_considered += s.orientations_considered;
        stats.orientations_empty_omega += s.orientations_empty_omega;
        stats.pairs_evaluated += s.pairs_evaluated;
        stats.obstacles_constructed += s.obstacles_constructed;
        stats.obstacles_extrapolated += s.obstacles_extrapolated;
        stats.obstacle_cache_hits += s.obstacle_cache_hits;
        stats.interference_tests += s.interference_tests;
        stats.known_obstacle_cuts += s.known_obstacle_cuts;
        stats.narrow_phase_tests += s.narrow_phase_tests;
        stats.nodes_expanded += s.nodes_expanded;
        stats.nodes_pushed += s.nodes_pushed;
        stats.cells_empty += s.cells_empty;
        stats.cells_unsolved += s.cells_unsolved;
        stats.qp_solves += s.qp_solves;
        stats.time_setup_ms += s.time_setup_ms;
        stats.time_roots_ms += s.time_roots_ms;
        stats.time_interference_ms += s.time_interference_ms;
        stats.time_obstacles_ms += s.time_obstacles_ms;
        stats.time_cells_ms += s.time_cells_ms;
    }
    stats
}

/// [`place_with_cache`] sharing `caches` with earlier searches (see [`SearchCaches`]); the stacking planner passes
/// the same caches to every search of a plan.
pub fn place_with_caches(
    request: &PlacementRequest<'_>,
    cache: &ObstacleCache,
    caches: &mut SearchCaches,
) -> Result<PlacementResult, PlacementError> {
    let start = Instant::now();
    let mut searches = prepare(request, cache, caches)?;
    let before = cache.stats();
    if let Some(first) = searches.first_mut() {
        first.stats.time_setup_ms = ms(start);
    }
    let result = match request.fixed_z {
        None => run::<3>(&mut searches, 0.0),
        Some(z) => run::<2>(&mut searches, z),
    };
    let after = cache.stats();
    for (search, lane) in searches.iter_mut().zip(&mut caches.lanes) {
        search.give_back(lane);
    }
    let mut result = result?;
    result.stats.obstacles_constructed = after.constructions - before.constructions;
    result.stats.obstacle_cache_hits = after.hits - before.hits;
    result.stats.time_total_ms = ms(start);
    tracing::info!(
        placements = result.placements.len(),
        nodes = result.stats.nodes_expanded,
        pairs = result.stats.pairs_evaluated,
        total_pairs = result.stats.total_pairs,
        ms = result.stats.time_total_ms,
        "placement search done"
    );
    Ok(result)
}

/// The search's state in 2 or 3 variables, one per partition of the orientations.
#[derive(Clone)]
enum States {
    Two(Vec<RunState<2>>),
    Three(Vec<RunState<3>>),
}

impl std::fmt::Debug for States {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (dimensions, open, free) = match self {
            States::Two(s) => {
                (2, s.iter().map(|s| s.heap.len()).sum::<usize>(), s.iter().map(|s| s.free_nodes.len()).sum::<usize>())
            }
            States::Three(s) => {
                (3, s.iter().map(|s| s.heap.len()).sum::<usize>(), s.iter().map(|s| s.free_nodes.len()).sum::<usize>())
            }
        };
        f.debug_struct("States")
            .field("dimensions", &dimensions)
            .field("open_entries", &open)
            .field("free_nodes", &free)
            .finish()
    }
}

/// A placement search that can be continued: the same search as [`place_with_caches`], whose heap (and every other
/// part of its state) is kept between calls of [`PlacementSearch::next_placements`], so asking for `a` placements
/// and then for `b` more gives the same placements, in the same order and with the same values, as one search with
/// `k = a + b` (the request's `k` is not used). The stacking planner, which asks for more candidates when all of the
/// first ones fail its stability checks, continues instead of starting again with a larger `k`.
///
/// The shared caches are held until the search is dropped (then handed back, as [`place_with_caches`] does).
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use glam::DVec3;
/// use stackplan_cspace::ObstacleCache;
/// use stackplan_geom::{ConvexPolytope, Part, PartOrigin, Pose};
/// use stackplan_planner::{FloorVolume, PlacementRequest, PlacementSearch, SearchCaches, StackPart, uniform_thetas};
///
/// let block = ConvexPolytope::cuboid(DVec3::ZERO, DVec3::new(40.0, 20.0, 10.0))?;
/// let part = Part::from_components("block", vec![block], 1.0, PartOrigin::ConvexPieces)?;
/// let stack = vec![StackPart { part: &part, pose: Pose::IDENTITY }];
/// let mut request = PlacementRequest::new(&part, stack, FloorVolume::rectangle(-50.0, -50.0, 90.0, 70.0, 100.0));
/// request.thetas = uniform_thetas(8);
/// let (cache, mut caches) = (ObstacleCache::new(), SearchCaches::new());
/// let mut search = PlacementSearch::new(&request, &cache, &mut caches)?;
/// let first = search.next_placements(2)?; // the 2 best
/// let more = search.next_placements(3)?; // the next 3: places 3..5 of a search with k = 5
/// assert!(first.placements[first.placements.len() - 1].cost <= more.placements[0].cost);
/// drop(search); // hands the caches back
/// request.k = 5;
/// let once = stackplan_planner::place_with_caches(&request, &ObstacleCache::new(), &mut SearchCaches::new())?;
/// assert_eq!([first.placements, more.placements].concat(), once.placements);
/// # Ok(())
/// # }
/// ```
pub struct PlacementSearch<'r, 'a, 'c> {
    /// One per partition of the orientations.
    searches: Vec<Search<'r, 'a>>,
    caches: &'c mut SearchCaches,
    /// `None`: Omega is empty at every orientation.
    state: Option<States>,
    cache: &'r ObstacleCache,
    /// Obstacle-cache constructions and hits during this search's own calls (the cache is shared: the caller may
    /// build obstacles through it between two calls).
    cache_counts: (u64, u64),
    /// Time spent in the calls so far (ms).
    elapsed_ms: f64,
    /// Set when the caches carry frontiers and no call failed: the state goes back to the caches on drop.
    signature: Option<FrontierSignature>,
    /// The stack's scene (shared with the partitions and the caches).
    scene: Arc<StackScene>,
}

impl std::fmt::Debug for PlacementSearch<'_, '_, '_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PlacementSearch")
            .field("empty_omega", &self.state.is_none())
            .field("stats", &merged_stats(&self.searches))
            .finish_non_exhaustive()
    }
}

impl<'r, 'a, 'c> PlacementSearch<'r, 'a, 'c> {
    /// Prepares the search and solves the roots (the setup and root phases of [`place_with_caches`]).
    pub fn new(
        request: &'r PlacementRequest<'a>,
        cache: &'r ObstacleCache,
        caches: &'c mut SearchCaches,
    ) -> Result<Self, PlacementError> {
        let start = Instant::now();
        let before = cache.stats();
        let mut searches = prepare(request, cache, caches)?;
        if let Some(first) = searches.first_mut() {
            first.stats.time_setup_ms = ms(start);
        }
        // the state of the newest search with this floor that this one continues, else of the newest one whose
        // floor lies inside this one's (widened); a state widened right after it was searched (the stacking
        // planner's stage 2 continuing its stage 1 when that accepted nothing) is copied, the original kept for the
        // next search of its own floor
        let signature = caches.carry.then(|| FrontierSignature::of(request));
        let carried = signature.as_ref().and_then(|sig| {
            let at = caches
                .frontiers
                .iter()
                .rposition(|(s, _)| s.floor == sig.floor && s.continues_into(sig))
                .or_else(|| caches.frontiers.iter().rposition(|(s, _)| s.continues_into(sig)))?;
            let widens = caches.frontiers[at].0.floor != request.floor;
            if widens && at + 1 == caches.frontiers.len() {
                let (old, state) = &caches.frontiers[at];
                return Some((state.clone(), Some(old.floor.clone())));
            }
            let (old, state) = caches.frontiers.remove(at);
            Some((state, widens.then_some(old.floor)))
        });
        let state = match (carried, request.fixed_z) {
            (Some((States::Three(s), old)), None) => {
                widen_all(&mut searches, s, old.as_ref()).map(|s| Some(States::Three(s)))
            }
            (Some((States::Two(s), old)), Some(_)) => {
                widen_all(&mut searches, s, old.as_ref()).map(|s| Some(States::Two(s)))
            }
            (_, None) => start_all::<3>(&mut searches, 0.0).map(|s| s.map(States::Three)),
            (_, Some(z)) => start_all::<2>(&mut searches, z).map(|s| s.map(States::Two)),
        };
        let state = match state {
            Ok(state) => state,
            Err(e) => {
                for (search, lane) in searches.iter_mut().zip(&mut caches.lanes) {
                    search.give_back(lane);
                }
                // the obstacle table the kept states name by id is lost with the search
                caches.frontiers.clear();
                return Err(e);
            }
        };
        let after = cache.stats();
        let cache_counts = (after.constructions - before.constructions, after.hits - before.hits);
        // (every partition holds the same scene; there is at least one partition, `validate`)
        let scene = searches.first().map_or_else(|| Arc::new(StackScene::new(&[])), |s| Arc::clone(&s.scene));
        Ok(Self { searches, caches, state, cache, cache_counts, elapsed_ms: ms(start), signature, scene })
    }

    /// The next `more` placements (fewer, with `exhausted` set, when the free space runs out); statistics over the
    /// whole search so far.
    pub fn next_placements(&mut self, more: usize) -> Result<PlacementResult, PlacementError> {
        self.next_placements_within(more, f64::INFINITY)
    }

    /// The next `more` placements that cost at most `max_cost`: as [`Self::next_placements`], but the search stops
    /// (fewer returned, `exhausted` = [`NoPlacement::CostLimit`]) as soon as every open node's key exceeds
    /// `max_cost`; the keys are lower bounds of the costs of every placement still to come, so none of those costs
    /// `max_cost` or less. The placements returned are those of [`Self::next_placements`] up to the first dearer
    /// than `max_cost` (to the keys' rounding, `quantised_cost`: one may cost up to `2^-40` relative more), and a
    /// later call, with any limit, continues exactly where this one stopped. Use: a caller that needs only
    /// placements cheaper than one it already has (the stacking planner's stage 2 against stage 1's part).
    pub fn next_placements_within(&mut self, more: usize, max_cost: f64) -> Result<PlacementResult, PlacementError> {
        let start = Instant::now();
        let before = self.cache.stats();
        let placements = match &mut self.state {
            None => {
                return Ok(PlacementResult {
                    placements: Vec::new(),
                    exhausted: (more > 0).then_some(NoPlacement::EmptyOmega),
                    stats: self.stats(),
                });
            }
            Some(States::Two(states)) => advance_all(&mut self.searches, states, more, max_cost),
            Some(States::Three(states)) => advance_all(&mut self.searches, states, more, max_cost),
        };
        let after = self.cache.stats();
        self.cache_counts.0 += after.constructions - before.constructions;
        self.cache_counts.1 += after.hits - before.hits;
        self.elapsed_ms += ms(start);
        if placements.is_err() {
            // a failed call may have lost a popped node: this state is not carried on
            self.signature = None;
        }
        let (placements, limited) = placements?;
        let exhausted = (placements.len() < more).then_some(if limited {
            NoPlacement::CostLimit
        } else {
            NoPlacement::FitsNowhere
        });
        Ok(PlacementResult { placements, exhausted, stats: self.stats() })
    }

    /// The stack's components placed in the world, as this search sees them (the scene the caches keep; the
    /// stacking planner settles its candidates among them).
    pub fn scene(&self) -> &StackScene {
        &self.scene
    }

    /// The statistics of the search so far.
    pub fn stats(&self) -> PlacementStats {
        let mut stats = merged_stats(&self.searches);
        (stats.obstacles_constructed, stats.obstacle_cache_hits) = self.cache_counts;
        stats.time_total_ms = self.elapsed_ms;
        stats
    }

    /// The statistics of each partition of the orientations so far (one entry per
    /// [`PlacementRequest::partitions`]; [`Self::stats`] sums them): the balance of the partitioned search.
    pub fn partition_stats(&self) -> Vec<PlacementStats> {
        self.searches.iter().map(|s| s.stats.clone()).collect()
    }
}

impl Drop for PlacementSearch<'_, '_, '_> {
    fn drop(&mut self) {
        if self.searches.len() > 1 {
            tracing::debug!(
                nodes = ?self.searches.iter().map(|s| s.stats.nodes_expanded).collect::<Vec<_>>(),
                pushed = ?self.searches.iter().map(|s| s.stats.nodes_pushed).collect::<Vec<_>>(),
                rounds = self.searches.first().map_or(0, |s| s.rounds),
                "partitioned search: nodes per partition"
            );
        }
        for (search, lane) in self.searches.iter_mut().zip(&mut self.caches.lanes) {
            search.give_back(lane);
            if self.caches.carry {
                lane.table = ObstacleTable {
                    obstacles: std::mem::take(&mut search.obstacles),
                    ids: std::mem::take(&mut search.obstacle_ids),
                    by_orientation: std::mem::take(&mut search.by_orientation),
                };
            }
        }
        if self.caches.carry
            && let (Some(signature), Some(state)) = (self.signature.take(), self.state.take())
        {
            self.caches.frontiers.retain(|(s, _)| *s != signature);
            self.caches.frontiers.push((signature, state));
            if self.caches.frontiers.len() > CARRIED_FRONTIERS {
                self.caches.frontiers.remove(0);
            }
        }
    }
}

fn ms(since: Instant) -> f64 {
    since.elapsed().as_secs_f64() * 1e3
}

/// Whether key `a` pops after key `b` (the heap's order: cheaper, then lower orientation, then lower id first; the
/// slot is not part of the order).
fn pops_after(a: HeapKey, b: HeapKey) -> bool {
    (a.rank_cost, a.rank_tie) < (b.rank_cost, b.rank_tie)
}

/// How many placements a partition finds ahead of the merge while another partition searches up to the best found
/// one ("Partitions" in the module documentation).
const LOOK_AHEAD: usize = 4;

/// Pops per partition between two exchanges of the partitions' next placements ("Partitions" in the module
/// documentation).
const ROUND_POPS: u64 = 256;

/// The whole search of [`place_with_caches`]: roots, then `k` placements.
fn run<const D: usize>(searches: &mut [Search<'_, '_>], fixed_z: f64) -> Result<PlacementResult, PlacementError> {
    let Some(k) = searches.first().map(|s| s.request.k) else {
        return Err(PlacementError::BadOption("no search partition".into()));
    };
    let Some(mut states) = start_all::<D>(searches, fixed_z)? else {
        return Ok(PlacementResult {
            placements: Vec::new(),
            exhausted: Some(NoPlacement::EmptyOmega),
            stats: merged_stats(searches),
        });
    };
    let (placements, _) = advance_all(searches, &mut states, k, f64::INFINITY)?;
    let exhausted = (placements.len() < k).then_some(NoPlacement::FitsNowhere);
    Ok(PlacementResult { placements, exhausted, stats: merged_stats(searches) })
}

/// Every partition's roots and state; `None` when Omega is empty at every orientation.
fn start_all<const D: usize>(
    searches: &mut [Search<'_, '_>],
    fixed_z: f64,
) -> Result<Option<Vec<RunState<D>>>, PlacementError> {
    let states = searches.iter_mut().map(|s| s.start::<D>(fixed_z)).collect::<Result<Vec<_>, _>>()?;
    Ok(states.iter().any(|s| !s.heap.is_empty()).then_some(states))
}

/// Every partition's carried state reopened and widened (`Search::widen`).
fn widen_all<const D: usize>(
    searches: &mut [Search<'_, '_>],
    states: Vec<RunState<D>>,
    old: Option<&FloorVolume>,
) -> Result<Vec<RunState<D>>, PlacementError> {
    searches.iter_mut().zip(states).map(|(s, state)| s.widen(state.reopened(), old)).collect()
}

/// The next `want` placements of the partitioned search ("Partitions" in the module documentation): a k-way merge
/// of the partitions' next placements in the heap's order, the partitions advanced in rounds; one partition is the
/// sequential loop itself ([`Search::advance`]). Returns `true` when it stopped at `max_cost`.
fn advance_all<const D: usize>(
    searches: &mut [Search<'_, '_>],
    states: &mut [RunState<D>],
    want: usize,
    max_cost: f64,
) -> Result<(Vec<Placement>, bool), PlacementError> {
    if let ([search], [state]) = (&mut *searches, &mut *states) {
        return search.advance(state, want, max_cost, None, u64::MAX);
    }
    let mut placements = Vec::new();
    if want == 0 {
        return Ok((placements, false));
    }
    // per partition: 0 idle, 1 needed (its next placement may precede every found one), 2 looking ahead
    let mut roles = vec![0u8; states.len()];
    loop {
        // the cheapest found placement of all partitions: every other partition searches up to its key
        let best = states
            .iter()
            .enumerate()
            .filter_map(|(i, s)| s.ahead.front().map(|(key, _)| (i, *key)))
            .reduce(|a, b| if pops_after(b.1, a.1) { a } else { b });
        let bound = best.map(|(_, key)| key);
        for (role, s) in roles.iter_mut().zip(states.iter()) {
            let open = s.heap.peek_key().filter(|top| top.cost() <= max_cost);
            *role = match open {
                Some(top) if s.ahead.is_empty() && bound.is_none_or(|b| pops_after(b, top)) => 1,
                Some(_) if s.ahead.len() < LOOK_AHEAD => 2,
                _ => 0,
            };
        }
        let needed = roles.iter().filter(|r| **r == 1).count();
        if needed == 0 {
            // every partition either holds its next placement or has nothing left before the best one (or within
            // the limit): the best one is the next placement of the whole search
            match best {
                Some((i, key)) if key.cost() <= max_cost => {
                    if let Some((_, placement)) = states[i].ahead.pop_front() {
                        placements.push(placement);
                    }
                    if placements.len() >= want {
                        return Ok((placements, false));
                    }
                    continue;
                }
                _ => {
                    let limited = states.iter().any(|s| !s.ahead.is_empty() || !s.heap.is_empty());
                    return Ok((placements, limited));
                }
            }
        }
        let running = roles.iter().filter(|r| **r != 0).count();
        if running == 1 {
            // alone it cannot learn a new bound from the others: no rounds
            if let Some(i) = roles.iter().position(|r| *r == 1) {
                searches[i].step(&mut states[i], 1, max_cost, bound, u64::MAX)?;
            }
            continue;
        }
        // a round: the needed partitions search for their next placement up to the best one, the others look
        // further ahead (placements the caller may ask for next; the work stays in the state either way)
        // (a partition that finishes its round first waits, spinning, for the others: `RoundEnd`)
        let round_end = RoundEnd::new(roles.len());
        let results: Vec<Result<(), PlacementError>> = searches
            .par_iter_mut()
            .zip(states.par_iter_mut())
            .zip(roles.par_iter())
            .enumerate()
            .map(|(i, ((search, state), &role))| {
                let want = match role {
                    1 => 1,
                    2 => LOOK_AHEAD - state.ahead.len(),
                    _ => return Ok(()),
                };
                round_end.start(i);
                let bound = if role == 1 { bound } else { None };
                let result = search.step(state, want, max_cost, bound, ROUND_POPS);
                round_end.finish(i);
                result
            })
            .collect();
        for result in results {
            result?;
        }
        searches[0].rounds += 1;
    }
}

impl Search<'_, '_> {
    /// Moves the shared caches' contents back into `caches` (this partition's).
    fn give_back(&mut self, caches: &mut LaneCaches) {
        caches.detect_scratch = std::mem::take(&mut self.detect_scratch);
        caches.rotated = std::mem::take(&mut self.rotated);
        caches.derived = std::mem::take(&mut self.derived);
        caches.intervals = std::mem::take(&mut self.intervals);
    }

    /// The permissible set `Omega(theta)` of orientation `o` in `floor` as half-spaces in the `D` variables
    /// (`None`: empty at the fixed height).
    fn omega<const D: usize>(&self, o: &Orientation, floor: &FloorVolume, fixed_z: f64) -> Option<Vec<Halfspace<D>>> {
        if D == 3 {
            let hs = o.omega_3d(floor);
            Some(
                hs.into_iter().map(|h| Halfspace::new(std::array::from_fn(|i| h.normal[i]), h.offset, h.tag)).collect(),
            )
        } else {
            let hs = o.omega_2d(floor, fixed_z, self.tol.linear)?;
            Some(
                hs.into_iter().map(|h| Halfspace::new(std::array::from_fn(|i| h.normal[i]), h.offset, h.tag)).collect(),
            )
        }
    }

    /// A carried state ([`SearchCaches::carrying_frontiers`]) widened from the floor volume `old` (inside the
    /// request's) to the request's: its cells lie in the old permissible set, so the difference
    /// `Omega_new(theta) \ Omega_old(theta)` of every orientation is added as new roots, split as a subtraction
    /// (\[A\] VI-A-3 with `Omega_old` as the convex set taken away): child `j` is `Omega_new` with `Omega_old`'s
    /// half-space `j` reversed and those before it kept (tagged as cuts, not as floor sides). Sides the two sets
    /// share give no child. O(orientations x sides) cells and QPs, in parallel (one boundedness check in all).
    fn widen<const D: usize>(
        &mut self,
        mut state: RunState<D>,
        old: Option<&FloorVolume>,
    ) -> Result<RunState<D>, PlacementError> {
        let Some(old) = old else {
            return Ok(state);
        };
        let t_roots = Instant::now();
        let fixed_z = state.fixed_z;
        let tol = self.tol;
        // every added cell lies in `Omega_new(theta)`, whose normals (the floor's sides, the floor and the ceiling)
        // are the same at every orientation: the first non-empty root's boundedness check answers for all of them,
        // as in `Search::start`, and the cells are built without their own (`2 D` LPs each)
        for o in self.orientations.iter().filter(|o| self.owns(o.index)) {
            if let Some(root) = self.root_cell::<D>(o, fixed_z)? {
                root.check_bounded()
                    .map_err(|e| PlacementError::FreeSpace { orientation: o.index, reason: e.to_string() })?;
                break;
            }
        }
        let added: Vec<Result<Vec<(Cell<D>, QpOptimum<D>)>, PlacementError>> = self
            .orientations
            .par_iter()
            .map(|o| {
                if !self.owns(o.index) {
                    return Ok(Vec::new());
                }
                let fs_err = |reason: String| PlacementError::FreeSpace { orientation: o.index, reason };
                let Some(new_hs) = self.omega::<D>(o, &self.request.floor, fixed_z) else {
                    return Ok(Vec::new());
                };
                let q = restrict_quadratic::<D>(&o.quadratic, fixed_z);
                let solve = |hs: Vec<Halfspace<D>>| -> Result<Option<(Cell<D>, QpOptimum<D>)>, PlacementError> {
                    let cell = Cell::new_unchecked_bounds(hs, tol).map_err(|e| fs_err(e.to_string()))?;
                    if cell.is_empty() {
                        return Ok(None);
                    }
                    Ok(minimise(&cell, &q).map_err(fs_err)?.map(|opt| (cell, opt)))
                };
                let Some(old_hs) = self.omega::<D>(o, old, fixed_z) else {
                    // nothing of this orientation was open before: its whole new set is a root
                    return Ok(solve(new_hs)?.into_iter().collect());
                };
                let mut out = Vec::new();
                for (j, h) in old_hs.iter().enumerate() {
                    if new_hs.iter().any(|g| g.normal == h.normal && g.offset == h.offset) {
                        continue;
                    }
                    let mut hs = new_hs.clone();
                    hs.extend(old_hs[..j].iter().map(|g| Halfspace::new(g.normal, g.offset, Tag::User(2 * j as u64))));
                    hs.push(h.flipped(Tag::User(2 * j as u64 + 1)));
                    out.extend(solve(hs)?);
                }
                Ok(out)
            })
            .collect();
        for (i, cells) in added.into_iter().enumerate() {
            for (cell, optimum) in cells? {
                self.stats.qp_solves += 1;
                self.stats.nodes_pushed += 1;
                state.heap.push(Node {
                    cost: optimum.value,
                    orientation: i,
                    id: state.next_id,
                    cell: Arc::new(cell),
                    optimum,
                    applied: Arc::from([]),
                });
                state.next_id += 1;
            }
        }
        self.stats.time_roots_ms += ms(t_roots);
        Ok(state)
    }

    fn root_cell<const D: usize>(&self, o: &Orientation, fixed_z: f64) -> Result<Option<Cell<D>>, PlacementError> {
        let fs_err = |e: stackplan_freespace::cell::CellError| PlacementError::FreeSpace {
            orientation: o.index,
            reason: e.to_string(),
        };
        let Some(hs) = self.omega::<D>(o, &self.request.floor, fixed_z) else {
            return Ok(None);
        };
        // bounded iff the first non-empty root is (the normals do not depend on the orientation): checked in `run`
        let cell = Cell::new_unchecked_bounds(hs, self.tol).map_err(fs_err)?;
        Ok((!cell.is_empty()).then_some(cell))
    }

    /// Whether orientation `i` belongs to this partition.
    fn owns(&self, i: usize) -> bool {
        lane_of(i, self.lanes) == self.lane
    }

    /// The roots of this partition's orientations (one QP per orientation, in parallel) and its state (an empty
    /// heap when Omega is empty at every one of them).
    fn start<const D: usize>(&mut self, fixed_z: f64) -> Result<RunState<D>, PlacementError> {
        let t_roots = Instant::now();
        // roots in parallel, collected in orientation order; Omega's normals are those of the floor's sides and
        // (3-D) of the floor and the ceiling at every orientation, only the offsets change, so the first non-empty
        // root's boundedness check (as `Cell::new` makes it) answers for all of them
        let cells: Vec<Result<Option<Cell<D>>, PlacementError>> = self
            .orientations
            .par_iter()
            .map(|o| if self.owns(o.index) { self.root_cell::<D>(o, fixed_z) } else { Ok(None) })
            .collect();
        let mut cells: Vec<Option<Cell<D>>> = cells.into_iter().collect::<Result<_, _>>()?;
        if let Some((i, cell)) = cells.iter().enumerate().find_map(|(i, c)| c.as_ref().map(|c| (i, c))) {
            cell.check_bounded().map_err(|e| PlacementError::FreeSpace { orientation: i, reason: e.to_string() })?;
        }
        let roots: Vec<Result<Option<(Cell<D>, QpOptimum<D>)>, PlacementError>> = self
            .orientations
            .par_iter()
            .zip(cells.par_iter_mut())
            .map(|(o, cell)| {
                let Some(cell) = cell.take() else {
                    return Ok(None);
                };
                let q = restrict_quadratic::<D>(&o.quadratic, fixed_z);
                let opt =
                    minimise(&cell, &q).map_err(|reason| PlacementError::FreeSpace { orientation: o.index, reason })?;
                Ok(opt.map(|opt| (cell, opt)))
            })
            .collect();
        let mut heap: NodeHeap<D> = NodeHeap::default();
        let mut next_id: u64 = 0;
        for (i, r) in roots.into_iter().enumerate() {
            match r? {
                Some((cell, optimum)) => {
                    self.stats.qp_solves += 1;
                    heap.push(Node {
                        cost: optimum.value,
                        orientation: i,
                        id: next_id,
                        cell: Arc::new(cell),
                        optimum,
                        applied: Arc::from([]),
                    });
                }
                None if self.owns(i) => self.stats.orientations_empty_omega += 1,
                None => {}
            }
            next_id += 1;
        }
        self.stats.nodes_pushed = heap.len() as u64;
        self.stats.time_roots_ms = ms(t_roots);
        Ok(RunState {
            fixed_z,
            heap,
            next_id,
            considered: vec![false; self.orientations.len()],
            found_points: Vec::new(),
            pops: 0,
            free_nodes: Vec::new(),
            buffers: Buffers::default(),
            found_keys: Vec::new(),
            ahead: VecDeque::new(),
        })
    }

    /// [`Search::advance`] for up to `want` placements of this partition, queued as its look-ahead (`state.ahead`),
    /// within a round: at most `max_pops` pops, stopping where the next key would pop after `bound`.
    fn step<const D: usize>(
        &mut self,
        state: &mut RunState<D>,
        want: usize,
        max_cost: f64,
        bound: Option<HeapKey>,
        max_pops: u64,
    ) -> Result<(), PlacementError> {
        let (found, _) = self.advance(state, want, max_cost, bound, max_pops)?;
        let keys = std::mem::take(&mut state.found_keys);
        state.ahead.extend(keys.iter().copied().zip(found));
        state.found_keys = keys;
        Ok(())
    }

    /// Continues the search from `state` until `want` more placements are found, the free space is exhausted or
    /// the cheapest open key exceeds `max_cost` (fewer returned; `true` for the last); the loop of the module
    /// documentation. Stopping after the `want`-th (or at the limit) and calling again continues exactly where one
    /// call with the sum of the `want`s would have been: the state is the whole loop's. A partition's round
    /// ("Partitions" in the module documentation) also stops after `max_pops` pops or where the next key would pop
    /// after `bound` (neither is a limit of the whole search).
    fn advance<const D: usize>(
        &mut self,
        state: &mut RunState<D>,
        want: usize,
        max_cost: f64,
        bound: Option<HeapKey>,
        max_pops: u64,
    ) -> Result<(Vec<Placement>, bool), PlacementError> {
        let RunState {
            fixed_z, heap, next_id, considered, found_points, pops, free_nodes, buffers, found_keys, ..
        } = state;
        found_keys.clear();
        let fixed_z = *fixed_z;
        let mut placements: Vec<Placement> = Vec::new();
        if want == 0 {
            return Ok((placements, false));
        }
        let clearance = self.request.clearance;
        let tol = self.tol.linear;
        let mut limited = false;
        let mut round_pops: u64 = 0;
        loop {
            // the keys are lower bounds of every cost still to come: past the limit, nothing within it is left
            if heap.peek_cost().is_some_and(|cost| cost > max_cost) {
                limited = true;
                break;
            }
            if round_pops >= max_pops || bound.is_some_and(|b| heap.peek_key().is_some_and(|top| pops_after(top, b))) {
                break;
            }
            round_pops += 1;
            let Some(popped) = heap.pop() else { break };
            *pops += 1;
            if *pops > self.request.node_budget as u64 {
                return Err(PlacementError::NodeBudget { budget: self.request.node_budget, found: found_points.len() });
            }
            if *pops % 1024 == 0 && self.request.deadline.is_some_and(|d| std::time::Instant::now() >= d) {
                return Err(PlacementError::TimeLimit { found: found_points.len() });
            }
            let node = match popped {
                Popped::Pending { family, id, face } => {
                    // build and solve the child now; push it back with its true cost (>= its key)
                    let t_cells = Instant::now();
                    // (the children that the box around the parent cell decides empty were never pushed, see the
                    // split below)
                    let f = &heap.families[family as usize];
                    let orientation = f.orientation;
                    let Some(parent) = f.cell.as_ref() else {
                        return Err(PlacementError::FreeSpace {
                            orientation,
                            reason: "a pending child's family has no cell (inconsistent heap)".into(),
                        });
                    };
                    self.child_inequalities::<D>(f.obstacle, face, fixed_z, f.cuts, &mut buffers.extra);
                    let solved = self.solve_child::<D>(orientation, parent, &buffers.extra, &f.start, fixed_z)?;
                    // the path is shared by the family's children: one more reference for a non-empty one
                    let applied = solved.as_ref().map(|_| Arc::clone(&f.applied));
                    if f.left == 0 {
                        // the last child: the family's cell is not needed any more
                        heap.families[family as usize].cell = None;
                    }
                    if let (Some((cell, optimum)), Some(applied)) = (solved, applied) {
                        heap.push(Node {
                            cost: optimum.value,
                            orientation,
                            id,
                            cell: Arc::new(cell),
                            optimum,
                            applied,
                        });
                    }
                    self.stats.time_cells_ms += ms(t_cells);
                    continue;
                }
                Popped::Solved(node) => node,
            };
            let optimum = &node.optimum;
            self.stats.nodes_expanded += 1;
            if !considered[node.orientation] {
                considered[node.orientation] = true;
                let t_setup = Instant::now();
                let o = &mut self.orientations[node.orientation];
                let key = o.rotation.to_cols_array().map(f64::to_bits);
                let part = self.request.part;
                let rotated = self.rotated.entry(key).or_insert_with(|| RotatedComponents {
                    components: rotated_components(part, o.rotation),
                    sweep: None,
                });
                o.set_components(Arc::clone(&rotated.components));
                if self.request.insertion {
                    let sweep = rotated.sweep.get_or_insert_with(|| Arc::new(SweepAxes::new(part, o.rotation, o)));
                    self.sweeps[node.orientation] = Some(Arc::clone(sweep));
                }
                // the obstacles earlier searches of the plan built at this orientation are known at once (their
                // stack parts have not moved), in a fixed order
                let mut shared = std::mem::take(&mut self.shared_pairs[node.orientation]);
                shared.sort_unstable();
                for (moving, fixed) in shared {
                    self.obstacle_id(node.orientation, moving, fixed)?;
                }
                if let Some(polygon) = &self.request.searched_elsewhere {
                    let region = DerivedObstacle::searched_elsewhere(&self.orientations[node.orientation], polygon);
                    self.elsewhere[node.orientation] = Some(self.obstacles.len() as u32);
                    self.obstacles.push(Arc::new(region));
                }
                self.stats.time_setup_ms += ms(t_setup);
            }
            let p = lift(&optimum.point, fixed_z);
            // an obstacle of this orientation built earlier that holds p* in its interior cuts at once (the deepest
            // holding one, as the detection's order prefers the deepest violation): the exact interference detection
            // below runs only when none does
            let elsewhere = self.elsewhere[node.orientation]
                .filter(|&id| !node.applied.contains(&id) && self.obstacles[id as usize].interior_contains(p, tol));
            let mut cutting: Option<u32> = elsewhere.or_else(|| {
                let mut best: Option<(f64, u32)> = None;
                let known = &self.by_orientation[node.orientation];
                for (k, &id) in known.ids.iter().enumerate() {
                    // the interior test exits at the first plane p* is outside of: cheaper than the path lookup
                    if let Some(depth) = known.interior_depth(k, p, tol)
                        && best.is_none_or(|(d, _)| depth > d)
                        && !node.applied.contains(&id)
                    {
                        best = Some((depth, id));
                    }
                }
                best.map(|(_, id)| id)
            });
            if cutting.is_some() {
                self.stats.known_obstacle_cuts += 1;
            } else {
                let t_det = Instant::now();
                let mut counts = DetectCounts::default();
                let mut queue = CandidateQueue::new(
                    &self.scene,
                    &self.orientations[node.orientation],
                    self.sweeps[node.orientation].as_deref(),
                    p,
                    clearance,
                    self.request.horizontal_clearance,
                    tol,
                    &mut self.detect_scratch,
                    &mut counts,
                );
                self.stats.interference_tests += 1;
                self.stats.narrow_phase_tests += counts.narrow_phase;
                self.stats.time_interference_ms += ms(t_det);
                // the first candidate (deepest first) whose obstacle holds p* in its interior; the queue finishes the
                // pairs' separating-axis scans only as far as this needs
                loop {
                    let t_det = Instant::now();
                    let next = queue.next(
                        &self.scene,
                        &self.orientations[node.orientation],
                        self.sweeps[node.orientation].as_deref(),
                    );
                    self.stats.time_interference_ms += ms(t_det);
                    let Some(c) = next else { break };
                    let id = self.obstacle_id(node.orientation, c.moving, c.fixed)?;
                    if node.applied.contains(&id) {
                        continue;
                    }
                    if self.obstacles[id as usize].interior_contains(p, tol) {
                        cutting = Some(id);
                        break;
                    }
                }
                queue.recycle(&mut self.detect_scratch);
            }
            let Some(id) = cutting else {
                // free: a placement, unless it repeats one already found (cells share boundaries)
                let dup = found_points
                    .iter()
                    .any(|(oi, q)| *oi == node.orientation && (*q - p).abs().max_element() <= 1e3 * tol);
                let found = (!dup).then(|| self.placement(&node.cell, optimum, node.orientation, p));
                let orientation = node.orientation;
                let key = HeapKey::new(node.cost, orientation, node.id, 0);
                free_nodes.push(node);
                if let Some(placement) = found {
                    found_keys.push(key);
                    found_points.push((orientation, p));
                    placements.push(placement);
                    if placements.len() >= want {
                        break;
                    }
                }
                continue;
            };
            let t_cells = Instant::now();
            self.split::<D>(node.orientation, id, fixed_z, &mut buffers.outside)?;
            // one allocation (an exact-size iterator collected into the shared slice)
            let applied: Arc<[u32]> = node.applied.iter().copied().chain(std::iter::once(id)).collect();
            let q = restrict_quadratic::<D>(&self.orientations[node.orientation].quadratic, fixed_z);
            // the box around the cell grown by the tolerance decides most empty children here, while the cell is at
            // hand: a child whose outside half-space misses the box is empty even with every offset grown by the
            // tolerance, as its phase 1 would find (`box_misses_halfspace`), and is never pushed (only when every
            // plane is finite: the phase 1 rejects the others with an error)
            let finite = buffers.outside.iter().all(|((n, d), _)| d.is_finite() && n.iter().all(|c| c.is_finite()));
            // (the children are built from the cell without the inequalities that box proves redundant)
            let (reach, pruned) = node.cell.grown_outer_box_pruned();
            let masked = self.obstacles[id as usize].planes.len() <= 128;
            let family_cuts =
                |kept: u128| if masked { InsideCuts::Kept(kept) } else { InsideCuts::Reach(finite.then_some(reach)) };
            let mut kept_faces = 0u128;
            let children = &mut buffers.children;
            children.clear();
            // the parent's box tightened by the inside cuts kept so far (in face order)
            let mut inside_box = reach;
            for &(outside, face) in &buffers.outside {
                if finite && box_misses_halfspace(&reach, &outside.0, outside.1, tol) {
                    // the id is still taken: the other children's ids, hence the search's order, are unchanged
                    self.stats.cells_empty += 1;
                    *next_id += 1;
                    continue;
                }
                // the box of the child: the parent's tightened by the inside cuts kept before this face and by its
                // outside half-space, each grown by the tolerance, so that it holds the child grown by the
                // tolerance (the set on which its phase 1 decides emptiness)
                let child_box = finite.then(|| {
                    let mut b = inside_box;
                    tighten_box(&mut b, &outside.0.map(|c| -c), tol - outside.1);
                    b
                });
                // this face's inside cut is kept by the later children (`InsideCuts`)
                if masked {
                    kept_faces |= 1 << face;
                }
                if finite {
                    tighten_box(&mut inside_box, &outside.0, outside.1 + tol);
                }
                if child_box.is_some_and(|b| box_is_empty(&b, tol)) {
                    // empty (the box propagation is a relaxation of the phase 1): never pushed, its id still taken
                    debug_assert!(
                        self.child_is_empty(&node, (id, face), fixed_z, family_cuts(kept_faces), reach),
                        "a child the box proves empty is not empty"
                    );
                    self.stats.cells_empty += 1;
                    *next_id += 1;
                    continue;
                }
                self.stats.nodes_pushed += 1;
                // key: a lower bound of the child's cost, the largest of the parent's cost, the cost's minimum over
                // the child's half-space outside the obstacle face (slack: twice the cell tolerance), the bound
                // from the parent's optimality conditions, which grows with the face's distance from p*
                // (`Quadratic::lower_bound_beyond`: the child lies in the parent's cell), and the cost's minimum over
                // the child's box (`Quadratic::box_lower_bound`)
                let bound = q
                    .halfspace_lower_bound(&outside.0, outside.1, 2.0 * tol)
                    .max(q.lower_bound_beyond(optimum, &outside.0, outside.1, 2.0 * tol, tol))
                    .max(child_box.map_or(f64::NEG_INFINITY, |b| q.box_lower_bound(&b.0, &b.1)));
                debug_assert!(
                    *next_id % 8 != 0
                        || self.child_cost_is_at_least(&node, (id, face), fixed_z, family_cuts(kept_faces), bound),
                    "a child's key is above its cost"
                );
                children.push((node.cost.max(bound), *next_id, face));
                *next_id += 1;
            }
            let family = Family {
                orientation: node.orientation,
                cell: Some(pruned.map_or_else(|| Arc::clone(&node.cell), Arc::new)),
                applied,
                obstacle: id,
                start: optimum.point,
                cuts: family_cuts(kept_faces),
                first: 0,
                left: 0,
            };
            heap.push_family(family, children);
            self.stats.time_cells_ms += ms(t_cells);
        }
        self.stats.orientations_considered = considered.iter().filter(|c| **c).count();
        Ok((placements, limited))
    }

    /// The id of the derived obstacle of a pair at an orientation, building it on first use: the pair's own, or the
    /// merged one that stands for it (`plates.rs`; the pair may also be a merged obstacle's key from the shared
    /// tables).
    fn obstacle_id(&mut self, orientation: usize, moving: usize, fixed: usize) -> Result<u32, PlacementError> {
        if let Some(id) = self.obstacle_ids.get(&(orientation, moving, fixed)) {
            return Ok(*id);
        }
        // a pair whose pieces merge into a plate takes the merged obstacle (`plates.rs`) under the merged key, and
        // the pair's own key becomes an alias of it (the rule depends only on the orientation and the stack, which
        // every search sharing these tables has in common)
        let merged = if self.moving_plate_of.is_empty() {
            None
        } else {
            crate::plates::merged_pair(
                self.request,
                &self.moving_plate_of,
                &self.scene,
                self.orientations[orientation].rotation,
                moving,
                fixed,
                self.tol.linear,
            )
        };
        let key = merged.map_or((moving, fixed), |m| m.key);
        if let Some(&id) = self.obstacle_ids.get(&(orientation, key.0, key.1)) {
            self.obstacle_ids.insert((orientation, moving, fixed), id);
            return Ok(id);
        }
        let t = Instant::now();
        if let Some(shared) = self.derived.get(&(orientation, key.0, key.1)) {
            let id = self.obstacles.len() as u32;
            self.obstacles.push(Arc::clone(shared));
            self.obstacle_ids.insert((orientation, key.0, key.1), id);
            self.obstacle_ids.insert((orientation, moving, fixed), id);
            self.by_orientation[orientation].push(id, shared);
            self.stats.pairs_evaluated += 1;
            self.stats.time_obstacles_ms += ms(t);
            return Ok(id);
        }
        if moving >= crate::plates::VIRTUAL || fixed >= crate::plates::VIRTUAL {
            // a merged obstacle's key names no pair: it is known from the shared tables or not at all
            return Err(PlacementError::FreeSpace {
                orientation,
                reason: format!("no merged obstacle under the key ({moving}, {fixed})"),
            });
        }
        let asked = (moving, fixed);
        let (moving, fixed) = merged.map_or((moving, fixed), |m| (m.moving, m.fixed));
        let o = &self.orientations[orientation];
        let sc = &self.scene.components[fixed];
        let to_error = |reason| PlacementError::Obstacle {
            moving_piece: moving,
            fixed_part: sc.part,
            fixed_piece: sc.piece,
            reason,
        };
        let raw = if let Some(pair) = &merged {
            crate::plates::merged_obstacle(self.request, &self.scene, self.cache, pair, o.rotation)
                .map_err(|e| to_error(format!("the merged plates' obstacle: {e}")))?
        } else if self.request.extrapolate {
            let rest_rotation = self.request.resting_rotations[o.rest];
            let (raw, route) = self
                .intervals
                .obstacle(self.request.part, moving, o.rest, rest_rotation, o.theta, o.rotation, fixed, sc, self.cache)
                .map_err(to_error)?;
            if route == ObstacleRoute::Extrapolated {
                self.stats.obstacles_extrapolated += 1;
            }
            raw
        } else {
            self.cache
                .get_or_build(moving, sc.part, sc.piece, &self.request.part.components[moving], o.rotation, &sc.world)
                .map_err(|e| to_error(e.to_string()))?
        };
        let mut built = DerivedObstacle::from_obstacle(
            &raw,
            o.index,
            moving,
            fixed,
            self.request.clearance,
            self.request.horizontal_clearance,
            self.request.insertion,
        );
        built.moving_plate = merged.and_then(|m| m.moving_plate);
        built.fixed_plate = merged.and_then(|m| m.fixed_plate);
        let built = Arc::new(built);
        self.derived.insert((orientation, key.0, key.1), Arc::clone(&built));
        let id = self.obstacles.len() as u32;
        self.by_orientation[orientation].push(id, &built);
        self.obstacles.push(built);
        self.obstacle_ids.insert((orientation, key.0, key.1), id);
        self.obstacle_ids.insert((orientation, asked.0, asked.1), id);

        self.stats.pairs_evaluated += 1;
        self.stats.time_obstacles_ms += ms(t);
        Ok(id)
    }

    /// The children of a cell cut by obstacle `id` (\[A\] VI-A-3): child `k` adds `n_k . p >= d_k` and `n_j . p <= d_j`
    /// for `j < k` ([`Search::child_inequalities`]); here only each child's outside half-space and face index. The
    /// children are built and solved lazily.
    fn split<const D: usize>(
        &mut self,
        orientation: usize,
        id: u32,
        fixed_z: f64,
        children: &mut Vec<Outside<D>>,
    ) -> Result<(), PlacementError> {
        let tol = self.tol.linear;
        let obstacle = &self.obstacles[id as usize];
        children.clear();
        for (k, plane) in obstacle.planes.iter().enumerate() {
            match restrict::<D>(plane.normal, plane.offset, fixed_z, tol) {
                Ok(outside) => children.push((outside, k as u32)),
                // a horizontal plane at fixed z: satisfied everywhere (no outside child, no cut needed) or nowhere
                // (the slice of the obstacle is empty: nothing to cut; cannot happen for an obstacle holding p*)
                Err(true) => {}
                Err(false) => {
                    return Err(PlacementError::FreeSpace {
                        orientation,
                        reason: format!(
                            "obstacle {id} holds the optimum but its slice at p_z = {fixed_z} is empty (inconsistent)"
                        ),
                    });
                }
            }
        }
        Ok(())
    }

    /// The extra inequalities of child `face` of obstacle `id`: the inside cuts `n_j . p <= d_j` of the faces before
    /// it that the family keeps ([`InsideCuts`]; restricted to the `D` variables; planes that do not depend on them
    /// are skipped, as in [`Search::split`]) and the outside `n_face . p >= d_face`, into `extra` (cleared first).
    /// The cuts left out are those the box around the parent cell proves redundant (it lies strictly inside them):
    /// the child is the same set. O(kept faces) with the mask, O(faces) with the box; the same values every time.
    fn child_inequalities<const D: usize>(
        &self,
        id: u32,
        face: u32,
        fixed_z: f64,
        cuts: InsideCuts<D>,
        extra: &mut Vec<Halfspace<D>>,
    ) {
        let tol = self.tol.linear;
        let planes = &self.obstacles[id as usize].planes;
        extra.clear();
        let mut inside_cut = |k: usize| {
            if let Ok((normal, offset)) = restrict::<D>(planes[k].normal, planes[k].offset, fixed_z, tol) {
                extra.push(Halfspace::new(
                    normal,
                    offset,
                    Tag::ObstacleCut { obstacle: u64::from(id), face: k as u32 },
                ));
            }
        };
        match cuts {
            InsideCuts::Kept(mask) => {
                // the faces before `face` whose inside cuts are kept, in increasing order
                let mut before = mask & ((1u128 << face) - 1);
                while before != 0 {
                    inside_cut(before.trailing_zeros() as usize);
                    before &= before - 1;
                }
            }
            InsideCuts::Reach(reach) => {
                for (k, plane) in planes.iter().enumerate().take(face as usize) {
                    if let Ok((normal, offset)) = restrict::<D>(plane.normal, plane.offset, fixed_z, tol)
                        && !reach.as_ref().is_some_and(|b| box_misses_halfspace(b, &normal, offset, tol))
                    {
                        inside_cut(k);
                    }
                }
            }
        }
        let plane = &planes[face as usize];
        if let Ok((normal, offset)) = restrict::<D>(plane.normal, plane.offset, fixed_z, tol) {
            let tag = Tag::ObstacleFace { obstacle: u64::from(id), face };
            extra.push(Halfspace::new(normal, offset, tag).flipped(tag));
        }
    }

    /// [`Search::child_inequalities`] into a new list (the debug checks below).
    fn child_list<const D: usize>(&self, id: u32, face: u32, fixed_z: f64, cuts: InsideCuts<D>) -> Vec<Halfspace<D>> {
        let mut extra = Vec::new();
        self.child_inequalities::<D>(id, face, fixed_z, cuts, &mut extra);
        extra
    }

    /// Debug check of a child that the box propagation drops at a split (`cuts`: the family's): the exact phase 1
    /// finds it empty, and its inside cuts are those that the box test per face keeps.
    fn child_is_empty<const D: usize>(
        &self,
        node: &Node<D>,
        (id, face): (u32, u32),
        fixed_z: f64,
        cuts: InsideCuts<D>,
        reach: ([f64; D], [f64; D]),
    ) -> bool {
        let extra = self.child_list(id, face, fixed_z, cuts);
        extra == self.child_list(id, face, fixed_z, InsideCuts::Reach(Some(reach)))
            && node.cell.is_empty_with(extra, &node.optimum.point).unwrap_or(false)
    }

    /// Debug check of a child's key (`cuts`: the family's): the child's cost, when it is not empty, is not below
    /// `bound`, up to the relative rounding that the heap's order ignores.
    fn child_cost_is_at_least<const D: usize>(
        &self,
        node: &Node<D>,
        (id, face): (u32, u32),
        fixed_z: f64,
        cuts: InsideCuts<D>,
        bound: f64,
    ) -> bool {
        let extra = self.child_list(id, face, fixed_z, cuts);
        let q = restrict_quadratic::<D>(&self.orientations[node.orientation].quadratic, fixed_z);
        match node.cell.with_halfspaces_from(&extra, &node.optimum.point) {
            Ok(Some(cell)) => match minimise(&cell, &q) {
                Ok(Some(opt)) => opt.value >= bound - 1e-12 * (bound.abs() + opt.value.abs()),
                _ => true,
            },
            _ => true,
        }
    }

    /// Builds a pending child's cell and solves its QP (`None` when empty).
    fn solve_child<const D: usize>(
        &mut self,
        orientation: usize,
        parent: &Cell<D>,
        extra: &[Halfspace<D>],
        start: &[f64; D],
        fixed_z: f64,
    ) -> Result<Option<(Cell<D>, QpOptimum<D>)>, PlacementError> {
        // the child from the parent's optimum (it satisfies the parent and the obstacle's inside cuts; only the
        // child's outside face is violated): emptiness by a phase 1 from it (most children are empty), and a
        // non-empty child's interior point by a second phase 1 on the exact cell instead of the Chebyshev LP
        // (`Cell::with_halfspaces_from`; a cell thinner than the tolerance still gets the Chebyshev build). The QP's
        // optimum equals a cold build's up to rounding in the last bits.
        let built = match parent.with_halfspaces_from(extra, start) {
            Ok(built) => built,
            // the cell's LPs (phase 1, Chebyshev centre) failed: skipped and counted as an unsolved QP (below)
            Err(e) => {
                self.stats.cells_unsolved += 1;
                tracing::warn!(orientation, reason = %e, "a free-space cell could not be built: skipped");
                return Ok(None);
            }
        };
        let Some(cell) = built else {
            self.stats.cells_empty += 1;
            return Ok(None);
        };
        if cell.is_empty() {
            self.stats.cells_empty += 1;
            return Ok(None);
        }
        self.stats.qp_solves += 1;
        let q = restrict_quadratic::<D>(&self.orientations[orientation].quadratic, fixed_z);
        match minimise(&cell, &q) {
            Ok(Some(opt)) => Ok(Some((cell, opt))),
            Ok(None) => {
                self.stats.cells_empty += 1;
                Ok(None)
            }
            // no solver could find the cell's optimum: the cell is skipped (no placement is ever taken from it, so
            // nothing returned interferes), and counted, since the search is then no longer exact
            Err(reason) => {
                self.stats.cells_unsolved += 1;
                tracing::warn!(orientation, %reason, "a free-space cell could not be solved: skipped");
                Ok(None)
            }
        }
    }

    fn placement<const D: usize>(
        &self,
        cell: &Cell<D>,
        optimum: &QpOptimum<D>,
        orientation: usize,
        p: DVec3,
    ) -> Placement {
        let o = &self.orientations[orientation];
        let mut contacts = Vec::new();
        for &j in &optimum.active {
            let contact = match cell.halfspaces()[j].tag {
                Tag::ObstacleFace { obstacle, face } => {
                    let ob = &self.obstacles[obstacle as usize];
                    // a face plane reaches past its face: p touches the obstacle only when it lies on it (the
                    // cells' tolerance; the clearance's growth is part of the planes)
                    if ob.is_searched_elsewhere() || !ob.closure_contains(p, self.tol.linear) {
                        continue;
                    }
                    let sc = &self.scene.components[ob.fixed];
                    // a face of C on the insertion obstacle's boundary below C is a side of the sweep
                    let face_kind = if ob.under_sweep(p, self.tol.linear) {
                        PlaneOrigin::InsertionSide.name()
                    } else {
                        ob.origins[face as usize].name()
                    };
                    if ob.moving_plate.is_some() || ob.fixed_plate.is_some() {
                        // a merged obstacle's face: the pieces of its sides that touch
                        let touching = crate::plates::touching_pieces(
                            self.request,
                            &self.scene,
                            &o.components,
                            ob.moving_plate,
                            ob.moving,
                            ob.fixed_plate,
                            ob.fixed,
                            p,
                            self.request.clearance,
                            self.tol.linear,
                        );
                        for (ours, theirs) in touching {
                            let contact = Contact::Stack {
                                our_component: ours,
                                stack_part: sc.part,
                                stack_component: self.scene.components[theirs].piece,
                                face_kind: face_kind.to_string(),
                            };
                            if !contacts.contains(&contact) {
                                contacts.push(contact);
                            }
                        }
                        continue;
                    }
                    Contact::Stack {
                        our_component: ob.moving,
                        stack_part: sc.part,
                        stack_component: sc.piece,
                        face_kind: face_kind.to_string(),
                    }
                }
                Tag::Floor => Contact::Floor,
                Tag::Ceiling => Contact::Ceiling,
                // a side of the request's floor (a state carried from a smaller floor keeps that floor's sides as
                // bounds of its old cells, which are not walls of this one)
                Tag::FloorSide { side } => {
                    let h = &cell.halfspaces()[j];
                    let wall = self.request.floor.side_planes().get(side as usize).is_some_and(|&(n, d)| {
                        let parallel = (h.normal[0] - n.x).abs() <= 1e-12 && (h.normal[1] - n.y).abs() <= 1e-12;
                        let gap = n.x * p.x + n.y * p.y + o.support(DVec3::new(n.x, n.y, 0.0)) - d;
                        parallel && gap.abs() <= self.tol.linear
                    });
                    if !wall {
                        continue;
                    }
                    Contact::FloorSide { side }
                }
                Tag::ObstacleCut { .. } | Tag::User(_) => continue,
            };
            if !contacts.contains(&contact) {
                contacts.push(contact);
            }
        }
        if D == 2 && (p.z + o.lo.z).abs() <= self.tol.linear {
            contacts.push(Contact::Floor);
        }
        Placement {
            position: p.to_array(),
            rotation: o.rotation.transpose().to_cols_array_2d(),
            theta: o.theta,
            theta_deg: o.theta.to_degrees(),
            resting_pose: o.rest,
            cost: o.quadratic.value(p),
            contacts,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Footprints clipped from an octagonal floor and grown (stage 1 of a plan on a floor that is no rectangle):
    /// each continues the last one's frontier. With an exact test about a third of them would not (their corners on
    /// the floor's slanted sides are interpolated), and those stage-1 searches would start from the roots: the
    /// 15-part Complex plan at `w 0.1` on such a floor (circumradius 560 mm) takes 1.51 s that way instead of 1.11 s,
    /// the same plan. A polygon larger by 1e-7 mm is not inside.
    #[test]
    fn grown_footprints_on_a_slanted_floor_continue_the_last_ones_frontier() {
        let octagon: Vec<glam::DVec2> = (0..8)
            .map(|k| {
                let a = std::f64::consts::FRAC_PI_4 * k as f64 + 0.3;
                glam::DVec2::new(560.0 * a.cos(), 560.0 * a.sin())
            })
            .collect();
        let signature = |polygon: Vec<glam::DVec2>| FrontierSignature {
            floor: FloorVolume { polygon, height: 1212.0 },
            searched_elsewhere: None,
            fixed_z: None,
            cost: "stacking".into(),
        };
        let mut rng = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut lo, mut hi) = (glam::DVec2::new(-120.3, -97.1), glam::DVec2::new(101.7, 133.9));
        let mut last = signature(crate::stack_plan::clip_to_rectangle(&octagon, lo, hi));
        for step in 0..200 {
            lo -= glam::DVec2::new(next(), next()) * 3.7;
            hi += glam::DVec2::new(next(), next()) * 3.7;
            let grown = signature(crate::stack_plan::clip_to_rectangle(&octagon, lo, hi));
            assert!(last.continues_into(&grown), "step {step}: {:?} into {:?}", last.floor, grown.floor);
            assert!(!grown.continues_into(&last) || grown.floor.polygon == last.floor.polygon, "step {step}");
            last = grown;
        }
        // the whole floor contains every footprint; a footprint 1e-7 mm beyond it is no longer inside
        assert!(last.continues_into(&signature(octagon.clone())));
        let beyond = signature(octagon.iter().map(|c| *c * (1.0 + 1e-7 / 560.0)).collect());
        assert!(!beyond.continues_into(&signature(octagon)));
    }

    /// The rounded key: last-bit neighbours compare equal, it is monotone, and it stays within `2^-40` relative.
    #[test]
    fn quantised_cost_merges_last_bit_ties_monotonically() {
        let exact = 8560.25_f64;
        let below = f64::from_bits(exact.to_bits() - 3);
        let above = f64::from_bits(exact.to_bits() + 5);
        assert_eq!(quantised_cost(below), quantised_cost(exact));
        assert_eq!(quantised_cost(above), quantised_cost(exact));
        assert!(quantised_cost(8560.25 * (1.0 + 1e-10)) > quantised_cost(exact));
        assert_eq!(quantised_cost(0.0), 0.0);
        assert_eq!(quantised_cost(f64::INFINITY), f64::INFINITY);
        let mut values: Vec<f64> = (0..2000).map(|i| 1e-3 * 1.37_f64.powi(i % 97) * (1.0 + i as f64 * 1e-14)).collect();
        values.extend([-2.5, -2.5000000000000004, 1.0, 0.9999999999999999, 2.0, 1.9999999999999998]);
        values.sort_by(f64::total_cmp);
        for w in values.windows(2) {
            assert!(quantised_cost(w[0]) <= quantised_cost(w[1]), "not monotone at {w:?}");
        }
        for v in values {
            let q = quantised_cost(v);
            assert!((q - v).abs() <= v.abs() * 2f64.powi(-40), "{v} -> {q}");
        }
    }

    /// The integer-encoded heap key orders as (rounded cost by `total_cmp`, orientation, id) reversed (the max-heap
    /// pops the cheapest), and gives the rounded cost back.
    #[test]
    fn heap_key_orders_as_cost_orientation_id() {
        let costs = [
            f64::NEG_INFINITY,
            -1e300,
            -2.5,
            -0.0,
            0.0,
            1e-300,
            0.75,
            1.0,
            1.0000000000000002,
            8560.25,
            8560.25 * (1.0 + 1e-9),
            1e300,
            f64::INFINITY,
        ];
        let mut keys = Vec::new();
        for (a, &cost) in costs.iter().enumerate() {
            for orientation in [0usize, 1, 359, (1 << 24) - 1] {
                for id in [0u64, 1, 77, (1 << 40) - 1] {
                    keys.push(((cost, orientation, id), HeapKey::new(cost, orientation, id, a as u32)));
                }
            }
        }
        for (x, kx) in &keys {
            assert_eq!(kx.cost().to_bits(), quantised_cost(x.0).to_bits(), "{x:?}");
            for (y, ky) in &keys {
                let expected =
                    quantised_cost(y.0).total_cmp(&quantised_cost(x.0)).then(y.1.cmp(&x.1)).then(y.2.cmp(&x.2));
                assert_eq!((kx.rank_cost, kx.rank_tie).cmp(&(ky.rank_cost, ky.rank_tie)), expected, "{x:?} vs {y:?}");
            }
        }
    }
}
