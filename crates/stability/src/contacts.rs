//! Contact patches between the parts of a stack and with the floor (`docs/algorithms.md`, "Stability, grasp and
//! insertion"; \[A\] II-B condition (ii)).
//!
//! For every pair of convex components of different parts whose bounding boxes meet, the separating-axis test
//! ([`crate::sat`]) gives the largest signed separation `g` and its axis `n` (from the first component to the second):
//!
//! * `g < -tol`: interference, penetration depth `-g` (exact for convex polytopes);
//! * `g > tol`: no contact;
//! * otherwise the components touch. Where they touch along an edge or at a vertex, several axes separate them equally
//!   (a normal cone: an edge of one on an edge of the other, or the seam between two components of one part whose
//!   faces are coplanar); the axis of the contact is then the most vertical of the face normals (of either component)
//!   whose separation is within `tol` of the largest ([`contact_axis`]), whatever order the components list their
//!   faces in. Gravity loads the stack, and a sideways normal at such a contact would let two opposite edge
//!   contacts pinch a part along one line and hold it by friction (a part resting across the seam of two coplanar
//!   tops was found "stable" that way, with its centre of gravity outside its supports). The supporting sets
//!   `S_A = {v in A : n.v >= max_A n.x - tol}` and `S_B = {v in B : n.v <= min_B n.x + tol}` (a vertex, an edge or
//!   a face of each) are projected onto the contact plane and intersected as planar convex sets
//!   ([`crate::polygon2d::intersect_convex`]): coplanar opposite faces give the polygon of their overlap, an edge
//!   on a face a segment, crossing edges or a vertex on a face a point. The patch's points are the vertices of that
//!   set, lifted to the mid-plane between the two supporting planes.
//!
//! The floor is the fixed plane z = 0: a component touches it when its lowest vertex is within `tol` of z = 0 and the
//! patch is the planar hull of its vertices within `tol` of the floor (normal +z). `tol` is the tolerance policy of
//! the stack ([`crate::world::stack_tolerance`]) unless the caller overrides it.
//!
//! Cost: O(P^2) bounding-box tests over parts, then the separating-axis test per component pair whose boxes meet.

use crate::polygon2d::{convex_hull_2d, intersect_convex};
use crate::sat::{Separation, Shape, separation, separation_along};
use crate::world::{WorldComponent, WorldPart, aabb_overlap};
use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

/// A body of the stack: the fixed floor or a part (index in the stack).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Body {
    /// The plane z = 0, fixed.
    Floor,
    /// A part, by its index in the stack.
    Part(usize),
}

/// What kind of set a contact patch is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PatchKind {
    /// A planar polygon (coplanar touching faces).
    Polygon,
    /// A segment (edge on face, parallel edges).
    Segment,
    /// A single point (vertex on face, crossing edges).
    Point,
}

/// A contact patch between body `a` and part `b`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactPatch {
    /// The first body (the floor, or the part with the smaller index).
    pub a: Body,
    /// The second body, always a part.
    pub b: usize,
    /// Component of `a` (None for the floor).
    pub component_a: Option<usize>,
    /// Component of `b`.
    pub component_b: usize,
    /// Unit contact normal pointing from `a` into `b` (the direction in which `a` can push `b`).
    pub normal: DVec3,
    /// Contact points (the patch's vertices), world coordinates.
    pub points: Vec<DVec3>,
    /// Kind of patch.
    pub kind: PatchKind,
    /// Signed gap of the pair (|gap| <= tol).
    pub gap: f64,
}

/// An interfering (penetrating) pair of components.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Interference {
    /// First body (floor or the part with the smaller index).
    pub a: Body,
    /// Second part.
    pub b: usize,
    /// Component of `a` (None for the floor).
    pub component_a: Option<usize>,
    /// Component of `b`.
    pub component_b: usize,
    /// Penetration depth (> tol).
    pub depth: f64,
}

/// Contacts and interferences of a stack.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ContactAnalysis {
    /// Touching pairs with their patches.
    pub patches: Vec<ContactPatch>,
    /// Penetrating pairs.
    pub interferences: Vec<Interference>,
}

/// An orthonormal basis `(u, w)` of the plane perpendicular to unit `n`, with `u x w = n`.
pub fn plane_basis(n: DVec3) -> (DVec3, DVec3) {
    let helper = if n.x.abs() < 0.6 {
        DVec3::X
    } else if n.y.abs() < 0.6 {
        DVec3::Y
    } else {
        DVec3::Z
    };
    let u = helper.cross(n).normalize();
    let w = n.cross(u);
    (u, w)
}

/// Contact between the floor and one component (`None` when not touching), or its penetration depth.
pub fn floor_contact(component: &WorldComponent, tol: f64) -> Result<Option<(Vec<DVec3>, f64)>, f64> {
    let lowest = component.aabb.0.z;
    if lowest < -tol {
        return Err(-lowest);
    }
    if lowest > tol {
        return Ok(None);
    }
    let pts: Vec<DVec2> =
        component.polytope.vertices().iter().filter(|v| v.z <= lowest + tol).map(|v| DVec2::new(v.x, v.y)).collect();
    let hull = convex_hull_2d(&pts, tol);
    Ok(Some((hull.iter().map(|p| DVec3::new(p.x, p.y, 0.0)).collect(), lowest)))
}

