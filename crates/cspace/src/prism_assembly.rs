//! The direct assembly of the obstacle of a tame z-prism pair: vertex numbering, offsets and the edge table generated
//! from the prism structure, without the general assembly's lookup-table pass.
//!
//! Paper: Ayyadevara et al. 2002 (\[A\]) App. B, eq. 12; the obstacle of two z-prisms turned about `z` is itself a
//! z-prism, `C = (b (+) (-R a)) x [b_lo - a_hi, b_hi - a_lo]` for the cross-sections `a`, `b` (see `z_prism.rs`).
//! For a *tame* pair `z_prism::derived_cycles` has read every face cycle off the features: `k` side faces (each a
//! quadrilateral with two corners on each pole) and two pole faces, `2 k` vertices, `3 k` edges. Every vertex has
//! exactly three edges, known by construction:
//!
//! * **along its pole**: `v -> next(v)` in the pole face, traversed back (`next(v) -> v`) by one side face;
//! * **from its pole's predecessor**: `prev(v) -> v` likewise (the same kind of edge, seen from its other end);
//! * **vertical**: `v -> partner(v)` in one side face, `partner(v) -> v` in the adjacent one.
//!
//! So one pass over the faces (in the general route's order, numbering the vertex pairs on first appearance as the
//! general assembly does; the vertices and every face's offset, the general assembly's arithmetic in its order, follow
//! in passes of their own) files each half-edge under the vertex that names it: a pole
//! face's half-edge under its source (`pole`), a side face's horizontal half-edge under its *target* (`twin`: its
//! reverse is that vertex's pole half-edge), a side face's vertical half-edge under its source (`vertical`). Then one
//! pass over the vertices in increasing order emits each vertex's edges to larger vertices (at most three, sorted):
//! exactly geom's edge table (edges by (smaller, larger) vertex, the face traversing smaller -> larger first, every
//! half-edge's edge), with no sort of half-edges and no search for twins.
//!
//! Checked on the way (else `None`, and the caller assembles as the general route does, with the same result): every
//! slot filled exactly once, `next` a permutation, the horizontal side half-edge filed under `v` comes from `next(v)`,
//! `partner` an involution, and the three neighbours of every vertex distinct from each other and from it. These
//! imply that every undirected edge has exactly one half-edge each way and no other, i.e. that the table is the one
//! geom builds (which debug builds check on every obstacle).
//!
//! Complexity: O(V + F + sum of the face lengths), no allocation besides the result's own.

use glam::{DMat3, DVec3};
use stackplan_geom::VertexCycle;
use stackplan_geom::polytope::{ConvexPolytope, Edge, Face, Plane};

use crate::minkowski::{FaceKind, FaceSpec, Feature, Obstacle, OverlayFailure, Route};

/// A half-edge filed under a vertex: the vertex at its other end, its index (in the faces' corner order) and its face.
#[derive(Clone, Copy)]
pub(crate) struct Half {
    pub(crate) other: u32,
    pub(crate) index: u32,
    pub(crate) face: u32,
}

pub(crate) const EMPTY: Half = Half { other: u32::MAX, index: u32::MAX, face: u32::MAX };

/// Working buffers, kept per thread with the overlay's.
#[derive(Default)]
pub(crate) struct Scratch {
    /// `stars[v]`: the half-edges filed under `v`: `[POLE]` is `v -> next(v)` of its pole face, `[TWIN]` is
    /// `next(v) -> v` of a side face (`other` its source), `[VERTICAL]` is `v -> partner(v)` of a side face.
    stars: Vec<[Half; 3]>,
    /// `prev[next(v)] = v`.
    prev: Vec<u32>,
}

pub(crate) const POLE: usize = 0;
pub(crate) const TWIN: usize = 1;
pub(crate) const VERTICAL: usize = 2;

/// The obstacle vertex of the vertex pair `[i, j]`, numbered on first appearance exactly as the general assembly
/// (`minkowski::assemble`) numbers them (its coordinates, `b[j] - ra[i]`, are computed after the numbering pass).
#[inline(always)]
fn number([i, j]: [usize; 2], index_of: &mut [u32], nb: usize, vertex_pairs: &mut Vec<[usize; 2]>) -> usize {
    let slot = &mut index_of[i * nb + j];
    if *slot == u32::MAX {
        *slot = vertex_pairs.len() as u32;
        vertex_pairs.push([i, j]);
    }
    *slot as usize
}

