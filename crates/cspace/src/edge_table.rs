//! The edge table of an assembled obstacle, built in the assembly's per-thread buffers.
//!
//! Input: the faces of a Minkowski sum as vertex cycles (counter-clockwise from outside). Output: exactly the edge
//! table of [`stackplan_geom::ConvexPolytope::new`] (edges in increasing (smaller vertex, larger vertex) order, each
//! with the face traversing it from its smaller to its larger vertex first; per half-edge its edge, in face order),
//! handed to [`stackplan_geom::ConvexPolytope::from_faces_and_edges`], or `None` exactly when that table does not exist
//! (a half-edge `a -> a`, the same directed half-edge twice, or one without its reverse: not a closed, consistently
//! oriented 2-manifold), in which case the caller lets geom build (and fail) the table to report the same error.
//!
//! Method: a counting sort of the half-edges by their *source* vertex (the out-star of every vertex; its counting pass
//! runs while the assembly numbers the vertices and lays out the faces, [`EdgeScratch::corner`]), an insertion
//! sort of each out-star by target (stars of a polytope's vertices are small: 3 to 6 half-edges for sheet metal), then
//! one pass over the vertices in increasing order emitting an edge for every half-edge `lo -> hi` with `hi > lo`,
//! whose reverse is looked up in the (sorted) out-star of `hi`. O(V + H + sum of squared star sizes) for `H`
//! half-edges; unlike geom's general table (a counting sort on the smaller vertex with packed keys, see
//! `polytope.rs`), it needs no keys and no second sort, and its working buffers are reused between obstacles.

use stackplan_geom::polytope::{Edge, Face};

/// Working buffers, kept per thread with the overlay's.
#[derive(Debug, Default)]
pub(crate) struct EdgeScratch {
    /// The out-star of vertex `a` is `out[start[a]..start[a + 1]]`.
    start: Vec<u32>,
    /// `(target, half-edge)`; half-edge `h` is corner `k` of face `f` with `h = (lengths of the faces before f) + k`.
    out: Vec<(u32, u32)>,
    /// The face of every half-edge (star sort only; filled while the half-edges are placed).
    face_of: Vec<u32>,
    /// The number of corners announced (half-edges).
    total: usize,
    /// Small polytopes: bit `b` of `targets[a]` says that the half-edge `a -> b` exists, ...
    targets: Vec<u64>,
    /// ... and `half_edge[a][b]` is it and its face (only read where the bit is set, so never cleared).
    half_edge: Vec<[(u32, u32); 64]>,
}

impl EdgeScratch {
    /// Starts a new face list (no vertices, no corners).
    pub(crate) fn clear(&mut self) {
        self.start.clear();
        self.start.extend([0, 0]);
        self.total = 0;
    }

    /// A new vertex (vertices are numbered in the order of these calls).
    #[inline]
    pub(crate) fn vertex(&mut self) {
        self.start.push(0);
    }

    /// Corner `v` of a face: called for every corner of every face, faces in order, corners in cycle order (the
    /// counting pass of the star sort, done while the faces are assembled).
    #[inline]
    pub(crate) fn corner(&mut self, v: usize) {
        self.start[v + 2] += 1;
        self.total += 1;
    }
}

/// The edges and the per-half-edge edge indices of `faces` over `nv` vertices, whose vertices and corners were
/// announced to `scratch` ([`EdgeScratch::clear`], then [`EdgeScratch::vertex`] and [`EdgeScratch::corner`]), or `None`
/// when the faces are not a closed, consistently oriented 2-manifold (see the module documentation).
pub(crate) fn build(nv: usize, faces: &[Face], scratch: &mut EdgeScratch) -> Option<(Vec<Edge>, Vec<usize>)> {
    if nv <= 64 { build_small(nv, faces, scratch) } else { build_stars(nv, faces, scratch) }
}

