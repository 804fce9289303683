//! The whole-stack check (\[A\] II-B conditions (i)-(iv) for every part of a stack).
//!
//! For a stack `0..n` (in placement order) and every part `i`:
//!
//! * **interference**: the worst penetration depth between a component of `i` and a component of any other part or
//!   the floor (exact separating-axis depth, [`crate::contacts`]); 0 when only touching;
//! * **clearance**: the smallest horizontal distance to the other parts' components whose z-ranges overlap
//!   ([`crate::clearance`]), met when at least `clearance - tol`. With [`CheckOptions::release_drops`] (a stacking
//!   plan whose parts are released above their supports and drop into place) it is the placement clearance instead:
//!   part `i` at its release position (resting position raised by its drop) against the parts `0..i` already
//!   placed, which is what the robot's positioning error meets;
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
//! clearance test). Shortcuts that decide exactly what the plain analysis decides: equilibrium problems split into
//! groups of parts connected by part-part contacts ([`crate::equilibrium::solve_equilibrium`]); prefix `i` solves only the group that part
//! `i` joins and reuses the other groups' verdicts (`prefix_verdicts`); the grasp analysis runs once per class of
//! placements of the same part with the same rotation (it depends only on the part's own material, so a translated
//! copy has the same answer up to rounding); the per-part analyses run in parallel (rayon). Cost: dominated by the
//! SOCP solves (`n` new-part problems with margin, `n - 1` prefix step groups, the whole-stack margin).

use crate::StabilityError;
use crate::clearance::{horizontal_distance_at_least, vertically_separated};
use crate::contacts::{Body, ContactAnalysis, ContactPatch, analyse_contacts};
use crate::equilibrium::{ContactForce, Equilibrium, EquilibriumOptions, SolveCache, Verdict, solve_equilibrium_with};
use crate::grasp::{GraspOptions, grasp_faces_of_components, is_graspable};
use crate::insertion::{Obstruction, insertion_obstruction};
use crate::world::{PlacedPart, WorldPart, aabb_overlap, stack_tolerance, world_stack};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use stackplan_geom::Pose;

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
    /// Per part, how far above its position the robot releases it (mm; a plan's `release_drop`). Empty: the
    /// clearance is checked symmetrically at the given positions; otherwise each part at its release position
    /// against the parts placed before it (one entry per part).
    #[serde(default)]
    pub release_drops: Vec<f64>,
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
            release_drops: Vec::new(),
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
    check_stack_with(stack, options, false)
}

