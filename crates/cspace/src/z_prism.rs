//! The Gauss-map overlay of two z-prisms turned about `z`: the sheet-metal case of [`crate::minkowski`], exactly.
//!
//! Paper: Ayyadevara et al. 2002 (\[A\]) App. B, eq. 12 (`C(A, B) = ConvexHull{ V_j^B - R V_i^A }`); the overlay of the
//! two normal fans is the one of [`crate::minkowski`] (its module documentation has the algorithm and the tolerance).
//!
//! A *z-prism* here is a polytope whose every face normal is either a **side** normal (`z` component exactly 0) or a
//! **pole** (`x` and `y` components exactly 0), whose edges between two side faces are exactly vertical (end points
//! with equal `x` and `y`), whose edges between a side face and a pole are exactly horizontal (equal `z`), and with no
//! edge between two poles; for `-RA` this is tested on the rotated data, so it holds for a z-prism rotated about `z`
//! (`R` keeps `z` components exact) and fails otherwise. Sheet-metal plates and their obstacles under the planner's
//! rotations about `z` are such pairs. For them most numbers the general overlay computes are exactly zero, by the
//! data, not by a tolerance:
//!
//! * the circle of a vertical edge's arc is `(±0, ±0, c)`, so its product with a side normal is exactly `±0`; the
//!   circle of a horizontal edge's arc is `(x, y, ±0)`, so its product with a pole is exactly `±0`;
//! * hence no two arcs cross properly (a crossing needs both end normals of each arc strictly on opposite sides of the
//!   other's circle, and every arc has an end normal with a zero product with the circles of the other kind): there
//!   are no `edge_edge` faces;
//! * a side normal lies strictly inside no horizontal arc (one of the two cross products the test takes is of two side
//!   normals, `(±0, ±0, w)`, against a circle with zero `z`: exactly `±0`, not positive), and a pole lies strictly
//!   inside no arc at all (pole x pole is the zero vector; side x pole against a vertical circle is `±0`).
//!
//! So the support feature of a side face of one summand is found among the vertical arcs of the other with the
//! general route's own test (`strictly_inside_arc`, in the same order, with the same ambiguity check; with a circle
//! `(±0, ±0, c)` and normals with zero `z` its value is exactly `w * c` for the `z` component `w` of the cross
//! product, the only term computed here), a pole that is not merged with a face of the other summand is supported by a
//! vertex, and the face list is the general route's steps 1 and 2 with step 3 empty: the same `FaceSpec`s in the same
//! order, handed to the same assembly, so the obstacle is bit for bit the general route's (checked by
//! `examples/obstacle_identity.rs dump` and by `minkowski.rs`'s unit test on pairs of prisms at many angles).
//! What is saved: both sign tables (`EA FB + EB FA` products), the arc-crossing pass, the circles of the horizontal
//! arcs and most of the support tests' arithmetic.
//!
//! **Derived cycles**: for a *tame* pair ([`derived_cycles`]: two poles per summand, merged pairwise, no
//! side face merged, every side face a quadrilateral, edge lengths far from under- and overflow, unit side normals
//! orthogonal to their horizontal edges, every side normal at least [`MARGIN`] inside the arc holding it) the obstacle
//! is the extrusion `(b (+) (-R a)) x [b_lo - a_hi, b_hi - a_lo]` of the 2-D Minkowski sum of the cross-sections, and
//! every decision the general assembly takes for it (`face_plus_segment`, `planar_merge`) is the geometric one with
//! a wide margin. The face cycles are then read off the features: a side face of one summand plus a vertical edge of
//! the other is its quadrilateral with the top corners translated by the edge's top end and the bottom ones by its
//! bottom end; a pole of the obstacle is the chain of the side faces' edges on that pole, started where the merge
//! starts. Same cycles, same order, same assembly (numbering, offsets, edge table): bit for bit the general route's
//! (`minkowski.rs`'s unit test compares both assemblies of every tame pair with the general overlay).
//! Pairs that are not tame (quarter turns and rotations within 1e-6 rad of one, where side faces merge; a side face
//! supported by a vertex; huge or tiny coordinates) keep the polygon merges.
//!
//! Complexity: O(E + F) to recognise the pair, O(FA FB) for the parallel faces (as in the general route),
//! O(FB EA_v + FA EB_v) for the support searches over the `EA_v`, `EB_v` vertical arcs, and O(V + output) for the
//! derived cycles.

