//! The check of one part added to a stack that passed before: the stacking planner's per-candidate test (\[A\] II-B,
//! conditions (ii)-(iv) for the new part; the step of \[A\] Fig. 1 that follows the placement search).
//!
//! A planner adds parts one at a time and tests each candidate position of the new part `n` on the stack `0..n` it
//! has accepted. It needs the new part's report only, and [`crate::check::check_stack`] would also re-check every
//! earlier part and solve the whole stack's equilibrium for its minimum-norm forces. [`check_added_part`] computes the
//! report of the last part of the stack, field for field what `check_stack` reports for it, under one
//! **precondition**: the stack without its last part is stable (every part movable, the floor fixed) — which holds
//! when each earlier addition passed.
//!
//! * **Stack stability**: the movable parts split into groups connected by part-part contacts, the stack is stable
//!   iff every group is ([`crate::equilibrium::solve_equilibrium`]), and adding part `n` changes only the group it
//!   joins (the union of the groups it touches, plus `n`: the "step group" of `crate::check`'s prefix analysis). By
//!   the precondition every other group is stable, so the stack's verdict is the step group's, solved for its verdict
//!   only (an admissible vertical force distribution certifies it without the SOCP when one exists). The verdict is
//!   the same as the whole-stack solve's; an `Unknown` status may read differently.
//! * **Removable**: the stack left when the part is lifted away is the stack `0..n`, stable by the precondition.
//! * Interference, clearance, equilibrium on fixed supports (with the margin the options ask for), grasp and
//!   insertion: exactly as in `check_stack` (the same code).
//!
//! Cost: the contact analysis of the stack (O(n) box tests per part pair that could touch), one equilibrium problem
//! of the new part on its supports, one verdict of the step group (a vertical certificate, O(M^3 + M K) for M parts
//! and K contact points, else one SOCP), the grasp of one part and one insertion sweep: no solve for any other part.

use crate::StabilityError;
use crate::check::{CheckOptions, PartCheck, StackFacts, analyse, grasp_of, part_report};
use crate::contacts::Body;
use crate::equilibrium::{EquilibriumOptions, SolveCache, Verdict, solve_equilibrium_with};
use crate::world::PlacedPart;

/// The report of the last part of `stack` (see the module documentation; the stack without it must be stable).
/// Errors: an empty stack, or the errors of [`crate::check::check_stack`].
pub fn check_added_part(stack: &[PlacedPart<'_>], options: &CheckOptions) -> Result<PartCheck, StabilityError> {
    let Some(last) = stack.len().checked_sub(1) else {
        return Err(StabilityError::BadOption("the stack has no part to check".into()));
    };
    let analysed = analyse(stack, options)?;
    let parts = &analysed.parts;
    let cache = SolveCache::new();
    let equilibrium = EquilibriumOptions::new(options.mu, options.margin_directions);
    let group = step_group(parts.len(), &analysed.patches, last);
    let movable: Vec<bool> = (0..parts.len()).map(|k| group[k]).collect();
    let verdict_only = EquilibriumOptions { directions: 0, verdict_only: true, ..equilibrium };
    let stack_stable: Verdict =
        solve_equilibrium_with(parts, &movable, &analysed.patches, &verdict_only, &cache)?.verdict;
    let facts = StackFacts {
        grasp: grasp_of(&parts[last], analysed.tol, &options.grasp),
        stack_stable,
        remaining_stable: true,
    };
    let report = part_report(&analysed, last, options, &equilibrium, &cache, facts)?;
    tracing::debug!(part = last, ok = report.ok, group = group.iter().filter(|g| **g).count(), "added part checked");
    Ok(report)
}

/// The parts connected to `last` through part-part contact patches (union-find over the patches; O(P + K alpha)).
pub(crate) fn step_group(n: usize, patches: &[crate::contacts::ContactPatch], last: usize) -> Vec<bool> {
    let mut sets = crate::union_find::UnionFind::new(n);
    for p in patches {
        if let Body::Part(a) = p.a
            && a < n
            && p.b < n
        {
            sets.union(a, p.b);
        }
    }
    let root = sets.find(last);
    (0..n).map(|k| sets.find(k) == root).collect()
}