/// geom's edge table from the half-edges filed under every vertex (`stars`, `prev` as in [`Scratch`]; `total`
/// half-edges, `face_count` faces): one pass over the vertices in increasing order emitting each vertex's edges to
/// larger vertices, with the checks of the module documentation (else `None`). Kept out of line (fewer live values,
/// fewer spills in [`assemble`]).
#[inline(never)]
pub(crate) fn edge_table(
    stars: &[[Half; 3]],
    prev: &[u32],
    total: usize,
    face_count: usize,
    mut edges: Vec<Edge>,
) -> Option<(Vec<Edge>, Vec<usize>)> {
    edges.clear();
    edges.reserve(total / 2);
    // (with room for the faces' starts, which geom keeps in the same buffer)
    let mut face_edges = Vec::with_capacity(total + face_count + 1);
    face_edges.resize(total, 0usize);
    for (lo, (&[p, t, d], &pp)) in stars.iter().zip(prev).enumerate() {
        // `prev` is a permutation (`pole` filled for every vertex), so `pp` is a vertex
        let (pn, vt, me) = (p.other, d.other, lo as u32);
        let (Some(&[pp_pole, pp_twin, _]), Some(&[_, _, down])) = (stars.get(pp as usize), stars.get(vt as usize))
        else {
            return None;
        };
        if t.other != pn || pp_twin.other != me || down.other != me || pn == pp || pn == vt || pp == vt || pn == me {
            return None;
        }
        // (larger vertex, forward half-edge, reverse half-edge); the side half-edge `lo -> pp` is filed under `pp`
        let mut up = [(pn, p, t), (pp, pp_twin, pp_pole), (vt, d, down)];
        if up[0].0 > up[1].0 {
            up.swap(0, 1);
        }
        if up[1].0 > up[2].0 {
            up.swap(1, 2);
        }
        if up[0].0 > up[1].0 {
            up.swap(0, 1);
        }
        for (hi, forward, reverse) in up {
            if hi > me {
                let e = edges.len();
                edges.push(Edge { vertices: [lo, hi as usize], faces: [forward.face as usize, reverse.face as usize] });
                face_edges[forward.index as usize] = e;
                face_edges[reverse.index as usize] = e;
            }
        }
    }
    Some((edges, face_edges))
}

/// The largest `normal . v` over the corners `face` in cycle order (`f64::max` from `-inf`): the general assembly's
/// offset, bit for bit; `None` when a corner is not a vertex. Kept out of line so that the running maximum stays in a
/// register (inlined into [`assemble`] it was kept on the stack, a store-to-load chain per corner).
#[inline(never)]
fn face_offset(normal: DVec3, face: &[usize], vertices: &[DVec3]) -> Option<f64> {
    let mut offset = f64::NEG_INFINITY;
    for &v in face {
        offset = offset.max(normal.dot(*vertices.get(v)?));
    }
    Some(offset)
}

