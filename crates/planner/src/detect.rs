//! Interference pairs of the new part at a configuration (\[A\] eq. 8, section 5.1.3): a broad phase on axis-aligned
//! boxes and the exact separating-axis narrow phase of `stackplan-cspace` on the complete axis set
//! (`classify_pair_all_axes`, and for pairs closer than the clearance their distance by closest features of the exact
//! hulls, `stackplan_cspace::distance`, reached as `interference::gjk_distance`).
//!
//! * Without clearance a pair is reported only when it *penetrates* by more than the tolerance; touching is free.
//! * With clearance `delta > 0`, a pair closer than `delta` is reported (touching included).
//! * With insertion, each moving component is replaced by its sweep upwards, the hull of the component and its copy
//!   lifted above the stack: the vertical path from above is blocked iff some sweep overlaps a stack component. The
//!   sweep's separating axes are the component's face normals, the horizontal normals `e x z` of its edges and the
//!   edge directions plus `z` (a superset of the sweep's face normals and edge directions, so the test stays exact).
//!
//! The broad phase is a linear scan in two levels: the stack components whose boxes meet the whole part's box, then
//! per moving component those whose boxes meet its own (O(m_stack + m_part m_near) box tests, a few nanoseconds
//! each; the stacks of \[A\] have at most a few hundred components); a moving component is translated (or swept)
//! only when a pair of it is scanned. Candidates are returned in a deterministic order: by violation (deepest first),
//! then by (moving component, stack component); pairs are scanned lazily, in the order of an upper bound of their
//! violation from their boxes ([`CandidateQueue`]), so the search's first cut leaves most of them unscanned.

use crate::orientation::Orientation;
use glam::{DMat3, DVec3};
use stackplan_cspace::PlacedConvex;
use stackplan_cspace::interference::{PairContact, gjk_distance, project};
use stackplan_geom::polytope::ConvexPolytope;
use stackplan_geom::{Part, Pose};
use std::collections::BinaryHeap;
use std::sync::Arc;

/// A component of a stack part, placed in the world.
#[derive(Debug, Clone)]
pub struct StackComponent {
    /// Stack part index.
    pub part: usize,
    /// Component index in that part.
    pub piece: usize,
    /// The component in world coordinates.
    pub world: ConvexPolytope,
    /// The component turned by its part's rotation but not moved (`R v`): the geometry up to translation, which is
    /// all a pair's orientation events depend on (`interval_obstacles.rs` shares them between copies).
    pub turned: Arc<ConvexPolytope>,
    /// Prepared for the separating-axis test.
    pub placed: PlacedConvex,
}

/// The stationary stack, prepared once (and grown part by part, [`StackScene::push_part`]).
#[derive(Debug, Clone)]
pub struct StackScene {
    /// Every component of every stack part, in (part, piece) order.
    pub components: Vec<StackComponent>,
    /// Highest z of the stack (or 0 for an empty stack).
    pub top: f64,
    /// Number of stack parts.
    parts: usize,
    /// The components' boxes (`placed.aabb`) in one compact list, for the broad phase.
    boxes: Vec<(DVec3, DVec3)>,
    /// Per stack part: the index of its first component in [`StackScene::components`].
    pub part_first: Vec<usize>,
    /// Per component: the plate of its part it belongs to ([`stackplan_geom::Part::plates`]), if any.
    pub plate_of: Vec<Option<u32>>,
    /// Per stack part, per plate: the filled plate in world coordinates.
    pub plates_world: Vec<Vec<ConvexPolytope>>,
    /// Per stack part: the number of plates of the parts before it (a plate's index in the whole stack).
    pub plate_first: Vec<usize>,
}

impl StackScene {
    /// Places every component. O(total size).
    pub fn new(parts: &[(&Part, Pose)]) -> Self {
        let mut scene = Self {
            components: Vec::new(),
            top: 0.0,
            parts: 0,
            boxes: Vec::new(),
            part_first: Vec::new(),
            plate_of: Vec::new(),
            plates_world: Vec::new(),
            plate_first: Vec::new(),
        };
        for &(part, pose) in parts {
            scene.push_part(part, pose);
        }
        scene
    }

