//! Interference pairs between a moving part and placed parts (\[A\] eq. 6-8, section 5.1.3).
//!
//! A part is a union of convex components; two parts interfere iff some pair of components has overlapping interiors
//! (touching is not interference, \[A\] App. A). The list `L` of such pairs at a configuration is what the planner
//! builds obstacles for.
//!
//! * **Broad phase**: the world AABBs of all placed components in a parry3d-f64 [`Bvh`] (binned SAH build,
//!   O(n log n)); the moving component's AABB, enlarged by the clearance and the tolerance, is queried against it.
//! * **Narrow phase**: the separating-axis theorem for convex polytopes. The candidate axes are the face normals of both
//!   and the cross products of their edge directions (deduplicated: a box has 3 normal axes and 3 edge directions, so
//!   3 + 3 + 9 axes). For each axis `u` the signed gap `max(min_B - max_A, min_A - max_B)` of the two projections is a
//!   lower bound on the distance; the largest gap over the complete axis set is positive iff the polytopes are
//!   disjoint, and when it is negative its magnitude is the penetration depth (the minimum translation distance is
//!   attained along one of these axes). With the tolerance `tol` of [`stackplan_geom::Tolerance`]:
//!   `gap > tol` separated, `|gap| <= tol` touching, `gap < -tol` penetrating by `-gap`. O((FA + FB + EA EB)(VA + VB))
//!   with early exit on the first separating axis. Two savings that leave the maximum unchanged: a polytope's
//!   projection onto its own face normals is precomputed ([`PlacedConvex::normal_extents`]), and a cross axis
//!   parallel to a face normal of either polytope is not tested again ([`cross_axis`]; the two gaps differ only by
//!   rounding). For parts turned about z most cross axes are such duplicates (box x box: all 8 non-zero ones), so
//!   the box pair costs 6 half-projections instead of 15 full ones. For two *upright prisms*
//!   ([`PlacedConvex::upright_prism`]: sheet metal turned about z) every cross axis is such a duplicate, provably
//!   from the flag's conditions, and the cross products are not even formed.
//! * **Clearance** `delta > 0`: pairs whose Euclidean distance is below `delta` are reported too. The SAT gap is only a
//!   lower bound on the distance of separated polytopes, so candidates with `tol < gap < delta` get their exact
//!   distance by closest features ([`pair_distance`], [`crate::distance`]; parry3d-f64's GJK answers 0 or more than
//!   the clearance a few tolerances from touching).

use glam::{DMat3, DVec3};
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};
use serde::{Deserialize, Serialize};
use stackplan_geom::polytope::ConvexPolytope;
use stackplan_geom::{Part, PlacedPart, Tolerance};

/// A convex component placed in the world, prepared for separating-axis tests.
#[derive(Debug, Clone)]
pub struct PlacedConvex {
    /// World vertices.
    pub vertices: Vec<DVec3>,
    /// Unique face normal directions (up to sign), world frame, unit.
    pub normal_axes: Vec<DVec3>,
    /// The projection `[min, max]` of the vertices onto each normal axis ([`project`]; kept so that a test never
    /// projects a polytope onto its own face normals; [`PlacedConvex::translated`] shifts it by `u . p`).
    pub normal_extents: Vec<(f64, f64)>,
    /// Unique edge directions (up to sign), world frame, unit.
    pub edge_directions: Vec<DVec3>,
    /// Per edge direction: bit `k` is set iff normal axis `k < 64` is perpendicular to it (`|n . d| <= 1e-9`): the
    /// normals a cross axis of this edge direction can be parallel to ([`cross_axis`]).
    pub edge_normal_masks: Vec<u64>,
    /// World AABB `(min, max)`.
    pub aabb: (DVec3, DVec3),
    /// Whether every cross axis of this polytope's edge directions with those of another upright prism duplicates
    /// a normal axis ([`cross_axis`] returns `None` for every pair), so that [`sat_gap`] can skip them all with the
    /// same result. Computed exactly from the axes ([`is_upright_prism`]): some normal axis among the first 64 is
    /// vertical (`x == y == 0`), and every edge direction is either vertical or horizontal (`z == 0`) with a
    /// horizontal normal axis among the first 64 perpendicular to it to within `1e-13` of its length. A z-prism
    /// turned about z (the planner's sheet metal) is one.
    pub upright_prism: bool,
}

