//! The contact manifold of a state: its equality residuals, the projections onto it (Levenberg-Marquardt) and
//! onto its closure, element distances of the PPCs, and the strict check of a state at a configuration (see the
//! [module documentation](super)).

use super::linalg::solve_spd6;
use crate::criteria::{ContactPart, Objective, Weights, face_point_distance_2d, pc_criterion, pc_terms, penetration};
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
    /// The state's contacts hold within `hold` but the configuration is not on their manifold: an equality residual
    /// (mm) above [`EXACT_RESIDUAL`]` L`. The state may exist only within the tolerance (contacts whose equalities
    /// have an exact solution only where further contacts hold).
    NotExact {
        /// The largest equality residual (mm).
        residual: f64,
    },
}

/// The largest equality residual (relative to `L`) of an exact witness: the projection reaches `1e-11 L`, and every
/// contact not in the state is at least `clear = 1e-5 L` away, five orders of magnitude further.
pub const EXACT_RESIDUAL: f64 = 1e-10;

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

pub(super) fn scale(k: usize, length: f64) -> f64 {
    if SCALE_ANGLES[k] { length } else { 1.0 }
}

/// Closest distance between segments `p0 p1` and `q0 q1` in 3-D (C. Ericson, Real-Time Collision Detection 5.1.9).
pub fn segment_segment_distance(p0: DVec3, p1: DVec3, q0: DVec3, q1: DVec3) -> f64 {
    segment_closest(p0, p1, q0, q1).0
}

/// The closest points of segments `p0 p1` and `q0 q1`: `(distance, s, t)` with the points `p0 + s (p1 - p0)` and
/// `q0 + t (q1 - q0)`, `s, t` in `[0, 1]` (C. Ericson, Real-Time Collision Detection 5.1.9; for parallel segments one
/// of the closest pairs).
pub fn segment_closest(p0: DVec3, p1: DVec3, q0: DVec3, q1: DVec3) -> (f64, f64, f64) {
    let d1 = p1 - p0;
    let d2 = q1 - q0;
    let r = p0 - q0;
    let a = d1.dot(d1);
    let e = d2.dot(d2);
    let f = d2.dot(r);
    let (s, t);
    if a <= f64::MIN_POSITIVE && e <= f64::MIN_POSITIVE {
        return (r.length(), 0.0, 0.0);
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
    (((p0 + d1 * s) - (q0 + d2 * t)).length(), s, t)
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

    pub(super) fn residuals_at(&self, state: &ContactState, t: &Config, out: &mut Vec<f64>) {
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
    pub(super) fn least_squares<R>(
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

    pub(super) fn closure_residuals(&self, state: &ContactState, t: &Config, out: &mut Vec<f64>) {
        let length = self.weights.length;
        let pose = Pose::from_config(t);
        self.residuals(state, &pose, out);
        for pc in &state.pcs {
            out.push(pc_terms(pc, self.fixed, self.moving, &pose, length).1);
        }
        out.push(length * penetration(self.fixed, self.moving, &pose));
    }

    /// The Jacobian of the closure residuals at `t` (scaled variables).
    pub(super) fn closure_jacobian(&self, state: &ContactState, t: &Config) -> Vec<[f64; 6]> {
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

    pub(super) fn project_closure_with(
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
                // edges that meet at an end point of either touch there with a vertex: that is the vertex's contact
                // (its f-v / v-f PPCs hold too), not a crossing; an end point nearly but not clearly there is
                // ambiguous
                if pc.kind() == PcType::EdgeEdge {
                    let end = self.edge_edge_end_distance(pc, &pose);
                    if end <= hold {
                        continue;
                    }
                    if end <= clear {
                        if ambiguous.is_none_or(|(_, best)| end < best) {
                            ambiguous = Some((*pc, end));
                        }
                        continue;
                    }
                }
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
        self.state_of(self.holding(t).0, &Pose::from_config(t)).0
    }

    /// The state of the PPCs `holding` at `pose`, with a PC whose contact set is nearly but not clearly on a
    /// boundary, if any ([`Self::without_boundary_contacts`]).
    pub(super) fn state_of(
        &self,
        holding: Vec<PrincipalContact>,
        pose: &Pose,
    ) -> (ContactState, Option<(PrincipalContact, f64)>) {
        let clear = self.clear();
        let merged = ContactState::canonical_with(holding, &self.fixed.surface, &self.moving.surface, |m| {
            pc_criterion(m, self.fixed, self.moving, pose, &self.weights) <= clear
        });
        self.without_boundary_contacts(merged, pose)
    }

    /// How far from an end point of either edge the closest points of an e-e PPC's edges lie (mm).
    fn edge_edge_end_distance(&self, pc: &PrincipalContact, pose: &Pose) -> f64 {
        let (a0, a1) = self.fixed.surface.edge_points(pc.a.index);
        let (b0, b1) = self.moving.surface.edge_points(pc.b.index);
        let (_, s, t) = segment_closest(a0, a1, pose.apply(b0), pose.apply(b1));
        let (la, lb) = ((a1 - a0).length(), (b1 - b0).length());
        (s.min(1.0 - s) * la).min(t.min(1.0 - t) * lb)
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
        let (actual, near_boundary) = self.state_of(holding, &pose);
        if let Some((pc, distance)) = near_boundary {
            return Err(Rejection::Ambiguous { pc: pc.label(), distance });
        }
        if &actual != state {
            return Err(Rejection::OtherState { holding: actual.label() });
        }
        let mut r = Vec::new();
        self.residuals(state, &pose, &mut r);
        let residual = r.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        if residual > EXACT_RESIDUAL * self.weights.length {
            return Err(Rejection::NotExact { residual });
        }
        Ok(())
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::criteria::tests::box_part;
    use crate::pose::ConfigBox;
    use crate::principal_contact::all_ppcs;

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
        // the side faces' contacts lie on the common edge line, the boundary of the faces flat on each other: they
        // are no contacts of their own, and the state is the face on the face alone
        assert_eq!(state.pcs.len(), 1, "{}", state.label());
        let single = ContactState::single(*ff[0]);
        assert_eq!(m.verify(&single, &t, &bounds), Ok(()));
        // and the hypotheses' mapping does not merge faces that cannot face each other within the box
        let (sa, sb) = (&a.surface, &b.surface);
        let holding = m.holding(&t).0;
        let can_face = crate::acsg::can_face(sa, sb, &bounds);
        let merged = ContactState::canonical_with(holding, sa, sb, |m| {
            m.kind() != PcType::FaceFace || can_face(m.a.index, m.b.index)
        });
        assert!(merged.pcs.iter().all(|m| m.kind() != PcType::FaceFace || m == ff[0]), "{}", merged.label());
    }
}
