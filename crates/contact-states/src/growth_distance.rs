//! Growth distance of two convex polytopes (C. Ong and E. Gilbert, *Growth distances: new measures for object
//! separation and penetration*, IEEE T-RA 12(6), 1996), the non-penetration measure of \[P\] II-B, eq. 5.
//!
//! Both polytopes are scaled about interior seed points `p` (of A) and `q` (of B) by a common factor `sigma` until
//! they just touch. As a linear program in `(x, sigma)` (\[P\]; `docs/algorithms.md`, "Contact states"):
//!
//! `min sigma  s.t.  a_i . (x - p) <= sigma (b_i - a_i . p)  (faces of A),  a_j . (x - q) <= sigma (b_j - a_j . q)  (B)`.
//!
//! `sigma < 1`: the polytopes penetrate; `= 1`: touch; `> 1`: separated.
//!
//! **Solver.** This 4-variable LP is solved exactly through its geometric dual rather than by pivoting. A point `x`
//! satisfies both groups iff `x = p + sigma u = q + sigma w` with `u in A - p`, `w in B - q`, i.e.
//! `(p - q) / sigma in D = (B - q) + (p - A)`, a convex polytope with the origin inside. So `1 / sigma` is the
//! largest `lambda` with `lambda d in D` (`d = p - q`): the exit of a ray from the origin through `D`. Since
//! `lambda d in D` implies `lambda n.d <= h_D(n)` for every direction `n` (support function `h_D`), with equality on
//! the facet the ray leaves through,
//!
//! `sigma = max_n  n.d / h_D(n) = max_n  n.d / (h_B(n) + h_A(-n) + n.d)`  over the facet normals `n` of `D` with
//! `n.d > 0`,
//!
//! and the facet normals of `D = B + (-A)` are among the face normals of B, the negated face normals of A and the
//! cross products of an edge direction of A with one of B (the LP's optimal dual basis picks exactly one such
//! facet). Enumerating these candidates gives the optimum without iterations, pivoting rules or degeneracy handling:
//! ties (face-to-face contact, the normal case for sheet metal) are harmless. Cost O((F_A + F_B + E'_A E'_B)(V_A +
//! V_B)) with `E'` the number of distinct edge directions (3 for a box: 30 candidates x 16 support evaluations).
//! The tests cross-check it against clarabel on the LP above and against a brute-force scaling search.

use crate::pose::Pose;
use stackplan_geom::{ConvexPolytope, DVec3};

/// A convex polytope prepared for growth-distance queries: vertices, face normals, distinct edge directions and an
/// interior seed point (the vertex mean).
#[derive(Debug, Clone, PartialEq)]
pub struct ConvexPiece {
    /// Vertices.
    pub vertices: Vec<DVec3>,
    /// Unit outward face normals.
    pub normals: Vec<DVec3>,
    /// Edge directions, one per class of parallel edges.
    pub edge_directions: Vec<DVec3>,
    /// Interior seed point.
    pub seed: DVec3,
    /// Axis-aligned bounding box `(min, max)`.
    pub aabb: (DVec3, DVec3),
    /// When the piece is a parallelepiped (a box, the usual sheet-metal piece): its centre (= `seed`) and half edge
    /// vectors, for the closed-form support `h(n) = n.c + sum |n.a_i|`.
    pub parallelepiped: Option<Parallelepiped>,
}

/// A parallelepiped `c + sum s_i a_i`, `s_i in [-1, 1]`: centre and half edge vectors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Parallelepiped {
    /// Centre.
    pub centre: DVec3,
    /// Half edge vectors.
    pub half_axes: [DVec3; 3],
    /// Per face normal `n_f` (in the order of [`ConvexPiece::normals`]), the half width `sum |n_f.a_i|` (rotation
    /// invariant: unchanged by [`ConvexPiece::transform_into`]).
    pub face_half_widths: [f64; 6],
}