/// The conditions of [`PlacedConvex::upright_prism`]. For two polytopes that meet them, each pair of edge directions
/// `da`, `db` gives one of (exact arithmetic on exact zeros): both vertical, `da x db = 0`, parallel; both
/// horizontal, `da x db = (0, 0, c)`, exactly parallel to the vertical normal axis (perpendicular to every
/// horizontal edge, so named in its mask); one horizontal (`d`, with its witness normal `n`: `n.z = 0`, in the
/// mask since `|n . d| <= 1e-13 |d| <= 1e-9`) and one vertical (`s z`): `c = d x (s z)` is horizontal, and
/// `c x n = (0, 0, s (n . d))` up to an ulp, so `|c x n|^2 <= 1.01e-26 s^2 |d|^2 <= 1e-24 |c|^2`: a duplicate.
pub fn is_upright_prism(normal_axes: &[DVec3], edge_directions: &[DVec3]) -> bool {
    let normals = &normal_axes[..normal_axes.len().min(64)];
    let vertical = |u: &DVec3| u.x == 0.0 && u.y == 0.0 && u.z != 0.0;
    normals.iter().any(vertical)
        && edge_directions.iter().all(|d| {
            vertical(d)
                || (d.z == 0.0
                    && d.is_finite()
                    && normals.iter().any(|n| {
                        let dot = n.dot(*d);
                        n.z == 0.0 && dot.abs() <= PERPENDICULAR && dot * dot <= 1e-26 * d.length_squared()
                    }))
        })
}

/// Adds `d` to `set` unless a parallel (or antiparallel) direction is already there.
fn push_unique_direction(set: &mut Vec<DVec3>, d: DVec3) {
    const PARALLEL: f64 = 1e-12;
    if !set.iter().any(|s| s.cross(d).length_squared() <= PARALLEL) {
        set.push(d);
    }
}

/// `|n . d|` at most this marks a unit normal as perpendicular to a unit edge direction in
/// [`PlacedConvex::edge_normal_masks`] (a filter only: [`cross_axis`] confirms parallelism exactly).
const PERPENDICULAR: f64 = 1e-9;

/// A unit cross axis `c` counts as parallel to a unit normal axis `n` when `|c x n|^2` is at most this (an angle of
/// `1e-12`): the gaps on the two axes then differ by at most `1e-12` times the extent of the pair, far below any
/// tolerance, so the cross axis is skipped.
const PARALLEL_AXIS: f64 = 1e-24;

/// Per edge direction, the bitmask of the normal axes (the first 64) perpendicular to it.
pub fn perpendicular_masks(normal_axes: &[DVec3], edge_directions: &[DVec3]) -> Vec<u64> {
    edge_directions
        .iter()
        .map(|d| {
            normal_axes
                .iter()
                .take(64)
                .enumerate()
                .filter(|(_, n)| n.dot(*d).abs() <= PERPENDICULAR)
                .fold(0u64, |m, (k, _)| m | (1u64 << k))
        })
        .collect()
}

/// Whether the axis `c` (of squared length `len2 > 0`) is parallel to one of the unit normal axes that `mask` names:
/// `|c x n|^2 <= PARALLEL_AXIS |c|^2`, the test on the unit axis `c / |c|` without normalising `c` first (most cross
/// axes of sheet-metal pairs are such duplicates, and the square root and the divisions were most of their cost).
#[inline]
fn parallel_to_any(c: DVec3, len2: f64, normals: &[DVec3], mut mask: u64) -> bool {
    let bound = PARALLEL_AXIS * len2;
    while mask != 0 {
        let k = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        if c.cross(normals[k]).length_squared() <= bound {
            return true;
        }
    }
    false
}

