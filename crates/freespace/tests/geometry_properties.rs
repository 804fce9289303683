//! Property tests of subtraction (set preservation, disjointness) and of Omega (the part at any vertex of Omega
//! touches the floor volume's boundary and stays inside it).

use crate::common;

use common::{Rng, Shape, bbox, random_cell, random_points};
use proptest::prelude::*;
use stackplan_freespace::{
    Cell, FloorVolume, Obstacle, SubtractOptions, Subtraction, omega, omega_fixed_z, subtract, subtract_from_all,
};
use stackplan_geom::{DMat3, DVec2, DVec3, convex_hull};

/// Distance from `p` to the nearest plane of a cell (for skipping ambiguous samples on boundaries).
fn near_boundary(cell: &Cell<3>, p: &[f64; 3], margin: f64) -> bool {
    cell.halfspaces().iter().any(|h| h.excess(p).abs() <= margin)
}

fn strictly_inside(cell: &Cell<3>, p: &[f64; 3], margin: f64) -> bool {
    cell.halfspaces().iter().all(|h| h.excess(p) < -margin)
}

proptest! {
    #[test]
    fn subtraction_preserves_the_set(seed in any::<u64>(), extra in 0usize..6, npts in 4usize..14, grow in any::<bool>()) {
        let mut rng = Rng(seed);
        let cell = random_cell(&mut rng, extra, Shape::Solid);
        prop_assume!(cell.is_solid());
        let c = cell.interior_point().expect("point");
        let (lo, hi) = bbox(&cell);
        // an obstacle near the cell: the hull of random points around a point of the cell's box
        let centre = DVec3::new(rng.range(lo[0], hi[0]), rng.range(lo[1], hi[1]), rng.range(lo[2], hi[2]));
        let centre = centre.lerp(DVec3::from_array(c), rng.range(0.0, 1.0));
        let radius = rng.range(0.5, 4.0);
        let pts = random_points(&mut rng, centre, radius, npts);
        let hull = match convex_hull(&pts) { Ok(h) => h, Err(_) => return Err(TestCaseError::reject("flat hull")) };
        let obstacle = Obstacle::from_polytope(7, &hull.polytope).expect("obstacle");
        let delta = if grow { rng.range(0.0, 0.5) } else { 0.0 };
        let opts = SubtractOptions { clearance: delta, remove_redundant: rng.below(2) == 0 };
        let pieces = match subtract(&cell, &obstacle, opts).expect("subtract") {
            Subtraction::Untouched => vec![cell.clone()],
            Subtraction::Eliminated => vec![],
            Subtraction::Pieces(p) => p,
        };
        let grown: Vec<([f64; 3], f64)> = obstacle.faces().iter().map(|(n, d)| (*n, d + delta)).collect();
        let margin = 1e-7;
        let mut checked = 0;
        for _ in 0..400 {
            let p = [rng.range(lo[0], hi[0]), rng.range(lo[1], hi[1]), rng.range(lo[2], hi[2])];
            let obstacle_excess = grown.iter().map(|(n, d)| common::dot(n, &p) - d).fold(f64::NEG_INFINITY, f64::max);
            if near_boundary(&cell, &p, margin) || obstacle_excess.abs() <= margin
                || pieces.iter().any(|q| near_boundary(q, &p, margin)) {
                continue;
            }
            checked += 1;
            let expected = strictly_inside(&cell, &p, margin) && obstacle_excess > margin;
            let count = pieces.iter().filter(|q| strictly_inside(q, &p, margin)).count();
            prop_assert_eq!(count, usize::from(expected), "point {:?}: in {} pieces", p, count);
        }
        prop_assert!(checked > 100);
        for i in 0..pieces.len() {
            prop_assert!(pieces[i].is_solid());
            for j in i + 1..pieces.len() {
                let both = pieces[i].intersection(&pieces[j]).expect("intersection");
                prop_assert!(!both.is_solid(), "pieces {} and {} overlap", i, j);
            }
        }
        // the batch form agrees
        let all = subtract_from_all(vec![cell.clone()], &obstacle, opts).expect("batch");
        prop_assert_eq!(all.len(), pieces.len());
    }

    #[test]
    fn part_at_any_vertex_of_omega_touches_and_stays_inside(seed in any::<u64>(), sides in 3usize..9, npts in 5usize..20) {
        let mut rng = Rng(seed);
        // a convex floor polygon: points on an ellipse at sorted random angles
        let (a, b) = (rng.range(4.0, 15.0), rng.range(4.0, 15.0));
        let mut angles: Vec<f64> = (0..sides).map(|_| rng.range(0.0, std::f64::consts::TAU)).collect();
        angles.sort_by(f64::total_cmp);
        let polygon: Vec<DVec2> = angles.iter().map(|t| DVec2::new(1.0 + a * t.cos(), -2.0 + b * t.sin())).collect();
        let floor = match FloorVolume::new(polygon, rng.range(2.0, 10.0)) {
            Ok(f) => f,
            Err(_) => return Err(TestCaseError::reject("degenerate polygon")),
        };
        let radius = rng.range(0.5, 3.0);
        let pts = random_points(&mut rng, DVec3::new(0.3, -0.2, 0.5), radius, npts);
        let hull = match convex_hull(&pts) { Ok(h) => h, Err(_) => return Err(TestCaseError::reject("flat hull")) };
        let rotation = DMat3::from_rotation_z(rng.range(0.0, 6.3)) * DMat3::from_rotation_x(rng.range(-1.5, 1.5));
        let rotated: Vec<DVec3> = hull.polytope.vertices().iter().map(|v| rotation * *v).collect();
        let om = omega(&floor, &rotated).expect("omega");
        let sigma = floor.halfspaces();
        let tol = om.tolerance().linear;
        let pz = -rotated.iter().map(|v| v.z).fold(f64::INFINITY, f64::min);
        let o2 = omega_fixed_z(&floor, &rotated, pz).expect("2d omega");
        if om.is_empty() {
            // the floor is too small for the part: then no height helps either
            prop_assert!(o2.is_empty());
            return Ok(());
        }
        let poly = om.polyhedron();
        prop_assert!(poly.vertices.len() >= 4 || !om.is_solid());
        for p in &poly.vertices {
            let placed: Vec<[f64; 3]> = rotated.iter().map(|v| [v.x + p[0], v.y + p[1], v.z + p[2]]).collect();
            let mut touching = 0;
            for h in &sigma {
                let worst = placed.iter().map(|q| h.excess(q)).fold(f64::NEG_INFINITY, f64::max);
                prop_assert!(worst <= 10.0 * tol, "a part vertex leaves the floor volume by {}", worst);
                if worst >= -10.0 * tol {
                    touching += 1;
                }
            }
            // a vertex of the 3-D Omega has three tight inequalities: three walls (or floor/ceiling) touched
            prop_assert!(touching >= 3, "only {} walls touched at an Omega vertex", touching);
        }
        // the 2-D Omega at the floor height is the horizontal slice of the 3-D one
        prop_assert!(!o2.is_empty());
        for q in o2.polygon() {
            prop_assert!(om.contains(&[q[0], q[1], pz]) != stackplan_geom::Containment::Exterior);
        }
    }
}

