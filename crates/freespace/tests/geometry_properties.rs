//! Property tests of a cell's children as the planner builds them: emptiness from a known point against the Chebyshev
//! LP, and the child built from a known point against the one built from scratch.

use crate::common;

use common::{Rng, Shape, bbox, random_cell};
use proptest::prelude::*;
use stackplan_freespace::Cell;

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
