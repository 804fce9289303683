//! Robustness margins with fewer and smaller SOCPs (`docs/algorithms.md`, "Stability, grasp and insertion"; the margin
//! of [`super`]). The reference is one SOCP per group and load direction (`EquilibriumOptions::margins_by_socp_only`);
//! everything here returns the same margin up to the solver's tolerance, by the following exact arguments.
//!
//! 1. **Support trees.** Contract the fixed bodies (floor, fixed parts) of a group to one node, the ground. When the
//!    graph "movable parts and ground, joined when they share a contact point" is a tree (a column of parts each
//!    resting on the one below, a part alone on its supports), the group's equations split into one problem per tree
//!    edge. For the edge between part `v` and its parent (towards the ground), let `S` be the parts of `v`'s subtree:
//!    summing the force and moment equations of the parts of `S` cancels every contact force inside `S` and leaves
//!    "the forces of the edge's contact points, acting on `S`, balance the gravity and load of `S`", the equations of
//!    one rigid body (the union of `S`: total mass, mass-weighted c.g. — the load `alpha m_i d` is proportional to the
//!    mass like gravity, so its resultant acts at the union's c.g.). The map from the per-part equations to the
//!    per-subtree sums is triangular and invertible (a part's equations are its subtree's minus its children's), and
//!    every contact point belongs to exactly one edge, so the group resists the load `alpha d` iff every edge problem
//!    does: `alpha_group(d) = min_edges alpha_edge(d)`. Graphs with a cycle (a brick on two bricks on the floor) keep
//!    one problem for the whole group.
//! 2. **Closed form** for an edge whose points are all supports from below in one horizontal plane: `min(mu, s / H)`
//!    for the union of `S` ([`super::FlatSupport`]).
//! 3. **Fewer points.** Contact points acting on the same body pair with the same normal (hence the same friction
//!    cone) in the same plane: a force `f` at a point `p = sum l_j q_j` (convex combination of other such points
//!    `q_j`) is the same wrench as the forces `l_j f` at the `q_j` (each in the cone, `sum l_j f = f`,
//!    `sum q_j x l_j f = p x f`), so only the vertices of the points' planar convex hull are kept: the feasible wrench
//!    set and hence every margin are unchanged. Points count as coplanar within the length tolerance `tol` of the
//!    flat-support test (1e-9 x the body's box diagonal), which moves moment arms by at most `tol`. The forces of the
//!    equilibrium solve are not affected (it keeps every point).
//! 4. **Triangle certificate.** The set `L` of horizontal loads `u = alpha d` a problem resists is convex and contains
//!    0. The stack's margin is the smallest value over all problems and directions, so a problem only matters where it
//!    is below `m`, the smallest closed-form value (or [`MARGIN_CAP`] when there is none). When the three largest
//!    loads along 0, 120 and 240 degrees (solved up to a little more than twice the cap) span a triangle whose inscribed distance from
//!    the origin is at least `m`, the disc of radius `m` lies in `L`: the problem resists `m` in every direction and
//!    needs no further solve (its value is `MARGIN_CAP` when `m` is the cap). Typical for nested parts, which are
//!    locked. Otherwise the other directions are solved one by one (the 0-degree solve is reused).
//!
//! 5. **Parallel forces** for a group without a support tree (a brick wall) whose contacts with the fixed bodies push
//!    straight up from one plane: summing all its equations gives the group as one rigid union on those contacts, a
//!    relaxation, so `alpha(d) <= U(d) = min(mu, s / H)` of the union. At `alpha = U(d)` take every force at a
//!    contact with a vertical normal parallel to the tilted gravity `z - alpha d` (on the upper body; friction
//!    `alpha <= mu` times the normal force: inside the cone) and none at the others: the group is in equilibrium iff
//!    every part's forces sum to its weight along that direction with the resultant through its c.g. (3 rows per
//!    part, linear in the magnitudes). In every direction where the least-squares magnitudes are nonnegative, the
//!    margin is exactly `U(d)` without an SOCP; the other directions are solved.
//!
//! The SOCPs of this module bound `alpha` by a little more than twice [`MARGIN_CAP`] and clamp the answer to the cap afterwards (the
//! feasible `alpha` form an interval, so clamping the larger problem's optimum gives the capped optimum). One solver
//! per problem is reused through `update_A` across its directions, as in the reference. Cost: per group a union-find
//! and a tree walk, O(K log K) for the point reduction; the SOCPs only for edges that are not flat, three of them for a
//! locked edge instead of one per direction.

