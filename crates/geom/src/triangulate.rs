//! Triangulation of a simple polygon with holes: hole bridging, then ear clipping, every decision exact.
//!
//! Algorithm: D. Eberly, *Triangulation by Ear Clipping* (Geometric Tools, 2002, rev. 2015), sections 2-5: the holes
//! are joined to the outer boundary by *bridges* (a pair of coincident, oppositely directed edges from a hole vertex
//! `M` to a mutually visible vertex `V` of the current outer polygon), which turns the polygon with holes into one
//! weakly simple polygon with `n + 2h` vertices; ear clipping then cuts off `n + 2h - 2` triangles. (H. ElGindy,
//! H. Everett, G. T. Toussaint, *Slicing an ear using prune-and-search*, 1993, for the two-ears theorem behind it.)
//!
//! Differences from Eberly's text, for robustness with exact predicates only:
//! * The bridge is not found through a computed ray intersection point. Holes are processed in decreasing order of
//!   their lexicographically largest vertex `M` (as in Eberly), and the candidate vertices `V` of the current
//!   polygon are tried in order of increasing distance from `M` (a heuristic only); the first `V` whose segment
//!   `MV` is *certified* visible is taken: `MV` lies strictly inside the interior angle at `V` and at `M`, and meets
//!   no edge of the polygon or of any hole, except edges incident to the positions of `M` and `V` themselves. Every
//!   test is an exact `orient2d`. Eberly's argument shows a visible `V` exists for this `M`.
//! * An ear `(a, b, c)` requires: `b` strictly convex; the diagonal `ac` strictly inside the interior angles at `a`
//!   and `c`; no other vertex in the *closed* triangle, except copies of `a`, `b`, `c` made by bridging. Straight
//!   vertices (collinear runs) are never ear tips, so no triangle is degenerate, and a vertex on the diagonal blocks
//!   the ear, so collinear runs are handled exactly.
//!
//! Preconditions (checked by [`crate::polygon::check_rings`] in the sheet-metal model): the outline is simple and
//! counter-clockwise, the holes are simple, clockwise, strictly inside the outline and pairwise disjoint, and no
//! ring has consecutive duplicate points. Violations give a [`TriangulationError`], never a panic.
//!
//! Complexity: bridging O(h n^2) in the worst case (O(h n log n) typically: the nearest candidate is usually
//! visible); ear clipping O(n^2) ear tests of O(n) each in the worst case, O(n^2) typically.

use crate::polygon::nearly_straight;
use crate::predicates::orient2d;
use glam::DVec2;
use std::cmp::Ordering;

/// Why a polygon could not be triangulated (only when the preconditions are violated).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TriangulationError {
    /// A ring has fewer than three vertices or refers to a missing point.
    #[error("ring {ring} is not a polygon (fewer than 3 vertices or a bad index)")]
    BadRing {
        /// 0 for the outline, k + 1 for hole k.
        ring: usize,
    },
    /// No vertex of the outer polygon sees the hole (the hole is not strictly inside, or rings intersect).
    #[error("hole {hole} cannot be bridged to the outline")]
    NoBridge {
        /// Hole index.
        hole: usize,
    },
    /// No ear exists: the polygon is not simple.
    #[error("no ear found with {remaining} vertices left: the polygon is not simple")]
    NoEar {
        /// Vertices left when clipping stopped.
        remaining: usize,
    },
}

/// Triangulates the polygon `outline` (counter-clockwise) with `holes` (clockwise), given as indices into
/// `points`. Returns counter-clockwise triangles of point indices: exactly `n + 2h - 2` of them for `n` vertices in
/// all rings and `h` holes. Same as [`triangulate_avoiding_slivers`] with `sliver = 0`.
pub fn triangulate(
    points: &[DVec2],
    outline: &[usize],
    holes: &[Vec<usize>],
) -> Result<Vec<[usize; 3]>, TriangulationError> {
    triangulate_avoiding_slivers(points, outline, holes, 0.0)
}

