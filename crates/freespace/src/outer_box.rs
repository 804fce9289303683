//! An axis-aligned box around a cell by bound propagation, and the emptiness test it gives for a cell cut by one more
//! half-space (the best-first placement search's pending children, \[A\] VI-A-3).
//!
//! **Propagation** (interval constraint propagation, as in the bound tightening of LP and MIP presolve): start from
//! the unbounded box; for every inequality `a . p <= b` and every variable `i` with `a_i != 0`,
//! `a_i p_i <= b - sum_{j != i} min(a_j lo_j, a_j hi_j)` tightens `hi_i` (`a_i > 0`) or `lo_i` (`a_i < 0`), in
//! `PASSES` passes over the list. Every point of the cell satisfies every derived bound, so the box always contains the
//! cell (it need not be the cell's bounding box; it is when the cell is a box, and it is close to it for the cells of
//! the planner's search: a permissible set whose floor has axis-aligned sides, cut by obstacle planes; in the 15-part
//! L-corner plan the exact bounding box (six LPs per cell) excludes 99.9 % of the children that the outside
//! half-space alone makes empty, and those are 96 % of all empty children). Variables no chain of inequalities bounds
//! stay infinite, and so does every support through them: the test below then answers "cannot tell".
//!
//! **Rounding.** Each bound is a sum of `D` products, so its rounding error is a few units in the last place of the
//! coordinates' magnitude; the test keeps a margin of the cell tolerance (`1e-9` of the problem's scale) above it.
//!
//! **Redundancy** ([`grown_outer_box_pruned`]): an inequality over whose box the cell's points keep a margin
//! from it is dropped, after a second propagation without the dropped ones confirms the box (the first used them).
//!
//! Cost: O(passes x m x D^2) for `m` inequalities, no allocation; the test O(D); the pruning two propagations and
//! one allocation.

use crate::cell::{Cell, CellError};
use crate::halfspace::Halfspace;

/// Passes of the propagation. A second pass tightens what the first could not derive from bounds found later in the
/// list; for the planner's cells (the permissible set's axis-aligned bounds come first) it filters a few more
/// children but costs more than they do: a 15-part L-corner plan ran 1,593 M instructions with one pass, 1,608 M with
/// two and 1,641 M with three (callgrind; 2,028 M without the filter).
const PASSES: usize = 1;

/// A box `[lo, hi]` (per variable; infinite where nothing bounds it) that contains the cell `{p : a_k . p <= b_k +
/// grow}` of `halfspaces` (unit or not), by `PASSES` passes of bound propagation (module documentation). With
/// `grow` the cell's tolerance, the box contains the tolerance-grown cell on which emptiness is decided
/// ([`Cell::is_empty_with`]).
pub fn outer_box<const D: usize>(halfspaces: &[Halfspace<D>], grow: f64) -> ([f64; D], [f64; D]) {
    let mut bounds = ([f64::NEG_INFINITY; D], [f64::INFINITY; D]);
    for _ in 0..PASSES {
        for h in halfspaces {
            tighten_box(&mut bounds, &h.normal, h.offset + grow);
        }
    }
    bounds
}

/// One step of the propagation: the box `[lo, hi]` tightened by the inequality `normal . p <= offset` (the bounds it
/// implies for each variable given the others' bounds). Every point of the box that satisfies the inequality stays
/// in it. An infinite bound of another variable that the inequality reaches leaves the variable as it is. O(D^2).
#[inline]
pub fn tighten_box<const D: usize>((lo, hi): &mut ([f64; D], [f64; D]), normal: &[f64; D], offset: f64) {
    for i in 0..D {
        let a = normal[i];
        if a == 0.0 {
            continue;
        }
        // the least the other variables can contribute (a zero coefficient contributes nothing, also against an
        // infinite bound)
        let mut rest = 0.0;
        for j in 0..D {
            let c = normal[j];
            if j != i && c != 0.0 {
                rest += (c * lo[j]).min(c * hi[j]);
            }
        }
        if !rest.is_finite() {
            continue;
        }
        let bound = (offset - rest) / a;
        if a > 0.0 {
            hi[i] = hi[i].min(bound);
        } else {
            lo[i] = lo[i].max(bound);
        }
    }
}

