//! The 2-D convex sum `F + G` of the two generating polygons of a merged face of the overlay (a face of `B` and a
//! parallel face or edge of `-RA`), as a cycle of vertex pairs.
//!
//! Paper: Ayyadevara et al. 2002 (\[A\]) App. B, eq. 12; the faces of a Minkowski sum are the sums of the support sets
//! (`F_u(P + Q) = F_u(P) + F_u(Q)`), and the edges of a sum of convex polygons are the summands' edges in angular
//! order (de Berg et al., *Computational Geometry*, 3rd ed., section 13.3, the O(m + n) Minkowski sum of convex
//! polygons).
//!
//! [`planar_merge`] is that O(|F| + |G|) merge of the two edge sequences by angle, on vertex labels, without
//! coordinates: an edge of `F` and an edge of `G` are ONE edge of the sum (their middle corner is not a corner) when the
//! faces across them are merged too, or when their unit directions point the same way within half the angular
//! tolerance (`|c_a x c_b| <= tol / 2`, the threshold of merged face normals, so that a rotation about a face normal
//! by less than it merges the faces and their edges alike). Every other decision is the sign of `(v x w) . u` for two
//! edge directions that are not parallel, which rounding cannot flip. A face plus an edge (most merged faces of sheet
//! metal rotated about `z`) takes a one-pass form of the same rule, [`face_plus_segment`], O(|F|). A labelled 2-D hull
//! of the `|F| |G|` rounded sum points, with duplicates and corners within a *length* tolerance removed, gives the
//! same faces on every input away from the tolerance band, but within it its length rule can contradict the angle
//! rule of the unmerged side faces.

use glam::DVec3;
use stackplan_geom::polytope::ConvexPolytope;

use crate::types::{Feature, PARALLEL_SQ};

/// One polygon of a merged face: its corners (vertex indices of its polytope), and per edge `k` (corner `k` to `k + 1`)
/// the direction, its squared length and its half-plane relative to the reference direction (see [`planar_merge`]),
/// and the face of the polytope across that edge (`usize::MAX` for an edge feature).
#[derive(Default)]
pub(crate) struct Polygon {
    pub(crate) corners: Vec<usize>,
    pub(crate) edges: Vec<(DVec3, f64, u8)>,
    pub(crate) across: Vec<usize>,
}

impl Polygon {
    /// The polygon of `feature` of `p` (whose vertices, as summed, are `points`): a face's vertex cycle,
    /// counter-clockwise about its outward normal (reversed when `reflect`, for `-RA`, whose faces are the point
    /// reflections of `A`'s); an edge as the 2-gon `[v0, v1]`. The half-planes are taken relative to `reference`, or
    /// to this polygon's edge 0 when `None`; returns the reference. The faces across the edges only `with_across`.
    /// Not called for vertices.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn build(
        &mut self,
        p: &ConvexPolytope,
        feature: Feature,
        reflect: bool,
        points: &[DVec3],
        normal: DVec3,
        reference: Option<DVec3>,
        with_across: bool,
    ) -> DVec3 {
        let Self { corners, edges, across } = self;
        corners.clear();
        edges.clear();
        across.clear();
        match feature {
            Feature::Vertex(v) => corners.push(v),
            Feature::Edge(e) => corners.extend_from_slice(&p.edges()[e].vertices),
            Feature::Face(f) => {
                let cycle = &p.faces()[f].vertices;
                if reflect {
                    corners.extend(cycle.iter().rev());
                } else {
                    corners.extend_from_slice(cycle);
                }
                if with_across {
                    let face_edges = p.face_edges(f);
                    let other = |e: usize| {
                        let [f0, f1] = p.edges()[e].faces;
                        if f0 == f { f1 } else { f0 }
                    };
                    if reflect {
                        // reversed cycle: corner k is cycle[n - 1 - k]; the edge to corner k + 1 joins cycle[n - 1 - k]
                        // and cycle[n - 2 - k], i.e. face_edges[n - 2 - k]; the closing edge is face_edges[n - 1]
                        let n = cycle.len();
                        across.extend(face_edges[..n - 1].iter().rev().map(|&e| other(e)));
                        across.push(other(face_edges[n - 1]));
                    } else {
                        across.extend(face_edges.iter().map(|&e| other(e)));
                    }
                }
            }
        }
        let n = corners.len();
        let first = points[corners[0]];
        let r = reference.unwrap_or_else(|| points[corners[1]] - first);
        let mut current = first;
        edges.reserve(n);
        for k in 1..=n {
            let next = if k == n { first } else { points[corners[k]] };
            let d = next - current;
            current = next;
            // 0 for angles in [0, pi) from r about the normal, 1 for [pi, 2 pi)
            let s = r.cross(d).dot(normal);
            edges.push((d, d.length_squared(), u8::from(!(s > 0.0 || (s == 0.0 && r.dot(d) > 0.0)))));
        }
        r
    }
}

