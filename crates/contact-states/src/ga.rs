//! Seeded real-coded genetic algorithm with a local polish: the outer optimisation of \[P\] II-D (feasibility, eq. 8)
//! and III (extremals, eq. 11-12).
//!
//! The GA (D. Goldberg 1989, as in \[P\]) keeps a population of configurations inside the search box: binary
//! tournament selection, blend crossover BLX-0.5 (each child gene uniform in the parents' interval widened by half
//! its width on both sides), Gaussian mutation of each gene with probability 1/6 and standard deviation 10 % of the
//! box width (shrinking linearly to 1 % over the generations), clamping to the box, and elitism (the two best
//! survive). Then a bounded Nelder-Mead simplex (J. Nelder, R. Mead 1965) polishes the best individual, followed by a
//! compass search with halving steps (robust on the non-smooth `|.|` terms of the criteria).
//!
//! Reproducibility: all random numbers come from SplitMix64 streams seeded from the user's seed and the generation
//! number, drawn on the calling thread in a fixed order; only the objective evaluations run in parallel (rayon,
//! results collected in index order), so the answer is identical at any thread count.
//! Cost: `population x (generations + 1)` evaluations plus at most `polish_evaluations`.

use crate::pose::{Config, ConfigBox};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// SplitMix64 (S. Vigna): a small, fast, well-mixed 64-bit generator; ours so results never depend on a crate.
#[derive(Debug, Clone)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Self { state: seed }
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in [lo, hi].
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// Standard normal (Box-Muller).
    pub fn normal(&mut self) -> f64 {
        let u1 = self.uniform().max(1e-300);
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }

    /// Uniform index below `n` (n > 0).
    pub fn below(&mut self, n: usize) -> usize {
        ((self.uniform() * n as f64) as usize).min(n.saturating_sub(1))
    }
}

/// Mixes a seed with a salt (for independent streams per generation, hypothesis, extremal).
pub fn mix_seed(seed: u64, salt: u64) -> u64 {
    SplitMix64::new(seed ^ salt.wrapping_mul(0xD1B5_4A32_D192_ED03)).next_u64()
}

/// GA settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GaSettings {
    /// Individuals per generation.
    pub population: usize,
    /// Generations after the initial one.
    pub generations: usize,
    /// Evaluation budget of the local polish.
    pub polish_evaluations: usize,
    /// Seed.
    pub seed: u64,
}

/// The largest [`GaSettings::population`] and [`GaSettings::generations`] accepted by [`GaSettings::check`].
pub const MAX_GA_SIZE: usize = 100_000;

/// The largest [`GaSettings::polish_evaluations`] accepted by [`GaSettings::check`].
pub const MAX_POLISH_EVALUATIONS: usize = 10_000_000;

/// The most GA evaluations of one search, `population x (generations + 1)`, accepted by [`GaSettings::check`]
/// (8 000 times the default 40 x 31; about 10 s of one core for the block example's objective). The two sizes alone
/// may each be up to [`MAX_GA_SIZE`], but not both.
pub const MAX_GA_EVALUATIONS: usize = 10_000_000;

/// Settings that no search can run with: a count outside its supported range, or a tolerance that is negative or not
/// finite (the name is the setting's field).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SettingsError {
    /// A count outside `min..=max`.
    #[error("{name} must lie in {min}..={max}, got {value}")]
    OutOfRange {
        /// The setting.
        name: &'static str,
        /// Its value.
        value: usize,
        /// The smallest supported value.
        min: usize,
        /// The largest supported value.
        max: usize,
    },
    /// One GA search would evaluate the objective more than [`MAX_GA_EVALUATIONS`] times.
    #[error(
        "population x (generations + 1) = {population} x ({generations} + 1) = {evaluations} GA evaluations per \
         search, more than the limit of {max}: lower population or generations"
    )]
    Effort {
        /// The population.
        population: usize,
        /// The generations.
        generations: usize,
        /// `population x (generations + 1)` (saturating).
        evaluations: usize,
        /// [`MAX_GA_EVALUATIONS`].
        max: usize,
    },
    /// The GA searches of a whole graph could evaluate the objective more than
    /// [`crate::acsg::MAX_GRAPH_EVALUATIONS`] times: checked before each level of the graph is searched, with every
    /// hypothesis of the level counted as one GA search (an upper bound: pruned hypotheses and those verified from
    /// their neighbours run none).
    #[error(
        "{hypotheses} hypotheses of level {level} x {per_search} evaluations per GA search (population x \
         (generations + 1) + polish_evaluations), after {spent} spent on the levels below, could exceed the limit of \
         {max} GA evaluations per graph: lower population, generations or polish_evaluations"
    )]
    TotalEffort {
        /// The level about to be searched.
        level: usize,
        /// Its hypotheses.
        hypotheses: usize,
        /// Evaluations of one GA search with its polish.
        per_search: usize,
        /// Evaluations spent on the lower levels.
        spent: usize,
        /// [`crate::acsg::MAX_GRAPH_EVALUATIONS`].
        max: usize,
    },
    /// A tolerance or fraction that is negative or not finite.
    #[error("{name} must be finite and >= 0, got {value}")]
    Negative {
        /// The setting.
        name: &'static str,
        /// Its value.
        value: f64,
    },
}