use glam::DVec3;
use stackplan_geom::polytope::ConvexPolytope;

use crate::types::{FaceSpec, Feature, OverlayFailure, PARALLEL_SQ, argmax};

/// A vertical arc: its edge, the `x`, `y` of the normals at its start and end, and the `z` of its circle (the general
/// route's circle is `(±0, ±0, cz)`).
#[derive(Clone, Copy)]
pub(crate) struct VerticalArc {
    edge: usize,
    from: [f64; 2],
    to: [f64; 2],
    cz: f64,
}

/// Working buffers, kept per thread with the overlay's.
#[derive(Default)]
pub(crate) struct Scratch {
    /// [`derived_cycles`]: per vertex pair `i * nB + j` on a pole, the next corner of its pole face.
    next: Vec<u32>,
    /// [`derived_cycles`]: the faces' vertex-pair cycles, face `s` at `cycles[starts[s]..starts[s + 1]]`.
    pub(crate) cycles: Vec<[usize; 2]>,
    pub(crate) starts: Vec<usize>,
    /// [`derived_cycles`]: the pole (`BOTTOM`, `TOP`) of every vertex of `-RA` and of `B`.
    a_levels: Vec<u8>,
    b_levels: Vec<u8>,
    /// The kind of every face normal of `-RA` and of `B`: 0 side, 1 pole.
    pub(crate) a_classes: Vec<u8>,
    pub(crate) b_classes: Vec<u8>,
    /// The vertical arcs of `-RA` and of `B`.
    pub(crate) a: Vec<VerticalArc>,
    pub(crate) b: Vec<VerticalArc>,
}

const SIDE: u8 = 0;
const POLE: u8 = 1;

/// The levels of [`derived_cycles`]: a vertex on the bottom or the top pole (the index of that end of a vertical
/// edge in `[bottom, top]`).
const BOTTOM: u8 = 0;
const TOP: u8 = 1;

/// The squared lengths of the edges [`derived_cycles`] accepts (far from under- and overflow of the tolerance tests
/// of `minkowski::face_plus_segment` and `minkowski::planar_merge`, which multiply two squared lengths by
/// `PARALLEL_SQ`).
const TAME_LO: f64 = 1e-60;
const TAME_HI: f64 = 1e60;

/// The least value of the support tests (the sines of the angles between a side normal and the two ends of the arc
/// holding it, up to the circle's `|cz|`, which is 1 within an ulp for tame edges) that [`derived_cycles`] accepts:
/// two orders of magnitude above the angular tolerance, nine above rounding.
pub(crate) const MARGIN: f64 = 1e-7;