/// Buffers reused by every merged face (no allocation per face): `B`'s polygon and `-RA`'s.
#[derive(Default)]
pub(crate) struct PlanarScratch {
    pub(crate) b: Polygon,
    pub(crate) a: Polygon,
    /// The edge classes of [`face_plus_segment`].
    pub(crate) classes: Vec<u8>,
}

/// The convex polygon `F + G` of a merged face with outward normal `normal`, where `F` is `B`'s polygon
/// (`scratch.pj`/`pe`) and `G` is `-RA`'s (`scratch.qi`/`qe`), both counter-clockwise about `normal` (a face, or an
/// edge as a 2-gon), as the vertex-pair cycle of its corners into `out`, counter-clockwise about `normal`.
///
/// The classic O(|F| + |G|) merge of the two edge sequences by angle (the sum's edges are the summands' edges in
/// angular order): starting at `F`'s edge 0 and the corner of `G` whose outgoing edge comes first at or after it, the
/// walk advances in the polygon whose next edge turns first. An edge `p` of `F` and an edge `q` of `G` that point the
/// same way (`p . q > 0`) are one edge of the sum (both advance; their middle corner is not a corner) when the sine of
/// their angle is at most half the tolerance (`|p x q|^2 <= (tol / 2)^2 |p|^2 |q|^2`), or when the faces of `B` and
/// `A` across them are merged. Both tests see the same vectors (up to an exact sign) for the same pair of edges in
/// every face, so neighbouring faces agree. All other order decisions are signs of `(v x w) . normal` for
/// non-parallel `v`, `w`, which the rounding of the inputs cannot flip. No coordinates are sorted or compared, so no
/// length tolerance enters. O(|F| + |G|), no allocation (the scratch buffers are reused).
pub(crate) fn planar_merge(
    merged_with_b: &[Option<usize>],
    normal: DVec3,
    faces: bool,
    scratch: &PlanarScratch,
    out: &mut Vec<[usize; 2]>,
) {
    let (pj, pd, pn) = (&scratch.b.corners, &scratch.b.edges, &scratch.b.across);
    let (qi, qd, qn) = (&scratch.a.corners, &scratch.a.edges, &scratch.a.across);
    let (m, n) = (pj.len(), qi.len());
    let r = pd[0].0;
    // one edge of the sum: pointing the same way, and the faces across both edges are merged (then so are the edges,
    // whatever their rounded directions say: the neighbouring merged face decides the same way) or the sine of their
    // angle is at most half the tolerance (`c = p x q`; the same vectors up to sign in every face, so the same answer)
    let same = |k: usize, l: usize, c: DVec3| {
        let ((p, p2, _), (q, q2, _)) = (pd[k], qd[l]);
        p.dot(q) > 0.0
            && (c.length_squared() <= PARALLEL_SQ * p2 * q2 || (faces && merged_with_b[qn[l]] == Some(pn[k])))
    };
    // G's first edge: the one parallel to r, else the first in angular order
    let mut l0 = 0;
    if !same(0, 0, r.cross(qd[0].0)) {
        for l in 1..n {
            if same(0, l, r.cross(qd[l].0)) {
                l0 = l;
                break;
            }
            let ((v, _, hv), (w, _, hw)) = (qd[l], qd[l0]);
            if hv < hw || (hv == hw && v.cross(w).dot(normal) > 0.0) {
                l0 = l;
            }
        }
    }
    let (mut k, mut l) = (0, 0);
    while k < m || l < n {
        let lq = if l0 + l >= n { l0 + l - n } else { l0 + l };
        out.push([qi[lq], pj[if k == m { 0 } else { k }]]);
        if k == m {
            l += 1;
        } else if l == n {
            k += 1;
        } else {
            let ((p, _, hp), (q, _, hq)) = (pd[k], qd[lq]);
            let c = p.cross(q);
            if same(k, lq, c) {
                k += 1;
                l += 1;
            } else if hp < hq || (hp == hq && c.dot(normal) > 0.0) {
                k += 1;
            } else {
                l += 1;
            }
        }
    }
}

