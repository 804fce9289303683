//! Translational c-space obstacle of a convex pair: `C(A, B) = B (+) (-R A)` with full provenance.
//!
//! Paper: Ayyadevara et al. 2002 (\[A\]) Appendix B, eq. 12: `C(A, B) = ConvexHull{ V_j^B - R V_i^A }`; \[A\] VI-A-2
//! (section 6.1.2 of the manuscript) asks for both an H-representation and a face-based one. The moving component `A`
//! is placed by `x -> R x + p`; `p` interferes with the fixed component `B` iff `p` lies in the interior of `C`
//! (touching is not interference, \[A\] App. A).
//!
//! # Algorithm: overlay of the two Gauss maps
//!
//! Every face of a Minkowski sum of convex polytopes has an outer normal `u` and is the sum of the support sets of the
//! summands in direction `u` (`F_u(P + Q) = F_u(P) + F_u(Q)`). The face normals of the sum are the vertices of the
//! overlay of the two normal fans on the unit sphere:
//! 1. a face normal of `B` (then the face is that face of `B` plus the support feature of `-RA`: normally a vertex,
//!    an edge when the normal lies on an edge arc of `-RA`, a face when the two faces are parallel),
//! 2. a face normal of `-RA` (`-R n_f^A`), likewise,
//! 3. a proper crossing of an edge arc of `-RA` with an edge arc of `B` (a parallelogram spanned by the two edges).
//!
//! The arc of an edge is the great-circle arc between the normals of its two faces; its circle has the edge direction as
//! normal. Every decision on the sphere goes through one number per (arc, face normal) pair, `c_e . n_f`, classified
//! with the angular tolerance [`ANGULAR_TOLERANCE`]: the same numbers decide "normal lies on arc" (degenerate faces) and
//! "arcs cross properly" (edge-edge faces), so the two decisions cannot disagree. Two face normals closer than half the
//! tolerance are the same direction: the faces are parallel and give ONE merged face (exactly what prisms and boxes
//! produce all the time). A face polygon is built from the generating features: a face of `B` translated by a vertex
//! keeps `B`'s vertex cycle, a face of `A` keeps `A`'s (reversed by the point reflection), an edge pair gives a
//! parallelogram; only the degenerate merged faces need a 2-D convex sum `F + G` of the two generating polygons (a face,
//! or an edge as a 2-gon): the O(|F| + |G|) merge of their edge sequences by angle, on vertex labels, with the same
//! angular tolerance for parallel edges (`planar.rs`).
//!
//! Why a tolerance and not exact predicates: the input to this step is a *rotated* polytope whose coordinates are
//! already rounded (`cos(pi / 2)` is not 0 in `f64`), so exact parallelism of a rotated face with a fixed one cannot be
//! decided from the data; the tolerance (1e-9 rad, the policy's [`stackplan_geom::tolerance::RELATIVE`]) is six orders
//! above rounding noise and merging faces closer than it moves vertices by less than `1e-9 * size`, inside the
//! policy's length tolerance. Rotations about `z` keep `z` components exact, so horizontal faces merge exactly.
//!
//! The result is assembled into a [`ConvexPolytope`] with an edge table that is checked while it is built (every edge
//! shared by exactly two consistently oriented faces; `edge_table.rs`, exactly geom's table); Euler's formula is
//! checked too. If the overlay was inconsistent (only possible for input
//! within the tolerance of a degenerate configuration, not at one) the obstacle is built by the exact-predicate hull of
//! the `nA * nB` difference points instead ([`obstacle_by_hull`]), and the route is recorded in [`Obstacle::route`].
//!
//! Complexity: O(FA FB + EA EB + (FA + FB)(EA + EB) + output); with at most 64 arcs of `B` the arc crossings are
//! found as bit sets, O(EA (FB + crossings)) instead of O(EA EB); the pair loops are a few flops each, which for the
//! small components of sheet-metal parts beats the O(nA + nB + output) sweep of a true overlay (CGAL's
//! `Gaussian_map`); each merged face costs O(|F| + |G|). The face count is at most `4 m n - 9 m - 9 n + 26` for `m`
//! and `n` facets.
//!
//! Two z-prisms turned about `z` (sheet-metal plates under the planner's rotations) take one fast path, with the same
//! result bit for bit: for them the sign tables and the crossing pass are exact zeros by the data, and `z_prism.rs`
//! builds the same face list in O(FA FB + FB EA + FA EB) with far fewer products; for a *tame* such pair (the usual
//! one, away from quarter turns) it also reads every face cycle off the features (`z_prism::derived_cycles`) instead
//! of merging polygons. Both go through the same assembly.

use glam::{DMat3, DVec3};
use stackplan_geom::polytope::{ConvexPolytope, Face, Plane};
use stackplan_geom::{VertexCycle, convex_hull};

use crate::edge_table::{self, EdgeScratch};
use crate::planar::{PlanarScratch, face_plus_segment, planar_merge};
pub use crate::types::{ANGULAR_TOLERANCE, FaceKind, Feature, Obstacle, ObstacleError, OverlayFailure, Route};
use crate::types::{FaceSpec, PARALLEL_SQ, argmax};
use crate::z_prism;

/// The facet bound `4 m n - 9 m - 9 n + 26` of a Minkowski sum of 3-polytopes with `m` and `n` facets.
pub fn facet_bound(m: usize, n: usize) -> usize {
    (4 * m * n + 26).saturating_sub(9 * m + 9 * n)
}

/// The obstacle of moving `A` (rotation `rotation`) against fixed `B`: Gauss-map overlay, hull fallback.
pub fn obstacle(moving: &ConvexPolytope, rotation: DMat3, fixed: &ConvexPolytope) -> Result<Obstacle, ObstacleError> {
    if !rotation.is_finite() {
        return Err(ObstacleError::NonFiniteRotation);
    }
    match gauss_map_obstacle(moving, rotation, fixed) {
        Ok(o) => Ok(o),
        Err(reason) => {
            tracing::debug!(?reason, "Gauss-map overlay inconsistent; building the obstacle by the exact hull");
            obstacle_by_hull(moving, rotation, fixed)
        }
    }
}