/// The separating axis of edge directions `da` (of A, perpendicular to the normals `mask_a` names) and `db` (of B):
/// the unit cross product, or `None` when it need not be tested: the edges are parallel (`|da x db|^2 <= 1e-18`,
/// covered by the face normals) or the cross product is parallel to a normal axis of A or B (tested already among
/// the face normals: a cross axis is parallel to a normal `n` only if `n` is perpendicular to both edges, so only the
/// normals of A perpendicular to `da` and of B perpendicular to `db` are checked). For parts turned about z most cross
/// axes are such duplicates (box x box: all of them).
#[inline]
pub fn cross_axis(
    da: DVec3,
    mask_a: u64,
    a_normals: &[DVec3],
    db: DVec3,
    mask_b: u64,
    b_normals: &[DVec3],
) -> Option<DVec3> {
    let c = da.cross(db);
    let len2 = c.length_squared();
    if len2 <= 1e-18 {
        return None;
    }
    if parallel_to_any(c, len2, a_normals, mask_a) || parallel_to_any(c, len2, b_normals, mask_b) {
        return None;
    }
    Some(c / len2.sqrt())
}

impl PlacedConvex {
    /// The polytope moved by `x -> rotation x + position`.
    pub fn new(polytope: &ConvexPolytope, rotation: DMat3, position: DVec3) -> Self {
        let vertices: Vec<DVec3> = polytope.vertices().iter().map(|v| rotation * *v + position).collect();
        let mut normal_axes = Vec::with_capacity(polytope.faces().len());
        for f in polytope.faces() {
            push_unique_direction(&mut normal_axes, (rotation * f.plane.normal).normalize());
        }
        let mut edge_directions = Vec::with_capacity(polytope.edges().len());
        for e in polytope.edges() {
            let d = vertices[e.vertices[1]] - vertices[e.vertices[0]];
            push_unique_direction(&mut edge_directions, d.normalize());
        }
        let first = vertices.first().copied().unwrap_or(DVec3::ZERO);
        let aabb = vertices.iter().fold((first, first), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
        Self::from_parts(vertices, normal_axes, edge_directions, aabb)
    }

    /// A placed polytope from its vertices, axes and box; the extents on the normal axes and the perpendicularity
    /// masks are computed here.
    pub fn from_parts(
        vertices: Vec<DVec3>,
        normal_axes: Vec<DVec3>,
        edge_directions: Vec<DVec3>,
        aabb: (DVec3, DVec3),
    ) -> Self {
        let normal_extents = normal_axes.iter().map(|u| project(&vertices, *u)).collect();
        let edge_normal_masks = perpendicular_masks(&normal_axes, &edge_directions);
        let upright_prism = is_upright_prism(&normal_axes, &edge_directions);
        Self { vertices, normal_axes, normal_extents, edge_directions, edge_normal_masks, aabb, upright_prism }
    }

    /// The polytope moved by `p`: vertices `v + p`, extents `[lo + u . p, hi + u . p]`.
    pub fn translated(&self, p: DVec3) -> Self {
        Self {
            vertices: self.vertices.iter().map(|v| *v + p).collect(),
            normal_axes: self.normal_axes.clone(),
            normal_extents: self
                .normal_axes
                .iter()
                .zip(&self.normal_extents)
                .map(|(u, &(lo, hi))| {
                    let d = u.dot(p);
                    (lo + d, hi + d)
                })
                .collect(),
            edge_directions: self.edge_directions.clone(),
            edge_normal_masks: self.edge_normal_masks.clone(),
            aabb: (self.aabb.0 + p, self.aabb.1 + p),
            upright_prism: self.upright_prism,
        }
    }
}

/// How two convex components relate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "contact", rename_all = "snake_case")]
pub enum PairContact {
    /// Interiors overlap: the minimum translation distance is `depth > tol`.
    Penetrating {
        /// Penetration depth (mm).
        depth: f64,
    },
    /// Boundaries touch within the tolerance; `gap` is the signed separation (|gap| <= tol).
    Touching {
        /// Signed separation (mm), within the tolerance of zero.
        gap: f64,
    },
    /// Disjoint; `gap` is a lower bound on the distance (the exact distance, [`pair_distance`], when a clearance
    /// asked for it).
    Separated {
        /// Separation (mm).
        gap: f64,
    },
}

/// The interval `[min, max]` of `u . v` over `vertices` (the projection of a convex set onto an axis, the basic step
/// of a separating-axis test). O(n). (Vertices are never NaN, so plain comparisons replace `f64::min`/`max`.)
#[inline]
pub fn project(vertices: &[DVec3], u: DVec3) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for v in vertices {
        let x = u.dot(*v);
        lo = if x < lo { x } else { lo };
        hi = if x > hi { x } else { hi };
    }
    (lo, hi)
}

