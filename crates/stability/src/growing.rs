//! A stack that grows one part at a time, and the stacking planner's test of a candidate for its next part (\[A\]
//! II-B, the "test" of generate-and-test: conditions (ii)-(iv) for the new part, \[A\] Fig. 1).
//!
//! [`crate::check_added_part`] reports every field of the new part's check; a planner tests many candidates per
//! part and needs only the verdict. [`GrowingStack::check_candidate`] gives the verdict of the conditions the planner
//! reads, in the planner's order, and stops at the first that fails:
//!
//! 1. **stable** on its supports (the stack fixed, [`crate::equilibrium`], verdict only);
//! 2. **stack stable** with the part added (the step group of [`crate::addition`], verdict only);
//! 3. **graspable** (a suction face for the cup, [`crate::grasp`]);
//! 4. **insertable** straight down ([`crate::insertion`]).
//!
//! Each verdict is the one `check_added_part` reports for the stack plus the candidate (the same code on the same
//! world coordinates, contacts and tolerance), under its precondition that the stack passed. What is kept between
//! candidates, and why the answers do not change:
//!
//! * the placed parts in world coordinates and their box (they never move); the tolerance of stack plus candidate is
//!   computed from the box exactly as [`crate::world::stack_tolerance`] does (a minimum and a maximum do not round);
//! * the contacts among the placed parts, per tolerance: the analysis of a stack is that of the stack without its
//!   last part followed by the last part's ([`crate::contacts::contacts_of_part`]), so only the candidate's contacts
//!   are computed per candidate;
//! * one memo of rigid-body equilibrium answers ([`SolveCache`], exact keys) for the whole plan: the support-tree
//!   edges the candidate does not load recur from candidate to candidate and from part to part;
//! * the candidates found not stable on their supports (test 1), by part, rotation, position and tolerance (exact
//!   bits): the planner meets the same free positions again part after part, and most are rejected so. Test 1 sees
//!   only the candidate's contacts (with the floor, and with the placed parts whose boxes meet its box grown by the
//!   tolerance: [`crate::contacts::contacts_of_part`]'s box test) and keeps only the contacts of the candidate, the
//!   one movable part. So while no part placed since meets its grown box, the same candidate at the same tolerance
//!   has the same contacts, the same equilibrium problem and the same verdict, and the memo answers it without
//!   computing its contacts;
//! * the grasp per part and rotation: the grasp of a part depends on its own material only, so a translated copy
//!   has the same largest inscribed radius up to rounding (and the tolerance's last digits). A memoised radius
//!   decides the verdict only when it is farther than [`GRASP_BAND`] (relative to the cup radius) from the cup
//!   radius; otherwise, and always for a candidate that passes every test (whose radius the plan records), the
//!   grasp is analysed at the candidate's own pose, as `check_added_part` does.
//!
//! The equilibrium verdicts are verdict-only solves, so an admissible force distribution certifies stability without
//! the minimum-norm SOCP (the vertical certificates of [`crate::equilibrium`]); a verdict can then differ from
//! `check_added_part`'s only where that one was `Unknown` (the solver ended with another status) and a certificate
//! exists. Interference and clearance are not tested (the placement search guarantees them; `check_added_part`
//! reports them).
//!
//! Cost per candidate: the candidate in world coordinates, its contacts (box tests against the placed parts, a
//! separating-axis test per component pair whose boxes meet), one equilibrium verdict of the part on its supports and
//! one of its step group (closed forms or certificates, else an SOCP each), an insertion sweep; the contacts of the
//! placed parts once per tolerance and a grasp analysis once per rotation (plus one per accepted candidate).

use crate::StabilityError;
use crate::addition::step_group;
use crate::check::{CheckOptions, grasp_of};
use crate::contacts::{ContactAnalysis, analyse_contacts, contacts_of_part};
use crate::equilibrium::{EquilibriumOptions, SolveCache, Verdict, solve_equilibrium_with};
use crate::insertion::{Obstruction, insertion_obstruction};
use crate::world::{PlacedPart, WorldPart, aabb_overlap};
use glam::DVec3;
use stackplan_geom::Pose;
use stackplan_geom::Tolerance;
use std::collections::HashMap;