/// The vertical arcs of `p` (vertices `vertices`, face normals `normals`) into `out`, in edge order, when `p` is a
/// z-prism (see the module documentation), else `false` (the buffers then hold garbage). The circle is the general
/// route's (`minkowski::arcs`, the same operations); a vertical arc's must come out as `(±0, ±0, cz)` (it does unless
/// the normalisation divides by an underflowed length), a horizontal arc's is `d * s` for an edge vector `d` with
/// `d.z == 0` and some `s`: its `z` is `±0` or NaN, and either way its product with a pole is not a sign, and no test
/// with it is positive (NaN compares false), which is all the module documentation uses.
pub(crate) fn vertical_arcs(
    p: &ConvexPolytope,
    vertices: &[DVec3],
    normals: &[DVec3],
    classes: &mut Vec<u8>,
    out: &mut Vec<VerticalArc>,
) -> bool {
    classes.clear();
    for n in normals {
        classes.push(if n.z == 0.0 && n.x.is_finite() && n.y.is_finite() {
            SIDE
        } else if n.x == 0.0 && n.y == 0.0 && n.z.is_finite() {
            POLE
        } else {
            return false;
        });
    }
    out.clear();
    // `s` depends on `|d.z|` alone (`d.z * d.z` is exact in sign), and every vertical edge of a z-prism has the same
    // `|d.z|`: the square root and the division (long latency) are taken once per distinct `|d.z|` (bit for bit the
    // same `s`)
    let (mut last_abs, mut last_s) = (u64::MAX, f64::NAN);
    for (k, e) in p.edges().iter().enumerate() {
        let [f0, f1] = e.faces;
        let d = vertices[e.vertices[1]] - vertices[e.vertices[0]];
        match classes[f0] + classes[f1] {
            0 => {
                if !(d.x == 0.0 && d.y == 0.0) {
                    return false;
                }
                // the general route's circle (`minkowski::arcs`): `d.normalize()` is `d * s` with
                // `s = 1 / sqrt((0 * 0 + 0 * 0) + dz * dz)`, whose x and y are `±0` exactly when `s` is finite (else
                // NaN: refused); then `cz` is finite or NaN, and `w * cz` is the general route's test value up to
                // exact zeros
                let abs = d.z.abs().to_bits();
                if abs != last_abs {
                    (last_abs, last_s) = (abs, (d.z * d.z).sqrt().recip());
                }
                let s = last_s;
                if !s.is_finite() {
                    return false;
                }
                let (n0, n1) = (normals[f0], normals[f1]);
                // its orientation: `(n0 x n1) . d` is `(±0 + ±0) + w * cz` (glam's operand order), `>= 0` exactly when
                // `w * cz >= 0` (a zero of either sign passes, NaN fails)
                let cz = d.z * s;
                let w = n0.x * n1.y - n1.x * n0.y;
                let cz = if w * cz >= 0.0 { cz } else { -cz };
                out.push(VerticalArc { edge: k, from: [n0.x, n0.y], to: [n1.x, n1.y], cz });
            }
            1 => {
                if d.z != 0.0 {
                    return false;
                }
            }
            _ => return false,
        }
    }
    true
}

/// The parallel faces of a z-prism pair (classes from [`vertical_arcs`]) into `merged_with_a` / `merged_with_b`
/// (cleared, sized), exactly as the general route's loop over all pairs (`|m - n|^2 <= PARALLEL_SQ`, every pair in
/// the same order, the last match kept), but skipping the pairs of a side normal and a pole: their squared distance
/// is at least the pole's `z^2` (a sum of squares rounds to at least each term), so when every pole has
/// `z^2 > PARALLEL_SQ` no such pair can match. `false` (nothing written) when some pole does not.
pub(crate) fn parallel_faces(
    am: &[DVec3],
    bn: &[DVec3],
    a_classes: &[u8],
    b_classes: &[u8],
    merged_with_a: &mut [Option<usize>],
    merged_with_b: &mut [Option<usize>],
) -> bool {
    let far = |normals: &[DVec3], classes: &[u8]| {
        normals.iter().zip(classes).all(|(n, &c)| c != POLE || n.z * n.z > PARALLEL_SQ)
    };
    if !(far(am, a_classes) && far(bn, b_classes)) {
        return false;
    }
    for ((f, m), &cf) in am.iter().enumerate().zip(a_classes) {
        for ((g, n), &cg) in bn.iter().enumerate().zip(b_classes) {
            if cf == cg && (*m - *n).length_squared() <= PARALLEL_SQ {
                merged_with_b[f] = Some(g);
                merged_with_a[g] = Some(f);
            }
        }
    }
    true
}

/// Whether the class is a pole's.
#[inline]
pub(crate) fn is_pole(class: u8) -> bool {
    class == POLE
}

