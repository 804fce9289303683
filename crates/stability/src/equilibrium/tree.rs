//! Support trees: the exact split of a group's equilibrium problem into one rigid-body problem per tree edge, and the
//! closed-form minimum-norm forces of a flat support (`docs/algorithms.md`, "Stability, grasp and insertion"; the
//! equations of [`super`]).
//!
//! Contract the fixed bodies (floor, fixed parts) of a group to one node, the ground. When the graph "movable parts
//! and ground, joined when they share a contact point" is a tree (a column of parts each resting on the one below, a
//! part alone on its supports), let `S_v` be the parts of the subtree of part `v` (rooted at the ground) and call the
//! contact points between `v` and its parent "edge `v`". Summing the force and moment equations of the parts of `S_v`
//! cancels the forces of every contact inside `S_v` and leaves: the forces of edge `v`, acting on `S_v`, balance the
//! gravity (and horizontal load) of `S_v` — the equations of one rigid body, the union of `S_v` (total mass,
//! mass-weighted c.g.; the load `alpha m_i d` is proportional to the mass like gravity, so its resultant acts at the
//! union's c.g.). This map of the equations is triangular and invertible (a part's equations are its subtree's minus
//! its children's subtrees'), and every contact point belongs to exactly one edge. So:
//!
//! * the group is in equilibrium iff every edge problem is feasible, and resists a load iff every edge problem does;
//! * the minimum-norm forces of the group are the edges' minimum-norm forces (the objective `sum ||f_k||^2` is a sum
//!   over the edges and the constraints are per edge).
//!
//! Graphs with a cycle (a brick on two bricks on the floor) are not split.
//!
//! **Flat support** ([`flat_minimum_norm`]): when every point of an edge pushes the subtree straight up (normal +z,
//! within 1e-12) from one horizontal plane `z = h` (within the tolerance), the equations decouple: friction `t_k`
//! enters the horizontal force rows, the torsion row and the moment rows about the horizontal axes, but in the latter
//! only as `(h - c_z) z x sum t_k`, a multiple of the horizontal force rows; subtracting it leaves moment rows in the
//! normal forces alone, and the friction rows have right-hand side 0 without load, so the minimum-norm friction is 0
//! (with points at several heights this fails: friction then helps the moments and the minimum norm uses it). The
//! normal forces `n_k` must satisfy the three rows `sum n_k = W`, `sum n_k (x_k - c_x) = 0`, `sum n_k (y_k - c_y) = 0`. Their least-squares minimum-norm
//! solution `n = A^T (A A^T)^-1 b` is the SOCP's optimum whenever it is nonnegative (an unconstrained minimiser that
//! satisfies the cone constraints is the constrained one), so it is taken then; otherwise (or when `A A^T` is
//! singular: collinear points) the edge is solved as an SOCP. Cost: O(K) per flat edge.
//!
//! Cost of the split: union-find-free breadth-first walk, O(P E + K) for P parts, E edges, K points.

use super::Group;
use super::{Point, Rigid};
use glam::{DMat3, DVec3};

/// One edge of a support tree.
pub(super) struct Edge {
    /// The rigid union of the subtree (the parts held by the edge).
    pub union: Rigid,
    /// The edge's contact points: (index in the points of the problem, whether the subtree holds the point's `b`).
    pub points: Vec<(usize, bool)>,
}

/// The edges of the group's support tree, `None` when the support graph is not a tree (see the module
/// documentation). One edge per movable part, in the order of `group.movers`.
pub(super) fn support_tree(bodies: &[Rigid], points: &[Point], group: &Group) -> Option<Vec<Edge>> {
    let n = group.movers.len();
    let ground = n;
    let node = |body: Option<usize>| body.and_then(|b| group.movers.binary_search(&b).ok()).unwrap_or(ground);
    // the edges (pairs of nodes) and their points
    let mut edges: Vec<((usize, usize), Vec<usize>)> = Vec::new();
    for &k in &group.point_indices {
        let (u, v) = (node(points[k].a), node(Some(points[k].b)));
        if u == v {
            return None;
        }
        let key = (u.min(v), u.max(v));
        match edges.iter_mut().find(|(e, _)| *e == key) {
            Some((_, list)) => list.push(k),
            None => edges.push((key, vec![k])),
        }
    }
    if edges.len() != n {
        return None;
    }
    // breadth-first from the ground: the parent of every node
    let mut parent = vec![usize::MAX; n + 1];
    let mut order = vec![ground];
    parent[ground] = ground;
    let mut head = 0;
    while head < order.len() {
        let x = order[head];
        head += 1;
        for ((u, v), _) in &edges {
            let y = if *u == x {
                *v
            } else if *v == x {
                *u
            } else {
                continue;
            };
            if parent[y] == usize::MAX {
                parent[y] = x;
                order.push(y);
            }
        }
    }
    if order.len() != n + 1 {
        return None;
    }
    // subtree unions, leaves first
    let mut union: Vec<Rigid> = group.movers.iter().map(|&i| bodies[i]).collect();
    for &x in order.iter().skip(1).rev() {
        let p = parent[x];
        if p != ground {
            union[p] = Rigid::union([union[x], union[p]].into_iter());
        }
    }
    let mut out = Vec::with_capacity(n);
    for (x, rigid) in union.into_iter().enumerate() {
        let key = (x.min(parent[x]), x.max(parent[x]));
        let (_, list) = edges.iter().find(|(e, _)| *e == key)?;
        let oriented = list.iter().map(|&k| (k, node(Some(points[k].b)) == x)).collect();
        out.push(Edge { union: rigid, points: oriented });
    }
    Some(out)
}

