//! Shared generators and independent oracles (LP and QP with clarabel) for the cspace tests.
#![allow(dead_code)]

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use glam::{DMat3, DVec3};
use proptest::prelude::*;
use stackplan_geom::{ConvexPolytope, convex_hull};

/// Number of proptest cases: `PROPTEST_CASES` if set, else `default`.
pub fn cases(default: u32) -> u32 {
    std::env::var("PROPTEST_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(default)
}

pub fn cuboid(lo: DVec3, hi: DVec3) -> ConvexPolytope {
    ConvexPolytope::cuboid(lo, hi).expect("box")
}

/// A prism: the convex polygon `outline` (x, y) extruded from `z0` to `z1`, then its axes permuted so the extrusion runs
/// along `axis` (0 = x, 1 = y, 2 = z).
pub fn prism(outline: &[(f64, f64)], z0: f64, z1: f64, axis: usize) -> Option<ConvexPolytope> {
    let mut pts = Vec::new();
    for &(x, y) in outline {
        for z in [z0, z1] {
            let p = DVec3::new(x, y, z);
            pts.push(match axis {
                0 => DVec3::new(p.z, p.x, p.y),
                1 => DVec3::new(p.y, p.z, p.x),
                _ => p,
            });
        }
    }
    convex_hull(&pts).ok().map(|h| h.polytope)
}

/// Points on a dyadic grid (multiples of 1/4 in [-2, 2]).
pub fn dyadic_cloud(n: std::ops::Range<usize>) -> impl Strategy<Value = ConvexPolytope> {
    prop::collection::vec((-8i32..=8, -8i32..=8, -8i32..=8), n).prop_filter_map("flat cloud", |v| {
        let pts: Vec<DVec3> = v.into_iter().map(|(a, b, c)| DVec3::new(a as f64, b as f64, c as f64) * 0.25).collect();
        convex_hull(&pts).ok().map(|h| h.polytope)
    })
}

pub fn any_box() -> impl Strategy<Value = ConvexPolytope> {
    ((-4i32..4, -4i32..4, -4i32..4), (1i32..6, 1i32..6, 1i32..6)).prop_map(|((x, y, z), (a, b, c))| {
        let lo = DVec3::new(x as f64, y as f64, z as f64) * 0.5;
        cuboid(lo, lo + DVec3::new(a as f64, b as f64, c as f64) * 0.5)
    })
}

/// Two prisms that share face directions: the same outline (a hull of grid points), scaled and shifted, extruded along
/// the same or another axis, with sheet-like thicknesses.
pub fn prism_pair() -> impl Strategy<Value = (ConvexPolytope, ConvexPolytope)> {
    (
        prop::collection::vec((-4i32..=4, -4i32..=4), 3..8),
        1i32..3,
        (-4i32..4, -4i32..4),
        (0usize..3, 0usize..3),
        (1i32..4, 1i32..4),
    )
        .prop_filter_map("flat outline", |(pts, scale, (dx, dy), (ax_a, ax_b), (ta, tb))| {
            let outline: Vec<(f64, f64)> = pts.iter().map(|&(x, y)| (x as f64 * 0.5, y as f64 * 0.5)).collect();
            let outline_b: Vec<(f64, f64)> =
                pts.iter().map(|&(x, y)| ((x * scale + dx) as f64 * 0.5, (y * scale + dy) as f64 * 0.5)).collect();
            let a = prism(&outline, 0.0, ta as f64 * 0.25, ax_a)?;
            let b = prism(&outline_b, -1.0, -1.0 + tb as f64 * 0.25, ax_b)?;
            Some((a, b))
        })
}

/// The 24 proper rotations that permute and flip the axes (exact matrices).
pub fn axis_rotation(k: usize) -> DMat3 {
    let perms = [[0, 1, 2], [1, 2, 0], [2, 0, 1], [1, 0, 2], [0, 2, 1], [2, 1, 0]];
    let p = perms[k % 6];
    let signs = k / 6; // 0..4
    let mut cols = [DVec3::ZERO; 3];
    let mut s = [1.0, 1.0, 1.0];
    if signs & 1 == 1 {
        s[0] = -1.0;
    }
    if signs & 2 == 2 {
        s[1] = -1.0;
    }
    for c in 0..3 {
        let mut v = DVec3::ZERO;
        v[p[c]] = s[c];
        cols[c] = v;
    }
    let mut m = DMat3::from_cols(cols[0], cols[1], cols[2]);
    if m.determinant() < 0.0 {
        m = DMat3::from_cols(cols[0], cols[1], -cols[2]);
    }
    m
}

/// Random rotations: identity, exact axis rotations, rotations about z, general axis-angle.
pub fn any_rotation() -> impl Strategy<Value = DMat3> {
    prop_oneof![
        Just(DMat3::IDENTITY),
        (0usize..24).prop_map(axis_rotation),
        (0i32..8).prop_map(|k| DMat3::from_rotation_z(k as f64 * std::f64::consts::FRAC_PI_2)),
        (-3.2f64..3.2).prop_map(DMat3::from_rotation_z),
        ((-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0), -3.2f64..3.2).prop_filter_map("axis", |((x, y, z), t)| {
            let v = DVec3::new(x, y, z);
            (v.length() > 0.1).then(|| DMat3::from_axis_angle(v.normalize(), t))
        }),
    ]
}

fn solve(
    p: CscMatrix<f64>,
    q: &[f64],
    a: CscMatrix<f64>,
    b: &[f64],
    cones: &[SupportedConeT<f64>],
) -> Option<Vec<f64>> {
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .tol_gap_abs(1e-10)
        .tol_gap_rel(1e-10)
        .tol_feas(1e-10)
        .build()
        .ok()?;
    let mut solver = DefaultSolver::new(&p, q, &a, b, cones, settings).ok()?;
    solver.solve();
    (solver.solution.status == SolverStatus::Solved).then(|| solver.solution.x.clone())
}

fn dense_csc(rows: &[Vec<f64>], n: usize) -> CscMatrix<f64> {
    let m = rows.len();
    let mut colptr = vec![0];
    let mut rowval = Vec::new();
    let mut nzval = Vec::new();
    for c in 0..n {
        for (r, row) in rows.iter().enumerate() {
            if row[c] != 0.0 {
                rowval.push(r);
                nzval.push(row[c]);
            }
        }
        colptr.push(rowval.len());
    }
    CscMatrix::new(m, n, colptr, rowval, nzval)
}

/// The LP oracle: `max t` such that some point `x` satisfies every face inequality of `R A + p` and of `B` with slack
/// `t` (capped at 1). The interiors intersect iff the optimum is positive; they touch iff it is zero.
/// `None` when the solver does not report `Solved`.
pub fn overlap_slack(a: &ConvexPolytope, rotation: DMat3, p: DVec3, b: &ConvexPolytope) -> Option<f64> {
    let mut rows = Vec::new();
    let mut rhs = Vec::new();
    for f in a.faces() {
        let n = rotation * f.plane.normal;
        rows.push(vec![n.x, n.y, n.z, 1.0]);
        rhs.push(f.plane.offset + n.dot(p));
    }
    for g in b.faces() {
        let n = g.plane.normal;
        rows.push(vec![n.x, n.y, n.z, 1.0]);
        rhs.push(g.plane.offset);
    }
    rows.push(vec![0.0, 0.0, 0.0, 1.0]);
    rhs.push(1.0);
    let m = rows.len();
    let x = solve(
        CscMatrix::zeros((4, 4)),
        &[0.0, 0.0, 0.0, -1.0],
        dense_csc(&rows, 4),
        &rhs,
        &[SupportedConeT::NonnegativeConeT(m)],
    )?;
    Some(x[3])
}

/// Euclidean distance from `p` to the convex hull of `points`, by a QP: `min |x - p|^2`, `x = sum l_k P_k`,
/// `l >= 0`, `sum l = 1`.
pub fn distance_to_hull(points: &[DVec3], p: DVec3) -> Option<f64> {
    let n = 3 + points.len();
    let mut pcols = vec![0];
    let mut prow = Vec::new();
    let mut pval = Vec::new();
    for c in 0..n {
        if c < 3 {
            prow.push(c);
            pval.push(2.0);
        }
        pcols.push(prow.len());
    }
    let pm = CscMatrix::new(n, n, pcols, prow, pval);
    let mut q = vec![0.0; n];
    q[0] = -2.0 * p.x;
    q[1] = -2.0 * p.y;
    q[2] = -2.0 * p.z;
    let mut rows = Vec::new();
    let mut b = Vec::new();
    for d in 0..3 {
        let mut r = vec![0.0; n];
        r[d] = 1.0;
        for (k, pt) in points.iter().enumerate() {
            r[3 + k] = -pt[d];
        }
        rows.push(r);
        b.push(0.0);
    }
    let mut r = vec![0.0; n];
    for k in 0..points.len() {
        r[3 + k] = 1.0;
    }
    rows.push(r);
    b.push(1.0);
    for k in 0..points.len() {
        let mut r = vec![0.0; n];
        r[3 + k] = -1.0;
        rows.push(r);
        b.push(0.0);
    }
    let x = solve(
        pm,
        &q,
        dense_csc(&rows, n),
        &b,
        &[SupportedConeT::ZeroConeT(4), SupportedConeT::NonnegativeConeT(points.len())],
    )?;
    Some((DVec3::new(x[0], x[1], x[2]) - p).length())
}

/// All difference points `b_j - R a_i`.
pub fn differences(a: &ConvexPolytope, rotation: DMat3, b: &ConvexPolytope) -> Vec<DVec3> {
    let mut v = Vec::new();
    for x in a.vertices() {
        let r = rotation * *x;
        for y in b.vertices() {
            v.push(*y - r);
        }
    }
    v
}