/// Whether no side face of `-RA` is merged with a face of `B`. Then, after [`parallel_faces`] (which merges only
/// normals of one class), the merged face of two poles needs no faces across its edges: the merge
/// (`minkowski::planar_merge`) reads them only in the test "the faces across both edges are merged", and every edge of
/// a pole face of a z-prism lies between the pole and a side face (no edge joins two poles), so the face of `-RA`
/// across it is a side face, merged with nothing: the test fails whatever the face of `B` across is, exactly as when
/// the merge is told that its polygons are not both faces.
pub(crate) fn no_side_merged(a_classes: &[u8], merged_with_b: &[Option<usize>]) -> bool {
    a_classes.iter().zip(merged_with_b).all(|(&c, m)| c == POLE || m.is_none())
}

/// The support feature of the other summand for the face normal `u` that is merged with none of its faces: an edge
/// whose (vertical) arc holds `u` strictly inside, else the vertex `argmax(points, u)`; as the general route decides
/// (every arc tested, two holding `u` are ambiguous). The least of the two support tests of the arc found goes into
/// `margin` (`-inf` for a side normal supported by a vertex). O(arcs + points).
#[inline]
fn support(u: DVec3, arcs: &[VerticalArc], points: &[DVec3], margin: &mut f64) -> Result<Feature, OverlayFailure> {
    if u.z != 0.0 {
        // a pole lies strictly inside no arc
        return Ok(Feature::Vertex(argmax(points, u)));
    }
    let mut found = None;
    for arc in arcs {
        // `strictly_inside_arc`: the z components of `from x u` and `u x to` (glam's operand order) times the
        // circle's z; the other terms of the general route's dot products are exact zeros
        let ([fx, fy], [tx, ty]) = (arc.from, arc.to);
        let (before, after) = ((fx * u.y - u.x * fy) * arc.cz, (u.x * ty - tx * u.y) * arc.cz);
        if before > 0.0 && after > 0.0 {
            if found.is_some() {
                return Err(OverlayFailure::AmbiguousSupport);
            }
            found = Some(arc.edge);
            *margin = margin.min(before.min(after));
        }
    }
    Ok(match found {
        Some(e) => Feature::Edge(e),
        None => {
            // a side face supported by a vertex: not the case [`derived_cycles`] handles
            *margin = f64::NEG_INFINITY;
            Feature::Vertex(argmax(points, u))
        }
    })
}

/// Steps 1 and 2 of the overlay (step 3, the arc crossings, is empty) for a z-prism pair whose vertical arcs
/// `(a_arcs, b_arcs)` came from [`vertical_arcs`]: the faces of `B`, then those of `-RA` not parallel to a face of
/// `B`, into `faces`; the least support test value of the side normals into `margin`. O(FB EA_v + FA EB_v + V).
#[allow(clippy::too_many_arguments)]
pub(crate) fn face_specs(
    am: &[DVec3],
    bn: &[DVec3],
    (a_arcs, b_arcs): (&[VerticalArc], &[VerticalArc]),
    neg_ra: &[DVec3],
    bv: &[DVec3],
    merged_with_a: &[Option<usize>],
    merged_with_b: &[Option<usize>],
    faces: &mut Vec<FaceSpec>,
    margin: &mut f64,
) -> Result<(), OverlayFailure> {
    for (g, &u) in bn.iter().enumerate() {
        let moving = match merged_with_a[g] {
            Some(f) => Feature::Face(f),
            None => support(u, a_arcs, neg_ra, margin)?,
        };
        faces.push(FaceSpec { normal: u, fixed: Feature::Face(g), moving });
    }
    for (f, &u) in am.iter().enumerate() {
        if merged_with_b[f].is_some() {
            continue;
        }
        let fixed = support(u, b_arcs, bv, margin)?;
        faces.push(FaceSpec { normal: u, fixed, moving: Feature::Face(f) });
    }
    Ok(())
}

