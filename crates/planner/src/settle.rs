//! Settling a released part: the vertical drop from the position the search found, where the robot releases the
//! part, to where it comes to rest (\[A\] VII-B; `docs/algorithms.md`, "Stability, grasp and insertion").
//!
//! **Why.** With the seed's clearance for robot positioning error ("the parts are separated in the plane by at least
//! 5 mm", \[A\] VII-B, grown as in eq. 10-11) an obstacle face of unit normal `n` moves out by `delta |n_xy|`. A
//! horizontal face does not move, so a part resting on a flat top rests exactly; an upward-facing *inclined* face
//! (the walls a Triangle part nests on) is lifted by `delta |n_xy| / n_z`, and the search's optimum floats that
//! far above its support. That is where the robot lets go; the part then drops straight down until it touches.
//! The plan records the resting position (what the stack is, what the checks and every later part see) and the
//! drop (the release height above it), lowered to the least that keeps the clearance ([`lowest_release`]: the
//! search's optimum of a cell can also float above what holds it).
//!
//! **The drop.** For the moving component `A_i` and a stack component `B_j` with zero-clearance c-space obstacle
//! `C_ij = {n_k . p <= d_k}` (\[A\] App. B, from the shared [`ObstacleCache`]), the downward ray `q(s) = p - s z`
//! lies in the interior of `C_ij` (by more than the tolerance, the search's test) iff for every face
//! `n_k . p - s n_{k,z} < d_k - tol`: a lower bound on `s` for faces with `n_{k,z} > 0`, an upper bound for
//! `n_{k,z} < 0`, a fixed test for vertical faces. The ray enters at `s_ij = max(0, max lower bounds)` when that is
//! below every upper bound and the vertical faces hold. The floor stops the part at `s_floor = p_z + min_v (R v)_z`.
//! The drop is `g = min(s_floor, min_ij s_ij)`, so `p - g z` touches what stopped it and no obstacle's interior is
//! crossed on the way (the segment is free, so a part insertable from above stays insertable). A drop of at most the
//! tolerance is none: the position is kept bit for bit.
//!
//! **Contacts.** After a drop, the contacts are what stopped the part: every pair whose entry is within the tolerance
//! of `g` (with the kind of the face it enters through) and the floor if it is; the release position's active
//! constraints (side faces held at the clearance) no longer touch.
//!
//! **Resting parts.** The drop is the least stop, so a stop within the tolerance (the floor, or a pair the ray enters
//! at once) decides "no drop" without the other pairs: the pairs whose boxes touch at a moving component's bottom
//! (where a part released on a flat top rests) are probed first, and the full pass also ends at such a stop. The
//! result is the full pass's (an obstacle that cannot be built among the pairs not visited is then not reported).
//! In the 15-part Complex plan at w = 0.9 (128 candidates, most of them resting where released) this takes settling
//! from 370 M to 110 M instructions.
//!
//! Cost: O(m + s) for the whole part's box against the `s` stack components (`m` moving components), then O(m k)
//! box tests against the `k` under it, plus O(sum of the faces of the pairs whose xy boxes overlap) and the construction of
//! any of their obstacles the search did not build.

use crate::detect::StackScene;
use crate::obstacles::DerivedObstacle;
use crate::request::PlacementError;
use crate::search::Contact;
use glam::{DMat3, DVec3};
use stackplan_cspace::ObstacleCache;
use stackplan_geom::Part;

/// A settled position.
#[derive(Debug, Clone, PartialEq)]
pub struct Settled {
    /// The resting position (`release - drop z`).
    pub position: DVec3,
    /// The drop from the release position (mm, `>= 0`; exactly 0 when the part rests where it is released).
    pub drop: f64,
    /// What stopped the drop (`None` when there was no drop: the search's contacts stand).
    pub contacts: Option<Vec<Contact>>,
}