/// How far (relative to the cup radius, at least 1 mm) a memoised grasp radius must be from the cup radius to decide
/// graspability for another pose with the same rotation (see the module documentation); rounding moves the radius of
/// a translated copy by many orders of magnitude less.
pub const GRASP_BAND: f64 = 1e-4;

/// Why a candidate fails, in the order of the tests (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub enum Rejection {
    /// Not stable on its supports (the verdict).
    NotStable(Verdict),
    /// The stack with the part added would not be stable (the verdict).
    StackNotStable(Verdict),
    /// No suction face for the cup.
    NotGraspable,
    /// It cannot be lowered straight down into place.
    NotInsertable(Obstruction),
}

/// A candidate that passes every test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Accepted {
    /// Largest inscribed disc radius on an upward face (mm; the grasp analysed at the candidate's pose).
    pub grasp_radius: f64,
}

/// The length tolerance of a candidate's tests when [`CheckOptions::contact_tolerance`] is `None`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ToleranceScale {
    /// The tolerance policy for the diagonal of the box of stack plus candidate
    /// ([`crate::world::stack_tolerance`], what [`crate::check_added_part`] uses).
    #[default]
    Exact,
    /// The same diagonal rounded up to a power of two ([`power_of_two_at_least`]): between 1 and 2 times the exact
    /// tolerance. Candidates that widen the stack's box by different amounts then share a tolerance, hence the
    /// contact analysis of the placed parts (the stacking planner's choice; its 15-part Complex plan at `w = 0.1`
    /// analysed the stack 429 times with exact tolerances). The verdicts are those of [`crate::check_added_part`]
    /// with [`CheckOptions::contact_tolerance`] set to this tolerance ([`GrowingStack::tolerance_for`]).
    PowerOfTwo,
}

/// The least power of two at least `x`, exact (from the bits: the exponent raised by one unless the significand is
/// zero); `x` itself when it is a power of two, not finite, not positive, or above the largest finite power of two.
pub fn power_of_two_at_least(x: f64) -> f64 {
    const SIGNIFICAND: u64 = (1 << 52) - 1;
    if !(x.is_finite() && x > 0.0) {
        return x;
    }
    if !x.is_normal() {
        // subnormal: the smallest normal number is a power of two above it
        return f64::MIN_POSITIVE;
    }
    let bits = x.to_bits();
    if bits & SIGNIFICAND == 0 {
        return x;
    }
    let up = f64::from_bits((bits & !SIGNIFICAND) + (1 << 52));
    if up.is_finite() { up } else { x }
}

/// A stack of placed parts that only grows, with what the tests of its candidates share (see the module
/// documentation).
#[derive(Debug)]
pub struct GrowingStack<'a> {
    options: CheckOptions,
    scale: ToleranceScale,
    placed: Vec<PlacedPart<'a>>,
    world: Vec<WorldPart>,
    /// Box of the placed parts (`None` while empty).
    bounds: Option<(DVec3, DVec3)>,
    /// Contacts among the placed parts, by the bits of the tolerance they were analysed with.
    contacts: HashMap<u64, ContactAnalysis>,
    /// Largest grasp radius by part ([`stackplan_geom::Part::fingerprint`], not its address) and rotation (bits).
    grasps: HashMap<(u64, [u64; 9]), f64>,
    /// Candidates found not stable on their supports, by [`UnstableKey`]: the number of parts placed then and the
    /// verdict (see the module documentation).
    unstable: HashMap<UnstableKey, (usize, Verdict)>,
    cache: SolveCache,
}

/// A candidate's part ([`stackplan_geom::Part::fingerprint`]), rotation and position (bits) and the tolerance (bits)
/// it was tested at.
type UnstableKey = (u64, [u64; 9], [u64; 3], u64);

