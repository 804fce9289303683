//! The extremal search on a state's manifold (\[P\] eq. 9-10): tangent moves along the active constraints, compass
//! moves and pair moves, each restored onto the closure by projection (see the [module documentation](super)).

use super::check::{Manifolds, scale};
use super::linalg::{null_space_projection, solve_spd6};
use crate::pose::{Config, ConfigBox};
use crate::principal_contact::ContactState;

/// The factor of the extremal search's steps after a sweep without improvement.
const STALL_SHRINK: f64 = 0.25;

/// The smallest step (fraction of the width) of the extremal search's moves of two variables together.
const PAIR_MIN_STEP: f64 = 1e-3;

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

impl Manifolds<'_> {
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
    use crate::manifold::StrictTolerances;
    use crate::principal_contact::{PrincipalContact, all_ppcs};
    use crate::surface::Element;
    use stackplan_geom::DVec3;

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
}
