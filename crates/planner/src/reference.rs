//! Brute-force references for the tests (not used by the search):
//!
//! * [`complete_optimum`]: for every orientation, the obstacles of *every* component pair, all subtracted from
//!   `Omega` (\[A\] VI-A-3), and the cost minimised over every resulting cell — the "complete c-space" method the seed
//!   compares with (section 5.2). Cells that do not meet an obstacle's interior are kept unsplit. Exponential in the
//!   number of overlapping obstacles in the worst case: small cases only.
//! * [`violations`]: an independent all-pairs check of a placement (the narrow phase of `stackplan-cspace` on every
//!   component pair through `PlacedScene::interference_pairs_brute_force`; containment in the floor volume; the
//!   vertical path for insertion), reporting every violated condition.

use crate::PlacedPart;
use crate::cell_qp::minimise;
use crate::detect::StackScene;
use crate::obstacles::DerivedObstacle;
use crate::orientation::Orientation;
use crate::request::PlacementRequest;
use glam::{DMat3, DVec3};
use stackplan_cspace::ObstacleCache;
use stackplan_cspace::interference::{PairContact, PlacedScene};
use stackplan_freespace::{Cell, Halfspace, Tag};
use stackplan_geom::{Part, Tolerance};

/// The best cost over all orientations and all cells of the complete free space (3-D `Omega` only), with the
/// orientation index (in theta-set order, resting pose 0) and position; `None` when nothing is free.
pub fn complete_optimum(request: &PlacementRequest<'_>) -> Result<Option<(f64, usize, DVec3)>, String> {
    if request.fixed_z.is_some() {
        return Err("the reference handles the 3-D permissible set only".into());
    }
    let part = request.part;
    let refs: Vec<(&Part, stackplan_geom::Pose)> = request.stack.iter().map(|s| (s.part, s.pose)).collect();
    let scene = StackScene::new(&refs);
    let mut scale = {
        let (lo, hi) = part.aabb();
        (hi - lo).length()
    };
    for s in &request.stack {
        let (lo, hi) = s.part.aabb();
        scale = scale.max((hi - lo).length());
    }
    let tol = Tolerance::for_scale(scale);
    let cache = ObstacleCache::new();
    let mut best: Option<(f64, usize, DVec3)> = None;
    for (ti, &theta) in request.thetas.iter().enumerate() {
        let o = Orientation::new(part, ti, 0, ti, theta, request.resting_rotations[0], &request.cost);
        let omega: Vec<Halfspace<3>> = o.omega_3d(&request.floor);
        let root = Cell::new(omega, tol).map_err(|e| e.to_string())?;
        if root.is_empty() {
            continue;
        }
        let mut cells = vec![root];
        for mi in 0..part.components().len() {
            for fi in 0..scene.components.len() {
                let ob = DerivedObstacle::build(
                    part,
                    &o,
                    mi,
                    &scene,
                    fi,
                    &cache,
                    request.clearance,
                    request.horizontal_clearance,
                    request.insertion,
                )?;
                let interior: Vec<Halfspace<3>> = ob
                    .planes
                    .iter()
                    .map(|p| Halfspace::new(p.normal.to_array(), p.offset - tol.linear, Tag::User(0)))
                    .collect();
                let mut next = Vec::new();
                for cell in cells {
                    let meets = cell.with_halfspaces(interior.iter().copied()).map_err(|e| e.to_string())?;
                    if meets.is_empty() {
                        next.push(cell);
                        continue;
                    }
                    let mut inside: Vec<Halfspace<3>> = Vec::new();
                    for p in &ob.planes {
                        let keep = Halfspace::new(p.normal.to_array(), p.offset, Tag::User(1));
                        let child = cell
                            .with_halfspaces(inside.iter().copied().chain(std::iter::once(keep.flipped(Tag::User(2)))))
                            .map_err(|e| e.to_string())?;
                        if !child.is_empty() {
                            next.push(child);
                        }
                        inside.push(keep);
                    }
                }
                cells = next;
            }
        }
        let quad = o.quadratic;
        for cell in &cells {
            if let Some(opt) = minimise(&cell.clone(), &quad)? {
                let p = DVec3::from_array(opt.point);
                if best.is_none_or(|(c, _, _)| opt.value < c) {
                    best = Some((opt.value, ti, p));
                }
            }
        }
    }
    Ok(best)
}

/// Every condition a placement `(rotation, position)` of `part` violates, by an independent all-pairs check; empty
/// when it is valid. `tol` is the length tolerance; `clearance` the required component distance; `insertion` asks
/// for a free vertical path from above (checked by sampling the path at steps of `insertion_step`).
pub fn violations(
    part: &Part,
    rotation: DMat3,
    position: DVec3,
    stack: &[PlacedPart<'_>],
    request: &PlacementRequest<'_>,
    tol: f64,
    insertion_step: f64,
) -> Vec<String> {
    let mut out = Vec::new();
    let placements: Vec<stackplan_geom::PlacedPart<'_>> = stack.to_vec();
    let scene = PlacedScene::new(&placements);
    for pair in scene.interference_pairs_brute_force(part, rotation, position, request.clearance) {
        let bad = match pair.contact {
            PairContact::Penetrating { depth } => depth > tol,
            PairContact::Touching { .. } => request.clearance > tol,
            PairContact::Separated { gap } => gap < request.clearance - 1e3 * tol,
        };
        if bad {
            out.push(format!(
                "component {} against stack part {} component {}: {:?}",
                pair.moving_piece, pair.fixed_part, pair.fixed_piece, pair.contact
            ));
        }
    }
    // floor volume
    let sides = request.floor.side_planes();
    for v in part.all_vertices() {
        let w = rotation * v + position;
        if w.z < -tol || w.z > request.floor.height + tol {
            out.push(format!("vertex at {w} outside the height range"));
            break;
        }
        if let Some(k) = sides.iter().position(|(n, d)| n.dot(w.truncate()) > d + tol) {
            out.push(format!("vertex at {w} outside floor side {k}"));
            break;
        }
    }
    if request.insertion {
        let top = stack.iter().flat_map(|s| s.part.all_vertices().map(|v| s.pose.apply(v).z)).fold(0.0f64, f64::max);
        let mut t = insertion_step;
        while position.z + t <= top + insertion_step {
            let up = position + DVec3::new(0.0, 0.0, t);
            if scene
                .interference_pairs_brute_force(part, rotation, up, 0.0)
                .iter()
                .any(|p| matches!(p.contact, PairContact::Penetrating { depth } if depth > tol))
            {
                out.push(format!("vertical path blocked at height {t} above the placement"));
                break;
            }
            t += insertion_step;
        }
    }
    out
}