/// A child-cell case like the planner's: a random parent (solid, face-thin or edge-thin), a point of it to start from
/// (the QP optimum of a random cost with diagonal `h`, on its boundary as in the planner, or its interior point) and
/// `cuts` random cuts through its box (some keep the start, some do not: then the phase 1 has to move). `None` when
/// the parent came out empty.
struct ChildCase {
    cell: stackplan_freespace::Cell<3>,
    cost: stackplan_freespace::SeparableCost<3>,
    start: [f64; 3],
    cuts: Vec<stackplan_freespace::Halfspace<3>>,
}

fn child_case(rng: &mut Rng, extra: usize, flat: usize, cuts: usize, h: [f64; 3]) -> Option<ChildCase> {
    use stackplan_freespace::{Halfspace, SeparableCost, Tag, minimize};
    let shape = [Shape::Solid, Shape::Face, Shape::Edge][flat];
    let cell = random_cell(rng, extra, shape);
    if cell.is_empty() {
        return None;
    }
    let (lo, hi) = bbox(&cell);
    let target = [rng.range(lo[0] - 3.0, hi[0] + 3.0), rng.range(lo[1] - 3.0, hi[1] + 3.0), rng.range(lo[2], hi[2])];
    let cost = SeparableCost::new(h, target.map(|t| -2.0 * t), 0.0).expect("cost");
    let start = if rng.below(2) == 0 {
        minimize(&cell, &cost).expect("qp").point
    } else {
        cell.interior_point().expect("point")
    };
    let mut hs = Vec::new();
    for k in 0..cuts {
        let n = rng.unit3();
        let through = [rng.range(lo[0], hi[0]), rng.range(lo[1], hi[1]), rng.range(lo[2], hi[2])];
        hs.push(Halfspace::new(n, common::dot(&n, &through), Tag::User(100 + k as u64)));
    }
    Some(ChildCase { cell, cost, start, cuts: hs })
}