/// Where the downward ray from `p` first touches the convex set `{n_k . q <= d_k}` on its way into the interior
/// (the interior by more than `tol`, the search's interference test), if it enters it: `(s, k)` with `k` the face it
/// enters through (`None` when `p` is already inside). The ray enters iff the open interval of `s` where every
/// `n_k . q(s) < d_k - tol` is not empty; `s` itself is the exact touching value `max(0, max_k (n_k . p - d_k) /
/// n_{k,z})` over the faces with `n_{k,z} > 0`, so the settled part touches and does not sink by the tolerance.
/// The c-space obstacle of the moving part's component `mi` (turned by `rotation`) against the stack component `sc`,
/// from the shared cache; a failure names the pair.
fn stack_obstacle(
    cache: &ObstacleCache,
    mi: usize,
    component: &stackplan_geom::ConvexPolytope,
    rotation: DMat3,
    sc: &crate::detect::StackComponent,
) -> Result<std::sync::Arc<stackplan_cspace::Obstacle>, PlacementError> {
    cache.get_or_build(mi, sc.part, sc.piece, component, rotation, &sc.world).map_err(|e| PlacementError::Obstacle {
        moving_piece: mi,
        fixed_part: sc.part,
        fixed_piece: sc.piece,
        reason: e.to_string(),
    })
}

fn ray_entry(planes: impl Iterator<Item = (DVec3, f64)>, p: DVec3, tol: f64) -> Option<(f64, Option<usize>)> {
    // vertical component below which a face counts as vertical: its bound would lie beyond any stack
    const VERTICAL: f64 = 1e-12;
    let (mut touch, mut entry_face) = (0.0f64, None);
    let (mut inner_lower, mut inner_upper) = (0.0f64, f64::INFINITY);
    for (k, (n, d)) in planes.enumerate() {
        let gap = n.dot(p) - d;
        if n.z > VERTICAL {
            let s = gap / n.z;
            if s > touch {
                touch = s;
                entry_face = Some(k);
            }
            inner_lower = inner_lower.max((gap + tol) / n.z);
        } else if n.z < -VERTICAL {
            inner_upper = inner_upper.min((gap + tol) / n.z);
        } else if gap + tol >= 0.0 {
            return None;
        }
    }
    (inner_lower < inner_upper).then_some((touch, entry_face))
}

/// Settles the part released at `release` with `rotation` among the stack `scene` (see the module documentation).
/// `cache` is the plan's obstacle cache (keys: moving piece, stack part, stack piece, rotation bits); `tol` the
/// search's linear tolerance. `Err` names the pair whose obstacle could not be built.
pub fn settle(
    part: &Part,
    rotation: DMat3,
    release: DVec3,
    scene: &StackScene,
    cache: &ObstacleCache,
    tol: f64,
) -> Result<Settled, PlacementError> {
    let lowest = part.all_vertices().map(|v| (rotation * v).z).fold(f64::INFINITY, f64::min);
    let floor_drop = release.z + lowest;
    let resting = Settled { position: release, drop: 0.0, contacts: None };
    // the drop is the least stop, so one stop within the tolerance settles it: no drop (the floor, or below the
    // pairs that touch at a component's bottom, probed first: most parts rest on a flat top where released)
    if floor_drop <= tol {
        return Ok(resting);
    }
    // the moving components' boxes at the release position (as `stackplan_cspace::PlacedConvex::new` computes them, without building
    // the rest of the placed component: only the boxes are needed here)
    let boxes: Vec<(DVec3, DVec3)> = part
        .components()
        .iter()
        .map(|component| {
            let mut world = component.vertices().iter().map(|v| rotation * *v + release);
            let first = world.next().unwrap_or(DVec3::ZERO);
            world.fold((first, first), |(lo, hi), v| (lo.min(v), hi.max(v)))
        })
        .collect();
    let stop = |mi: usize, sc: &crate::detect::StackComponent| -> Result<Option<(f64, Contact)>, PlacementError> {
        let component = &part.components()[mi];
        let obstacle = stack_obstacle(cache, mi, component, rotation, sc)?;
        let planes = obstacle.planes().map(|pl| (pl.normal, pl.offset));
        let Some((s, face)) = ray_entry(planes, release, tol) else {
            return Ok(None);
        };
        let face_kind = face.map_or("interior", |k| obstacle.face_kinds()[k].name()).to_string();
        Ok(Some((s, Contact::Stack { our_component: mi, stack_part: sc.part, stack_component: sc.piece, face_kind })))
    };
    // only what lies under the component's xy box and starts below its top can stop it
    let under = |(lo, hi): (DVec3, DVec3), sc: &crate::detect::StackComponent| {
        let (slo, shi) = sc.placed.aabb;
        slo.x < hi.x + tol && lo.x < shi.x + tol && slo.y < hi.y + tol && lo.y < shi.y + tol && slo.z < hi.z
    };
    // broad phase: a stack component under some moving component's box is under the whole part's box (the test is
    // monotone in the box), so the per-component tests below run over this list, in the scene's order
    let whole = boxes.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), b| (lo.min(b.0), hi.max(b.1)));
    let nearby: Vec<&crate::detect::StackComponent> = scene.components.iter().filter(|sc| under(whole, sc)).collect();
    for (mi, &moving) in boxes.iter().enumerate() {
        for &sc in &nearby {
            if under(moving, sc)
                && (sc.placed.aabb.1.z - moving.0.z).abs() <= tol
                && stop(mi, sc)?.is_some_and(|(s, _)| s <= tol)
            {
                return Ok(resting);
            }
        }
    }
    let mut drop = floor_drop.max(0.0);
    // (drop, contact) of every stop found, filtered to the lowest at the end
    let mut stops: Vec<(f64, Contact)> = vec![(floor_drop, Contact::Floor)];
    for (mi, &moving) in boxes.iter().enumerate() {
        for &sc in &nearby {
            if !under(moving, sc) {
                continue;
            }
            let Some((s, contact)) = stop(mi, sc)? else {
                continue;
            };
            if s <= tol {
                return Ok(resting);
            }
            stops.push((s, contact));
            drop = drop.min(s);
        }
    }
    if drop <= tol {
        return Ok(resting);
    }
    let contacts = stops.into_iter().filter(|(s, _)| *s <= drop + tol).map(|(_, c)| c).collect();
    Ok(Settled { position: release - DVec3::Z * drop, drop, contacts: Some(contacts) })
}