impl<'a> GrowingStack<'a> {
    /// An empty stack tested with `options` (friction, grasp, contact tolerance; clearance, margins and prefix
    /// stability are not used). Errors: the option errors of [`crate::check::check_stack`]; release drops are not
    /// supported.
    pub fn new(options: &CheckOptions) -> Result<Self, StabilityError> {
        if !(options.grasp.cup_diameter >= 0.0 && options.grasp.cup_diameter.is_finite()) {
            return Err(StabilityError::BadOption(format!(
                "cup diameter must be >= 0, got {}",
                options.grasp.cup_diameter
            )));
        }
        if let Some(t) = options.contact_tolerance
            && !(t >= 0.0 && t.is_finite())
        {
            return Err(StabilityError::BadOption(format!("contact tolerance must be >= 0, got {t}")));
        }
        if !options.release_drops.is_empty() {
            return Err(StabilityError::BadOption("a growing stack takes no release drops".into()));
        }
        Ok(Self {
            options: options.clone(),
            scale: ToleranceScale::Exact,
            placed: Vec::new(),
            world: Vec::new(),
            bounds: None,
            contacts: HashMap::new(),
            grasps: HashMap::new(),
            unstable: HashMap::new(),
            cache: SolveCache::new(),
        })
    }

    /// The same stack with its candidates' tolerance chosen by `scale` (see [`ToleranceScale`]; [`Self::new`]:
    /// [`ToleranceScale::Exact`]).
    pub fn with_tolerance_scale(mut self, scale: ToleranceScale) -> Self {
        self.scale = scale;
        self.contacts.clear();
        self
    }

    /// The length tolerance the tests of `candidate` use (mm): [`CheckOptions::contact_tolerance`] when set, else
    /// the policy's tolerance for the diagonal of the box of the placed parts and the candidate, rounded as
    /// [`ToleranceScale`] says. Errors: a bad pose.
    pub fn tolerance_for(&self, candidate: &PlacedPart<'_>) -> Result<f64, StabilityError> {
        let aabb = WorldPart::aabb_of(candidate, self.world.len())?;
        Ok(self.tolerance_with(&aabb))
    }

    /// The tolerance for the placed parts and a candidate with the box `aabb`.
    fn tolerance_with(&self, aabb: &(DVec3, DVec3)) -> f64 {
        match self.options.contact_tolerance {
            Some(t) => t,
            None => {
                let (lo, hi) = self.bounds_with(aabb);
                let diagonal = (hi - lo).length();
                let scale = match self.scale {
                    ToleranceScale::Exact => diagonal,
                    ToleranceScale::PowerOfTwo => power_of_two_at_least(diagonal),
                };
                Tolerance::for_scale(scale).linear
            }
        }
    }

    /// Number of placed parts.
    pub fn len(&self) -> usize {
        self.placed.len()
    }

    /// Whether no part is placed.
    pub fn is_empty(&self) -> bool {
        self.placed.is_empty()
    }

    /// The placed parts, in order.
    pub fn placed(&self) -> &[PlacedPart<'a>] {
        &self.placed
    }

    /// Places a part on the stack (the caller's accepted candidate; it is not tested again).
    pub fn push(&mut self, part: PlacedPart<'a>) -> Result<(), StabilityError> {
        let world = WorldPart::new(&part, self.world.len())?;
        self.bounds = Some(self.bounds_with(&world.aabb));
        self.world.push(world);
        self.placed.push(part);
        self.contacts.clear();
        Ok(())
    }