    /// Places one more stack part's components (stack part index [`StackScene::parts`] before the call): the scene
    /// of the longer list, as [`StackScene::new`] builds it. O(size of the part).
    pub fn push_part(&mut self, part: &Part, pose: Pose) {
        self.part_first.push(self.components.len());
        self.plate_first.push(self.plates_world.iter().map(Vec::len).sum());
        self.plate_of.extend(part.plate_of_components());
        self.plates_world
            .push(part.plates().iter().map(|p| p.filled.transformed(pose.rotation, pose.position)).collect());
        for (ci, c) in part.components().iter().enumerate() {
            let world = c.transformed(pose.rotation, pose.position);
            let turned = Arc::new(c.transformed(pose.rotation, DVec3::ZERO));
            let placed = PlacedConvex::new(c, pose.rotation, pose.position);
            self.top = self.top.max(placed.aabb.1.z);
            self.boxes.push(placed.aabb);
            self.components.push(StackComponent { part: self.parts, piece: ci, world, turned, placed });
        }
        self.parts += 1;
    }

    /// Number of stack parts placed.
    pub fn parts(&self) -> usize {
        self.parts
    }
}

/// A reported pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// Moving component.
    pub moving: usize,
    /// Stack component (index into [`StackScene::components`]).
    pub fixed: usize,
    /// How much the pair violates (penetration depth plus clearance, or clearance minus gap), > 0.
    pub violation: f64,
}

/// Sweep axes of the rotated components (they do not depend on the position).
#[derive(Debug, Clone)]
pub struct SweepAxes {
    /// Per component: (normal axes, edge directions).
    pub axes: Vec<(Vec<DVec3>, Vec<DVec3>)>,
}

fn push_unique(set: &mut Vec<DVec3>, d: DVec3) {
    let len = d.length();
    if len.is_nan() || len <= 1e-12 {
        return;
    }
    let d = d / len;
    if !set.iter().any(|s| s.cross(d).length_squared() <= 1e-24) {
        set.push(d);
    }
}

impl SweepAxes {
    /// The axes of each rotated component's upward sweep.
    pub fn new(part: &Part, rotation: DMat3, orientation: &Orientation) -> Self {
        let axes = part
            .components()
            .iter()
            .zip(orientation.components.iter())
            .map(|(c, placed)| {
                let mut normals = placed.normal_axes.clone();
                let mut edges = placed.edge_directions.clone();
                for e in c.edges() {
                    let d = rotation * (c.vertices()[e.vertices[1]] - c.vertices()[e.vertices[0]]);
                    push_unique(&mut normals, d.cross(DVec3::Z));
                }
                push_unique(&mut edges, DVec3::Z);
                (normals, edges)
            })
            .collect();
        Self { axes }
    }
}

/// `placed` moved by `p` ([`PlacedConvex::translated`]).
pub fn translated(placed: &PlacedConvex, p: DVec3) -> PlacedConvex {
    placed.translated(p)
}

/// `placed` moved by `p` and swept up to `top` (see the module documentation).
fn swept(placed: &PlacedConvex, axes: &(Vec<DVec3>, Vec<DVec3>), p: DVec3, top: f64) -> PlacedConvex {
    let lift = Some(sweep_lift(top, placed, p));
    let mut vertices = Vec::with_capacity(2 * placed.vertices.len());
    moved_vertices(placed, p, lift, &mut vertices);
    PlacedConvex::from_parts(vertices, axes.0.clone(), axes.1.clone(), moved_box(placed, p, lift))
}

/// How far a sweep reaches above its component at `p`: to the stack's top `top`, and 1 mm more.
fn sweep_lift(top: f64, placed: &PlacedConvex, p: DVec3) -> f64 {
    (top - (placed.aabb.0.z + p.z)).max(0.0) + 1.0
}

/// The vertices of `placed` moved by `p` into `out`, and with a `lift`, each of them lifted by it after them (the
/// sweep): the sums of [`translated`] and [`swept`] everywhere, so every projection is bit for bit theirs.
fn moved_vertices(placed: &PlacedConvex, p: DVec3, lift: Option<f64>, out: &mut Vec<DVec3>) {
    out.extend(placed.vertices.iter().map(|v| *v + p));
    if let Some(lift) = lift {
        let n = out.len();
        for k in 0..n {
            out.push(out[k] + DVec3::new(0.0, 0.0, lift));
        }
    }
}

/// The box of [`moved_vertices`].
fn moved_box(placed: &PlacedConvex, p: DVec3, lift: Option<f64>) -> (DVec3, DVec3) {
    match lift {
        Some(lift) => (placed.aabb.0 + p, placed.aabb.1 + p + DVec3::new(0.0, 0.0, lift)),
        None => (placed.aabb.0 + p, placed.aabb.1 + p),
    }
}