/// Whether the box `[lo, hi]` is empty by more than `2 slack` in some variable (with a box that contains a
/// tolerance-grown cell and `slack` the tolerance: that cell is empty, and [`Cell::is_empty_with`] finds it so; the
/// margin covers the propagation's rounding, as in [`box_misses_halfspace`]).
pub fn box_is_empty<const D: usize>((lo, hi): &([f64; D], [f64; D]), slack: f64) -> bool {
    (0..D).any(|i| lo[i] > hi[i] + 2.0 * slack)
}

/// [`outer_box`] of `cell` grown by its tolerance: a box that holds every point of the cell with each offset grown by
/// the tolerance (the cell on which [`Cell::is_empty_with`] decides).
pub fn grown_outer_box<const D: usize>(cell: &Cell<D>) -> ([f64; D], [f64; D]) {
    outer_box(cell.halfspaces(), cell.tolerance().linear)
}

/// [`grown_outer_box`], and `cell` without the inequalities that box proves redundant when there are any (`None`
/// otherwise).
///
/// **Redundancy.** Inequality `a . p <= b` is dropped when the box proves `a . p < b - 2 tol` over the whole
/// tolerance-grown cell (the test and margin of [`box_misses_halfspace`], which decide empty children; the
/// cell's normals are unit). The first box was derived with the dropped inequalities themselves, so the drops
/// are checked again against the box of the kept inequalities alone: when every dropped one still holds over
/// it, the kept inequalities define the same cell, exactly and grown by the tolerance (the kept cell lies in
/// that box, which lies strictly inside every dropped half-space); otherwise nothing is dropped. No LP: two
/// propagations, O(m D^2).
///
/// The planner's search cuts a cell by one obstacle after another and each child inherits its parent's
/// inequalities, so most of a deep cell's list no longer touches it (in the 15-part Complex plan about 14 of
/// 20 inequalities per split cell); its children are built from the pruned cell.
pub fn grown_outer_box_pruned<const D: usize>(cell: &Cell<D>) -> (([f64; D], [f64; D]), Option<Cell<D>>) {
    let tol = cell.tolerance().linear;
    let outer = outer_box(cell.halfspaces(), tol);
    if cell.is_empty() {
        return (outer, None);
    }
    let holds = |(lo, hi): &([f64; D], [f64; D]), h: &Halfspace<D>| unit_box_inside(lo, hi, h, tol);
    let Some(first) = cell.halfspaces().iter().position(|h| holds(&outer, h)) else {
        return (outer, None);
    };
    let mut kept = Vec::with_capacity(cell.len());
    kept.extend_from_slice(&cell.halfspaces()[..first]);
    kept.extend(cell.halfspaces()[first + 1..].iter().filter(|h| !holds(&outer, h)).copied());
    let check = outer_box(&kept, tol);
    // (the dropped ones are found again by the same O(D) test rather than kept in a second list: in the 15-part
    // Complex plan that list's allocation cost 3 % more instructions than the second test)
    let dropped = cell.halfspaces()[first..].iter().filter(|h| holds(&outer, h));
    if !dropped.clone().all(|h| holds(&check, h)) {
        return (outer, None);
    }
    (outer, Some(cell.with_only(kept)))
}