/// The obstacle of a tame z-prism pair from the face cycles of `z_prism::derived_cycles` (face `s` is the vertex-pair
/// cycle `cycles[starts[s]..starts[s + 1]]` of `specs[s]`; `b_levels` the pole of every vertex of `B`): bit for bit
/// the general assembly's result, or `None` when the cycles are not the structure described in the module
/// documentation (then the caller runs the general assembly). `index_of` is the general assembly's numbering table.
#[allow(clippy::too_many_arguments)]
pub(crate) fn assemble(
    fixed: &ConvexPolytope,
    rotation: DMat3,
    ra: &[DVec3],
    specs: &[FaceSpec],
    cycles: &[[usize; 2]],
    starts: &[usize],
    b_levels: &[u8],
    index_of: &mut Vec<u32>,
    scratch: &mut Scratch,
) -> Option<Result<Obstacle, OverlayFailure>> {
    let bv = fixed.vertices();
    let nb = bv.len();
    // `k` side faces and two poles: `2 k` vertices, `3 k` edges, `6 k` half-edges
    let nv = 2 * specs.len().checked_sub(2)?;
    let total = 3 * nv;
    if starts.len() != specs.len() + 1 || starts[specs.len()] != total || cycles.len() < total {
        return None;
    }
    // (the buffers only grow; the parts used are filled here)
    let na_nb = ra.len() * nb;
    if index_of.len() < na_nb {
        index_of.resize(na_nb, u32::MAX);
    }
    let index_of = &mut index_of[..na_nb];
    index_of.fill(u32::MAX);
    let Scratch { stars, prev } = scratch;
    if stars.len() < nv {
        stars.resize(nv, [EMPTY; 3]);
    }
    if prev.len() < nv {
        prev.resize(nv, u32::MAX);
    }
    let (stars, prev) = (&mut stars[..nv], &mut prev[..nv]);
    stars.fill([EMPTY; 3]);
    prev.fill(u32::MAX);
    let mut vertex_pairs: Vec<[usize; 2]> = Vec::with_capacity(nv);
    let mut faces: Vec<Face> = Vec::with_capacity(specs.len());
    let mut kinds: Vec<FaceKind> = Vec::with_capacity(specs.len());
    for (s, (spec, range)) in specs.iter().zip(starts.windows(2)).enumerate() {
        let (start, end) = (range[0], range[1]);
        let corners = cycles.get(start..end)?;
        let face_index = s as u32;
        let face: VertexCycle = if let (Feature::Face(_), Feature::Face(_)) = (spec.fixed, spec.moving) {
            // a pole face: every half-edge `a -> b` is filed under its source
            let mut face = VertexCycle::with_capacity(corners.len());
            for &c in corners {
                face.push(number(c, index_of, nb, &mut vertex_pairs));
            }
            let &last = face.last()?;
            let mut a = last;
            for (k, &b) in face.iter().enumerate() {
                let index = (start + if k == 0 { face.len() - 1 } else { k - 1 }) as u32;
                let (slot, back) = (&mut stars.get_mut(a)?[POLE], prev.get_mut(b)?);
                if slot.other != u32::MAX || *back != u32::MAX {
                    return None;
                }
                *slot = Half { other: b as u32, index, face: face_index };
                *back = a as u32;
                a = b;
            }
            face
        } else {
            // a side face, a quadrilateral whose half-edges `k` and `k + 2` run along the poles, `k + 1` and `k + 3`
            // between them (the labels need not be geometric: the checks below are combinatorial)
            let &[c0, c1, c2, c3] = corners else { return None };
            let mut v = [0; 4];
            for (v, c) in v.iter_mut().zip([c0, c1, c2, c3]) {
                *v = number(c, index_of, nb, &mut vertex_pairs);
            }
            let k = usize::from(b_levels[c0[1]] != b_levels[c1[1]]);
            for q in 0..4 {
                let (a, b) = (v[q], v[(q + 1) & 3]);
                let index = (start + q) as u32;
                let (owner, kind, other) = if q & 1 == k { (b, TWIN, a) } else { (a, VERTICAL, b) };
                let slot = &mut stars.get_mut(owner)?[kind];
                if slot.other != u32::MAX {
                    return None;
                }
                *slot = Half { other: other as u32, index, face: face_index };
            }
            VertexCycle::from(v)
        };
        if vertex_pairs.len() > nv || face.len() < 3 {
            return None;
        }
        // (the offset is set below, once the vertices are known)
        faces.push(Face { vertices: face, plane: Plane { normal: spec.normal, offset: f64::NEG_INFINITY } });
        kinds.push(FaceKind::from_features(spec.fixed, spec.moving).unwrap_or(FaceKind::Unclassified));
    }
    if vertex_pairs.len() != nv {
        return None;
    }
    // the vertices `b[j] - ra[i]` and the offsets exactly as the general assembly (the largest `n . v`, corners in
    // cycle order), in passes of their own (fewer live values in the numbering pass)
    let mut vertices: Vec<DVec3> = Vec::with_capacity(nv);
    for &[i, j] in &vertex_pairs {
        vertices.push(*bv.get(j)? - *ra.get(i)?);
    }
    for face in &mut faces {
        face.plane.offset = face_offset(face.plane.normal, &face.vertices, &vertices)?;
    }
    let table = edge_table(stars, prev, total, faces.len(), Vec::with_capacity(total / 2))?;
    finish(vertices, faces, table, vertex_pairs, kinds, rotation)
}