/// The lowest point `rest + h z`, `0 <= h <= drop`, from which the robot can release the part settled at `rest` (the
/// search released it at `rest + drop z`): the part there keeps the horizontal clearance `clearance` from every stack
/// component, and with `insertion` also the path straight down to it from above (the search's clearance-grown,
/// insertion obstacles, [`DerivedObstacle::from_obstacle`]). Returns `h`, the release drop; `drop` itself when nothing
/// lower is free.
///
/// **Why.** The search's optimum of a cell can float above what holds it: beside the obstacle whose face plane
/// bounds the cell from below (the plane reaches past the face), or anywhere when the cost does not depend on the
/// height (`w = 1`). Released there, a part would drop up to 0.8 m in a 6-part Complex plan at `w = 1`; the robot can
/// let it go just above where it rests. The vertical line through the part meets each pair's obstacle (interior by more
/// than the tolerance, the search's test) in an open interval of heights, and `h` is the least height at or above the
/// rest not inside any of them, found by raising it past each interval that holds it (at most one pass per
/// interval); the segment from there up to the search's release is free of the zero-clearance obstacles (`settle`
/// dropped the part along it), so the part reaches the release point from above, as it would the search's.
///
/// Cost: the pairs whose boxes come within the clearance of the part's vertical sweep, each one obstacle from the
/// cache (usually built by the search or the settling already) and O(F) per interval.
#[allow(clippy::too_many_arguments)]
pub fn lowest_release(
    part: &Part,
    rotation: DMat3,
    rest: DVec3,
    drop: f64,
    scene: &StackScene,
    cache: &ObstacleCache,
    clearance: f64,
    insertion: bool,
    tol: f64,
) -> Result<f64, PlacementError> {
    if drop <= tol {
        return Ok(drop);
    }
    // the part's box swept from the rest up to the release, grown by the clearance horizontally
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for v in part.all_vertices() {
        let w = rotation * v + rest;
        lo = lo.min(w);
        hi = hi.max(w);
    }
    let reach = DVec3::new(clearance + tol, clearance + tol, 0.0);
    let (lo, hi) = (lo - reach, hi + reach + DVec3::Z * drop);
    let mut intervals: Vec<(f64, f64)> = Vec::new();
    for (fi, sc) in scene.components.iter().enumerate() {
        let (slo, shi) = sc.placed.aabb;
        // a stack component the segment's part never comes near horizontally, or wholly below the part at rest, holds
        // no height of the segment; without insertion neither does one wholly above the part at the search's release
        // (with insertion it does: the path down to a release passes it)
        if slo.x > hi.x || shi.x < lo.x || slo.y > hi.y || shi.y < lo.y || shi.z < lo.z - tol {
            continue;
        }
        if !insertion && slo.z > hi.z {
            continue;
        }
        for (mi, component) in part.components().iter().enumerate() {
            let raw = stack_obstacle(cache, mi, component, rotation, sc)?;
            let derived = DerivedObstacle::from_obstacle(&raw, mi, fi, clearance, true, insertion);
            if let Some(interval) = line_interval(&derived.planes, rest, tol) {
                intervals.push(interval);
            }
        }
    }
    // the least height >= 0 above the rest in no open interval: raise it past every interval that holds it
    intervals.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut h = 0.0f64;
    let mut raised = true;
    while raised {
        raised = false;
        for &(below, above) in &intervals {
            if below < h && h < above {
                h = above;
                raised = true;
            }
        }
    }
    // never above the search's own release (free by construction; rounding could put `h` a hair over it)
    Ok(if h < drop - tol { h } else { drop })
}