/// `cell` grown by its tolerance ([`Cell::grown_by_tolerance`]) without the near-duplicates: inequality `j` is left out when an earlier kept
/// inequality `k` implies it within the tolerance over the box around the cell ([`outer_box`] grown by the
/// tolerance): `max over the box of (a_j - a_k) . p <= b_j - b_k + tol`, so every point of the
/// reduced grown cell satisfies `j` within twice the tolerance. The c-space obstacles of parts whose faces are a
/// sliver out of line put a dozen planes through one vertex with normals 1e-16 to 1e-9 apart, a degenerate
/// problem on which both QP solvers can fail. Returns the cell and the index in this cell of each of its
/// inequalities. `Err` when the box is not finite.
pub fn grown_without_near_duplicates<const D: usize>(cell: &Cell<D>) -> Result<(Cell<D>, Vec<usize>), CellError> {
    let tol = cell.tolerance().linear;
    let (lo, hi) = outer_box(cell.halfspaces(), tol);
    if lo.iter().chain(&hi).any(|v| !v.is_finite()) {
        return Err(CellError::Unbounded);
    }
    let mut kept: Vec<Halfspace<D>> = Vec::with_capacity(cell.len());
    let mut index = Vec::with_capacity(cell.len());
    for (j, h) in cell.halfspaces().iter().enumerate() {
        let implied = kept.iter().any(|k| {
            let reach: f64 = (0..D)
                .map(|i| {
                    let d = h.normal[i] - k.normal[i];
                    if d > 0.0 { d * hi[i] } else { d * lo[i] }
                })
                .sum();
            reach <= h.offset - (k.offset - tol) + tol
        });
        if !implied {
            kept.push(Halfspace { offset: h.offset + tol, ..*h });
            index.push(j);
        }
    }
    Ok((Cell::new(kept, cell.tolerance())?, index))
}

/// Whether every point of the box `[lo, hi]` satisfies `h` (unit normal) with a margin: `max over the box of
/// n . p < b - 2 tol` ([`box_misses_halfspace`] without the normalisation; `false` when the box is unbounded where
/// the normal reaches).
#[inline]
fn unit_box_inside<const D: usize>(lo: &[f64; D], hi: &[f64; D], h: &Halfspace<D>, tol: f64) -> bool {
    let mut reach = 0.0;
    for i in 0..D {
        let n = h.normal[i];
        if n != 0.0 {
            reach += (n * lo[i]).max(n * hi[i]);
        }
    }
    // (an infinite or NaN reach compares false)
    reach < h.offset - 2.0 * tol
}

