//! Quickhull with exact visibility: the triangulated surface of the 3-D convex hull of a point set, before its
//! coplanar facets are merged into faces ([`crate::hull_faces`]; the whole construction and why it is correct on
//! sheet-metal input: [`crate::hull`]).
//!
//! C. B. Barber, D. P. Dobkin, H. Huhdanpaa, *The Quickhull Algorithm for Convex Hulls*, ACM TOMS 22(4), 1996, with
//! every visibility decision made by Shewchuk's exact `orient3d` ([`crate::predicates`], behind a static float
//! filter) instead of Barber's thick facets: a point is visible from a triangle only if it lies strictly above its
//! plane. Expected O(n log n) for random input, O(n^2) worst case.

use crate::predicates::{self, side};
use glam::DVec3;
use std::cmp::Ordering;

/// Why a point set spans no tetrahedron.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Degenerate {
    /// All points coincide.
    Coincident,
    /// All points lie on a line.
    Collinear,
    /// All points lie in a plane.
    Coplanar,
}

/// The triangles of the hull of `points` (finite, within the hull's coordinate range): the live ones (`alive`)
/// close up into a convex surface whose vertices are the input's extreme points (and possibly points inside its
/// faces or edges, which the face merge drops). Adjacent triangles are linked (`nbr`).
pub(crate) fn triangulate(points: &[DVec3]) -> Result<Vec<Tri>, Degenerate> {
    let simplex = initial_simplex(points)?;
    // a slight overestimate of the largest |q - a| keeps the static filter safe
    let diameter = crate::tolerance::bounding_diagonal(points) * (1.0 + 1e-9);
    let mut tris = Vec::with_capacity(64 + 4 * points.len().min(4096)); // avoids regrowing the triangle list
    let mut outside = Outside { next: vec![NONE; points.len()] };
    build_simplex(points, simplex, &mut tris, diameter);
    assign_initial_outside(points, simplex, &mut tris, &mut outside);
    expand(points, &mut tris, &mut outside, diameter);
    Ok(tris)
}

pub(crate) const NONE: u32 = u32::MAX;

/// A triangle of the hull under construction.
#[derive(Debug, Clone)]
pub(crate) struct Tri {
    /// Its corners, counter-clockwise seen from outside.
    pub(crate) v: [u32; 3],
    /// `nbr[k]` is the triangle across the edge `v[k] -> v[(k + 1) % 3]`.
    pub(crate) nbr: [u32; 3],
    /// Float normal `(b - a) x (c - a)`: picks the farthest point, and filters the exact test (see [`above`]).
    pub(crate) normal: DVec3,
    /// Static error bound of `normal . (q - a)` over the input's bounding box: a float value beyond it has the sign
    /// of the exact determinant.
    pub(crate) filter: f64,
    /// Outside set: a FIFO linked list through [`Outside::next`] (no allocation per triangle).
    head: u32,
    tail: u32,
    pub(crate) alive: bool,
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

fn initial_simplex(p: &[DVec3]) -> Result<[u32; 4], Degenerate> {
    // i0: lexicographically smallest point (an extreme point).
    let i0 = (0..p.len())
        .min_by(|&a, &b| p[a].to_array().partial_cmp(&p[b].to_array()).unwrap_or(Ordering::Equal))
        .unwrap_or(0);
    // i1: farthest from i0 (float choice, exact meaning: any point different from i0).
    let i1 = argmax(p.len(), |i| (p[i] - p[i0]).length_squared()).filter(|&i| p[i] != p[i0]);
    let Some(i1) = i1.or_else(|| (0..p.len()).find(|&i| p[i] != p[i0])) else {
        return Err(Degenerate::Coincident);
    };
    let dir = p[i1] - p[i0];
    let i2 = argmax(p.len(), |i| (p[i] - p[i0]).cross(dir).length_squared())
        .filter(|&i| !predicates::collinear(p[i0], p[i1], p[i]));
    let Some(i2) = i2.or_else(|| (0..p.len()).find(|&i| !predicates::collinear(p[i0], p[i1], p[i]))) else {
        return Err(Degenerate::Collinear);
    };
    let n = (p[i1] - p[i0]).cross(p[i2] - p[i0]);
    let i3 =
        argmax(p.len(), |i| n.dot(p[i] - p[i0]).abs()).filter(|&i| side(p[i0], p[i1], p[i2], p[i]) != Ordering::Equal);
    let Some(i3) = i3.or_else(|| (0..p.len()).find(|&i| side(p[i0], p[i1], p[i2], p[i]) != Ordering::Equal)) else {
        return Err(Degenerate::Coplanar);
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
