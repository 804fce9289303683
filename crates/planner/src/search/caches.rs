//! What successive searches of a plan share: derived obstacles, constant-topology structures, rotated components,
//! the scene and the carried frontiers.

use super::*;
use crate::detect::{DetectScratch, StackScene, SweepAxes};
use crate::interval_obstacles::{EventStore, IntervalObstacles};
use crate::obstacles::DerivedObstacle;
use crate::request::{FloorVolume, PlacementRequest, polygon_side_planes};
use std::collections::HashMap;
use std::sync::Arc;

/// What successive searches into a growing stack share beyond the [`ObstacleCache`]: the derived obstacles (insertion
/// and clearance applied) of each (orientation, pair), keyed by orientation index, the constant-topology structures
/// the obstacles are extrapolated from ([`IntervalObstacles`]) and the detection's scratch lists. They are reused
/// only while the searches place the same part (a fingerprint of its components' vertex bits) with the same
/// orientations (bit-identical rotations), the same clearance, insertion,
/// horizontal-clearance and extrapolation settings, and the previous search's stack components are the first
/// components of the new stack, bit for bit (parts appended, never moved); otherwise they are cleared. The derived
/// obstacles are pure functions of those inputs; an extrapolated obstacle depends (in its last bits) on which angle its
/// structure was built at, so a plan's results depend on its search history, deterministically.
///
/// With several partitions of the orientations ([`crate::request::SearchTuning::partitions`]) each partition keeps its own
/// caches (its orientations' derived obstacles, structures and obstacle ids).
#[derive(Debug, Default)]
pub struct SearchCaches {
    pub(super) signature: Option<CacheSignature>,
    /// Whether searches continue the open frontier of an earlier search ([`SearchCaches::carrying_frontiers`]).
    pub(super) carry: bool,
    /// One per partition.
    pub(super) lanes: Vec<LaneCaches>,
    /// The pair events of the constant-topology intervals, shared by the partitions ([`IntervalObstacles`]).
    pub(super) events: EventStore,
    /// The states of the last searches, by floor and cost, newest last (at most [`CARRIED_FRONTIERS`]).
    pub(super) frontiers: Vec<(FrontierSignature, States)>,
    /// The last search's scene and its stack's keys: a search whose stack extends that stack places only its new
    /// parts' components (a plan's stack only grows).
    pub(super) scene: Option<(Vec<SceneKey>, Arc<StackScene>)>,
}

/// A stack part as the caches compare it: a fingerprint of the part's geometry and the bits of its pose.
pub(super) type SceneKey = (u64, [u64; 12]);

/// The [`SceneKey`]s of a stack (the fingerprint computed once per distinct part).
pub(super) fn scene_keys(stack: &[crate::PlacedPart<'_>]) -> Vec<SceneKey> {
    let mut fingerprints: Vec<(*const stackplan_geom::Part, u64)> = Vec::new();
    stack
        .iter()
        .map(|s| {
            let at = std::ptr::from_ref(s.part);
            let fingerprint = match fingerprints.iter().find(|(p, _)| *p == at) {
                Some(&(_, f)) => f,
                None => {
                    let f = s.part.fingerprint();
                    fingerprints.push((at, f));
                    f
                }
            };
            let mut pose = [0u64; 12];
            for (slot, x) in
                pose.iter_mut().zip(s.pose.rotation.to_cols_array().into_iter().chain(s.pose.position.to_array()))
            {
                *slot = x.to_bits();
            }
            (fingerprint, pose)
        })
        .collect()
}

/// What one partition of the orientations keeps from search to search ([`SearchCaches`]).
#[derive(Debug, Default)]
pub(super) struct LaneCaches {
    pub(super) detect_scratch: DetectScratch,
    /// The part's components rotated, and their sweep axes (with insertion), by rotation (bits of its matrix),
    /// built at an orientation's first expansion in some search: every search of a plan expands many of the same
    /// orientations (the values are those of building them again).
    pub(super) rotated: HashMap<[u64; 9], RotatedComponents>,
    pub(super) derived: HashMap<(usize, usize, usize), Arc<DerivedObstacle>>,
    pub(super) intervals: IntervalObstacles,
    /// The derived obstacles by id (the ids the carried cells' tags and paths name).
    pub(super) table: ObstacleTable,
}

/// The part's components at one rotation ([`LaneCaches::rotated`]).
#[derive(Debug, Clone)]
pub(super) struct RotatedComponents {
    pub(super) components: Arc<[stackplan_cspace::PlacedConvex]>,
    pub(super) sweep: Option<Arc<SweepAxes>>,
}

/// How many frontiers [`SearchCaches`] keeps: the stacking planner alternates a stage-1 search (a floor that grows
/// with the stack's footprint) and a stage-2 search (the whole floor).
pub(super) const CARRIED_FRONTIERS: usize = 2;

/// The derived obstacles of a sequence of searches by id, and by orientation.
#[derive(Debug, Default)]
pub(super) struct ObstacleTable {
    pub(super) obstacles: Vec<Arc<DerivedObstacle>>,
    pub(super) ids: HashMap<(usize, usize, usize), u32>,
    pub(super) by_orientation: Vec<KnownObstacles>,
}

/// What a search's open nodes depend on beyond [`CacheSignature`]: the floor volume, the fixed height and the cost.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct FrontierSignature {
    pub(super) floor: FloorVolume,
    pub(super) searched_elsewhere: Option<Vec<glam::DVec2>>,
    pub(super) fixed_z: Option<u64>,
    pub(super) cost: String,
}