/// The obstacle as the exact-predicate hull of the `nA * nB` difference points `b[j] - R a[i]`, with face kinds
/// inferred from the vertex provenance. O(nA nB log(nA nB)) expected. The reference route and the fallback.
pub fn obstacle_by_hull(
    moving: &ConvexPolytope,
    rotation: DMat3,
    fixed: &ConvexPolytope,
) -> Result<Obstacle, ObstacleError> {
    if !rotation.is_finite() {
        return Err(ObstacleError::NonFiniteRotation);
    }
    let ra: Vec<DVec3> = moving.vertices().iter().map(|a| rotation * *a).collect();
    let nb = fixed.vertices().len();
    let mut points = Vec::with_capacity(ra.len() * nb);
    for r in &ra {
        for b in fixed.vertices() {
            points.push(*b - *r);
        }
    }
    let hull = convex_hull(&points)?;
    let vertex_pairs: Vec<[usize; 2]> = hull.source.iter().map(|&k| [k / nb, k % nb]).collect();
    let face_kinds = hull
        .polytope
        .faces()
        .iter()
        .map(|f| {
            let mut is: Vec<usize> = f.vertices.iter().map(|&v| vertex_pairs[v][0]).collect();
            let mut js: Vec<usize> = f.vertices.iter().map(|&v| vertex_pairs[v][1]).collect();
            let moving_feature = identify_feature(moving, &mut is);
            let fixed_feature = identify_feature(fixed, &mut js);
            match (fixed_feature, moving_feature) {
                (Some(b), Some(a)) => FaceKind::from_features(b, a).unwrap_or(FaceKind::Unclassified),
                _ => FaceKind::Unclassified,
            }
        })
        .collect();
    Ok(Obstacle { polytope: hull.polytope, vertex_pairs, face_kinds, rotation, route: Route::Hull })
}

/// The smallest feature of `p` whose vertex set contains all of `ids` (sorted and deduplicated in place).
fn identify_feature(p: &ConvexPolytope, ids: &mut Vec<usize>) -> Option<Feature> {
    ids.sort_unstable();
    ids.dedup();
    match ids.len() {
        0 => None,
        1 => Some(Feature::Vertex(ids[0])),
        2 => p
            .edges()
            .iter()
            .position(|e| {
                let mut v = e.vertices;
                v.sort_unstable();
                v == [ids[0], ids[1]]
            })
            .map(Feature::Edge),
        _ => p.faces().iter().position(|f| ids.iter().all(|i| f.vertices.contains(i))).map(Feature::Face),
    }
}

#[derive(Clone, Copy)]
struct Arc {
    /// Unit circle normal, oriented so that the arc runs counter-clockwise about it from `from` to `to`.
    circle: DVec3,
    /// Face at the start of the arc.
    from: usize,
    /// Face at the end of the arc.
    to: usize,
}

/// Arcs of a polytope whose vertices are `vertices` and face normals `normals` (edge topology from `p`), into `out`.
fn arcs(p: &ConvexPolytope, vertices: &[DVec3], normals: &[DVec3], out: &mut Vec<Arc>) {
    out.clear();
    out.extend(p.edges().iter().map(|e| {
        let d = (vertices[e.vertices[1]] - vertices[e.vertices[0]]).normalize();
        let (n0, n1) = (normals[e.faces[0]], normals[e.faces[1]]);
        let circle = if n0.cross(n1).dot(d) >= 0.0 { d } else { -d };
        Arc { circle, from: e.faces[0], to: e.faces[1] }
    }));
}

#[inline]
fn tol_sign(v: f64) -> i8 {
    // branch-free: 1 above the tolerance, -1 below minus it, 0 within it (and for NaN)
    i8::from(v > ANGULAR_TOLERANCE) - i8::from(v < -ANGULAR_TOLERANCE)
}

/// `out[e * normals.len() + f]`: the side of `normals[f]` w.r.t. the circle of `arcs[e]` ([`tol_sign`]).
fn sign_table(arcs: &[Arc], normals: &[DVec3], out: &mut Vec<i8>) {
    out.clear();
    out.resize(arcs.len() * normals.len(), 0);
    if normals.is_empty() {
        return;
    }
    for (row, arc) in out.chunks_exact_mut(normals.len()).zip(arcs) {
        for (sign, n) in row.iter_mut().zip(normals) {
            *sign = tol_sign(arc.circle.dot(*n));
        }
    }
}

/// Whether `u` (already known to lie on the arc's circle) lies strictly inside the arc.
#[inline]
fn strictly_inside_arc(arc: &Arc, normals: &[DVec3], u: DVec3) -> bool {
    normals[arc.from].cross(u).dot(arc.circle) > 0.0 && u.cross(normals[arc.to]).dot(arc.circle) > 0.0
}

/// Working buffers of one overlay, kept per thread between calls: the overlay itself allocates nothing once they
/// have grown; only the result's own vectors are allocated.
#[derive(Default)]
struct Scratch {
    ra: Vec<DVec3>,
    neg_ra: Vec<DVec3>,
    am: Vec<DVec3>,
    bn: Vec<DVec3>,
    a_arcs: Vec<Arc>,
    b_arcs: Vec<Arc>,
    s_ab: Vec<i8>,
    s_ba: Vec<i8>,
    merged_with_b: Vec<Option<usize>>,
    merged_with_a: Vec<Option<usize>>,
    /// `from_mask[g]` / `to_mask[g]`: the B arcs (at most 64) starting / ending at B's face `g`, as bits.
    from_mask: Vec<u64>,
    to_mask: Vec<u64>,
    specs: Vec<FaceSpec>,
    index_of: Vec<u32>,
    cycle: Vec<[usize; 2]>,
    planar: PlanarScratch,
    edges: EdgeScratch,
    prism: z_prism::Scratch,
}