/// The largest separating-axis gap of two placed convex polytopes (see the module documentation); stops early and
/// returns a gap `> stop_above` as soon as one axis exceeds it. A polytope's projection onto its own face normals is
/// its [`PlacedConvex::normal_extents`]; cross axes parallel to a face normal are skipped ([`cross_axis`]).
pub fn sat_gap(a: &PlacedConvex, b: &PlacedConvex, stop_above: f64) -> f64 {
    let mut best = f64::NEG_INFINITY;
    let mut gap_of = |(a_lo, a_hi): (f64, f64), (b_lo, b_hi): (f64, f64)| -> bool {
        let gap = (b_lo - a_hi).max(a_lo - b_hi);
        if gap > best {
            best = gap;
        }
        best > stop_above
    };
    for (&u, &ea) in a.normal_axes.iter().zip(&a.normal_extents) {
        if gap_of(ea, project(&b.vertices, u)) {
            return best;
        }
    }
    for (&u, &eb) in b.normal_axes.iter().zip(&b.normal_extents) {
        if gap_of(project(&a.vertices, u), eb) {
            return best;
        }
    }
    if a.upright_prism && b.upright_prism {
        // every cross axis duplicates a normal axis (`is_upright_prism`)
        return best;
    }
    for (&da, &ma) in a.edge_directions.iter().zip(&a.edge_normal_masks) {
        for (&db, &mb) in b.edge_directions.iter().zip(&b.edge_normal_masks) {
            if let Some(c) = cross_axis(da, ma, &a.normal_axes, db, mb, &b.normal_axes)
                && gap_of(project(&a.vertices, c), project(&b.vertices, c))
            {
                return best;
            }
        }
    }
    best
}

/// [`sat_gap`] on the complete axis set: every face normal axis and every non-degenerate edge cross product, each
/// polytope projected onto every axis (no precomputed extents, no skipped duplicates). The reference for
/// [`sat_gap`], which agrees with it up to rounding, and the arithmetic the planner's lazy narrow phase reproduces
/// bit for bit (`stackplan-planner`'s `detect`). Stops early like [`sat_gap`].
pub fn sat_gap_all_axes(a: &PlacedConvex, b: &PlacedConvex, stop_above: f64) -> f64 {
    let mut best = f64::NEG_INFINITY;
    let mut test = |u: DVec3| -> bool {
        let (a_lo, a_hi) = project(&a.vertices, u);
        let (b_lo, b_hi) = project(&b.vertices, u);
        let gap = (b_lo - a_hi).max(a_lo - b_hi);
        if gap > best {
            best = gap;
        }
        best > stop_above
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
            if len2 <= 1e-18 {
                continue; // parallel edges: covered by the face normals
            }
            if test(c / len2.sqrt()) {
                return best;
            }
        }
    }
    best
}

