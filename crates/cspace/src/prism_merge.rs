//! The obstacle of a tame z-prism pair in one pass over the merged pole chains: face cycles, vertex numbering,
//! vertices, planes and the edge table's half-edges written straight into the result, without the vertex-pair
//! cycles of `z_prism::derived_cycles` and their second reading by `prism_assembly.rs`.
//!
//! Paper: Ayyadevara et al. 2002 (\[A\]) App. B, eq. 12. For two z-prisms turned about `z` the obstacle is itself a
//! z-prism, `C = (b (+) (-R a)) x [b_lo - a_hi, b_hi - a_lo]`: its cross-section is the 2-D Minkowski sum of the
//! cross-sections, whose boundary is the merge of their edge sequences in angular order. On each pole (`L`, bottom
//! or top) the obstacle's face is that merge: a *chain* of `k = kA + kB` corners (the side faces of both summands)
//! starting, as the general route's `planar_merge` does, at `B`'s corner 0 of its pole face, leaving along `B`'s pole
//! edge 0. A **B step** moves along `B`'s pole face (`j -> j'`, the side face of `B` across that edge, its corner
//! `i` of `-RA` the end on `L` of the vertical edge that supports it, from the face specs); an **A step** moves
//! along `-RA`'s pole face backwards (`i -> i'`: `-RA`'s cycles are `A`'s reversed by the point reflection), the side
//! face of `-RA` across that edge, which must be supported by a vertical edge of `B` ending at the current `j`. The
//! supports, found with margin by `z_prism::face_specs` (the pair is tame), are the merge's order decisions: B steps
//! in `B`'s order, each preceded by the A steps that bring `i` to the support of the next side face of `B`.
//!
//! Every corner of the obstacle is a chain position `(L, p)`, `2 k` in all, with its vertex pair. A side face of the
//! obstacle is the side face of one step of each chain (positions `p_L`), a quadrilateral whose corners in the
//! summand face's own order (as `derived_cycles` reads them) are `(L, p_L + 1), (L, p_L)` on one pole and the same on
//! the other (its pole edges run against the chains). So one pass over the faces in the general route's order
//! numbers the chain positions on first appearance (exactly as the general assembly numbers the vertex pairs: the
//! positions of a chain are distinct pairs, since `i` and `j` only advance), computes each new vertex `b[j] - ra[i]`
//! and every face's offset (the largest `n . v` over its corners in cycle order, the general assembly's arithmetic),
//! and files every half-edge under the vertex that names it for `prism_assembly::edge_table` (geom's table).
//!
//! Checked on the way (else `None`, and the caller derives the cycles and assembles them directly, with the same
//! result): the poles and levels (`z_prism::poles`), every side face supported by a vertical edge, every chain
//! closing with `k` steps that cover each side face once per pole, each A step's support ending at the chain's `j`,
//! every side face a quadrilateral, tame (`z_prism::tame_side`, on the corners `derived_cycles` tests), and each of
//! its corners the one `derived_cycles` reads off the face (its `j` for a side face of `B`, its `i` for one of
//! `-RA`; the other component is the chain's, from the same support, by construction; a corner off its pole fails
//! this test); the edge table's own checks (`prism_assembly.rs`). So the faces are `derived_cycles`' cycles (a pole's
//! chain is the walk of the side faces' reversed pole edges from the same start), and the result is bit for bit the
//! direct assembly's and the general route's (unit tests here and in `z_prism.rs`, `examples/obstacle_identity.rs
//! dump`).
//!
//! Complexity: O(V + F + k), no allocation besides the result's own.

use glam::{DMat3, DVec3};
use stackplan_geom::VertexCycle;
use stackplan_geom::polytope::{ConvexPolytope, Face, Plane};

use crate::minkowski::{FaceKind, FaceSpec, Feature, Obstacle, OverlayFailure};
use crate::prism_assembly::{EMPTY, Half, POLE, TWIN, VERTICAL, edge_table, finish};
use crate::z_prism::{self, Poles};