impl Scratch {
    /// The summands as the overlay sums them: the vertices `R a` and `-R a` of the moving polytope, the unit face
    /// normals `-R n` of `-RA` and the face normals of `B`; no parallel faces and no face specs yet. O(VA + FA + FB).
    fn prepare(&mut self, moving: &ConvexPolytope, rotation: DMat3, fixed: &ConvexPolytope) {
        let Self { ra, neg_ra, am, bn, merged_with_b, merged_with_a, specs, .. } = self;
        ra.clear();
        ra.extend(moving.vertices().iter().map(|a| rotation * *a));
        // -RA: vertices -ra, normals -R n; edge arcs computed from -ra.
        neg_ra.clear();
        neg_ra.extend(ra.iter().map(|r| -*r));
        am.clear();
        am.extend(moving.faces().iter().map(|f| -(rotation * f.plane.normal).normalize()));
        bn.clear();
        bn.extend(fixed.faces().iter().map(|f| f.plane.normal));
        // parallel faces: merged_with_b[f] = Some(g) when -R n_f == n_g within half the tolerance.
        merged_with_b.clear();
        merged_with_b.resize(am.len(), None);
        merged_with_a.clear();
        merged_with_a.resize(bn.len(), None);
        specs.clear();
    }
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
}

/// The Gauss-map route alone, without the hull fallback (for tests and benchmarks).
pub fn gauss_map_obstacle(
    moving: &ConvexPolytope,
    rotation: DMat3,
    fixed: &ConvexPolytope,
) -> Result<Obstacle, OverlayFailure> {
    // the per-thread buffers, or fresh ones when they are in use (re-entrant call) or gone (thread exit)
    SCRATCH
        .try_with(|cell| match cell.try_borrow_mut() {
            Ok(mut scratch) => Some(overlay(moving, rotation, fixed, &mut scratch)),
            Err(_) => None,
        })
        .ok()
        .flatten()
        .unwrap_or_else(|| overlay(moving, rotation, fixed, &mut Scratch::default()))
}

/// The overlay of `-RA` and `B`: the z-prism route for two z-prisms turned about `z` (sheet metal, `z_prism.rs`),
/// else the general one; the same obstacle either way, bit for bit.
fn overlay(
    moving: &ConvexPolytope,
    rotation: DMat3,
    fixed: &ConvexPolytope,
    scratch: &mut Scratch,
) -> Result<Obstacle, OverlayFailure> {
    scratch.prepare(moving, rotation, fixed);
    let Scratch { neg_ra, am, bn, prism, .. } = scratch;
    let z_prisms = z_prism::vertical_arcs(moving, neg_ra, am, &mut prism.a_classes, &mut prism.a)
        && z_prism::vertical_arcs(fixed, fixed.vertices(), bn, &mut prism.b_classes, &mut prism.b);
    if z_prisms {
        prism_overlay(moving, rotation, fixed, scratch)
    } else {
        general_overlay(moving, rotation, fixed, scratch)
    }
}

/// The overlay of two z-prisms turned about `z` (vertical arcs from `z_prism::vertical_arcs` in `scratch.prism`): the
/// general route's face specs without sign tables or arc crossings ([`prism_specs`]), and for a *tame* pair its face
/// cycles read off the features (`z_prism::derived_cycles`) instead of the polygon merges; the general assembly.
fn prism_overlay(
    moving: &ConvexPolytope,
    rotation: DMat3,
    fixed: &ConvexPolytope,
    scratch: &mut Scratch,
) -> Result<Obstacle, OverlayFailure> {
    let pair = prism_specs(fixed, scratch)?;
    let Scratch { neg_ra, am, bn, specs, prism, .. } = scratch;
    let derived = pair.tame && z_prism::derived_cycles(moving, fixed, neg_ra, am, bn, specs, prism);
    prism_assemble(moving, rotation, fixed, scratch, pair, derived)
}

/// What [`prism_specs`] found out about a z-prism pair.
#[derive(Clone, Copy)]
struct PrismPair {
    /// The merged pole faces need no faces across their edges: faces merged only within a class, and no side face
    /// merged (`z_prism::no_side_merged`).
    pole_faces_alone: bool,
    /// Tame so far: faces merged only within a class, and every side normal inside the arc that supports it by more
    /// than `z_prism::MARGIN` (what `z_prism::derived_cycles` requires of its caller).
    tame: bool,
}

/// The face specs of a z-prism pair into `scratch.specs` (`z_prism::face_specs`: the general route's steps 1 and 2
/// from exact zeros of the data; step 3 is empty). O(FA FB + FB EA_v + FA EB_v).
fn prism_specs(fixed: &ConvexPolytope, scratch: &mut Scratch) -> Result<PrismPair, OverlayFailure> {
    let Scratch { neg_ra, am, bn, merged_with_a, merged_with_b, specs, prism, .. } = scratch;
    // as the general route: all parallel pairs (within a class when the poles are far from the sides)
    let by_class = z_prism::parallel_faces(am, bn, &prism.a_classes, &prism.b_classes, merged_with_a, merged_with_b);
    if !by_class {
        all_parallel_faces(am, bn, merged_with_a, merged_with_b);
    }
    let mut margin = f64::INFINITY;
    let (arcs, bv) = ((prism.a.as_slice(), prism.b.as_slice()), fixed.vertices());
    z_prism::face_specs(am, bn, arcs, neg_ra, bv, merged_with_a, merged_with_b, specs, &mut margin)?;
    Ok(PrismPair {
        pole_faces_alone: by_class && z_prism::no_side_merged(&prism.a_classes, merged_with_b),
        tame: by_class && margin > z_prism::MARGIN,
    })
}