fn boxes_overlap(a: &(DVec3, DVec3), b: &(DVec3, DVec3), margin: f64) -> bool {
    a.0.x <= b.1.x + margin
        && b.0.x <= a.1.x + margin
        && a.0.y <= b.1.y + margin
        && b.0.y <= a.1.y + margin
        && a.0.z <= b.1.z + margin
        && b.0.z <= a.1.z + margin
}

/// Counters of one detection.
#[derive(Debug, Clone, Copy, Default)]
pub struct DetectCounts {
    /// Pairs past the broad phase (each scanned by the exact narrow phase only as far as the search needs).
    pub narrow_phase: u64,
}

/// A moving component at the queue's position: its vertices (moved, or swept) and, computed on first use, its
/// projection onto each of its own normal axes, which every pair of the component needs on the same axes (the same
/// values as projecting again: computed once per detection instead of once per pair).
#[derive(Debug, Clone, Default)]
struct MovedComponent {
    vertices: Vec<DVec3>,
    /// Per normal axis of the component (or of its sweep): the projection `[lo, hi]`, NaN until computed.
    own: Vec<(f64, f64)>,
}

impl MovedComponent {
    /// The projection onto the component's own normal axis `k` (`u`).
    #[inline]
    fn own(&mut self, k: usize, u: DVec3) -> (f64, f64) {
        let e = self.own[k];
        if e.0.is_nan() {
            let e = project(&self.vertices, u);
            self.own[k] = e;
            return e;
        }
        e
    }
}

/// The stopping rule of a scan: the per-axis value is `gap - weight |u_xy|`; a running maximum past `stop` decides
/// the pair as not violating.
#[derive(Debug, Clone, Copy)]
struct Rule {
    weight: f64,
    stop: f64,
    inclusive: bool,
}

impl Rule {
    #[inline]
    fn decided(&self, best: f64) -> bool {
        if self.inclusive { best >= self.stop } else { best > self.stop }
    }
}

/// The separating-axis scan of a pair, on the fly (no allocation): the normal axes (`normals = true`: the moving
/// component's, then the stack component's) or the unit cross products of their edge directions longer than `1e-9`,
/// in the order and with the arithmetic of `stackplan_cspace::interference::sat_gap` and [`horizontal_slack`], so
/// every per-axis value is bit-identical to theirs.
fn scan_direct(
    moving_normals: &[DVec3],
    moving_edges: &[DVec3],
    fixed: &PlacedConvex,
    moving: &mut MovedComponent,
    rule: &Rule,
    normals: bool,
    best: &mut f64,
) -> bool {
    // the stack component's projection onto its own normals is its `normal_extents`, the moving component's onto
    // its own normals is computed once per detection (the same values)
    let mut test = |u: DVec3, (a_lo, a_hi): (f64, f64), (b_lo, b_hi): (f64, f64)| {
        let gap = (b_lo - a_hi).max(a_lo - b_hi);
        let value = if rule.weight == 0.0 { gap } else { gap - rule.weight * (1.0 - u.z * u.z).max(0.0).sqrt() };
        *best = best.max(value);
        rule.decided(*best)
    };
    if normals {
        for (k, &u) in moving_normals.iter().enumerate() {
            if test(u, moving.own(k, u), project(&fixed.vertices, u)) {
                return true;
            }
        }
        for (&u, &extent) in fixed.normal_axes.iter().zip(&fixed.normal_extents) {
            if test(u, project(&moving.vertices, u), extent) {
                return true;
            }
        }
        return false;
    }
    for &da in moving_edges {
        for &db in &fixed.edge_directions {
            let c = da.cross(db);
            let len2 = c.length_squared();
            if len2 > 1e-18 {
                let u = c / len2.sqrt();
                if test(u, project(&moving.vertices, u), project(&fixed.vertices, u)) {
                    return true;
                }
            }
        }
    }
    false
}

/// The lists of a finished [`CandidateQueue`] ([`CandidateQueue::recycle`]), emptied, for the next one: no allocation
/// per detection once warm.
///
/// The scratch keeps no per-pair separating axes: the pairs are tested a few times each, so building and keeping
/// the axes costs more than deriving them on the fly (the Channel search runs 5.6 % and the Triangle one 9 % more
/// instructions with such a cache, and a 15-part Complex plan holds 376 MB of it).
#[derive(Debug, Clone, Default)]
pub struct DetectScratch {
    spare: QueueLists,
}

/// The lists of a [`CandidateQueue`], kept between detections.
#[derive(Debug, Clone, Default)]
struct QueueLists {
    moved: Vec<MovedComponent>,
    near: Vec<usize>,
    /// The boxes of `near`, in its order (the inner loop of the broad phase reads one compact list).
    near_boxes: Vec<(DVec3, DVec3)>,
    open: Vec<OpenPair>,
    exact: Vec<Candidate>,
}

