//! One candidate of a placement search tested on the stack placed so far (module documentation of
//! [`crate::stack_plan`], step 3): settled where it comes to rest (`settle.rs`), then the new part's verdicts
//! (statically stable on its supports, the whole stack stable, a suction face for the cup, insertable from above),
//! the lowest release that keeps the clearance, and the horizontal clearance at that release as `stackplan check`
//! measures it.
//!
//! Cost: one settle (O(stack components) box tests plus the obstacles of the pairs under the part) and the
//! incremental checks of [`GrowingStack`] (the placed parts are not checked again).

use super::floor::sides_of_floor;
use super::{PlanError, PlanOptions, PlanStats};
use crate::detect::StackScene;
use crate::orientation::Orientation;
use crate::request::{Cost, FloorVolume};
use crate::search::Placement;
use crate::settle::{lowest_release, settle};
use glam::DMat3;
use stackplan_cspace::cache::ObstacleCache;
use stackplan_geom::Part;
use stackplan_stability::equilibrium::Verdict as Equilibrium;
use stackplan_stability::growing::{GrowingStack, Rejection};
use stackplan_stability::world::PlacedPart;

/// What a candidate is tested with.
pub(super) struct Candidate<'t> {
    pub(super) part: &'t Part,
    pub(super) rests: &'t [DMat3],
    pub(super) options: &'t PlanOptions,
    pub(super) cache: &'t ObstacleCache,
    pub(super) tol: f64,
    pub(super) cost: &'t Cost,
    /// Stage 1's clipped floor, whose sides are walls only where they lie on the plan's floor's sides.
    pub(super) searched_floor: Option<&'t FloorVolume>,
}

/// A tested candidate: where it rests, the robot's release height above that, and the verdict.
#[derive(Debug)]
pub(super) struct Tested {
    /// The settled placement (its cost and contacts at the resting position).
    pub(super) placement: Placement,
    /// The drop from the release position (mm).
    pub(super) release_drop: f64,
    pub(super) verdict: Verdict,
}

/// Whether a candidate passed.
#[derive(Debug)]
pub(super) enum Verdict {
    /// Every test passed; the radius of the largest suction disc on its grasp face (mm).
    Passed { grasp_radius: f64 },
    /// Rejected, with the reason a plan that ends here gives.
    Rejected(String),
}

impl Candidate<'_> {
    /// Tests `found` (a placement of the search over `scene`) on the stack `growing`, counting rejections in `stats`.
    pub(super) fn test(
        &self,
        found: &Placement,
        scene: &StackScene,
        growing: &mut GrowingStack<'_>,
        stats: &mut PlanStats,
    ) -> Result<Tested, PlanError> {
        let (part, options, tol) = (self.part, self.options, self.tol);
        let (mut placement, search_drop) = self.settled(found, scene)?;
        if let Some(searched) = self.searched_floor {
            placement.contacts = sides_of_floor(&placement.contacts, searched, &options.floor, tol);
        }
        let mut verdict = accept(growing, part, &placement, stats)?;
        // the lowest release above the rest that keeps the clearance (the search's may float far above it), for a
        // candidate the checks accepted (most rejected ones fail the stability test, which does not depend on the
        // release)
        let pose = placement.pose();
        let mut release_drop = search_drop;
        if matches!(verdict, Verdict::Passed { .. }) {
            release_drop = lowest_release(
                part,
                pose.rotation,
                pose.position,
                search_drop,
                scene,
                self.cache,
                options.clearance,
                options.insertion,
                tol,
            )?;
        }
        // the clearance at the release position as the plan's check measures it: at the lowered release, else
        // (should the check's measure and the search's obstacles disagree within their tolerances) at the search's
        // own
        if matches!(verdict, Verdict::Passed { .. }) && options.clearance > 0.0 {
            let placed = PlacedPart { part, pose };
            let keeps = |drop: f64, growing: &mut GrowingStack<'_>| {
                growing.keeps_clearance(placed, drop, options.clearance).map_err(|e| PlanError::Check(e.to_string()))
            };
            let mut kept = keeps(release_drop, growing)?;
            if !kept && release_drop < search_drop {
                tracing::debug!(lowered = release_drop, search_drop, "lowered release rejected by the check");
                release_drop = search_drop;
                kept = keeps(release_drop, growing)?;
            }
            if !kept {
                stats.rejected_clearance += 1;
                verdict = Verdict::Rejected(
                    "the best interference-free positions were rejected (last: closer to a placed part than the \
                     clearance)"
                        .into(),
                );
            }
        }
        Ok(Tested { placement, release_drop, verdict })
    }

    /// The candidate settled (`settle.rs`): at its resting position, with its cost there and what stopped it,
    /// and the drop from the release position.
    fn settled(&self, candidate: &Placement, scene: &StackScene) -> Result<(Placement, f64), PlanError> {
        let part = self.part;
        let pose = candidate.pose();
        let s = settle(part, pose.rotation, pose.position, scene, self.cache, self.tol)?;
        let Some(contacts) = s.contacts else {
            return Ok((candidate.clone(), 0.0));
        };
        let rest = self.rests.get(candidate.resting_pose).copied().unwrap_or(DMat3::IDENTITY);
        let quadratic =
            Orientation::without_components(part, 0, candidate.resting_pose, 0, candidate.theta, rest, self.cost)
                .quadratic;
        let settled = Placement {
            position: s.position.to_array(),
            cost: quadratic.value(&s.position.to_array()),
            contacts,
            ..candidate.clone()
        };
        Ok((settled, s.drop))
    }
}

/// The new part's verdicts on the stack placed so far. The stack passed these tests when its parts were added, so
/// only the new part is tested ([`GrowingStack::check_candidate`]: the verdicts of
/// [`stackplan_stability::check_added_part`]'s report that matter here, in this order, up to the first that fails).
fn accept(
    growing: &mut GrowingStack<'_>,
    part: &Part,
    candidate: &Placement,
    stats: &mut PlanStats,
) -> Result<Verdict, PlanError> {
    let pose = candidate.pose();
    let tested = growing.check_candidate(PlacedPart { part, pose }).map_err(|e| PlanError::Check(e.to_string()))?;
    if let Err(
        Rejection::NotStable(Equilibrium::Unknown(status)) | Rejection::StackNotStable(Equilibrium::Unknown(status)),
    ) = &tested
    {
        // never read as stable, but not a proof either: counted apart so the plan says so
        stats.undecided_verdicts += 1;
        tracing::warn!(status, position = ?pose.position, "equilibrium undecided for a candidate: rejected as not stable");
    }
    let (reason, count) = match tested {
        Ok(accepted) => return Ok(Verdict::Passed { grasp_radius: accepted.grasp_radius }),
        Err(Rejection::NotStable(_)) => ("not stable on its supports", &mut stats.rejected_not_stable),
        Err(Rejection::StackNotStable(_)) => ("the stack would not be stable", &mut stats.rejected_stack_not_stable),
        Err(Rejection::NotGraspable) => ("no suction face for the cup", &mut stats.rejected_not_graspable),
        Err(Rejection::NotInsertable(_)) => {
            ("cannot be lowered straight down into place", &mut stats.rejected_not_insertable)
        }
    };
    *count += 1;
    Ok(Verdict::Rejected(format!("the best interference-free positions were rejected (last: {reason})")))
}