/// The obstacle of a z-prism pair from its face specs ([`prism_specs`]): from the cycles of `z_prism::derived_cycles`
/// when `derived` (it accepted the pair), else by the general assembly's polygon merges.
fn prism_assemble(
    moving: &ConvexPolytope,
    rotation: DMat3,
    fixed: &ConvexPolytope,
    scratch: &mut Scratch,
    pair: PrismPair,
    derived: bool,
) -> Result<Obstacle, OverlayFailure> {
    let Scratch { ra, neg_ra, merged_with_b, specs, index_of, cycle, planar, edges, prism, .. } = scratch;
    let plain = if pair.pole_faces_alone { Some(prism.b_classes.as_slice()) } else { None };
    let cycles = if derived { Some((prism.cycles.as_slice(), prism.starts.as_slice())) } else { None };
    let buffers = AssemblyBuffers { index_of, cycle, planar, merged_with_b, neg_ra, edges, plain, cycles };
    assemble(moving, fixed, rotation, ra, specs, buffers)
}

/// The general overlay of `-RA` and `B` (`scratch` prepared): steps 1-3 of the module documentation from the sign
/// tables, then the general assembly. O(FA FB + EA EB + (FA + FB)(EA + EB) + output).
fn general_overlay(
    moving: &ConvexPolytope,
    rotation: DMat3,
    fixed: &ConvexPolytope,
    scratch: &mut Scratch,
) -> Result<Obstacle, OverlayFailure> {
    let Scratch {
        ra,
        neg_ra,
        am,
        bn,
        a_arcs,
        b_arcs,
        s_ab,
        s_ba,
        merged_with_b,
        merged_with_a,
        from_mask,
        to_mask,
        specs: faces,
        index_of,
        cycle,
        planar,
        edges,
        ..
    } = scratch;
    let bv = fixed.vertices();
    let (fa, fb) = (am.len(), bn.len());
    all_parallel_faces(am, bn, merged_with_a, merged_with_b);
    arcs(moving, neg_ra, am, a_arcs);
    arcs(fixed, bv, bn, b_arcs);
    let (am, bn, a_arcs, b_arcs) = (&*am, &*bn, &*a_arcs, &*b_arcs);

    // sides: s_ab[e * fb + g] = side of B's normal g w.r.t. the circle of A-arc e; s_ba[e * fa + f] likewise.
    sign_table(a_arcs, bn, s_ab);
    sign_table(b_arcs, am, s_ba);
    let (s_ab, s_ba) = (&*s_ab, &*s_ba);

    // 1. faces of B
    for (g, &u) in bn.iter().enumerate() {
        let moving_feature = if let Some(f) = merged_with_a[g] {
            Feature::Face(f)
        } else {
            let mut found = None;
            for (e, arc) in a_arcs.iter().enumerate() {
                if s_ab[e * fb + g] == 0 && strictly_inside_arc(arc, am, u) {
                    if found.is_some() {
                        return Err(OverlayFailure::AmbiguousSupport);
                    }
                    found = Some(e);
                }
            }
            match found {
                Some(e) => Feature::Edge(e),
                None => Feature::Vertex(argmax(neg_ra, u)),
            }
        };
        faces.push(FaceSpec { normal: u, fixed: Feature::Face(g), moving: moving_feature });
    }
    // 2. faces of -RA not parallel to a face of B
    for (f, &u) in am.iter().enumerate() {
        if merged_with_b[f].is_some() {
            continue;
        }
        let mut found = None;
        for (e, arc) in b_arcs.iter().enumerate() {
            if s_ba[e * fa + f] == 0 && strictly_inside_arc(arc, bn, u) {
                if found.is_some() {
                    return Err(OverlayFailure::AmbiguousSupport);
                }
                found = Some(e);
            }
        }
        let fixed_feature = match found {
            Some(e) => Feature::Edge(e),
            None => Feature::Vertex(argmax(bv, u)),
        };
        faces.push(FaceSpec { normal: u, fixed: fixed_feature, moving: Feature::Face(f) });
    }
    // 3. proper arc crossings, in (A arc, B arc) order
    let sums = Sums { am, bn, a_arcs, b_arcs, s_ab, s_ba };
    if b_arcs.len() <= 64 {
        crossings_by_bit_sets(&sums, from_mask, to_mask, faces);
    } else {
        crossings_one_by_one(&sums, faces);
    }
    let buffers = AssemblyBuffers { index_of, cycle, planar, merged_with_b, neg_ra, edges, plain: None, cycles: None };
    assemble(moving, fixed, rotation, ra, faces, buffers)
}

/// The two Gauss maps as the arc crossings read them: the face normals of `-RA` and `B`, their arcs, and the sign
/// tables (`s_ab[e * FB + g]`: the side of `B`'s normal `g` of the circle of `-RA`'s arc `e`; `s_ba` likewise).
struct Sums<'a> {
    am: &'a [DVec3],
    bn: &'a [DVec3],
    a_arcs: &'a [Arc],
    b_arcs: &'a [Arc],
    s_ab: &'a [i8],
    s_ba: &'a [i8],
}

/// The edge-edge face of the arc `ea` of `-RA` and the arc `eb` of `B`, whose end normals lie strictly on opposite
/// sides of the circle of `ea` (checked by the caller), when they cross properly: the ends of `ea` strictly on
/// opposite sides of the circle of `eb`, and the crossing point the one on both arcs (not its antipode).
#[inline]
fn push_crossing(sums: &Sums<'_>, (ea, a_arc): (usize, &Arc), (eb, b_arc): (usize, &Arc), faces: &mut Vec<FaceSpec>) {
    let Sums { am, bn, s_ba, .. } = *sums;
    let fa = am.len();
    let (sa0, sa1) = (s_ba[eb * fa + a_arc.from], s_ba[eb * fa + a_arc.to]);
    if sa0 == 0 || sa0 != -sa1 {
        return;
    }
    let mut x = a_arc.circle.cross(b_arc.circle);
    if x.dot(am[a_arc.from] + am[a_arc.to]) < 0.0 {
        x = -x;
    }
    if x.dot(bn[b_arc.from] + bn[b_arc.to]) <= 0.0 {
        return;
    }
    faces.push(FaceSpec { normal: x.normalize(), fixed: Feature::Edge(eb), moving: Feature::Edge(ea) });
}