/// [`classify_pair`]'s decisions on a gap: penetrating below `-tol`, touching within `tol`, separated above (with
/// `clearance > tol` and a gap below it, the exact distance, [`pair_distance`], or the gap itself, a lower bound of
/// it, when a point set has no 3-D hull).
fn classify_gap(a: &PlacedConvex, b: &PlacedConvex, gap: f64, tol: f64, clearance: f64) -> PairContact {
    if gap < -tol {
        PairContact::Penetrating { depth: -gap }
    } else if gap <= tol {
        PairContact::Touching { gap }
    } else if clearance > tol && gap < clearance {
        PairContact::Separated { gap: pair_distance(a, b).unwrap_or(gap) }
    } else {
        PairContact::Separated { gap }
    }
}

/// [`classify_pair`] on the complete axis set ([`sat_gap_all_axes`]): the same decisions, the gap bit for bit the one
/// of the planner's narrow phase. A reference for tests.
pub fn classify_pair_all_axes(a: &PlacedConvex, b: &PlacedConvex, tol: f64, clearance: f64) -> PairContact {
    classify_gap(a, b, sat_gap_all_axes(a, b, tol.max(clearance)), tol, clearance)
}

/// Classifies a convex pair with tolerance `tol`; with `clearance > 0`, a separated pair closer than `clearance` gets
/// its exact distance ([`pair_distance`]) in `Separated { gap }`.
pub fn classify_pair(a: &PlacedConvex, b: &PlacedConvex, tol: f64, clearance: f64) -> PairContact {
    classify_gap(a, b, sat_gap(a, b, tol.max(clearance)), tol, clearance)
}

/// Euclidean distance of two disjoint placed polytopes, exact up to rounding at every distance: closest features of
/// the exact hulls of their vertices ([`crate::distance::convex_distance`]; `None` when either has no 3-D hull). Not
/// below the separating-axis gap (a lower bound of the distance) beyond rounding.
pub fn pair_distance(a: &PlacedConvex, b: &PlacedConvex) -> Option<f64> {
    crate::distance::convex_distance(&a.vertices, &b.vertices)
}

/// [`pair_distance`] under another name (not GJK, which answers 0, or more than the clearance, for pairs a few
/// tolerances apart: [`crate::distance`]). The planner's narrow phase (`stackplan-planner`'s `detect`) calls it by
/// this name, and must agree with [`classify_pair`] bit for bit.
pub fn gjk_distance(a: &PlacedConvex, b: &PlacedConvex) -> Option<f64> {
    pair_distance(a, b)
}

/// One interfering (or, with clearance, too close) component pair.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct InterferencePair {
    /// Component of the moving part.
    pub moving_piece: usize,
    /// Index of the placed part.
    pub fixed_part: usize,
    /// Component of that placed part.
    pub fixed_piece: usize,
    /// Penetrating, touching, or (clearance only) separated by less than the clearance.
    pub contact: PairContact,
}

/// The placed parts of a stack, prepared once: placed components and the BVH over their AABBs.
#[derive(Debug)]
pub struct PlacedScene {
    components: Vec<(usize, usize, PlacedConvex)>,
    bvh: Bvh,
    tolerance: Tolerance,
}

fn aabb_of(lo: DVec3, hi: DVec3, grow: f64) -> Aabb {
    Aabb::new(lo - DVec3::splat(grow), hi + DVec3::splat(grow))
}

