//! States from configurations: the contact state that holds at a configuration found anywhere (a sampled
//! configuration pushed into contact, a GA minimum, an extremal, a configuration the strict check rejected as another
//! state), verified strictly there.
//!
//! The bottom-up generation of \[P\] grows states one PPC at a time, which cannot reach a state that the bounds force
//! several contacts into at once (translation only: a vertex on the floor is the whole face on it). Every
//! configuration the generation meets is therefore classified ([`Manifolds::state_at`]); a state not yet feasible is
//! checked there ([`Manifolds::verify`], after a projection onto its own manifold when the configuration is not on it
//! to `EXACT_RESIDUAL`), and becomes feasible with that configuration as its witness.
//!
//! *Sampling* ([`contact_samples`]): seeded configurations uniform in the box, each moved along a random direction
//! (scaled by the box widths) until the parts touch: bisection (60 halvings) on the growth-distance penetration between
//! the free start and the first penetrating point of the ray inside the box. Cost per sample: at most 61 penetration
//! evaluations. Deterministic: sample `i` draws from its own generator (`mix_seed(seed, i)`), in parallel.

use crate::criteria::penetration;
use crate::ga::{SplitMix64, mix_seed};
use crate::manifold::Manifolds;
use crate::pose::{Config, ConfigBox, Pose};
use crate::principal_contact::ContactState;
use rayon::prelude::*;

/// Halvings of the bisection that finds first contact along a ray.
const BISECTIONS: usize = 60;

/// Configurations in `bounds` where the parts touch: `samples` seeded starts pushed along random directions into
/// contact (see the module documentation). Starts that penetrate, and rays that leave the box without contact, give
/// nothing.
pub fn contact_samples(manifolds: &Manifolds<'_>, bounds: &ConfigBox, samples: usize, seed: u64) -> Vec<Config> {
    let (a, b) = (manifolds.fixed, manifolds.moving);
    let pen = |t: &Config| penetration(a, b, &Pose::from_config(t));
    (0..samples)
        .into_par_iter()
        .filter_map(|i| {
            let mut rng = SplitMix64::new(mix_seed(seed, i as u64));
            let mut t0 = [0.0; 6];
            for (k, x) in t0.iter_mut().enumerate() {
                *x = rng.range(bounds.min[k], bounds.max[k]);
            }
            if pen(&t0) > 0.0 {
                return None;
            }
            let mut u = [0.0; 6];
            for (k, x) in u.iter_mut().enumerate() {
                *x = rng.normal() * bounds.width(k);
            }
            let mut s_max = f64::INFINITY;
            for k in 0..6 {
                if u[k] > 0.0 {
                    s_max = s_max.min((bounds.max[k] - t0[k]) / u[k]);
                } else if u[k] < 0.0 {
                    s_max = s_max.min((bounds.min[k] - t0[k]) / u[k]);
                }
            }
            let at = |s: f64| {
                let mut t = t0;
                for k in 0..6 {
                    t[k] += s * u[k];
                }
                bounds.clamp(&mut t);
                t
            };
            if !(s_max.is_finite() && pen(&at(s_max)) > 0.0) {
                return None;
            }
            let (mut lo, mut hi) = (0.0, s_max);
            for _ in 0..BISECTIONS {
                let mid = 0.5 * (lo + hi);
                if pen(&at(mid)) > 0.0 {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            Some(at(lo))
        })
        .collect()
}

/// The state holding at `t` with a strict witness: `t` itself, or its projection onto that state's manifold (a
/// sampled or extremal configuration is in contact only to the bisection's or the search's accuracy). `None` when
/// nothing is in contact or neither passes the strict check.
pub fn state_with_witness(manifolds: &Manifolds<'_>, t: &Config, bounds: &ConfigBox) -> Option<(ContactState, Config)> {
    let state = manifolds.state_at(t);
    if state.pcs.is_empty() {
        return None;
    }
    if manifolds.verify(&state, t, bounds).is_ok() {
        return Some((state, *t));
    }
    let p = manifolds.project(&state, t, bounds, &[false; 6])?;
    // the projection may move onto further contacts: the state there is the one verified
    let at_p = manifolds.state_at(&p);
    (manifolds.verify(&at_p, &p, bounds).is_ok()).then_some((at_p, p))
}