use super::cache::{self, SolveCache};
use super::tree::{edge_point, support_tree};
use super::{EquilibriumError, FlatSupport, Group, MARGIN_CAP, Point, Problem, Rigid};
use crate::contacts::plane_basis;
use crate::polygon2d::convex_hull_2d;
use clarabel::solver::SolverStatus;
use glam::{DVec2, DVec3};
use rayon::prelude::*;

/// Bound of `alpha` in the margin SOCPs of this module: the triangle certificate needs loads of twice the cap, and a
/// little more so that a solver's answer at the bound (accurate to about 1e-8) still certifies the cap.
const SOCP_CAP: f64 = 2.0 * MARGIN_CAP * (1.0 + 1e-6);

/// Relative slack of the triangle certificate (the solver's answers are accurate to about 1e-8).
const CERTIFICATE_SLACK: f64 = 1e-9;

/// One margin problem: a rigid body (the union of a subtree, or a whole group when its support graph has a cycle)
/// on fixed supports, or a group solved as it is.
struct Unit {
    /// The rigid bodies of the problem and its movable ones.
    bodies: Vec<Rigid>,
    movers: Vec<usize>,
    /// Its contact points (reduced).
    points: Vec<Point>,
}

/// The margin (smallest over the directions of the largest resisted load factor) and the weakest direction of the
/// groups, `None` when a margin solve does not end `Solved` (see the module documentation).
pub(super) fn fast_margins(
    bodies: &[Rigid],
    points: &[Point],
    groups: &[Group],
    directions: usize,
    mu: f64,
    cache: &SolveCache,
) -> Result<(Option<f64>, Option<DVec3>), EquilibriumError> {
    let direction = |j: usize| {
        let angle = std::f64::consts::TAU * j as f64 / directions as f64;
        DVec3::new(angle.cos(), angle.sin(), 0.0)
    };
    let units: Vec<Unit> = groups.iter().flat_map(|g| units_of(bodies, points, g)).collect();
    // closed forms first: they give m
    let mut closed: Vec<Vec<f64>> = Vec::new();
    let mut socp: Vec<&Unit> = Vec::new();
    for unit in &units {
        let refs: Vec<&Point> = unit.points.iter().collect();
        match FlatSupport::of(&unit.bodies, &unit.movers, &refs) {
            Some(flat) => closed.push((0..directions).map(|j| flat.margin(direction(j), mu)).collect()),
            None => socp.push(unit),
        }
    }
    let m = closed.iter().flatten().fold(MARGIN_CAP, |a, &b| a.min(b));
    let solved: Vec<Vec<Option<f64>>> = socp
        .par_iter()
        .map(|unit| match tilted_bounds(unit, directions, mu) {
            Some(certified) => {
                // the directions the certificate did not decide, by their SOCPs
                let missing: Vec<usize> = (0..directions).filter(|&j| certified[j].is_none()).collect();
                let mut values: Vec<Option<f64>> = certified;
                if !missing.is_empty() {
                    let refs: Vec<&Point> = unit.points.iter().collect();
                    let problem = Problem::new(&unit.bodies, &unit.movers, &refs, mu);
                    let angles: Vec<f64> =
                        missing.iter().map(|&j| std::f64::consts::TAU * j as f64 / directions as f64).collect();
                    for (j, value) in missing.into_iter().zip(solve_sequence(&problem, &angles)?) {
                        values[j] = value.map(|a| a.min(MARGIN_CAP));
                    }
                }
                Ok(values)
            }
            None => unit_margins(unit, directions, mu, m, cache),
        })
        .collect::<Result<_, _>>()?;
    let mut smallest = f64::INFINITY;
    let mut weakest = None;
    for j in 0..directions {
        let mut alpha = f64::INFINITY;
        for values in &closed {
            alpha = alpha.min(values[j]);
        }
        for values in &solved {
            match values[j] {
                Some(a) => alpha = alpha.min(a),
                None => {
                    // a solve did not end `Solved`: the answer of the plain path (one SOCP per group and direction,
                    // bounded by the cap), which may succeed where this path's problem did not, or else says None
                    tracing::debug!("a margin solve did not end Solved; margins by the plain SOCPs");
                    let problems: Vec<Problem> =
                        groups.iter().map(|g| Problem::new(bodies, &g.movers, &g.points(points), mu)).collect();
                    return super::margins(&problems, directions);
                }
            }
        }
        if alpha < smallest {
            smallest = alpha;
            weakest = Some(direction(j));
        }
    }
    Ok((Some(smallest), weakest))
}