    fn bounds_with(&self, aabb: &(DVec3, DVec3)) -> (DVec3, DVec3) {
        let (lo, hi) = self.bounds.unwrap_or((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)));
        (lo.min(aabb.0), hi.max(aabb.1))
    }

    /// Whether `candidate` (at rest), released `release_drop` above its position, keeps the horizontal clearance
    /// `delta` from the placed parts: `check_stack`'s `clearance_met` for the last part of a plan with release drops
    /// (the same function, the part at its release position against the parts placed before it). The tolerance is
    /// the policy's for the box of the placed parts and the candidate at rest, not rounded (at most the finished
    /// stack's, whose check therefore passes too); [`CheckOptions::contact_tolerance`] when set. The placement search
    /// guarantees the clearance up to its length tolerance measured along obstacle face normals, which is longer
    /// horizontally for nearly horizontal faces; this test makes the plan's own check hold. Errors: a bad pose.
    /// O(component pairs whose boxes come within `delta`); an SOCP only for the pairs that the cheap filters of
    /// [`crate::clearance::horizontal_distance_at_least`] leave near or below `delta`.
    pub fn keeps_clearance(
        &self,
        candidate: PlacedPart<'_>,
        release_drop: f64,
        delta: f64,
    ) -> Result<bool, StabilityError> {
        if delta <= 0.0 {
            return Ok(true);
        }
        let at_rest = WorldPart::new(&candidate, self.world.len())?;
        let tol = match self.options.contact_tolerance {
            Some(t) => t,
            None => {
                let (lo, hi) = self.bounds_with(&at_rest.aabb);
                Tolerance::for_scale((hi - lo).length()).linear
            }
        };
        let released = PlacedPart {
            pose: Pose { position: candidate.pose.position + DVec3::Z * release_drop, ..candidate.pose },
            ..candidate
        };
        let released = WorldPart::new(&released, self.world.len())?;
        Ok(crate::check::clearance_of(&released, self.world.iter(), delta, tol).1)
    }

    /// Tests `candidate` as the next part (see the module documentation): `Ok(Ok(_))` when it passes, `Ok(Err(why))`
    /// at the first test it fails. The placed stack must have passed (the precondition of
    /// [`crate::check_added_part`]). Errors: a bad pose, or an equilibrium problem that cannot be set up.
    pub fn check_candidate(
        &mut self,
        candidate: PlacedPart<'_>,
    ) -> Result<Result<Accepted, Rejection>, StabilityError> {
        let last = self.world.len();
        // the candidate's box (its components are built only when the memo does not answer)
        let aabb = WorldPart::aabb_of(&candidate, last)?;
        let tol = self.tolerance_with(&aabb);
        let part = candidate.part.fingerprint();
        let key: UnstableKey = (
            part,
            candidate.pose.rotation.to_cols_array().map(f64::to_bits),
            candidate.pose.position.to_array().map(f64::to_bits),
            tol.to_bits(),
        );
        if let Some((then, verdict)) = self.unstable.get(&key)
            && self.world[*then..].iter().all(|p| !aabb_overlap(&p.aabb, &aabb, tol))
        {
            return Ok(Err(Rejection::NotStable(verdict.clone())));
        }
        let new = WorldPart::new(&candidate, last)?;
        let prefix = self.contacts.entry(tol.to_bits()).or_insert_with(|| analyse_contacts(&self.world, tol, |_| true));
        let (patches, interferences) = (prefix.patches.len(), prefix.interferences.len());
        self.world.push(new);
        contacts_of_part(&self.world, last, tol, |_| true, prefix);
        let outcome =
            test_last(&self.world, prefix, tol, &self.options, &self.cache, &mut self.grasps, candidate, part);
        prefix.patches.truncate(patches);
        prefix.interferences.truncate(interferences);
        self.world.pop();
        if let Ok(Err(Rejection::NotStable(verdict))) = &outcome {
            self.unstable.insert(key, (last, verdict.clone()));
        }
        outcome
    }
}

