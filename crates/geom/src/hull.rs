//! Robust 3-D convex hull: Quickhull with exact visibility, then exact coplanar-facet merging.
//!
//! Algorithm: C. B. Barber, D. P. Dobkin, H. Huhdanpaa, *The Quickhull Algorithm for Convex Hulls*, ACM TOMS 22(4),
//! 1996 — with every combinatorial decision made by Shewchuk's exact `orient3d` ([`crate::predicates`]) instead of
//! Barber's thick facets. Expected O(n log n) for random input (O(n^2) worst case), plus O(h) for merging.
//!
//! Why it is correct on sheet-metal input without any tolerance:
//! * a point is *visible* from a triangle only if it lies strictly above its plane (exact sign). A point outside the
//!   current hull is strictly above at least one triangle, so no extreme point is ever lost; a point on the boundary
//!   is never added, so duplicates and points inside faces or on edges never become vertices;
//! * a new triangle joins the point `p` to a horizon edge `e` of a visible triangle `t`. It cannot be degenerate:
//!   `p` collinear with `e` would put `p` in the plane of `t`, contradicting strict visibility;
//! * afterwards, adjacent triangles that are exactly coplanar (exact `orient3d == 0`) are merged into one polygonal
//!   face (on a convex surface such a group is a single convex polygon), and a vertex is kept only if at least three
//!   distinct faces meet there: a vertex with one face lies inside it, with two it lies inside an edge. What remains is
//!   exactly the set of extreme points, and every face is strictly convex to its neighbours.
//!
//! Flat, collinear and coincident input has no 3-D hull and returns a [`HullError`].
//!
//! **Face planes.** A face's plane is computed from its best-conditioned triangle with an accurate cross product
//! ([`crate::accurate_normal`]): where rounding moved points off a common plane, the exact hull has sliver facets a
//! few ulps wide, whose plain `f64` normals can point anywhere (planes that cut the hull by tens of millimetres).
//!
//! **Creases.** The points of a rotated sheet-metal face are coplanar only to rounding, so the exact hull splits the
//! face into facets that meet at creases of about 1e-16 rad, with slivers a few ulps wide where a point lies next to
//! an edge; no real part has such folds, and downstream they make near-parallel faces within one polytope (the c-space
//! overlay cannot pair them with the other summand's faces; its exact-hull fallback is correct but fragmented) and
//! split a resting face so that no facet holds the c.g. [`convex_hull_merged`], the hull the part readers build, joins
//! adjacent facets that lie in one plane within the kernel's length tolerance (`1e-9 x` the points' extent,
//! [`crate::tolerance`]): a facet whose vertices all lie within it of its larger neighbour's plane joins that
//! neighbour, and a joined face is kept only when all its vertices lie within the tolerance of its plane (the
//! area-weighted normal of its facets); else its facets stay apart. So a fold is merged only when it moves no vertex
//! by more than the tolerance (between faces 100 mm across, a crease of about 1e-9 rad). Every decision of the hull
//! itself stays exact, only facets are grouped; a vertex where fewer than three faces meet is dropped, as in the exact
//! merge (it lies within the tolerance of an edge or a face). Should the merged faces not close up into a polytope,
//! the exact hull is returned.
//!
//! The exact predicates are exact only while products of coordinate differences neither underflow nor overflow: a
//! coordinate below [`MIN_COORDINATE`] (1e-50) in magnitude is taken as 0 (the hull's vertices carry the zero), and
//! one above [`MAX_HULL_COORDINATE`] (1e50) is [`HullError::OutOfRange`].

use crate::accurate_normal::accurate_cross;
use crate::polytope::{ConvexPolytope, Face, Plane, PolytopeError};
use crate::predicates::{self, side};
use glam::DVec3;
use std::cmp::Ordering;

/// Why a point set has no 3-D convex hull.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HullError {
    /// No points.
    #[error("no points")]
    Empty,
    /// A coordinate is NaN or infinite.
    #[error("point {index} has a non-finite coordinate")]
    NonFinite {
        /// Index of the offending point.
        index: usize,
    },
    /// All points coincide.
    #[error("all points coincide: the hull is a point, not a solid")]
    Coincident,
    /// All points lie on a line.
    #[error("all points are collinear: the hull is a segment, not a solid")]
    Collinear,
    /// All points lie in a plane.
    #[error("all points are coplanar: the hull is flat, not a solid")]
    Coplanar,
    /// A coordinate larger than [`MAX_HULL_COORDINATE`] in magnitude.
    #[error(
        "point {index} has the coordinate {value:e}, beyond the supported 1e50 in magnitude (where the exact \
         predicates' products would overflow)"
    )]
    OutOfRange {
        /// Index of the offending point.
        index: usize,
        /// The coordinate.
        value: f64,
    },
    /// Internal consistency failure (a bug): the triangulated surface could not be turned into a polytope.
    #[error("internal hull error: {0}")]
    Internal(#[from] PolytopeError),
}

/// A convex hull and, for each of its vertices, the index of the input point it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvexHull {
    /// The hull.
    pub polytope: ConvexPolytope,
    /// `source[i]` is the index in the input of `polytope.vertices()[i]` (the first such index when duplicated).
    pub source: Vec<usize>,
}

/// The smallest nonzero coordinate magnitude [`convex_hull`] keeps; smaller ones are taken as 0. The exact predicates
/// (Shewchuk's adaptive `orient3d`) are exact only while no product of coordinate differences underflows: a
/// coordinate that is 0 or at least 1e-50 in magnitude makes every nonzero difference at least `ulp(1e-50)`, about
/// 2^-218, and a product of three of them (with their expansion tails) stays far above the smallest normal double,
/// 2^-1022. Below it a product can round to zero, and a hull could come out inconsistent (a tetrahedron of edge
/// 1e-160 was "coplanar", two 1e-300 apart an "internal hull error"). Such coordinates arise from rounding (a part
/// turned by 1e-50 degree), never from a length that matters: moving a point by less than 1e-50 mm is no change.
/// The part readers reject them in files ([`crate::io`]), where they can only be mistakes.
pub const MIN_COORDINATE: f64 = 1e-50;

/// The largest coordinate magnitude [`convex_hull`] accepts: cubes of differences stay below 1e151, far from
/// overflow. (Part files are held to a tighter 1e9 mm, [`crate::io::MAX_COORDINATE`].)
pub const MAX_HULL_COORDINATE: f64 = 1e50;

/// The first coordinate beyond [`MAX_HULL_COORDINATE`], with its point's index.
fn out_of_range(points: &[DVec3]) -> Option<(usize, f64)> {
    points
        .iter()
        .enumerate()
        .find_map(|(i, p)| p.to_array().into_iter().find(|c| c.abs() > MAX_HULL_COORDINATE).map(|c| (i, c)))
}

