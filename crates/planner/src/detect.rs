//! Interference pairs of the new part at a configuration ([A] eq. 8, section 5.1.3): a broad phase on axis-aligned
//! boxes and the exact separating-axis narrow phase of `stackplan-cspace` (`classify_pair`, GJK distance for pairs
//! closer than the clearance).
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
//! each; the stacks of [A] have at most a few hundred components); a moving component is translated (or swept)
//! only when some box meets its own. Candidates are returned
//! in a deterministic order: by violation (deepest first), then by (moving component, stack component).

use crate::orientation::Orientation;
use glam::{DMat3, DVec3};
use stackplan_cspace::PlacedConvex;
use stackplan_cspace::interference::{PairContact, classify_pair};
use stackplan_geom::polytope::ConvexPolytope;
use stackplan_geom::{Part, Pose};

/// A component of a stack part, placed in the world.
#[derive(Debug, Clone)]
pub struct StackComponent {
    /// Stack part index.
    pub part: usize,
    /// Component index in that part.
    pub piece: usize,
    /// The component in world coordinates.
    pub world: ConvexPolytope,
    /// Prepared for the separating-axis test.
    pub placed: PlacedConvex,
}

/// The stationary stack, prepared once.
#[derive(Debug, Clone)]
pub struct StackScene {
    /// Every component of every stack part, in (part, piece) order.
    pub components: Vec<StackComponent>,
    /// Highest z of the stack (or 0 for an empty stack).
    pub top: f64,
}

impl StackScene {
    /// Places every component. O(total size).
    pub fn new(parts: &[(&Part, Pose)]) -> Self {
        let mut components = Vec::new();
        let mut top: f64 = 0.0;
        for (pi, (part, pose)) in parts.iter().enumerate() {
            for (ci, c) in part.components.iter().enumerate() {
                let world = c.transformed(pose.rotation, pose.position);
                let placed = PlacedConvex::new(c, pose.rotation, pose.position);
                top = top.max(placed.aabb.1.z);
                components.push(StackComponent { part: pi, piece: ci, world, placed });
            }
        }
        Self { components, top }
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
            .components
            .iter()
            .zip(&orientation.components)
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

/// `placed` moved by `p`.
pub fn translated(placed: &PlacedConvex, p: DVec3) -> PlacedConvex {
    PlacedConvex {
        vertices: placed.vertices.iter().map(|v| *v + p).collect(),
        normal_axes: placed.normal_axes.clone(),
        edge_directions: placed.edge_directions.clone(),
        aabb: (placed.aabb.0 + p, placed.aabb.1 + p),
    }
}

/// `placed` moved by `p` and swept up to `top` (see the module documentation).
fn swept(placed: &PlacedConvex, axes: &(Vec<DVec3>, Vec<DVec3>), p: DVec3, top: f64) -> PlacedConvex {
    let lift = (top - (placed.aabb.0.z + p.z)).max(0.0) + 1.0;
    let mut vertices: Vec<DVec3> = placed.vertices.iter().map(|v| *v + p).collect();
    let n = vertices.len();
    for k in 0..n {
        vertices.push(vertices[k] + DVec3::new(0.0, 0.0, lift));
    }
    PlacedConvex {
        vertices,
        normal_axes: axes.0.clone(),
        edge_directions: axes.1.clone(),
        aabb: (placed.aabb.0 + p, placed.aabb.1 + p + DVec3::new(0.0, 0.0, lift)),
    }
}

/// The box of [`swept`] without building the sweep (the same arithmetic).
fn swept_box(placed: &PlacedConvex, p: DVec3, top: f64) -> (DVec3, DVec3) {
    let lift = (top - (placed.aabb.0.z + p.z)).max(0.0) + 1.0;
    (placed.aabb.0 + p, placed.aabb.1 + p + DVec3::new(0.0, 0.0, lift))
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
    /// Exact narrow-phase pair tests.
    pub narrow_phase: u64,
}

/// The violating pairs of the orientation at `p` (see the module documentation).
pub fn candidates(
    scene: &StackScene,
    orientation: &Orientation,
    sweep: Option<&SweepAxes>,
    p: DVec3,
    clearance: f64,
    horizontal_clearance: bool,
    tol: f64,
    counts: &mut DetectCounts,
) -> Vec<Candidate> {
    let mut out = Vec::new();
    let margin = clearance + tol;
    // broad phase in two levels: the stack components near the whole part's box (a superset of each component's,
    // the sweep reaching up without bound), then each component's box; a component is moved only when some stack
    // box meets its own
    let part_box = match sweep {
        Some(_) => (orientation.lo + p, DVec3::new(orientation.hi.x + p.x, orientation.hi.y + p.y, f64::INFINITY)),
        None => (orientation.lo + p, orientation.hi + p),
    };
    let near: Vec<usize> = scene
        .components
        .iter()
        .enumerate()
        .filter(|(_, f)| boxes_overlap(&part_box, &f.placed.aabb, margin))
        .map(|(i, _)| i)
        .collect();
    if near.is_empty() {
        return out;
    }
    for (mi, placed) in orientation.components.iter().enumerate() {
        let moved_box = match sweep {
            Some(_) => swept_box(placed, p, scene.top),
            None => (placed.aabb.0 + p, placed.aabb.1 + p),
        };
        let mut moved: Option<PlacedConvex> = None;
        for &fi in &near {
            let fixed = &scene.components[fi];
            if !boxes_overlap(&moved_box, &fixed.placed.aabb, margin) {
                continue;
            }
            let moved = moved.get_or_insert_with(|| match sweep {
                Some(axes) => swept(placed, &axes.axes[mi], p, scene.top),
                None => translated(placed, p),
            });
            counts.narrow_phase += 1;
            if horizontal_clearance && clearance > 0.0 {
                let slack = horizontal_slack(moved, &fixed.placed, clearance);
                if slack >= -tol {
                    continue;
                }
                out.push(Candidate { moving: mi, fixed: fi, violation: -slack });
                continue;
            }
            let violation = match classify_pair(moved, &fixed.placed, tol, clearance) {
                PairContact::Penetrating { depth } => depth + clearance,
                PairContact::Touching { gap } if clearance > tol => clearance - gap,
                PairContact::Separated { gap } if clearance > tol && gap < clearance - tol => clearance - gap,
                _ => continue,
            };
            out.push(Candidate { moving: mi, fixed: fi, violation });
        }
    }
    out.sort_by(|a, b| b.violation.total_cmp(&a.violation).then(a.moving.cmp(&b.moving)).then(a.fixed.cmp(&b.fixed)));
    out
}

/// Horizontal clearance of a convex pair: the largest, over the separating axes `u` (face normals of both, edge
/// cross products), of `gap_u - clearance |u_xy|`. Non-negative iff the pair stays apart when one of them is moved
/// horizontally by at most `clearance` (up to the mitring of the axis set); negative values measure the violation.
pub fn horizontal_slack(a: &PlacedConvex, b: &PlacedConvex, clearance: f64) -> f64 {
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
    };
    for &u in a.normal_axes.iter().chain(&b.normal_axes) {
        test(u);
    }
    for &da in &a.edge_directions {
        for &db in &b.edge_directions {
            let c = da.cross(db);
            let len2 = c.length_squared();
            if len2 > 1e-18 {
                test(c / len2.sqrt());
            }
        }
    }
    best
}