/// The open interval of heights `h` at which `rest + h z` lies in the interior of `{n_k . q <= d_k}` by more than
/// `tol` (`n_k . q < d_k - tol` for every plane), or `None` when the vertical line misses it.
fn line_interval(planes: &[stackplan_geom::polytope::Plane], rest: DVec3, tol: f64) -> Option<(f64, f64)> {
    const VERTICAL: f64 = 1e-12;
    let (mut below, mut above) = (f64::NEG_INFINITY, f64::INFINITY);
    for pl in planes {
        // n . (rest + h z) < d - tol  <=>  n_z h < d - tol - n . rest
        let slack = pl.offset - tol - pl.normal.dot(rest);
        if pl.normal.z > VERTICAL {
            above = above.min(slack / pl.normal.z);
        } else if pl.normal.z < -VERTICAL {
            below = below.max(slack / pl.normal.z);
        } else if slack <= 0.0 {
            return None;
        }
    }
    (below < above).then_some((below, above))
}

#[cfg(test)]
mod tests {
    use super::*;
    use stackplan_geom::Pose;
    use stackplan_geom::part::PartOrigin;
    use stackplan_geom::polytope::ConvexPolytope;

    fn cube_part(size: f64) -> Part {
        let c = ConvexPolytope::cuboid(DVec3::ZERO, DVec3::splat(size)).expect("cube");
        Part::from_components("cube", vec![c], 1.0, PartOrigin::ConvexPieces).expect("part")
    }

    #[test]
    fn ray_entry_of_a_box_from_above() {
        // the box [0,1]^3: the ray from (0.5, 0.5, 3) enters through the top at s = 2
        let planes = [
            (DVec3::X, 1.0),
            (DVec3::NEG_X, 0.0),
            (DVec3::Y, 1.0),
            (DVec3::NEG_Y, 0.0),
            (DVec3::Z, 1.0),
            (DVec3::NEG_Z, 0.0),
        ];
        let (s, face) = ray_entry(planes.into_iter(), DVec3::new(0.5, 0.5, 3.0), 0.0).expect("enters");
        assert_eq!(s, 2.0);
        assert_eq!(face, Some(4));
        // with a tolerance the touching value is kept (the interior is entered a tolerance later)
        assert_eq!(ray_entry(planes.into_iter(), DVec3::new(0.5, 0.5, 3.0), 1e-3).map(|e| e.0), Some(2.0));
        // beside the box (on a vertical face's plane): never enters the interior
        assert!(ray_entry(planes.into_iter(), DVec3::new(1.0, 0.5, 3.0), 1e-9).is_none());
        // below the box: the interval lies at negative s
        assert!(ray_entry(planes.into_iter(), DVec3::new(0.5, 0.5, -1.0), 0.0).is_none());
    }

    #[test]
    fn a_cube_released_above_another_drops_onto_it_and_one_beside_it_to_the_floor() {
        let part = cube_part(10.0);
        let stack = [(&part, Pose { rotation: DMat3::IDENTITY, position: DVec3::ZERO })];
        let scene = StackScene::new(&stack);
        let cache = ObstacleCache::new();
        let tol = 1e-9 * 20.0;
        // above the placed cube, 7 mm over its top
        let s = settle(&part, DMat3::IDENTITY, DVec3::new(2.0, 3.0, 17.0), &scene, &cache, tol).expect("settles");
        assert!((s.drop - 7.0).abs() <= 1e-12, "drop {}", s.drop);
        assert!((s.position - DVec3::new(2.0, 3.0, 10.0)).length() <= 1e-12);
        let contacts = s.contacts.expect("dropped");
        assert!(
            matches!(&contacts[..], [Contact::Stack { stack_part: 0, face_kind, .. }] if face_kind == "face_face"),
            "{contacts:?}"
        );
        // beside it (touching its side face): down to the floor
        let s = settle(&part, DMat3::IDENTITY, DVec3::new(10.0, 0.0, 4.0), &scene, &cache, tol).expect("settles");
        assert_eq!(s.drop, 4.0);
        assert_eq!(s.contacts, Some(vec![Contact::Floor]));
        // already resting: kept bit for bit
        let p = DVec3::new(1.0 / 3.0, 0.1, 10.0);
        let s = settle(&part, DMat3::IDENTITY, p, &scene, &cache, tol).expect("settles");
        assert_eq!((s.position, s.drop, s.contacts), (p, 0.0, None));
    }