/// `points` with every coordinate below [`MIN_COORDINATE`] in magnitude set to 0 (borrowed when there is none).
fn snap_tiny(points: &[DVec3]) -> std::borrow::Cow<'_, [DVec3]> {
    let tiny = |c: f64| c != 0.0 && c.abs() < MIN_COORDINATE;
    if !points.iter().any(|p| p.to_array().into_iter().any(tiny)) {
        return std::borrow::Cow::Borrowed(points);
    }
    let snap = |c: f64| if tiny(c) { 0.0 } else { c };
    std::borrow::Cow::Owned(points.iter().map(|p| DVec3::new(snap(p.x), snap(p.y), snap(p.z))).collect())
}

const NONE: u32 = u32::MAX;

#[derive(Debug, Clone)]
struct Tri {
    v: [u32; 3],
    /// `nbr[k]` is the triangle across the edge `v[k] -> v[(k + 1) % 3]`.
    nbr: [u32; 3],
    /// Float normal `(b - a) x (c - a)`: picks the farthest point, and filters the exact test (see [`above`]).
    normal: DVec3,
    /// Static error bound of `normal . (q - a)` over the input's bounding box: a float value beyond it has the sign
    /// of the exact determinant.
    filter: f64,
    /// Outside set: a FIFO linked list through [`Outside::next`] (no allocation per triangle).
    head: u32,
    tail: u32,
    alive: bool,
}

/// The links of the outside sets: `next[q]` is the point after `q` in its triangle's outside list.
struct Outside {
    next: Vec<u32>,
}

impl Outside {
    fn push(&mut self, t: &mut Tri, q: u32) {
        self.next[q as usize] = NONE;
        if t.head == NONE {
            t.head = q;
        } else {
            self.next[t.tail as usize] = q;
        }
        t.tail = q;
    }

    /// The points of `t`'s outside set, in insertion order.
    fn iter<'a>(&'a self, t: &Tri) -> impl Iterator<Item = u32> + 'a {
        let mut cur = t.head;
        std::iter::from_fn(move || {
            (cur != NONE).then(|| {
                let q = cur;
                cur = self.next[q as usize];
                q
            })
        })
    }
}

/// Convex hull of `points`. See the module documentation.
pub fn convex_hull(points: &[DVec3]) -> Result<ConvexHull, HullError> {
    hull_with(points, None)
}

/// [`convex_hull`] whose adjacent facets that lie in one plane within the length tolerance are one face: the hull of a
/// part's piece as the readers build it (see the module documentation, "Creases"). When the merged faces do not close
/// up into a polytope (a merge left a face with fewer than three corners), the exact hull.
pub fn convex_hull_merged(points: &[DVec3]) -> Result<ConvexHull, HullError> {
    convex_hull_merged_within(points, 0.0)
}

/// [`convex_hull_merged`] with a length tolerance of at least `tolerance` (never below the kernel's, `1e-9 x` the
/// points' extent; a tolerance that is not finite counts as 0): for points known only to a coarser precision, such as
/// the single-precision coordinates of an STL file, whose faces are planar only to that precision.
pub fn convex_hull_merged_within(points: &[DVec3], tolerance: f64) -> Result<ConvexHull, HullError> {
    let kernel = crate::tolerance::Tolerance::for_scale(crate::tolerance::bounding_diagonal(points)).linear;
    let tol = if tolerance.is_finite() { tolerance.max(kernel) } else { kernel };
    match hull_with(points, Some(tol)) {
        Ok(hull) => Ok(hull),
        // the exact hull of the same points (its errors are the input's, reported as such)
        Err(HullError::Internal(_)) => hull_with(points, None),
        Err(e) => Err(e),
    }
}

fn hull_with(points: &[DVec3], merge_tolerance: Option<f64>) -> Result<ConvexHull, HullError> {
    if points.is_empty() {
        return Err(HullError::Empty);
    }
    if let Some(index) = points.iter().position(|p| !p.is_finite()) {
        return Err(HullError::NonFinite { index });
    }
    if let Some((index, value)) = out_of_range(points) {
        return Err(HullError::OutOfRange { index, value });
    }
    let snapped = snap_tiny(points);
    let points: &[DVec3] = &snapped;
    let simplex = initial_simplex(points)?;
    // a slight overestimate of the largest |q - a| keeps the static filter safe
    let diameter = crate::tolerance::bounding_diagonal(points) * (1.0 + 1e-9);
    let mut tris = Vec::with_capacity(64 + 4 * points.len().min(4096)); // avoids regrowing the triangle list
    let mut outside = Outside { next: vec![NONE; points.len()] };
    build_simplex(points, simplex, &mut tris, diameter);
    assign_initial_outside(points, simplex, &mut tris, &mut outside);
    expand(points, &mut tris, &mut outside, diameter);
    merge(points, &tris, merge_tolerance)
}

fn initial_simplex(p: &[DVec3]) -> Result<[u32; 4], HullError> {
    // i0: lexicographically smallest point (an extreme point).
    let i0 = (0..p.len())
        .min_by(|&a, &b| p[a].to_array().partial_cmp(&p[b].to_array()).unwrap_or(Ordering::Equal))
        .unwrap_or(0);
    // i1: farthest from i0 (float choice, exact meaning: any point different from i0).
    let i1 = argmax(p.len(), |i| (p[i] - p[i0]).length_squared()).filter(|&i| p[i] != p[i0]);
    let Some(i1) = i1.or_else(|| (0..p.len()).find(|&i| p[i] != p[i0])) else {
        return Err(HullError::Coincident);
    };
    let dir = p[i1] - p[i0];
    let i2 = argmax(p.len(), |i| (p[i] - p[i0]).cross(dir).length_squared())
        .filter(|&i| !predicates::collinear(p[i0], p[i1], p[i]));
    let Some(i2) = i2.or_else(|| (0..p.len()).find(|&i| !predicates::collinear(p[i0], p[i1], p[i]))) else {
        return Err(HullError::Collinear);
    };
    let n = (p[i1] - p[i0]).cross(p[i2] - p[i0]);
    let i3 =
        argmax(p.len(), |i| n.dot(p[i] - p[i0]).abs()).filter(|&i| side(p[i0], p[i1], p[i2], p[i]) != Ordering::Equal);
    let Some(i3) = i3.or_else(|| (0..p.len()).find(|&i| side(p[i0], p[i1], p[i2], p[i]) != Ordering::Equal)) else {
        return Err(HullError::Coplanar);
    };
    Ok([i0 as u32, i1 as u32, i2 as u32, i3 as u32])
}

fn argmax(n: usize, f: impl Fn(usize) -> f64) -> Option<usize> {
    let mut best = None;
    let mut best_value = f64::NEG_INFINITY;
    for i in 0..n {
        let v = f(i);
        if v > best_value {
            best_value = v;
            best = Some(i);
        }
    }
    best
}

