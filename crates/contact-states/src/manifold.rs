//! Exact contact manifolds: projection of a configuration onto the set where a state's PCs hold, strict
//! verification of a state at a configuration, and extremal configurations by a compass search on the manifold
//! (\[P\] II-A, III; the projection and the strict check are ours, see the crate README "Exact feasibility").
//!
//! **Equalities.** Each PC holds on a smooth manifold given by signed lengths (the *intersection conditions* of
//! \[P\] eq. 1 with signs): f-v / v-f the height of the vertex over the face plane (1 equation); e-e the signed
//! distance between the carrier lines, `(b0 - a0).(da x db) / |da x db|` (1); f-e / e-f the heights of both end
//! points (2); f-f the heights of all vertices of the moving face over the fixed face's plane (rank 3). The bounding
//! conditions and non-penetration are inequalities, checked after the projection.
//!
//! **Projection** (Levenberg-Marquardt, K. Levenberg 1944, D. Marquardt 1963): minimise `|r(t)|^2` from `t0` in the
//! scaled variables `u = (x, y, z, L rx, L ry, L rz)` with a central-difference Jacobian `J` (6 columns) and steps
//! `(J^T J + mu I) du = -J^T r`, kept inside the box (variables at a bound whose step points outwards are frozen).
//! With small `mu` the step is the minimum-norm Gauss-Newton step, so the result is close to the nearest point of
//! the manifold; convergence is quadratic near a regular point. Converged when `max |r| <= 1e-11 L`.
//! Cost: about 13 residual evaluations (O(size of the state's elements)) per iteration, 3-6 iterations.
//!
//! **Strict verification** at `t`: inside the box; every PC's full criterion (with the bounding conditions,
//! [`crate::criteria`]) at most `hold`; the penetration term `L d_G` at most `hold`; and the PPCs in contact are
//! exactly the state: with Euclidean distances between the elements (point to planar face
//! `sqrt(height^2 + in-plane distance^2)`, segment to segment in 3-D), the PPCs at distance `<= hold` map to the state
//! by [`ContactState::canonical`], and no PPC lies in the ambiguous band `(hold, clear]`. `hold = 1e-7 L`,
//! `clear = 1e-5 L` by default. Cost O(number of reachable PPCs) distance evaluations.
//!
//! **Interior witness.** A GA witness of eq. 8 can sit where further contacts also hold (closure semantics). The
//! witness is projected; if the strict check fails, seeded random perturbations of growing size
//! (`1e-4 .. 0.1` of the box widths) are projected and checked until one passes.
//!
//! **Extremals** (\[P\] eq. 9-10 solved on the manifold): from a configuration of the state, a local search on `±t_k`
//! whose sweeps try (1) a *tangent move*: the objective's direction projected onto the tangent space of the state's
//! equalities and of the active inequalities it would violate (bounding terms and penetration at their boundary,
//! variables at a box bound), a step limited per variable, restored by the closure projection with `t_k` frozen, or
//! else by the plain closure projection (a gradient projection); (2) *compass moves* of one variable `t_j`, restored by
//! the projection with `t_j` frozen onto the equalities, the bounding terms and non-penetration (a move blocked by a
//! face boundary or another contact is restored by the other variables, e.g. a turn that lets a face slide further over
//! an edge); (3) when that sweep failed, *pair moves* of `t_k` with one other variable, both frozen. A trial is accepted
//! when it improves `±t_k`, stays in the box and satisfies eq. 8 to `hold` (closure: other contacts may hold at an
//! extremal); a trial the projection did not reach to `1e-11 L` is accepted when every PC and the penetration term are
//! within `hold` there ([`Manifolds::holds_at`]). Steps double after a success and shrink to a quarter after a failed
//! sweep, down to `1e-7` of the box width; the search ends at once when `t_k` reaches its bound. Unlike the penalty
//! formulation of eq. 11-12, every accepted point lies on the manifold, so the search does not stop short by the
//! penalty's slack; it is local (it can stop where the extreme lies in another region of the state).

use crate::criteria::{ContactPart, Objective, Weights, face_point_distance_2d, pc_criterion, pc_terms, penetration};
use crate::ga::SplitMix64;
use crate::pose::{Config, ConfigBox, Pose};
use crate::principal_contact::{ContactState, PcType, PrincipalContact};
use serde::{Deserialize, Serialize};
use stackplan_geom::DVec3;

/// Relative tolerances of the strict check (multiples of the characteristic length `L`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StrictTolerances {
    /// A PPC holds when its elements are at most `hold * L` apart; criteria and penetration must be below it.
    pub hold: f64,
    /// PPCs not in the state must be more than `clear * L` apart (no ambiguous near-contacts).
    pub clear: f64,
}

impl Default for StrictTolerances {
    fn default() -> Self {
        Self { hold: 1e-7, clear: 1e-5 }
    }
}

/// Why a configuration does not verify a state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Rejection {
    /// The projection onto the state's manifold did not converge.
    NoProjection,
    /// Outside the box.
    OutsideBox,
    /// A PC of the state does not hold (its criterion, mm).
    NotInContact {
        /// The PC.
        pc: String,
        /// Its criterion value (mm).
        value: f64,
    },
    /// The parts penetrate (`L d_G`, mm).
    Penetrating {
        /// `L d_G` (mm).
        value: f64,
    },
    /// A PPC is nearly but not clearly in contact.
    Ambiguous {
        /// The PPC.
        pc: String,
        /// Distance between its elements (mm).
        distance: f64,
    },
    /// The contacts that hold make another state.
    OtherState {
        /// The state actually in contact.
        holding: String,
    },
}

/// Context of the exact computations for one pair of parts.
#[derive(Debug, Clone)]
pub struct Manifolds<'a> {
    /// Fixed part A.
    pub fixed: &'a ContactPart,
    /// Moving part B.
    pub moving: &'a ContactPart,
    /// PPCs that can hold within the box (the others never do).
    pub ppcs: Vec<PrincipalContact>,
    /// Weights (`L`).
    pub weights: Weights,
    /// Tolerances.
    pub tolerances: StrictTolerances,
}

const SCALE_ANGLES: [bool; 6] = [false, false, false, true, true, true];

fn scale(k: usize, length: f64) -> f64 {
    if SCALE_ANGLES[k] { length } else { 1.0 }
}

