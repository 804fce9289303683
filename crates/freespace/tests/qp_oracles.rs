//! Property tests of the exact placement QP (`minimize`; strictly convex costs take the closed-form path of
//! `active_set`, singular ones the general method) against independent methods:
//!
//! * **brute-force enumeration of active sets**: for every subset `S` of at most `D` inequalities, the KKT system
//!   `[H A_S^T; A_S 0] (p, lambda) = (-g, b_S)` solved by Gaussian elimination with partial pivoting (singular
//!   systems skipped); the feasible solutions are ranked by cost and then by the tie-break (lowest z, then y, then
//!   x). The lexicographic optimum is always among them (it is a KKT point that is a vertex of the set of
//!   minimisers, so some independent tight subset pins it with a non-singular system), so this finds it without
//!   any active-set logic;
//! * the general active-set method (`qp::minimize_general`, the definition the fast path must reproduce): the same
//!   point up to rounding in the last bits, the same tight set; for singular Hessians (which do not take the fast
//!   path) the identical solution;
//! * clarabel on solid cells (same cost within 1e-7 relative).
//!
//! Cells include the degenerate cases of sheet-metal stacking: duplicate and parallel planes, faces and edges (flat
//! cells), vertices where more than three planes are tight, empty cells; costs include w = 0 and w = 1 of cost (1)
//! (singular Hessians), linear costs (LPs with the tie-break only) and badly scaled positive Hessians.

use crate::common;

use common::Rng;
use proptest::prelude::*;
use stackplan_freespace::qp::minimize_general;
use stackplan_freespace::{Cell, Halfspace, QpError, QpSolution, SeparableCost, Tag, minimize, minimize_clarabel};
use stackplan_geom::{DVec3, Tolerance};

fn dot<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    (0..D).map(|i| a[i] * b[i]).sum()
}

fn normalize(v: [f64; 3]) -> [f64; 3] {
    let l = dot(&v, &v).sqrt();
    v.map(|c| c / l)
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// The kinds of test cells.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    /// A box with random cuts.
    Solid,
    /// A box with cuts, an exact duplicate of one inequality and a parallel copy of another.
    Duplicates,
    /// A face: a box cut by two opposite inequalities through its centre.
    Face,
    /// An edge: two such pairs.
    Edge,
    /// A pyramid: `k` = 4..6 planes through an apex, capped, inside a box.
    Apex,
    /// A box with an inequality that excludes it.
    Empty,
}

const KINDS: [Kind; 6] = [Kind::Solid, Kind::Duplicates, Kind::Face, Kind::Edge, Kind::Apex, Kind::Empty];