impl Parallelepiped {
    /// Recognises a parallelepiped from its vertices and (unit) edge directions: three direction classes, and every
    /// vertex at `c + sum +-a_i` within `1e-12` of the piece's size. O(V).
    fn recognise(vertices: &[DVec3], normals: &[DVec3], edge_directions: &[DVec3], centre: DVec3) -> Option<Self> {
        if vertices.len() != 8 || normals.len() != 6 || edge_directions.len() != 3 {
            return None;
        }
        // half extent along each direction class: the half width of the vertices' projections
        let mut half_axes = [DVec3::ZERO; 3];
        let (d0, d1, d2) = (edge_directions[0], edge_directions[1], edge_directions[2]);
        // the vertex v - c = sum s_i a_i: solve with the dual basis of the directions
        let det = d0.dot(d1.cross(d2));
        if det.abs() < 1e-9 {
            return None;
        }
        let dual = [d1.cross(d2) / det, d2.cross(d0) / det, d0.cross(d1) / det];
        let first = vertices[0] - centre;
        for i in 0..3 {
            half_axes[i] = edge_directions[i] * first.dot(dual[i]).abs();
        }
        let size = vertices.iter().map(|v| (*v - centre).length()).fold(0.0, f64::max);
        let tol = 1e-12 * size.max(1e-300);
        let mut seen = [false; 8];
        for v in vertices {
            let r = *v - centre;
            let mut index = 0;
            let mut rebuilt = DVec3::ZERO;
            for i in 0..3 {
                let s = r.dot(dual[i]);
                let sign = if s >= 0.0 { 1.0 } else { -1.0 };
                index |= usize::from(s >= 0.0) << i;
                rebuilt += half_axes[i] * sign;
            }
            if (rebuilt - r).length() > tol || seen[index] {
                return None;
            }
            seen[index] = true;
        }
        let mut out = Self { centre, half_axes, face_half_widths: [0.0; 6] };
        for (k, n) in normals.iter().enumerate() {
            out.face_half_widths[k] = out.half_width(*n);
        }
        Some(out)
    }

    #[inline]
    fn support(&self, n: DVec3) -> f64 {
        n.dot(self.centre)
            + n.dot(self.half_axes[0]).abs()
            + n.dot(self.half_axes[1]).abs()
            + n.dot(self.half_axes[2]).abs()
    }

    /// `sum |n.a_i|`, the support about the centre.
    #[inline]
    fn half_width(&self, n: DVec3) -> f64 {
        n.dot(self.half_axes[0]).abs() + n.dot(self.half_axes[1]).abs() + n.dot(self.half_axes[2]).abs()
    }
}

impl ConvexPiece {
    /// Prepares a polytope. O(V + F + E^2) for the direction classes.
    pub fn from_polytope(poly: &ConvexPolytope) -> Self {
        let vertices = poly.vertices().to_vec();
        let normals: Vec<DVec3> = poly.planes().map(|p| p.normal).collect();
        let mut edge_directions: Vec<DVec3> = Vec::new();
        for e in poly.edges() {
            let d = (vertices[e.vertices[1]] - vertices[e.vertices[0]]).normalize();
            if !edge_directions.iter().any(|x| x.cross(d).length() <= 1e-12) {
                edge_directions.push(d);
            }
        }
        let seed = poly.vertex_centroid();
        let aabb = poly.aabb();
        let parallelepiped = Parallelepiped::recognise(&vertices, &normals, &edge_directions, seed);
        Self { vertices, normals, edge_directions, seed, aabb, parallelepiped }
    }

    /// Writes the image of `self` under `pose` into `out` (reusing its buffers).
    pub fn transform_into(&self, pose: &Pose, out: &mut Self) {
        out.vertices.clear();
        out.vertices.extend(self.vertices.iter().map(|v| pose.apply(*v)));
        out.normals.clear();
        out.normals.extend(self.normals.iter().map(|n| pose.apply_vector(*n)));
        out.edge_directions.clear();
        out.edge_directions.extend(self.edge_directions.iter().map(|n| pose.apply_vector(*n)));
        out.seed = pose.apply(self.seed);
        out.parallelepiped = self.parallelepiped.map(|b| Parallelepiped {
            centre: pose.apply(b.centre),
            half_axes: b.half_axes.map(|a| pose.apply_vector(a)),
            face_half_widths: b.face_half_widths,
        });
        let first = out.vertices.first().copied().unwrap_or(DVec3::ZERO);
        out.aabb = out.vertices.iter().fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    }

    /// The image under `pose`.
    pub fn transformed(&self, pose: &Pose) -> Self {
        let mut out = self.clone();
        self.transform_into(pose, &mut out);
        out
    }