/// Contact patch of two touching components (`a` first, normal from `a` to `b`), or `None` when the supporting sets
/// do not overlap within `tol` (a near miss).
pub fn touching_patch(a: &WorldComponent, b: &WorldComponent, axis: DVec3, tol: f64) -> Option<(Vec<DVec3>, DVec3)> {
    let n = axis;
    let ha = a.polytope.vertices().iter().map(|v| n.dot(*v)).fold(f64::NEG_INFINITY, f64::max);
    let hb = b.polytope.vertices().iter().map(|v| n.dot(*v)).fold(f64::INFINITY, f64::min);
    let (u, w) = plane_basis(n);
    let project = |v: &DVec3| DVec2::new(u.dot(*v), w.dot(*v));
    let sa: Vec<DVec2> = a.polytope.vertices().iter().filter(|v| n.dot(**v) >= ha - tol).map(project).collect();
    let sb: Vec<DVec2> = b.polytope.vertices().iter().filter(|v| n.dot(**v) <= hb + tol).map(project).collect();
    let ia = convex_hull_2d(&sa, tol);
    let ib = convex_hull_2d(&sb, tol);
    let patch = intersect_convex(&ia, &ib, tol);
    if patch.is_empty() {
        return None;
    }
    let mid = 0.5 * (ha + hb);
    Some((patch.iter().map(|p| u * p.x + w * p.y + n * mid).collect(), n))
}

/// The axis of the contact of two touching components (module documentation): among `sep`'s axis and the face
/// normals of both components (oriented from `a` to `b`), those whose separation is within `tol` of `sep.distance`,
/// the one with the largest `|z|` (the first found when that ties too, `sep`'s axis first). O(faces x vertices).
pub fn contact_axis(a: &WorldComponent, b: &WorldComponent, sep: Separation, tol: f64) -> DVec3 {
    let (sa, sb) = (Shape::of(a), Shape::of(b));
    let mut best = sep.axis;
    for &n in a.normals.iter().chain(&b.normals) {
        if n.z.abs() <= best.z.abs() + 1e-12 {
            continue;
        }
        let (d, axis) = separation_along(&sa, &sb, n);
        if d >= sep.distance - tol {
            best = axis;
        }
    }
    best
}

fn kind_of(points: &[DVec3]) -> PatchKind {
    match points.len() {
        0 | 1 => PatchKind::Point,
        2 => PatchKind::Segment,
        _ => PatchKind::Polygon,
    }
}

/// Contacts and interferences among `parts` and with the floor, with length tolerance `tol`.
///
/// Only parts for which `include(i)` holds take part (to analyse a prefix of a stack).
pub fn analyse_contacts(parts: &[WorldPart], tol: f64, include: impl Fn(usize) -> bool) -> ContactAnalysis {
    let mut out = ContactAnalysis::default();
    for j in 0..parts.len() {
        if include(j) {
            contacts_of_part(parts, j, tol, &include, &mut out);
        }
    }
    tracing::debug!(patches = out.patches.len(), interferences = out.interferences.len(), "contacts analysed");
    out
}

/// The contacts and interferences of part `j` with the floor and with the parts `i < j` for which `include(i)`
/// holds, appended to `out` in the order of [`analyse_contacts`] (which is this for every included `j` in turn: the
/// analysis of a stack is that of the stack without its last part followed by the last part's).
pub fn contacts_of_part(
    parts: &[WorldPart],
    j: usize,
    tol: f64,
    include: impl Fn(usize) -> bool,
    out: &mut ContactAnalysis,
) {
    let pb = &parts[j];
    // the floor
    if pb.aabb.0.z <= tol {
        for (cb, comp) in pb.components.iter().enumerate() {
            match floor_contact(comp, tol) {
                Err(depth) => out.interferences.push(Interference {
                    a: Body::Floor,
                    b: j,
                    component_a: None,
                    component_b: cb,
                    depth,
                }),
                Ok(Some((points, gap))) => out.patches.push(ContactPatch {
                    a: Body::Floor,
                    b: j,
                    component_a: None,
                    component_b: cb,
                    normal: DVec3::Z,
                    kind: kind_of(&points),
                    points,
                    gap,
                }),
                Ok(None) => {}
            }
        }
    }
    for (i, pa) in parts.iter().enumerate().take(j) {
        if !include(i) || !aabb_overlap(&pa.aabb, &pb.aabb, tol) {
            continue;
        }
        for (ca, a) in pa.components.iter().enumerate() {
            if !aabb_overlap(&a.aabb, &pb.aabb, tol) {
                continue;
            }
            for (cb, b) in pb.components.iter().enumerate() {
                if !aabb_overlap(&a.aabb, &b.aabb, tol) {
                    continue;
                }
                let sep = separation(&Shape::of(a), &Shape::of(b));
                if sep.distance < -tol {
                    out.interferences.push(Interference {
                        a: Body::Part(i),
                        b: j,
                        component_a: Some(ca),
                        component_b: cb,
                        depth: -sep.distance,
                    });
                } else if sep.distance <= tol
                    && let Some((points, normal)) = touching_patch(a, b, contact_axis(a, b, sep, tol), tol)
                {
                    out.patches.push(ContactPatch {
                        a: Body::Part(i),
                        b: j,
                        component_a: Some(ca),
                        component_b: cb,
                        normal,
                        kind: kind_of(&points),
                        points,
                        gap: sep.distance,
                    });
                }
            }
        }
    }
}
