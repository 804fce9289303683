//! The whole-stack check ([A] II-B conditions (i)-(iv) for every part of a stack).
//!
//! For a stack `0..n` (in placement order) and every part `i`:
//!
//! * **interference**: the worst penetration depth between a component of `i` and a component of any other part or
//!   the floor (exact separating-axis depth, [`crate::contacts`]); 0 when only touching;
//! * **clearance**: the smallest horizontal distance to the other parts' components whose z-ranges overlap
//!   ([`crate::clearance`]), met when at least `clearance - tol`;
//! * **stable** (the new part on fixed supports): part `i` movable, the floor and parts `0..i` fixed, contacts among
//!   them ([`crate::equilibrium`]), with a margin and forces;
//! * **stack stable** (after placing `i`): the sub-stack `0..=i` with every part movable and the floor fixed. The last
//!   one is the whole stack; its margin is computed, the intermediate ones only decide stability;
//! * **graspable**: an upward face holding the cup (or pattern) ([`crate::grasp`]);
//! * **insertable**: lowered straight down with `0..i` in place ([`crate::insertion`]);
//! * **removable** (safe unstacking in reverse order): the vertical path is free and the remaining stack `0..i` is
//!   stable.
//!
//! Pruning: parts and components are paired only when their bounding boxes meet (enlarged by the clearance for the
//! clearance test). Cost: dominated by the SOCP solves (`n` new-part problems with margin, `n` prefix problems, one
//! whole-stack margin).

use crate::StabilityError;
use crate::clearance::{horizontal_distance_at_least, vertically_separated};
use crate::contacts::{Body, ContactAnalysis, ContactPatch, analyse_contacts};
use crate::equilibrium::{ContactForce, Equilibrium, EquilibriumOptions, Verdict, solve_equilibrium};
use crate::grasp::{GraspOptions, grasp_faces_of_components, is_graspable};
use crate::insertion::{Obstruction, insertion_obstruction};
use crate::world::{PlacedPart, WorldPart, aabb_overlap, stack_tolerance, world_stack};
use serde::{Deserialize, Serialize};

/// Options of [`check_stack`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CheckOptions {
    /// Coulomb friction coefficient.
    pub mu: f64,
    /// Required horizontal clearance between parts (mm); 0 disables the test.
    pub clearance: f64,
    /// Suction grasp options (cup diameter, pattern).
    pub grasp: GraspOptions,
    /// Number of horizontal directions for robustness margins (0 = none).
    pub margin_directions: usize,
    /// Overrides the contact tolerance of the policy (mm), e.g. for stacks whose positions were rounded.
    pub contact_tolerance: Option<f64>,
    /// Check stability of every intermediate stack `0..=i` (else only the whole stack).
    pub prefix_stability: bool,
}

impl Default for CheckOptions {
    fn default() -> Self {
        Self {
            mu: 0.5,
            clearance: 0.0,
            grasp: GraspOptions::default(),
            margin_directions: 8,
            contact_tolerance: None,
            prefix_stability: true,
        }
    }
}

/// The report for one part.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PartCheck {
    /// Index in the stack.
    pub index: usize,
    /// Part name.
    pub name: String,
    /// Worst penetration depth with another part or the floor (mm; 0 = none).
    pub interference: f64,
    /// The bodies it penetrates.
    pub interferes_with: Vec<Body>,
    /// Smallest horizontal distance to another part whose components share its height range (None: none closer than
    /// the required clearance, or clearance 0).
    pub min_horizontal_clearance: Option<f64>,
    /// Horizontal clearance met.
    pub clearance_met: bool,
    /// Equilibrium of the part on fixed supports (floor and parts placed before it).
    pub stable: Verdict,
    /// Its robustness margin (largest horizontal load factor resisted, worst direction).
    pub margin: Option<f64>,
    /// Its contact forces.
    pub forces: Vec<ContactForce>,
    /// Equilibrium of the stack `0..=index` with every part movable.
    pub stack_stable: Verdict,
    /// Largest inscribed disc radius on an upward face (mm, lower bound).
    pub grasp_radius: f64,
    /// A cup (or the pattern) fits.
    pub graspable: bool,
    /// Can be lowered straight down into place.
    pub insertable: bool,
    /// The deepest obstruction of the insertion path.
    pub insertion_obstruction: Option<Obstruction>,
    /// Can be lifted straight up in reverse order leaving a stable stack.
    pub removable: bool,
    /// All checks pass.
    pub ok: bool,
}

/// The report for a stack.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StackCheck {
    /// Per part.
    pub parts: Vec<PartCheck>,
    /// Equilibrium of the whole stack (every part movable), with margin and forces.
    pub stack: Equilibrium,
    /// All contact patches of the stack.
    pub contacts: Vec<ContactPatch>,
    /// The length tolerance used (mm).
    pub tolerance: f64,
    /// Every part passes.
    pub ok: bool,
}