/// Whether the box `(lo, hi)` proves that no point `p` of it has `normal . p >= offset - slack |normal|`, with a
/// margin of `slack` beyond that: `max over the box of n . p < d - 2 slack` for the unit normal `n = normal / |normal|`
/// and `d = offset / |normal|`. `false` ("cannot tell") for a zero or non-finite normal or offset and for a box
/// unbounded in a direction the normal reaches.
///
/// With the box of [`grown_outer_box`] and `slack` the cell's tolerance, `true` means that the cell with
/// `-normal . p <= -offset` added (and any further inequalities) is empty even with every offset grown by the
/// tolerance, so [`Cell::is_empty_with`] and [`Cell::with_halfspaces_from`] find it empty (the margin covers their
/// rounding and the box's).
pub fn box_misses_halfspace<const D: usize>(
    (lo, hi): &([f64; D], [f64; D]),
    normal: &[f64; D],
    offset: f64,
    slack: f64,
) -> bool {
    let length = normal.iter().map(|c| c * c).sum::<f64>().sqrt();
    if !(length > 0.0 && length.is_finite() && offset.is_finite()) {
        return false;
    }
    let mut reach = 0.0;
    for i in 0..D {
        let n = normal[i] / length;
        if n != 0.0 {
            reach += (n * lo[i]).max(n * hi[i]);
        }
    }
    // (an infinite or NaN reach compares false)
    reach < offset / length - 2.0 * slack
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::halfspace::Tag;
    use proptest::prelude::*;
    use stackplan_geom::Tolerance;

    fn hs<const D: usize>(normal: [f64; D], offset: f64) -> Halfspace<D> {
        Halfspace::new(normal, offset, Tag::User(0))
    }

    fn unit_box() -> Vec<Halfspace<3>> {
        vec![
            hs([1.0, 0.0, 0.0], 1.0),
            hs([-1.0, 0.0, 0.0], 1.0),
            hs([0.0, 1.0, 0.0], 2.0),
            hs([0.0, -1.0, 0.0], 2.0),
            hs([0.0, 0.0, 1.0], 3.0),
            hs([0.0, 0.0, -1.0], 0.0),
        ]
    }

    /// [`unit_box`] cut by `n . p <= d` for each `(n_x, n_y, n_z, d)` of `cuts`.
    fn box_with_cuts(cuts: &[(f64, f64, f64, f64)], tol: Tolerance) -> Cell<3> {
        let mut list = unit_box();
        list.extend(cuts.iter().map(|&(x, y, z, d)| hs([x, y, z], d)));
        Cell::new(list, tol).expect("finite inequalities inside a box: a bounded cell")
    }

    #[test]
    fn a_box_is_its_own_outer_box() {
        let (lo, hi) = outer_box(&unit_box(), 0.0);
        assert_eq!(lo, [-1.0, -2.0, 0.0]);
        assert_eq!(hi, [1.0, 2.0, 3.0]);
        let (lo, hi) = outer_box(&unit_box(), 0.5);
        assert_eq!(lo, [-1.5, -2.5, -0.5]);
        assert_eq!(hi, [1.5, 2.5, 3.5]);
    }

    #[test]
    fn an_oblique_cut_tightens_the_other_variables() {
        // x + y <= 0 with x >= -1 gives y <= 1; with y >= -2 it gives x <= 2 (no tighter than x <= 1)
        let mut cell = unit_box();
        cell.push(hs([1.0, 1.0, 0.0], 0.0));
        let (lo, hi) = outer_box(&cell, 0.0);
        assert_eq!((lo[1], hi[1]), (-2.0, 1.0));
        assert_eq!((lo[0], hi[0]), (-1.0, 1.0));
    }

    #[test]
    fn an_unbounded_variable_stays_infinite_and_the_test_cannot_tell() {
        let cell = vec![hs([1.0, 0.0], 1.0), hs([-1.0, 0.0], 1.0), hs([0.0, -1.0], 0.0)];
        let b = outer_box(&cell, 0.0);
        assert_eq!(b.1[1], f64::INFINITY);
        // y >= 5 cannot be excluded (y is unbounded above) ...
        assert!(!box_misses_halfspace(&b, &[0.0, 1.0], 5.0, 1e-9));
        // ... x >= 5 can (x <= 1), and y <= -5 too (y >= 0), through a normal that does not reach y's infinite side
        assert!(box_misses_halfspace(&b, &[1.0, 0.0], 5.0, 1e-9));
        assert!(box_misses_halfspace(&b, &[0.0, -1.0], 5.0, 1e-9));
    }

    #[test]
    fn the_margin_keeps_touching_and_near_touching_cuts() {
        let b = outer_box(&unit_box(), 0.0);
        // x >= 1 touches the box: not excluded; x >= 1 + 1e-12 neither (inside the margin); x >= 1.1 is
        assert!(!box_misses_halfspace(&b, &[1.0, 0.0, 0.0], 1.0, 1e-9));
        assert!(!box_misses_halfspace(&b, &[1.0, 0.0, 0.0], 1.0 + 1e-12, 1e-9));
        assert!(box_misses_halfspace(&b, &[1.0, 0.0, 0.0], 1.1, 1e-9));
        // a scaled normal is the same half-space
        assert!(box_misses_halfspace(&b, &[4.0, 0.0, 0.0], 4.4, 1e-9));
        assert!(!box_misses_halfspace(&b, &[0.0, 0.0, 0.0], -1.0, 1e-9));
        assert!(!box_misses_halfspace(&b, &[f64::NAN, 0.0, 0.0], 1.1, 1e-9));
    }

    #[test]
    fn tightening_a_box_by_an_inequality() {
        // x + y <= 0 over [-1, 1] x [-2, 2]: y <= 1, x unchanged (x <= 2 is looser); then y >= 1.5 empties it
        let mut b = ([-1.0, -2.0], [1.0, 2.0]);
        tighten_box(&mut b, &[1.0, 1.0], 0.0);
        assert_eq!(b, ([-1.0, -2.0], [1.0, 1.0]));
        assert!(!box_is_empty(&b, 1e-9));
        tighten_box(&mut b, &[0.0, -1.0], -1.5);
        assert!(box_is_empty(&b, 1e-9));
        // empty by less than twice the slack: not declared empty
        let touching = ([0.0, 1.0 + 1e-10], [1.0, 1.0]);
        assert!(!box_is_empty(&touching, 1e-9));
        // an infinite bound the inequality reaches leaves the other variable alone
        let mut open = ([0.0, f64::NEG_INFINITY], [1.0, 1.0]);
        tighten_box(&mut open, &[1.0, 1.0], 0.0);
        assert_eq!(open.1[0], 1.0);
    }

    #[test]
    fn pruning_drops_the_far_cuts_and_keeps_the_ones_that_bound() {
        let tol = Tolerance::for_scale(10.0);
        let mut list = unit_box();
        // far outside the box (dropped), touching it (kept) and cutting a corner (kept)
        list.push(hs([1.0, 1.0, 0.0], 10.0));
        list.push(hs([0.0, 0.0, 1.0], 3.0));
        list.push(hs([1.0, 1.0, 1.0], 4.0));
        let cell = Cell::new(list, tol).expect("bounded");
        let (outer, pruned) = grown_outer_box_pruned(&cell);
        assert_eq!(outer, grown_outer_box(&cell));
        let pruned = pruned.expect("the far cut is dropped");
        assert_eq!(pruned.len(), cell.len() - 1);
        assert!(pruned.halfspaces().iter().all(|h| h.offset != 10.0 / 2f64.sqrt()));
        assert_eq!(pruned.shape(), cell.shape());
        // nothing left to drop
        assert!(grown_outer_box_pruned(&pruned).1.is_none());
    }

    proptest! {
        /// Against the exact support LPs of the cell (an independent method): the box holds the cell, and whenever
        /// the test excludes a half-space, the cell with it added is empty.
        #[test]
        fn the_box_holds_the_cell_and_its_exclusions_are_empty_cells(
            cuts in proptest::collection::vec(
                (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0, -0.5f64..2.0), 0..8),
            probe in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0, -3.0f64..3.0),
        ) {
            let tol = Tolerance::for_scale(10.0);
            let cell = box_with_cuts(&cuts, tol);
            prop_assume!(!cell.is_empty());
            let b = grown_outer_box(&cell);
            for i in 0..3 {
                for sign in [1.0, -1.0] {
                    let mut e = [0.0; 3];
                    e[i] = sign;
                    let (h, _) = cell.support(&e).expect("support LP").expect("non-empty cell");
                    let bound = if sign > 0.0 { b.1[i] } else { -b.0[i] };
                    prop_assert!(h <= bound + 1e-12, "support {h} beyond the box {bound} on axis {i} sign {sign}");
                }
            }
            let normal = [probe.0, probe.1, probe.2];
            if box_misses_halfspace(&b, &normal, probe.3, tol.linear) {
                let outside = hs(normal, probe.3).flipped(Tag::User(1));
                let start = cell.interior_point().expect("non-empty cell");
                prop_assert!(cell.is_empty_with([outside], &start).expect("phase 1"));
                let (h, _) = cell.support(&normal).expect("support LP").expect("non-empty cell");
                prop_assert!(h < probe.3);
            }
        }

        /// The planner's child box: the cell's grown box tightened by further inequalities (each grown by the
        /// tolerance, as the planner does) against the exact support LPs of the cell with them added (it holds
        /// that cell), and whenever it is empty by the margin, the exact phase 1 finds the cell with them added
        /// empty.
        #[test]
        fn a_tightened_box_holds_the_cut_cell_and_its_emptiness_is_exact(
            cuts in proptest::collection::vec(
                (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0, -0.5f64..2.0), 0..6),
            extra in proptest::collection::vec(
                (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0, -2.0f64..2.0), 1..4),
        ) {
            let tol = Tolerance::for_scale(10.0);
            let cell = box_with_cuts(&cuts, tol);
            prop_assume!(!cell.is_empty());
            let mut b = grown_outer_box(&cell);
            let extra: Vec<Halfspace<3>> = extra.iter().map(|&(x, y, z, d)| hs([x, y, z], d)).collect();
            for h in &extra {
                tighten_box(&mut b, &h.normal, h.offset + tol.linear);
            }
            let start = cell.interior_point().expect("non-empty cell");
            if box_is_empty(&b, tol.linear) {
                prop_assert!(cell.is_empty_with(extra.iter().copied(), &start).expect("phase 1"));
            } else if let Some(cut) = cell.with_halfspaces_from(&extra, &start).expect("phase 1") {
                for i in 0..3 {
                    for sign in [1.0, -1.0] {
                        let mut e = [0.0; 3];
                        e[i] = sign;
                        let Some((h, _)) = cut.support(&e).expect("support LP") else { continue };
                        let bound = if sign > 0.0 { b.1[i] } else { -b.0[i] };
                        prop_assert!(h <= bound + 1e-12, "support {h} beyond the box {bound} on axis {i}");
                    }
                }
            }
        }

        /// Against the exact support LPs of both cells: the pruned cell is the same set (the same support in every
        /// probed direction) and decides a cut's emptiness as the cell does; it keeps a sub-list of the
        /// inequalities. Cuts are random, so a dropped one may have bounded the box that proved the others
        /// redundant (the second propagation guards that case).
        #[test]
        fn the_pruned_cell_is_the_same_set(
            cuts in proptest::collection::vec(
                (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0, -0.5f64..4.0), 1..10),
            probes in proptest::collection::vec((-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0, -3.0f64..3.0), 6),
        ) {
            let tol = Tolerance::for_scale(10.0);
            let cell = box_with_cuts(&cuts, tol);
            prop_assume!(!cell.is_empty());
            let (_, pruned) = grown_outer_box_pruned(&cell);
            let Some(pruned) = pruned else { return Ok(()) };
            prop_assert!(pruned.len() < cell.len());
            prop_assert!(pruned.halfspaces().iter().all(|h| cell.halfspaces().contains(h)));
            // every dropped inequality holds strictly over the pruned cell, and the supports along every normal of
            // the list (the directions a wrong drop shows in) agree
            for h in cell.halfspaces() {
                let a = cell.support(&h.normal).expect("support LP").expect("non-empty");
                let b = pruned.support(&h.normal).expect("support LP").expect("non-empty");
                prop_assert!((a.0 - b.0).abs() <= 1e-9, "support {} against {} along {:?}", a.0, b.0, h.normal);
                if !pruned.halfspaces().contains(h) {
                    prop_assert!(b.0 < h.offset, "a dropped inequality binds: {} >= {}", b.0, h.offset);
                }
            }
            let start = cell.interior_point().expect("non-empty cell");
            for probe in probes {
                let normal = [probe.0, probe.1, probe.2];
                let a = cell.support(&normal).expect("support LP").expect("non-empty");
                let b = pruned.support(&normal).expect("support LP").expect("non-empty");
                prop_assert!((a.0 - b.0).abs() <= 1e-9, "support {} against {} along {normal:?}", a.0, b.0);
                let outside = hs(normal, probe.3).flipped(Tag::User(1));
                prop_assert_eq!(
                    cell.is_empty_with([outside], &start).expect("phase 1"),
                    pruned.is_empty_with([outside], &start).expect("phase 1")
                );
            }
        }
    }
}