/// Solves the symmetric positive definite 6x6 system `a x = b` (Cholesky); `None` if not positive definite.
fn solve_spd6(a: &[[f64; 6]; 6], b: &[f64; 6]) -> Option<[f64; 6]> {
    let mut l = [[0.0; 6]; 6];
    for i in 0..6 {
        for j in 0..=i {
            let mut s = a[i][j];
            for k in 0..j {
                s -= l[i][k] * l[j][k];
            }
            if i == j {
                if s <= 0.0 || !s.is_finite() {
                    return None;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    let mut y = [0.0; 6];
    for i in 0..6 {
        let mut s = b[i];
        for k in 0..i {
            s -= l[i][k] * y[k];
        }
        y[i] = s / l[i][i];
    }
    let mut x = [0.0; 6];
    for i in (0..6).rev() {
        let mut s = y[i];
        for k in i + 1..6 {
            s -= l[k][i] * x[k];
        }
        x[i] = s / l[i][i];
    }
    Some(x)
}

/// The factor of the extremal search's steps after a sweep without improvement.
const STALL_SHRINK: f64 = 0.25;

/// The smallest step (fraction of the width) of the extremal search's moves of two variables together.
const PAIR_MIN_STEP: f64 = 1e-3;

/// Eigenvalues and eigenvectors (the columns of the returned matrix) of the symmetric 6x6 matrix `a` (cyclic Jacobi
/// rotations; converges quadratically, a dozen sweeps at most for 6x6).
fn symmetric_eigen6(mut a: [[f64; 6]; 6]) -> ([f64; 6], [[f64; 6]; 6]) {
    let mut v = [[0.0; 6]; 6];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for _ in 0..50 {
        let off: f64 = (0..6).flat_map(|p| (p + 1..6).map(move |q| (p, q))).map(|(p, q)| a[p][q] * a[p][q]).sum();
        let diag: f64 = (0..6).map(|p| a[p][p] * a[p][p]).sum();
        if off <= 1e-30 * diag || off == 0.0 {
            break;
        }
        for p in 0..6 {
            for q in p + 1..6 {
                if a[p][q] == 0.0 {
                    continue;
                }
                // the rotation that zeroes a[p][q] (Golub & Van Loan, 8.5.2)
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..6 {
                    let (akp, akq) = (a[k][p], a[k][q]);
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for k in 0..6 {
                    let (apk, aqk) = (a[p][k], a[q][k]);
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for row in v.iter_mut() {
                    let (vp, vq) = (row[p], row[q]);
                    row[p] = c * vp - s * vq;
                    row[q] = s * vp + c * vq;
                }
            }
        }
    }
    (std::array::from_fn(|i| a[i][i]), v)
}

/// The projection of `goal` onto the common null space of `rows` (each normalised) and of the unit vectors of the
/// variables in `fixed`: the part of `goal` that keeps every row's value to first order (eigenvectors of
/// `sum r r^T + sum e_j e_j^T` with eigenvalue at most `1e-9` of the largest, so nearly dependent rows are harmless).
fn null_space_projection(goal: &[f64; 6], rows: &[[f64; 6]], fixed: &[bool; 6]) -> [f64; 6] {
    let mut a = [[0.0; 6]; 6];
    for row in rows {
        let norm = row.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm <= 0.0 || !norm.is_finite() {
            continue;
        }
        for p in 0..6 {
            for q in 0..6 {
                a[p][q] += row[p] * row[q] / (norm * norm);
            }
        }
    }
    for j in (0..6).filter(|&j| fixed[j]) {
        a[j][j] += 1.0;
    }
    let (values, vectors) = symmetric_eigen6(a);
    let largest = values.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    let mut d = [0.0; 6];
    for i in (0..6).filter(|&i| values[i].abs() <= 1e-9 * largest) {
        let along: f64 = (0..6).map(|p| vectors[p][i] * goal[p]).sum();
        for p in 0..6 {
            d[p] += along * vectors[p][i];
        }
    }
    d
}

/// A direction (scaled variables, unit length) that improves the objective `sign t_k` (decreases it) while keeping
/// the state's closure to first order: the objective's gradient projected onto the tangent space of the equalities
/// (rows `..equalities` of the closure Jacobian `jac`), with every active inequality (a bounding term or the
/// penetration term, rows `equalities..`, whose row is not zero: at or past its boundary) that the direction would
/// increase, and every variable at a bound of `bounds` that it would leave, added to the constraints until none is
/// violated. `None` when nothing is left (the point is stationary for these constraints).
fn tangent_direction(
    jac: &[[f64; 6]],
    equalities: usize,
    k: usize,
    sign: f64,
    at: &Config,
    bounds: &ConfigBox,
) -> Option<[f64; 6]> {
    let mut goal = [0.0; 6];
    goal[k] = -sign;
    let mut rows: Vec<[f64; 6]> = jac[..equalities.min(jac.len())].to_vec();
    let mut added = vec![false; jac.len()];
    let mut fixed: [bool; 6] = std::array::from_fn(|j| bounds.width(j) <= 0.0);
    for _ in 0..=jac.len() + 6 {
        let d = null_space_projection(&goal, &rows, &fixed);
        let norm = d.iter().map(|x| x * x).sum::<f64>().sqrt();
        // the improvement rate of t_k per unit move (scaled) is |d|: below 1e-6 it is rounding, or the first-order
        // gain is negligible (at the extremum, where the objective's row lies in the span of the constraints')
        if norm <= 1e-6 {
            return None;
        }
        let mut violated = false;
        for i in equalities.min(jac.len())..jac.len() {
            let row = &jac[i];
            let row_norm = row.iter().map(|x| x * x).sum::<f64>().sqrt();
            if added[i] || row_norm <= 1e-12 {
                continue;
            }
            let rate: f64 = (0..6).map(|p| row[p] * d[p]).sum();
            if rate > 1e-9 * row_norm * norm {
                added[i] = true;
                rows.push(*row);
                violated = true;
            }
        }
        for j in 0..6 {
            if !fixed[j] && ((at[j] >= bounds.max[j] && d[j] > 0.0) || (at[j] <= bounds.min[j] && d[j] < 0.0)) {
                fixed[j] = true;
                violated = true;
            }
        }
        if !violated {
            return Some(d.map(|x| x / norm));
        }
    }
    None
}

/// The variables that the equalities pin locally: a change of `t_j` alone cannot be compensated by the other
/// variables to first order (the column `J_j` is not in the span of the other columns: least-squares residual above
/// `1e-6 |J_j|`). A compass move of a pinned variable cannot stay on the manifold, so it is not tried.
fn pinned_variables(jac: &[[f64; 6]]) -> [bool; 6] {
    let mut out = [false; 6];
    if jac.is_empty() {
        return out;
    }
    for j in 0..6 {
        let norm_j: f64 = jac.iter().map(|row| row[j] * row[j]).sum::<f64>().sqrt();
        if norm_j <= 1e-12 {
            continue;
        }
        // normal equations of min |J_-j x + J_j| (j's own row and column replaced by the identity)
        let mut a = [[0.0; 6]; 6];
        let mut b = [0.0; 6];
        for row in jac {
            for p in 0..6 {
                if p == j {
                    continue;
                }
                b[p] -= row[p] * row[j];
                for q in 0..6 {
                    if q != j {
                        a[p][q] += row[p] * row[q];
                    }
                }
            }
        }
        let diag_max = (0..6).map(|p| a[p][p]).fold(0.0, f64::max).max(1e-300);
        for p in 0..6 {
            a[p][p] += if p == j { 1.0 } else { 1e-12 * diag_max };
        }
        let Some(x) = solve_spd6(&a, &b) else { continue };
        let residual: f64 = jac
            .iter()
            .map(|row| {
                let v: f64 = (0..6).filter(|&p| p != j).map(|p| row[p] * x[p]).sum::<f64>() + row[j];
                v * v
            })
            .sum::<f64>()
            .sqrt();
        out[j] = residual > 1e-6 * norm_j;
    }
    out
}

/// Closest distance between segments `p0 p1` and `q0 q1` in 3-D (C. Ericson, Real-Time Collision Detection 5.1.9).
pub fn segment_segment_distance(p0: DVec3, p1: DVec3, q0: DVec3, q1: DVec3) -> f64 {
    let d1 = p1 - p0;
    let d2 = q1 - q0;
    let r = p0 - q0;
    let a = d1.dot(d1);
    let e = d2.dot(d2);
    let f = d2.dot(r);
    let (s, t);
    if a <= f64::MIN_POSITIVE && e <= f64::MIN_POSITIVE {
        return r.length();
    }
    if a <= f64::MIN_POSITIVE {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(r);
        if e <= f64::MIN_POSITIVE {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let mut s0 = if denom > 1e-14 * a * e { ((b * f - c * e) / denom).clamp(0.0, 1.0) } else { 0.0 };
            let mut t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t0 = 0.0;
                s0 = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t0 = 1.0;
                s0 = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = s0;
            t = t0;
        }
    }
    ((p0 + d1 * s) - (q0 + d2 * t)).length()
}

/// The configuration `(x, y, z, rx + pi, pi - ry, rz + pi)` (the same pose: `Rz(c + pi) Ry(pi - b) Rx(a + pi) =
/// Rz(c) Ry(b) Rx(a)`), with `rx`, `rz` wrapped by `2 pi` into the box, if it lies in the box.
pub fn other_chart(t: &Config, bounds: &ConfigBox) -> Option<Config> {
    use std::f64::consts::{PI, TAU};
    let mut alt = *t;
    alt[3] += PI;
    alt[4] = PI - alt[4];
    alt[5] += PI;
    for k in [3, 5] {
        while alt[k] > bounds.max[k] {
            alt[k] -= TAU;
        }
        while alt[k] < bounds.min[k] {
            alt[k] += TAU;
        }
    }
    if alt[4] > PI {
        alt[4] -= TAU;
    }
    bounds.contains(&alt).then_some(alt)
}

impl<'a> Manifolds<'a> {
    /// The context for `fixed` against `moving` with the PPCs reachable in the box.
    pub fn new(
        fixed: &'a ContactPart,
        moving: &'a ContactPart,
        ppcs: Vec<PrincipalContact>,
        tolerances: StrictTolerances,
    ) -> Self {
        Self { fixed, moving, ppcs, weights: Weights::for_parts(moving), tolerances }
    }

    /// `hold * L` (mm).
    pub fn hold(&self) -> f64 {
        self.tolerances.hold * self.weights.length
    }

    /// `clear * L` (mm).
    pub fn clear(&self) -> f64 {
        self.tolerances.clear * self.weights.length
    }

    /// The signed equality residuals (mm) of the state's PCs at `pose` (see the module documentation).
    pub fn residuals(&self, state: &ContactState, pose: &Pose, out: &mut Vec<f64>) {
        out.clear();
        let (sa, sb) = (&self.fixed.surface, &self.moving.surface);
        for pc in &state.pcs {
            match pc.kind() {
                PcType::FaceVertex => {
                    out.push(sa.faces[pc.a.index].frame.height(pose.apply(sb.vertices[pc.b.index].position)))
                }
                PcType::VertexFace => {
                    out.push(sb.faces[pc.b.index].frame.height(pose.inverse_apply(sa.vertices[pc.a.index].position)))
                }
                PcType::EdgeEdge => {
                    let (a0, a1) = sa.edge_points(pc.a.index);
                    let (b0, b1) = sb.edge_points(pc.b.index);
                    let (b0, b1) = (pose.apply(b0), pose.apply(b1));
                    let (da, db) = (a1 - a0, b1 - b0);
                    let c = da.cross(db);
                    let n = c.length();
                    if n > 1e-9 * da.length() * db.length() {
                        out.push((b0 - a0).dot(c) / n);
                    } else {
                        let u = da.normalize();
                        let w = b0 - a0;
                        out.push((w - u * w.dot(u)).length());
                    }
                }
                PcType::FaceEdge => {
                    let frame = &sa.faces[pc.a.index].frame;
                    let (b0, b1) = sb.edge_points(pc.b.index);
                    out.push(frame.height(pose.apply(b0)));
                    out.push(frame.height(pose.apply(b1)));
                }
                PcType::EdgeFace => {
                    let frame = &sb.faces[pc.b.index].frame;
                    let (a0, a1) = sa.edge_points(pc.a.index);
                    out.push(frame.height(pose.inverse_apply(a0)));
                    out.push(frame.height(pose.inverse_apply(a1)));
                }
                PcType::FaceFace => {
                    let frame = &sa.faces[pc.a.index].frame;
                    for &v in &sb.faces[pc.b.index].vertices {
                        out.push(frame.height(pose.apply(sb.vertices[v].position)));
                    }
                }
            }
        }
    }

    fn residuals_at(&self, state: &ContactState, t: &Config, out: &mut Vec<f64>) {
        self.residuals(state, &Pose::from_config(t), out);
    }

    /// Projects `t0` onto the state's manifold inside `bounds`, keeping the variables in `frozen` fixed
    /// (Levenberg-Marquardt, see the module documentation); `None` when it does not converge.
    pub fn project(&self, state: &ContactState, t0: &Config, bounds: &ConfigBox, frozen: &[bool; 6]) -> Option<Config> {
        let target = 1e-11 * self.weights.length;
        let (t, r) =
            self.least_squares(|t, out| self.residuals_at(state, t, out), t0, bounds, frozen, target, 40, None);
        r.iter().all(|x| x.abs() <= target).then_some(t)
    }

    /// Levenberg-Marquardt on `residuals` from `t0` in the box (see the module documentation); stops when every
    /// residual is at most `target` or no step improves. Returns the point and its residuals.
    fn least_squares<R>(
        &self,
        residuals_at: R,
        t0: &Config,
        bounds: &ConfigBox,
        frozen: &[bool; 6],
        target: f64,
        iterations: usize,
        jacobian: Option<&[[f64; 6]]>,
    ) -> (Config, Vec<f64>)
    where
        R: Fn(&Config, &mut Vec<f64>),
    {
        let length = self.weights.length;
        let mut t = *t0;
        bounds.clamp(&mut t);
        let mut r = Vec::new();
        let mut trial_r = Vec::new();
        residuals_at(&t, &mut r);
        let norm2 = |r: &[f64]| r.iter().map(|x| x * x).sum::<f64>();
        let mut cost = norm2(&r);
        let mut mu = 1e-9;
        let mut plus = Vec::new();
        let mut minus = Vec::new();
        // a Jacobian from a nearby point (the caller's) is used as if stale: a failed step recomputes it
        let mut jac: Vec<[f64; 6]> = jacobian.map(<[[f64; 6]]>::to_vec).unwrap_or_default();
        let mut fresh = jacobian.is_some_and(|j| j.len() == r.len());
        let mut since_update = usize::from(fresh);
        let mut history: Vec<f64> = Vec::with_capacity(iterations);
        for iteration in 0..iterations {
            if r.iter().all(|x| x.abs() <= target) {
                return (t, r);
            }
            // near a regular solution the convergence is quadratic: give up on slow progress (an inconsistent
            // system, the usual case for an infeasible combination of PCs)
            history.push(cost);
            if iteration >= 8 && cost > 0.25 * history[iteration - 4] {
                break;
            }
            // Jacobian in the scaled variables by central differences, reused (chord steps) while steps succeed
            let m = r.len();
            if !fresh || since_update >= 4 || jac.len() != m {
                jac = vec![[0.0; 6]; m];
                for k in 0..6 {
                    if frozen[k] {
                        continue;
                    }
                    // step of 1e-7 L in the scaled variable
                    let h = 1e-7 * length / scale(k, length);
                    let (mut tp, mut tm) = (t, t);
                    tp[k] += h;
                    tm[k] -= h;
                    residuals_at(&tp, &mut plus);
                    residuals_at(&tm, &mut minus);
                    for i in 0..m {
                        jac[i][k] = (plus[i] - minus[i]) / (2.0 * h) / scale(k, length);
                    }
                }
                fresh = true;
                since_update = 0;
            }
            let mut active = [true; 6];
            for k in 0..6 {
                active[k] = !frozen[k];
            }
            let mut accepted = false;
            for _ in 0..6 {
                // normal equations on the active variables
                let mut a = [[0.0; 6]; 6];
                let mut g = [0.0; 6];
                for i in 0..m {
                    for p in 0..6 {
                        if !active[p] {
                            continue;
                        }
                        g[p] -= jac[i][p] * r[i];
                        for q in 0..6 {
                            if active[q] {
                                a[p][q] += jac[i][p] * jac[i][q];
                            }
                        }
                    }
                }
                let diag_max = (0..6).map(|p| a[p][p]).fold(0.0, f64::max).max(1e-300);
                for p in 0..6 {
                    if active[p] {
                        a[p][p] += mu * diag_max;
                    } else {
                        a[p][p] = 1.0;
                        g[p] = 0.0;
                    }
                }
                let Some(du) = solve_spd6(&a, &g) else {
                    mu *= 10.0;
                    continue;
                };
                let mut trial = t;
                let mut froze_one = false;
                for k in 0..6 {
                    if !active[k] {
                        continue;
                    }
                    let step = du[k] / scale(k, length);
                    let next = t[k] + step;
                    if (next < bounds.min[k] && t[k] <= bounds.min[k])
                        || (next > bounds.max[k] && t[k] >= bounds.max[k])
                    {
                        active[k] = false;
                        froze_one = true;
                    }
                    trial[k] = next.clamp(bounds.min[k], bounds.max[k]);
                }
                if froze_one {
                    continue;
                }
                residuals_at(&trial, &mut trial_r);
                let c = norm2(&trial_r);
                if c < cost {
                    t = trial;
                    std::mem::swap(&mut r, &mut trial_r);
                    cost = c;
                    mu = (mu * 0.1).max(1e-15);
                    accepted = true;
                    break;
                }
                mu *= 10.0;
                if mu > 1e4 {
                    break;
                }
            }
            if accepted {
                since_update += 1;
            } else if since_update > 0 {
                // a stale Jacobian failed: recompute it before giving up
                fresh = false;
                mu = 1e-9;
            } else {
                break;
            }
        }
        (t, r)
    }

    /// Like [`Self::project_closure`] (equalities, bounding terms, penetration), and also pushes the PPCs of `near`
    /// to at least `2 clear` apart: hinge residuals `max(0, 2 clear - distance)` join the others.
    fn project_clear(
        &self,
        state: &ContactState,
        near: &[PrincipalContact],
        t0: &Config,
        bounds: &ConfigBox,
    ) -> Config {
        let margin = 2.0 * self.clear();
        let residuals = |t: &Config, out: &mut Vec<f64>| {
            self.closure_residuals(state, t, out);
            let pose = Pose::from_config(t);
            for pc in near {
                out.push((margin - self.ppc_distance_within(pc, &pose, margin)).max(0.0));
            }
        };
        self.least_squares(residuals, t0, bounds, &[false; 6], 1e-11 * self.weights.length, 40, None).0
    }

    /// Projection onto the closure of the state (eq. 8 zero): the equalities plus the bounding terms `h2` of every PC
    /// and `L d_G` as residuals (both are zero inside their regions, so they pull back only what left them), with
    /// the variables in `frozen` fixed; `None` when it does not converge.
    pub fn project_closure(
        &self,
        state: &ContactState,
        t0: &Config,
        bounds: &ConfigBox,
        frozen: &[bool; 6],
    ) -> Option<Config> {
        self.project_closure_with(state, t0, bounds, frozen, None)
    }

    fn closure_residuals(&self, state: &ContactState, t: &Config, out: &mut Vec<f64>) {
        let length = self.weights.length;
        let pose = Pose::from_config(t);
        self.residuals(state, &pose, out);
        for pc in &state.pcs {
            out.push(pc_terms(pc, self.fixed, self.moving, &pose, length).1);
        }
        out.push(length * penetration(self.fixed, self.moving, &pose));
    }

    /// The Jacobian of the closure residuals at `t` (scaled variables).
    fn closure_jacobian(&self, state: &ContactState, t: &Config) -> Vec<[f64; 6]> {
        let length = self.weights.length;
        let (mut plus, mut minus) = (Vec::new(), Vec::new());
        let mut jac: Vec<[f64; 6]> = Vec::new();
        for k in 0..6 {
            let h = 1e-7 * length / scale(k, length);
            let (mut tp, mut tm) = (*t, *t);
            tp[k] += h;
            tm[k] -= h;
            self.closure_residuals(state, &tp, &mut plus);
            self.closure_residuals(state, &tm, &mut minus);
            if jac.is_empty() {
                jac = vec![[0.0; 6]; plus.len()];
            }
            for i in 0..plus.len().min(jac.len()) {
                jac[i][k] = (plus[i] - minus[i]) / (2.0 * h) / scale(k, length);
            }
        }
        jac
    }

    fn project_closure_with(
        &self,
        state: &ContactState,
        t0: &Config,
        bounds: &ConfigBox,
        frozen: &[bool; 6],
        jacobian: Option<&[[f64; 6]]>,
    ) -> Option<Config> {
        let target = 1e-11 * self.weights.length;
        // a compass move starts next to the closure: a few iterations suffice, or the move is rejected
        let (t, r) =
            self.least_squares(|t, out| self.closure_residuals(state, t, out), t0, bounds, frozen, target, 8, jacobian);
        r.iter().all(|x| x.abs() <= target).then_some(t)
    }

    /// Euclidean distance between the elements of a PPC at `pose` (mm).
    pub fn ppc_distance(&self, pc: &PrincipalContact, pose: &Pose) -> f64 {
        self.ppc_distance_within(pc, pose, f64::INFINITY)
    }

    /// [`Self::ppc_distance`] when it is at most `limit`; otherwise some number above `limit` (a cheap lower
    /// bound: the height over the face plane, or the distance of the segments' bounding spheres), so comparisons
    /// with `limit` or smaller thresholds come out as with the exact distance.
    pub fn ppc_distance_within(&self, pc: &PrincipalContact, pose: &Pose, limit: f64) -> f64 {
        let (sa, sb) = (&self.fixed.surface, &self.moving.surface);
        match pc.kind() {
            PcType::FaceVertex => {
                let face = &sa.faces[pc.a.index];
                let p = pose.apply(sb.vertices[pc.b.index].position);
                let h = face.frame.height(p);
                if h.abs() > limit {
                    return h.abs();
                }
                h.hypot(face_point_distance_2d(face, face.frame.to_2d(p)))
            }
            PcType::VertexFace => {
                let face = &sb.faces[pc.b.index];
                let p = pose.inverse_apply(sa.vertices[pc.a.index].position);
                let h = face.frame.height(p);
                if h.abs() > limit {
                    return h.abs();
                }
                h.hypot(face_point_distance_2d(face, face.frame.to_2d(p)))
            }
            PcType::EdgeEdge => {
                let (a0, a1) = sa.edge_points(pc.a.index);
                let (b0, b1) = sb.edge_points(pc.b.index);
                let (b0, b1) = (pose.apply(b0), pose.apply(b1));
                // every point of a segment is within half its length of its midpoint
                let spheres = ((a0 + a1) - (b0 + b1)).length() * 0.5 - 0.5 * ((a1 - a0).length() + (b1 - b0).length());
                if spheres > limit {
                    return spheres;
                }
                segment_segment_distance(a0, a1, b0, b1)
            }
            // not PPCs: the full criterion (zero iff in contact)
            _ => pc_criterion(pc, self.fixed, self.moving, pose, &self.weights),
        }
    }

    /// The PPCs in contact at `t` (distance `<= hold`), and the closest PPC in the ambiguous band, if any.
    pub fn holding(&self, t: &Config) -> (Vec<PrincipalContact>, Option<(PrincipalContact, f64)>) {
        let pose = Pose::from_config(t);
        let (hold, clear) = (self.hold(), self.clear());
        let mut holding = Vec::new();
        let mut ambiguous: Option<(PrincipalContact, f64)> = None;
        for pc in &self.ppcs {
            let d = self.ppc_distance_within(pc, &pose, clear);
            if d <= hold {
                holding.push(*pc);
            } else if d <= clear && ambiguous.is_none_or(|(_, best)| d < best) {
                ambiguous = Some((*pc, d));
            }
        }
        (holding, ambiguous)
    }

    /// The contact state at `t`: the PPCs in contact (distance `<= hold`) in highest-level form, with only merged
    /// PCs that hold at `t` (criterion `<= clear`; [`ContactState::canonical_with`]: at degenerate configurations the
    /// mapping's rules can name a PC that does not hold, such as two coplanar faces with equal normals).
    pub fn state_at(&self, t: &Config) -> ContactState {
        self.state_of(self.holding(t).0, &Pose::from_config(t))
    }

    fn state_of(&self, holding: Vec<PrincipalContact>, pose: &Pose) -> ContactState {
        let clear = self.clear();
        ContactState::canonical_with(holding, &self.fixed.surface, &self.moving.surface, |m| {
            pc_criterion(m, self.fixed, self.moving, pose, &self.weights) <= clear
        })
    }

    /// The strict check of `state` at `t` (see the module documentation).
    pub fn verify(&self, state: &ContactState, t: &Config, bounds: &ConfigBox) -> Result<(), Rejection> {
        if !bounds.contains(t) {
            return Err(Rejection::OutsideBox);
        }
        let pose = Pose::from_config(t);
        let hold = self.hold();
        for pc in &state.pcs {
            let value = pc_criterion(pc, self.fixed, self.moving, &pose, &self.weights);
            if value > hold {
                return Err(Rejection::NotInContact { pc: pc.label(), value });
            }
        }
        let value = self.weights.length * penetration(self.fixed, self.moving, &pose);
        if value > hold {
            return Err(Rejection::Penetrating { value });
        }
        let (holding, ambiguous) = self.holding(t);
        if let Some((pc, distance)) = ambiguous {
            return Err(Rejection::Ambiguous { pc: pc.label(), distance });
        }
        let actual = self.state_of(holding, &pose);
        if &actual != state {
            return Err(Rejection::OtherState { holding: actual.label() });
        }
        Ok(())
    }

    /// A configuration verifying `state` near one of `starts` (projection, then seeded perturbations of growing
    /// size, `attempts` per start); when none is found, the rejection at the first projected start.
    pub fn interior_witness(
        &self,
        state: &ContactState,
        starts: &[Config],
        bounds: &ConfigBox,
        seed: u64,
        attempts: usize,
    ) -> Result<Config, Rejection> {
        self.interior_witness_with(state, starts, bounds, seed, attempts, true)
    }

    /// [`Self::interior_witness`]; with `perturb_when_apart` false the perturbations are skipped when the first
    /// projected start is rejected as `NotInContact` or `Penetrating` (for neighbours' configurations, which a GA
    /// run follows: such starts rarely lead to a witness).
    pub fn interior_witness_with(
        &self,
        state: &ContactState,
        starts: &[Config],
        bounds: &ConfigBox,
        seed: u64,
        attempts: usize,
        perturb_when_apart: bool,
    ) -> Result<Config, Rejection> {
        let mut rng = SplitMix64::new(seed);
        let mut last = Rejection::NoProjection;
        // the rejection at the first projected start is the informative one (later ones come from perturbations)
        let mut first: Option<Rejection> = None;
        let free = [false; 6];
        // every start projected and checked first, then perturbations around the first few that projected
        let mut projected: Vec<Config> = Vec::new();
        for start in starts {
            // onto the equalities; when that leaves a bounding condition or penetration violated, onto the closure
            let Some(p) = self.project(state, start, bounds, &free) else {
                continue;
            };
            let p = if self.in_closure(state, &p, bounds) {
                p
            } else {
                self.project_closure_with(state, &p, bounds, &free, None).unwrap_or(p)
            };
            match self.verify(state, &p, bounds) {
                Ok(()) => return Ok(p),
                Err(e) => {
                    first.get_or_insert_with(|| e.clone());
                    last = e;
                }
            }
            if !projected.iter().any(|q| q == &p) {
                projected.push(p);
            }
            // the same pose in the other Euler chart, (rx + pi, pi - ry, rz + pi): near ry = +-pi/2 (gimbal lock) a
            // bound on ry can block the tilt a strict witness needs, which the other chart allows
            if let Some(alt) = other_chart(&p, bounds)
                && !projected.contains(&alt)
            {
                match self.verify(state, &alt, bounds) {
                    Ok(()) => return Ok(alt),
                    Err(e) => last = e,
                }
                projected.push(alt);
            }
        }
        if !perturb_when_apart && matches!(first, Some(Rejection::NotInContact { .. } | Rejection::Penetrating { .. }))
        {
            return Err(first.unwrap_or(last));
        }
        let (sa, sb) = (&self.fixed.surface, &self.moving.surface);
        for p in projected.iter().take(2) {
            let start_pose = Pose::from_config(p);
            let near_limit = 0.02 * self.weights.length;
            // the PPCs not implied by the state, with their distances at the start (computed once per start)
            let others: Vec<(PrincipalContact, f64)> = self
                .ppcs
                .iter()
                .copied()
                .filter(|q| {
                    let mut pcs = state.pcs.clone();
                    pcs.push(*q);
                    &ContactState::canonical(pcs, sa, sb) != state
                })
                .map(|q| (q, self.ppc_distance_within(&q, &start_pose, near_limit)))
                .collect();
            for i in 0..attempts {
                let mut trial = *p;
                if i > 0 {
                    let size = 1e-4 * 3e3f64.powf(i as f64 / attempts.saturating_sub(1).max(1) as f64);
                    for k in 0..6 {
                        trial[k] += rng.normal() * size * bounds.width(k);
                    }
                    bounds.clamp(&mut trial);
                }
                // PPCs that may come into contact near the trial point and are not part of the state
                let pose = Pose::from_config(&trial);
                let near: Vec<PrincipalContact> = others
                    .iter()
                    .filter(|(q, at_start)| {
                        *at_start <= near_limit || self.ppc_distance_within(q, &pose, near_limit) <= near_limit
                    })
                    .map(|(q, _)| *q)
                    .collect();
                let q = self.project_clear(state, &near, &trial, bounds);
                // the hinge terms can leave a small equality residual: finish with the plain projection
                let candidates = [Some(q), self.project(state, &q, bounds, &free)];
                for q in candidates.into_iter().flatten() {
                    match self.verify(state, &q, bounds) {
                        Ok(()) => return Ok(q),
                        Err(e) => last = e,
                    }
                }
            }
        }
        Err(first.unwrap_or(last))
    }

    /// Whether every PC of the state holds at `t` (criterion at most `hold`), nothing penetrates (`L d_G` at most
    /// `hold`) and `t` is in the box: the first part of [`Self::verify`], without the other contacts. The extremal
    /// search accepts a trial point that its projection did not reach to `1e-11 L` on this test (a start within the
    /// strict tolerance of an ill-conditioned system; a translation along the faces in contact).
    pub fn holds_at(&self, state: &ContactState, t: &Config, bounds: &ConfigBox) -> bool {
        if !bounds.contains(t) {
            return false;
        }
        let pose = Pose::from_config(t);
        let hold = self.hold();
        state.pcs.iter().all(|pc| pc_criterion(pc, self.fixed, self.moving, &pose, &self.weights) <= hold)
            && self.weights.length * penetration(self.fixed, self.moving, &pose) <= hold
    }

    /// Whether `t` lies in the closure of the state: eq. 8 at most `hold` inside the box.
    pub fn in_closure(&self, state: &ContactState, t: &Config, bounds: &ConfigBox) -> bool {
        // each PC's criterion and the penetration term may each be up to `hold` at a verified witness
        bounds.contains(t)
            && Objective { fixed: self.fixed, moving: self.moving, state, weights: self.weights }.value(t)
                <= self.hold() * (state.pcs.len() + 1) as f64
    }

    /// The extremal of `t_k` (lower, or upper when `upper`) by a local search on the manifold from `start` (a
    /// configuration in the closure of the state): projected-gradient moves along the tangent space of the state's
    /// equalities and active inequalities, and compass moves of single variables, each restored onto the closure by
    /// projection (see the module documentation). Returns the configuration reached and the projections spent.
    pub fn extremal(
        &self,
        state: &ContactState,
        start: Config,
        k: usize,
        upper: bool,
        bounds: &ConfigBox,
        budget: usize,
    ) -> (Config, usize) {
        let sign = if upper { -1.0 } else { 1.0 };
        let length = self.weights.length;
        let mut best = start;
        let mut used = 0;
        let min_step = 1e-7;
        let mut step = [0.05f64; 6];
        // the tangent move's step: the first-order change of t_k, as a fraction of its width
        let mut tangent_step = 0.05f64;
        let mut frozen = [false; 6];
        let mut base_jacobian = self.closure_jacobian(state, &best);
        let mut equality_rows = Vec::new();
        self.residuals_at(state, &best, &mut equality_rows);
        let equalities = equality_rows.len().min(base_jacobian.len());
        let improves = |q: &Config, best: &Config| sign * (q[k] - best[k]) < -1e-12 * bounds.width(k).max(1e-12);
        let at_bound = |t: &Config| if upper { t[k] >= bounds.max[k] } else { t[k] <= bounds.min[k] };
        while used < budget && (tangent_step >= min_step || step.iter().any(|s| *s >= min_step)) && !at_bound(&best) {
            // a move along the tangent space towards better t_k, restored with t_k frozen (coordinated moves of
            // several variables that no single-variable move finds)
            if tangent_step >= min_step {
                // d in scaled variables: t_k changes by d_k / scale(k) per unit; none left: stationary for the
                // constraints, until a compass move leads elsewhere
                let direction =
                    tangent_direction(&base_jacobian, equalities, k, sign, &best, bounds).filter(|d| d[k] != 0.0);
                match direction {
                    Some(d) => {
                        // no variable moves by more than `tangent_step` of its width (a trust region: the boundary
                        // the move follows is curved), and the move stops at the box (clamping would leave the
                        // tangent space)
                        let mut alpha = f64::INFINITY;
                        for j in (0..6).filter(|&j| d[j] != 0.0) {
                            let rate = d[j] / scale(j, length);
                            alpha = alpha.min(tangent_step * bounds.width(j) / rate.abs());
                            let room = if rate > 0.0 { bounds.max[j] - best[j] } else { bounds.min[j] - best[j] };
                            alpha = alpha.min(room / rate);
                        }
                        let mut trial = best;
                        for j in 0..6 {
                            trial[j] += alpha * d[j] / scale(j, length);
                        }
                        bounds.clamp(&mut trial);
                        frozen[k] = true;
                        let mut projected = self
                            .project_closure_with(state, &trial, bounds, &frozen, Some(&base_jacobian))
                            .or_else(|| self.holds_at(state, &trial, bounds).then_some(trial));
                        frozen[k] = false;
                        used += 1;
                        // t_k beyond what the closure allows there (a curved boundary): the nearest point of the
                        // closure, which trades part of the gain for the other variables (a gradient projection)
                        if projected.is_none_or(|q| !improves(&q, &best)) && used < budget {
                            projected = self.project_closure_with(state, &trial, bounds, &frozen, Some(&base_jacobian));
                            used += 1;
                        }
                        if let Some(q) = projected
                            && improves(&q, &best)
                            && self.in_closure(state, &q, bounds)
                        {
                            best = q;
                            base_jacobian = self.closure_jacobian(state, &best);
                            tangent_step = (tangent_step * 2.0).min(0.5);
                            continue;
                        }
                        tangent_step *= 0.5;
                    }
                    None => tangent_step = 0.0,
                }
            }
            let mut improved = false;
            // the objective's own variable first, then the others
            let order = std::iter::once(k).chain((0..6).filter(|&j| j != k));
            let pinned = pinned_variables(&base_jacobian[..equalities]);
            for j in order {
                if step[j] < min_step || bounds.width(j) <= 0.0 || pinned[j] {
                    continue;
                }
                for dir in [-sign, sign] {
                    if used >= budget {
                        break;
                    }
                    // t_k itself frozen at a worse value can never improve: only its improving direction is tried
                    if j == k && dir == sign {
                        continue;
                    }
                    let mut trial = best;
                    trial[j] = (trial[j] + dir * step[j] * bounds.width(j)).clamp(bounds.min[j], bounds.max[j]);
                    if trial[j] == best[j] {
                        continue;
                    }
                    frozen[j] = true;
                    // (a start within the strict tolerance of an ill-conditioned system may not project to 1e-11 L,
                    // while the move itself stays in the closure: a translation along a face)
                    let projected = self
                        .project_closure_with(state, &trial, bounds, &frozen, Some(&base_jacobian))
                        .or_else(|| self.holds_at(state, &trial, bounds).then_some(trial));
                    frozen[j] = false;
                    used += 1;
                    let Some(q) = projected else { continue };
                    if improves(&q, &best) && self.in_closure(state, &q, bounds) {
                        best = q;
                        base_jacobian = self.closure_jacobian(state, &best);
                        // (the pinned set is recomputed from it at the next sweep)
                        step[j] = (step[j] * 2.0).min(0.5);
                        // from the new point the tangent space may lead on
                        tangent_step = tangent_step.max(step[j]);
                        improved = true;
                        break;
                    }
                }
            }
            // stalled: moves of t_k together with one other variable, both frozen while the others restore the
            // closure (a tilt limited by an edge that a lift clears); coarse steps only (they escape a corner, the
            // fine steps above converge)
            if !improved && step[k] >= PAIR_MIN_STEP && bounds.width(k) > 0.0 {
                'pairs: for j in (0..6).filter(|&j| j != k && bounds.width(j) > 0.0) {
                    for dir in [-1.0, 1.0] {
                        if used >= budget {
                            break 'pairs;
                        }
                        let mut trial = best;
                        trial[k] = (trial[k] - sign * step[k] * bounds.width(k)).clamp(bounds.min[k], bounds.max[k]);
                        trial[j] = (trial[j] + dir * step[k] * bounds.width(j)).clamp(bounds.min[j], bounds.max[j]);
                        if trial[j] == best[j] {
                            continue;
                        }
                        frozen[k] = true;
                        frozen[j] = true;
                        let projected = self
                            .project_closure_with(state, &trial, bounds, &frozen, Some(&base_jacobian))
                            .or_else(|| self.holds_at(state, &trial, bounds).then_some(trial));
                        frozen[k] = false;
                        frozen[j] = false;
                        used += 1;
                        if let Some(q) = projected
                            && improves(&q, &best)
                            && self.in_closure(state, &q, bounds)
                        {
                            best = q;
                            base_jacobian = self.closure_jacobian(state, &best);
                            tangent_step = tangent_step.max(step[k]);
                            improved = true;
                            break 'pairs;
                        }
                    }
                }
            }
            if !improved {
                for s in &mut step {
                    *s *= STALL_SHRINK;
                }
            }
        }
        (best, used)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::criteria::tests::box_part;
    use crate::principal_contact::all_ppcs;
    use crate::surface::Element;

    #[test]
    fn segment_distances() {
        let d = segment_segment_distance(DVec3::ZERO, DVec3::X, DVec3::new(0.5, -1.0, 2.0), DVec3::new(0.5, 1.0, 2.0));
        assert!((d - 2.0).abs() < 1e-15);
        let d = segment_segment_distance(DVec3::ZERO, DVec3::X, DVec3::new(3.0, 1.0, 0.0), DVec3::new(4.0, 1.0, 0.0));
        assert!((d - 5f64.sqrt()).abs() < 1e-15);
        // parallel overlapping
        let d = segment_segment_distance(DVec3::ZERO, DVec3::X, DVec3::new(0.5, 1.0, 0.0), DVec3::new(2.0, 1.0, 0.0));
        assert!((d - 1.0).abs() < 1e-15);
    }

    #[test]
    fn projection_puts_a_vertex_on_a_face_and_the_check_is_strict() {
        let slab = box_part("slab", DVec3::new(-50.0, -50.0, -10.0), DVec3::new(50.0, 50.0, 0.0));
        let cube = box_part("cube", DVec3::splat(-0.5), DVec3::splat(0.5));
        let top = slab.surface.faces.iter().position(|f| (f.plane.normal - DVec3::Z).length() < 1e-12).expect("top");
        let low = cube.surface.vertices.iter().position(|v| v.position == DVec3::splat(-0.5)).expect("vertex");
        let state = ContactState::single(PrincipalContact::new(Element::face(top), Element::vertex(low)).expect("pc"));
        let bounds = ConfigBox::new([-1.0, -1.0, 0.0, -0.3, -0.3, -0.3], [1.0, 1.0, 2.0, 0.3, 0.3, 0.3]).expect("box");
        let m = Manifolds::new(&slab, &cube, all_ppcs(&slab.surface, &cube.surface), StrictTolerances::default());
        // tilted so that the lowest vertex is -0.5,-0.5,-0.5 of the cube; start 0.2 too high
        let t0 = [0.1, 0.2, 0.9, 0.15, -0.12, 0.05];
        let t = m.project(&state, &t0, &bounds, &[false; 6]).expect("converges");
        let p = Pose::from_config(&t).apply(DVec3::splat(-0.5));
        assert!(p.z.abs() < 1e-9, "{p:?}");
        assert!(m.verify(&state, &t, &bounds).is_ok(), "{:?}", m.verify(&state, &t, &bounds));
        // flat on the face: four vertices touch, the f-v state is not the one in contact
        let flat =
            m.project(&state, &[0.0, 0.0, 0.6, 0.0, 0.0, 0.0], &bounds, &[false, false, false, true, true, true]);
        let flat = flat.expect("flat");
        assert!(matches!(m.verify(&state, &flat, &bounds), Err(Rejection::OtherState { .. })));
        // and the interior search finds a strict witness from there
        let w = m.interior_witness(&state, &[flat], &bounds, 3, 20).expect("witness");
        assert!(m.verify(&state, &w, &bounds).is_ok());
    }

    #[test]
    fn faces_side_by_side_are_no_face_face_contact() {
        // two aligned unit cubes, B on top of A: the top and bottom faces lie flat on each other, and the side faces
        // of the two cubes are coplanar with equal normals, touching only along their common edge line; the points
        // on that line used to merge them into f-f PCs such as f1-f0, whose criterion (opposite normals) fails
        let a = box_part("a", DVec3::ZERO, DVec3::ONE);
        let b = box_part("b", DVec3::ZERO, DVec3::ONE);
        let t = [0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
        let e = 1e-9;
        let bounds = ConfigBox::new([-e, -e, 1.0, -e, -e, -e], [e, e, 1.0, e, e, e]).expect("box");
        let m = Manifolds::new(&a, &b, all_ppcs(&a.surface, &b.surface), StrictTolerances::default());
        let state = m.state_at(&t);
        let pose = Pose::from_config(&t);
        for pc in &state.pcs {
            let value = pc_criterion(pc, &a, &b, &pose, &m.weights);
            assert!(value <= m.hold(), "{} in {} has criterion {value}", pc.label(), state.label());
        }
        let ff: Vec<&PrincipalContact> = state.pcs.iter().filter(|pc| pc.kind() == PcType::FaceFace).collect();
        assert_eq!(ff.len(), 1, "{}", state.label());
        let (na, nb) = (a.surface.faces[ff[0].a.index].plane.normal, b.surface.faces[ff[0].b.index].plane.normal);
        assert!((na - DVec3::Z).length() < 1e-12 && (nb + DVec3::Z).length() < 1e-12, "{}", state.label());
        // the strict check of a single PPC names that state, the one it finds there
        let single = ContactState::single(*ff[0]);
        match m.verify(&single, &t, &bounds) {
            Err(Rejection::OtherState { holding }) => assert_eq!(holding, state.label()),
            other => panic!("{other:?}"),
        }
        // and the hypotheses' mapping does not merge faces that cannot face each other within the box
        let (sa, sb) = (&a.surface, &b.surface);
        let holding = m.holding(&t).0;
        let can_face = crate::acsg::can_face(sa, sb, &bounds);
        let merged = ContactState::canonical_with(holding, sa, sb, |m| {
            m.kind() != PcType::FaceFace || can_face(m.a.index, m.b.index)
        });
        assert!(merged.pcs.iter().all(|m| m.kind() != PcType::FaceFace || m == ff[0]), "{}", merged.label());
    }

    #[test]
    fn eigen_decomposition_and_null_space() {
        // a symmetric matrix with a known spectrum: Q diag(0, 0, 1, 2, 3, 4) Q^T for a rotation Q in the (0, 1), (2,
        // 5) and (3, 4) planes
        let (c, s) = (0.6, 0.8);
        let mut q = [[0.0; 6]; 6];
        for (i, row) in q.iter_mut().enumerate() {
            row[i] = 1.0;
        }
        for (p, r) in [(0, 1), (2, 5), (3, 4)] {
            q[p][p] = c;
            q[r][r] = c;
            q[p][r] = -s;
            q[r][p] = s;
        }
        let diag = [0.0, 0.0, 1.0, 2.0, 3.0, 4.0];
        let a: [[f64; 6]; 6] =
            std::array::from_fn(|i| std::array::from_fn(|j| (0..6).map(|m| q[i][m] * diag[m] * q[j][m]).sum()));
        let (values, vectors) = symmetric_eigen6(a);
        let mut sorted = values;
        sorted.sort_by(f64::total_cmp);
        for (x, y) in sorted.iter().zip(diag) {
            assert!((x - y).abs() < 1e-12, "{values:?}");
        }
        for i in 0..6 {
            // A v = lambda v
            for p in 0..6 {
                let av: f64 = (0..6).map(|m| a[p][m] * vectors[m][i]).sum();
                assert!((av - values[i] * vectors[p][i]).abs() < 1e-12);
            }
        }
        // the null space of two rows and one fixed variable: what is left of the goal is orthogonal to all three
        let rows = [[1.0, 1.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 2.0, 0.0, 0.0, 0.0]];
        let mut fixed = [false; 6];
        fixed[5] = true;
        let d = null_space_projection(&[1.0, 0.0, 1.0, 1.0, 0.0, 1.0], &rows, &fixed);
        let expected = [0.5, -0.5, 0.0, 1.0, 0.0, 0.0];
        assert!(d.iter().zip(expected).all(|(x, y)| (x - y).abs() < 1e-12), "{d:?}");
    }

    /// The cube's face on a 2 x 2 plate, `|rz| <= pi/4`: the farthest x is `1 + sqrt(2)/2`, a corner first at
    /// `rz = +-pi/4`, where the corner's bounding condition and the rz bound meet. Moves of one variable (restored by
    /// projection) approach it slowly; a move along the tangent space of the active constraints follows the plate's
    /// edge with x and rz together.
    #[test]
    fn the_extremal_search_follows_the_active_constraints() {
        let plate = box_part("plate", DVec3::new(-1.0, -1.0, -1.0), DVec3::new(1.0, 1.0, 0.0));
        let cube = box_part("cube", DVec3::splat(-0.5), DVec3::splat(0.5));
        let q = std::f64::consts::FRAC_PI_4;
        let bounds = ConfigBox::new([-3.0, -3.0, 0.45, -0.02, -0.02, -q], [3.0, 3.0, 0.7, 0.02, 0.02, q]).expect("box");
        let face = |s: &crate::surface::SurfaceElements, n: DVec3| {
            s.faces.iter().position(|f| (f.plane.normal - n).length() < 1e-12).expect("face")
        };
        let pc = PrincipalContact::new(
            Element::face(face(&plate.surface, DVec3::Z)),
            Element::face(face(&cube.surface, -DVec3::Z)),
        );
        let state = ContactState::single(pc.expect("f-f"));
        let m = Manifolds::new(&plate, &cube, all_ppcs(&plate.surface, &cube.surface), StrictTolerances::default());
        let witness = [0.1, -0.2, 0.5, 0.0, 0.0, 0.1];
        assert!(m.verify(&state, &witness, &bounds).is_ok());
        let reach = 1.0 + 0.5 * 2f64.sqrt();
        for (k, upper, target) in [(0, true, reach), (0, false, -reach), (1, true, reach)] {
            let (t, used) = m.extremal(&state, witness, k, upper, &bounds, 100);
            assert!((t[k] - target).abs() < 1e-6, "variable {k} upper {upper}: {t:?} after {used} projections");
            assert!(m.in_closure(&state, &t, &bounds));
        }
    }

    #[test]
    fn the_other_euler_chart_is_the_same_pose() {
        use std::f64::consts::PI;
        let bounds =
            ConfigBox::new([-1.0, -1.0, -1.0, -PI, -PI / 2.0, -PI], [1.0, 1.0, 1.0, PI, PI / 2.0, PI]).expect("box");
        // with |ry| <= pi/2 the other chart is in the box only on the gimbal-lock bound
        let t = [0.1, 0.2, 0.3, 0.7, PI / 2.0, -2.0];
        assert!(other_chart(&[0.1, 0.2, 0.3, 0.7, 1.5, -2.0], &bounds).is_none());
        let alt = other_chart(&t, &bounds).expect("in the box");
        let (a, b) = (Pose::from_config(&t), Pose::from_config(&alt));
        for p in [DVec3::X, DVec3::Y, DVec3::Z] {
            assert!((a.apply(p) - b.apply(p)).length() < 1e-12);
        }
        // with small angle bounds the other chart is outside
        let small = ConfigBox::new([-1.0, -1.0, -1.0, -0.2, -0.2, -0.2], [1.0, 1.0, 1.0, 0.2, 0.2, 0.2]).expect("box");
        assert!(other_chart(&[0.0, 0.0, 0.0, 0.1, 0.1, 0.1], &small).is_none());
    }
}
