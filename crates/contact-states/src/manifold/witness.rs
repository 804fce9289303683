//! Interior witnesses: a configuration where exactly a state's contacts hold, searched from candidate configurations
//! by projection and seeded perturbations (see the [module documentation](super)).

use super::check::{Manifolds, Rejection};
use crate::ga::SplitMix64;
use crate::pose::{Config, ConfigBox, Pose};
use crate::principal_contact::{ContactState, PrincipalContact};

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
/// The most configurations one witness search reports as lying in another state.
pub const MAX_OTHER_STATES: usize = 16;

impl Manifolds<'_> {
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
        self.interior_witness_with(state, starts, bounds, seed, attempts, true, &mut Vec::new())
    }

    /// [`Self::interior_witness`]; with `perturb_when_apart` false the perturbations are skipped when the first
    /// projected start is rejected as `NotInContact` or `Penetrating` (for neighbours' configurations, which a GA
    /// run follows: such starts rarely lead to a witness). Configurations rejected as another state
    /// ([`Rejection::OtherState`]) are appended to `other_states` (at most `MAX_OTHER_STATES`): they are candidate
    /// witnesses of the state that holds there.
    pub fn interior_witness_with(
        &self,
        state: &ContactState,
        starts: &[Config],
        bounds: &ConfigBox,
        seed: u64,
        attempts: usize,
        perturb_when_apart: bool,
        other_states: &mut Vec<Config>,
    ) -> Result<Config, Rejection> {
        let mut note = |t: &Config, e: &Rejection| {
            if matches!(e, Rejection::OtherState { .. }) && other_states.len() < MAX_OTHER_STATES {
                other_states.push(*t);
            }
        };
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
                    note(&p, &e);
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
                    Err(e) => {
                        note(&alt, &e);
                        last = e;
                    }
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
                        Err(e) => {
                            note(&q, &e);
                            last = e;
                        }
                    }
                }
            }
        }
        Err(first.unwrap_or(last))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::criteria::tests::box_part;
    use crate::manifold::StrictTolerances;
    use crate::principal_contact::all_ppcs;
    use crate::surface::Element;
    use stackplan_geom::DVec3;

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