/// A random cell of `kind` around a random centre; for [`Kind::Apex`] also the apex and its planes' normals.
fn random_cell(rng: &mut Rng, kind: Kind, cuts: usize) -> (Vec<Halfspace<3>>, [f64; 3], Vec<[f64; 3]>) {
    let c = [rng.range(-5.0, 5.0), rng.range(-5.0, 5.0), rng.range(0.0, 5.0)];
    let mut hs = Vec::new();
    let half = if kind == Kind::Apex { 20.0 } else { 6.0 };
    for i in 0..3 {
        let mut n = [0.0; 3];
        n[i] = 1.0;
        hs.push(Halfspace::new(n, c[i] + rng.range(1.0, half), Tag::User(0)));
        n[i] = -1.0;
        hs.push(Halfspace::new(n, -c[i] + rng.range(1.0, half), Tag::User(0)));
    }
    for _ in 0..cuts {
        let n = rng.unit3();
        hs.push(Halfspace::new(n, dot(&n, &c) + rng.range(0.3, 4.0), Tag::User(0)));
    }
    let mut apex_normals = Vec::new();
    match kind {
        Kind::Solid => {}
        Kind::Duplicates => {
            let a = hs[rng.below(hs.len())];
            hs.push(a);
            let b = hs[rng.below(hs.len())];
            // a parallel plane: sometimes coincident up to rounding of the offset, sometimes strictly inside
            let shift = if rng.below(2) == 0 { 0.0 } else { rng.range(0.05, 0.5) };
            hs.push(Halfspace::new(b.normal.map(|x| 2.0 * x), 2.0 * (b.offset - shift), Tag::User(0)));
        }
        Kind::Face | Kind::Edge => {
            for _ in 0..if kind == Kind::Face { 1 } else { 2 } {
                let n = common::sheet_normal(rng);
                let d = dot(&n, &c);
                hs.push(Halfspace::new(n, d, Tag::User(0)));
                hs.push(Halfspace::new(n.map(|x| -x), -d, Tag::User(0)));
            }
        }
        Kind::Apex => {
            // planes a_j . (p - c) <= 0 with normals around the axis u; capped by -u . (p - c) <= height
            let u = rng.unit3();
            let e1 = normalize(cross(u, if u[0].abs() < 0.6 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] }));
            let e2 = cross(u, e1);
            let k = 4 + rng.below(3);
            let beta = rng.range(0.3, 1.2);
            for j in 0..k {
                let t = std::f64::consts::TAU * (j as f64 + rng.range(-0.2, 0.2)) / k as f64;
                let a =
                    normalize([0, 1, 2].map(|i| u[i] * beta.cos() + beta.sin() * (t.cos() * e1[i] + t.sin() * e2[i])));
                hs.push(Halfspace::new(a, dot(&a, &c), Tag::User(0)));
                apex_normals.push(a);
            }
            let cap = u.map(|x| -x);
            hs.push(Halfspace::new(cap, dot(&cap, &c) + rng.range(1.0, 8.0), Tag::User(0)));
        }
        Kind::Empty => {
            let n = rng.unit3();
            hs.push(Halfspace::new(n, dot(&n, &c) - 12.0, Tag::User(0)));
        }
    }
    for i in (1..hs.len()).rev() {
        let j = rng.below(i + 1);
        hs.swap(i, j);
    }
    for (j, h) in hs.iter_mut().enumerate() {
        h.tag = Tag::User(j as u64);
    }
    (hs, c, apex_normals)
}

/// Cost kinds: cost (1) with `w` in (0, 1), w = 0, w = 1, the desired position, a positive Hessian with entries
/// over three orders of magnitude, a Hessian with zero entries, a linear cost (possibly zero).
fn random_cost(rng: &mut Rng, kind: usize) -> SeparableCost<3> {
    let ext = common::random_extents(rng);
    let reference = DVec3::new(rng.range(-15.0, 15.0), rng.range(-15.0, 15.0), rng.range(-4.0, 8.0));
    match kind % 7 {
        0 => common::stacking_cost(rng.range(0.02, 0.98), &ext, reference).expect("cost"),
        1 => common::stacking_cost(0.0, &ext, reference).expect("cost"),
        2 => common::stacking_cost(1.0, &ext, reference).expect("cost"),
        3 => common::desired_position_cost(ext.center_of_gravity, reference).expect("cost"),
        4 => {
            let h = [0; 3].map(|_| 10f64.powf(rng.range(-2.0, 1.0)));
            let g = [0; 3].map(|_| rng.range(-30.0, 30.0));
            SeparableCost::new(h, g, 0.0).expect("cost")
        }
        5 => {
            let zero = rng.below(3);
            let h = [0, 1, 2].map(|i| if i == zero || rng.below(3) == 0 { 0.0 } else { rng.range(0.1, 5.0) });
            let g = [0; 3].map(|_| if rng.below(4) == 0 { 0.0 } else { rng.range(-20.0, 20.0) });
            SeparableCost::new(h, g, 0.0).expect("cost")
        }
        _ => {
            let g = [0; 3].map(|_| if rng.below(3) == 0 { 0.0 } else { rng.range(-1.0, 1.0) });
            SeparableCost::new([0.0; 3], g, 0.0).expect("cost")
        }
    }
}

