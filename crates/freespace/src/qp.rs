//! The placement QP: minimum of a separable convex quadratic over a cell, with the active inequalities.
//!
//! \[A\] VI-A-1 and VI-A-4 (Ayyadevara et al. 2002, sections 6.1.1, 6.1.4): the optimum of the convex quadratic cost
//! per convex free-space component; its active inequalities name the contacts (obstacle faces) or the walls of the
//! floor volume.
//!
//! Two solvers:
//! * [`minimize`]: the exact primal active-set method of `active_set.rs` started at the cell's interior point
//!   (O(m) per iteration, a handful of iterations in 2-3 variables). When the Hessian is singular (`w = 1` leaves z
//!   free, `w = 0` leaves x and y free) the minimiser set is not a point; the solver returns its lexicographic
//!   minimum: lowest z, then lowest y, then lowest x (lowest y then x in 2-D). Before returning, the KKT conditions
//!   are verified from scratch (see [`crate::verify_kkt`]); a failed check is an error, never a silent wrong answer.
//!   Strictly convex costs (every `h_i > 0` within a factor 1000 of each other: cost (1) with
//!   `0.002 <= w <= 0.9995`, the desired-position cost) run the same
//!   iteration with closed-form linear algebra (`closed_form.rs`, "strictly convex fast path"); if that path
//!   breaks down or its answer fails the KKT check, the general method solves the problem again. The minimiser is
//!   unique there, so both give the same point up to rounding in the last bits; [`minimize_general`] runs the
//!   general method alone (the reference of the tests and benchmarks).
//! * [`minimize_clarabel`]: clarabel's interior-point QP (general path and cross-check; statuses other than
//!   `Solved` are errors). Its point is some minimiser (no tie-break); its `active` list is the tight inequalities.
//!
//! The answer and its errors are in [`crate::solution`], the KKT check in `kkt.rs`, the enumeration that
//! solves degenerate cells in `enumerate.rs`, clarabel's call in `clarabel.rs`.

use crate::active_set::{Outcome, Problem, default_tie};
use crate::cell::Cell;
use crate::clarabel::clarabel_qp;
use crate::cost::SeparableCost;
use crate::enumerate::minimize_enumerated;
use crate::kkt::verify_kkt_dual;
use crate::linalg::{MAX_N, from_v4, to_v4};
use crate::outer_box::grown_without_near_duplicates;
use crate::solution::{QpError, QpSolution, ShortList, tight_set, tight_set_within};

/// An active-set problem, its start point and the cost's `h` and `g`.
type Prepared<'c, const D: usize> = (Problem<'c>, [f64; MAX_N], [f64; D], [f64; D]);

/// The active-set problem of `cost` over `cell` and its start (the cell's interior point), with the checked cost.
fn problem<'c, const D: usize>(cell: &'c Cell<D>, cost: &SeparableCost<D>) -> Result<Prepared<'c, D>, QpError> {
    let (h, g) = (cost.hessian_diagonal(), cost.linear());
    let start = cell.interior_point().ok_or(QpError::EmptyCell)?;
    let prob = Problem {
        n: D,
        rows: cell.rows(),
        offsets: cell.offsets(),
        mask: None,
        h: to_v4(&h),
        g: to_v4(&g),
        tie: default_tie(D),
        length_scale: cell.length_scale(),
    };
    Ok((prob, to_v4(&start), h, g))
}