/// Checks a stack; see the module documentation.
pub fn check_stack(stack: &[PlacedPart<'_>], options: &CheckOptions) -> Result<StackCheck, StabilityError> {
    if !(options.clearance >= 0.0 && options.clearance.is_finite()) {
        return Err(StabilityError::BadOption(format!("clearance must be >= 0, got {}", options.clearance)));
    }
    if !(options.grasp.cup_diameter >= 0.0 && options.grasp.cup_diameter.is_finite()) {
        return Err(StabilityError::BadOption(format!(
            "cup diameter must be >= 0, got {}",
            options.grasp.cup_diameter
        )));
    }
    let parts = world_stack(stack)?;
    let tol = match options.contact_tolerance {
        Some(t) if t >= 0.0 && t.is_finite() => t,
        Some(t) => return Err(StabilityError::BadOption(format!("contact tolerance must be >= 0, got {t}"))),
        None => stack_tolerance(&parts).linear,
    };
    let n = parts.len();
    let ContactAnalysis { patches, interferences } = analyse_contacts(&parts, tol, |_| true);
    let eq_with_margin = EquilibriumOptions { mu: options.mu, directions: options.margin_directions };
    let eq_plain = EquilibriumOptions { mu: options.mu, directions: 0 };

    // the whole stack, then the prefixes
    let movable_all = vec![true; n];
    let whole = if n == 0 {
        Equilibrium {
            verdict: Verdict::Stable,
            forces: Vec::new(),
            margin: None,
            weakest_direction: None,
            decided_by_precheck: false,
        }
    } else {
        solve_equilibrium(&parts, &movable_all, &patches, &eq_with_margin)?
    };
    let mut prefix_verdicts: Vec<Verdict> = Vec::with_capacity(n);
    for i in 0..n {
        if i + 1 == n {
            prefix_verdicts.push(whole.verdict.clone());
        } else if options.prefix_stability {
            let sub: Vec<ContactPatch> = patches.iter().filter(|p| patch_within(p, i)).cloned().collect();
            let movable: Vec<bool> = (0..n).map(|k| k <= i).collect();
            prefix_verdicts.push(solve_equilibrium(&parts, &movable, &sub, &eq_plain)?.verdict);
        } else {
            prefix_verdicts.push(Verdict::Unknown("not checked".into()));
        }
    }

    let mut reports = Vec::with_capacity(n);
    for i in 0..n {
        let mut interference = 0.0f64;
        let mut interferes_with = Vec::new();
        for x in &interferences {
            let other = if x.b == i {
                Some(x.a)
            } else if x.a == Body::Part(i) {
                Some(Body::Part(x.b))
            } else {
                None
            };
            if let Some(o) = other {
                interference = interference.max(x.depth);
                if !interferes_with.contains(&o) {
                    interferes_with.push(o);
                }
            }
        }
        let (min_clear, clearance_met) = clearance_of(&parts, i, options.clearance, tol);
        let sub: Vec<ContactPatch> = patches.iter().filter(|p| patch_within(p, i)).cloned().collect();
        let movable: Vec<bool> = (0..n).map(|k| k == i).collect();
        let alone = solve_equilibrium(&parts, &movable, &sub, &eq_with_margin)?;
        let faces = grasp_faces_of_components(&parts[i].components, tol, &options.grasp);
        let graspable = is_graspable(&faces, &options.grasp);
        let grasp_radius = faces.iter().map(|f| f.inscribed_radius).fold(0.0, f64::max);
        let obstruction = insertion_obstruction(&parts, i, tol).err();
        let insertable = obstruction.is_none();
        let remaining_stable = i == 0 || prefix_verdicts[i - 1].is_stable();
        let removable = insertable && remaining_stable;
        let stack_stable = prefix_verdicts[i].clone();
        let ok = interferes_with.is_empty()
            && clearance_met
            && alone.verdict.is_stable()
            && stack_stable.is_stable()
            && graspable
            && insertable
            && removable;
        reports.push(PartCheck {
            index: i,
            name: parts[i].name.clone(),
            interference,
            interferes_with,
            min_horizontal_clearance: min_clear,
            clearance_met,
            stable: alone.verdict,
            margin: alone.margin,
            forces: alone.forces,
            stack_stable,
            grasp_radius,
            graspable,
            insertable,
            insertion_obstruction: obstruction,
            removable,
            ok,
        });
    }
    let ok = reports.iter().all(|r| r.ok);
    tracing::info!(parts = n, ok, "stack checked");
    Ok(StackCheck { parts: reports, stack: whole, contacts: patches, tolerance: tol, ok })
}

/// Whether both bodies of the patch are among the floor and parts `0..=i`.
fn patch_within(p: &ContactPatch, i: usize) -> bool {
    p.b <= i
        && match p.a {
            Body::Floor => true,
            Body::Part(a) => a <= i,
        }
}

/// Smallest horizontal distance from part `i` to other parts' components sharing its height range, and whether it
/// meets `delta`.
fn clearance_of(parts: &[WorldPart], i: usize, delta: f64, tol: f64) -> (Option<f64>, bool) {
    if delta <= 0.0 {
        return (None, true);
    }
    let mut smallest: Option<f64> = None;
    let mut unknown = false;
    for (j, other) in parts.iter().enumerate() {
        if j == i || !aabb_overlap(&parts[i].aabb, &other.aabb, delta) {
            continue;
        }
        for a in &parts[i].components {
            if !aabb_overlap(&a.aabb, &other.aabb, delta) {
                continue;
            }
            for b in &other.components {
                if !aabb_overlap(&a.aabb, &b.aabb, delta) || vertically_separated(a, b, tol) {
                    continue;
                }
                match horizontal_distance_at_least(a, b, delta, tol) {
                    Some(d) if d < delta => smallest = Some(smallest.map_or(d, |s: f64| s.min(d))),
                    Some(_) => {}
                    None => unknown = true,
                }
            }
        }
    }
    let met = !unknown && smallest.is_none_or(|d| d >= delta - tol);
    (smallest, met)
}