/// The tests of the module documentation for the last part of `parts` (contacts `analysis`).
fn test_last(
    parts: &[WorldPart],
    analysis: &ContactAnalysis,
    tol: f64,
    options: &CheckOptions,
    cache: &SolveCache,
    grasps: &mut HashMap<(u64, [u64; 9]), f64>,
    candidate: PlacedPart<'_>,
    part: u64,
) -> Result<Result<Accepted, Rejection>, StabilityError> {
    let n = parts.len();
    let last = n - 1;
    let patches = &analysis.patches;
    let verdict_only = EquilibriumOptions { verdict_only: true, ..EquilibriumOptions::new(options.mu, 0) };
    // every patch lies within the parts 0..=last: the problem of part_report's "stable on its supports"
    let alone: Vec<bool> = (0..n).map(|k| k == last).collect();
    let stable = solve_equilibrium_with(parts, &alone, patches, &verdict_only, cache)?.verdict;
    if !stable.is_stable() {
        return Ok(Err(Rejection::NotStable(stable)));
    }
    let group = step_group(n, patches, last);
    let stack_stable = solve_equilibrium_with(parts, &group, patches, &verdict_only, cache)?.verdict;
    if !stack_stable.is_stable() {
        return Ok(Err(Rejection::StackNotStable(stack_stable)));
    }
    // the grasp: a memoised radius of the same rotation decides a clear verdict; else the grasp at this pose
    let mut exact: Option<(f64, bool)> = None;
    if options.grasp.pattern.is_empty() {
        let key = (part, candidate.pose.rotation.to_cols_array().map(f64::to_bits));
        let radius = match grasps.get(&key) {
            Some(r) => *r,
            None => {
                let g = grasp_of(&parts[last], tol, &options.grasp);
                grasps.insert(key, g.0);
                exact = Some(g);
                g.0
            }
        };
        let cup = 0.5 * options.grasp.cup_diameter;
        let band = GRASP_BAND * cup.max(1.0);
        if exact.is_none() && radius < cup - band {
            return Ok(Err(Rejection::NotGraspable));
        }
        if exact.is_none() && radius < cup + band {
            exact = Some(grasp_of(&parts[last], tol, &options.grasp));
        }
    } else {
        exact = Some(grasp_of(&parts[last], tol, &options.grasp));
    }
    if exact.is_some_and(|(_, graspable)| !graspable) {
        return Ok(Err(Rejection::NotGraspable));
    }
    if let Err(obstruction) = insertion_obstruction(parts, last, tol) {
        return Ok(Err(Rejection::NotInsertable(obstruction)));
    }
    // a passing candidate: its own grasp (the radius the plan records)
    let (grasp_radius, graspable) = exact.unwrap_or_else(|| grasp_of(&parts[last], tol, &options.grasp));
    if !graspable {
        return Ok(Err(Rejection::NotGraspable));
    }
    Ok(Ok(Accepted { grasp_radius }))
}

#[cfg(test)]
mod tests {
    use super::power_of_two_at_least;

    #[test]
    fn powers_of_two_round_up_exactly() {
        assert_eq!(power_of_two_at_least(1.0), 1.0);
        assert_eq!(power_of_two_at_least(1024.0), 1024.0);
        assert_eq!(power_of_two_at_least(1024.0 + 1e-9), 2048.0);
        assert_eq!(power_of_two_at_least(f64::from_bits(1024f64.to_bits() + 1)), 2048.0);
        assert_eq!(power_of_two_at_least(f64::from_bits(1024f64.to_bits() - 1)), 1024.0);
        assert_eq!(power_of_two_at_least(0.3), 0.5);
        assert_eq!(power_of_two_at_least(745.0), 1024.0);
        assert_eq!(power_of_two_at_least(1e-320), f64::MIN_POSITIVE);
        assert_eq!(power_of_two_at_least(0.0), 0.0);
        assert_eq!(power_of_two_at_least(-3.0), -3.0);
        assert!(power_of_two_at_least(f64::NAN).is_nan());
        assert_eq!(power_of_two_at_least(f64::INFINITY), f64::INFINITY);
        assert_eq!(power_of_two_at_least(f64::MAX), f64::MAX);
        assert_eq!(power_of_two_at_least(2f64.powi(1023)), 2f64.powi(1023));
        // against the logarithm on ordinary values
        let mut x = 0.013;
        while x < 1e7 {
            let p = power_of_two_at_least(x);
            assert!(p >= x && p / 2.0 < x, "{x} -> {p}");
            assert_eq!(p.log2().fract(), 0.0);
            x *= 1.37;
        }
    }
}