/// Solves `m x = r` (order `n`) by Gaussian elimination with partial pivoting; `None` when a pivot is below
/// `1e-10` of the largest entry.
fn gauss(mut m: Vec<Vec<f64>>, mut r: Vec<f64>) -> Option<Vec<f64>> {
    let n = r.len();
    let big = m.iter().flatten().fold(0.0_f64, |a, &x| a.max(x.abs()));
    for col in 0..n {
        let piv = (col..n).max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))?;
        if m[piv][col].abs() <= 1e-10 * big {
            return None;
        }
        m.swap(col, piv);
        r.swap(col, piv);
        for row in col + 1..n {
            let f = m[row][col] / m[col][col];
            for k in col..n {
                m[row][k] -= f * m[col][k];
            }
            r[row] -= f * r[col];
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let s: f64 = (row + 1..n).map(|k| m[row][k] * x[k]).sum();
        x[row] = (r[row] - s) / m[row][row];
    }
    Some(x)
}

fn subsets(m: usize, max: usize, prefix: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
    out.push(prefix.clone());
    if prefix.len() == max {
        return;
    }
    let from = prefix.last().map_or(0, |&j| j + 1);
    for j in from..m {
        prefix.push(j);
        subsets(m, max, prefix, out);
        prefix.pop();
    }
}

/// The brute-force lexicographic optimum (see the module documentation); `None` when no subset gives a feasible
/// point (an empty cell).
fn brute_force<const D: usize>(hs: &[Halfspace<D>], h: &[f64; D], g: &[f64; D], tol: f64) -> Option<[f64; D]> {
    let mut all = Vec::new();
    subsets(hs.len(), D, &mut Vec::new(), &mut all);
    let f = |p: &[f64; D]| (0..D).map(|i| (0.5 * h[i] * p[i] + g[i]) * p[i]).sum::<f64>();
    // the size of the terms of f, for the rounding-level tolerance of cost ties
    let terms = |p: &[f64; D]| (0..D).map(|i| (0.5 * h[i] * p[i] * p[i]).abs() + (g[i] * p[i]).abs()).sum::<f64>();
    let mut candidates: Vec<(f64, [f64; D])> = Vec::new();
    for s in &all {
        let n = D + s.len();
        let mut m = vec![vec![0.0; n]; n];
        let mut r = vec![0.0; n];
        for i in 0..D {
            m[i][i] = h[i];
            r[i] = -g[i];
        }
        for (k, &j) in s.iter().enumerate() {
            for i in 0..D {
                m[i][D + k] = hs[j].normal[i];
                m[D + k][i] = hs[j].normal[i];
            }
            r[D + k] = hs[j].offset;
        }
        let Some(x) = gauss(m, r) else { continue };
        let mut p = [0.0; D];
        p.copy_from_slice(&x[..D]);
        let feasible = hs.iter().all(|hh| dot(&hh.normal, &p) - hh.offset <= tol);
        if feasible && p.iter().all(|c| c.is_finite()) {
            candidates.push((f(&p), p));
        }
    }
    let (fmin, at) = candidates.iter().fold((f64::INFINITY, None), |a, c| if c.0 < a.0 { (c.0, Some(c.1)) } else { a });
    // minimisers tie within rounding; a looser tolerance would admit points near the optimum of a quadratic
    // coordinate (f grows like the square of the distance) that beat it on the tie-break
    let ftol = 1e-12 * at.map_or(1.0, |p| terms(&p).max(1.0));
    // lowest z, then y, then x (2-D: lowest y, then x) among the minimisers, coordinates equal within 1e-7
    let better = |a: &[f64; D], b: &[f64; D]| {
        for i in (0..D).rev() {
            if a[i] < b[i] - 1e-7 {
                return true;
            }
            if a[i] > b[i] + 1e-7 {
                return false;
            }
        }
        false
    };
    let mut best: Option<[f64; D]> = None;
    for (fc, p) in &candidates {
        if *fc <= fmin + ftol && best.is_none_or(|b| better(p, &b)) {
            best = Some(*p);
        }
    }
    best
}

fn cost_eq(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1.0)
}