/// Working buffers, kept per thread with the overlay's.
#[derive(Default)]
pub(crate) struct Scratch {
    /// Per vertex of `-RA` on a pole: its successor in the chain (its predecessor in its pole face) and the spec of
    /// the side face across that edge (`u32::MAX`: none).
    prev_a: Vec<[u32; 2]>,
    /// Per face spec: the ends `[bottom, top]` of the vertical edge supporting a side face (`NONE` for a pole).
    sides: Vec<[u32; 2]>,
    /// The chains' vertex pairs `[i, j]`, position `(L, p)` at `L * k + p`.
    pairs: Vec<[u32; 2]>,
    /// The vertex number of every chain position (`u32::MAX` before its first appearance).
    ids: Vec<u32>,
    /// Per face spec: the chain positions of its steps, `[bottom, top]` (`u32::MAX`: none).
    pos: Vec<[u32; 2]>,
    /// As in `prism_assembly::Scratch`: the half-edges filed under every vertex, `prev[next(v)] = v`.
    stars: Vec<[Half; 3]>,
    prev: Vec<u32>,
    /// The vertex pairs and the vertices in the order numbered.
    numbered: Vec<[usize; 2]>,
    coords: Vec<DVec3>,
}

const BOTTOM: usize = 0;
const TOP: usize = 1;
const NONE: u32 = u32::MAX;