impl PlacedScene {
    /// Places every component of every part and builds the BVH. The tolerance is the policy's for the largest part
    /// (or the moving part, passed later, whichever is larger). O(n log n) in the number of components.
    pub fn new(parts: &[PlacedPart<'_>]) -> Self {
        let mut components = Vec::new();
        let mut scale: f64 = 0.0;
        for (pi, placement) in parts.iter().enumerate() {
            let (lo, hi) = placement.part.aabb();
            scale = scale.max((hi - lo).length());
            for (ci, c) in placement.part.components().iter().enumerate() {
                components.push((pi, ci, PlacedConvex::new(c, placement.pose.rotation, placement.pose.position)));
            }
        }
        let bvh = Bvh::from_iter(
            BvhBuildStrategy::default(),
            components.iter().enumerate().map(|(k, (_, _, c))| (k, aabb_of(c.aabb.0, c.aabb.1, 0.0))),
        );
        Self { components, bvh, tolerance: Tolerance::for_scale(scale) }
    }

    /// Number of placed components.
    pub fn len(&self) -> usize {
        self.components.len()
    }

    /// Whether no component is placed.
    pub fn is_empty(&self) -> bool {
        self.components.is_empty()
    }

    /// The interfering component pairs of `moving` placed by `(rotation, position)`: penetrating and touching pairs,
    /// and with `clearance > 0` also separated pairs closer than `clearance`. Sorted by (moving, part, piece).
    pub fn interference_pairs(
        &self,
        moving: &Part,
        rotation: DMat3,
        position: DVec3,
        clearance: f64,
    ) -> Vec<InterferencePair> {
        self.collect_pairs(moving, rotation, position, clearance, |placed, tol| {
            let query = aabb_of(placed.aabb.0, placed.aabb.1, clearance.max(0.0) + tol);
            self.bvh.intersect_aabb(&query).map(|k| k as usize).collect()
        })
    }

    /// Same as [`Self::interference_pairs`] by testing every component pair (the brute-force reference for the
    /// broad phase: same narrow phase and keep rule, no bounding-volume hierarchy).
    pub fn interference_pairs_brute_force(
        &self,
        moving: &Part,
        rotation: DMat3,
        position: DVec3,
        clearance: f64,
    ) -> Vec<InterferencePair> {
        self.collect_pairs(moving, rotation, position, clearance, |_, _| (0..self.components.len()).collect())
    }

    /// The narrow phase and keep rule over the fixed components that `candidates` names for each placed moving
    /// component: penetrating and touching pairs always, separated pairs closer than `clearance` when it is positive.
    fn collect_pairs(
        &self,
        moving: &Part,
        rotation: DMat3,
        position: DVec3,
        clearance: f64,
        candidates: impl Fn(&PlacedConvex, f64) -> Vec<usize>,
    ) -> Vec<InterferencePair> {
        let (lo, hi) = moving.aabb();
        let tol = self.tolerance.linear.max(Tolerance::for_scale((hi - lo).length()).linear);
        let mut out = Vec::new();
        for (mi, c) in moving.components().iter().enumerate() {
            let placed = PlacedConvex::new(c, rotation, position);
            for k in candidates(&placed, tol) {
                let (fixed_part, fixed_piece, other) = &self.components[k];
                let contact = classify_pair(&placed, other, tol, clearance);
                let keep = match contact {
                    PairContact::Penetrating { .. } | PairContact::Touching { .. } => true,
                    PairContact::Separated { gap } => clearance > 0.0 && gap < clearance,
                };
                if keep {
                    out.push(InterferencePair {
                        moving_piece: mi,
                        fixed_part: *fixed_part,
                        fixed_piece: *fixed_piece,
                        contact,
                    });
                }
            }
        }
        out.sort_by_key(|p| (p.moving_piece, p.fixed_part, p.fixed_piece));
        out
    }

    /// Only the pairs whose interiors overlap by more than the tolerance (the list `L` of \[A\] eq. 8).
    pub fn penetrating_pairs(&self, moving: &Part, rotation: DMat3, position: DVec3) -> Vec<InterferencePair> {
        let mut v = self.interference_pairs(moving, rotation, position, 0.0);
        v.retain(|p| matches!(p.contact, PairContact::Penetrating { .. }));
        v
    }

    /// The tolerance of the scene.
    pub fn tolerance(&self) -> Tolerance {
        self.tolerance
    }
}