/// Relative size of the static filter. The rounding error of `fl((b - a) x (c - a)) . fl(q - a)` is below
/// `12 eps |b - a| |c - a| |q - a|` (eps = 2^-53, about 1.1e-16); 1e-12 leaves a margin of more than 700x.
const FILTER: f64 = 1e-12;

fn make_tri(p: &[DVec3], v: [u32; 3], diameter: f64) -> Tri {
    let (a, b, c) = (p[v[0] as usize], p[v[1] as usize], p[v[2] as usize]);
    let filter = FILTER * (b - a).length() * (c - a).length() * diameter;
    Tri { v, nbr: [NONE; 3], normal: (b - a).cross(c - a), filter, head: NONE, tail: NONE, alive: true }
}

/// Exactly whether `q` is strictly above the triangle's plane: a float evaluation decides when it is farther from
/// zero than its error bound, Shewchuk's adaptive `orient3d` otherwise.
#[inline]
fn above(p: &[DVec3], t: &Tri, q: u32) -> bool {
    let a = p[t.v[0] as usize];
    let d = t.normal.dot(p[q as usize] - a);
    if d > t.filter {
        return true;
    }
    if d < -t.filter {
        return false;
    }
    side(a, p[t.v[1] as usize], p[t.v[2] as usize], p[q as usize]) == Ordering::Greater
}

fn build_simplex(p: &[DVec3], s: [u32; 4], tris: &mut Vec<Tri>, diameter: f64) {
    let [a, b, c, d] = s;
    // orient (a, b, c) so that d is below it
    let (b, c) = if side(p[a as usize], p[b as usize], p[c as usize], p[d as usize]) == Ordering::Greater {
        (c, b)
    } else {
        (b, c)
    };
    let faces = [[a, b, c], [a, d, b], [b, d, c], [c, d, a]];
    for f in faces {
        tris.push(make_tri(p, f, diameter));
    }
    link_all(tris);
}

/// Links neighbours of all triangles by matching opposite half-edges (used for the simplex only).
fn link_all(tris: &mut [Tri]) {
    let n = tris.len();
    for i in 0..n {
        for k in 0..3 {
            let (a, b) = (tris[i].v[k], tris[i].v[(k + 1) % 3]);
            for j in 0..n {
                if j == i {
                    continue;
                }
                for m in 0..3 {
                    if tris[j].v[m] == b && tris[j].v[(m + 1) % 3] == a {
                        tris[i].nbr[k] = j as u32;
                    }
                }
            }
        }
    }
}

fn assign_initial_outside(p: &[DVec3], s: [u32; 4], tris: &mut [Tri], outside: &mut Outside) {
    for q in 0..p.len() as u32 {
        if s.contains(&q) {
            continue;
        }
        for t in tris.iter_mut() {
            if above(p, t, q) {
                outside.push(t, q);
                break;
            }
        }
    }
}

fn expand(p: &[DVec3], tris: &mut Vec<Tri>, outside: &mut Outside, diameter: f64) {
    let mut stack: Vec<u32> = (0..tris.len() as u32).filter(|&t| tris[t as usize].head != NONE).collect();
    let mut visible: Vec<u32> = Vec::new();
    let mut horizon: Vec<(u32, u32, u32)> = Vec::new(); // (a, b, invisible neighbour) with a -> b in visible tri
    let mut bfs: Vec<u32> = Vec::new();
    let mut mark: Vec<u32> = vec![0; tris.len()];
    let mut epoch = 0u32;
    // next_of[v] = position in `horizon` of the horizon edge starting at v (only valid for horizon vertices)
    let mut next_of: Vec<u32> = vec![NONE; p.len()];
    let mut ordered: Vec<(u32, u32, u32)> = Vec::new();
    let mut orphans: Vec<u32> = Vec::new();
    while let Some(t0) = stack.pop() {
        let t0u = t0 as usize;
        if !tris[t0u].alive || tris[t0u].head == NONE {
            continue;
        }
        // farthest outside point of t0 (float heuristic)
        let a0 = p[tris[t0u].v[0] as usize];
        let n0 = tris[t0u].normal;
        // `max_by` keeps the last of equal maxima (the tie rule the hull's output depends on)
        let apex = outside
            .iter(&tris[t0u])
            .max_by(|&x, &y| {
                n0.dot(p[x as usize] - a0).partial_cmp(&n0.dot(p[y as usize] - a0)).unwrap_or(Ordering::Equal)
            })
            .unwrap_or(tris[t0u].head);
        // visible set by BFS from t0 (the visible region is connected)
        epoch += 1;
        if mark.len() < tris.len() {
            mark.resize(tris.len(), 0);
        }
        visible.clear();
        horizon.clear();
        bfs.clear();
        bfs.push(t0);
        mark[t0u] = epoch;
        while let Some(t) = bfs.pop() {
            visible.push(t);
            for k in 0..3 {
                let nb = tris[t as usize].nbr[k];
                let nbu = nb as usize;
                if mark[nbu] == epoch {
                    continue;
                }
                if above(p, &tris[nbu], apex) {
                    mark[nbu] = epoch;
                    bfs.push(nb);
                }
            }
        }
        // horizon half-edges: edges of visible triangles whose neighbour is not visible
        for &t in &visible {
            let tr = &tris[t as usize];
            for k in 0..3 {
                let nb = tr.nbr[k];
                if mark[nb as usize] != epoch {
                    horizon.push((tr.v[k], tr.v[(k + 1) % 3], nb));
                }
            }
        }
        // order the horizon into a cycle: each start vertex appears exactly once
        let hn = horizon.len();
        ordered.clear();
        {
            for (i, h) in horizon.iter().enumerate() {
                next_of[h.0 as usize] = i as u32;
            }
            let mut i = 0usize;
            for _ in 0..hn {
                ordered.push(horizon[i]);
                i = next_of[horizon[i].1 as usize] as usize;
            }
        }
        // new cone of triangles (a, b, apex)
        let first_new = tris.len() as u32;
        for (i, &(a, b, nb)) in ordered.iter().enumerate() {
            let mut t = make_tri(p, [a, b, apex], diameter);
            let id = first_new + i as u32;
            t.nbr[0] = nb;
            t.nbr[1] = first_new + ((i + 1) % hn) as u32;
            t.nbr[2] = first_new + ((i + hn - 1) % hn) as u32;
            // re-point the invisible neighbour's edge b -> a to the new triangle
            let n = &mut tris[nb as usize];
            for k in 0..3 {
                if n.v[k] == b && n.v[(k + 1) % 3] == a {
                    n.nbr[k] = id;
                }
            }
            tris.push(t);
        }
        mark.resize(tris.len(), 0);
        // redistribute outside points of the removed triangles
        orphans.clear();
        for &t in &visible {
            orphans.extend(outside.iter(&tris[t as usize]));
            let tr = &mut tris[t as usize];
            tr.alive = false;
            tr.head = NONE;
        }
        for &q in &orphans {
            if q == apex {
                continue;
            }
            for id in first_new..tris.len() as u32 {
                if above(p, &tris[id as usize], q) {
                    outside.push(&mut tris[id as usize], q);
                    break;
                }
            }
        }
        for id in first_new..tris.len() as u32 {
            if tris[id as usize].head != NONE {
                stack.push(id);
            }
        }
    }
}

fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        parent[x as usize] = parent[parent[x as usize] as usize];
        x = parent[x as usize];
    }
    x
}

/// Joins, in the union-find `parent` over the triangles (exactly coplanar ones joined already), adjacent facets that
/// lie in one plane within the length tolerance `tol` (module documentation, "Creases"): across each edge, when the
/// smaller facet's vertices all lie within `tol` of the larger one's plane (normals on the same side), their two
/// groups join, provided all the vertices of both lie within `tol` of the joined group's plane (the area-weighted
/// normal of its facets). So no joined face bends by more than `tol` (creases adding up to a fold stay apart), and a
/// sliver in the planes of two faces joins one of them. The edges are visited in the order of the triangles, which
/// decides only which of two faces such a sliver joins (its vertices, within `tol` of both, are dropped either way).
/// O(triangles x the size of the groups joined).
/// Joins the exact facets (the groups of `parent`) that lie in one plane within `tol` (the module documentation,
/// "Creases"); returns, per triangle index, whether it is the root of a face joined from two or more exact facets
/// (a creased face: exactly coplanar facets are never two, the exact merge joined them).
fn merge_creases(p: &[DVec3], tris: &[Tri], triangle_normal: &[DVec3], parent: &mut [u32], tol: f64) -> Vec<bool> {
    let n = tris.len();
    // each exact facet (at its root): twice its area times its unit normal, accurately; its vertices
    let mut facet_normal = vec![DVec3::ZERO; n];
    let facet_of: Vec<u32> =
        (0..n as u32).map(|i| if tris[i as usize].alive { find(parent, i) } else { NONE }).collect();
    for (i, t) in tris.iter().enumerate() {
        if t.alive {
            facet_normal[facet_of[i] as usize] += triangle_normal[i];
        }
    }
    let unit = |v: DVec3| v.try_normalize().unwrap_or(DVec3::ZERO);
    // the triangles of each facet, by a counting sort (`members[start[f]..start[f + 1]]`)
    let mut start = vec![0u32; n + 1];
    for &f in &facet_of {
        if f != NONE {
            start[f as usize + 1] += 1;
        }
    }
    for f in 0..n {
        start[f + 1] += start[f];
    }
    let mut fill = start.clone();
    let mut members = vec![0u32; start[n] as usize];
    for (i, &f) in facet_of.iter().enumerate() {
        if f != NONE {
            members[fill[f as usize] as usize] = i as u32;
            fill[f as usize] += 1;
        }
    }
    // the largest distance of a facet's vertices from the plane of normal `u` through the point `at`
    let off_plane = |facet: u32, u: DVec3, at: DVec3| {
        members[start[facet as usize] as usize..start[facet as usize + 1] as usize]
            .iter()
            .flat_map(|&i| tris[i as usize].v)
            .map(|v| u.dot(p[v as usize] - at).abs())
            .fold(0.0f64, f64::max)
    };
    // the joined groups: union-find over the facets' roots, each root with the facets joined to it (besides itself:
    // no allocation for a facet that joins nothing) and the sum of their normals
    let mut joined: Vec<u32> = (0..n as u32).collect();
    let mut group_facets: Vec<Vec<u32>> = vec![Vec::new(); n];
    let mut group_normal = facet_normal.clone();
    for (i, t) in tris.iter().enumerate() {
        if !t.alive {
            continue;
        }
        for (k, &j) in t.nbr.iter().enumerate() {
            let (fi, fj) = (facet_of[i], facet_of[j as usize]);
            if fj == NONE || fi >= fj {
                continue;
            }
            let (ga, gb) = (find(&mut joined, fi), find(&mut joined, fj));
            let (ni, nj) = (facet_normal[fi as usize], facet_normal[fj as usize]);
            if ga == gb || ni.dot(nj) <= 0.0 {
                continue;
            }
            // the smaller facet against the larger one's plane, through a point of their shared edge
            let (small, large) = if ni.length_squared() <= nj.length_squared() { (fi, nj) } else { (fj, ni) };
            if off_plane(small, unit(large), p[t.v[k] as usize]) > tol {
                continue;
            }
            // the two groups as one face: all their vertices within `tol` of its plane (so a sliver that lies in two
            // faces' planes joins one of them, never both into one face)
            let u = unit(group_normal[ga as usize] + group_normal[gb as usize]);
            let (mut high, mut low) = (f64::NEG_INFINITY, f64::INFINITY);
            let facets = [ga, gb].into_iter().chain(group_facets[ga as usize].iter().copied());
            for f in facets.chain(group_facets[gb as usize].iter().copied()) {
                for &m in &members[start[f as usize] as usize..start[f as usize + 1] as usize] {
                    for v in tris[m as usize].v {
                        let h = u.dot(p[v as usize]);
                        high = high.max(h);
                        low = low.min(h);
                    }
                }
            }
            if high - low > tol {
                continue;
            }
            let (root, other) = (ga.min(gb), ga.max(gb));
            joined[other as usize] = root;
            let moved = std::mem::take(&mut group_facets[other as usize]);
            group_facets[root as usize].push(other);
            group_facets[root as usize].extend(moved);
            let added = group_normal[other as usize];
            group_normal[root as usize] += added;
        }
    }
    let mut creased_root = vec![false; n];
    for f in 0..n {
        if facet_of[f] == f as u32 {
            let g = find(&mut joined, f as u32);
            if g != f as u32 {
                parent[f] = g;
                creased_root[g as usize] = true;
            }
        }
    }
    creased_root
}