/// [`triangulate`], preferring ears whose tip is farther than `sliver` from the line through its neighbours (see
/// [`clip_ears`]): for input that is only nearly collinear (rotated collinear runs), this avoids needle triangles
/// whenever another valid ear exists.
pub fn triangulate_avoiding_slivers(
    points: &[DVec2],
    outline: &[usize],
    holes: &[Vec<usize>],
    sliver: f64,
) -> Result<Vec<[usize; 3]>, TriangulationError> {
    for (r, ring) in std::iter::once(outline).chain(holes.iter().map(|h| h.as_slice())).enumerate() {
        if ring.len() < 3 || ring.iter().any(|&i| i >= points.len()) {
            return Err(TriangulationError::BadRing { ring: r });
        }
    }
    let polygon = bridge_holes(points, outline, holes, sliver)?;
    let mut triangles = clip_ears(points, &polygon, sliver)?;
    make_delaunay(points, &mut triangles);
    Ok(triangles)
}

/// Turns a triangulation of a polygon into its *constrained Delaunay* triangulation by Lawson's edge flips
/// (C. L. Lawson, *Software for C1 surface interpolation*, 1977; the constrained version: L. P. Chew, *Constrained
/// Delaunay triangulations*, Algorithmica 4, 1989): an edge shared by two triangles `(a, c, x)` and `(c, a, y)` is
/// replaced by `xy` when `y` lies strictly inside the circumcircle of `(a, c, x)` (Shewchuk's exact `incircle`) and
/// the quadrilateral is strictly convex (exact `orient2d`). Polygon edges have one triangle and are never flipped.
/// Each flip strictly lowers the triangulation on the paraboloid lifting, so the loop terminates; O(n^2) flips in
/// the worst case, about O(n) in practice.
///
/// Why: a Delaunay triangulation maximises the smallest angle, so it avoids needle triangles wherever the polygon
/// allows. Ear clipping on a rotated part produces needles along lines that carry several vertices (hole edges
/// aligned across holes, common in sheet metal), and needles cannot be extruded into strictly convex prisms.
fn make_delaunay(points: &[DVec2], triangles: &mut [[usize; 3]]) {
    use std::collections::HashMap;
    let incircle = |a: DVec2, b: DVec2, c: DVec2, d: DVec2| {
        let q = |p: DVec2| robust::Coord { x: p.x, y: p.y };
        robust::incircle(q(a), q(b), q(c), q(d)) > 0.0
    };
    let mut edges: HashMap<(usize, usize), usize> = HashMap::with_capacity(3 * triangles.len());
    for (i, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            edges.insert((t[k], t[(k + 1) % 3]), i);
        }
    }
    let mut stack: Vec<(usize, usize)> = edges.keys().copied().filter(|&(a, c)| a < c).collect();
    stack.sort_unstable();
    let mut budget = 8 * triangles.len() * triangles.len() + 16;
    while let Some((a, c)) = stack.pop() {
        if budget == 0 {
            tracing::debug!("Delaunay flip budget exhausted");
            return;
        }
        let (Some(&i), Some(&j)) = (edges.get(&(a, c)), edges.get(&(c, a))) else {
            continue;
        };
        let third = |t: [usize; 3]| t.iter().copied().find(|&v| v != a && v != c);
        let (Some(x), Some(y)) = (third(triangles[i]), third(triangles[j])) else {
            continue;
        };
        let (pa, pc, px, py) = (points[a], points[c], points[x], points[y]);
        if px == py || !incircle(pa, pc, px, py) {
            continue;
        }
        if orient2d(px, pa, py) != Ordering::Greater || orient2d(py, pc, px) != Ordering::Greater {
            continue;
        }
        budget -= 1;
        for t in [triangles[i], triangles[j]] {
            for m in 0..3 {
                edges.remove(&(t[m], t[(m + 1) % 3]));
            }
        }
        triangles[i] = [x, a, y];
        triangles[j] = [y, c, x];
        for idx in [i, j] {
            let t = triangles[idx];
            for m in 0..3 {
                edges.insert((t[m], t[(m + 1) % 3]), idx);
            }
        }
        for (u, v) in [(a, x), (x, c), (c, y), (y, a)] {
            stack.push((u.min(v), u.max(v)));
        }
    }
}