/// A pair that passed the boxes and is not scanned yet, with an upper bound of its violation
/// ([`CandidateQueue::bound`] of its [`box_bound`]), the heap's key.
#[derive(Debug, Clone, Copy)]
struct OpenPair {
    moving: usize,
    fixed: usize,
    bound: f64,
    /// [`OpenPair::order`] of the pair, compared as one integer.
    rank: u128,
}

impl OpenPair {
    fn new(moving: usize, fixed: usize, bound: f64) -> Self {
        Self { moving, fixed, bound, rank: Self::order(bound, moving, fixed) }
    }

    fn key(&self) -> (f64, usize, usize) {
        (self.bound, self.moving, self.fixed)
    }

    /// [`precedes`]'s order as an integer, greater first: the bound's bits mapped to `f64::total_cmp`'s order, then
    /// the complements of the moving and the stack component (a lower index precedes). Indices beyond `u32` (not
    /// met: a scene that large does not fit in memory) would share their tie-break.
    fn order(bound: f64, moving: usize, fixed: usize) -> u128 {
        let mut bits = bound.to_bits() as i64;
        bits ^= (((bits >> 63) as u64) >> 1) as i64;
        let ordered = (bits as u64) ^ (1u64 << 63);
        let index = |i: usize| u128::from(!u32::try_from(i).unwrap_or(u32::MAX));
        (u128::from(ordered) << 64) | (index(moving) << 32) | index(fixed)
    }
}

/// The queue's order: the greatest open pair is the one whose bound precedes every other's ([`precedes`]).
impl Ord for OpenPair {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.rank.cmp(&other.rank)
    }
}

impl PartialOrd for OpenPair {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl PartialEq for OpenPair {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == std::cmp::Ordering::Equal
    }
}

impl Eq for OpenPair {}

/// A value at most the largest per-axis value of the complete scan of a pair whose boxes are `a` and `b` (so that
/// [`CandidateQueue::bound`] of it bounds the pair's violation from above), from the boxes alone.
///
/// On the complete axis set the largest gap of a polytope pair is `-MTD` when they overlap (the minimum translation
/// distance is attained on one of the axes) and positive otherwise; `MTD` is at most the distance that pushes the
/// projections apart on any direction, `min(a_hi - b_lo, b_hi - a_lo)`, and on `x`, `y` and `z` those projections are
/// the boxes (the boxes are the vertices' extents, moved by the same sums as the vertices). So the largest gap is at least `-max(min overlap, 0)`; the horizontal
/// rule subtracts at most `weight` per axis (`sqrt(1 - u_z^2) <= 1`). `slack` covers the projections' rounding.
fn box_bound(a: &(DVec3, DVec3), b: &(DVec3, DVec3), weight: f64, slack: f64) -> f64 {
    // the distance to push the projections apart along each axis (not their intersection: one may contain the other)
    let overlap = (a.1 - b.0).min(b.1 - a.0).min_element();
    -overlap.max(0.0) - weight - slack
}

/// The violating pairs of an orientation at `p`, produced lazily in the order of [`candidates`] (largest violation
/// first, then moving, then stack component).
///
/// Every pair that passes the boxes stays *open*, not scanned, with an upper bound of its violation from the boxes
/// alone (`box_bound`; the distance that `classify_pair` takes from the closest features is at least the
/// separating-axis gap, and the bound keeps a margin that once covered parry's GJK error). [`CandidateQueue::next`] returns a pair only when its exact
/// violation is at least every open bound (ties by the same index order), scanning open pairs (normal axes, then
/// cross axes) in the order of their bounds: the sequence is the one of sorting the exact violations, but the pairs
/// whose bounds lie below the violation the search cuts with are never scanned.
#[derive(Debug)]
pub struct CandidateQueue {
    p: DVec3,
    clearance: f64,
    horizontal: bool,
    tol: f64,
    rule: Rule,
    moved: Vec<MovedComponent>,
    /// The open pairs, a max-heap in the order of their bounds (each bound is fixed until the pair is scanned).
    open: BinaryHeap<OpenPair>,
    exact: Vec<Candidate>,
}

/// `a` comes before `b` in the candidates' order.
fn precedes(a: (f64, usize, usize), b: (f64, usize, usize)) -> bool {
    b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)) == std::cmp::Ordering::Less
}