/// [`check_stack`] with every equilibrium problem solved as one SOCP per group (and one per group and direction for
/// the margins), without the support-tree split, the closed forms, the point reduction and the margin certificates
/// of [`crate::equilibrium`]: the reference those shortcuts are tested against (same verdicts, margins and forces up
/// to the solver's tolerance), several times slower.
pub fn check_stack_reference(stack: &[PlacedPart<'_>], options: &CheckOptions) -> Result<StackCheck, StabilityError> {
    check_stack_with(stack, options, true)
}

/// A stack in world coordinates with its contacts: what every per-part report reads.
pub(crate) struct Analysed {
    /// The parts in world coordinates.
    pub parts: Vec<WorldPart>,
    /// The parts at their release positions (with [`CheckOptions::release_drops`]).
    pub released: Option<Vec<WorldPart>>,
    /// The length tolerance (mm).
    pub tol: f64,
    /// Every contact patch.
    pub patches: Vec<ContactPatch>,
    /// Every interference.
    pub interferences: Vec<crate::contacts::Interference>,
}

/// Validates the options, places the parts and analyses their contacts.
pub(crate) fn analyse(stack: &[PlacedPart<'_>], options: &CheckOptions) -> Result<Analysed, StabilityError> {
    if !(options.clearance >= 0.0 && options.clearance.is_finite()) {
        return Err(StabilityError::BadOption(format!("clearance must be >= 0, got {}", options.clearance)));
    }
    if !(options.grasp.cup_diameter >= 0.0 && options.grasp.cup_diameter.is_finite()) {
        return Err(StabilityError::BadOption(format!(
            "cup diameter must be >= 0, got {}",
            options.grasp.cup_diameter
        )));
    }
    if options.margin_directions > crate::equilibrium::MAX_MARGIN_DIRECTIONS {
        return Err(StabilityError::BadOption(format!(
            "at most {} margin directions are supported, got {}",
            crate::equilibrium::MAX_MARGIN_DIRECTIONS,
            options.margin_directions
        )));
    }
    let parts = world_stack(stack)?;
    let released = if options.release_drops.is_empty() {
        None
    } else {
        if options.release_drops.len() != stack.len()
            || !options.release_drops.iter().all(|d| *d >= 0.0 && d.is_finite())
        {
            return Err(StabilityError::BadOption(format!(
                "release drops: one finite non-negative value per part ({} parts), got {:?}",
                stack.len(),
                options.release_drops
            )));
        }
        let lifted: Vec<PlacedPart<'_>> = stack
            .iter()
            .zip(&options.release_drops)
            .map(|(p, d)| PlacedPart { pose: Pose { position: p.pose.position + glam::DVec3::Z * *d, ..p.pose }, ..*p })
            .collect();
        Some(world_stack(&lifted)?)
    };
    let tol = match options.contact_tolerance {
        Some(t) if t >= 0.0 && t.is_finite() => t,
        Some(t) => return Err(StabilityError::BadOption(format!("contact tolerance must be >= 0, got {t}"))),
        None => stack_tolerance(&parts).linear,
    };
    let ContactAnalysis { patches, interferences } = analyse_contacts(&parts, tol, |_| true);
    Ok(Analysed { parts, released, tol, patches, interferences })
}

/// What a part's report takes from the stack-level analyses.
pub(crate) struct StackFacts {
    /// The part's grasp: largest inscribed radius and whether the cup fits.
    pub grasp: (f64, bool),
    /// Equilibrium of the stack `0..=i`.
    pub stack_stable: Verdict,
    /// Whether the stack `0..i` left behind when the part is lifted away is stable.
    pub remaining_stable: bool,
}

/// The report of part `i` (interference, clearance, equilibrium on fixed supports, insertion; the stack-level facts
/// given).
pub(crate) fn part_report(
    a: &Analysed,
    i: usize,
    options: &CheckOptions,
    equilibrium: &EquilibriumOptions,
    cache: &SolveCache,
    facts: StackFacts,
) -> Result<PartCheck, StabilityError> {
    let (parts, tol) = (&a.parts, a.tol);
    let n = parts.len();
    let mut interference = 0.0f64;
    let mut interferes_with = Vec::new();
    for x in &a.interferences {
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
    let (min_clear, clearance_met) = match &a.released {
        None => clearance_of(
            &parts[i],
            parts.iter().enumerate().filter(|(j, _)| *j != i).map(|(_, p)| p),
            options.clearance,
            tol,
        ),
        Some(lifted) => clearance_of(&lifted[i], parts[..i].iter(), options.clearance, tol),
    };
    let sub: Vec<ContactPatch> = a.patches.iter().filter(|p| patch_within(p, i)).cloned().collect();
    let movable: Vec<bool> = (0..n).map(|k| k == i).collect();
    let alone = solve_equilibrium_with(parts, &movable, &sub, equilibrium, cache)?;
    let (grasp_radius, graspable) = facts.grasp;
    let obstruction = insertion_obstruction(parts, i, tol).err();
    let insertable = obstruction.is_none();
    let removable = insertable && facts.remaining_stable;
    let stack_stable = facts.stack_stable;
    let ok = interferes_with.is_empty()
        && clearance_met
        && alone.verdict.is_stable()
        && stack_stable.is_stable()
        && graspable
        && insertable
        && removable;
    Ok(PartCheck {
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
    })
}

/// The grasp of part `i` alone: largest inscribed radius of an upward face and whether the cup (or pattern) fits.
pub(crate) fn grasp_of(part: &WorldPart, tol: f64, options: &GraspOptions) -> (f64, bool) {
    let faces = grasp_faces_of_components(&part.components, tol, options);
    (faces.iter().map(|f| f.inscribed_radius).fold(0.0, f64::max), is_graspable(&faces, options))
}

fn check_stack_with(
    stack: &[PlacedPart<'_>],
    options: &CheckOptions,
    reference: bool,
) -> Result<StackCheck, StabilityError> {
    let analysed = analyse(stack, options)?;
    let (parts, patches, tol) = (&analysed.parts, &analysed.patches, analysed.tol);
    let n = parts.len();
    // one memo for every equilibrium problem of the check (the reference solves everything afresh)
    let cache = SolveCache::new();
    let eq_with_margin = EquilibriumOptions {
        margins_by_socp_only: reference,
        equilibrium_by_socp_only: reference,
        ..EquilibriumOptions::new(options.mu, options.margin_directions)
    };

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
        solve_equilibrium_with(parts, &movable_all, patches, &eq_with_margin, &cache)?
    };
    let prefix_verdicts = if options.prefix_stability {
        prefix_verdicts(
            parts,
            patches,
            &whole.verdict,
            &EquilibriumOptions { directions: 0, verdict_only: true, ..eq_with_margin },
            &cache,
        )?
    } else {
        let mut v = vec![Verdict::Unknown("not checked".into()); n];
        if let Some(last) = v.last_mut() {
            *last = whole.verdict.clone();
        }
        v
    };

    // the grasp of a part depends only on the part and its rotation (its own material, translated): one analysis per
    // class of placements sharing both, at the class's first placement
    let mut grasp_class = vec![0usize; n];
    let mut representatives: Vec<usize> = Vec::new();
    for i in 0..n {
        let same = |&r: &usize| {
            std::ptr::eq(stack[r].part, stack[i].part)
                && stack[r].pose.rotation.to_cols_array() == stack[i].pose.rotation.to_cols_array()
        };
        grasp_class[i] = match representatives.iter().position(same) {
            Some(c) => c,
            None => {
                representatives.push(i);
                representatives.len() - 1
            }
        };
    }
    let grasps: Vec<(f64, bool)> =
        representatives.par_iter().map(|&r| grasp_of(&parts[r], tol, &options.grasp)).collect();
    let reports: Vec<PartCheck> = (0..n)
        .into_par_iter()
        .map(|i| {
            let facts = StackFacts {
                grasp: grasps[grasp_class[i]],
                stack_stable: prefix_verdicts[i].clone(),
                remaining_stable: i == 0 || prefix_verdicts[i - 1].is_stable(),
            };
            part_report(&analysed, i, options, &eq_with_margin, &cache, facts)
        })
        .collect::<Result<_, _>>()?;
    let ok = reports.iter().all(|r| r.ok);
    tracing::info!(parts = n, ok, "stack checked");
    Ok(StackCheck { parts: reports, stack: whole, contacts: analysed.patches, tolerance: tol, ok })
}

/// The verdicts of the prefix stacks `0..=i` (every part movable, the floor fixed); the last one is `whole`.
///
/// A prefix stack is the product of its groups of parts connected by part-part contacts (see
/// [`crate::equilibrium::solve_equilibrium`]), and a group's problem depends only on its set of parts: its contacts are among its
/// parts and with the floor, and a later part touching it would have joined it. Placing part `i` changes only the
/// group that `i` joins, so step `i` solves that group alone (the "step group" of `i`); every group of prefix `i` is
/// the step group of its highest part. Prefix `i` is unstable when one of its groups is, else unknown when one is,
/// else stable: the same decision as one solve of the whole prefix, with `n - 1` solves of (usually) small groups
/// instead of `n - 1` solves of growing prefixes. The step groups are solved in parallel.
fn prefix_verdicts(
    parts: &[WorldPart],
    patches: &[ContactPatch],
    whole: &Verdict,
    plain: &EquilibriumOptions,
    cache: &SolveCache,
) -> Result<Vec<Verdict>, StabilityError> {
    let n = parts.len();
    if n == 0 {
        return Ok(Vec::new());
    }
    // group label of every part after each step: label[k] = the highest part of k's group so far
    let mut label: Vec<usize> = (0..n).collect();
    let mut step_groups: Vec<Vec<usize>> = Vec::with_capacity(n);
    let mut labels_after: Vec<Vec<usize>> = Vec::with_capacity(n);
    for i in 0..n {
        let joined: Vec<usize> = patches
            .iter()
            .filter_map(|p| match p.a {
                Body::Part(a) if p.b == i && a < i => Some(label[a]),
                _ => None,
            })
            .collect();
        for k in 0..i {
            if joined.contains(&label[k]) {
                label[k] = i;
            }
        }
        step_groups.push((0..=i).filter(|&k| label[k] == i).collect());
        labels_after.push(label[..=i].to_vec());
    }
    let step_verdicts: Vec<Verdict> = (0..n - 1)
        .into_par_iter()
        .map(|i| {
            let group = &step_groups[i];
            let movable: Vec<bool> = (0..n).map(|k| group.contains(&k)).collect();
            let sub: Vec<ContactPatch> = patches
                .iter()
                .filter(|p| {
                    patch_within(p, i) && (group.contains(&p.b) || matches!(p.a, Body::Part(a) if group.contains(&a)))
                })
                .cloned()
                .collect();
            solve_equilibrium_with(parts, &movable, &sub, plain, cache).map(|e| e.verdict)
        })
        .collect::<Result<_, _>>()?;
    let mut out = Vec::with_capacity(n);
    for labels in labels_after.iter().take(n - 1) {
        let mut tops: Vec<usize> = labels.clone();
        tops.sort_unstable();
        tops.dedup();
        let verdicts: Vec<&Verdict> = tops.iter().map(|&t| &step_verdicts[t]).collect();
        let combined = if let Some(v) = verdicts.iter().find(|v| ***v == Verdict::Unstable) {
            (*v).clone()
        } else if let Some(v) = verdicts.iter().find(|v| !v.is_stable()) {
            (*v).clone()
        } else {
            Verdict::Stable
        };
        out.push(combined);
    }
    out.push(whole.clone());
    Ok(out)
}

/// Whether both bodies of the patch are among the floor and parts `0..=i`.
pub(crate) fn patch_within(p: &ContactPatch, i: usize) -> bool {
    p.b <= i
        && match p.a {
            Body::Floor => true,
            Body::Part(a) => a <= i,
        }
}

/// Smallest horizontal distance from `part` to the `others`' components sharing its height range, and whether it
/// meets `delta`.
pub(crate) fn clearance_of<'p>(
    part: &WorldPart,
    others: impl Iterator<Item = &'p WorldPart>,
    delta: f64,
    tol: f64,
) -> (Option<f64>, bool) {
    if delta <= 0.0 {
        return (None, true);
    }
    let mut smallest: Option<f64> = None;
    let mut unknown = false;
    for other in others {
        if !aabb_overlap(&part.aabb, &other.aabb, delta) {
            continue;
        }
        for a in &part.components {
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
