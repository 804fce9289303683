//! Multiple interference-free positions for one orientation: one optimum per cell, sorted by cost.
//!
//! \[A\] VI-A-4 (Ayyadevara et al. 2002, section 6.1.4): "since a position in every convex component has already been
//! computed, the interference analysis module sorts them in increasing order of cost and then returns the list";
//! the other modules (stability, grasp) search this list. Different cells have different faces, so the list tends to
//! offer different contact states. O(c * QP + c log c) for c cells.
//!
//! Order: increasing cost; ties (equal `f64` costs) by lowest z, then y, then x of the point, then by cell index,
//! so the list is deterministic. Empty cells are skipped; a cell whose QP fails is reported in `failures` (and
//! logged), never silently dropped.

use crate::cell::Cell;
use crate::cost::SeparableQuadratic;
use crate::qp::{QpError, QpSolution, minimize};

/// The optimum of one cell.
#[derive(Debug, Clone, PartialEq)]
pub struct Placement<const D: usize> {
    /// Index of the cell in the input.
    pub cell: usize,
    /// Its optimum.
    pub solution: QpSolution<D>,
}

/// The ranked optima of a free space.
#[derive(Debug, Clone, PartialEq)]
pub struct RankedPlacements<const D: usize> {
    /// One optimum per non-empty cell, cheapest first.
    pub placements: Vec<Placement<D>>,
    /// Cells whose QP failed, with the error.
    pub failures: Vec<(usize, QpError)>,
}

/// Minimises `cost` over every cell and sorts the optima. See the module documentation.
pub fn ranked_placements<const D: usize>(cells: &[Cell<D>], cost: &impl SeparableQuadratic<D>) -> RankedPlacements<D> {
    let mut placements = Vec::with_capacity(cells.len());
    let mut failures = Vec::new();
    for (i, cell) in cells.iter().enumerate() {
        if cell.is_empty() {
            continue;
        }
        match minimize(cell, cost) {
            Ok(solution) => placements.push(Placement { cell: i, solution }),
            Err(e) => {
                tracing::warn!(cell = i, error = %e, "placement QP failed");
                failures.push((i, e));
            }
        }
    }
    placements.sort_by(|a, b| {
        let (p, q) = (&a.solution.point, &b.solution.point);
        let mut ord = a.solution.cost.total_cmp(&b.solution.cost);
        for i in (0..D).rev() {
            ord = ord.then(p[i].total_cmp(&q[i]));
        }
        ord.then(a.cell.cmp(&b.cell))
    });
    RankedPlacements { placements, failures }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::{Halfspace, Tag};
    use crate::cost::SeparableCost;
    use stackplan_geom::Tolerance;

    fn square(x0: f64) -> Cell<2> {
        Cell::new(
            vec![
                Halfspace::new([1.0, 0.0], x0 + 1.0, Tag::User(0)),
                Halfspace::new([-1.0, 0.0], -x0, Tag::User(1)),
                Halfspace::new([0.0, 1.0], 1.0, Tag::User(2)),
                Halfspace::new([0.0, -1.0], 0.0, Tag::User(3)),
            ],
            Tolerance::for_scale(10.0),
        )
        .expect("cell")
    }

    #[test]
    fn sorted_by_cost_with_deterministic_ties() {
        let cells = vec![square(3.0), square(-2.0), square(-5.0), square(1.5)];
        // distance to the origin in x only: squares at 1.5 and -2 both reach distance... 1.5 vs 1
        let f = SeparableCost::new([2.0, 0.0], [0.0, 0.0], 0.0).expect("cost");
        let r = ranked_placements(&cells, &f);
        assert!(r.failures.is_empty());
        let order: Vec<usize> = r.placements.iter().map(|p| p.cell).collect();
        assert_eq!(order, vec![1, 3, 0, 2]);
        assert_eq!(r.placements[0].solution.point, [-1.0, 0.0]);
        // equal costs: squares at -2 and 1 both have x distance 1; tie broken by x (lower first)
        let cells = vec![square(1.0), square(-2.0)];
        let r = ranked_placements(&cells, &f);
        let order: Vec<usize> = r.placements.iter().map(|p| p.cell).collect();
        assert_eq!(order, vec![1, 0]);
    }
}
