//! Horizontal clearance between parts (\[A\] section 7.2: "parts are separated in the plane by at least 5 mm to account
//! for robot positioning error").
//!
//! A robot places a part with a horizontal positioning error `e` (|e| <= delta) before lowering it. Two convex
//! components `A`, `B` keep clear under every such error iff no horizontal `e` with `|e| < delta` makes `A + e`
//! overlap `B`'s interior. Pairs whose z-ranges are disjoint (within the tolerance; a part resting on another) can
//! never meet by a horizontal shift and are exempt. For the others the **horizontal distance**
//!
//! ```text
//! d_h(A, B) = min |e|  s.t.  e = b - a,  a in A,  b in B,  e_z = 0
//! ```
//!
//! must be at least `delta`. With `a = sum lambda_i a_i`, `b = sum mu_j b_j` (convex combinations of the vertices)
//! this is a small SOCP (one `SecondOrderConeT(3)`), solved by clarabel. Cheap filters run first, all lower bounds
//! of `d_h` or `d_h` itself: the gap between the boxes in x or in y; the separating axes' bound
//! ([`horizontal_distance_bound_by_axes`]: the gap along a facet normal of the Minkowski difference over its
//! horizontal part, exact when the nearest point of the slice lies on one of the slice's edges); the distance between
//! the vertical projections; the exact `d_h` from the slice of the Minkowski difference at `z = 0`
//! ([`horizontal_distance_by_slice`], for pairs of at most 256 vertex differences). The axes and the slice stand for
//! the SOCP when they are above `delta` by more than 1e-6 mm, the others when they are at least `delta` (a pair
//! farther than `delta` is only known to keep its clearance: [`horizontal_distance_at_least`] returns a value at
//! least `delta`, not the distance). Cost: O(1) for the boxes, O((F_A + F_B + E_A E_B)(V_A + V_B)) for the axes,
//! O(V log V) for the projections, O((V_A V_B)^2) for the slice; one SOCP with `V_A + V_B + 1` variables for the pairs
//! the filters leave within 1e-6 mm of `delta` or below it. On the 15-part Triangle plan (1 263 pairs near the
//! clearance, `benches/check.rs`) the whole test takes 7.5 ms, the axes alone 3.2 ms, the slice alone 84 ms.

use crate::polygon2d::{convex_distance, convex_hull_2d};
use crate::world::WorldComponent;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SecondOrderConeT, SolverStatus, ZeroConeT,
};
use glam::DVec2;

/// Whether the z-ranges of `a` and `b` are disjoint within `tol` (exempt from the horizontal clearance).
pub fn vertically_separated(a: &WorldComponent, b: &WorldComponent, tol: f64) -> bool {
    a.aabb.1.z <= b.aabb.0.z + tol || b.aabb.1.z <= a.aabb.0.z + tol
}

/// A lower bound of the horizontal distance when one of the filters puts it at least at `delta` (the boxes' gap in x
/// or y, the separating axes' bound, the distance of the vertical projections, the slice; in that order, cheapest
/// first); the SOCP's value otherwise. `None` when the SOCP did not end `Solved`. A value at least `delta` only says
/// that the pair keeps its clearance; below `delta` it is the distance.
pub fn horizontal_distance_at_least(a: &WorldComponent, b: &WorldComponent, delta: f64, tol: f64) -> Option<f64> {
    let gap_x = (b.aabb.0.x - a.aabb.1.x).max(a.aabb.0.x - b.aabb.1.x);
    let gap_y = (b.aabb.0.y - a.aabb.1.y).max(a.aabb.0.y - b.aabb.1.y);
    let box_gap = gap_x.max(gap_y);
    if box_gap >= delta {
        return Some(box_gap);
    }
    // the separating axes' bound (a few dozen projections): clearly above `delta`, the pair keeps its clearance
    let by_axes = horizontal_distance_bound_by_axes(a, b, tol);
    if by_axes >= delta + SLICE_MARGIN {
        return Some(by_axes);
    }
    let project = |c: &WorldComponent| {
        let pts: Vec<DVec2> = c.polytope.vertices().iter().map(|v| DVec2::new(v.x, v.y)).collect();
        convex_hull_2d(&pts, tol)
    };
    let projected = convex_distance(&project(a), &project(b));
    if projected >= delta {
        return Some(projected);
    }
    // the exact distance from the slice of the Minkowski difference (cheap for a component's few vertices): a value
    // clearly above `delta` is one the SOCP would also put above it, so the SOCP is left out; near `delta` (and for
    // pairs with many vertices) the SOCP decides
    if a.polytope.vertices().len() * b.polytope.vertices().len() <= SLICE_MAX_DIFFERENCES
        && let Some(sliced) = horizontal_distance_by_slice(a, b, tol)
        && sliced >= delta + SLICE_MARGIN
    {
        return Some(sliced);
    }
    horizontal_distance(a, b)
}

/// How far above `delta` (mm) the slice's distance must be to stand for the SOCP's: both are exact up to rounding
/// (about 1e-12 of the coordinates).
const SLICE_MARGIN: f64 = 1e-6;

/// The most vertex differences the slice takes (its cost is quadratic in them).
const SLICE_MAX_DIFFERENCES: usize = 256;

