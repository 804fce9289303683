//! Extremal configurations of a feasible contact state (\[P\] III, Definition 1, eq. 9-12).
//!
//! For each configuration variable `t_k` the lower extremal solves eq. 9, `min t_k` subject to the state's criteria
//! (eq. 4), non-penetration (eq. 5) and the box (eq. 7), and the upper one eq. 10 (`min -t_k`). \[P\] solves the
//! penalised forms eq. 11-12 with a GA; the penalty leaves a slack (the minimiser of `t_k + lambda f` sits where the
//! decrease of `t_k` balances the growth of `lambda f`), and a GA/compass search on a thin manifold stops short of
//! the true extreme (the earlier version of this module did: the face-down cube test could only assert that a vertex
//! contact lifts the centre, not the analytic maximum). Here every extremal is searched *on* the state's manifold
//! ([`crate::manifold::Manifolds::extremal`]): a compass search whose moves change one variable and restore the
//! equalities by projection, accepting only points that satisfy eq. 8 to the strict tolerance. The 12 searches run
//! one after the other from the best configuration known so far for each objective (the witness, or an extremal
//! already found), which gives the later searches several starting points.
//! Cost: at most `budget` projections per extremal (each a few residual evaluations and one eq. 8 evaluation).

use crate::criteria::Objective;
use crate::manifold::Manifolds;
use crate::pose::{Config, ConfigBox, VARIABLE_NAMES};
use crate::principal_contact::ContactState;
use serde::{Deserialize, Serialize};

/// One extremal configuration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Extremal {
    /// Variable index (0..6: x, y, z, rx, ry, rz).
    pub variable: usize,
    /// Variable name.
    pub name: String,
    /// `false` for the minimum of `t_k`, `true` for the maximum.
    pub upper: bool,
    /// The extremal value of `t_k`.
    pub value: f64,
    /// The configuration.
    pub t: Config,
    /// `f(t)` of eq. 8 there (below the strict tolerance when `converged`).
    pub objective: f64,
    /// Whether the configuration lies in the closure of the state (eq. 8 below the strict tolerance).
    pub converged: bool,
}

/// The 12 extremals of `state`, in the closure of which `witness` lies, searched in `bounds` with at most `budget`
/// projections each.
pub fn extremals(
    manifolds: &Manifolds<'_>,
    state: &ContactState,
    bounds: &ConfigBox,
    witness: Config,
    budget: usize,
) -> Vec<Extremal> {
    let objective = Objective { fixed: manifolds.fixed, moving: manifolds.moving, state, weights: manifolds.weights };
    let mut known: Vec<Config> = vec![witness];
    let mut out = Vec::with_capacity(12);
    for k in 0..6 {
        for upper in [false, true] {
            let better = |a: &Config, b: &Config| if upper { a[k] > b[k] } else { a[k] < b[k] };
            let start = known.iter().copied().fold(witness, |best, t| if better(&t, &best) { t } else { best });
            let (t, _) = if bounds.width(k) > 0.0 {
                manifolds.extremal(state, start, k, upper, bounds, budget)
            } else {
                (start, 0)
            };
            known.push(t);
            out.push(Extremal {
                variable: k,
                name: VARIABLE_NAMES[k].to_string(),
                upper,
                value: t[k],
                t,
                objective: objective.value(&t),
                converged: manifolds.in_closure(state, &t, bounds),
            });
        }
    }
    out
}

/// The range box spanned by a state's extremals; a bound whose search did not converge stays at `fallback`'s (the
/// search box), so that the refinement of Propositions 1-2 never cuts off configurations on the strength of a
/// failed search.
pub fn range_of(extremals: &[Extremal], fallback: &ConfigBox) -> ConfigBox {
    let mut b = *fallback;
    for e in extremals.iter().filter(|e| e.converged) {
        if e.upper {
            b.max[e.variable] = e.value;
        } else {
            b.min[e.variable] = e.value;
        }
    }
    for k in 0..6 {
        if b.min[k] > b.max[k] {
            std::mem::swap(&mut b.min[k], &mut b.max[k]);
        }
    }
    b
}