/// Step 3 by the definition: for every arc of `-RA`, every arc of `B` whose end normals lie strictly on opposite sides
/// of its circle ([`push_crossing`] tests the rest). O(EA EB).
fn crossings_one_by_one(sums: &Sums<'_>, faces: &mut Vec<FaceSpec>) {
    let fb = sums.bn.len();
    for (ea, a_arc) in sums.a_arcs.iter().enumerate() {
        let row = &sums.s_ab[ea * fb..(ea + 1) * fb];
        for (eb, b_arc) in sums.b_arcs.iter().enumerate() {
            let (sb0, sb1) = (row[b_arc.from], row[b_arc.to]);
            if sb0 == 0 || sb0 != -sb1 {
                continue;
            }
            push_crossing(sums, (ea, a_arc), (eb, b_arc), faces);
        }
    }
}

/// [`crossings_one_by_one`] for at most 64 arcs of `B`, as bit sets: with `from_mask[g]` / `to_mask[g]` the arcs of
/// `B` starting / ending at `B`'s face `g`, the arcs from a face on the positive side of an arc's circle to one on the
/// negative side are `(OR of from_mask over positive g) & (OR of to_mask over negative g)`, and vice versa: the same
/// pairs (the same signs), visited in the same order. O(EA (FB + crossings)).
fn crossings_by_bit_sets(sums: &Sums<'_>, from_mask: &mut Vec<u64>, to_mask: &mut Vec<u64>, faces: &mut Vec<FaceSpec>) {
    let fb = sums.bn.len();
    debug_assert!(sums.b_arcs.len() <= 64);
    from_mask.clear();
    from_mask.resize(fb, 0);
    to_mask.clear();
    to_mask.resize(fb, 0);
    for (eb, b_arc) in sums.b_arcs.iter().enumerate() {
        from_mask[b_arc.from] |= 1 << eb;
        to_mask[b_arc.to] |= 1 << eb;
    }
    for (ea, a_arc) in sums.a_arcs.iter().enumerate() {
        let row = &sums.s_ab[ea * fb..(ea + 1) * fb];
        let (mut from_pos, mut from_neg, mut to_pos, mut to_neg) = (0u64, 0u64, 0u64, 0u64);
        for ((&sign, &from), &to) in row.iter().zip(from_mask.iter()).zip(to_mask.iter()) {
            // all ones where the sign is +1 (resp. -1), else zero
            let (pos, neg) = (0u64.wrapping_sub(u64::from(sign == 1)), 0u64.wrapping_sub(u64::from(sign == -1)));
            from_pos |= from & pos;
            from_neg |= from & neg;
            to_pos |= to & pos;
            to_neg |= to & neg;
        }
        let mut candidates = (from_pos & to_neg) | (from_neg & to_pos);
        while candidates != 0 {
            let eb = candidates.trailing_zeros() as usize;
            candidates &= candidates - 1;
            push_crossing(sums, (ea, a_arc), (eb, &sums.b_arcs[eb]), faces);
        }
    }
}

/// The parallel faces of `-RA` (normals `am`) and `B` (normals `bn`): every pair whose unit normals are within half
/// the angular tolerance, in (face of `-RA`, face of `B`) order, the last match kept.
fn all_parallel_faces(
    am: &[DVec3],
    bn: &[DVec3],
    merged_with_a: &mut [Option<usize>],
    merged_with_b: &mut [Option<usize>],
) {
    for (f, m) in am.iter().enumerate() {
        for (g, n) in bn.iter().enumerate() {
            if (*m - *n).length_squared() <= PARALLEL_SQ {
                merged_with_b[f] = Some(g);
                merged_with_a[g] = Some(f);
            }
        }
    }
}

/// The scratch buffers [`assemble`] works in.
struct AssemblyBuffers<'a> {
    /// `index_of[i * nB + j]`: the obstacle vertex of the pair `(i, j)`, `u32::MAX` if none yet.
    index_of: &'a mut Vec<u32>,
    /// The vertex-pair cycle of the face being built.
    cycle: &'a mut Vec<[usize; 2]>,
    planar: &'a mut PlanarScratch,
    /// `merged_with_b[f] = Some(g)`: face `f` of `-RA` and face `g` of `B` are parallel (one face of the sum).
    merged_with_b: &'a [Option<usize>],
    /// The vertices of `-RA`.
    neg_ra: &'a [DVec3],
    /// The edge table's buffers.
    edges: &'a mut EdgeScratch,
    /// `Some(classes of B's faces)` when the merged faces of two poles (`z_prism.rs`) need no faces across their
    /// edges: the test that reads them cannot succeed (see `z_prism::no_side_merged`).
    plain: Option<&'a [u8]>,
    /// `Some((cycles, starts))`: the vertex-pair cycle of face `s` is `cycles[starts[s]..starts[s + 1]]`, derived
    /// without the polygon merges (`z_prism::derived_cycles`).
    cycles: Option<(&'a [[usize; 2]], &'a [usize])>,
}

