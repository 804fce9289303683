//! Extremal configurations of a feasible contact state ([P] III, Definition 1, eq. 9-12).
//!
//! For each configuration variable `t_k` the lower extremal minimises `f1 = t_k + lambda (sum h + W3 d_G)` and the
//! upper one `f2 = -t_k + lambda (...)` over the state's search box (eq. 11-12). We scale the variable by the box
//! width and the criteria by the characteristic length `L`, `f1 = (t_k - min_k) / width_k + lambda f / L` with
//! `lambda = 1e4`: the criteria are sums of absolute values, so the penalty is exact (for `lambda` above the
//! constraint multipliers the penalised minimiser satisfies `f = 0`), and `lambda = 1e4` exceeds them for every
//! configuration whose criteria change by at least `1e-4 L` per box width. The 12 searches use the GA with half the
//! feasibility population and generations, seeded with the feasibility witness, then the polish, which works on the
//! quadratic penalty `±(t_k - min_k)/width_k + 1e9 (sum of squared terms) / L^2` (smooth, so Nelder-Mead can follow
//! the curved manifold of the state; the exact penalty makes coordinate moves stall). A result whose
//! `f` exceeds the feasibility threshold is replaced by the best configuration already known to be in the state (the
//! witness or another accepted extremal), and flagged `converged = false`.
//! Cost: 12 GA runs per feasible state, run in parallel (each deterministic).

use crate::criteria::Objective;
use crate::ga::{GaSettings, minimise_with_polish, mix_seed};
use crate::pose::{Config, ConfigBox, VARIABLE_NAMES};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Penalty factor `lambda` of eq. 11-12 (on the normalised objective).
pub const PENALTY: f64 = 1e4;

/// Quadratic penalty factor of the polish (on `sum of squares / L^2`); its minimiser violates the criteria by about
/// `1 / (2 SMOOTH_PENALTY)` relative, far below the feasibility threshold.
pub const SMOOTH_PENALTY: f64 = 1e9;

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
    /// `f(t)` of eq. 8 there (below the feasibility threshold).
    pub objective: f64,
    /// Whether the optimiser's own result was accepted (otherwise a known configuration of the state stands in).
    pub converged: bool,
}

/// The 12 extremals of a state known to be feasible at `witness` (objective `witness_value`), searched in `bounds`.
pub fn extremals(
    objective: &Objective<'_>,
    bounds: &ConfigBox,
    witness: Config,
    threshold: f64,
    settings: &GaSettings,
) -> Vec<Extremal> {
    let length = objective.weights.length;
    let ga = GaSettings {
        population: (settings.population / 2).max(8),
        generations: (settings.generations / 2).max(2),
        polish_evaluations: (settings.polish_evaluations / 2).max(100),
        seed: settings.seed,
    };
    let jobs: Vec<(usize, bool)> = (0..6).flat_map(|k| [(k, false), (k, true)]).collect();
    let found: Vec<(usize, bool, Config, f64, bool)> = jobs
        .par_iter()
        .map(|&(k, upper)| {
            let width = bounds.width(k);
            if width <= 0.0 {
                return (k, upper, witness, objective.value(&witness), true);
            }
            let sign = if upper { -1.0 } else { 1.0 };
            let g = |t: &Config| sign * (t[k] - bounds.min[k]) / width + PENALTY * objective.value(t) / length;
            // the polish follows the state's manifold better on a smooth (quadratic) penalty
            let smooth = |t: &Config| {
                sign * (t[k] - bounds.min[k]) / width + SMOOTH_PENALTY * objective.smooth_value(t) / (length * length)
            };
            let mut edge = witness;
            edge[k] = if upper { bounds.max[k] } else { bounds.min[k] };
            let s = GaSettings { seed: mix_seed(settings.seed, 1000 + 2 * k as u64 + upper as u64), ..ga };
            let m = minimise_with_polish(&g, &smooth, bounds, &s, &[witness, edge]);
            let f = objective.value(&m.t);
            (k, upper, m.t, f, f <= threshold)
        })
        .collect();
    // fall back to the best known configuration of the state for searches that did not converge
    let mut known: Vec<Config> = vec![witness];
    known.extend(found.iter().filter(|x| x.4).map(|x| x.2));
    found
        .into_iter()
        .map(|(k, upper, t, f, ok)| {
            let (t, f) = if ok {
                (t, f)
            } else {
                let pick = known
                    .iter()
                    .copied()
                    .max_by(|a, b| {
                        let (x, y) = if upper { (a[k], b[k]) } else { (-a[k], -b[k]) };
                        x.total_cmp(&y)
                    })
                    .unwrap_or(witness);
                (pick, objective.value(&pick))
            };
            Extremal {
                variable: k,
                name: VARIABLE_NAMES[k].to_string(),
                upper,
                value: t[k],
                t,
                objective: f,
                converged: ok,
            }
        })
        .collect()
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