/// Exact minimum of `cost` over `cell`: see the module documentation.
///
/// **Degenerate cells.** A cell can be non-empty only within its tolerance ([`CellShape::Flat`], or a
/// [`CellShape::Known`] cell that is: two obstacle faces nanometres apart with normals 1e-9 rad from opposite, as a
/// part fitting exactly between two others gives), or have a dozen planes through one vertex with normals 1e-16 to
/// 1e-9 apart (parts whose faces are a sliver out of line). The working set of two nearly opposite planes then gets
/// multipliers near 1e265 that fail the KKT check. When both paths fail, the problem is solved once more on the cell
/// with every offset grown by the tolerance (the cell on which emptiness is decided, [`Cell::is_empty_with`], where
/// the inequalities have a common point) and without its near-duplicate inequalities
/// ([`grown_without_near_duplicates`]; indices mapped back to this cell's), by the same method and, if that
/// fails too, by enumeration of its faces (at most 16 inequalities; the same lexicographic tie-break when the
/// Hessian is singular). The answer, KKT-verified on that cell,
/// lies within three times the tolerance of every original inequality (the search treats points within the tolerance
/// of an obstacle face as touching). An error remains an error: the retry's own when it fails too.
///
/// [`CellShape::Flat`]: crate::cell::CellShape::Flat
/// [`CellShape::Known`]: crate::cell::CellShape::Known
pub fn minimize<const D: usize>(cell: &Cell<D>, cost: &SeparableCost<D>) -> Result<QpSolution<D>, QpError> {
    match minimize_exact(cell, cost) {
        Err(e @ (QpError::Kkt { .. } | QpError::Solver(_))) => {
            let (reduced, index) = grown_without_near_duplicates(cell).map_err(|_| e.clone())?;
            tracing::debug!(error = %e, kept = reduced.len(), of = cell.len(), "QP failed on a cell; grown and reduced");
            let sol = match minimize_exact(&reduced, cost) {
                Ok(sol) => sol,
                Err(e2) => minimize_enumerated(&reduced, cost).ok_or(e2)?,
            };
            let active: Vec<usize> = sol.active.iter().map(|&j| index[j]).collect();
            let tight = tight_set_within(cell, &sol.point, 3.0 * cell.tolerance().linear);
            Ok(QpSolution { active: ShortList::from_slice(&active), tight, ..sol })
        }
        other => other,
    }
}

/// [`minimize`] without the retry on degenerate cells.
fn minimize_exact<const D: usize>(cell: &Cell<D>, cost: &SeparableCost<D>) -> Result<QpSolution<D>, QpError> {
    let (prob, start, h, g) = problem(cell, cost)?;
    // strictly convex costs: the closed-form range-space iteration; a result that fails the KKT check (or a
    // breakdown of that path) falls back to the general method, whose answer is the definition
    if let Some(outcome) = prob.solve_strictly_convex(start) {
        match solution(cell, cost, &h, &g, outcome) {
            Ok(sol) => return Ok(sol),
            Err(e) => tracing::debug!(error = %e, "strictly convex QP path rejected; general active-set method"),
        }
    }
    solution(cell, cost, &h, &g, prob.solve(start)?)
}

/// [`minimize`] by the general active-set method only (Gram-Schmidt null-space split, lexicographic multipliers),
/// without the closed-form path for strictly convex costs. Same answer as [`minimize`] up to rounding in the last
/// bits (the minimiser is unique when the fast path applies); the tests' reference for the fast path.
pub fn minimize_general<const D: usize>(cell: &Cell<D>, cost: &SeparableCost<D>) -> Result<QpSolution<D>, QpError> {
    let (prob, start, h, g) = problem(cell, cost)?;
    solution(cell, cost, &h, &g, prob.solve(start)?)
}

/// The solution of an outcome of the active-set solver, KKT-verified.
fn solution<const D: usize>(
    cell: &Cell<D>,
    cost: &SeparableCost<D>,
    h: &[f64; D],
    g: &[f64; D],
    outcome: Outcome,
) -> Result<QpSolution<D>, QpError> {
    match outcome {
        Outcome::Optimal { point, working, multipliers, iterations } => {
            let p: [f64; D] = from_v4(&point);
            let k = working.as_slice().len();
            let mut pairs = [(0usize, 0.0f64); MAX_N];
            for (a, &j) in working.as_slice().iter().enumerate() {
                pairs[a] = (j, multipliers[a]);
            }
            let pairs = &mut pairs[..k];
            pairs.sort_unstable_by_key(|x| x.0);
            let mut active = [0usize; MAX_N];
            let mut lambda = [0.0f64; MAX_N];
            for (a, &(j, l)) in pairs.iter().enumerate() {
                active[a] = j;
                lambda[a] = l;
            }
            // one pass over the inequalities: primal feasibility and the tight set
            let tol = cell.tolerance().linear;
            let mut worst = f64::NEG_INFINITY;
            let mut tight = Vec::new();
            for (j, hs) in cell.halfspaces().iter().enumerate() {
                let e = hs.excess(&p);
                worst = worst.max(e);
                if e.abs() <= tol {
                    tight.push(j);
                }
            }
            let sol = QpSolution {
                point: p,
                cost: cost.evaluate(&p),
                active: ShortList::from_slice(&active[..k]),
                multipliers: ShortList::from_slice(&lambda[..k]),
                tight,
                iterations,
            };
            if worst > tol {
                return Err(QpError::Kkt { what: "primal feasibility", value: worst, allowed: tol });
            }
            verify_kkt_dual(cell, h, g, &sol)?;
            Ok(sol)
        }
        Outcome::Unbounded { stage, .. } => {
            tracing::debug!(stage, "QP unbounded (stage 0: the cost, k > 0: the k-th tie-break coordinate)");
            Err(QpError::Unbounded)
        }
    }
}