/// Joins every hole to the outer polygon by a bridge; returns the weakly simple polygon (with repeated indices).
///
/// Among valid bridges, one that is not (nearly) collinear with an edge at either end is preferred (`sliver` as in
/// [`clip_ears`]); validity is always decided exactly.
pub fn bridge_holes(
    points: &[DVec2],
    outline: &[usize],
    holes: &[Vec<usize>],
    sliver: f64,
) -> Result<Vec<usize>, TriangulationError> {
    let mut polygon: Vec<usize> = outline.to_vec();
    // (hole index, position of its lexicographically largest vertex)
    let mut order: Vec<(usize, usize)> = holes
        .iter()
        .enumerate()
        .map(|(h, ring)| {
            let m = (0..ring.len()).max_by(|&i, &j| lex(points[ring[i]], points[ring[j]])).unwrap_or(0);
            (h, m)
        })
        .collect();
    order.sort_by(|&(h, m), &(g, k)| lex(points[holes[g][k]], points[holes[h][m]]));
    let mut merged = vec![false; holes.len()];
    for &(h, m_pos) in &order {
        let ring = &holes[h];
        let hole_seq: Vec<usize> = (0..ring.len()).map(|k| ring[(m_pos + k) % ring.len()]).collect();
        let m = points[hole_seq[0]];
        let m_prev = points[hole_seq[hole_seq.len() - 1]];
        let m_next = points[hole_seq[1]];
        let mut candidates: Vec<usize> = (0..polygon.len()).collect();
        candidates.sort_by(|&i, &j| {
            let di = (points[polygon[i]] - m).length_squared();
            let dj = (points[polygon[j]] - m).length_squared();
            di.total_cmp(&dj).then(i.cmp(&j))
        });
        let unmerged: Vec<&Vec<usize>> =
            holes.iter().enumerate().filter(|&(g, _)| !merged[g]).map(|(_, ring)| ring).collect();
        let valid = |k: usize| {
            let n = polygon.len();
            let v = points[polygon[k]];
            let v_prev = points[polygon[(k + n - 1) % n]];
            let v_next = points[polygon[(k + 1) % n]];
            v != m
                && strictly_inside_angle(v_prev, v, v_next, m)
                && strictly_inside_angle(m_prev, m, m_next, v)
                && segment_is_free(points, m, v, &polygon, &unmerged)
        };
        // a bridge nearly collinear with an edge at either end would give needle triangles: prefer a clean one
        let clean = |k: usize| {
            let n = polygon.len();
            let v = points[polygon[k]];
            let v_prev = points[polygon[(k + n - 1) % n]];
            let v_next = points[polygon[(k + 1) % n]];
            ![(v_prev, v, m), (m, v, v_next), (v, m, m_next), (m_prev, m, v)]
                .iter()
                .any(|&(a, b, c)| orient2d(a, b, c) == Ordering::Equal || nearly_straight(a, b, c, sliver))
        };
        let found = candidates
            .iter()
            .copied()
            .find(|&k| clean(k) && valid(k))
            .or_else(|| candidates.iter().copied().find(|&k| valid(k)));
        let Some(k) = found else {
            return Err(TriangulationError::NoBridge { hole: h });
        };
        let v_index = polygon[k];
        let mut spliced = Vec::with_capacity(polygon.len() + hole_seq.len() + 2);
        spliced.extend_from_slice(&polygon[..=k]);
        spliced.extend_from_slice(&hole_seq);
        spliced.push(hole_seq[0]);
        spliced.push(v_index);
        spliced.extend_from_slice(&polygon[k + 1..]);
        polygon = spliced;
        merged[h] = true;
        tracing::trace!(hole = h, bridge_from = hole_seq[0], bridge_to = v_index, "bridged hole");
    }
    Ok(polygon)
}

/// Whether the segment `mv` meets no edge of `polygon` or of `rings`, ignoring edges with an endpoint at the
/// position of `m` or `v` (those are judged by the angle tests).
fn segment_is_free(points: &[DVec2], m: DVec2, v: DVec2, polygon: &[usize], rings: &[&Vec<usize>]) -> bool {
    let blocked = |ring: &[usize]| {
        let n = ring.len();
        (0..n).any(|i| {
            let a = points[ring[i]];
            let b = points[ring[(i + 1) % n]];
            if a == m || a == v || b == m || b == v {
                return false;
            }
            crate::polygon::segments_intersect(m, v, a, b)
        })
    };
    !blocked(polygon) && !rings.iter().any(|r| blocked(r))
}