/// The two poles of each summand of a z-prism pair, indexed by level (`[bottom, top]`, faces of `-RA` and of `B`).
struct Poles {
    a: [usize; 2],
    b: [usize; 2],
}

/// The first conditions of [`derived_cycles`]: each summand has exactly two poles, a top
/// (`+z`) and a bottom one, every vertex on one of them (its level into `scratch.a_levels` / `b_levels`), fewer than
/// `2^16` vertices, and a height (the length of every vertical edge) whose square is in `[TAME_LO, TAME_HI]`. `None`
/// (levels garbage) otherwise. O(V + F).
fn poles(
    moving: &ConvexPolytope,
    fixed: &ConvexPolytope,
    neg_ra: &[DVec3],
    am: &[DVec3],
    bn: &[DVec3],
    scratch: &mut Scratch,
) -> Option<Poles> {
    let Scratch { a_classes, b_classes, a_levels, b_levels, .. } = scratch;
    let bv = fixed.vertices();
    let (na, nb) = (neg_ra.len(), bv.len());
    // the two poles of each summand: (top face, bottom face)
    let poles = |normals: &[DVec3], classes: &[u8]| {
        let (mut top, mut bottom, mut count) = (usize::MAX, usize::MAX, 0);
        for (f, (n, &c)) in normals.iter().zip(classes.iter()).enumerate() {
            if c == POLE {
                count += 1;
                if n.z > 0.0 { top = f } else { bottom = f }
            }
        }
        (count == 2 && top != usize::MAX && bottom != usize::MAX).then_some((top, bottom))
    };
    let (Some((a_top, a_bottom)), Some((b_top, b_bottom))) = (poles(am, a_classes), poles(bn, b_classes)) else {
        return None;
    };
    // every vertex's pole (TOP, BOTTOM; else `None`)
    // (and the height `hi - lo`, exactly the difference of the z of any top and any bottom vertex)
    let levels = |p: &ConvexPolytope, points: &[DVec3], top: usize, bottom: usize, out: &mut Vec<u8>| {
        let (Some(&t), Some(&b)) = (p.faces()[top].vertices.first(), p.faces()[bottom].vertices.first()) else {
            return None;
        };
        let (hi, lo) = (points[t].z, points[b].z);
        out.clear();
        out.resize(points.len(), BOTTOM);
        let mut on_poles = hi > lo;
        for (level, v) in out.iter_mut().zip(points) {
            *level = u8::from(v.z == hi);
            on_poles &= (v.z == hi) | (v.z == lo);
        }
        on_poles.then_some(hi - lo)
    };
    let (Some(a_height), Some(b_height)) =
        (levels(moving, neg_ra, a_top, a_bottom, a_levels), levels(fixed, bv, b_top, b_bottom, b_levels))
    else {
        return None;
    };
    // tame: the vertical edges (all of length `hi - lo`, exactly) far from under- and overflow
    if na >= 1 << 16
        || nb >= 1 << 16
        || !(TAME_LO..=TAME_HI).contains(&(a_height * a_height))
        || !(TAME_LO..=TAME_HI).contains(&(b_height * b_height))
    {
        return None;
    }
    Some(Poles { a: [a_bottom, a_top], b: [b_bottom, b_top] })
}

/// Tame (see [`derived_cycles`]): a side face's horizontal edge `p -> q` far from under- and overflow, its normal
/// `n` a unit vector orthogonal to the edge within 1e-12 rad.
#[inline(always)]
fn tame_side(n: DVec3, p: DVec3, q: DVec3) -> bool {
    let d = q - p;
    let (len2, nn, dot) = (d.x * d.x + d.y * d.y, n.x * n.x + n.y * n.y, n.x * d.x + n.y * d.y);
    (TAME_LO..=TAME_HI).contains(&len2) && (nn - 1.0).abs() <= 1e-9 && dot * dot <= 1e-24 * len2
}