/// Checks `minimize` on a cell against the brute force, the general method and clarabel.
fn check<const D: usize>(
    hs: Vec<Halfspace<D>>,
    scale: f64,
    cost: &SeparableCost<D>,
    clarabel_must_solve: bool,
) -> Result<Option<QpSolution<D>>, TestCaseError> {
    let cell = Cell::new(hs, Tolerance::for_scale(scale)).map_err(|e| TestCaseError::fail(format!("cell: {e}")))?;
    let tol = cell.tolerance().linear;
    let (h, g) = (cost.hessian_diagonal(), cost.linear());
    let oracle = brute_force(cell.halfspaces(), &h, &g, tol);
    let fast = minimize(&cell, cost);
    let general = minimize_general(&cell, cost);
    if cell.is_empty() {
        prop_assert_eq!(fast, Err(QpError::EmptyCell));
        prop_assert_eq!(general, Err(QpError::EmptyCell));
        // empty means a Chebyshev radius below -tol: every point violates some inequality by more than tol
        prop_assert!(oracle.is_none(), "brute force found {:?} in an empty cell", oracle);
        return Ok(None);
    }
    let fast = fast.map_err(|e| TestCaseError::fail(format!("minimize: {e}")))?;
    let general = general.map_err(|e| TestCaseError::fail(format!("minimize_general: {e}")))?;
    let strictly_convex = h.iter().all(|&x| x > 0.0);
    if strictly_convex {
        for i in 0..D {
            prop_assert!(
                (fast.point[i] - general.point[i]).abs() <= 1e-9 * scale,
                "fast {:?} vs general {:?}",
                fast.point,
                general.point
            );
        }
        prop_assert!(cost_eq(fast.cost, general.cost, 1e-12), "cost {} vs {}", fast.cost, general.cost);
        prop_assert_eq!(&fast.tight, &general.tight);
    } else {
        // singular Hessians do not take the fast path: the general method's answer, bit for bit
        prop_assert_eq!(&fast, &general);
    }
    let oracle =
        oracle.ok_or_else(|| TestCaseError::fail("brute force found no feasible point of a non-empty cell"))?;
    let f_oracle = cost.evaluate(&oracle);
    // the brute force accepts points within the cell's tolerance, so on a flat cell (opposite planes) it may gain
    // up to |grad f| tol by leaving the face; beyond that the costs agree to 1e-9 relative
    let grad = cost.gradient(&fast.point);
    let slack = 2.0 * tol * dot(&grad, &grad).sqrt();
    prop_assert!(
        (fast.cost - f_oracle).abs() <= 1e-9 * fast.cost.abs().max(1.0) + slack,
        "cost {} vs brute force {}",
        fast.cost,
        f_oracle
    );
    for i in 0..D {
        prop_assert!(
            (fast.point[i] - oracle[i]).abs() <= 1e-6 * scale,
            "point {:?} vs brute force {:?} (h {:?}, g {:?})",
            fast.point,
            oracle,
            h,
            g
        );
    }
    // clarabel: compared when it solves a solid cell; it must solve the plain ones (degenerate vertices, duplicate
    // planes and LPs can stop it at its iteration limit, which is never taken as success)
    if cell.is_solid() {
        match minimize_clarabel(&cell, cost) {
            Ok(k) => prop_assert!(cost_eq(fast.cost, k.cost, 1e-7), "cost {} vs clarabel {}", fast.cost, k.cost),
            Err(e) => prop_assert!(!clarabel_must_solve, "clarabel failed on a plain solid cell: {e}"),
        }
    }
    Ok(Some(fast))
}