proptest! {
    /// The phase 1 of `is_empty_with` (from a point of the parent: its QP optimum or its interior point) decides
    /// emptiness as the Chebyshev LP of `with_halfspaces` does.
    #[test]
    fn phase_one_agrees_with_the_chebyshev_lp(seed in any::<u64>(), extra in 0usize..5, cuts in 1usize..5,
                                             flat in 0usize..3) {
        use stackplan_freespace::{Halfspace, minimize};
        let mut rng = Rng(seed);
        let Some(ChildCase { cell, cost, start, cuts: hs }) = child_case(&mut rng, extra, flat, cuts, [2.0; 3]) else {
            return Ok(());
        };
        let empty = cell.is_empty_with(hs.iter().copied(), &start).expect("phase 1");
        let reference = cell.with_halfspaces(hs.iter().copied()).expect("chebyshev");
        let tol = cell.tolerance().linear;
        match (empty, reference.shape()) {
            (true, stackplan_freespace::CellShape::Empty) => {}
            (false, s) if s != stackplan_freespace::CellShape::Empty => {
                // and the QP of the non-empty cell has an answer
                minimize(&reference, &cost).expect("qp");
            }
            // a disagreement is allowed only at the tolerance boundary: the Chebyshev radius within rounding of -tol,
            // i.e. the cell grown by 1.001 tol is non-empty and the cell grown by 0.999 tol is empty (both judged
            // with a negligible tolerance)
            (pe, s) => {
                let fine = stackplan_geom::Tolerance::for_scale(1e-6);
                let shifted = |by: f64| {
                    let hs: Vec<Halfspace<3>> = reference.halfspaces().iter()
                        .map(|h| Halfspace::new(h.normal, h.offset + by, h.tag)).collect();
                    Cell::new(hs, fine).map(|c| c.is_empty())
                };
                prop_assert!(
                    shifted(1.001 * tol) == Ok(false) && shifted(0.999 * tol) == Ok(true),
                    "phase 1 empty = {pe}, Chebyshev {s:?}, not a tolerance-boundary case"
                );
            }
        }
    }
}

proptest! {
    /// `with_halfspaces_from` (phase 1 from a point of the parent, no Chebyshev LP) against `with_halfspaces` (the
    /// oracle): the same emptiness as `is_empty_with`, the same inequalities, a known point inside the cell, and the
    /// same QP optimum up to rounding. Solid, face-thin and edge-thin parents; starts at the parent's QP optimum (on
    /// its boundary, as in the planner) or its interior point; cuts that keep or exclude the start, parallel and
    /// coplanar ones (a face of the parent repeated or flipped: the child is a face or touches it).
    #[test]
    fn child_from_a_known_point_agrees_with_the_chebyshev_build(seed in any::<u64>(), extra in 0usize..5,
                                                              cuts in 1usize..5, flat in 0usize..3, special in 0usize..4) {
        use stackplan_freespace::{CellShape, Halfspace, Tag, minimize};
        let mut rng = Rng(seed);
        let Some(ChildCase { cell, cost, start, cuts: mut hs }) = child_case(&mut rng, extra, flat, cuts, [2.0, 1.5, 0.4])
        else {
            return Ok(());
        };
        let face = cell.halfspaces()[rng.below(cell.len())];
        match special {
            // the outside of a face of the parent: the child is that face (flat), or empty by rounding
            1 => hs.push(face.flipped(Tag::User(200))),
            // a face of the parent repeated (coplanar, redundant)
            2 => hs.push(Halfspace::new(face.normal, face.offset, Tag::User(201))),
            // the outside of a face moved outwards: empty
            3 => hs.push(Halfspace::new(face.normal, face.offset + 1.0, Tag::User(202)).flipped(Tag::User(202))),
            _ => {}
        }
        let from = cell.with_halfspaces_from(&hs, &start).expect("phase 1");
        let empty = cell.is_empty_with(hs.iter().copied(), &start).expect("phase 1");
        prop_assert_eq!(from.is_none(), empty);
        let Some(child) = from else { return Ok(()) };
        let reference = cell.with_halfspaces(hs.iter().copied()).expect("chebyshev");
        prop_assert_eq!(child.halfspaces(), reference.halfspaces());
        let p = child.interior_point().expect("a point");
        if let CellShape::Known { .. } = child.shape() {
            let tol = cell.tolerance().linear;
            for h in child.halfspaces() {
                prop_assert!(h.excess(&p) <= 1e-3 * tol, "known point outside {:?} by {}", h, h.excess(&p));
            }
        }
        if reference.is_empty() {
            // only at the tolerance boundary (see phase_one_agrees_with_the_chebyshev_lp)
            return Ok(());
        }
        let a = minimize(&child, &cost).expect("qp from the known point");
        let b = minimize(&reference, &cost).expect("qp from the Chebyshev centre");
        let scale = 1.0 + b.cost.abs();
        prop_assert!((a.cost - b.cost).abs() <= 1e-9 * scale, "costs {} vs {}", a.cost, b.cost);
        for i in 0..3 {
            prop_assert!((a.point[i] - b.point[i]).abs() <= 1e-7, "points {:?} vs {:?}", a.point, b.point);
        }
    }
}