/// The two ends of a vertical edge as `[bottom, top]` (indexed by the level), else `None`.
#[inline]
fn ends([v0, v1]: [usize; 2], levels: &[u8]) -> Option<[usize; 2]> {
    match (levels[v0], levels[v1]) {
        (BOTTOM, TOP) => Some([v0, v1]),
        (TOP, BOTTOM) => Some([v1, v0]),
        _ => None,
    }
}

/// The vertex-pair cycles of every face of the obstacle of a *tame* z-prism pair, in the order of `specs` (from
/// [`face_specs`]), without the general assembly's polygon merges (`minkowski::face_plus_segment`,
/// `minkowski::planar_merge`), into `cycles` / `starts`; `false` (buffers garbage) when the pair is not one this
/// handles, and the caller runs the general assembly.
///
/// Handled: each summand has exactly two poles, a top (`+z`) and a bottom one, every vertex on one of them, every
/// side face a quadrilateral; each pole of `B` is merged with the same pole of `-RA` and no side face is merged
/// (`specs` holds `FaceFace` for the two poles of `B`, `FixedFaceMovingEdge` for its sides, `MovingFaceFixedEdge`
/// for those of `-RA`); and the caller has checked that the pair is *tame*: every edge's squared length in
/// `[TAME_LO, TAME_HI]`, unit side normals orthogonal to their horizontal edges within 1e-12 rad
/// ([`vertical_arcs`]), and every side normal strictly inside its supporting arc by at least [`MARGIN`]
/// ([`face_specs`]). Then every decision the general assembly takes is the geometric one with a wide margin, and
/// its cycles are the geometric ones:
///
/// * a side face of `B` plus a vertical edge of `-RA` (`face_plus_segment`: its two vertical edges are parallel to
///   the segment, the horizontal ones clearly not) is the face's own quadrilateral with every top corner `j`
///   translated by the edge's top end and every bottom corner by its bottom end, from the face's corner 0; a side
///   face of `-RA` plus a vertical edge of `B` likewise, from corner 0 of the reversed cycle;
/// * a pole of the obstacle (`planar_merge` of the two pole polygons: no two of their edges within the tolerance of
///   each other, every order decision at least `MARGIN` from a tie) is the cycle of the side faces' edges on that
///   pole, reversed (each pole edge is shared with exactly one side face, traversed the other way), starting, as
///   the merge does, at the corner where `B`'s pole edge 0 leaves `B`'s corner 0: `[i, j0]` with `i` the end on
///   that pole of the vertical edge of `-RA` that supports the side face of `B` across that edge.
///
/// The result is checked to close up with `|F| + |G|` corners (else `false`). O(V + sum of the cycles' lengths).
#[allow(clippy::too_many_arguments)]
pub(crate) fn derived_cycles(
    moving: &ConvexPolytope,
    fixed: &ConvexPolytope,
    neg_ra: &[DVec3],
    am: &[DVec3],
    bn: &[DVec3],
    specs: &[FaceSpec],
    scratch: &mut Scratch,
) -> bool {
    let Some(Poles { a: [a_bottom, a_top], b: [b_bottom, b_top] }) = poles(moving, fixed, neg_ra, am, bn, scratch)
    else {
        return false;
    };
    let Scratch { next, cycles, starts, a_levels, b_levels, .. } = scratch;
    let bv = fixed.vertices();
    let (na, nb) = (neg_ra.len(), bv.len());
    let (a_levels, b_levels) = (&a_levels[..], &b_levels[..]);
    // (the buffers only grow: every entry used below is written first, or filled here)
    if next.len() < na * nb {
        next.resize(na * nb, u32::MAX);
    }
    next[..na * nb].fill(u32::MAX);
    // the cycles' total length when every side face is a quadrilateral (checked below)
    let size = |p: &ConvexPolytope, f: usize| p.faces()[f].vertices.len();
    let total = 4 * specs.len().saturating_sub(2)
        + size(fixed, b_top)
        + size(moving, a_top)
        + size(fixed, b_bottom)
        + size(moving, a_bottom);
    // every cycle position and every start is written below before it is read (the cycles' garbage beyond `total`
    // is never read: faces are read through `starts`)
    if cycles.len() < total {
        cycles.resize(total, [0, 0]);
    }
    if starts.len() != specs.len() + 1 {
        starts.clear();
        starts.resize(specs.len() + 1, 0);
    }
    // the pole faces: (position in `cycles`, face of B, corners)
    let mut pole_faces = [(0, 0, 0); 2];
    let mut pole_count = 0;
    let mut w = 0;
    for (s, spec) in specs.iter().enumerate() {
        starts[s] = w;
        if w + 4 > total {
            return false;
        }
        // the corners' levels
        let mut quad = [0u8; 4];
        match (spec.fixed, spec.moving) {
            (Feature::Face(g), Feature::Edge(ea)) => {
                let corners = &fixed.faces()[g].vertices;
                let Some(i) = ends(moving.edges()[ea].vertices, a_levels) else { return false };
                if corners.len() != 4 {
                    return false;
                }
                for ((&j, level), corner) in corners.iter().zip(&mut quad).zip(&mut cycles[w..w + 4]) {
                    *level = b_levels[j];
                    *corner = [i[usize::from(*level)], j];
                }
                let k = if quad[0] == quad[1] { 0 } else { 1 };
                if !tame_side(bn[g], bv[corners[k]], bv[corners[k + 1]]) {
                    return false;
                }
            }
            (Feature::Edge(eb), Feature::Face(f)) => {
                let corners = &moving.faces()[f].vertices;
                let Some(j) = ends(fixed.edges()[eb].vertices, b_levels) else { return false };
                if corners.len() != 4 {
                    return false;
                }
                for ((&i, level), corner) in corners.iter().rev().zip(&mut quad).zip(&mut cycles[w..w + 4]) {
                    *level = a_levels[i];
                    *corner = [i, j[usize::from(*level)]];
                }
                let k = if quad[0] == quad[1] { 0 } else { 1 };
                if !tame_side(am[f], neg_ra[corners[k]], neg_ra[corners[k + 1]]) {
                    return false;
                }
            }
            (Feature::Face(g), Feature::Face(f)) if g == b_top || g == b_bottom => {
                if pole_count == 2 || (g == b_top) != (f == a_top) {
                    return false;
                }
                let size = size(fixed, g) + size(moving, f);
                if w + size > total {
                    return false;
                }
                pole_faces[pole_count] = (w, g, size);
                pole_count += 1;
                w += size;
                continue;
            }
            _ => return false,
        }
        // the quadrilateral's pole edges (two corners on the same pole; a corner's `i` and `j` are on the same one by
        // construction), reversed, into `next` (as `i << 16 | j`)
        let c = &cycles[w..w + 4];
        w += 4;
        for k in 0..4 {
            let l = if k == 3 { 0 } else { k + 1 };
            if quad[k] == quad[l] {
                let ([i0, j0], [i1, j1]) = (c[k], c[l]);
                let slot = &mut next[..na * nb][i1 * nb + j1];
                if *slot != u32::MAX {
                    return false;
                }
                *slot = ((i0 << 16) | j0) as u32;
            }
        }
    }
    starts[specs.len()] = w;
    if pole_count != 2 || w != total {
        return false;
    }
    for &(position, g, size) in &pole_faces {
        let corners = &fixed.faces()[g].vertices;
        // the side face of B across B's pole edge 0 and the end of its supporting edge of -RA on this pole
        let [f0, f1] = fixed.edges()[fixed.face_edges(g)[0]].faces;
        let across = if f0 == g { f1 } else { f0 };
        let Some(&FaceSpec { fixed: Feature::Face(h), moving: Feature::Edge(ea), .. }) = specs.get(across) else {
            return false;
        };
        let Some(i) = ends(moving.edges()[ea].vertices, a_levels) else { return false };
        if h != across || corners.len() < 2 {
            return false;
        }
        let i = i[usize::from(g == b_top)];
        let start = [i, corners[0]];
        let mut corner = start;
        for k in 0..size {
            if k > 0 && corner == start {
                return false;
            }
            cycles[position + k] = corner;
            let packed = next[..na * nb][corner[0] * nb + corner[1]];
            if packed == u32::MAX {
                return false;
            }
            corner = [(packed >> 16) as usize, (packed & 0xFFFF) as usize];
        }
        let key = corner;
        // closed, and leaving the start along B's edge 0
        if key != start || cycles[position + 1] != [i, corners[1]] {
            return false;
        }
    }
    true
}