/// The obstacle from its assembled parts (shared with [`crate::prism_merge`]): Euler's `V + F = E + 2` first
/// (`None`: the caller falls back to the general route), then geom's polytope and the obstacle with its provenance.
#[inline(always)]
pub(crate) fn finish(
    vertices: Vec<DVec3>,
    faces: Vec<Face>,
    (edges, face_edges): (Vec<Edge>, Vec<usize>),
    vertex_pairs: Vec<[usize; 2]>,
    kinds: Vec<FaceKind>,
    rotation: DMat3,
) -> Option<Result<Obstacle, OverlayFailure>> {
    if vertices.len() + faces.len() != edges.len() + 2 {
        return None;
    }
    let polytope = ConvexPolytope::from_faces_and_edges(vertices, faces, edges, face_edges);
    Some(match polytope {
        Ok(polytope) => {
            Obstacle::from_parts(polytope, vertex_pairs, kinds, rotation, Route::GaussMap).ok_or(OverlayFailure::Euler)
        }
        Err(e) => Err(OverlayFailure::Assembly(e)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::minkowski::gauss_map_obstacle;
    use stackplan_geom::convex_hull;

    fn hex_prism(scale: f64) -> ConvexPolytope {
        let hex = [(0.0, 0.0), (60.0, 0.0), (90.0, 30.0), (80.0, 70.0), (20.0, 80.0), (-10.0, 40.0)];
        let points: Vec<DVec3> =
            hex.iter().flat_map(|&(x, y)| [0.0, 2.0].map(|z| DVec3::new(x * scale, y * scale, z))).collect();
        convex_hull(&points).expect("prism").polytope
    }

    /// The inputs of [`assemble`] recovered from an obstacle of a tame pair: its face specs, vertex-pair cycles and
    /// starts.
    fn inputs(o: &Obstacle) -> (Vec<FaceSpec>, Vec<[usize; 2]>, Vec<usize>) {
        let p = o.polytope();
        let mut specs = Vec::new();
        let (mut cycles, mut starts) = (Vec::new(), vec![0]);
        for (face, kind) in p.faces().iter().zip(o.face_kinds()) {
            let (Some(fixed), Some(moving)) = (kind.fixed_feature(), kind.moving_feature()) else { panic!("{kind:?}") };
            specs.push(FaceSpec { normal: face.plane.normal, fixed, moving });
            cycles.extend(face.vertices.iter().map(|&v| o.vertex_pairs()[v]));
            starts.push(cycles.len());
        }
        (specs, cycles, starts)
    }

    fn run(
        b: &ConvexPolytope,
        r: DMat3,
        ra: &[DVec3],
        (specs, cycles, starts): (&[FaceSpec], &[[usize; 2]], &[usize]),
    ) -> Option<String> {
        let b_levels: Vec<u8> = b.vertices().iter().map(|v| u8::from(v.z > 1.0)).collect();
        let mut index_of = Vec::new();
        let result = assemble(b, r, ra, specs, cycles, starts, &b_levels, &mut index_of, &mut Scratch::default())?;
        Some(format!("{result:?}"))
    }

    #[test]
    fn equals_the_general_assembly_and_refuses_broken_cycles() {
        let (a, b) = (hex_prism(1.0), hex_prism(0.7));
        for angle in [0.3, 1.0, 2.0, -2.5] {
            let r = DMat3::from_rotation_z(angle);
            let o = gauss_map_obstacle(&a, r, &b).expect("obstacle");
            let ra: Vec<DVec3> = a.vertices().iter().map(|v| r * *v).collect();
            let (specs, cycles, starts) = inputs(&o);
            assert_eq!(specs.len(), 14);
            // the same obstacle, bit for bit
            let direct = run(&b, r, &ra, (&specs, &cycles, &starts));
            assert_eq!(direct, Some(format!("{:?}", Ok::<_, OverlayFailure>(o.clone()))));
            // broken cycles: refused (`None`; in debug builds geom would also reject a wrong table), never a panic
            let side = (0..specs.len()).find(|&s| starts[s + 1] - starts[s] == 4).expect("a side face");
            let pole = (0..specs.len()).find(|&s| starts[s + 1] - starts[s] > 4).expect("a pole face");
            let mut broken: Vec<Vec<[usize; 2]>> = Vec::new();
            let mut swapped = cycles.clone();
            swapped.swap(starts[side], starts[side] + 1);
            broken.push(swapped);
            let mut reversed = cycles.clone();
            reversed[starts[pole]..starts[pole + 1]].reverse();
            broken.push(reversed);
            let mut repeated = cycles.clone();
            repeated[starts[side] + 2] = repeated[starts[side]];
            broken.push(repeated);
            let mut moved = cycles.clone();
            moved[starts[pole]] = [0, 0];
            broken.push(moved);
            for cycles in &broken {
                assert_eq!(run(&b, r, &ra, (&specs, cycles, &starts)), None);
            }
            // wrong lengths
            assert_eq!(run(&b, r, &ra, (&specs[..13], &cycles, &starts[..14])), None);
            assert_eq!(run(&b, r, &ra, (&specs, &cycles[..cycles.len() - 1], &starts)), None);
        }
    }
}