/// `value` within `min..=max`, else [`SettingsError::OutOfRange`] naming the setting.
pub(crate) fn check_count(name: &'static str, value: usize, min: usize, max: usize) -> Result<(), SettingsError> {
    if (min..=max).contains(&value) { Ok(()) } else { Err(SettingsError::OutOfRange { name, value, min, max }) }
}

impl GaSettings {
    /// Checks the sizes: a population of 4 to [`MAX_GA_SIZE`], at most [`MAX_GA_SIZE`] generations and
    /// [`MAX_POLISH_EVALUATIONS`] polish evaluations, and at most [`MAX_GA_EVALUATIONS`] evaluations
    /// `population x (generations + 1)` per search. [`minimise`] allocates the population it is given, so settings
    /// from users should pass this first ([`crate::generate`] checks them).
    pub fn check(&self) -> Result<(), SettingsError> {
        check_count("population", self.population, 4, MAX_GA_SIZE)?;
        check_count("generations", self.generations, 0, MAX_GA_SIZE)?;
        check_count("polish_evaluations", self.polish_evaluations, 0, MAX_POLISH_EVALUATIONS)?;
        let evaluations = self.ga_evaluations();
        if evaluations > MAX_GA_EVALUATIONS {
            return Err(SettingsError::Effort {
                population: self.population,
                generations: self.generations,
                evaluations,
                max: MAX_GA_EVALUATIONS,
            });
        }
        Ok(())
    }

    /// The objective evaluations of the GA proper, `population x (generations + 1)` (saturating).
    pub fn ga_evaluations(&self) -> usize {
        self.population.saturating_mul(self.generations.saturating_add(1))
    }

    /// The objective evaluations of one search with its polish, `population x (generations + 1) +
    /// polish_evaluations` (saturating).
    pub fn evaluations_per_search(&self) -> usize {
        self.ga_evaluations().saturating_add(self.polish_evaluations)
    }
}

impl Default for GaSettings {
    fn default() -> Self {
        Self { population: 40, generations: 30, polish_evaluations: 1200, seed: 1 }
    }
}

/// Result of a minimisation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Minimum {
    /// Best configuration.
    pub t: Config,
    /// Objective value there.
    pub value: f64,
    /// Evaluations spent.
    pub evaluations: usize,
}

/// Minimises `f` over `bounds` with the GA and the polish. `initial` individuals (clamped) join the first
/// population. Deterministic for a given `settings.seed`.
pub fn minimise<F>(f: &F, bounds: &ConfigBox, settings: &GaSettings, initial: &[Config]) -> Minimum
where
    F: Fn(&Config) -> f64 + Sync,
{
    minimise_with_polish(f, f, bounds, settings, initial)
}