/// Whether the direction from `v` to `x` lies strictly inside the interior angle at `v` of a polygon traversed
/// `prev -> v -> next` with the interior on the left.
#[inline]
fn strictly_inside_angle(prev: DVec2, v: DVec2, next: DVec2, x: DVec2) -> bool {
    let left_of_in = orient2d(prev, v, x) == Ordering::Greater;
    let left_of_out = orient2d(v, next, x) == Ordering::Greater;
    if orient2d(prev, v, next) == Ordering::Greater { left_of_in && left_of_out } else { left_of_in || left_of_out }
}

/// Ear clipping of a weakly simple counter-clockwise polygon (indices may repeat where holes were bridged).
///
/// `sliver` is a length: ears whose tip lies within `sliver` of the line through its neighbours (nearly straight
/// tips, which give needle triangles) are taken only when no other ear exists. The validity of an ear is always
/// decided exactly; `sliver` only orders the choice. Pass 0 to take the first exact ear.
pub fn clip_ears(points: &[DVec2], polygon: &[usize], sliver: f64) -> Result<Vec<[usize; 3]>, TriangulationError> {
    let n = polygon.len();
    if n < 3 {
        return Err(TriangulationError::NoEar { remaining: n });
    }
    let mut prev: Vec<usize> = (0..n).map(|i| (i + n - 1) % n).collect();
    let mut next: Vec<usize> = (0..n).map(|i| (i + 1) % n).collect();
    let mut triangles = Vec::with_capacity(n - 2);
    let mut remaining = n;
    let mut current = 0;
    let robust = |a: usize, b: usize, c: usize| {
        let (pa, pb, pc) = (points[polygon[a]], points[polygon[b]], points[polygon[c]]);
        (pb - pa).perp_dot(pc - pa) > sliver * (pc - pa).length()
    };
    while remaining > 3 {
        let scan = |want_robust: bool| {
            let mut k = current;
            for _ in 0..remaining {
                if (!want_robust || robust(prev[k], k, next[k])) && is_ear(points, polygon, &prev, &next, k) {
                    return Some(k);
                }
                k = next[k];
            }
            None
        };
        let Some(ear) = scan(true).or_else(|| scan(false)) else {
            return Err(TriangulationError::NoEar { remaining });
        };
        let (a, c) = (prev[ear], next[ear]);
        triangles.push([polygon[a], polygon[ear], polygon[c]]);
        next[a] = c;
        prev[c] = a;
        remaining -= 1;
        // the neighbours' ear status changed: look at the previous one first
        current = a;
    }
    let (a, c) = (prev[current], next[current]);
    let last = [polygon[a], polygon[current], polygon[c]];
    if orient2d(points[last[0]], points[last[1]], points[last[2]]) != Ordering::Greater {
        return Err(TriangulationError::NoEar { remaining });
    }
    triangles.push(last);
    Ok(triangles)
}

fn is_ear(points: &[DVec2], polygon: &[usize], prev: &[usize], next: &[usize], b: usize) -> bool {
    let a = prev[b];
    let c = next[b];
    let (pa, pb, pc) = (points[polygon[a]], points[polygon[b]], points[polygon[c]]);
    if orient2d(pa, pb, pc) != Ordering::Greater {
        return false;
    }
    if !strictly_inside_angle(points[polygon[prev[a]]], pa, pb, pc)
        || !strictly_inside_angle(pb, pc, points[polygon[next[c]]], pa)
    {
        return false;
    }
    let mut k = next[c];
    while k != a {
        let p = points[polygon[k]];
        if p != pa
            && p != pb
            && p != pc
            && orient2d(pa, pb, p) != Ordering::Less
            && orient2d(pb, pc, p) != Ordering::Less
            && orient2d(pc, pa, p) != Ordering::Less
        {
            return false;
        }
        k = next[k];
    }
    true
}