#[cfg(test)]
pub(crate) mod tests {
    use glam::{DMat3, DVec3};
    use stackplan_geom::{ConvexPolytope, convex_hull};

    /// The outline `(x, y)` extruded over `[z0, z1]` along `z` (`axis` 2) or along `x` (`axis` 0).
    pub(crate) fn prism(outline: &[(f64, f64)], z0: f64, z1: f64, axis: usize) -> ConvexPolytope {
        let pts: Vec<DVec3> = outline
            .iter()
            .flat_map(|&(x, y)| [z0, z1].map(|z| if axis == 0 { DVec3::new(z, x, y) } else { DVec3::new(x, y, z) }))
            .collect();
        convex_hull(&pts).expect("prism").polytope
    }

    /// A box with corners scaled by `s` and unit face normals (the planes of a box of ordinary size).
    pub(crate) fn scaled(s: f64) -> ConvexPolytope {
        let unit = ConvexPolytope::cuboid(DVec3::new(-1.0, 0.0, -1.0), DVec3::new(2.0, 1.0, 3.0)).expect("box");
        let vertices = unit.vertices().iter().map(|v| *v * s).collect();
        let planes = unit.planes().map(|p| stackplan_geom::Plane { normal: p.normal, offset: p.offset * s }).collect();
        unit.with_geometry(vertices, planes).expect("same topology")
    }