/// The obstacle of a tame z-prism pair (`specs` from `z_prism::face_specs` with the poles merged pairwise and every
/// side normal supported with margin), bit for bit the general route's, or `None` when the pair is not the structure
/// of the module documentation (then the caller derives the cycles and assembles them). `prism` holds the classes from
/// `z_prism::vertical_arcs`; its levels are overwritten.
#[allow(clippy::too_many_arguments)]
pub(crate) fn obstacle(
    moving: &ConvexPolytope,
    fixed: &ConvexPolytope,
    rotation: DMat3,
    ra: &[DVec3],
    neg_ra: &[DVec3],
    am: &[DVec3],
    bn: &[DVec3],
    specs: &[FaceSpec],
    prism: &mut z_prism::Scratch,
    scratch: &mut Scratch,
) -> Option<Result<Obstacle, OverlayFailure>> {
    let (bv, fb) = (fixed.vertices(), fixed.faces().len());
    // every face of B and every face of -RA but its two poles (no side face merged); `k` side faces
    let k = specs.len().checked_sub(2)?;
    if specs.len() + 2 != moving.faces().len() + fb || k < 3 {
        return None;
    }
    let Poles { a: a_poles, b: b_poles } = z_prism::poles(moving, fixed, neg_ra, am, bn, prism)?;
    let (a_levels, b_levels) = (prism.a_levels.as_slice(), prism.b_levels.as_slice());
    let Scratch { prev_a, sides, pairs, ids, pos, stars, prev, numbered, coords } = scratch;
    prev_a.clear();
    prev_a.resize(neg_ra.len(), [NONE; 2]);
    pos.clear();
    pos.resize(specs.len(), [NONE; 2]);
    ids.clear();
    ids.resize(2 * k, NONE);
    // (every position is written by its chain before it is read)
    if pairs.len() < 2 * k {
        pairs.resize(2 * k, [0, 0]);
    }
    // every side face's supporting vertical edge: its ends `[bottom, top]` (`i` of -RA for a side face of B, `j` of
    // B for one of -RA; `NONE` for the poles)
    sides.clear();
    for (s, spec) in specs.iter().enumerate() {
        let ends = match (spec.fixed, spec.moving) {
            (Feature::Face(g), Feature::Edge(ea)) if g == s => z_prism::ends(moving.edges()[ea].vertices, a_levels)?,
            (Feature::Edge(eb), Feature::Face(_)) if s >= fb => z_prism::ends(fixed.edges()[eb].vertices, b_levels)?,
            (Feature::Face(g), Feature::Face(_)) if g == s => [NONE as usize; 2],
            _ => return None,
        };
        sides.push(ends.map(|x| x as u32));
    }
    for level in [BOTTOM, TOP] {
        // -RA's pole face backwards: `i -> i'` with the side face across (its spec: after B's faces, -RA's in order
        // without the two poles)
        let (f, g) = (a_poles[level], b_poles[level]);
        let (ic, fea) = (&moving.faces()[f].vertices, moving.face_edges(f));
        let mut before = *ic.last()?;
        for (&i, &e) in ic.iter().zip(fea.iter().cycle().skip(ic.len() - 1)) {
            // `e` joins `before` and `i`
            let [f0, f1] = moving.edges()[e].faces;
            let across = if f0 == f { f1 } else { f0 };
            let s = fb + across - usize::from(across > a_poles[0]) - usize::from(across > a_poles[1]);
            if let Some(&FaceSpec { moving: Feature::Face(h), .. }) = specs.get(s)
                && h == across
            {
                prev_a[i] = [before as u32, s as u32];
            }
            before = i;
        }
        // B's pole face forwards, the A steps before each B step: the side face of B across B's pole edge `q` and
        // the end on this pole of its support
        let (jc, feb) = (&fixed.faces()[g].vertices, fixed.face_edges(g));
        let b_step = |q: usize| -> Option<(usize, usize)> {
            let [g0, g1] = fixed.edges()[feb[q]].faces;
            let across = if g0 == g { g1 } else { g0 };
            let i = if across < fb { sides[across][level] } else { NONE };
            (i != NONE).then_some((across, i as usize))
        };
        let chain = &mut pairs[level * k..(level + 1) * k];
        let (mut next_b, mut target) = b_step(0)?;
        let start = target;
        let (mut i, mut j, mut p, mut q) = (start, *jc.first()?, 0usize, 0usize);
        loop {
            let s = if i != target {
                // an A step: the side face of -RA across must be supported by a vertical edge of B ending at `j`
                let [next, s] = prev_a[i];
                if sides.get(s as usize)?[level] != j as u32 {
                    return None;
                }
                *chain.get_mut(p)? = [i as u32, j as u32];
                i = next as usize;
                s as usize
            } else if q < jc.len() {
                // a B step
                *chain.get_mut(p)? = [i as u32, j as u32];
                let s = next_b;
                q += 1;
                if q < jc.len() {
                    j = jc[q];
                    (next_b, target) = b_step(q)?;
                } else {
                    (j, target) = (jc[0], start);
                }
                s
            } else {
                break;
            };
            let place = &mut pos[s][level];
            if *place != NONE {
                return None;
            }
            *place = p as u32;
            p += 1;
        }
        if p != k {
            return None;
        }
    }

    // one pass over the faces in the general route's order
    let nv = 2 * k;
    if stars.len() < nv {
        stars.resize(nv, [EMPTY; 3]);
    }
    if prev.len() < nv {
        prev.resize(nv, NONE);
    }
    let (stars, prev) = (&mut stars[..nv], &mut prev[..nv]);
    stars.fill([EMPTY; 3]);
    prev.fill(NONE);
    // (the vertex pairs and coordinates in buffers of the scratch, copied into the result after the faces:
    // allocated in this order, the result's vectors are served by the allocator's per-thread caches when the
    // previous obstacle was dropped)
    if coords.len() < nv {
        numbered.resize(nv, [0, 0]);
        coords.resize(nv, DVec3::ZERO);
    }
    let (numbered, coords) = (&mut numbered[..nv], &mut coords[..nv]);
    let mut vertex_pairs: Vec<[usize; 2]> = Vec::with_capacity(nv);
    let mut faces: Vec<Face> = Vec::with_capacity(specs.len());
    let mut kinds: Vec<FaceKind> = Vec::with_capacity(specs.len());
    let mut count = 0usize;
    // the vertex of a chain position, numbered on first appearance (its coordinates as the general assembly's)
    macro_rules! number {
        ($key:expr) => {{
            let key = $key;
            let id = ids[key];
            if id == NONE {
                let [i, j] = pairs[key];
                let (i, j) = (i as usize, j as usize);
                let id = count;
                ids[key] = id as u32;
                *numbered.get_mut(id)? = [i, j];
                coords[id] = bv[j] - ra[i];
                count += 1;
                id
            } else {
                id as usize
            }
        }};
    }
    let mut poles_seen = [false; 2];
    let mut start = 0usize;
    for (s, spec) in specs.iter().enumerate() {
        let (face_index, normal) = (s as u32, spec.normal);
        let mut offset = f64::NEG_INFINITY;
        // a side face: its corners' levels and vertex pairs in the order `derived_cycles` reads them
        let (kind, levels, derived) = match (spec.fixed, spec.moving) {
            (Feature::Face(g), Feature::Face(f)) => {
                // a pole: its chain from position 0; every half-edge `a -> b` filed under its source
                let level = usize::from(g == b_poles[TOP]);
                if g != b_poles[level] || f != a_poles[level] || poles_seen[level] {
                    return None;
                }
                poles_seen[level] = true;
                // (a `Vec` first: its pushes are cheaper than the inline cycle's, and the `k = kA + kB >= 6` corners
                // of a tame pole never fit inline; the conversion keeps the allocation)
                let mut face = Vec::with_capacity(k);
                for key in level * k..(level + 1) * k {
                    let v = number!(key);
                    offset = offset.max(normal.dot(coords[v]));
                    face.push(v);
                }
                let mut a = face[k - 1];
                for (q, &b) in face.iter().enumerate() {
                    let index = (start + if q == 0 { k - 1 } else { q - 1 }) as u32;
                    stars[a][POLE] = Half { other: b as u32, index, face: face_index };
                    prev[b] = a as u32;
                    a = b;
                }
                start += k;
                faces.push(Face { vertices: VertexCycle::from(face), plane: Plane { normal, offset } });
                kinds.push(FaceKind::FaceFace { face_a: f, face_b: g });
                continue;
            }
            (Feature::Face(g), Feature::Edge(ea)) => {
                // a side face of B plus a vertical edge of -RA: the face's corners `j`, each with the edge's end on
                // its pole
                let &[c0, c1, c2, c3] = fixed.faces()[g].vertices.as_slice() else { return None };
                let corners = [c0, c1, c2, c3];
                let levels = [b_levels[c0], b_levels[c1]].map(usize::from);
                let q = usize::from(levels[0] != levels[1]);
                if !z_prism::tame_side(bn[g], bv[corners[q]], bv[corners[q + 1]]) {
                    return None;
                }
                // (the chain's `i` is the edge's end on each pole: its B steps for this face read it)
                let derived = (1, corners);
                (FaceKind::FixedFaceMovingEdge { face_b: g, edge_a: ea }, levels, derived)
            }
            (Feature::Edge(eb), Feature::Face(f)) => {
                // a side face of -RA plus a vertical edge of B: the face's corners `i` reversed, each with the edge's
                // end on its pole
                let &[c0, c1, c2, c3] = moving.faces()[f].vertices.as_slice() else { return None };
                let corners = [c3, c2, c1, c0];
                let levels = [a_levels[c3], a_levels[c2]].map(usize::from);
                let q = usize::from(levels[0] != levels[1]);
                // (tested as `derived_cycles` tests it: on the face's own corners `q` and `q + 1`)
                let own = [c0, c1, c2, c3];
                if !z_prism::tame_side(am[f], neg_ra[own[q]], neg_ra[own[q + 1]]) {
                    return None;
                }
                // (the chain's `j` is the edge's end on each pole: checked at its A steps for this face)
                let derived = (0, corners);
                (FaceKind::MovingFaceFixedEdge { face_a: f, edge_b: eb }, levels, derived)
            }
            _ => return None,
        };
        // one pole edge at corners `q`, `q + 1` (level `l`), the other at `q + 2`, `q + 3`; each runs against its
        // chain: `(l, p + 1) -> (l, p)` for the step `p` of this face (a corner on the other pole fails the pair test
        // below: the chains' pairs are on their own pole)
        let q = usize::from(levels[0] != levels[1]);
        let l = levels[q];
        let place = pos[s];
        let (p, r) = (place[l] as usize, place[1 - l] as usize);
        if p >= k || r >= k {
            return None;
        }
        let (base, other) = (l * k, (1 - l) * k);
        let mut keys = [0; 4];
        keys[q] = base + if p + 1 == k { 0 } else { p + 1 };
        keys[q + 1] = base + p;
        keys[(q + 2) & 3] = other + if r + 1 == k { 0 } else { r + 1 };
        keys[(q + 3) & 3] = other + r;
        let mut v = [0; 4];
        // the corners' vertex pairs are `derived_cycles`' (its `i` or `j` as the chain's, as noted above; the other
        // from the face's own corners)
        let (own, corners) = derived;
        for ((v, &key), &corner) in v.iter_mut().zip(&keys).zip(&corners) {
            if pairs[key][own] as usize != corner {
                return None;
            }
            *v = number!(key);
            offset = offset.max(normal.dot(coords[*v]));
        }
        // horizontal half-edges filed under their target, vertical ones under their source
        for c in 0..4 {
            let (a, b) = (v[c], v[(c + 1) & 3]);
            let index = (start + c) as u32;
            if c & 1 == q {
                stars[b][TWIN] = Half { other: a as u32, index, face: face_index };
            } else {
                stars[a][VERTICAL] = Half { other: b as u32, index, face: face_index };
            }
        }
        start += 4;
        // (a quadrilateral: stored inline in its face, no allocation)
        let face = VertexCycle::from(v);
        faces.push(Face { vertices: face, plane: Plane { normal, offset } });
        kinds.push(kind);
    }
    if poles_seen != [true; 2] || count != nv || start != 3 * nv {
        return None;
    }
    vertex_pairs.extend_from_slice(numbered);
    let vertices = coords.to_vec();
    let table = edge_table(stars, prev, start, faces.len(), Vec::with_capacity(3 * k))?;
    finish(vertices, faces, table, vertex_pairs, kinds, rotation)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::minkowski::gauss_map_obstacle;
    use stackplan_geom::convex_hull;

    fn prism(outline: &[(f64, f64)], scale: f64) -> ConvexPolytope {
        let points: Vec<DVec3> =
            outline.iter().flat_map(|&(x, y)| [0.0, 2.0].map(|z| DVec3::new(x * scale, y * scale, z))).collect();
        convex_hull(&points).expect("prism").polytope
    }

    /// [`obstacle`] on the face specs of the obstacle `o` of `a` turned by `r` against `b` (recovered from its face
    /// kinds), with `change` applied to them.
    fn run(
        a: &ConvexPolytope,
        r: DMat3,
        b: &ConvexPolytope,
        o: &Obstacle,
        change: impl Fn(&mut Vec<FaceSpec>),
    ) -> Option<String> {
        let ra: Vec<DVec3> = a.vertices().iter().map(|v| r * *v).collect();
        let neg_ra: Vec<DVec3> = ra.iter().map(|v| -*v).collect();
        let am: Vec<DVec3> = a.faces().iter().map(|f| -(r * f.plane.normal).normalize()).collect();
        let bn: Vec<DVec3> = b.faces().iter().map(|f| f.plane.normal).collect();
        let mut prism = z_prism::Scratch::default();
        let z_prism::Scratch { a_classes, b_classes, a: a_arcs, b: b_arcs, wide, .. } = &mut prism;
        assert!(z_prism::vertical_arcs(a, &neg_ra, &am, a_classes, a_arcs, &mut wide[0]));
        assert!(z_prism::vertical_arcs(b, b.vertices(), &bn, b_classes, b_arcs, &mut wide[1]));
        let mut specs: Vec<FaceSpec> = o
            .polytope()
            .faces()
            .iter()
            .zip(o.face_kinds())
            .map(|(face, kind)| FaceSpec {
                normal: face.plane.normal,
                fixed: kind.fixed_feature().expect("classified"),
                moving: kind.moving_feature().expect("classified"),
            })
            .collect();
        change(&mut specs);
        let result = obstacle(a, b, r, &ra, &neg_ra, &am, &bn, &specs, &mut prism, &mut Scratch::default())?;
        Some(format!("{result:?}"))
    }

    /// A change of the face specs.
    type Change<'a> = &'a dyn Fn(&mut Vec<FaceSpec>);

    #[test]
    fn equals_the_general_route_and_refuses_inconsistent_specs() {
        let hex = [(0.0, 0.0), (60.0, 0.0), (90.0, 30.0), (80.0, 70.0), (20.0, 80.0), (-10.0, 40.0)];
        let quad = [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 2.0)];
        let shapes = [prism(&hex, 1.0), prism(&hex, 0.7), prism(&quad, 10.0)];
        let mut refused = 0;
        for (a, b) in [(0, 1), (1, 0), (0, 2), (2, 2)] {
            let (a, b) = (&shapes[a], &shapes[b]);
            for angle in [0.3, 1.0, 2.0, -2.5] {
                let r = DMat3::from_rotation_z(angle);
                let o = gauss_map_obstacle(a, r, b).expect("obstacle");
                // the same obstacle, bit for bit
                let same = run(a, r, b, &o, |_| {});
                assert_eq!(same, Some(format!("{:?}", Ok::<_, OverlayFailure>(o.clone()))));
                // inconsistent specs: refused (`None`), never a panic or another obstacle
                let sides: Vec<usize> = (0..o.face_kinds().len())
                    .filter(|&s| matches!(o.face_kinds()[s], FaceKind::FixedFaceMovingEdge { .. }))
                    .collect();
                let others: Vec<usize> = (0..o.face_kinds().len())
                    .filter(|&s| matches!(o.face_kinds()[s], FaceKind::MovingFaceFixedEdge { .. }))
                    .collect();
                // (two side faces with different supports)
                let (s, u) = (sides[0], others[0]);
                let support = |f: usize| o.face_kinds()[f].moving_feature().zip(o.face_kinds()[f].fixed_feature());
                let t = *sides.iter().find(|&&t| support(t).map(|x| x.0) != support(s).map(|x| x.0)).expect("B sides");
                let w = *others.iter().find(|&&w| support(w).map(|x| x.1) != support(u).map(|x| x.1)).expect("A sides");
                let changes: [Change<'_>; 7] = [
                    // two side faces of B with each other's supports
                    &|specs| {
                        let m = specs[s].moving;
                        specs[s].moving = specs[t].moving;
                        specs[t].moving = m;
                    },
                    // two side faces of -RA with each other's supports
                    &|specs| {
                        let m = specs[u].fixed;
                        specs[u].fixed = specs[w].fixed;
                        specs[w].fixed = m;
                    },
                    // a side face supported by a vertex
                    &|specs| specs[s].moving = Feature::Vertex(0),
                    &|specs| specs[u].fixed = Feature::Vertex(0),
                    // a face missing, one twice
                    &|specs| {
                        specs.remove(u);
                    },
                    &|specs| specs.push(FaceSpec { ..specs[u] }),
                    // a pole merged with the other pole
                    &|specs| {
                        let p = specs.iter().position(|f| matches!(f.moving, Feature::Face(_))).expect("pole");
                        if let (Feature::Face(g), Feature::Face(_)) = (specs[p].fixed, specs[p].moving) {
                            let other = specs
                                .iter()
                                .skip(p + 1)
                                .find_map(|f| match (f.fixed, f.moving) {
                                    (Feature::Face(_), Feature::Face(f)) => Some(f),
                                    _ => None,
                                })
                                .expect("two poles");
                            specs[p] = FaceSpec { moving: Feature::Face(other), fixed: Feature::Face(g), ..specs[p] };
                        }
                    },
                ];
                for change in changes {
                    let changed = run(a, r, b, &o, change);
                    assert!(changed.is_none(), "{changed:?}");
                    refused += 1;
                }
            }
        }
        assert_eq!(refused, 4 * 4 * 7);
    }
}