/// The margins of a group without a support tree whose contacts with the fixed bodies all push straight up from one
/// plane, per direction where the parallel-force certificate decides it (module documentation, item 5; `None` in the
/// other directions, which the caller solves as SOCPs); `None` when the certificate does not apply (one part, other
/// fixed contacts). Per direction `d`: the upper bound `U(d)` is the closed form of
/// the group as one rigid union on its fixed contacts (summing the group's equations is a relaxation); the group
/// resists `U(d)` when forces parallel to `z - U(d) d` at its horizontal contacts balance every part
/// ([`super::tree::parallel_certificate`]); then its margin is exactly `U(d)`.
fn tilted_bounds(unit: &Unit, directions: usize, mu: f64) -> Option<Vec<Option<f64>>> {
    if unit.movers.len() < 2 {
        return None;
    }
    let union = Rigid::union(unit.movers.iter().map(|&i| unit.bodies[i]));
    let is_mover = |b: Option<usize>| b.is_some_and(|b| unit.movers.binary_search(&b).is_ok());
    // the contacts with the fixed bodies, as forces on the union
    let ground: Vec<Point> = unit
        .points
        .iter()
        .filter(|p| !(is_mover(Some(p.b)) && is_mover(p.a)))
        .map(|p| super::tree::edge_point(p, is_mover(Some(p.b))))
        .collect();
    let refs: Vec<&Point> = ground.iter().collect();
    let flat = FlatSupport::of(&[union], &[0], &refs)?;
    let all: Vec<&Point> = unit.points.iter().collect();
    let mut out = Vec::with_capacity(directions);
    for j in 0..directions {
        let angle = std::f64::consts::TAU * j as f64 / directions as f64;
        let d = DVec3::new(angle.cos(), angle.sin(), 0.0);
        let bound = flat.margin(d, mu);
        let certified = bound <= mu
            && super::tree::parallel_certificate(&unit.bodies, &unit.movers, &all, DVec3::Z - d * bound).is_some();
        out.push(certified.then_some(bound));
    }
    Some(out)
}

/// The capped largest load factor of one SOCP unit per direction (`None`: the solve did not end `Solved`; infinity:
/// at least `m`, by the triangle certificate, with `m` below the cap). Three memoised stages, each a fresh solver
/// reused across its directions: the 0-degree load, the 120- and 240-degree loads (only when the certificate can
/// succeed), the other directions; each stage's answers depend only on the problem, not on `m`, so the stages are
/// shared between checks of the same rigid body with different bounds `m`.
fn unit_margins(
    unit: &Unit,
    directions: usize,
    mu: f64,
    m: f64,
    cache: &SolveCache,
) -> Result<Vec<Option<f64>>, EquilibriumError> {
    let problem = std::cell::OnceCell::new();
    let sequence = |stage: f64, angles: Vec<f64>| -> Result<Vec<Option<f64>>, EquilibriumError> {
        let run = || {
            let problem = problem.get_or_init(|| {
                let refs: Vec<&Point> = unit.points.iter().collect();
                Problem::new(&unit.bodies, &unit.movers, &refs, mu)
            });
            solve_sequence(problem, &angles)
        };
        match unit.bodies.as_slice() {
            [body] => cache.margin(cache::key(&[mu, stage, directions as f64], body, &unit.points), run),
            _ => run(),
        }
    };
    let first = sequence(0.0, vec![0.0])?[0];
    let third = std::f64::consts::TAU / 3.0;
    if directions > 3
        && let Some(a0) = first
        && a0 >= 2.0 * m * (1.0 - CERTIFICATE_SLACK)
        && let [Some(a1), Some(a2)] = sequence(1.0, vec![third, 2.0 * third])?[..]
    {
        let corners = [DVec2::new(a0, 0.0), DVec2::from_angle(third) * a1, DVec2::from_angle(2.0 * third) * a2];
        let inscribed = (0..3)
            .map(|k| {
                let (p, q) = (corners[k], corners[(k + 1) % 3]);
                p.perp_dot(q).abs() / (q - p).length()
            })
            .fold(f64::INFINITY, f64::min);
        if inscribed >= m * (1.0 - CERTIFICATE_SLACK) {
            let value = if m >= MARGIN_CAP { MARGIN_CAP } else { f64::INFINITY };
            return Ok(vec![Some(value); directions]);
        }
    }
    let angles = (1..directions).map(|j| std::f64::consts::TAU * j as f64 / directions as f64).collect();
    let rest = if directions > 1 { sequence(2.0, angles)? } else { Vec::new() };
    let out: Vec<Option<f64>> = std::iter::once(first).chain(rest).map(|a| a.map(|a| a.min(MARGIN_CAP))).collect();
    if out.iter().any(Option::is_none) {
        tracing::debug!("a margin solve did not end Solved");
    }
    Ok(out)
}