/// Minimum of `cost` over `cell` by clarabel (interior point). The general path and the tests' cross-check.
pub fn minimize_clarabel<const D: usize>(cell: &Cell<D>, cost: &SeparableCost<D>) -> Result<QpSolution<D>, QpError> {
    let (h, g) = (cost.hessian_diagonal(), cost.linear());
    if cell.is_empty() {
        return Err(QpError::EmptyCell);
    }
    let x = clarabel_qp::<D>(&h, &g, cell.rows(), cell.offsets()).map_err(QpError::Clarabel)?;
    let mut p = [0.0; D];
    p.copy_from_slice(&x[..D]);
    let tight = tight_set(cell, &p);
    Ok(QpSolution {
        point: p,
        cost: cost.evaluate(&p),
        active: ShortList::from_slice(&tight),
        multipliers: ShortList::default(),
        tight,
        iterations: 0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::CellShape;
    use crate::cost::SeparableCost;
    use crate::halfspace::{Halfspace, Tag};
    use crate::kkt::verify_kkt;
    use stackplan_geom::Tolerance;

    fn unit_cube() -> Cell<3> {
        let mut hs = Vec::new();
        for i in 0..3 {
            let mut n = [0.0; 3];
            n[i] = 1.0;
            hs.push(Halfspace::new(n, 1.0, Tag::User(2 * i as u64)));
            n[i] = -1.0;
            hs.push(Halfspace::new(n, 0.0, Tag::User(2 * i as u64 + 1)));
        }
        Cell::new(hs, Tolerance::for_scale(1.0)).expect("cube")
    }

    #[test]
    fn golden_corner_and_clarabel_agree() {
        let c = unit_cube();
        let f = SeparableCost::new([2.0, 4.0, 6.0], [-6.0, 2.0, -3.0], 1.0).expect("cost");
        // unconstrained optimum (3, -0.5, 0.5) -> clamp to (1, 0, 0.5)
        let s = minimize(&c, &f).expect("exact");
        assert!((s.point[0] - 1.0).abs() < 1e-14 && s.point[1].abs() < 1e-14 && (s.point[2] - 0.5).abs() < 1e-14);
        assert_eq!(s.active, vec![0, 3]);
        assert!((s.multipliers[0] - 4.0).abs() < 1e-12 && (s.multipliers[1] - 2.0).abs() < 1e-12);
        let k = minimize_clarabel(&c, &f).expect("clarabel");
        assert!((k.cost - s.cost).abs() < 1e-8);
    }

    /// A 3-variable, 9-row cell (from a 4096-case run, seed 2718) on which clarabel with its equilibration stalls at a
    /// relative gap of 0.47 for 200 iterations; the retry without it solves, and agrees with the exact solver.
    #[test]
    fn clarabel_solves_the_small_qp_its_equilibration_stalls_on() {
        let h = [2.0, 2.0, 2.0];
        let g = [-0.4672644918784834, 22.806429424430554, 4.373286125626196];
        let normals = [
            [-0.3620179775484921, 0.46771722401751636, 0.8063396196944858],
            [0.07630716357185668, -0.8013886602896434, 0.5932566324507368],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, -1.0],
            [-1.0, 0.0, 0.0],
            [-0.7252681058982173, 0.6875362426856121, -0.03577833926502584],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
        ];
        let offsets = [
            2.6809105485185585,
            2.135827676705782,
            3.7637033111125273,
            3.769647071525684,
            -0.29754214747753416,
            2.416069221940545,
            3.2136131084002786,
            5.55764497470787,
            7.055580836009968,
        ];
        let rows: Vec<[f64; MAX_N]> =
            normals.iter().map(|n| std::array::from_fn(|i| n.get(i).copied().unwrap_or(0.0))).collect();
        let x = clarabel_qp::<3>(&h, &g, &rows, &offsets).expect("clarabel");
        let hs = normals.iter().zip(offsets).enumerate().map(|(k, (n, d))| Halfspace::new(*n, d, Tag::User(k as u64)));
        let cell = Cell::new(hs.collect(), Tolerance::for_scale(10.0)).expect("cell");
        let exact = minimize(&cell, &SeparableCost::new(h, g, 0.0).expect("cost")).expect("exact");
        for i in 0..3 {
            assert!((x[i] - exact.point[i]).abs() < 1e-7, "clarabel {x:?} vs exact {:?}", exact.point);
        }
    }

    /// A wedge-shaped cell (found by `planner/tests/plans_vs_parry.rs`: an L of two boxes whose outer faces are
    /// 3.5e-6 mm apart, so the pair's c-space obstacle has two faces 2.5e-7 rad from parallel): the optimum is the
    /// wedge's apex, held by both nearly parallel planes with multipliers near 1e8, whose rounding leaves a
    /// stationarity residual of about 1e-2 (relative 1e-10 of the terms summed).
    fn wedge_cell() -> (Cell<3>, SeparableCost<3>) {
        let wedge: [([f64; 3], f64); 13] = [
            ([0.0, -1.0, 0.0], 49.10412399076219),
            ([1.0, -0.0, 0.0], 61.380151866013556),
            ([0.0, 1.0, 0.0], 26.471365294545485),
            ([-1.0, -0.0, 0.0], 34.715136346825965),
            ([0.0, 0.0, -1.0], -12.60650595661997),
            ([0.0, 0.0, 1.0], 150.0),
            ([6.123233995736766e-17, -1.0, -3.749399456654644e-33], 33.94913804432505),
            ([-6.123233995736766e-17, 1.0, 3.749399456654644e-33], 11.316379348108352),
            ([-1.0, -6.123233995736766e-17, 6.123233995736766e-17], 0.7260130911520407),
            ([1.0, 6.123233995736766e-17, -6.123233995736766e-17], 25.939008672913427),
            ([6.123233995736766e-17, 0.0, 1.0], 25.213008790802007),
            ([-0.9999999999999694, 6.123233995736766e-17, -2.4768480339515496e-7], 0.7260099687129289),
            ([-0.9999999999999694, 6.123233995736766e-17, -2.4768480339515496e-7], -25.93901179535345),
        ];
        let hs = wedge.iter().enumerate().map(|(k, (n, d))| Halfspace::new(*n, *d, Tag::User(k as u64))).collect();
        let cell = Cell::new(hs, Tolerance::for_scale(37.1778011596673)).expect("cell");
        let (h, c) = (
            [1.2173464143156723, 1.2173464143156723, 1.5653071713686555],
            [13.332507759593794, -11.316379348108352, 6.303253801426855],
        );
        let cost =
            SeparableCost::new(std::array::from_fn(|i| 2.0 * h[i]), std::array::from_fn(|i| -2.0 * h[i] * c[i]), 0.0)
                .expect("cost");
        (cell, cost)
    }

    #[test]
    fn the_apex_of_a_thin_wedge_passes_the_kkt_check() {
        let (cell, cost) = wedge_cell();
        let k = minimize_clarabel(&cell, &cost).expect("clarabel");
        for s in [minimize(&cell, &cost).expect("exact"), minimize_general(&cell, &cost).expect("general")] {
            // the apex of the wedge (z = 12.6065094..., 3.5e-6 above the floor, x at the face x <= 25.939...);
            // clarabel stops on the floor, within the tolerance of the walls (1e-7 rad apart, the tolerance
            // reaches 0.15 mm along the wedge), at a cost below the apex's by rounding
            assert!((s.point[0] - 25.939008672913427).abs() < 1e-9 && (s.point[2] - 12.6065094454).abs() < 1e-8);
            assert!((s.point[2] - k.point[2]).abs() < 1e-5, "exact {:?} vs clarabel {:?}", s.point, k.point);
            assert!(k.cost <= s.cost + 1e-9 * s.cost.abs() && s.cost - k.cost < 1e-3, "{} vs {}", s.cost, k.cost);
            verify_kkt(&cell, &cost, &s).expect("the solver's answer passes the check");
            // held by the two walls alone, with multipliers about |grad f| / 2.5e-7
            assert_eq!(s.active, vec![9, 12]);
            assert!(s.multipliers.iter().all(|&l| l > 1e7), "{:?}", s.multipliers);
        }
        // a wrong working set still fails: the wall x <= 25.939 alone leaves the gradient in z unbalanced
        let exact = minimize(&cell, &cost).expect("exact");
        let floor_only = QpSolution {
            active: ShortList::from_slice(&[9]),
            multipliers: ShortList::from_slice(&[30.69]),
            ..exact.clone()
        };
        assert!(matches!(verify_kkt(&cell, &cost, &floor_only), Err(QpError::Kkt { what: "stationarity", .. })));
        // and so do huge multipliers that do not balance the gradient
        let unbalanced = QpSolution { multipliers: ShortList::from_slice(&[8.0e7, 8.1e7]), ..exact };
        assert!(matches!(verify_kkt(&cell, &cost, &unbalanced), Err(QpError::Kkt { what: "stationarity", .. })));
    }

    /// A cell thinner than the tolerance (found by `planner/tests/plans_vs_parry.rs`, an L whose outer faces are
    /// 1e-7 mm out of line, `w = 0`): its lower and upper planes, 1e-8 rad from opposite, have no exact common point
    /// (9e-9 mm apart), the working set gets multipliers near 1e265 and clarabel ends in a numerical error; the
    /// retry on the tolerance-grown cell (without its near-duplicates) solves it.
    #[test]
    fn a_cell_thinner_than_the_tolerance_is_solved_on_the_grown_cell() {
        let flat: [([f64; 3], f64); 11] = [
            ([1.0, -0.0, 0.0], -33.59283991765285),
            ([0.0, 1.0, 0.0], 19.159859157251127),
            ([-1.0, -0.0, 0.0], 34.36539536814442),
            ([0.0, 0.0, -1.0], -17.814320164694255),
            ([0.0, 0.0, 1.0], 149.9999998719327),
            ([1.0, -0.0, 0.0], -33.59283991765285),
            ([-0.0, -1.0, -0.0], -1.1065727715007512),
            ([6.123233995736766e-17, 0.0, 1.0], 35.62864042938851),
            ([-2.8067307673313902e-9, 4.861400292184758e-9, 1.0], 35.628640600797546),
            ([-1.1226923390950122e-8, 0.0, 1.0], 35.62864089073468),
            ([0.0, -6.481867241936348e-9, -1.0], -35.628640562661346),
        ];
        let hs = flat.iter().enumerate().map(|(k, (n, d))| Halfspace::new(*n, *d, Tag::User(k as u64))).collect();
        let cell = Cell::new(hs, Tolerance { linear: 3.411399075099622e-8 }).expect("cell");
        assert!(matches!(cell.shape(), CellShape::Flat { .. }), "{:?}", cell.shape());
        let (h, c) = ([0.0, 0.0, 4.0], [2.113722224754235, 14.392212099388535, 8.9071600292715]);
        let cost =
            SeparableCost::new(std::array::from_fn(|i| 2.0 * h[i]), std::array::from_fn(|i| -2.0 * h[i] * c[i]), 0.0)
                .expect("cost");
        // the exact problem alone fails its check
        assert!(matches!(minimize_exact(&cell, &cost), Err(QpError::Kkt { .. })));
        let s = minimize(&cell, &cost).expect("solved on the grown cell");
        let tol = cell.tolerance().linear;
        for hs in cell.halfspaces() {
            assert!(hs.excess(&s.point) <= 3.0 * tol, "{:?} violated by {}", hs, hs.excess(&s.point));
        }
        // verified on the grown, reduced cell: the lowest z there (the cost depends on z alone)
        let (reduced, index) = grown_without_near_duplicates(&cell).expect("reduced");
        let local: Vec<usize> = s.active.iter().map(|j| index.iter().position(|k| k == j).expect("kept")).collect();
        verify_kkt(&reduced, &cost, &QpSolution { active: ShortList::from_slice(&local), ..s.clone() })
            .expect("KKT on the reduced cell");
        let lowest =
            cell.grown_by_tolerance().expect("grown").support(&[0.0, 0.0, -1.0]).expect("LP").expect("bounded");
        assert!((-lowest.0 - s.point[2]).abs() <= 2.0 * tol, "z {} against the lowest {}", s.point[2], -lowest.0);
    }

    /// A cell of 36 inequalities (found by `planner/tests/plans_vs_parry.rs`, nearly flush L-shapes, seed 7): a dozen
    /// planes through one vertex with normals 1e-16 to 1e-9 apart, and a slab in y 7e-8 mm thick whose two sides are
    /// 5e-9 rad from opposite, so that the cost's optimum is the slab's apex 13.6 mm below the top. The active-set
    /// method fails on the cell, on the grown cell and on the grown cell without near-duplicates (infinite
    /// multipliers), clarabel ends `AlmostSolved`; the enumeration of the reduced cell's faces finds the apex.
    #[test]
    fn a_degenerate_vertex_of_near_duplicate_planes_is_solved_by_enumeration() {
        let planes: Vec<([f64; 3], f64)> = vec![
            ([0.0, -1.0, 0.0], 40.0),
            ([1.0, -0.0, 0.0], 32.09504830609204),
            ([0.0, 1.0, 0.0], 26.76907301780147),
            ([-1.0, -0.0, 0.0], 50.0),
            ([0.0, 0.0, -1.0], -3.156767494607399e-7),
            ([0.0, 0.0, 1.0], 123.97440751504803),
            ([1.9842073519859255e-16, 1.0, -3.2714562742152126e-18], 7.211700682241288),
            ([1.0, 0.0, 1.7991069155934705e-23], -4.874683606837523),
            ([1.0, -1.1398412570493276e-16, 1.7991069206553913e-23], -4.874683606837524),
            ([1.0, -2.664299418895067e-16, 4.2052869148118717e-23], -4.874683606837522),
            ([-1.9842073533816014e-16, -1.0, 0.0], 22.183402829152506),
            ([-1.9842073505902486e-16, -0.9999999999999999, 1.5085360748639663e-8], 22.18340280289229),
            ([0.0, -1.0, 4.314610695227751e-17], 22.183402829152506),
            ([1.813426340845264e-7, 1.813426317201695e-7, 0.9999999999999671], 26.025591140774367),
            ([1.813426344474069e-7, -2.7175933290703456e-23, 0.9999999999999836], 26.025591916640323),
            ([1.0, -1.8163162403408531e-16, 7.316919560315212e-10], -4.874683587794807),
            ([1.0, 0.0, 7.316919604908517e-10], -4.874683587794808),
            ([-3.5462053374404384e-16, 0.0, 1.0], 26.025593116305476),
            ([3.288515003507369e-14, -0.9999999999999836, 1.8134263015603024e-7], 22.18340723302469),
            ([1.8134263079991472e-7, -2.717593329070343e-23, 0.9999999999999836], 26.025591916640344),
            ([-0.7071067807183419, -0.7071067816547416, 1.282286055605642e-7], 33.02458620080326),
            ([-1.984207351985925e-16, -1.0, 0.0], 22.183402829152506),
            ([0.0, -0.9999999999999836, 1.8134263079991477e-7], 22.183407233024916),
            ([-1.9842067041846145e-16, -0.9999999999999836, 1.8134263079991477e-7], 22.183407233024916),
            ([-0.9999999999999836, 4.87939979082215e-16, 1.813426317444236e-7], 24.520415185006932),
            ([-0.7071067813298919, -0.7071067810431917, 1.2822860333858611e-7], 33.024586202232435),
            ([-0.9999999999999837, 0.0, 1.8134263160791512e-7], 24.520415185006936),
            ([-1.0, -3.331825836640595e-22, 0.0], 24.520415185007224),
            ([5.526005053419141e-16, 1.8134263172017258e-7, 0.9999999999999836], 26.02559234043951),
            ([-0.9999999999999836, 3.293138405461407e-14, 1.813426317444236e-7], 24.520415185006794),
            ([-1.0, 7.104798450386838e-16, -1.1214098407946668e-22], 24.52041518500722),
            ([-1.0, 8.468129764666714e-16, -1.1214098376395024e-22], 24.520415185007224),
            ([-0.9999999999999837, 3.345541937886465e-14, 1.813426316079151e-7], 24.520415185006794),
            ([0.0, 1.0, 0.0], 7.211700682241292),
            ([1.9842073519859255e-16, 1.0, 0.0], 7.211700682241288),
            ([-1.9842073519859255e-16, -1.0, -5.028453565195011e-9], -7.211700813109764),
        ];
        let hs = planes.iter().enumerate().map(|(k, (n, d))| Halfspace::new(*n, *d, Tag::User(k as u64))).collect();
        let cell = Cell::new(hs, Tolerance { linear: 3.4248739828041275e-8 }).expect("cell");
        let (h, c) = (
            [1.148418868072217, 1.148418868072217, 1.7031622638555661],
            [-8.952475846953979, -6.615463491099263, -9.293874636785603],
        );
        let cost =
            SeparableCost::new(std::array::from_fn(|i| 2.0 * h[i]), std::array::from_fn(|i| -2.0 * h[i] * c[i]), 0.0)
                .expect("cost");
        assert!(minimize_exact(&cell, &cost).is_err());
        let (reduced, index) = grown_without_near_duplicates(&cell).expect("reduced");
        assert_eq!(reduced.len(), 11);
        assert!(minimize_exact(&reduced, &cost).is_err());
        let enumerated = minimize_enumerated(&reduced, &cost).expect("enumerated");
        verify_kkt(&reduced, &cost, &enumerated).expect("KKT on the reduced cell, multipliers near 1.5e10");
        let s = minimize(&cell, &cost).expect("solved");
        assert_eq!(s.point, enumerated.point);
        assert_eq!(
            s.active.iter().copied().collect::<Vec<_>>(),
            enumerated.active.iter().map(|&j| index[j]).collect::<Vec<_>>()
        );
        let tol = cell.tolerance().linear;
        for hs in cell.halfspaces() {
            assert!(hs.excess(&s.point) <= 3.0 * tol, "{hs:?} violated by {}", hs.excess(&s.point));
        }
        // the apex: the upper y side and the tilted lower one meet at z = 12.4036..., x at the cost's centre
        assert!((s.point[2] - 12.40361385829693).abs() < 1e-6 && (s.point[0] - c[0]).abs() < 1e-9, "{:?}", s.point);
        // cheaper than the points where the active set and clarabel stop on this cell (on its top, z = 26.03)
        let top = [c[0], 7.211700647994338, 26.025579816179977];
        assert!(s.cost < cost.evaluate(&top));
    }

    /// A random cell of `D` variables for [`enumeration_matches_the_active_set_method_and_its_tie_break`]: a box with
    /// sides 1-10 from the origin and up to 16 - 2D more planes, each at a distance 0.2-3 from a point `c` inside
    /// the box (so the cell holds `c`); a third of the normals are taken from a few axis-aligned and diagonal
    /// directions, so that faces parallel to the box's or to each other (ties, sheet metal's normal case) are common.
    fn random_cell<const D: usize>(next: &mut impl FnMut() -> f64) -> Cell<D> {
        let mut hs = Vec::new();
        let mut centre = [0.0; D];
        for i in 0..D {
            let (lo, hi) = (1.0 + 9.0 * next(), 1.0 + 9.0 * next());
            centre[i] = (hi - lo) * (next() - 0.5) * 0.8;
            let mut n = [0.0; D];
            n[i] = 1.0;
            hs.push(Halfspace::new(n, hi, Tag::User(hs.len() as u64)));
            n[i] = -1.0;
            hs.push(Halfspace::new(n, lo, Tag::User(hs.len() as u64)));
        }
        for _ in 0..(next() * (16 - 2 * D + 1) as f64) as usize {
            let mut n: [f64; D] = std::array::from_fn(|_| next() - 0.5);
            if next() < 1.0 / 3.0 {
                n = std::array::from_fn(|_| [0.0, 1.0, -1.0][(next() * 3.0) as usize]);
            }
            let length = n.iter().map(|x| x * x).sum::<f64>().sqrt();
            if length < 1e-3 {
                continue;
            }
            let n = n.map(|x| x / length);
            let offset = (0..D).map(|i| n[i] * centre[i]).sum::<f64>() + 0.2 + 2.8 * next();
            hs.push(Halfspace::new(n, offset, Tag::User(hs.len() as u64)));
        }
        Cell::new(hs, Tolerance::for_scale(20.0)).expect("a bounded cell holding its centre")
    }

    /// A random convex separable cost for [`enumeration_matches_the_active_set_method_and_its_tie_break`]: kind 0
    /// leaves the last variable free (cost (1) at `w = 1`), kind 1 the others (`w = 0`), kind 2 is linear (every
    /// `h_i = 0`), kind 3 curves one variable only, kind 4 is strictly convex.
    fn random_cost<const D: usize>(kind: usize, next: &mut impl FnMut() -> f64) -> SeparableCost<D> {
        let curved: [bool; D] = std::array::from_fn(|i| match kind {
            0 => i + 1 < D,
            1 => i + 1 == D,
            2 => false,
            3 => i == 0,
            _ => true,
        });
        let h: [f64; D] = std::array::from_fn(|i| if curved[i] { 0.5 + 4.0 * next() } else { 0.0 });
        // a centre inside or outside the cell, the cost flat along the other variables (as cost (1)); the linear
        // cost along one axis, either way
        let axis = (next() * D as f64) as usize;
        let sign = if next() < 0.5 { -1.0 } else { 1.0 };
        let g: [f64; D] = std::array::from_fn(|i| match kind {
            2 if i == axis => sign,
            _ if curved[i] => -h[i] * 24.0 * (next() - 0.5),
            _ => 0.0,
        });
        SeparableCost::new(h, g, 0.0).expect("cost")
    }

    /// The enumeration (the last resort of [`minimize`]) against the general active-set method, whose lexicographic
    /// tie-break defines the answer when the Hessian is singular, on 1 400 random cells and costs of 2 and 3
    /// variables, four fifths of them with a singular Hessian: the same cost and the same point. (Before the
    /// tie-break the enumeration returned no answer for a singular cost; taking the first cheapest candidate instead
    /// disagrees with the active-set method on 446 of the 960 singular problems of the first two samples.) A 78 000-case run (seeds 1-39 of
    /// two samples, release) passes; it found the case pinned at the end, which ties decided by cost values missed.
    #[test]
    fn enumeration_matches_the_active_set_method_and_its_tie_break() {
        fn check<const D: usize>(seed: u64, cases: usize) -> (usize, usize) {
            let mut state = seed;
            let mut next = move || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64
            };
            let (mut compared, mut singular) = (0, 0);
            for case in 0..cases {
                let cell = random_cell::<D>(&mut next);
                let kind = case % 5;
                let cost = random_cost::<D>(kind, &mut next);
                let Ok(general) = minimize_general(&cell, &cost) else { continue };
                let enumerated = minimize_enumerated(&cell, &cost).expect("a bounded non-empty cell has a minimum");
                let scale = cell.length_scale();
                assert!(
                    (enumerated.cost - general.cost).abs() <= 1e-9 * (1.0 + general.cost.abs()),
                    "case {case} (kind {kind}): cost {} by enumeration, {} by the active set",
                    enumerated.cost,
                    general.cost
                );
                for i in 0..D {
                    assert!(
                        (enumerated.point[i] - general.point[i]).abs() <= 1e-7 * scale,
                        "case {case} (kind {kind}): {:?} by enumeration, {:?} by the active set",
                        enumerated.point,
                        general.point
                    );
                }
                compared += 1;
                singular += usize::from(kind < 4);
            }
            (compared, singular)
        }
        let (compared, singular) = check::<3>(0x2030_5eed, 800);
        assert!(compared >= 780 && singular >= 620, "{compared} compared, {singular} singular");
        let (compared, singular) = check::<2>(0x2030_2d2d, 400);
        assert!(compared >= 390 && singular >= 310, "{compared} compared, {singular} singular");
        // case 176 of this sample: z curved, x and y free, the cost's centre 1e-5 inside the cell's lowest z; tied by
        // cost values within 2e-9, the lowest z 2e-5 below the minimiser was taken, and x and y followed it
        let (compared, _) = check::<3>(0x9e37_79b9_7f4a_7c15 ^ 35, 200);
        assert!(compared >= 195, "{compared} compared");
    }

    #[test]
    fn short_lists_read_as_slices_inline_or_spilled() {
        let short = ShortList::from_slice(&[3usize, 5, 6]);
        assert_eq!(short, vec![3, 5, 6]);
        assert_eq!(short, [3, 5, 6]);
        assert_eq!(short.len(), 3);
        assert_eq!((&short).into_iter().copied().sum::<usize>(), 14);
        assert_eq!(format!("{short:?}"), "[3, 5, 6]");
        let long = ShortList::from_slice(&[1usize, 2, 3, 4, 5, 6]);
        assert_eq!(long, vec![1, 2, 3, 4, 5, 6]);
        assert_ne!(long, short);
        assert_eq!(ShortList::from_slice(&long[..3]), ShortList::from_slice(&[1, 2, 3]));
        let empty = ShortList::<f64>::default();
        assert!(empty.is_empty() && empty == Vec::<f64>::new());
    }

    #[test]
    fn rejects_bad_costs_and_empty_cells() {
        let c = unit_cube();
        let bad = SeparableCost::new([1.0; 3], [0.0; 3], 0.0).expect("ok");
        assert!(minimize(&c, &bad).is_ok());
        let empty = c.with_halfspaces([Halfspace::new([1.0, 0.0, 0.0], -1.0, Tag::User(7))]).expect("cell");
        assert_eq!(minimize(&empty, &bad), Err(QpError::EmptyCell));
        assert_eq!(minimize_clarabel(&empty, &bad), Err(QpError::EmptyCell));
    }
}