    /// A cube released 50 mm above the floor beside another, 2 mm from it: with a clearance of 5 mm it must be let go
    /// above the other cube's top (10 mm), with 1 mm at the floor; with insertion or without, and never above the
    /// search's own release.
    #[test]
    fn the_lowest_release_keeps_the_clearance_and_no_more() {
        let part = cube_part(10.0);
        let stack = [(&part, Pose { rotation: DMat3::IDENTITY, position: DVec3::ZERO })];
        let scene = StackScene::new(&stack);
        let cache = ObstacleCache::new();
        let tol = 1e-9 * 20.0;
        let rest = DVec3::new(12.0, 0.0, 0.0);
        for insertion in [true, false] {
            let h = lowest_release(&part, DMat3::IDENTITY, rest, 50.0, &scene, &cache, 5.0, insertion, tol).expect("h");
            // (touching within the tolerance is free, as in the search)
            assert!((h - 10.0).abs() <= 2.0 * tol, "insertion {insertion}: release {h} above the rest, not 10");
            let h = lowest_release(&part, DMat3::IDENTITY, rest, 50.0, &scene, &cache, 1.0, insertion, tol).expect("h");
            assert_eq!(h, 0.0, "insertion {insertion}: 2 mm apart keeps a 1 mm clearance at rest");
            // the search released it lower than the clearance allows: its own release stands
            let h = lowest_release(&part, DMat3::IDENTITY, rest, 6.0, &scene, &cache, 5.0, insertion, tol).expect("h");
            assert_eq!(h, 6.0);
        }
        // a cube resting on top of the other, released 30 mm above: it can be let go where it rests
        let on_top = DVec3::new(1.0, 2.0, 10.0);
        let h = lowest_release(&part, DMat3::IDENTITY, on_top, 30.0, &scene, &cache, 5.0, true, tol).expect("h");
        assert_eq!(h, 0.0);
    }

    #[test]
    fn a_wedge_released_above_a_v_groove_drops_until_it_touches_both_walls() {
        // a V groove of two slabs inclined at 45 degrees and a square bar turned 45 degrees about x (a diamond):
        // released above the groove, the diamond drops until its lower faces rest on both walls
        let wall = |sign: f64| {
            let pts: Vec<DVec3> = [(0.0, 0.0), (sign * 20.0, 20.0), (sign * 22.0, 18.0), (sign * 2.0, -2.0)]
                .iter()
                .flat_map(|&(y, z)| [DVec3::new(0.0, y, z + 2.0), DVec3::new(10.0, y, z + 2.0)])
                .collect();
            stackplan_geom::convex_hull(&pts).expect("wall").polytope
        };
        let groove = Part::from_components("groove", vec![wall(1.0), wall(-1.0)], 1.0, PartOrigin::ConvexPieces)
            .expect("groove");
        let bar = cube_part(4.0);
        let stack = [(&groove, Pose { rotation: DMat3::IDENTITY, position: DVec3::ZERO })];
        let scene = StackScene::new(&stack);
        let cache = ObstacleCache::new();
        let rotation = DMat3::from_rotation_x(std::f64::consts::FRAC_PI_4);
        // the bar's lowest edge (its local y = 0, z = 0 edge stays at the origin) centred over the groove
        let release = DVec3::new(3.0, 0.0, 30.0);
        let s = settle(&bar, rotation, release, &scene, &cache, 1e-9 * 40.0).expect("settles");
        // resting, the bar's two lower faces lie on the walls' upper faces (the planes y = z - 2 and -y = z - 2
        // through the groove's apex at z = 2): the bar's lowest edge is at the apex
        assert!((s.position.z - 2.0).abs() <= 1e-9, "rest z {}", s.position.z);
        assert!((s.drop - 28.0).abs() <= 1e-9);
        let contacts = s.contacts.expect("dropped");
        assert_eq!(contacts.len(), 2, "{contacts:?}");
    }
}