/// The largest load factors (bounded by [`SOCP_CAP`]) for horizontal loads at `angles`, by
/// [`Problem::solve_loads`] (one solver reused across the angles, retried where a solve does not end `Solved`);
/// `None` where no attempt ends `Solved`.
fn solve_sequence(problem: &Problem, angles: &[f64]) -> Result<Vec<Option<f64>>, EquilibriumError> {
    let loads: Vec<DVec3> = angles.iter().map(|&angle| DVec3::new(angle.cos(), angle.sin(), 0.0)).collect();
    let results = problem.solve_loads(&loads, SOCP_CAP)?;
    Ok(results.into_iter().map(|(status, alpha)| (status == SolverStatus::Solved).then_some(alpha)).collect())
}

/// The margin units of a group: one per edge of its support tree, or the group itself when the support graph is not
/// a tree (see the module documentation).
fn units_of(bodies: &[Rigid], points: &[Point], group: &Group) -> Vec<Unit> {
    match support_tree(bodies, points, group) {
        Some(edges) => edges
            .into_iter()
            .map(|edge| {
                let own = edge.points.iter().map(|&(k, holds_b)| edge_point(&points[k], holds_b)).collect();
                Unit { bodies: vec![edge.union], movers: vec![0], points: reduce_points(own, edge.union.tolerance()) }
            })
            .collect(),
        None => {
            let tol = Rigid::union(group.movers.iter().map(|&i| bodies[i])).tolerance();
            let own: Vec<Point> = group.point_indices.iter().map(|&k| points[k].clone()).collect();
            vec![Unit { bodies: bodies.to_vec(), movers: group.movers.clone(), points: reduce_points(own, tol) }]
        }
    }
}

/// Keeps, among the points acting on the same bodies with the same normal in the same plane (within `tol`), the
/// vertices of their planar convex hull (see the module documentation); the order of the kept points is preserved.
fn reduce_points(points: Vec<Point>, tol: f64) -> Vec<Point> {
    let same_normal = |a: DVec3, b: DVec3| (a - b).abs().max_element() <= 1e-12;
    // (fixed side, movable side, normal, plane offset, members)
    type Class = (Option<usize>, usize, DVec3, f64, Vec<usize>);
    let mut classes: Vec<Class> = Vec::new();
    for (k, pt) in points.iter().enumerate() {
        let n = pt.frame[0];
        let offset = n.dot(pt.p);
        match classes
            .iter_mut()
            .find(|(a, b, m, o, _)| *a == pt.a && *b == pt.b && same_normal(*m, n) && (offset - *o).abs() <= tol)
        {
            Some((_, _, _, _, list)) => list.push(k),
            None => classes.push((pt.a, pt.b, n, offset, vec![k])),
        }
    }
    let mut keep = vec![false; points.len()];
    for (_, _, n, _, list) in &classes {
        if list.len() <= 3 {
            list.iter().for_each(|&k| keep[k] = true);
            continue;
        }
        let (u, w) = plane_basis(*n);
        let flat: Vec<DVec2> = list.iter().map(|&k| DVec2::new(u.dot(points[k].p), w.dot(points[k].p))).collect();
        // tolerance 0: only points inside the hull or exactly on its edges are dropped
        for v in convex_hull_2d(&flat, 0.0) {
            if let Some(i) = flat.iter().position(|f| *f == v) {
                keep[list[i]] = true;
            }
        }
    }
    points.into_iter().zip(keep).filter_map(|(p, k)| k.then_some(p)).collect()
}