/// [`build`] by the star sort (any number of vertices).
fn build_stars(nv: usize, faces: &[Face], scratch: &mut EdgeScratch) -> Option<(Vec<Edge>, Vec<usize>)> {
    let EdgeScratch { start, out, face_of, total, .. } = scratch;
    debug_assert_eq!(start.len(), nv + 2, "every vertex announced");
    let total = *total;
    for a in 2..nv + 2 {
        start[a] += start[a - 1];
    }
    // pass 2: place the half-edges (start[a + 1] is the cursor of star a, and ends as its end)
    out.clear();
    out.resize(total, (0, 0));
    face_of.clear();
    face_of.resize(total, 0);
    let mut h = 0u32;
    for (f, face) in faces.iter().enumerate() {
        let Some((&first, rest)) = face.vertices.split_first() else { continue };
        let mut a = first;
        for &b in rest.iter().chain(std::iter::once(&first)) {
            if a == b {
                return None;
            }
            let slot = &mut start[a + 1];
            out[*slot as usize] = (b as u32, h);
            *slot += 1;
            face_of[h as usize] = f as u32;
            h += 1;
            a = b;
        }
    }
    // every star by target; the same directed half-edge twice is not a manifold
    for a in 0..nv {
        let star = &mut out[start[a] as usize..start[a + 1] as usize];
        for i in 1..star.len() {
            let x = star[i];
            let mut j = i;
            while j > 0 && star[j - 1].0 > x.0 {
                star[j] = star[j - 1];
                j -= 1;
            }
            if j > 0 && star[j - 1].0 == x.0 {
                return None;
            }
            star[j] = x;
        }
    }
    // pass 3: the edges in (smaller, larger) vertex order
    let mut edges = Vec::with_capacity(total / 2);
    // (with room for the faces' starts, which geom keeps in the same buffer)
    let mut face_edges = Vec::with_capacity(total + faces.len() + 1);
    face_edges.resize(total, usize::MAX);
    for lo in 0..nv {
        for &(hi, forward) in &out[start[lo] as usize..start[lo + 1] as usize] {
            let hi = hi as usize;
            if hi < lo {
                continue;
            }
            let reverse = out[start[hi] as usize..start[hi + 1] as usize].iter().find(|x| x.0 as usize == lo)?.1;
            let e = edges.len();
            edges.push(Edge {
                vertices: [lo, hi],
                faces: [face_of[forward as usize] as usize, face_of[reverse as usize] as usize],
            });
            face_edges[forward as usize] = e;
            face_edges[reverse as usize] = e;
        }
    }
    // a half-edge `hi -> lo` without its forward twin was not reached
    (2 * edges.len() == total).then_some((edges, face_edges))
}