/// The point as a contact of the subtree's rigid union (body 0, the other side fixed): its frame is turned so that
/// it gives the force on the subtree (`+f` when the subtree holds `b`, `-f` when it holds `a`; the friction cone is
/// symmetric in the tangents).
pub(super) fn edge_point(pt: &Point, holds_b: bool) -> Point {
    let frame = if holds_b { pt.frame } else { [-pt.frame[0], pt.frame[1], pt.frame[2]] };
    Point { patch: pt.patch, p: pt.p, frame, a: None, b: 0 }
}

/// The minimum-norm forces (world vectors, on the body) of a rigid body of weight `union.mass` at `union.cg` on
/// points that all push straight up, when that solution has no negative normal force (see the module
/// documentation); `None` otherwise (not flat, collinear points, or a negative normal force).
pub(super) fn flat_minimum_norm(union: &Rigid, points: &[Point]) -> Option<Vec<DVec3>> {
    if points.is_empty() || !points.iter().all(|p| p.b == 0 && p.a.is_none() && p.frame[0].z >= 1.0 - 1e-12) {
        return None;
    }
    // one plane: with points at several heights, friction enters the moment rows and the minimum norm needs it
    let (lo, hi) = points.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p.p.z), hi.max(p.p.z)));
    if hi - lo > union.tolerance() {
        return None;
    }
    let scale = (union.aabb.1 - union.aabb.0).length().max(1.0);
    let arm = |p: &Point| ((p.p.x - union.cg.x) / scale, (p.p.y - union.cg.y) / scale);
    // A A^T with the rows (1, x_k, y_k) (scaled arms)
    let mut gram = [[0.0f64; 3]; 3];
    for p in points {
        let (x, y) = arm(p);
        let row = [1.0, x, y];
        for (r, gr) in gram.iter_mut().enumerate() {
            for (c, g) in gr.iter_mut().enumerate() {
                *g += row[r] * row[c];
            }
        }
    }
    let m = DMat3::from_cols_array_2d(&gram);
    let det = m.determinant();
    // relative conditioning test (the Gram matrix has entries of order K)
    if det.is_nan() || det.abs() <= 1e-12 * (points.len() as f64).powi(3) {
        return None;
    }
    let lambda = m.inverse() * DVec3::new(union.mass, 0.0, 0.0);
    let mut forces = Vec::with_capacity(points.len());
    let (mut total, mut mx, mut my) = (0.0, 0.0, 0.0);
    for p in points {
        let (x, y) = arm(p);
        let normal = lambda.x + lambda.y * x + lambda.z * y;
        if normal.is_nan() || normal < 0.0 {
            return None;
        }
        total += normal;
        mx += normal * x;
        my += normal * y;
        forces.push(DVec3::Z * normal);
    }
    // the residual of the three rows, relative to the weight
    let residual = (total - union.mass).abs().max(mx.abs()).max(my.abs());
    (residual <= 1e-12 * union.mass.max(f64::MIN_POSITIVE)).then_some(forces)
}