/// A lower bound of the horizontal distance `d_h` from separating axes: for any direction `w` with a horizontal part,
/// every horizontal `e = b - a` has `w . e = w_xy . e_xy <= |w_xy| |e|` and `w . e >= gap_w` (the gap between the
/// projections of `A` and `B` on `w`), so `|e| >= gap_w / |w_xy|` when `gap_w > 0`. The largest such value over the
/// face normals of both and the cross products of their edge directions: these are the facet normals of the
/// Minkowski difference, so the bound is `d_h` itself when the nearest point of the slice lies on an edge of the
/// slice, and below it when it is a vertex of the slice. Each gap is taken `tol` smaller (unit axes), so that
/// its rounding, magnified by `1 / |w_xy|` for nearly vertical axes, never lifts the bound above `d_h`.
/// `-inf` when no axis separates. O((F_A + F_B + E_A E_B) (V_A + V_B)), no solver.
pub fn horizontal_distance_bound_by_axes(a: &WorldComponent, b: &WorldComponent, tol: f64) -> f64 {
    let (va, vb) = (a.polytope.vertices(), b.polytope.vertices());
    let project = |vs: &[glam::DVec3], w: glam::DVec3| {
        vs.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            let x = w.dot(*v);
            (lo.min(x), hi.max(x))
        })
    };
    let mut best = f64::NEG_INFINITY;
    let mut test = |w: glam::DVec3| {
        let horizontal = w.truncate().length();
        if horizontal.is_nan() || horizontal <= 0.0 {
            return;
        }
        let (a_lo, a_hi) = project(va, w);
        let (b_lo, b_hi) = project(vb, w);
        let gap = (b_lo - a_hi).max(a_lo - b_hi) - tol;
        if gap > 0.0 {
            best = best.max(gap / horizontal);
        }
    };
    for &n in a.normals.iter().chain(&b.normals) {
        test(n);
    }
    for &da in &a.edge_directions {
        for &db in &b.edge_directions {
            let c = da.cross(db);
            let length = c.length();
            if length > 1e-9 {
                test(c / length);
            }
        }
    }
    best
}

/// The horizontal distance `d_h` of the module documentation by the slice of the Minkowski difference `B - A` at
/// `z = 0`: `B - A` is the hull of the vertex differences `b - a`, and its slice is the hull of the points where the
/// segments between differences on opposite sides of the plane cross it (and the differences on it); `d_h` is the
/// distance from the origin to that polygon (0 when it holds the origin; its hull drops points within `tol` of each
/// other, as [`convex_hull_2d`] does). `None` when no difference reaches the
/// plane (the z-ranges do not meet). O(N^2) for `N = V_A V_B` differences, no solver.
pub fn horizontal_distance_by_slice(a: &WorldComponent, b: &WorldComponent, tol: f64) -> Option<f64> {
    let diffs: Vec<glam::DVec3> =
        b.polytope.vertices().iter().flat_map(|q| a.polytope.vertices().iter().map(move |p| *q - *p)).collect();
    let mut slice: Vec<DVec2> = Vec::new();
    for (i, p) in diffs.iter().enumerate() {
        if p.z == 0.0 {
            slice.push(p.truncate());
        }
        for q in &diffs[i + 1..] {
            if (p.z < 0.0 && q.z > 0.0) || (p.z > 0.0 && q.z < 0.0) {
                let t = p.z / (p.z - q.z);
                slice.push((*p + (*q - *p) * t).truncate());
            }
        }
    }
    if slice.is_empty() {
        return None;
    }
    Some(convex_distance(&convex_hull_2d(&slice, tol), &[DVec2::ZERO]))
}

/// The exact horizontal distance `d_h` of the module documentation (SOCP). `None` when not `Solved`.
pub fn horizontal_distance(a: &WorldComponent, b: &WorldComponent) -> Option<f64> {
    let va = a.polytope.vertices();
    let vb = b.polytope.vertices();
    let origin = a.polytope.vertex_centroid();
    let (na, nb) = (va.len(), vb.len());
    let n = na + nb + 1;
    let t = na + nb;
    let (mut ri, mut ci, mut vi) = (Vec::new(), Vec::new(), Vec::new());
    let mut push = |r: usize, c: usize, v: f64| {
        ri.push(r);
        ci.push(c);
        vi.push(v);
    };
    // equalities: sum lambda = 1, sum mu = 1, (b - a)_z = 0
    for i in 0..na {
        push(0, i, 1.0);
        push(2, i, -(va[i].z - origin.z));
    }
    for j in 0..nb {
        push(1, na + j, 1.0);
        push(2, na + j, vb[j].z - origin.z);
    }
    let mut rhs = vec![1.0, 1.0, 0.0];
    // lambda, mu >= 0
    for k in 0..na + nb {
        push(3 + k, k, -1.0);
        rhs.push(0.0);
    }
    // (t, e_x, e_y) in SOC
    let r0 = 3 + na + nb;
    push(r0, t, -1.0);
    for i in 0..na {
        push(r0 + 1, i, va[i].x - origin.x);
        push(r0 + 2, i, va[i].y - origin.y);
    }
    for j in 0..nb {
        push(r0 + 1, na + j, -(vb[j].x - origin.x));
        push(r0 + 2, na + j, -(vb[j].y - origin.y));
    }
    rhs.extend_from_slice(&[0.0, 0.0, 0.0]);
    let m = r0 + 3;
    let amat = CscMatrix::new_from_triplets(m, n, ri, ci, vi);
    let p = CscMatrix::zeros((n, n));
    let mut q = vec![0.0; n];
    q[t] = 1.0;
    let cones = [ZeroConeT(3), NonnegativeConeT(na + nb), SecondOrderConeT(3)];
    let settings = DefaultSettingsBuilder::default().verbose(false).build().ok()?;
    let mut solver = DefaultSolver::new(&p, &q, &amat, &rhs, &cones, settings).ok()?;
    solver.solve();
    if solver.solution.status != SolverStatus::Solved {
        tracing::debug!(status = ?solver.solution.status, "horizontal distance SOCP not solved");
        return None;
    }
    Some(solver.solution.x[t].max(0.0))
}