impl CandidateQueue {
    /// Broad phase and each pair's bound from the boxes (see the type's documentation). The queue's lists come from
    /// `scratch` ([`CandidateQueue::recycle`] gives them back).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        scene: &StackScene,
        orientation: &Orientation,
        sweep: Option<&SweepAxes>,
        p: DVec3,
        clearance: f64,
        horizontal_clearance: bool,
        tol: f64,
        scratch: &mut DetectScratch,
        counts: &mut DetectCounts,
    ) -> Self {
        let horizontal = horizontal_clearance && clearance > 0.0;
        let rule = if horizontal {
            Rule { weight: clearance, stop: -tol, inclusive: true }
        } else {
            Rule { weight: 0.0, stop: tol.max(clearance), inclusive: false }
        };
        let QueueLists { mut moved, mut near, mut near_boxes, open: mut pending, exact } =
            std::mem::take(&mut scratch.spare);
        pending.clear();
        for m in &mut moved {
            m.vertices.clear();
            m.own.clear();
        }
        moved.resize_with(orientation.components.len(), MovedComponent::default);
        let mut queue = Self { p, clearance, horizontal, tol, rule, moved, open: BinaryHeap::new(), exact };
        queue.exact.clear();
        let margin = clearance + tol;
        // broad phase in two levels: the stack components near the whole part's box (a superset of each
        // component's, the sweep reaching up without bound), then each component's box
        let part_box = match sweep {
            Some(_) => (orientation.lo + p, DVec3::new(orientation.hi.x + p.x, orientation.hi.y + p.y, f64::INFINITY)),
            None => (orientation.lo + p, orientation.hi + p),
        };
        near.clear();
        near.extend(
            scene.boxes.iter().enumerate().filter(|(_, b)| boxes_overlap(&part_box, b, margin)).map(|(i, _)| i),
        );
        // by the boxes' lowest x, so that each moving component's loop stops at the first box beyond its own in x
        near.sort_unstable_by(|&a, &b| scene.boxes[a].0.x.total_cmp(&scene.boxes[b].0.x));
        near_boxes.clear();
        near_boxes.extend(near.iter().map(|&i| scene.boxes[i]));
        for (mi, placed) in orientation.components.iter().enumerate() {
            if near.is_empty() {
                break;
            }
            let moved_box = moved_box(placed, p, sweep.map(|_| sweep_lift(scene.top, placed, p)));
            let reach = near_boxes.partition_point(|b| b.0.x <= moved_box.1.x + margin);
            for (&fi, fixed_box) in near[..reach].iter().zip(&near_boxes[..reach]) {
                if !boxes_overlap(&moved_box, fixed_box, margin) {
                    continue;
                }
                counts.narrow_phase += 1;
                // (not scanned yet: the boxes bound its violation; `next` scans it when that bound matters)
                let bound = queue.bound(box_bound(&moved_box, fixed_box, rule.weight, tol));
                pending.push(OpenPair::new(mi, fi, bound));
            }
        }
        scratch.spare.near = near;
        scratch.spare.near_boxes = near_boxes;
        // (heapified in O(n): most detections take only the first few pairs)
        queue.open = BinaryHeap::from(pending);
        queue
    }

    /// Gives the queue's lists back to `scratch` for the next detection (optional: a queue simply dropped costs only
    /// the allocations of the next one).
    pub fn recycle(self, scratch: &mut DetectScratch) {
        let near = std::mem::take(&mut scratch.spare.near);
        let near_boxes = std::mem::take(&mut scratch.spare.near_boxes);
        scratch.spare =
            QueueLists { moved: self.moved, near, near_boxes, open: self.open.into_vec(), exact: self.exact };
    }

    /// Upper bound of a pair's violation from a lower bound `best` of its scan's largest value, plus (with a
    /// clearance, where `classify_pair` replaces the gap by the pair's distance) a margin of `1e-3 clearance + tol`.
    /// The distance is exact up to rounding (`stackplan_cspace::distance`) and never below the gap, so the margin
    /// only loosens the bound (a few more pairs scanned), never the order of the candidates.
    fn bound(&self, best: f64) -> f64 {
        if self.horizontal {
            -best
        } else if self.clearance > self.tol {
            self.clearance - best + 1e-3 * self.clearance + self.tol
        } else {
            self.clearance - best
        }
    }

    /// The next violating pair (see the type's documentation), `None` when there is none left.
    pub fn next(
        &mut self,
        scene: &StackScene,
        orientation: &Orientation,
        sweep: Option<&SweepAxes>,
    ) -> Option<Candidate> {
        loop {
            let best_exact = (0..self.exact.len()).reduce(|a, b| {
                let (x, y) = (&self.exact[a], &self.exact[b]);
                if precedes((y.violation, y.moving, y.fixed), (x.violation, x.moving, x.fixed)) { b } else { a }
            });
            match (best_exact, self.open.peek()) {
                (None, None) => return None,
                (Some(e), None) => return Some(self.exact.swap_remove(e)),
                (None, Some(_)) => {}
                (Some(e), Some(y)) => {
                    let x = &self.exact[e];
                    if !precedes(y.key(), (x.violation, x.moving, x.fixed)) {
                        return Some(self.exact.swap_remove(e));
                    }
                }
            }
            let open = self.open.pop()?;
            if let Some(c) = self.finish(open, scene, orientation, sweep) {
                self.exact.push(c);
            }
        }
    }

    /// Scans an open pair's remaining axes and classifies it as `classify_pair` / [`horizontal_slack`] would.
    fn finish(
        &mut self,
        open: OpenPair,
        scene: &StackScene,
        orientation: &Orientation,
        sweep: Option<&SweepAxes>,
    ) -> Option<Candidate> {
        let (mi, fi) = (open.moving, open.fixed);
        let placed = &orientation.components[mi];
        let fixed = &scene.components[fi];
        let moving = &mut self.moved[mi];
        let (normals, edges) = match sweep {
            Some(s) => (&s.axes[mi].0, &s.axes[mi].1),
            None => (&placed.normal_axes, &placed.edge_directions),
        };
        if moving.vertices.is_empty() {
            let lift = sweep.map(|_| sweep_lift(scene.top, placed, self.p));
            moved_vertices(placed, self.p, lift, &mut moving.vertices);
            moving.own.clear();
            moving.own.resize(normals.len(), (f64::NAN, f64::NAN));
        }
        // the normal axes (a pair they decide is not violating), then the cross axes, as one running maximum
        let mut best = f64::NEG_INFINITY;
        if scan_direct(normals, edges, &fixed.placed, moving, &self.rule, true, &mut best) {
            return None;
        }
        let decided = scan_direct(normals, edges, &fixed.placed, moving, &self.rule, false, &mut best);
        let tol = self.tol;
        let clearance = self.clearance;
        if self.horizontal {
            let slack = best;
            return (!decided && slack < -tol).then_some(Candidate { moving: mi, fixed: fi, violation: -slack });
        }
        // `classify_pair`'s decisions on the same gap
        let gap = best;
        let contact = if gap < -tol {
            PairContact::Penetrating { depth: -gap }
        } else if gap <= tol {
            PairContact::Touching { gap }
        } else if clearance > tol && gap < clearance {
            let moved = match sweep {
                Some(s) => swept(placed, &s.axes[mi], self.p, scene.top),
                None => translated(placed, self.p),
            };
            PairContact::Separated { gap: gjk_distance(&moved, &fixed.placed).unwrap_or(gap) }
        } else {
            PairContact::Separated { gap }
        };
        let violation = match contact {
            PairContact::Penetrating { depth } => depth + clearance,
            PairContact::Touching { gap } if clearance > tol => clearance - gap,
            PairContact::Separated { gap } if clearance > tol && gap < clearance - tol => clearance - gap,
            _ => return None,
        };
        Some(Candidate { moving: mi, fixed: fi, violation })
    }
}