    #[inline]
    fn support(&self, n: DVec3) -> f64 {
        match &self.parallelepiped {
            Some(b) => b.support(n),
            None => self.vertices.iter().fold(f64::NEG_INFINITY, |m, v| m.max(n.dot(*v))),
        }
    }
}

/// The growth distance `sigma` of two convex pieces about their seed points (see the module docs). Returns 0 when the
/// seeds coincide (every positive scaling overlaps).
pub fn growth_distance(a: &ConvexPiece, b: &ConvexPiece) -> f64 {
    growth_distance_with_seeds(a, a.seed, b, b.seed)
}

/// [`growth_distance`] with explicit interior seed points `p` of A and `q` of B.
pub fn growth_distance_with_seeds(a: &ConvexPiece, p: DVec3, b: &ConvexPiece, q: DVec3) -> f64 {
    growth_distance_capped(a, p, b, q, f64::INFINITY)
}

/// `min(sigma, cap)`-exact growth distance: returns as soon as one facet direction proves `sigma >= cap` (the value
/// returned is then some number `>= cap`). With `cap = 1` it decides penetration (`sigma < 1`) and gives the exact
/// `sigma` of penetrating pairs, while separated and touching pairs usually stop at the first face normal.
pub fn growth_distance_capped(a: &ConvexPiece, p: DVec3, b: &ConvexPiece, q: DVec3, cap: f64) -> f64 {
    let d = p - q;
    if d == DVec3::ZERO {
        return 0.0;
    }
    if let (Some(ba), Some(bb)) = (&a.parallelepiped, &b.parallelepiped)
        && p == ba.centre
        && q == bb.centre
    {
        return parallelepipeds_capped(a, ba, b, bb, d, cap);
    }
    let mut best: f64 = 0.0;
    let mut consider = |n: DVec3| -> bool {
        let nd = n.dot(d);
        if nd > 0.0 {
            let h = b.support(n) + a.support(-n) + nd;
            if h > 0.0 {
                best = best.max(nd / h);
            }
        }
        best >= cap
    };
    // A's faces first: the fixed part's pieces are the large slabs whose faces usually separate (an early exit)
    for n in &a.normals {
        if consider(-*n) {
            return best;
        }
    }
    for n in &b.normals {
        if consider(*n) {
            return best;
        }
    }
    for ea in &a.edge_directions {
        for eb in &b.edge_directions {
            let n = ea.cross(*eb);
            if n.length_squared() > 1e-24 {
                let n = if n.dot(d) >= 0.0 { n } else { -n };
                if consider(n) {
                    return best;
                }
            }
        }
    }
    best
}