#[inline]
fn lex(a: DVec2, b: DVec2) -> Ordering {
    crate::polygon::lex(a, b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::polygon::signed_area2;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    fn area(points: &[DVec2], t: &[usize; 3]) -> f64 {
        signed_area2(&[points[t[0]], points[t[1]], points[t[2]]]) / 2.0
    }

    fn check(points: &[DVec2], outline: &[usize], holes: &[Vec<usize>], expected_area: f64) -> Vec<[usize; 3]> {
        let tris = triangulate(points, outline, holes).expect("triangulation");
        let n: usize = outline.len() + holes.iter().map(|h| h.len()).sum::<usize>();
        assert_eq!(tris.len(), n + 2 * holes.len() - 2);
        let mut total = 0.0;
        for t in &tris {
            let a = area(points, t);
            assert!(a > 0.0, "degenerate or clockwise triangle {t:?}");
            total += a;
        }
        assert!((total - expected_area).abs() < 1e-9 * expected_area.max(1.0), "area {total} vs {expected_area}");
        tris
    }

    #[test]
    fn square_and_collinear_runs() {
        let pts = vec![v(0.0, 0.0), v(1.0, 0.0), v(2.0, 0.0), v(3.0, 0.0), v(3.0, 3.0), v(0.0, 3.0), v(0.0, 1.5)];
        let outline: Vec<usize> = (0..pts.len()).collect();
        check(&pts, &outline, &[], 9.0);
    }

    #[test]
    fn comb_polygon() {
        // a comb: a concave polygon with many reflex vertices
        let mut pts = vec![v(0.0, 0.0), v(10.0, 0.0)];
        for k in (0..5).rev() {
            let x = 2.0 * k as f64;
            pts.push(v(x + 2.0, 5.0));
            pts.push(v(x + 1.0, 1.0));
        }
        pts.push(v(0.0, 5.0));
        let outline: Vec<usize> = (0..pts.len()).collect();
        let area = signed_area2(&pts) / 2.0;
        assert!(area > 0.0);
        check(&pts, &outline, &[], area);
    }

    #[test]
    fn square_with_holes_sharing_x_extremes() {
        let mut pts = vec![v(0.0, 0.0), v(10.0, 0.0), v(10.0, 10.0), v(0.0, 10.0)];
        let mut holes = Vec::new();
        // three holes whose rightmost vertices share an x coordinate, and one aligned with an outline vertex row
        for (x0, y0) in [(2.0, 2.0), (2.0, 6.0), (6.0, 2.0), (6.0, 6.0)] {
            let base = pts.len();
            pts.extend([v(x0, y0), v(x0, y0 + 2.0), v(x0 + 2.0, y0 + 2.0), v(x0 + 2.0, y0)]); // clockwise
            holes.push((base..base + 4).collect::<Vec<_>>());
        }
        check(&pts, &[0, 1, 2, 3], &holes, 100.0 - 16.0);
    }

    #[test]
    fn hole_in_concave_polygon_behind_reflex_vertex() {
        // a U shape whose hole's visible vertex is hidden behind the reflex corner for the naive nearest choice
        let pts = vec![
            v(0.0, 0.0),
            v(10.0, 0.0),
            v(10.0, 10.0),
            v(7.0, 10.0),
            v(7.0, 3.0),
            v(3.0, 3.0),
            v(3.0, 10.0),
            v(0.0, 10.0),
            // hole in the left arm (clockwise)
            v(1.0, 5.0),
            v(1.0, 8.0),
            v(2.0, 8.0),
            v(2.0, 5.0),
        ];
        let area = 100.0 - 28.0 - 3.0;
        check(&pts, &[0, 1, 2, 3, 4, 5, 6, 7], &[vec![8, 9, 10, 11]], area);
    }

    #[test]
    fn rejects_non_simple_input() {
        // a bow tie is not simple: no valid ear sequence
        let pts = vec![v(0.0, 0.0), v(2.0, 2.0), v(2.0, 0.0), v(0.0, 2.0)];
        assert!(triangulate(&pts, &[0, 1, 2, 3], &[]).is_err());
        assert_eq!(triangulate(&pts, &[0, 1], &[]), Err(TriangulationError::BadRing { ring: 0 }));
        assert_eq!(triangulate(&pts, &[0, 1, 9], &[]), Err(TriangulationError::BadRing { ring: 0 }));
        // a hole outside the outline cannot be bridged
        let pts = vec![v(0.0, 0.0), v(1.0, 0.0), v(0.0, 1.0), v(5.0, 5.0), v(5.0, 6.0), v(6.0, 6.0)];
        assert!(triangulate(&pts, &[0, 1, 2], &[vec![3, 4, 5]]).is_err());
    }
}