/// [`planar_merge`] for a face plus a parallel edge (a 2-gon), in one pass: the face polygon `corners` (points
/// `points`, counter-clockwise about `normal`) plus the segment `segment` (points `segment_points`); `FACE_IS_B` says
/// whether the face is `B`'s (the corner labels are then `[segment vertex, corner]`, else `[corner, segment vertex]`).
///
/// With `d` the segment's direction, every face edge `e` is *parallel* (`e . d > 0`), *antiparallel* (`e . d < 0`)
/// when the sine of their angle is at most half the tolerance (the test of [`planar_merge`], evaluated with the same
/// operands in the same order: `B`'s edge first), else *after* `d` (`(d x e) . normal > 0`) or *before* it. The sum
/// translates the face edges before `d` by the segment's start `s0`, those after it by its end `s1`; a parallel edge
/// runs from `s0` to `s1`, an antiparallel one from `s1` to `s0`. Each corner of the face is one corner of the sum
/// when the edges on both sides translate it alike, else two (the segment's edge `d` or `-d` joins them). Exactly the
/// cycle [`planar_merge`] gives for the 2-gon (up to where it starts), in O(|F|) with one cross product per edge.
#[allow(clippy::too_many_arguments)]
pub(crate) fn face_plus_segment<const FACE_IS_B: bool>(
    corners: &[usize],
    points: &[DVec3],
    segment: [usize; 2],
    segment_points: &[DVec3],
    normal: DVec3,
    classes: &mut Vec<u8>,
    out: &mut Vec<[usize; 2]>,
) {
    const BEFORE: u8 = 0;
    const AFTER: u8 = 1;
    const PARALLEL: u8 = 2;
    const ANTIPARALLEL: u8 = 3;
    let d = segment_points[segment[1]] - segment_points[segment[0]];
    let m = corners.len();
    classes.clear();
    let first = points[corners[0]];
    let mut current = first;
    for k in 1..=m {
        let next = if k == m { first } else { points[corners[k]] };
        let e = next - current;
        current = next;
        // the parallel test with B's edge first, as in `planar_merge` (bit for bit: the same products in the same
        // order); `|c . normal| <= |c|`, so a turn clearly above the tolerance skips the length (the margin 2 covers
        // the rounding of the unit normal)
        let (p, q) = if FACE_IS_B { (e, d) } else { (d, e) };
        let c = p.cross(q);
        let turn = c.dot(normal);
        let tolerance = PARALLEL_SQ * p.length_squared() * q.length_squared();
        let parallel = turn * turn <= 2.0 * tolerance && c.length_squared() <= tolerance;
        // (d x e) . normal is `turn` for an A face and `-turn` for a B face
        classes.push(if parallel {
            if e.dot(d) > 0.0 { PARALLEL } else { ANTIPARALLEL }
        } else if (if FACE_IS_B { -turn } else { turn }) > 0.0 {
            AFTER
        } else {
            BEFORE
        });
    }
    let label = |corner: usize, end: usize| if FACE_IS_B { [segment[end], corner] } else { [corner, segment[end]] };
    for k in 0..m {
        let (incoming, outgoing) = (classes[if k == 0 { m - 1 } else { k - 1 }], classes[k]);
        // the end of the segment by which corner k is translated as the end of the incoming edge, and as the start
        // of the outgoing one
        let end = usize::from(incoming == AFTER || incoming == PARALLEL);
        let start = usize::from(!(outgoing == BEFORE || outgoing == PARALLEL));
        out.push(label(corners[k], end));
        if start != end {
            out.push(label(corners[k], start));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::types::ANGULAR_TOLERANCE;

    /// A polygon for [`planar_merge`] from raw points (what `Polygon::build` computes for a feature).
    fn raw_polygon(points: &[DVec3], corners: &[usize], normal: DVec3, reference: Option<DVec3>) -> (Polygon, DVec3) {
        let n = corners.len();
        let r = reference.unwrap_or(points[corners[1]] - points[corners[0]]);
        let edges = (0..n)
            .map(|k| {
                let d = points[corners[(k + 1) % n]] - points[corners[k]];
                let s = r.cross(d).dot(normal);
                (d, d.length_squared(), u8::from(!(s > 0.0 || (s == 0.0 && r.dot(d) > 0.0))))
            })
            .collect();
        (Polygon { corners: corners.to_vec(), edges, across: vec![usize::MAX; n] }, r)
    }

    fn same_cycle(a: &[[usize; 2]], b: &[[usize; 2]]) -> bool {
        a.len() == b.len() && (0..a.len()).any(|s| (0..a.len()).all(|k| a[(s + k) % a.len()] == b[k]))
    }

    #[test]
    fn face_plus_segment_is_the_general_merge_of_a_2_gon() {
        // convex polygons (regular, rotated, scaled) plus segments in every direction: exactly along an edge, within
        // 0.3 and 0.7 of the tolerance of it, and generic; the face as B's and as A's
        let normal = DVec3::Z;
        let mut cases = 0;
        for sides in 3..9 {
            for turn in [0.0, 0.1, 1.0] {
                let points: Vec<DVec3> = (0..sides)
                    .map(|k| {
                        let t = turn + k as f64 * std::f64::consts::TAU / sides as f64;
                        DVec3::new(3.0 * t.cos() + 1.0, 2.0 * t.sin() - 0.5, 0.25)
                    })
                    .collect();
                let corners: Vec<usize> = (0..sides).collect();
                let mut directions = Vec::new();
                for k in 0..sides {
                    let e = points[(k + 1) % sides] - points[k];
                    let angle = e.y.atan2(e.x);
                    for offset in [0.0, 0.3, -0.3, 0.7, -0.7, 3.0] {
                        let a = angle + offset * ANGULAR_TOLERANCE;
                        directions.push(DVec3::new(a.cos(), a.sin(), 0.0) * 1.5);
                    }
                    directions.push(DVec3::new((angle + 0.4).cos(), (angle + 0.4).sin(), 0.0));
                }
                for d in directions {
                    for face_is_b in [true, false] {
                        // the segment's points: [p, p + d]
                        let seg_points = vec![DVec3::new(0.5, 0.25, 0.0), DVec3::new(0.5, 0.25, 0.0) + d];
                        let mut got = Vec::new();
                        let mut classes = Vec::new();
                        let (c, p, sp) = (&corners, &points, &seg_points);
                        if face_is_b {
                            face_plus_segment::<true>(c, p, [0, 1], sp, normal, &mut classes, &mut got);
                        } else {
                            face_plus_segment::<false>(c, p, [0, 1], sp, normal, &mut classes, &mut got);
                        }
                        let (b_points, b_corners, a_points, a_corners) = if face_is_b {
                            (&points, corners.clone(), &seg_points, vec![0, 1])
                        } else {
                            (&seg_points, vec![0, 1], &points, corners.clone())
                        };
                        let (b, r) = raw_polygon(b_points, &b_corners, normal, None);
                        let (a, _) = raw_polygon(a_points, &a_corners, normal, Some(r));
                        let scratch = PlanarScratch { b, a, classes: Vec::new() };
                        let mut expected = Vec::new();
                        planar_merge(&[], normal, false, &scratch, &mut expected);
                        assert!(
                            same_cycle(&got, &expected),
                            "{sides} sides, d {d}, face_is_b {face_is_b}: {got:?} vs {expected:?}"
                        );
                        cases += 1;
                    }
                }
            }
        }
        assert!(cases > 500);
    }
}