/// The GA on `f`, then the polish on `smooth` (a smoother function with the same zero set, e.g. a sum of squares)
/// from the three best distinct individuals and the best of `initial`, sharing `polish_evaluations` (Nelder-Mead on `smooth` for
/// half of it, compass search on `f` for the rest); the result is the
/// polished point with the smallest `f`.
pub fn minimise_with_polish<F, G>(
    f: &F,
    smooth: &G,
    bounds: &ConfigBox,
    settings: &GaSettings,
    initial: &[Config],
) -> Minimum
where
    F: Fn(&Config) -> f64 + Sync,
    G: Fn(&Config) -> f64 + Sync,
{
    let pop_size = settings.population.max(4);
    let mut rng = SplitMix64::new(mix_seed(settings.seed, 0));
    let mut population: Vec<Config> = Vec::with_capacity(pop_size);
    for t in initial.iter().take(pop_size) {
        let mut t = *t;
        bounds.clamp(&mut t);
        population.push(t);
    }
    while population.len() < pop_size {
        let mut t = [0.0; 6];
        for k in 0..6 {
            t[k] = rng.range(bounds.min[k], bounds.max[k]);
        }
        population.push(t);
    }
    let mut values: Vec<f64> = population.par_iter().map(f).collect();
    let n_init = initial.len().min(pop_size);
    let best_initial: Option<(Config, f64)> = (0..n_init)
        .min_by(|&i, &j| values[i].total_cmp(&values[j]).then(i.cmp(&j)))
        .map(|i| (population[i], values[i]));
    let mut evaluations = pop_size;
    for g in 0..settings.generations {
        let mut rng = SplitMix64::new(mix_seed(settings.seed, g as u64 + 1));
        let mut order: Vec<usize> = (0..pop_size).collect();
        order.sort_by(|&i, &j| values[i].total_cmp(&values[j]).then(i.cmp(&j)));
        let mut next: Vec<Config> = vec![population[order[0]], population[order[1]]];
        let progress = g as f64 / settings.generations.max(1) as f64;
        let sigma = 0.1 - 0.09 * progress;
        let tournament = |rng: &mut SplitMix64| {
            let (i, j) = (rng.below(pop_size), rng.below(pop_size));
            if values[i] <= values[j] { i } else { j }
        };
        while next.len() < pop_size {
            let (pa, pb) = (tournament(&mut rng), tournament(&mut rng));
            let mut child = [0.0; 6];
            for k in 0..6 {
                let (x, y) = (population[pa][k], population[pb][k]);
                let (lo, hi) = (x.min(y), x.max(y));
                let span = hi - lo;
                child[k] = rng.range(lo - 0.5 * span, hi + 0.5 * span);
                if rng.uniform() < 1.0 / 6.0 {
                    child[k] += rng.normal() * sigma * bounds.width(k);
                }
            }
            bounds.clamp(&mut child);
            next.push(child);
        }
        let new_values: Vec<f64> = next[2..].par_iter().map(f).collect();
        evaluations += new_values.len();
        values = [values[order[0]], values[order[1]]].into_iter().chain(new_values).collect();
        population = next;
    }
    let mut order: Vec<usize> = (0..pop_size).collect();
    order.sort_by(|&i, &j| values[i].total_cmp(&values[j]).then(i.cmp(&j)));
    let mut starts: Vec<usize> = Vec::new();
    for &i in &order {
        if starts.len() == 3 {
            break;
        }
        if !starts.iter().any(|&j| population[j] == population[i]) {
            starts.push(i);
        }
    }
    let mut starts: Vec<(Config, f64)> = starts.into_iter().map(|i| (population[i], values[i])).collect();
    // also polish from the best of the caller's initial individuals (configurations of neighbouring states)
    if let Some(b) = best_initial.filter(|b| !starts.iter().any(|s| s.0 == b.0)) {
        starts.push(b);
    }
    let budget = (settings.polish_evaluations / starts.len().max(1)).max(2);
    let polished: Vec<(Config, f64, usize)> = starts
        .par_iter()
        .map(|&(t0, v0)| {
            // Nelder-Mead on the smooth function, then compass search on f itself
            let (t, _, used) = polish(smooth, bounds, t0, smooth(&t0), budget / 2);
            let v = f(&t);
            let (t, v) = if v <= v0 { (t, v) } else { (t0, v0) };
            let (t, v, more) = compass(f, bounds, t, v, budget - budget / 2);
            (t, v, used + more + 1)
        })
        .collect();
    let mut best = (population[order[0]], values[order[0]]);
    for (t, v, used) in &polished {
        evaluations += used;
        if *v < best.1 {
            best = (*t, *v);
        }
    }
    Minimum { t: best.0, value: best.1, evaluations }
}