impl FrontierSignature {
    pub(super) fn of(request: &PlacementRequest<'_>) -> Self {
        Self {
            floor: request.floor.clone(),
            searched_elsewhere: request.tuning.searched_elsewhere.clone(),
            fixed_z: request.fixed_z.map(f64::to_bits),
            // `Debug` of an f64 round-trips: equal strings iff equal values
            cost: format!("{:?}", request.cost),
        }
    }

    /// Whether a frontier searched under `self` can be continued under `next`: the same cost and fixed height,
    /// `self`'s floor volume inside `next`'s (the same height; every corner of the old polygon inside the new one),
    /// so every old cell lies in the new permissible set and only the difference needs new cells
    /// (`Search::widen`), and `self`'s region searched elsewhere (if any) inside `next`'s (so the old cells cover
    /// everything `next` searches; `next` cuts its larger region out of them as they pop).
    pub(super) fn continues_into(&self, next: &Self) -> bool {
        // a footprint clipped from a slanted floor side has interpolated corners there, and a grown footprint's side
        // along the same floor side passes them only within rounding: "inside" allows 64 ulps of the polygons' size
        // (the search's own tolerance is 1e-9 of the part's size; a carried cell poking out of the new floor by that
        // much is not seen)
        let inside = |a: &[glam::DVec2], b: &[glam::DVec2]| {
            a == b || {
                let scale = a.iter().chain(b).map(|c| c.abs().max_element()).fold(1.0, f64::max);
                let slack = 64.0 * f64::EPSILON * scale;
                let sides = polygon_side_planes(b);
                a.iter().all(|&c| sides.iter().all(|&(n, d)| n.dot(c) <= d + slack))
            }
        };
        self.fixed_z == next.fixed_z
            && self.cost == next.cost
            && self.floor.height.to_bits() == next.floor.height.to_bits()
            && inside(&self.floor.polygon, &next.floor.polygon)
            && match (&self.searched_elsewhere, &next.searched_elsewhere) {
                (None, _) => true,
                (Some(_), None) => false,
                (Some(old), Some(new)) => inside(old, new),
            }
    }
}

#[derive(Debug, PartialEq)]
pub(super) struct CacheSignature {
    pub(super) rotations: Vec<[u64; 9]>,
    pub(super) clearance: u64,
    pub(super) insertion: bool,
    pub(super) horizontal: bool,
    pub(super) extrapolate: bool,
    pub(super) merge_plates: bool,
    pub(super) partitions: usize,
    /// [`stackplan_geom::Part::fingerprint`] of the part placed (the derived obstacles and structures are its components').
    pub(super) moving: u64,
    pub(super) stack: Vec<SceneKey>,
}

impl SearchCaches {
    /// Empty caches.
    pub fn new() -> Self {
        Self::default()
    }