#[allow(clippy::too_many_arguments)]
fn assemble(
    moving: &ConvexPolytope,
    fixed: &ConvexPolytope,
    rotation: DMat3,
    ra: &[DVec3],
    specs: &[FaceSpec],
    buffers: AssemblyBuffers<'_>,
) -> Result<Obstacle, OverlayFailure> {
    let AssemblyBuffers {
        index_of,
        cycle,
        planar: scratch,
        merged_with_b,
        neg_ra,
        edges: edge_scratch,
        plain,
        cycles: derived,
    } = buffers;
    let bv = fixed.vertices();
    let nb = bv.len();
    index_of.clear();
    index_of.resize(ra.len() * nb, u32::MAX);
    let mut vertices: Vec<DVec3> = Vec::with_capacity(specs.len() * 2);
    let mut vertex_pairs: Vec<[usize; 2]> = Vec::with_capacity(specs.len() * 2);
    let mut faces: Vec<Face> = Vec::with_capacity(specs.len());
    let mut kinds: Vec<FaceKind> = Vec::with_capacity(specs.len());
    edge_scratch.clear();
    // one face from its vertex-pair cycle: number its new vertices, its offset, its vertex list
    macro_rules! add_face {
        ($spec:expr, $corners:expr) => {{
            let (spec, corners): (&FaceSpec, &[[usize; 2]]) = ($spec, $corners);
            if corners.len() < 3 {
                return Err(OverlayFailure::FlatFace);
            }
            let mut face = VertexCycle::with_capacity(corners.len());
            let mut offset = f64::NEG_INFINITY;
            for &[i, j] in corners {
                let slot = &mut index_of[i * nb + j];
                if *slot == u32::MAX {
                    *slot = vertices.len() as u32;
                    vertices.push(bv[j] - ra[i]);
                    vertex_pairs.push([i, j]);
                    edge_scratch.vertex();
                }
                let v = *slot as usize;
                edge_scratch.corner(v);
                offset = offset.max(spec.normal.dot(vertices[v]));
                face.push(v);
            }
            faces.push(Face { vertices: face, plane: Plane { normal: spec.normal, offset } });
            kinds.push(FaceKind::from_features(spec.fixed, spec.moving).unwrap_or(FaceKind::Unclassified));
        }};
    }
    if let Some((cycles, starts)) = derived {
        for (spec, range) in specs.iter().zip(starts.windows(2)) {
            add_face!(spec, &cycles[range[0]..range[1]]);
        }
    } else {
        for spec in specs {
            cycle.clear();
            face_cycle(moving, fixed, ra, neg_ra, spec, merged_with_b, plain, scratch, cycle);
            add_face!(spec, cycle);
        }
    }
    let (v, f) = (vertices.len(), faces.len());
    // every face has a positive area by construction (a translated face of `A` or `B`, a sum containing one, or a
    // parallelogram of two edges that cross properly, i.e. are not parallel): only the edge table is checked. It is
    // built from the faces in the reused buffers; when it does not exist, geom's own table reports the same error.
    let polytope = match edge_table::build(v, &faces, edge_scratch) {
        Some((edges, face_edges)) => ConvexPolytope::from_faces_and_edges(vertices, faces, edges, face_edges),
        None => ConvexPolytope::from_faces_with_area(vertices, faces),
    }
    .map_err(OverlayFailure::Assembly)?;
    if v + f != polytope.edges().len() + 2 {
        return Err(OverlayFailure::Euler);
    }
    Ok(Obstacle { polytope, vertex_pairs, face_kinds: kinds, rotation, route: Route::GaussMap })
}