/// An admissible force distribution (world vectors, each the force of the point's `a` on its `b`, in the order of
/// `points`) made of vertical forces at the points with vertical normals (`|n_z| >= 1 - 1e-12`) and no force at the
/// others, when the least-squares one has no negative normal force; `None` otherwise. It certifies equilibrium
/// (vertical forces with `f_k >= 0` lie in their friction cones, zero forces in every cone) but is in general *not*
/// the minimum-norm distribution (friction can lower the norm), so it serves verdicts only. Rows per movable part `i`
/// (`s = +1` on `b`, `-1` on `a`): `sum s n_z f_k = m_i` and the moments about the two horizontal axes through `c_i`,
/// `sum s n_z f_k (y_k - c_y) = 0`, `sum s n_z f_k (x_k - c_x) = 0` (vertical forces have no other moment and no
/// horizontal resultant, and no load acts). Least squares through the normal equations `(A A^T) y = b` (3 M
/// unknowns, faer's dense Cholesky factorisation), O(M^3 + M K).
///
/// The points whose normal lies in the friction cone of the vertical (`|n_xy| <= mu |n_z|`, see
/// [`super::hull_certificate`]) also take a vertical force: it lies in their cones too.
pub(super) fn vertical_certificate(
    bodies: &[Rigid],
    movers: &[usize],
    points: &[&Point],
    mu: f64,
) -> Option<Vec<DVec3>> {
    certificate_with(bodies, movers, points, DVec3::Z, &|p| super::hull_certificate::admits_vertical_force(p, mu))
}

/// [`vertical_certificate`] under the tilted gravity `g = z - alpha d` of a horizontal load `alpha d` (`alpha` at
/// most the friction coefficient): at every point with a vertical normal the force on the upper body is `f_k g`
/// (normal component `f_k`, friction `alpha f_k <= mu f_k`: inside the cone), zero at the others; the rows are per
/// part `sum s n_z f_k = m_i` (then the forces balance `m_i g`) and the moments about the two axes through `c_i`
/// perpendicular to `g`, `sum s n_z f_k (p_k - c_i) . e = 0` (a resultant along `g` through `c_i`). Nonnegative
/// least-squares `f_k` certify that the group resists the load; `None` otherwise.
pub(super) fn parallel_certificate(
    bodies: &[Rigid],
    movers: &[usize],
    points: &[&Point],
    gravity: DVec3,
) -> Option<Vec<DVec3>> {
    certificate_with(bodies, movers, points, gravity, &|p| p.frame[0].z.abs() >= 1.0 - 1e-12)
}

/// [`parallel_certificate`] with forces along `gravity` at the points `vertical` admits.
fn certificate_with(
    bodies: &[Rigid],
    movers: &[usize],
    points: &[&Point],
    gravity: DVec3,
    vertical: &dyn Fn(&Point) -> bool,
) -> Option<Vec<DVec3>> {
    let g = gravity.normalize();
    let (e1, e2) = crate::contacts::plane_basis(g);
    let rows = 3 * movers.len();
    let union = Rigid::union(movers.iter().map(|&i| bodies[i]));
    let scale = (union.aabb.1 - union.aabb.0).length().max(1.0);
    let weight = union.mass.max(f64::MIN_POSITIVE);
    let columns: Vec<Vec<(usize, f64)>> = points
        .iter()
        .map(|p| if vertical(p) { certificate_column(bodies, movers, p, (e1, e2), scale) } else { Vec::new() })
        .collect();
    let mut gram = vec![0.0f64; rows * rows];
    for col in &columns {
        for &(r, a) in col {
            for &(c, b) in col {
                gram[r * rows + c] += a * b;
            }
        }
    }
    let mut rhs = vec![0.0f64; rows];
    for (m, &i) in movers.iter().enumerate() {
        rhs[3 * m] = bodies[i].mass / weight;
    }
    let y = solve_spd(&gram, &rhs, rows)?;
    let mut forces = Vec::with_capacity(points.len());
    let mut residual = vec![0.0f64; rows];
    for (p, col) in points.iter().zip(&columns) {
        let normal: f64 = col.iter().map(|&(r, a)| a * y[r]).sum();
        if normal.is_nan() || normal < 0.0 {
            return None;
        }
        for &(r, a) in col {
            residual[r] += a * normal;
        }
        forces.push(gravity * (p.frame[0].z.signum() * normal * weight));
    }
    residual.iter().zip(&rhs).all(|(r, b)| (r - b).abs() <= 1e-12).then_some(forces)
}

/// The sparse column of a vertical point in the certificate rows of [`parallel_certificate`] (also those of
/// [`super::vertical_qp`]): per movable body it acts on (up to two), `s n_z` in the force row `3 m` and `s n_z (p - c)
/// . e / scale` in the moment rows `3 m + 1`, `3 m + 2` (`s = +1` on `b`, `-1` on `a`; `e1`, `e2` the axes
/// perpendicular to gravity; `movers` ascending).
pub(super) fn certificate_column(
    bodies: &[Rigid],
    movers: &[usize],
    p: &Point,
    (e1, e2): (DVec3, DVec3),
    scale: f64,
) -> Vec<(usize, f64)> {
    let mut out = Vec::with_capacity(6);
    let nz = p.frame[0].z.signum();
    for (body, sign) in [(Some(p.b), 1.0), (p.a, -1.0)] {
        let Some(body) = body else { continue };
        let Ok(m) = movers.binary_search(&body) else { continue };
        let c = bodies[body].cg;
        let v = sign * nz;
        out.push((3 * m, v));
        out.push((3 * m + 1, v * (p.p - c).dot(e1) / scale));
        out.push((3 * m + 2, v * (p.p - c).dot(e2) / scale));
    }
    out
}