/// [`build`] for at most 64 vertices: the out-star of every vertex as a bit set of targets (a duplicate half-edge is a
/// bit already set), the edges of `lo` are the bits above `lo` in increasing order, each reverse half-edge one bit test;
/// the same table and the same failures as the star sort, with no sort at all.
fn build_small(nv: usize, faces: &[Face], scratch: &mut EdgeScratch) -> Option<(Vec<Edge>, Vec<usize>)> {
    let EdgeScratch { total, targets, half_edge, .. } = scratch;
    let total = *total;
    targets.clear();
    targets.resize(nv, 0);
    if half_edge.len() < nv {
        half_edge.resize(nv, [(0, 0); 64]);
    }
    let (targets, half_edge) = (&mut targets[..nv], &mut half_edge[..nv]);
    let mut h = 0u32;
    // the half-edge `a -> b` of face `f`: `None` for `a == b`, a vertex that does not exist or the same directed
    // half-edge twice
    let mut half = |a: usize, b: usize, f: u32| -> Option<()> {
        let star = targets.get_mut(a)?;
        let bit = 1u64 << (b & 63);
        if a == b || b >= nv || *star & bit != 0 {
            return None;
        }
        *star |= bit;
        half_edge[a][b & 63] = (h, f);
        h += 1;
        Some(())
    };
    for (f, face) in faces.iter().enumerate() {
        let Some((&first, rest)) = face.vertices.split_first() else { continue };
        let mut a = first;
        for &b in rest {
            half(a, b, f as u32)?;
            a = b;
        }
        half(a, first, f as u32)?;
    }
    let mut edges = Vec::with_capacity(total / 2);
    // (with room for the faces' starts, which geom keeps in the same buffer)
    let mut face_edges = Vec::with_capacity(total + faces.len() + 1);
    face_edges.resize(total, 0);
    for lo in 0..nv {
        let mut above = targets[lo] & (u64::MAX << lo);
        while above != 0 {
            let hi = (above.trailing_zeros() & 63) as usize;
            above &= above - 1;
            if targets[hi] & (1u64 << lo) == 0 {
                return None;
            }
            let ((forward, forward_face), (reverse, reverse_face)) = (half_edge[lo][hi], half_edge[hi][lo]);
            let e = edges.len();
            edges.push(Edge { vertices: [lo, hi], faces: [forward_face as usize, reverse_face as usize] });
            face_edges[forward as usize] = e;
            face_edges[reverse as usize] = e;
        }
    }
    // a half-edge `hi -> lo` without its forward twin was not reached
    (2 * edges.len() == total).then_some((edges, face_edges))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;
    use stackplan_geom::{ConvexPolytope, convex_hull};

    type Table = Option<(Vec<Edge>, Vec<usize>)>;

    /// Both methods on `faces` (vertices announced in index order): the same answer, or `None`.
    fn run(nv: usize, faces: &[Face]) -> Table {
        let stars = announce(nv, faces, build_stars);
        if nv <= 64 {
            assert_eq!(announce(nv, faces, build_small), stars);
        }
        stars
    }

    fn announce(nv: usize, faces: &[Face], method: fn(usize, &[Face], &mut EdgeScratch) -> Table) -> Table {
        let mut scratch = EdgeScratch::default();
        scratch.clear();
        for _ in 0..nv {
            scratch.vertex();
        }
        for face in faces {
            for &v in &face.vertices {
                scratch.corner(v);
            }
        }
        method(nv, faces, &mut scratch)
    }

    fn polytopes() -> Vec<ConvexPolytope> {
        let mut out = vec![ConvexPolytope::cuboid(DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0)).expect("box")];
        for n in [5, 9, 20, 40, 64, 65, 100] {
            let pts: Vec<DVec3> = (0..n)
                .map(|k| {
                    let t = k as f64 * 2.399;
                    let z = 1.0 - 2.0 * (k as f64 + 0.5) / n as f64;
                    let r = (1.0 - z * z).sqrt();
                    DVec3::new(r * t.cos(), r * t.sin(), z)
                })
                .collect();
            out.push(convex_hull(&pts).expect("hull").polytope);
        }
        out
    }

    #[test]
    fn equals_geoms_table() {
        for p in polytopes() {
            let (edges, face_edges) = run(p.vertices().len(), p.faces()).expect("manifold");
            assert_eq!(edges, p.edges());
            let flat: Vec<usize> = (0..p.faces().len()).flat_map(|f| p.face_edges(f).to_vec()).collect();
            assert_eq!(face_edges, flat);
        }
    }

    #[test]
    fn fails_exactly_where_geom_fails() {
        for p in polytopes() {
            let nv = p.vertices().len();
            let faces = p.faces().to_vec();
            let mut broken: Vec<Vec<Face>> = Vec::new();
            let mut open = faces.clone();
            open.pop();
            broken.push(open);
            let mut twice = faces.clone();
            twice.push(faces[0].clone());
            broken.push(twice);
            let mut reversed = faces.clone();
            reversed[1].vertices.reverse();
            broken.push(reversed);
            let mut repeated = faces.clone();
            let first = repeated[0].vertices[0];
            repeated[0].vertices.insert(0, first);
            broken.push(repeated);
            let mut swapped = faces.clone();
            swapped[0].vertices.swap(0, 1);
            broken.push(swapped);
            for faces in broken {
                let geom = ConvexPolytope::from_faces_with_area(p.vertices().to_vec(), faces.clone());
                assert_eq!(run(nv, &faces).is_some(), geom.is_ok(), "{geom:?}");
                assert!(geom.is_err());
            }
        }
    }
}