    /// Empty caches that also carry each [`PlacementSearch`]'s state, when it is dropped, to the next search with the
    /// same fixed height and cost and a floor volume that contains its floor, into the grown stack: that search
    /// starts from the open cells and the cells found free of the earlier one (and the new strip of a grown floor,
    /// `Search::widen`) instead of the roots. Its first placement is the same exact optimum; the later ones are one
    /// per cell of a different partition of the free space, so they can differ from a fresh search's, as can the
    /// counters (a carried search evaluates only pairs no earlier search did). The stacking planner uses these.
    pub fn carrying_frontiers() -> Self {
        Self { carry: true, ..Self::default() }
    }

    /// The scene of `request`'s stack (`keys`: its [`scene_keys`]): the last search's, with the components of the
    /// parts added since, when the stack extends that search's; otherwise built afresh.
    pub(super) fn scene(&mut self, request: &PlacementRequest<'_>, keys: &[SceneKey]) -> Arc<StackScene> {
        let mut scene = match self.scene.take() {
            Some((old, scene)) if old.len() <= keys.len() && old[..] == keys[..old.len()] => scene,
            _ => Arc::new(StackScene::new(&[])),
        };
        let placed = scene.parts();
        if placed < request.stack.len() {
            let grown = Arc::make_mut(&mut scene);
            for s in &request.stack[placed..] {
                grown.push_part(s.part, s.pose);
            }
        }
        self.scene = Some((keys.to_vec(), Arc::clone(&scene)));
        scene
    }

    /// Keeps the caches when `next` extends the signature they were built under, clears them otherwise.
    pub(super) fn adopt(&mut self, next: CacheSignature) {
        let keep = self.signature.as_ref().is_some_and(|old| {
            old.rotations == next.rotations
                && old.clearance == next.clearance
                && old.insertion == next.insertion
                && old.horizontal == next.horizontal
                && old.extrapolate == next.extrapolate
                && old.merge_plates == next.merge_plates
                && old.partitions == next.partitions
                && old.moving == next.moving
                && old.stack.len() <= next.stack.len()
                && old.stack.iter().zip(&next.stack).all(|(a, b)| a == b)
        });
        if !keep {
            self.lanes.clear();
            self.frontiers.clear();
            self.events.clear();
        }
        self.lanes.resize_with(next.partitions, LaneCaches::default);
        self.signature = Some(next);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Footprints clipped from an octagonal floor and grown (stage 1 of a plan on a floor that is no rectangle):
    /// each continues the last one's frontier. With an exact test about a third of them would not (their corners on
    /// the floor's slanted sides are interpolated), and those stage-1 searches would start from the roots: the
    /// 15-part Complex plan at `w 0.1` on such a floor (circumradius 560 mm) takes 1.51 s that way instead of 1.11 s,
    /// the same plan. A polygon larger by 1e-7 mm is not inside.
    #[test]
    fn grown_footprints_on_a_slanted_floor_continue_the_last_ones_frontier() {
        let octagon: Vec<glam::DVec2> = (0..8)
            .map(|k| {
                let a = std::f64::consts::FRAC_PI_4 * k as f64 + 0.3;
                glam::DVec2::new(560.0 * a.cos(), 560.0 * a.sin())
            })
            .collect();
        let signature = |polygon: Vec<glam::DVec2>| FrontierSignature {
            floor: FloorVolume { polygon, height: 1212.0 },
            searched_elsewhere: None,
            fixed_z: None,
            cost: "stacking".into(),
        };
        let mut rng = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut lo, mut hi) = (glam::DVec2::new(-120.3, -97.1), glam::DVec2::new(101.7, 133.9));
        let mut last = signature(crate::stack_plan::floor::clip_to_rectangle(&octagon, lo, hi));
        for step in 0..200 {
            lo -= glam::DVec2::new(next(), next()) * 3.7;
            hi += glam::DVec2::new(next(), next()) * 3.7;
            let grown = signature(crate::stack_plan::floor::clip_to_rectangle(&octagon, lo, hi));
            assert!(last.continues_into(&grown), "step {step}: {:?} into {:?}", last.floor, grown.floor);
            assert!(!grown.continues_into(&last) || grown.floor.polygon == last.floor.polygon, "step {step}");
            last = grown;
        }
        // the whole floor contains every footprint; a footprint 1e-7 mm beyond it is no longer inside
        assert!(last.continues_into(&signature(octagon.clone())));
        let beyond = signature(octagon.iter().map(|c| *c * (1.0 + 1e-7 / 560.0)).collect());
        assert!(!beyond.continues_into(&signature(octagon)));
    }
}