/// Two parallelepipeds about their centres: `h_B(n) + h_A(-n) + n.d = sum |n.a_i| + sum |n.b_j|` (the centre terms
/// cancel exactly), so `sigma = max_n n.d / (sum |n.a_i| + sum |n.b_j|)` over the same candidate directions, the
/// separating-axis formula. A face normal's own half width is precomputed (rotation invariant), and a cross product
/// `a_i x b_j` is orthogonal to both its axes, so a candidate costs 4 or 5 dot products and no division unless it
/// improves the maximum.
fn parallelepipeds_capped(
    a: &ConvexPiece,
    ba: &Parallelepiped,
    b: &ConvexPiece,
    bb: &Parallelepiped,
    d: DVec3,
    cap: f64,
) -> f64 {
    let mut best: f64 = 0.0;
    // n.d / h > best, without dividing unless it holds (h > 0 whenever n.d > 0 for non-degenerate pieces)
    let mut consider = |nd: f64, h: f64| -> bool {
        if nd > 0.0 && h > 0.0 && nd > best * h {
            best = nd / h;
        }
        best >= cap
    };
    let [a0, a1, a2] = ba.half_axes;
    let [b0, b1, b2] = bb.half_axes;
    // A's faces first: the fixed part's pieces are the large slabs whose faces usually separate (an early exit)
    for (n, w) in a.normals.iter().zip(ba.face_half_widths) {
        let nd = -n.dot(d);
        if nd > 0.0 && consider(nd, w + n.dot(b0).abs() + n.dot(b1).abs() + n.dot(b2).abs()) {
            return best;
        }
    }
    for (n, w) in b.normals.iter().zip(bb.face_half_widths) {
        let nd = n.dot(d);
        if nd > 0.0 && consider(nd, w + n.dot(a0).abs() + n.dot(a1).abs() + n.dot(a2).abs()) {
            return best;
        }
    }
    let (aa, bx) = (&ba.half_axes, &bb.half_axes);
    for (i, ea) in a.edge_directions.iter().enumerate() {
        for (j, eb) in b.edge_directions.iter().enumerate() {
            let n = ea.cross(*eb);
            if n.length_squared() > 1e-24 {
                // n is orthogonal to a_i and b_j
                let h = n.dot(aa[(i + 1) % 3]).abs()
                    + n.dot(aa[(i + 2) % 3]).abs()
                    + n.dot(bx[(j + 1) % 3]).abs()
                    + n.dot(bx[(j + 2) % 3]).abs();
                if consider(n.dot(d).abs(), h) {
                    return best;
                }
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use stackplan_geom::convex_hull;

    pub(crate) fn cuboid(lo: DVec3, hi: DVec3) -> ConvexPiece {
        let pts: Vec<DVec3> = (0..8)
            .map(|i| {
                DVec3::new(
                    if i & 1 == 0 { lo.x } else { hi.x },
                    if i & 2 == 0 { lo.y } else { hi.y },
                    if i & 4 == 0 { lo.z } else { hi.z },
                )
            })
            .collect();
        ConvexPiece::from_polytope(&convex_hull(&pts).expect("box").polytope)
    }

    #[test]
    fn boxes_along_an_axis() {
        let a = cuboid(DVec3::splat(-1.0), DVec3::splat(1.0));
        // touching face to face
        let b = cuboid(DVec3::new(1.0, -1.0, -1.0), DVec3::new(3.0, 1.0, 1.0));
        assert!((growth_distance(&a, &b) - 1.0).abs() < 1e-15);
        // gap of 2 between the faces: seeds 4 apart, half-widths 1 + 1 -> sigma = 4 / 2
        let c = cuboid(DVec3::new(3.0, -1.0, -1.0), DVec3::new(5.0, 1.0, 1.0));
        assert!((growth_distance(&a, &c) - 2.0).abs() < 1e-15);
        // overlap by 1: seeds 1.5 apart -> sigma = 1.5 / 2
        let e = cuboid(DVec3::new(0.5, -1.0, -1.0), DVec3::new(2.5, 1.0, 1.0));
        assert!((growth_distance(&a, &e) - 0.75).abs() < 1e-15);
        // same seed
        assert_eq!(growth_distance(&a, &a), 0.0);
    }

    #[test]
    fn edge_edge_contact_needs_cross_normals() {
        // a unit cube and a cube rotated 45 degrees about x and about z so that two edges cross: the contact normal
        // is the cross product of the edges, not a face normal
        let a = cuboid(DVec3::splat(-1.0), DVec3::splat(1.0));
        let b0 = cuboid(DVec3::splat(-1.0), DVec3::splat(1.0));
        let s2 = std::f64::consts::SQRT_2;
        // rotate b about x by 45 deg: its lowest edge is along x at depth sqrt2; rotate a about y by 45 deg: its
        // highest edge is along z at height sqrt2. Put b's centre 2 sqrt2 above a's: the edges cross and touch.
        let pb = Pose::from_config(&[0.0, 0.0, 2.0 * s2, std::f64::consts::FRAC_PI_4, 0.0, 0.0]);
        let pa = Pose::from_config(&[0.0, 0.0, 0.0, 0.0, std::f64::consts::FRAC_PI_4, 0.0]);
        let at = a.transformed(&pa);
        let bt = b0.transformed(&pb);
        let s = growth_distance(&at, &bt);
        assert!((s - 1.0).abs() < 1e-12, "{s}");
        // face normals alone would claim separation: the edge cross product is what makes sigma exact
        let d = at.seed - bt.seed;
        let only_faces = bt
            .normals
            .iter()
            .copied()
            .chain(at.normals.iter().map(|n| -*n))
            .filter(|n| n.dot(d) > 0.0)
            .map(|n| n.dot(d) / (bt.support(n) + at.support(-n) + n.dot(d)))
            .fold(0.0, f64::max);
        assert!(only_faces < 0.99, "{only_faces}");
    }
}