fn merge(p: &[DVec3], tris: &[Tri], merge_tolerance: Option<f64>) -> Result<ConvexHull, HullError> {
    let n = tris.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    for (i, t) in tris.iter().enumerate() {
        if !t.alive {
            continue;
        }
        for k in 0..3 {
            let j = t.nbr[k] as usize;
            if j < i {
                continue;
            }
            // the vertex of the neighbour opposite the shared edge
            let nt = &tris[j];
            let far = nt.v.iter().copied().find(|v| !t.v.contains(v)).unwrap_or(nt.v[0]);
            // the static filter settles "not coplanar" for almost every edge; only near-zero values go exact
            let float_side = t.normal.dot(p[far as usize] - p[t.v[0] as usize]);
            if float_side.abs() <= t.filter
                && side(p[t.v[0] as usize], p[t.v[1] as usize], p[t.v[2] as usize], p[far as usize]) == Ordering::Equal
            {
                let (a, b) = (find(&mut parent, i as u32), find(&mut parent, j as u32));
                if a != b {
                    parent[a as usize] = b;
                }
            }
        }
    }
    // with a merge tolerance: each triangle's accurate normal (twice its area), for the creases and the planes
    let triangle_normal: Vec<DVec3> = match merge_tolerance {
        Some(_) => tris
            .iter()
            .map(|t| {
                if t.alive {
                    accurate_cross(p[t.v[0] as usize], p[t.v[1] as usize], p[t.v[2] as usize])
                } else {
                    DVec3::ZERO
                }
            })
            .collect(),
        None => Vec::new(),
    };
    let creased_root = match merge_tolerance {
        Some(tol) => merge_creases(p, tris, &triangle_normal, &mut parent, tol),
        None => Vec::new(),
    };
    // group ids
    let mut group_of = vec![u32::MAX; n];
    let mut group_of_root = vec![u32::MAX; n];
    let mut group_count = 0u32;
    // per group: joined from two or more exact facets across creases (its plane is then its facets' area normal)
    let mut creased: Vec<bool> = Vec::new();
    for i in 0..n {
        if tris[i].alive {
            let r = find(&mut parent, i as u32) as usize;
            if group_of_root[r] == u32::MAX {
                group_of_root[r] = group_count;
                group_count += 1;
                creased.push(creased_root.get(r).copied().unwrap_or(false));
            }
            group_of[i] = group_of_root[r];
        }
    }
    // distinct groups per vertex, counted up to 3 (a vertex is extreme iff at least 3 faces meet there)
    let mut vgroups: Vec<[u32; 3]> = vec![[u32::MAX; 3]; p.len()];
    let mut vcount: Vec<u8> = vec![0; p.len()];
    for (i, t) in tris.iter().enumerate() {
        if !t.alive {
            continue;
        }
        let g = group_of[i];
        for &v in &t.v {
            let (slots, count) = (&mut vgroups[v as usize], &mut vcount[v as usize]);
            if (*count as usize) < 3 && !slots[..*count as usize].contains(&g) {
                slots[*count as usize] = g;
                *count += 1;
            }
        }
    }
    // boundary half-edges of each group, chained into a cycle
    // (one flat list bucketed by group with a counting sort: no allocation per group)
    let mut bucket_start: Vec<u32> = vec![0; group_count as usize + 1];
    for (i, t) in tris.iter().enumerate() {
        if t.alive {
            for k in 0..3 {
                if group_of[t.nbr[k] as usize] != group_of[i] {
                    bucket_start[group_of[i] as usize + 1] += 1;
                }
            }
        }
    }
    for g in 0..group_count as usize {
        bucket_start[g + 1] += bucket_start[g];
    }
    let mut fill = bucket_start.clone();
    let mut flat: Vec<(u32, u32)> = vec![(0, 0); bucket_start[group_count as usize] as usize];
    for (i, t) in tris.iter().enumerate() {
        if t.alive {
            for k in 0..3 {
                if group_of[t.nbr[k] as usize] != group_of[i] {
                    let g = group_of[i] as usize;
                    flat[fill[g] as usize] = (t.v[k], t.v[(k + 1) % 3]);
                    fill[g] += 1;
                }
            }
        }
    }
    // per group, the triangle whose float normal is longest: the best-conditioned of its exactly coplanar triangles,
    // whose accurate normal is the face's; for a group of facets merged across creases, the sum of its triangles'
    // accurate normals (twice their areas) instead
    let mut representative: Vec<u32> = vec![NONE; group_count as usize];
    let mut area_normal: Vec<DVec3> = vec![DVec3::ZERO; group_count as usize];
    for (i, t) in tris.iter().enumerate() {
        if t.alive {
            let g = group_of[i] as usize;
            let r = &mut representative[g];
            if *r == NONE || t.normal.length_squared() > tris[*r as usize].normal.length_squared() {
                *r = i as u32;
            }
            if merge_tolerance.is_some() {
                area_normal[g] += triangle_normal[i];
            }
        }
    }
    let boundary = (0..group_count as usize).map(|g| &flat[bucket_start[g] as usize..bucket_start[g + 1] as usize]);
    let mut next: Vec<u32> = vec![NONE; p.len()];
    let mut new_index: Vec<u32> = vec![NONE; p.len()];
    let mut vertices = Vec::new();
    let mut source = Vec::new();
    let mut faces = Vec::with_capacity(group_count as usize);
    for (g, (b, &r)) in boundary.zip(&representative).enumerate() {
        let Some(&(start, _)) = b.iter().min_by_key(|e| e.0) else { continue };
        for &(a, c) in b {
            next[a as usize] = c;
        }
        let mut cycle = Vec::with_capacity(b.len());
        let mut v = start;
        for _ in 0..b.len() {
            if vcount[v as usize] >= 3 {
                if new_index[v as usize] == NONE {
                    new_index[v as usize] = vertices.len() as u32;
                    vertices.push(p[v as usize]);
                    source.push(v as usize);
                }
                cycle.push(new_index[v as usize] as usize);
            }
            v = next[v as usize];
        }
        // (cannot happen for exact facets; a merge that leaves a face with fewer corners falls back to them)
        if cycle.len() < 3 {
            return Err(HullError::Internal(PolytopeError::DegenerateFace { face: faces.len() }));
        }
        // the face's plane through its representative triangle, computed accurately (a sliver's plain cross product
        // can point anywhere); the offset is the largest `n . v` over the face's vertices, as `ConvexPolytope::new`
        let n = if creased[g] {
            area_normal[g]
        } else {
            let [a, b, c] = tris[r as usize].v.map(|v| p[v as usize]);
            accurate_cross(a, b, c)
        };
        let len = n.length();
        if !(len > 0.0 && len.is_finite()) {
            return Err(HullError::Internal(PolytopeError::DegenerateFace { face: faces.len() }));
        }
        if creased[g] {
            // a face planar only to the tolerance: its cycle starts at its lexicographically smallest corner, so that
            // the fans of its triangles (its mass properties, its mesh triangles) depend on the face, not on the order
            // of the input points
            let first = (0..cycle.len())
                .min_by(|&x, &y| {
                    vertices[cycle[x]].to_array().partial_cmp(&vertices[cycle[y]].to_array()).unwrap_or(Ordering::Equal)
                })
                .unwrap_or(0);
            cycle.rotate_left(first);
        }
        let normal = n / len;
        let offset = cycle.iter().map(|&i| normal.dot(vertices[i])).fold(f64::NEG_INFINITY, f64::max);
        faces.push(Face { vertices: cycle.into(), plane: Plane { normal, offset } });
    }
    // every face has a positive area: it is a union of triangles that are not exactly degenerate (see the module
    // documentation), and its plane was computed above
    let polytope = ConvexPolytope::from_faces_with_area(vertices, faces)?;
    Ok(ConvexHull { polytope, source })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A box turned by a general rotation: its faces are planar only to rounding. The exact hull splits some of them
    /// into facets; the merged hull has the box's 6 faces and 8 vertices, planes supporting every point.
    #[test]
    fn merged_hull_of_a_turned_box_has_its_six_faces() {
        let r = glam::DMat3::from_euler(glam::EulerRot::ZYX, 0.3, 0.2, 0.1);
        let mut split = 0;
        for (k, size) in [DVec3::new(40.0, 20.0, 2.0), DVec3::new(1.0, 1.0, 1.0), DVec3::new(300.0, 0.5, 7.0)]
            .into_iter()
            .enumerate()
        {
            let t = DVec3::new(k as f64 * 13.7, -5.3, 60.0);
            let pts: Vec<DVec3> = (0..8)
                .map(|i| {
                    let c = |bit: usize, e: f64| if i & bit == 0 { 0.0 } else { e };
                    r * DVec3::new(c(1, size.x), c(2, size.y), c(4, size.z)) + t
                })
                .collect();
            split += convex_hull(&pts).expect("hull").polytope.faces().len() - 6;
            let h = convex_hull_merged(&pts).expect("hull");
            assert_eq!((h.polytope.vertices().len(), h.polytope.faces().len()), (8, 6), "box {k}");
            h.polytope.validate().expect("valid within the tolerance");
            for f in h.polytope.faces() {
                let above = pts.iter().map(|p| f.plane.normal.dot(*p) - f.plane.offset).fold(f64::MIN, f64::max);
                assert!(above <= 1e-12 * 300.0, "box {k}: a point {above} above a face");
            }
        }
        // the test has teeth: the exact hull splits some of these faces
        assert!(split > 0);
    }

    /// A box with points on its edges (and at their midpoints), turned by general rotations: rounding puts each such
    /// point a few nanometres off its edge, where the exact hull makes it a vertex with sliver facets around it. The
    /// merged hull is the box: 8 vertices, 6 faces (the slivers joined to the faces they lie in, the points dropped).
    /// Joined by the angle between their normals instead of by distance, some slivers stay apart and leave a face
    /// of two corners ("internal hull error") in 20 of 30 turns.
    #[test]
    fn a_turned_box_with_points_on_its_edges_is_a_box() {
        let size = DVec3::new(40.0, 20.0, 10.0);
        let corner = |i: usize| {
            let c = |bit: usize, e: f64| if i & bit == 0 { 0.0 } else { e };
            DVec3::new(c(1, size.x), c(2, size.y), c(4, size.z))
        };
        let mut base: Vec<DVec3> = (0..8).map(corner).collect();
        // three points on the edge along x at y = z = 0, and the midpoint of every edge
        base.extend([0.25, 0.5, 0.75].map(|t| DVec3::new(t * size.x, 0.0, 0.0)));
        for i in 0..8 {
            for bit in [1, 2, 4] {
                if i & bit == 0 {
                    base.push(0.5 * (corner(i) + corner(i | bit)));
                }
            }
        }
        let mut exact_split = 0;
        for k in 0..30 {
            let r = glam::DMat3::from_euler(
                glam::EulerRot::ZYX,
                0.17 + 0.31 * k as f64,
                0.35 - 0.023 * k as f64,
                0.52 + 0.19 * k as f64,
            );
            let pts: Vec<DVec3> = base.iter().map(|v| r * *v + DVec3::new(3.0, -7.0, 11.0)).collect();
            exact_split += usize::from(convex_hull(&pts).expect("hull").polytope.faces().len() > 6);
            let h = convex_hull_merged(&pts).unwrap_or_else(|e| panic!("turn {k}: {e}"));
            assert_eq!((h.polytope.vertices().len(), h.polytope.faces().len()), (8, 6), "turn {k}");
            h.polytope.validate().expect("valid within the tolerance");
        }
        assert!(exact_split > 0, "the test has teeth: the exact hulls have slivers");
    }

    /// A real fold, however shallow (1e-6 rad over 10 mm: 1e-5 mm off the other face's plane), stays two faces; a
    /// bend of several creases each within the tolerance but adding up to more than it is not one face.
    #[test]
    fn merged_hull_keeps_real_folds() {
        // a wedge roof: two top faces meeting at a ridge with a 1e-6 rad fold
        let h = 1e-6 * 10.0;
        let pts = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(20.0, 0.0, 0.0),
            DVec3::new(0.0, 5.0, 0.0),
            DVec3::new(20.0, 5.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(20.0, 0.0, 1.0),
            DVec3::new(0.0, 5.0, 1.0),
            DVec3::new(20.0, 5.0, 1.0),
            DVec3::new(10.0, 0.0, 1.0 + h),
            DVec3::new(10.0, 5.0, 1.0 + h),
        ];
        let merged = convex_hull_merged(&pts).expect("hull");
        assert_eq!(merged.polytope.faces().len(), convex_hull(&pts).expect("hull").polytope.faces().len());
        assert_eq!(merged.polytope.faces().len(), 7);
        // a gentle arc of 11 points (coordinates near the origin so that its sagitta is representable): neighbouring
        // facets 1e-3 mm wide meet at 7e-7 rad, each within the tolerance (1.4e-9 mm) of the other's plane, but the
        // ten of them bend by 7e-6 rad, 8.8e-9 mm off one plane
        let (w, alpha) = (1e-3, 7e-7);
        let r = w / alpha;
        let arc: Vec<DVec3> = (0..=10)
            .flat_map(|k| {
                let t = (k as f64 - 5.0) * alpha;
                let (x, z) = (r * t.sin(), -2.0 * r * (0.5 * t).sin().powi(2));
                [DVec3::new(x, 0.0, z), DVec3::new(x, 1.0, z)]
            })
            .chain([DVec3::new(-5e-3, 0.0, -1.0), DVec3::new(5e-3, 0.0, -1.0), DVec3::new(0.0, 1.0, -1.0)])
            .collect();
        let top = |h: &ConvexHull| h.polytope.faces().iter().filter(|f| f.plane.normal.z > 0.9).count();
        assert_eq!(top(&convex_hull(&arc).expect("hull")), 10, "the arc's exact hull has ten top facets");
        // merged piecewise: some faces, none of them bent by more than the tolerance
        let merged = convex_hull_merged(&arc).expect("hull");
        assert!((2..10).contains(&top(&merged)), "{} top faces", top(&merged));
        let tol = crate::tolerance::Tolerance::for_scale(crate::tolerance::bounding_diagonal(&arc)).linear;
        for f in merged.polytope.faces() {
            for &v in &f.vertices {
                let off = f.plane.offset - f.plane.normal.dot(merged.polytope.vertices()[v]);
                assert!((0.0..=tol).contains(&off), "a vertex {off} off its face's plane (tolerance {tol})");
            }
        }
        // the same arc flattened a hundredfold (its sagitta 8.8e-11 mm) is one face
        let flat: Vec<DVec3> =
            arc.iter().map(|p| if p.z > -0.5 { DVec3::new(p.x, p.y, p.z * 0.01) } else { *p }).collect();
        assert_eq!(top(&convex_hull_merged(&flat).expect("hull")), 1, "a bend within the tolerance is one face");
    }

    fn grid_box(nx: usize, ny: usize, nz: usize) -> Vec<DVec3> {
        let mut v = Vec::new();
        for i in 0..=nx {
            for j in 0..=ny {
                for k in 0..=nz {
                    v.push(DVec3::new(i as f64, j as f64, k as f64));
                }
            }
        }
        v
    }

    #[test]
    fn grid_of_coplanar_points_gives_a_box() {
        let pts = grid_box(4, 3, 2);
        let h = convex_hull(&pts).expect("hull");
        assert_eq!(h.polytope.vertices().len(), 8);
        assert_eq!(h.polytope.faces().len(), 6);
        assert_eq!(h.polytope.edges().len(), 12);
        h.polytope.validate_exact().expect("valid");
        assert!((h.polytope.volume() - 24.0).abs() < 1e-12);
        for (i, &s) in h.source.iter().enumerate() {
            assert_eq!(pts[s], h.polytope.vertices()[i]);
        }
    }

    #[test]
    fn degenerate_inputs_are_typed_errors() {
        assert_eq!(convex_hull(&[]), Err(HullError::Empty));
        assert_eq!(convex_hull(&[DVec3::ONE; 5]), Err(HullError::Coincident));
        let line: Vec<DVec3> = (0..5).map(|i| DVec3::splat(i as f64)).collect();
        assert_eq!(convex_hull(&line), Err(HullError::Collinear));
        let plane: Vec<DVec3> = (0..9).map(|i| DVec3::new((i % 3) as f64, (i / 3) as f64, 2.0)).collect();
        assert_eq!(convex_hull(&plane), Err(HullError::Coplanar));
        assert_eq!(convex_hull(&[DVec3::ZERO, DVec3::new(f64::NAN, 0.0, 0.0)]), Err(HullError::NonFinite { index: 1 }));
    }

    #[test]
    fn coordinates_whose_products_would_underflow_are_zero_and_overflow_is_an_error() {
        let tetra = |s: f64| [DVec3::ZERO, DVec3::new(s, 0.0, 0.0), DVec3::new(0.0, s, 0.0), DVec3::new(0.0, 0.0, s)];
        // a tetrahedron of edge 1e-160: its volume determinant (1e-480) underflows; it was reported "coplanar", and
        // is now all zeros, coincident
        assert_eq!(convex_hull(&tetra(1e-160)), Err(HullError::Coincident));
        assert_eq!(convex_hull(&tetra(-1e60)), Err(HullError::OutOfRange { index: 1, value: -1e60 }));
        // the ends of the range are kept, and zeros anywhere
        for s in [MIN_COORDINATE, 1e-40, 1e40, MAX_HULL_COORDINATE] {
            assert_eq!(convex_hull(&tetra(s)).map(|h| h.polytope.vertices().len()), Ok(4), "edge {s:e}");
        }
        // two tetrahedra 1e-300 apart in z (the fuzzer's case: "internal hull error: face 3 is degenerate"): the
        // point 1e-300 above the origin is the origin, a duplicate
        let mut two = tetra(1.0).to_vec();
        two.push(DVec3::new(0.0, 0.0, 1e-300));
        let hull = convex_hull(&two).expect("a tetrahedron");
        assert_eq!(hull.polytope.vertices().len(), 4);
        assert!(hull.polytope.vertices().iter().all(|v| v.to_array().iter().all(|c| *c == 0.0 || *c == 1.0)));
        // a tiny coordinate beside normal ones: the vertex carries the zero
        let tilted = [DVec3::new(0.0, 1.5e-60, 0.0), DVec3::X, DVec3::Y, DVec3::Z];
        let hull = convex_hull(&tilted).expect("a tetrahedron");
        assert!(hull.polytope.vertices().contains(&DVec3::ZERO));
    }

    #[test]
    fn prism_with_duplicates_and_collinear_runs() {
        // an extruded hexagon (dyadic corners, so the edge samples are exactly collinear), every point twice
        let corners = [(2.0, 0.0), (1.0, 2.0), (-1.0, 2.0), (-2.0, 0.0), (-1.0, -2.0), (1.0, -2.0)];
        let mut pts = Vec::new();
        for layer in [0.0, 2.0] {
            for k in 0..6 {
                let (a, b) = (corners[k], corners[(k + 1) % 6]);
                let (pa, pb) = (DVec3::new(a.0, a.1, layer), DVec3::new(b.0, b.1, layer));
                for s in 0..4 {
                    let q = pa + (pb - pa) * (s as f64 / 4.0);
                    pts.push(q);
                    pts.push(q);
                }
            }
        }
        let h = convex_hull(&pts).expect("hull");
        assert_eq!(h.polytope.faces().len(), 8);
        assert_eq!(h.polytope.vertices().len(), 12);
        h.polytope.validate_exact().expect("valid");
    }

    #[test]
    fn sliver_faces_between_nearly_coincident_points() {
        // differences of two rotated boxes (a c-space obstacle): points one or two ulps apart make faces too thin
        // for Newell's normal; found by the cspace property tests
        let pts = vec![
            DVec3::new(-1.7500000000000004, -1.4999999999999998, 1.0),
            DVec3::new(-1.0000000000000004, -1.4999999999999998, 1.0),
            DVec3::new(-1.0000000000000004, 0.5000000000000002, -2.5),
            DVec3::new(-1.7500000000000004, 0.5000000000000002, -2.5),
            DVec3::new(-1.7500000000000004, -3.5, -1.0),
            DVec3::new(-1.0000000000000004, -3.5, -1.0),
            DVec3::new(-1.7500000000000004, -1.9999999999999998, -3.0),
            DVec3::new(-1.7500000000000004, -2.5, -2.5),
            DVec3::new(-1.0000000000000004, -1.9999999999999998, -3.0),
            DVec3::new(-1.0000000000000004, -2.5, -2.5),
            DVec3::new(-1.7500000000000002, -0.9999999999999998, -1.5),
            DVec3::new(-1.0000000000000002, -0.9999999999999998, -1.5),
            DVec3::new(-1.0000000000000002, 1.0000000000000002, -5.0),
            DVec3::new(-1.7500000000000002, 1.0000000000000002, -5.0),
            DVec3::new(-1.7500000000000002, -3.0, -3.5),
            DVec3::new(-1.0000000000000002, -3.0, -3.5),
            DVec3::new(-1.7500000000000002, -1.4999999999999998, -5.5),
            DVec3::new(-1.7500000000000002, -1.9999999999999998, -5.0),
            DVec3::new(-1.0000000000000002, -1.4999999999999998, -5.5),
            DVec3::new(-1.0000000000000002, -1.9999999999999998, -5.0),
            DVec3::new(-1.7499999999999996, 2.5, 0.5),
            DVec3::new(-0.9999999999999997, 2.5, 0.5),
            DVec3::new(-0.9999999999999997, 4.5, -3.0),
            DVec3::new(-1.7499999999999996, 4.5, -3.0),
            DVec3::new(-1.7499999999999996, 0.5, -1.5),
            DVec3::new(-0.9999999999999997, 0.5, -1.5),
            DVec3::new(-1.7499999999999996, 2.0, -3.5),
            DVec3::new(-1.7499999999999996, 1.5, -3.0),
            DVec3::new(-0.9999999999999997, 2.0, -3.5),
            DVec3::new(-0.9999999999999997, 1.5, -3.0),
            DVec3::new(-1.75, 0.5000000000000001, 2.5),
            DVec3::new(-1.0, 0.5000000000000001, 2.5),
            DVec3::new(-1.0, 2.5, -1.0),
            DVec3::new(-1.75, 2.5, -1.0),
            DVec3::new(-1.75, -1.4999999999999998, 0.5),
            DVec3::new(-1.0, -1.4999999999999998, 0.5),
            DVec3::new(-1.75, 1.3777276490407724e-16, -1.5),
            DVec3::new(-1.75, -0.4999999999999999, -1.0),
            DVec3::new(-1.0, 1.3777276490407724e-16, -1.5),
            DVec3::new(-1.0, -0.4999999999999999, -1.0),
            DVec3::new(-1.7500000000000002, -0.9999999999999998, 1.5),
            DVec3::new(-1.0000000000000002, -0.9999999999999998, 1.5),
            DVec3::new(-1.0000000000000002, 1.0000000000000002, -2.0),
            DVec3::new(-1.7500000000000002, 1.0000000000000002, -2.0),
            DVec3::new(-1.7500000000000002, -3.0, -0.5),
            DVec3::new(-1.0000000000000002, -3.0, -0.5),
            DVec3::new(-1.7500000000000002, -1.4999999999999998, -2.5),
            DVec3::new(-1.7500000000000002, -1.9999999999999998, -2.0),
            DVec3::new(-1.0000000000000002, -1.4999999999999998, -2.5),
            DVec3::new(-1.0000000000000002, -1.9999999999999998, -2.0),
            DVec3::new(-1.0000000000000004, -1.5, 1.0),
            DVec3::new(-0.2500000000000004, -1.5, 1.0),
            DVec3::new(-0.2500000000000004, 0.5, -2.5),
            DVec3::new(-1.0000000000000004, 0.5, -2.5),
            DVec3::new(-1.0000000000000004, -3.5, -1.0),
            DVec3::new(-0.2500000000000004, -3.5, -1.0),
            DVec3::new(-1.0000000000000004, -2.0, -3.0),
            DVec3::new(-1.0000000000000004, -2.5, -2.5),
            DVec3::new(-0.2500000000000004, -2.0, -3.0),
            DVec3::new(-0.2500000000000004, -2.5, -2.5),
            DVec3::new(-1.0000000000000002, -1.0, -1.5),
            DVec3::new(-0.2500000000000003, -1.0, -1.5),
            DVec3::new(-0.2500000000000003, 1.0, -5.0),
            DVec3::new(-1.0000000000000002, 1.0, -5.0),
            DVec3::new(-1.0000000000000002, -3.0, -3.5),
            DVec3::new(-0.2500000000000003, -3.0, -3.5),
            DVec3::new(-1.0000000000000002, -1.5, -5.5),
            DVec3::new(-1.0000000000000002, -2.0, -5.0),
            DVec3::new(-0.2500000000000003, -1.5, -5.5),
            DVec3::new(-0.2500000000000003, -2.0, -5.0),
            DVec3::new(-1.0000000000000002, -1.0, 1.5),
            DVec3::new(-0.2500000000000003, -1.0, 1.5),
            DVec3::new(-0.2500000000000003, 1.0, -2.0),
            DVec3::new(-1.0000000000000002, 1.0, -2.0),
            DVec3::new(-1.0000000000000002, -3.0, -0.5),
            DVec3::new(-0.2500000000000003, -3.0, -0.5),
            DVec3::new(-1.0000000000000002, -1.5, -2.5),
            DVec3::new(-1.0000000000000002, -2.0, -2.0),
            DVec3::new(-0.2500000000000003, -1.5, -2.5),
            DVec3::new(-0.2500000000000003, -2.0, -2.0),
            DVec3::new(-0.9999999999999997, 2.5, 0.5),
            DVec3::new(-0.24999999999999964, 2.5, 0.5),
            DVec3::new(-0.24999999999999964, 4.5, -3.0),
            DVec3::new(-0.9999999999999997, 4.5, -3.0),
            DVec3::new(-0.9999999999999997, 0.5, -1.5),
            DVec3::new(-0.24999999999999964, 0.5, -1.5),
            DVec3::new(-0.9999999999999997, 2.0, -3.5),
            DVec3::new(-0.9999999999999997, 1.5, -3.0),
            DVec3::new(-0.24999999999999964, 2.0, -3.5),
            DVec3::new(-0.24999999999999964, 1.5, -3.0),
            DVec3::new(-1.0, 0.5, 2.5),
            DVec3::new(-0.25, 0.5, 2.5),
            DVec3::new(-0.25, 2.5, -1.0),
            DVec3::new(-1.0, 2.5, -1.0),
            DVec3::new(-1.0, -1.5, 0.5),
            DVec3::new(-0.25, -1.5, 0.5),
            DVec3::new(-1.0, 0.0, -1.5),
            DVec3::new(-1.0, -0.5, -1.0),
            DVec3::new(-0.25, 0.0, -1.5),
            DVec3::new(-0.25, -0.5, -1.0),
        ];
        let h = convex_hull(&pts).expect("hull");
        h.polytope.validate_exact().expect("exact");
        for f in 0..h.polytope.faces().len() {
            let (a, b, c) = h.polytope.face_frame(f).expect("frame");
            for p in &pts {
                assert_ne!(side(a, b, c, *p), Ordering::Greater);
            }
        }
    }
}