/// Solves the symmetric positive definite `n x n` system `a y = b` (row-major: the Gram matrix `A A^T` of the
/// certificate rows) by faer's Cholesky factorisation `a = L L^T`, O(n^3 / 3); `None` when `a` is not numerically
/// positive definite: the factorisation fails or a pivot `L_kk^2` (the pivot Gaussian elimination would take) is at
/// most `1e-12` times the largest entry (a singular or nearly singular Gram matrix: rows without support, or
/// dependent ones). The caller verifies the result's residual, so the verdict never rests on this solve's accuracy.
fn solve_spd(a: &[f64], b: &[f64], n: usize) -> Option<Vec<f64>> {
    use faer::linalg::solvers::Solve as _;
    let largest = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if largest.is_nan() || largest == 0.0 || a.len() != n * n || b.len() != n {
        return None;
    }
    let matrix = faer::Mat::from_fn(n, n, |i, j| a[i * n + j]);
    let factor = matrix.llt(faer::Side::Lower).ok()?;
    let l = factor.L();
    // NaN-safe: a NaN pivot is not `Greater`, so it fails the test too
    if (0..n).any(|k| (l[(k, k)] * l[(k, k)]).partial_cmp(&(1e-12 * largest)) != Some(std::cmp::Ordering::Greater)) {
        return None;
    }
    let mut y = faer::Mat::from_fn(n, 1, |i, _| b[i]);
    factor.solve_in_place(y.as_mut());
    Some((0..n).map(|i| y[(i, 0)]).collect())
}

#[cfg(test)]
mod tests {
    use super::solve_spd;
    use proptest::prelude::*;

    /// `M M^T + I / 10` for the `n x n` matrix `M` of `entries` (row-major): symmetric positive definite.
    fn gram_plus_ridge(entries: &[f64], n: usize) -> Vec<f64> {
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                let dot: f64 = (0..n).map(|k| entries[i * n + k] * entries[j * n + k]).sum();
                a[i * n + j] = dot + if i == j { 0.1 } else { 0.0 };
            }
        }
        a
    }

    proptest! {
        #[test]
        fn the_cholesky_solution_satisfies_the_system(
            entries in prop::collection::vec(-1.0f64..1.0, 36),
            rhs in prop::collection::vec(-1.0f64..1.0, 6),
        ) {
            let n = 6;
            let a = gram_plus_ridge(&entries, n);
            let y = solve_spd(&a, &rhs, n);
            prop_assert!(y.is_some(), "a positive definite system has a solution");
            let y = y.unwrap_or_default();
            for i in 0..n {
                let row: f64 = (0..n).map(|j| a[i * n + j] * y[j]).sum();
                prop_assert!((row - rhs[i]).abs() <= 1e-9, "row {i}: {row} against {}", rhs[i]);
            }
        }
    }

    #[test]
    fn singular_indefinite_or_malformed_systems_have_no_solution() {
        // rank one
        assert!(solve_spd(&[1.0, 2.0, 2.0, 4.0], &[1.0, 0.0], 2).is_none());
        // a zero row and column (a part without a vertical support)
        assert!(solve_spd(&[1.0, 0.0, 0.0, 0.0], &[1.0, 1.0], 2).is_none());
        // nearly singular: the second pivot is 1e-14 of the largest entry
        assert!(solve_spd(&[1.0, 1.0, 1.0, 1.0 + 1e-14], &[1.0, 1.0], 2).is_none());
        // indefinite
        assert!(solve_spd(&[1.0, 2.0, 2.0, 1.0], &[1.0, 1.0], 2).is_none());
        // not a number, wrong sizes, all zero
        assert!(solve_spd(&[f64::NAN, 0.0, 0.0, 1.0], &[1.0, 1.0], 2).is_none());
        assert!(solve_spd(&[1.0, 0.0, 0.0], &[1.0, 1.0], 2).is_none());
        assert!(solve_spd(&[0.0; 4], &[1.0, 1.0], 2).is_none());
        // a well-conditioned one is solved
        let y = solve_spd(&[4.0, 2.0, 2.0, 3.0], &[2.0, 1.0], 2).unwrap_or_default();
        assert!((y[0] - 0.5).abs() < 1e-15 && y[1].abs() < 1e-15, "{y:?}");
    }
}