/// The violating pairs of the orientation at `p`, all of them, in order (largest violation first, then moving, then
/// stack component): [`CandidateQueue`] drained. The answers are the ones of `classify_pair` and
/// [`horizontal_slack`] on the moved components.
#[allow(clippy::too_many_arguments)]
pub fn candidates(
    scene: &StackScene,
    orientation: &Orientation,
    sweep: Option<&SweepAxes>,
    p: DVec3,
    clearance: f64,
    horizontal_clearance: bool,
    tol: f64,
    scratch: &mut DetectScratch,
    counts: &mut DetectCounts,
) -> Vec<Candidate> {
    let mut queue =
        CandidateQueue::new(scene, orientation, sweep, p, clearance, horizontal_clearance, tol, scratch, counts);
    let mut out = Vec::new();
    while let Some(c) = queue.next(scene, orientation, sweep) {
        out.push(c);
    }
    queue.recycle(scratch);
    out
}

/// Horizontal clearance of a convex pair: the largest, over the separating axes `u` (face normals of both, edge
/// cross products), of `gap_u - clearance |u_xy|`. Non-negative iff the pair stays apart when one of them is moved
/// horizontally by at most `clearance` (up to the mitring of the axis set); negative values measure the violation.
pub fn horizontal_slack(a: &PlacedConvex, b: &PlacedConvex, clearance: f64) -> f64 {
    horizontal_slack_below(a, b, clearance, f64::INFINITY)
}