/// Bounded Nelder-Mead from `start` (half the budget) then compass search (the rest). Returns `(t, f(t), evals)`.
pub fn polish<F>(f: &F, bounds: &ConfigBox, start: Config, start_value: f64, budget: usize) -> (Config, f64, usize)
where
    F: Fn(&Config) -> f64 + Sync,
{
    let mut evals = 0;
    let eval = |t: &Config, evals: &mut usize| {
        *evals += 1;
        f(t)
    };
    // Nelder-Mead on the box (points clamped)
    let scale: Vec<f64> = (0..6).map(|k| 0.05 * bounds.width(k)).collect();
    let mut simplex: Vec<(Config, f64)> = vec![(start, start_value)];
    for k in 0..6 {
        if scale[k] == 0.0 {
            continue;
        }
        let mut t = start;
        t[k] = if t[k] + scale[k] <= bounds.max[k] { t[k] + scale[k] } else { t[k] - scale[k] };
        let v = eval(&t, &mut evals);
        simplex.push((t, v));
    }
    let dims = simplex.len() - 1;
    while dims > 0 && evals < budget / 2 {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let worst = simplex[dims];
        let mut centroid = [0.0; 6];
        for (t, _) in &simplex[..dims] {
            for k in 0..6 {
                centroid[k] += t[k] / dims as f64;
            }
        }
        let along = |c: f64| {
            let mut t = [0.0; 6];
            for k in 0..6 {
                t[k] = centroid[k] + c * (worst.0[k] - centroid[k]);
            }
            bounds.clamp(&mut t);
            t
        };
        let reflected = along(-1.0);
        let fr = eval(&reflected, &mut evals);
        if fr < simplex[0].1 {
            let expanded = along(-2.0);
            let fe = eval(&expanded, &mut evals);
            simplex[dims] = if fe < fr { (expanded, fe) } else { (reflected, fr) };
        } else if fr < simplex[dims - 1].1 {
            simplex[dims] = (reflected, fr);
        } else {
            let contracted = along(0.5);
            let fc = eval(&contracted, &mut evals);
            if fc < worst.1 {
                simplex[dims] = (contracted, fc);
            } else {
                let best = simplex[0].0;
                for item in simplex.iter_mut().skip(1) {
                    let mut t = [0.0; 6];
                    for k in 0..6 {
                        t[k] = best[k] + 0.5 * (item.0[k] - best[k]);
                    }
                    item.1 = eval(&t, &mut evals);
                    item.0 = t;
                }
            }
        }
        let spread = simplex.iter().map(|s| s.1).fold(f64::NEG_INFINITY, f64::max) - simplex[0].1;
        if spread <= 1e-15 * (1.0 + simplex[0].1.abs()) {
            break;
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    let (best, best_value) = simplex[0];
    let (t, v, used) = compass(f, bounds, best, best_value, budget.saturating_sub(evals));
    (t, v, evals + used)
}

/// Compass search with halving steps from `start` (budget `budget`). Returns `(t, f(t), evals)`.
pub fn compass<F>(f: &F, bounds: &ConfigBox, start: Config, start_value: f64, budget: usize) -> (Config, f64, usize)
where
    F: Fn(&Config) -> f64 + Sync,
{
    let (mut best, mut best_value) = (start, start_value);
    let mut evals = 0;
    let eval = |t: &Config, evals: &mut usize| {
        *evals += 1;
        f(t)
    };
    let mut step: Vec<f64> = (0..6).map(|k| 0.02 * bounds.width(k)).collect();
    while evals < budget {
        let mut improved = false;
        for k in 0..6 {
            if step[k] <= 1e-12 * bounds.width(k).max(1e-300) {
                continue;
            }
            for dir in [1.0, -1.0] {
                let mut t = best;
                t[k] += dir * step[k];
                bounds.clamp(&mut t);
                let v = eval(&t, &mut evals);
                if v < best_value {
                    best = t;
                    best_value = v;
                    improved = true;
                    break;
                }
            }
        }
        if !improved {
            let mut any = false;
            for s in step.iter_mut() {
                *s *= 0.5;
                any |= *s > 0.0;
            }
            if step.iter().enumerate().all(|(k, s)| *s <= 1e-12 * bounds.width(k).max(1e-300)) || !any {
                break;
            }
        }
    }
    (best, best_value, evals)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere(t: &Config) -> f64 {
        t.iter().enumerate().map(|(k, x)| (x - 0.1 * k as f64).abs()).sum()
    }

    #[test]
    fn finds_the_minimum_of_a_non_smooth_bowl() {
        let b = ConfigBox::new([-5.0; 6], [5.0; 6]).expect("box");
        let m = minimise(
            &sphere,
            &b,
            &GaSettings { population: 30, generations: 20, polish_evaluations: 2000, seed: 7 },
            &[],
        );
        assert!(m.value < 1e-6, "{m:?}");
        for k in 0..6 {
            assert!((m.t[k] - 0.1 * k as f64).abs() < 1e-6);
        }
    }

    #[test]
    fn same_seed_same_answer_at_any_thread_count() {
        let b = ConfigBox::new([-5.0; 6], [5.0; 6]).expect("box");
        let f = |t: &Config| sphere(t) + (3.0 * t[0]).sin().abs();
        let s = GaSettings { population: 24, generations: 10, polish_evaluations: 100, seed: 42 };
        let one =
            rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool").install(|| minimise(&f, &b, &s, &[]));
        let three =
            rayon::ThreadPoolBuilder::new().num_threads(3).build().expect("pool").install(|| minimise(&f, &b, &s, &[]));
        assert_eq!(one, three);
        let other = minimise(&f, &b, &GaSettings { seed: 43, ..s }, &[]);
        assert_ne!(one.t, other.t);
    }

    #[test]
    fn respects_bounds() {
        let b = ConfigBox::new([1.0, 1.0, 1.0, 0.0, 0.0, 0.0], [2.0, 2.0, 2.0, 0.0, 0.0, 0.0]).expect("box");
        let m = minimise(
            &sphere,
            &b,
            &GaSettings { population: 10, generations: 5, polish_evaluations: 300, seed: 1 },
            &[],
        );
        assert!(b.contains(&m.t));
        assert!((m.t[0] - 1.0).abs() < 1e-9 && (m.t[1] - 1.0).abs() < 1e-9);
    }
}