proptest! {
    /// 3-D cells of every kind, every cost kind.
    #[test]
    fn qp_matches_brute_force_general_method_and_clarabel(
        seed in any::<u64>(), kind in 0usize..6, cost_kind in 0usize..7, cuts in 0usize..5,
    ) {
        let mut rng = Rng(seed);
        let (hs, _, _) = random_cell(&mut rng, KINDS[kind], cuts);
        let cost = random_cost(&mut rng, cost_kind);
        check(hs, 30.0, &cost, kind == 0 && cost_kind != 6)?;
    }

    /// Strictly convex costs (the fast path) on every kind of cell.
    #[test]
    fn strictly_convex_qp_matches_brute_force(seed in any::<u64>(), kind in 0usize..6, cost_kind in 0usize..3, cuts in 0usize..5) {
        let mut rng = Rng(seed);
        let (hs, _, _) = random_cell(&mut rng, KINDS[kind], cuts);
        let cost = random_cost(&mut rng, [0, 3, 4][cost_kind]);
        check(hs, 30.0, &cost, kind == 0)?;
    }

    /// A vertex where 4 to 6 planes are tight: a cost whose unconstrained optimum lies in the apex's normal cone
    /// (`p0 = c + H^-1 sum mu_j a_j`, `mu_j > 0`) has its minimum exactly at the apex, with every apex plane tight.
    #[test]
    fn more_than_three_tight_planes_at_the_optimum(seed in any::<u64>(), cuts in 0usize..3) {
        let mut rng = Rng(seed);
        let (hs, apex, normals) = random_cell(&mut rng, Kind::Apex, cuts);
        let h = [0; 3].map(|_| rng.range(0.2, 5.0));
        let mut p0 = apex;
        for a in &normals {
            let mu = rng.range(0.1, 3.0);
            for i in 0..3 {
                p0[i] += mu * a[i] / h[i];
            }
        }
        let g = [0, 1, 2].map(|i| -h[i] * p0[i]);
        let cost = SeparableCost::new(h, g, 0.0).expect("cost");
        let sol = check(hs, 30.0, &cost, false)?.ok_or_else(|| TestCaseError::fail("apex cell is empty"))?;
        for i in 0..3 {
            prop_assert!((sol.point[i] - apex[i]).abs() <= 1e-9, "{:?} vs apex {:?}", sol.point, apex);
        }
        prop_assert!(sol.tight.len() >= normals.len(), "tight {:?}", sol.tight);
    }

    /// 2-D cells (the seed's Omega at fixed p_z): polygons with cuts, duplicates, a segment (flat) or empty.
    #[test]
    fn qp_2d_matches_brute_force(seed in any::<u64>(), kind in 0usize..4, cuts in 0usize..5, cost_kind in 0usize..4) {
        let mut rng = Rng(seed);
        let c = [rng.range(-5.0, 5.0), rng.range(-5.0, 5.0)];
        let mut hs = Vec::new();
        for i in 0..2 {
            let mut n = [0.0; 2];
            n[i] = 1.0;
            hs.push(Halfspace::new(n, c[i] + rng.range(1.0, 6.0), Tag::User(0)));
            n[i] = -1.0;
            hs.push(Halfspace::new(n, -c[i] + rng.range(1.0, 6.0), Tag::User(0)));
        }
        let unit2 = |rng: &mut Rng| {
            let t = rng.range(0.0, std::f64::consts::TAU);
            [t.cos(), t.sin()]
        };
        for _ in 0..cuts {
            let n = unit2(&mut rng);
            hs.push(Halfspace::new(n, dot(&n, &c) + rng.range(0.3, 4.0), Tag::User(0)));
        }
        match kind {
            1 => {
                let a = hs[rng.below(hs.len())];
                hs.push(a);
                // three lines through one point: a vertex with three tight lines
                let n = unit2(&mut rng);
                let q = [c[0] + 0.5, c[1] - 0.25];
                for k in 0..3 {
                    let t = 0.7 * (k as f64 - 1.0);
                    let m = [n[0] * t.cos() - n[1] * t.sin(), n[0] * t.sin() + n[1] * t.cos()];
                    hs.push(Halfspace::new(m, dot(&m, &q), Tag::User(0)));
                }
            }
            2 => {
                let n = unit2(&mut rng);
                let d = dot(&n, &c);
                hs.push(Halfspace::new(n, d, Tag::User(0)));
                hs.push(Halfspace::new([-n[0], -n[1]], -d, Tag::User(0)));
            }
            3 => {
                let n = unit2(&mut rng);
                hs.push(Halfspace::new(n, dot(&n, &c) - 9.0, Tag::User(0)));
            }
            _ => {}
        }
        for i in (1..hs.len()).rev() {
            let j = rng.below(i + 1);
            hs.swap(i, j);
        }
        let (h, g) = match cost_kind {
            0 => ([0; 2].map(|_| rng.range(0.1, 8.0)), [0; 2].map(|_| rng.range(-40.0, 40.0))),
            1 => ([0.0, 0.0], [0; 2].map(|_| if rng.below(2) == 0 { 0.0 } else { rng.range(-1.0, 1.0) })),
            2 => ([0.0, rng.range(0.1, 8.0)], [0; 2].map(|_| rng.range(-40.0, 40.0))),
            _ => ([rng.range(0.1, 8.0), 0.0], [rng.range(-40.0, 40.0), 0.0]),
        };
        let cost = SeparableCost::new(h, g, 0.0).expect("cost");
        check(hs, 30.0, &cost, kind == 0 && cost_kind != 1)?;
    }
}