/// [`horizontal_slack`] that stops as soon as an axis shows a slack of at least `stop` and returns that axis' value
/// (a value `>= stop`, not necessarily the largest): the pair is then known not to violate. Below `stop` the value is
/// the exact maximum over all axes (the same arithmetic in the same order as [`horizontal_slack`]).
pub fn horizontal_slack_below(a: &PlacedConvex, b: &PlacedConvex, clearance: f64, stop: f64) -> f64 {
    let project = |vs: &[DVec3], u: DVec3| {
        vs.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            let x = u.dot(*v);
            (lo.min(x), hi.max(x))
        })
    };
    let mut best = f64::NEG_INFINITY;
    let mut test = |u: DVec3| {
        let (a_lo, a_hi) = project(&a.vertices, u);
        let (b_lo, b_hi) = project(&b.vertices, u);
        let gap = (b_lo - a_hi).max(a_lo - b_hi);
        best = best.max(gap - clearance * (1.0 - u.z * u.z).max(0.0).sqrt());
        best >= stop
    };
    for &u in a.normal_axes.iter().chain(&b.normal_axes) {
        if test(u) {
            return best;
        }
    }
    for &da in &a.edge_directions {
        for &db in &b.edge_directions {
            let c = da.cross(db);
            let len2 = c.length_squared();
            if len2 > 1e-18 && test(c / len2.sqrt()) {
                return best;
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::request::Cost;
    use stackplan_cspace::interference::{classify_pair, classify_pair_all_axes};
    use stackplan_geom::PartOrigin;

    fn cuboid(lo: DVec3, hi: DVec3) -> ConvexPolytope {
        ConvexPolytope::cuboid(lo, hi).expect("box")
    }

    fn l_part(a: f64, t: f64, h: f64) -> Part {
        let c = vec![
            cuboid(DVec3::ZERO, DVec3::new(a, t, h)),
            cuboid(DVec3::new(0.0, t, 0.0), DVec3::new(t, a, h)),
            cuboid(DVec3::new(0.0, 0.0, h), DVec3::new(a * 0.5, a * 0.5, h + t)),
        ];
        Part::from_components("l", c, 1.0, PartOrigin::ConvexPieces).expect("part")
    }

    /// The reference: every pair moved and classified by `classify_pair_all_axes` / `horizontal_slack` (the complete
    /// axis set), sorted by (violation desc, moving, fixed). Also checks that `classify_pair` (which skips duplicate
    /// axes) agrees with the complete axis set up to rounding.
    fn reference(
        scene: &StackScene,
        o: &Orientation,
        sweep: Option<&SweepAxes>,
        p: DVec3,
        clearance: f64,
        horizontal: bool,
        tol: f64,
    ) -> Vec<Candidate> {
        let mut out = Vec::new();
        for (mi, placed) in o.components.iter().enumerate() {
            let moved = match sweep {
                Some(s) => swept(placed, &s.axes[mi], p, scene.top),
                None => translated(placed, p),
            };
            for (fi, fixed) in scene.components.iter().enumerate() {
                if !boxes_overlap(&moved.aabb, &fixed.placed.aabb, clearance + tol) {
                    continue;
                }
                if horizontal && clearance > 0.0 {
                    let slack = horizontal_slack(&moved, &fixed.placed, clearance);
                    if slack < -tol {
                        out.push(Candidate { moving: mi, fixed: fi, violation: -slack });
                    }
                    continue;
                }
                let all_axes = classify_pair_all_axes(&moved, &fixed.placed, tol, clearance);
                let pruned = classify_pair(&moved, &fixed.placed, tol, clearance);
                let gap = |c: PairContact| match c {
                    PairContact::Penetrating { depth } => -depth,
                    PairContact::Touching { gap } | PairContact::Separated { gap } => gap,
                };
                assert!((gap(all_axes) - gap(pruned)).abs() <= 1e-9, "{all_axes:?} vs {pruned:?}");
                let violation = match all_axes {
                    PairContact::Penetrating { depth } => depth + clearance,
                    PairContact::Touching { gap } if clearance > tol => clearance - gap,
                    PairContact::Separated { gap } if clearance > tol && gap < clearance - tol => clearance - gap,
                    _ => continue,
                };
                out.push(Candidate { moving: mi, fixed: fi, violation });
            }
        }
        out.sort_by(|a, b| {
            b.violation.total_cmp(&a.violation).then(a.moving.cmp(&b.moving)).then(a.fixed.cmp(&b.fixed))
        });
        out
    }

    proptest::proptest! {
        /// The open pairs' integer order is [`precedes`]'s (the bound by `f64::total_cmp`, descending, then the lower
        /// moving and stack component), including signed zeros, infinities and equal bounds.
        #[test]
        fn open_pairs_order_as_precedes(
            a in (proptest::sample::select(vec![0.0, -0.0, 1.5, -1.5, f64::INFINITY, f64::NEG_INFINITY, 3e-300]),
                -2.0f64..2.0, 0usize..4, 0usize..4, proptest::bool::ANY),
            b in (proptest::sample::select(vec![0.0, -0.0, 1.5, -1.5, f64::INFINITY, f64::NEG_INFINITY, 3e-300]),
                -2.0f64..2.0, 0usize..4, 0usize..4, proptest::bool::ANY),
        ) {
            let pick = |(special, any, m, f, use_special): (f64, f64, usize, usize, bool)| {
                (if use_special { special } else { any }, m, f)
            };
            let (x, y) = (pick(a), pick(b));
            let (p, q) = (OpenPair::new(x.1, x.2, x.0), OpenPair::new(y.1, y.2, y.0));
            let expected = if precedes(x, y) {
                std::cmp::Ordering::Greater
            } else if precedes(y, x) {
                std::cmp::Ordering::Less
            } else {
                std::cmp::Ordering::Equal
            };
            proptest::prop_assert_eq!(p.cmp(&q), expected, "{:?} {:?}", x, y);
        }
    }

    /// The lazy queue (first and repeated tests of each pair, with the scratch lists recycled) gives exactly the
    /// reference's pairs, order and violations (bit for bit), with and without clearance, horizontal clearance and
    /// sweeps, at positions from far apart to deeply overlapping.
    #[test]
    fn queue_matches_the_full_separating_axis_test() {
        let part = l_part(30.0, 8.0, 10.0);
        let stack_pose = |k: usize| Pose {
            rotation: DMat3::from_rotation_z(0.3 * k as f64),
            position: DVec3::new(25.0 * k as f64, 10.0 * (k % 2) as f64, 12.0 * (k / 2) as f64),
        };
        let parts = [(&part, stack_pose(0)), (&part, stack_pose(1)), (&part, stack_pose(2))];
        let scene = StackScene::new(&parts);
        let tol = 1e-9 * 200.0;
        let mut seed: u64 = 12345;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut total, mut bounds_checked) = (0, 0);
        for (clearance, horizontal, insertion) in
            [(0.0, false, false), (3.0, false, false), (3.0, true, false), (3.0, true, true), (0.0, false, true)]
        {
            let mut scratch = DetectScratch::default();
            for ti in 0..6 {
                let theta = ti as f64 * 0.7;
                let cost = Cost::Target { target: DVec3::ZERO };
                let o = Orientation::new(&part, ti, 0, ti, theta, DMat3::IDENTITY, &cost);
                let sweep = insertion.then(|| SweepAxes::new(&part, o.rotation, &o));
                for _ in 0..12 {
                    let p = DVec3::new(rnd() * 70.0 - 10.0, rnd() * 40.0 - 10.0, rnd() * 30.0);
                    let expected = reference(&scene, &o, sweep.as_ref(), p, clearance, horizontal, tol);
                    // every violation is within its pair's bound from the boxes alone (what lets the queue leave
                    // pairs unscanned)
                    let (sw, c, h) = (sweep.as_ref(), clearance, horizontal);
                    let mut counts = DetectCounts::default();
                    let queue = CandidateQueue::new(&scene, &o, sw, p, c, h, tol, &mut scratch, &mut counts);
                    for c in &expected {
                        let open = queue.open.iter().find(|x| (x.moving, x.fixed) == (c.moving, c.fixed));
                        let bound = open.map(|x| x.bound);
                        assert!(bound.is_some_and(|b| b >= c.violation), "{c:?}: bound {bound:?}, p {p}");
                        bounds_checked += 1;
                    }
                    queue.recycle(&mut scratch);
                    // twice, the second time with the lists the first one recycled
                    for _ in 0..2 {
                        let got = candidates(&scene, &o, sw, p, c, h, tol, &mut scratch, &mut counts);
                        assert_eq!(got, expected, "p {p}, theta {theta}, clearance {clearance}, {horizontal}");
                    }
                    total += expected.len();
                }
            }
        }
        assert!(total > 50, "too few violating pairs to be a test: {total}");
        assert_eq!(bounds_checked, total);
    }
}
