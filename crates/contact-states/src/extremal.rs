//! Extremal configurations of a feasible contact state (\[P\] III, Definition 1, eq. 9-12).
//!
//! For each configuration variable `t_k` the lower extremal solves eq. 9, `min t_k` subject to the state's criteria
//! (eq. 4), non-penetration (eq. 5) and the box (eq. 7), and the upper one eq. 10 (`min -t_k`). \[P\] solves the
//! penalised forms eq. 11-12 with a GA; the penalty leaves a slack (the minimiser of `t_k + lambda f` sits where the
//! decrease of `t_k` balances the growth of `lambda f`), and a GA/compass search on a thin manifold stops short of
//! the true extreme (with it the face-down cube test could only assert that a vertex contact lifts the centre, not
//! the analytic maximum). Here every extremal is searched *on* the state's manifold
//! ([`crate::manifold::Manifolds::extremal`]): a local search whose moves (along the tangent space of the state's
//! active constraints, or of one variable) are restored onto the closure by projection, accepting only points that
//! satisfy eq. 8 to the strict tolerance. The 12 searches run one after the other from the best configuration known
//! so far for each objective (the witness, or an extremal already found), which gives the later searches several
//! starting points; then the searches that a configuration found later beats run again from it (at most
//! [`RERUN_PASSES`] passes), and one still beaten takes that configuration: no extremal is beaten by the witness or
//! another extremal of its state.
//! Cost: at most `budget` projections per search, 12 to `12 (1 + RERUN_PASSES)` searches per state.

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

/// Passes of [`extremals`] that re-run the searches whose extremal another known configuration of the state beats.
pub const RERUN_PASSES: usize = 2;

/// The 12 extremals of `state`, in the closure of which `witness` lies, searched in `bounds` with at most `budget`
/// projections each.
///
/// Each search starts from the best configuration known so far for its objective (the witness or an extremal
/// already found). A later search can pass through a configuration that beats an earlier extremal (the rz maximum of
/// a state may lie higher than its z "maximum"), so up to [`RERUN_PASSES`] passes re-run every search beaten by a
/// known configuration of the state, from that configuration; a search still beaten after them takes the best known
/// configuration itself. So every extremal is at least as extreme as the witness and every other extremal, and the
/// range spanned by the extremal configurations ([`range_of`]) has the extremal values as its bounds.
pub fn extremals(
    manifolds: &Manifolds<'_>,
    state: &ContactState,
    bounds: &ConfigBox,
    witness: Config,
    budget: usize,
) -> Vec<Extremal> {
    let objective = Objective { fixed: manifolds.fixed, moving: manifolds.moving, state, weights: manifolds.weights };
    // the configurations known to lie in the closure of the state (the witness, the searches' results)
    let mut known: Vec<Config> = vec![witness];
    let better = |k: usize, upper: bool, a: &Config, b: &Config| if upper { a[k] > b[k] } else { a[k] < b[k] };
    let best_known = |known: &[Config], k: usize, upper: bool| {
        known.iter().copied().fold(witness, |best, t| if better(k, upper, &t, &best) { t } else { best })
    };
    let mut found: Vec<Config> = Vec::with_capacity(12);
    let search = |start: Config, k: usize, upper: bool, known: &mut Vec<Config>| -> Config {
        let t =
            if bounds.width(k) > 0.0 { manifolds.extremal(state, start, k, upper, bounds, budget).0 } else { start };
        if manifolds.in_closure(state, &t, bounds) {
            known.push(t);
        }
        t
    };
    for k in 0..6 {
        for upper in [false, true] {
            let start = best_known(&known, k, upper);
            found.push(search(start, k, upper, &mut known));
        }
    }
    for pass in 0..=RERUN_PASSES {
        let mut beaten = 0;
        for (i, (k, upper)) in (0..6).flat_map(|k| [(k, false), (k, true)]).enumerate() {
            let start = best_known(&known, k, upper);
            if !better(k, upper, &start, &found[i]) {
                continue;
            }
            beaten += 1;
            found[i] = if pass < RERUN_PASSES { search(start, k, upper, &mut known) } else { start };
        }
        tracing::trace!(state = %state.label(), pass, beaten, "extremals beaten by known configurations");
        if beaten == 0 {
            break;
        }
    }
    found
        .into_iter()
        .enumerate()
        .map(|(i, t)| {
            let (k, upper) = (i / 2, i % 2 == 1);
            Extremal {
                variable: k,
                name: VARIABLE_NAMES[k].to_string(),
                upper,
                value: t[k],
                t,
                objective: objective.value(&t),
                converged: manifolds.in_closure(state, &t, bounds),
            }
        })
        .collect()
}

/// The range box spanned by a state's extremal configurations: the lowest and highest value of each variable over
/// the configurations of the extremals that converged (lie in the closure of the state). A bound no converged
/// extremal configuration gives (every search starts from the strict witness and accepts only points in the closure,
/// so this does not happen in [`extremals`]' output) stays at `fallback`'s (the search box), so that the refinement
/// of Propositions 1-2 never cuts off configurations on the strength of a failed search.
pub fn range_of(extremals: &[Extremal], fallback: &ConfigBox) -> ConfigBox {
    let converged: Vec<&Extremal> = extremals.iter().filter(|e| e.converged).collect();
    let mut b = *fallback;
    for k in 0..6 {
        let (lo, hi) =
            converged.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), e| (lo.min(e.t[k]), hi.max(e.t[k])));
        // the bound of variable k is found by its own search; without it the fallback's
        if converged.iter().any(|e| e.variable == k && !e.upper) {
            b.min[k] = lo;
        }
        if converged.iter().any(|e| e.variable == k && e.upper) {
            b.max[k] = hi;
        }
    }
    b
}