/// The vertex-pair cycle of the face `spec` into `cycle` (cleared by the caller), from its generating features.
#[allow(clippy::too_many_arguments)]
fn face_cycle(
    moving: &ConvexPolytope,
    fixed: &ConvexPolytope,
    ra: &[DVec3],
    neg_ra: &[DVec3],
    spec: &FaceSpec,
    merged_with_b: &[Option<usize>],
    plain: Option<&[u8]>,
    scratch: &mut PlanarScratch,
    cycle: &mut Vec<[usize; 2]>,
) {
    let bv = fixed.vertices();
    match (spec.fixed, spec.moving) {
        (Feature::Face(g), Feature::Vertex(i)) => {
            cycle.extend(fixed.faces()[g].vertices.iter().map(|&j| [i, j]));
        }
        (Feature::Vertex(j), Feature::Face(f)) => {
            cycle.extend(moving.faces()[f].vertices.iter().rev().map(|&i| [i, j]));
        }
        (Feature::Edge(eb), Feature::Edge(ea)) => {
            let [j0, j1] = fixed.edges()[eb].vertices;
            let [i0, i1] = moving.edges()[ea].vertices;
            // p00 -> p01 runs along B's edge, p01 -> p11 along -RA's edge
            let d_b = bv[j1] - bv[j0];
            let d_a = ra[i0] - ra[i1];
            if d_b.cross(d_a).dot(spec.normal) > 0.0 {
                cycle.extend([[i0, j0], [i0, j1], [i1, j1], [i1, j0]]);
            } else {
                cycle.extend([[i0, j0], [i1, j0], [i1, j1], [i0, j1]]);
            }
        }
        (Feature::Face(g), Feature::Edge(ea)) => {
            let corners = &fixed.faces()[g].vertices;
            let [i0, i1] = moving.edges()[ea].vertices;
            face_plus_segment::<true>(corners, bv, [i0, i1], neg_ra, spec.normal, &mut scratch.classes, cycle);
        }
        (Feature::Edge(eb), Feature::Face(f)) => {
            let corners = &mut scratch.a.corners;
            corners.clear();
            corners.extend(moving.faces()[f].vertices.iter().rev());
            let [j0, j1] = fixed.edges()[eb].vertices;
            face_plus_segment::<false>(corners, neg_ra, [j0, j1], bv, spec.normal, &mut scratch.classes, cycle);
        }
        (fixed_feature, moving_feature) => {
            let n = spec.normal;
            let both_faces = match (fixed_feature, moving_feature) {
                (Feature::Face(g), Feature::Face(_)) => !plain.is_some_and(|c| z_prism::is_pole(c[g])),
                _ => false,
            };
            let r = scratch.b.build(fixed, fixed_feature, false, bv, n, None, both_faces);
            scratch.a.build(moving, moving_feature, true, neg_ra, n, Some(r), both_faces);
            planar_merge(merged_with_b, n, both_faces, scratch, cycle);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::z_prism::tests::{prism, scaled};

    fn cuboid(lo: DVec3, hi: DVec3) -> ConvexPolytope {
        ConvexPolytope::cuboid(lo, hi).expect("box")
    }

    #[test]
    fn box_box_identity_is_a_box() {
        let a = cuboid(DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0));
        let b = cuboid(DVec3::ZERO, DVec3::new(4.0, 5.0, 6.0));
        let o = obstacle(&a, DMat3::IDENTITY, &b).expect("obstacle");
        assert_eq!(o.route(), Route::GaussMap);
        assert_eq!(o.polytope().vertices().len(), 8);
        assert_eq!(o.polytope().faces().len(), 6);
        o.polytope().validate().expect("valid");
        assert!((o.polytope().volume() - 5.0 * 7.0 * 9.0).abs() < 1e-9);
        assert!(o.face_kinds().iter().all(|k| matches!(k, FaceKind::FaceFace { .. })));
        let (lo, hi) = o.polytope().aabb();
        assert_eq!(lo, DVec3::new(-1.0, -2.0, -3.0));
        assert_eq!(hi, DVec3::new(4.0, 5.0, 6.0));
    }

    #[test]
    fn rotated_boxes_about_z() {
        let a = cuboid(DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0));
        let b = cuboid(DVec3::ZERO, DVec3::new(4.0, 5.0, 6.0));
        let o = obstacle(&a, DMat3::from_rotation_z(0.3), &b).expect("obstacle");
        assert_eq!(o.route(), Route::GaussMap);
        o.polytope().validate().expect("valid");
        // octagonal prism: 8 vertical faces + top + bottom
        assert_eq!(o.polytope().faces().len(), 10);
        assert_eq!(o.polytope().vertices().len(), 16);
        let h = obstacle_by_hull(&a, DMat3::from_rotation_z(0.3), &b).expect("hull");
        assert!((h.polytope().volume() - o.polytope().volume()).abs() < 1e-9);
    }

    #[test]
    fn crossing_bit_sets_equal_the_one_by_one_test() {
        // pairs with edge-edge faces (general rotations, point clouds) and without (boxes and prisms about z)
        let cloud = |n: usize, seed: f64| {
            let pts: Vec<DVec3> = (0..n)
                .map(|k| {
                    let t = k as f64 * 2.399 + seed;
                    let z = 1.0 - 2.0 * (k as f64 + 0.5) / n as f64;
                    let r = (1.0 - z * z).sqrt();
                    DVec3::new(r * t.cos() * 3.0, r * t.sin() * 2.0, z)
                })
                .collect();
            convex_hull(&pts).expect("hull").polytope
        };
        let shapes = [
            cuboid(DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0)),
            cuboid(DVec3::new(-1.0, 0.5, 0.0), DVec3::new(4.0, 5.0, 0.5)),
            cloud(8, 0.0),
            cloud(14, 0.3),
            cloud(24, 0.7),
        ];
        let rotations = [
            DMat3::IDENTITY,
            DMat3::from_rotation_z(0.3),
            DMat3::from_rotation_x(std::f64::consts::FRAC_PI_2),
            DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7),
            DMat3::from_axis_angle(DVec3::new(-0.3, 0.2, 1.0).normalize(), 2.1),
        ];
        let mut s = Scratch::default();
        let (mut pairs, mut crossings) = (0, 0);
        for a in &shapes {
            for b in &shapes {
                for r in rotations {
                    s.prepare(a, r, b);
                    let Scratch { neg_ra, am, bn, a_arcs, b_arcs, s_ab, s_ba, from_mask, to_mask, .. } = &mut s;
                    arcs(a, neg_ra, am, a_arcs);
                    arcs(b, b.vertices(), bn, b_arcs);
                    if b_arcs.len() > 64 {
                        continue;
                    }
                    sign_table(a_arcs, bn, s_ab);
                    sign_table(b_arcs, am, s_ba);
                    let sums = Sums { am, bn, a_arcs, b_arcs, s_ab, s_ba };
                    let (mut bits, mut one_by_one) = (Vec::new(), Vec::new());
                    crossings_by_bit_sets(&sums, from_mask, to_mask, &mut bits);
                    crossings_one_by_one(&sums, &mut one_by_one);
                    let key = |f: &FaceSpec| (f.normal.to_array().map(f64::to_bits), f.fixed, f.moving);
                    assert_eq!(
                        bits.iter().map(key).collect::<Vec<_>>(),
                        one_by_one.iter().map(key).collect::<Vec<_>>()
                    );
                    pairs += 1;
                    crossings += bits.len();
                }
            }
        }
        assert!(pairs >= 80 && crossings > 100, "{pairs} pairs, {crossings} crossings");
    }

    #[test]
    fn z_prism_route_equals_the_general_overlay() {
        // boxes, the bench's hexagons, regular and irregular outlines (some sharing edge directions), extruded along
        // z (the z-prism route) or x (the general one); rotations about z at generic angles, quarter turns (rounded
        // and exact), angles around the angular tolerance, and one general rotation
        let hex = [(0.0, 0.0), (60.0, 0.0), (90.0, 30.0), (80.0, 70.0), (20.0, 80.0), (-10.0, 40.0)];
        let mut shapes = vec![
            ConvexPolytope::cuboid(DVec3::ZERO, DVec3::new(100.0, 50.0, 2.0)).expect("box"),
            ConvexPolytope::cuboid(DVec3::new(-1.0, 0.5, 0.0), DVec3::new(4.0, 5.0, 6.0)).expect("box"),
            prism(&hex, 0.0, 2.0, 2),
            prism(&hex.map(|(x, y)| (x * 0.7, y * 0.7)), 0.0, 2.0, 2),
            prism(&[(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 2.0)], -0.5, 0.25, 2),
            prism(&[(0.0, 0.0), (1.5, 0.5), (0.5, 1.5)], 0.0, 0.75, 2),
            prism(&[(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 2.0)], -0.5, 0.25, 0),
            // squared lengths that overflow and underflow (circles of zero length, or refused)
            scaled(1e160),
            scaled(1e-170),
        ];
        for (n, turn) in [(5, 0.1), (8, 0.0), (7, 1.3)] {
            let outline: Vec<(f64, f64)> = (0..n)
                .map(|k| {
                    let t = turn + k as f64 * std::f64::consts::TAU / n as f64;
                    (3.0 * t.cos(), 2.0 * t.sin())
                })
                .collect();
            shapes.push(prism(&outline, -1.0, 1.0, 2));
        }
        let mut rotations: Vec<DMat3> = (0..52).map(|k| DMat3::from_rotation_z(k as f64 * 0.1234)).collect();
        for t in [1e-12, 3e-10, 5e-10, 7e-10, 1e-9, 2e-9, 1e-6] {
            rotations.push(DMat3::from_rotation_z(t));
            rotations.push(DMat3::from_rotation_z(-t));
            rotations.push(DMat3::from_rotation_z(std::f64::consts::FRAC_PI_2 + t));
        }
        for k in 1..8 {
            rotations.push(DMat3::from_rotation_z(k as f64 * std::f64::consts::FRAC_PI_4));
        }
        rotations.push(DMat3::from_cols(DVec3::Y, -DVec3::X, DVec3::Z));
        rotations.push(DMat3::from_cols(-DVec3::X, -DVec3::Y, DVec3::Z));
        rotations.push(DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7));
        // the z-prisms among them (not the x-extruded one; not the tiny box, whose vertical edges' squared lengths
        // underflow; the 7-gon is one because the hull computes its face planes accurately: a plainly computed top
        // normal has a rounded x of 3e-17)
        let z_prisms = shapes
            .iter()
            .filter(|s| {
                let n: Vec<DVec3> = s.faces().iter().map(|f| f.plane.normal).collect();
                z_prism::vertical_arcs(s, s.vertices(), &n, &mut Vec::new(), &mut Vec::new())
            })
            .count();
        assert_eq!(z_prisms, 10);
        let mut s = Scratch::default();
        let (mut cases, mut prism_pairs, mut tame_pairs) = (0, 0, 0);
        for a in &shapes {
            for b in &shapes {
                for &r in &rotations {
                    // the obstacle (the z-prism route where it applies) against the general overlay
                    let fast = format!("{:?}", gauss_map_obstacle(a, r, b));
                    s.prepare(a, r, b);
                    let general = format!("{:?}", general_overlay(a, r, b, &mut s));
                    assert_eq!(fast, general, "{a:?} {r:?} {b:?}");
                    cases += 1;
                    // the z-prism route's two assemblies, each against the general overlay: by the polygon merges
                    // (every z-prism pair) and from the derived cycles (the tame pairs)
                    s.prepare(a, r, b);
                    let Scratch { neg_ra, am, bn, prism, .. } = &mut s;
                    if !(z_prism::vertical_arcs(a, neg_ra, am, &mut prism.a_classes, &mut prism.a)
                        && z_prism::vertical_arcs(b, b.vertices(), bn, &mut prism.b_classes, &mut prism.b))
                    {
                        continue;
                    }
                    prism_pairs += 1;
                    let pair = match prism_specs(b, &mut s) {
                        Ok(pair) => pair,
                        Err(e) => {
                            assert_eq!(format!("{:?}", Err::<Obstacle, _>(e)), general);
                            continue;
                        }
                    };
                    let merged = format!("{:?}", prism_assemble(a, r, b, &mut s, pair, false));
                    assert_eq!(merged, general, "{a:?} {r:?} {b:?}");
                    let Scratch { neg_ra, am, bn, specs, prism, .. } = &mut s;
                    if pair.tame && z_prism::derived_cycles(a, b, neg_ra, am, bn, specs, prism) {
                        tame_pairs += 1;
                        let derived = format!("{:?}", prism_assemble(a, r, b, &mut s, pair, true));
                        assert_eq!(derived, general, "{a:?} {r:?} {b:?}");
                    }
                }
            }
        }
        // every pair of z-prisms under every rotation about z (all but the last rotation), and no other
        assert_eq!(prism_pairs, z_prisms * z_prisms * (rotations.len() - 1), "{prism_pairs} of {cases}");
        // the tame pairs (most pairs at generic angles; not the quarter turns, not within 1e-6 of one, not the huge
        // box) assembled from their derived cycles
        assert!(tame_pairs * 2 > prism_pairs && tame_pairs < prism_pairs, "{tame_pairs} of {prism_pairs} tame");
    }

    #[test]
    fn per_thread_buffers_do_not_leak_between_obstacles() {
        // a large pair between two builds of a small one: the reused buffers must not change the result
        let a = cuboid(DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0));
        let b = cuboid(DVec3::new(-1.0, 0.5, 0.0), DVec3::new(4.0, 5.0, 6.0));
        let r = DMat3::from_rotation_z(0.3);
        let first = gauss_map_obstacle(&a, r, &b).expect("obstacle");
        let pts: Vec<DVec3> = (0..40)
            .map(|k| {
                let t = k as f64 * 0.7;
                DVec3::new(t.cos() * 5.0, t.sin() * 5.0, (k % 7) as f64 - 3.0)
            })
            .collect();
        let big = convex_hull(&pts).expect("hull").polytope;
        let other = gauss_map_obstacle(&big, DMat3::from_rotation_x(0.2), &big).expect("obstacle");
        assert!(other.polytope().vertices().len() > first.polytope().vertices().len());
        let again = gauss_map_obstacle(&a, r, &b).expect("obstacle");
        assert_eq!(format!("{first:?}"), format!("{again:?}"));
    }
}