proptest! {
    /// Nearly singular Hessians (cost (1) with w within 1e-3 of 0 or 1, min h / max h < 1e-3) keep the general
    /// method: the minimiser is ill-determined within the multiplier tolerance there, so `minimize` must return the
    /// general method's solution bit for bit.
    #[test]
    fn nearly_singular_costs_keep_the_general_method(seed in any::<u64>(), kind in 0usize..6, cuts in 0usize..5, e in -9.0f64..-3.5, near_one in any::<bool>()) {
        let mut rng = Rng(seed);
        let (hs, _, _) = random_cell(&mut rng, KINDS[kind], cuts);
        let w = if near_one { 1.0 - 10f64.powf(e) } else { 10f64.powf(e) };
        let ext = common::Extents {
            x_max: 2.0, x_min: -1.0, y_max: 1.5, y_min: -2.5, center_of_gravity: DVec3::new(0.1, -0.2, 0.7),
        };
        let reference = DVec3::new(rng.range(-15.0, 15.0), rng.range(-15.0, 15.0), rng.range(-4.0, 8.0));
        let cost = common::stacking_cost(w, &ext, reference).expect("cost");
        let cell = Cell::new(hs, Tolerance::for_scale(30.0)).map_err(|e| TestCaseError::fail(format!("{e}")))?;
        prop_assert_eq!(minimize(&cell, &cost), minimize_general(&cell, &cost));
    }
}

/// Goldens: the planner's typical situations with exact answers.
#[test]
fn goldens_of_the_fast_path() {
    let boxed = common::boxed;
    let tol = Tolerance::for_scale(10.0);
    // interior optimum: the unconstrained minimiser exactly, no active constraint
    let cell = Cell::new(boxed([0.0; 3], [4.0; 3]), tol).expect("cell");
    let f = SeparableCost::new([2.0, 4.0, 8.0], [-3.0, -4.0, -8.0], 0.0).expect("cost");
    let s = minimize(&cell, &f).expect("qp");
    assert_eq!(s.point, [1.5, 1.0, 1.0]);
    assert!(s.active.is_empty() && s.tight.is_empty());
    // optimum on an edge of a slanted plane and the floor: (x, y, z) = (t, 0, 0) with the plane x + y + z <= 1
    let mut hs = boxed([0.0; 3], [4.0; 3]);
    hs.push(Halfspace::new([1.0, 1.0, 1.0], 1.0, Tag::User(6)));
    let cell = Cell::new(hs, tol).expect("cell");
    // f = (x - 3)^2 + (y + 1)^2 + (z + 1)^2: on x + y + z = 1 with y = z = 0 at x = 1 (multipliers 6, 6, 4 sqrt 3)
    let f = SeparableCost::new([2.0; 3], [-6.0, 2.0, 2.0], 0.0).expect("cost");
    let s = minimize(&cell, &f).expect("qp");
    assert!((s.point[0] - 1.0).abs() < 1e-15 && s.point[1].abs() < 1e-15 && s.point[2].abs() < 1e-15, "{s:?}");
    assert_eq!(s.active, vec![3, 5, 6]);
    let want = [6.0, 6.0, 4.0 * 3.0_f64.sqrt()];
    for (m, w) in s.multipliers.iter().zip(want) {
        assert!((m - w).abs() < 1e-12, "{:?}", s.multipliers);
    }
    // a face cell (z squeezed to 1): the optimum stays on the face
    let cell = Cell::new(boxed([0.0, 0.0, 1.0], [4.0, 4.0, 1.0]), tol).expect("cell");
    let f = SeparableCost::new([2.0; 3], [-2.0, -4.0, 10.0], 0.0).expect("cost");
    let s = minimize(&cell, &f).expect("qp");
    assert!((s.point[0] - 1.0).abs() < 1e-15 && (s.point[1] - 2.0).abs() < 1e-15 && (s.point[2] - 1.0).abs() < 1e-15);
}