    #[test]
    fn vertical_arcs_reuse_the_circle_only_for_equal_heights() {
        // every vertical arc's circle is the general route's (`d * (1 / sqrt(d.z * d.z))`, z component), whether its
        // `1 / sqrt` was computed for this edge or reused from an earlier edge of the same `|d.z|`; the scaled boxes
        // reach the edges of the exponent range
        let hex = [(0.0, 0.0), (60.0, 0.0), (90.0, 30.0), (80.0, 70.0), (20.0, 80.0), (-10.0, 40.0)];
        let shapes = [
            prism(&hex, 0.0, 2.0, 2),
            prism(&hex, -0.3, 0.1, 2),
            ConvexPolytope::cuboid(DVec3::new(-1.0, 0.5, 0.0), DVec3::new(4.0, 5.0, 6.0)).expect("box"),
            scaled(1e150),
            scaled(1e-150),
        ];
        for r in [DMat3::IDENTITY, DMat3::from_rotation_z(0.3), DMat3::from_rotation_z(-2.0)] {
            for p in &shapes {
                let points: Vec<DVec3> = p.vertices().iter().map(|v| -(r * *v)).collect();
                let normals: Vec<DVec3> = p.faces().iter().map(|f| -(r * f.plane.normal).normalize()).collect();
                let (mut classes, mut arcs) = (Vec::new(), Vec::new());
                assert!(super::vertical_arcs(p, &points, &normals, &mut classes, &mut arcs));
                assert!(arcs.len() >= 4);
                for arc in &arcs {
                    let [v0, v1] = p.edges()[arc.edge].vertices;
                    let d = points[v1] - points[v0];
                    let cz = d.z * (d.z * d.z).sqrt().recip();
                    assert!(arc.cz.to_bits() == cz.to_bits() || arc.cz.to_bits() == (-cz).to_bits(), "{p:?}");
                }
            }
        }
    }
}
