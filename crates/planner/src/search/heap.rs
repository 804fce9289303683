//! The search's open nodes: solved nodes and families of pending children in a 4-ary heap keyed by (rounded cost,
//! orientation, id), the search's total order.

use super::dary_heap::DaryHeap;
use crate::cell_qp::QpOptimum;
use stackplan_freespace::Cell;
use std::sync::Arc;

/// A solved node: an orientation, a cell, its optimum and the obstacles applied on its path.
#[derive(Clone)]
pub(super) struct Node<const D: usize> {
    pub(super) cost: f64,
    pub(super) orientation: usize,
    pub(super) id: u64,
    pub(super) cell: Arc<Cell<D>>,
    pub(super) optimum: QpOptimum<D>,
    pub(super) applied: Arc<[u32]>,
}

/// The pending children of one split: the parent's cell plus the extra inequalities of child `face` of obstacle
/// `obstacle` (rebuilt from the obstacle's planes when the child is popped), the parent's optimum as the start of
/// their phase 1, and per child its key (a lower bound of its cost), id and face. A child is built and solved only
/// when popped. The heap holds one entry per family, keyed by its cheapest remaining child (`children` is sorted
/// so that it is the last): the heap pops the children in the same order as with one entry each (a family's key
/// is the least of its children's, and a total order's least over a union is the least of the least ones), without
/// holding the many children that are never popped. The children live in one arena of the heap
/// ([`NodeHeap::children`]: no allocation per family).
#[derive(Clone)]
pub(super) struct Family<const D: usize> {
    pub(super) orientation: usize,
    /// The parent cell; released (`None`) once the last child has been popped, so that a long search (and the
    /// frontiers carried through a plan) holds only the cells of families with children still pending.
    pub(super) cell: Option<Arc<Cell<D>>>,
    pub(super) applied: Arc<[u32]>,
    pub(super) obstacle: u32,
    pub(super) start: [f64; D],
    /// Which inside cuts the children keep ([`Search::child_inequalities`]).
    pub(super) cuts: InsideCuts<D>,
    /// The family's children are `NodeHeap::children[first..first + left]` (`(key, id, face)`), the cheapest (by
    /// [`HeapKey`]'s order) last; popping one decrements `left`.
    pub(super) first: usize,
    pub(super) left: u32,
}

/// The inside cuts `n_j . p <= d_j` that a family's children keep: those the box around the parent cell
/// (`outer_box::grown_outer_box_pruned`, when the obstacle's planes are finite) does not prove redundant. The test is
/// the one that drops the empty outside child of the same face at the split (`box_misses_halfspace` with the same
/// arguments), so the kept cuts are recorded there as a mask; an obstacle with more faces than the mask's bits keeps
/// the box and repeats the test per child.
#[derive(Clone, Copy)]
pub(super) enum InsideCuts<const D: usize> {
    /// Bit `j`: face `j`'s inside cut is kept (its outside half-space meets the box).
    Kept(u128),
    /// The box (`None`: no finite box, every cut kept).
    Reach(Option<([f64; D], [f64; D])>),
}

/// A popped entry: a solved node, or the next child of a family (its id and face; the family by index into
/// [`NodeHeap::families`]).
pub(super) enum Popped<const D: usize> {
    Solved(Node<D>),
    Pending { family: u32, id: u64, face: u32 },
}

/// Low mantissa bits rounded away by [`quantised_cost`]: 12 of 52, a relative step of `2^-40` (about `1e-12`).
pub(super) const KEY_ROUND_BITS: u32 = 12;

/// The cost as the heap compares it: rounded to the nearest multiple of `2^-40` of its binade (about `1e-12`
/// relative; half-way cases away from zero), so that costs equal but for rounding in their last bits (mirror-image
/// cells, optima reached from different start points) compare equal and their order falls to (orientation, id),
/// which no rounding moves. Rounding is monotone (`a <= b` implies `q(a) <= q(b)`), so a lower bound of a cost stays
/// a lower bound of its key, and comparing rounded values is a total order (a strict weak order, unlike "within
/// eps"). Non-finite values are kept.
#[inline]
pub(super) fn quantised_cost(cost: f64) -> f64 {
    if !cost.is_finite() {
        return cost;
    }
    let half = 1u64 << (KEY_ROUND_BITS - 1);
    let mask = !((1u64 << KEY_ROUND_BITS) - 1);
    // sign bit untouched; a carry out of the mantissa moves to the next binade (or to infinity at the very top,
    // which only a cost near f64::MAX could reach)
    f64::from_bits((cost.to_bits().wrapping_add(half)) & mask)
}

/// The key of a node in the heap: its cost (rounded, [`quantised_cost`]), orientation and id (the total order of
/// the search), and its slot in [`NodeHeap`]'s slab, or (with [`FAMILY`] set) its family's index.
///
/// The order is encoded in two integers so that a comparison is two integer compares (a heap walk makes up to four
/// per level): `rank_cost` is the rounded cost's bits mapped monotonically to `u64` (the order of `f64::total_cmp`),
/// `rank_tie` is `orientation << 40 | id`, both complemented so that the max-heap pops the cheapest, then the lowest
/// orientation, then the lowest id. Ids stay below `2^40` (the node budget is far smaller) and orientations below
/// `2^24` (checked when the search is prepared).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(super) struct HeapKey {
    pub(super) rank_cost: u64,
    pub(super) rank_tie: u64,
    pub(super) slot: u32,
}

/// Bits of [`HeapKey::rank_tie`] that hold the id.
pub(super) const ID_BITS: u32 = 40;

impl HeapKey {
    pub(super) fn new(cost: f64, orientation: usize, id: u64, slot: u32) -> Self {
        debug_assert!(id < 1 << ID_BITS && orientation < 1 << (64 - ID_BITS));
        let bits = quantised_cost(cost).to_bits();
        // negative: all bits flipped; positive: the sign bit set (`total_cmp`'s order as unsigned integers)
        let ordered = if bits >> 63 == 1 { !bits } else { bits | 1 << 63 };
        Self { rank_cost: !ordered, rank_tie: !((orientation as u64) << ID_BITS | id), slot }
    }

    /// The rounded cost.
    pub(super) fn cost(&self) -> f64 {
        let ordered = !self.rank_cost;
        f64::from_bits(if ordered >> 63 == 1 { ordered & !(1 << 63) } else { !ordered })
    }
}

/// The bit of [`HeapKey::slot`] that marks a family's entry.
pub(super) const FAMILY: u32 = 1 << 31;

/// The open nodes: a 4-ary heap ([`DaryHeap`]) of small keys (cost, orientation, id) over a slab of the solved nodes
/// (whose cells, optima and paths would otherwise be moved at every sift) and the families of pending children (one
/// entry each, see [`Family`]). Pops in the order (cost, orientation, id).
#[derive(Clone)]
pub(super) struct NodeHeap<const D: usize> {
    pub(super) keys: DaryHeap<HeapKey>,
    pub(super) slab: Vec<Option<Node<D>>>,
    pub(super) free: Vec<u32>,
    pub(super) families: Vec<Family<D>>,
    /// The families' children, each family's a contiguous run ([`Family::first`]).
    pub(super) children: Vec<(f64, u64, u32)>,
}

impl<const D: usize> Default for NodeHeap<D> {
    fn default() -> Self {
        Self { keys: DaryHeap::new(), slab: Vec::new(), free: Vec::new(), families: Vec::new(), children: Vec::new() }
    }
}

impl<const D: usize> NodeHeap<D> {
    pub(super) fn push(&mut self, node: Node<D>) {
        let (cost, orientation, id) = (node.cost, node.orientation, node.id);
        let slot = match self.free.pop() {
            Some(slot) => {
                self.slab[slot as usize] = Some(node);
                slot
            }
            None => {
                self.slab.push(Some(node));
                (self.slab.len() - 1) as u32
            }
        };
        self.keys.push(HeapKey::new(cost, orientation, id, slot));
    }

    /// Pushes a family with the pending children `children` (`(key, id, face)`; drained; none: nothing to push).
    /// `family.first` and `family.left` are set here.
    pub(super) fn push_family(&mut self, mut family: Family<D>, children: &mut Vec<(f64, u64, u32)>) {
        // descending in (rounded key, id): the cheapest last
        children.sort_unstable_by(|a, b| quantised_cost(b.0).total_cmp(&quantised_cost(a.0)).then(b.1.cmp(&a.1)));
        family.first = self.children.len();
        family.left = children.len() as u32;
        let Some(&(cost, id, _)) = children.last() else {
            return;
        };
        self.children.append(children);
        let index = self.families.len() as u32;
        self.keys.push(HeapKey::new(cost, family.orientation, id, index | FAMILY));
        self.families.push(family);
    }

    pub(super) fn pop(&mut self) -> Option<Popped<D>> {
        let top = *self.keys.peek()?;
        if top.slot & FAMILY != 0 {
            let index = top.slot & !FAMILY;
            let family = &mut self.families[index as usize];
            family.left = family.left.checked_sub(1)?;
            let (_, id, face) = self.children[family.first + family.left as usize];
            if family.left > 0 {
                // the family's next child: its key is not less than the popped one's, so it replaces the top
                let (cost, next, _) = self.children[family.first + family.left as usize - 1];
                self.keys.replace_top(HeapKey::new(cost, family.orientation, next, top.slot));
            } else {
                self.keys.pop();
            }
            return Some(Popped::Pending { family: index, id, face });
        }
        let key = self.keys.pop()?;
        self.free.push(key.slot);
        self.slab[key.slot as usize].take().map(Popped::Solved)
    }

    pub(super) fn len(&self) -> usize {
        self.keys.len()
    }

    /// The key popped next.
    pub(super) fn peek_key(&self) -> Option<HeapKey> {
        self.keys.peek().copied()
    }

    /// The cheapest key's (rounded) cost: a lower bound of every cost the heap still holds.
    pub(super) fn peek_cost(&self) -> Option<f64> {
        self.keys.peek().map(HeapKey::cost)
    }

    pub(super) fn is_empty(&self) -> bool {
        self.keys.is_empty()
    }
}

/// Whether key `a` pops after key `b` (the heap's order: cheaper, then lower orientation, then lower id first; the
/// slot is not part of the order).
pub(super) fn pops_after(a: HeapKey, b: HeapKey) -> bool {
    (a.rank_cost, a.rank_tie) < (b.rank_cost, b.rank_tie)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rounded key: last-bit neighbours compare equal, it is monotone, and it stays within `2^-40` relative.
    #[test]
    fn quantised_cost_merges_last_bit_ties_monotonically() {
        let exact = 8560.25_f64;
        let below = f64::from_bits(exact.to_bits() - 3);
        let above = f64::from_bits(exact.to_bits() + 5);
        assert_eq!(quantised_cost(below), quantised_cost(exact));
        assert_eq!(quantised_cost(above), quantised_cost(exact));
        assert!(quantised_cost(8560.25 * (1.0 + 1e-10)) > quantised_cost(exact));
        assert_eq!(quantised_cost(0.0), 0.0);
        assert_eq!(quantised_cost(f64::INFINITY), f64::INFINITY);
        let mut values: Vec<f64> = (0..2000).map(|i| 1e-3 * 1.37_f64.powi(i % 97) * (1.0 + i as f64 * 1e-14)).collect();
        values.extend([-2.5, -2.5000000000000004, 1.0, 0.9999999999999999, 2.0, 1.9999999999999998]);
        values.sort_by(f64::total_cmp);
        for w in values.windows(2) {
            assert!(quantised_cost(w[0]) <= quantised_cost(w[1]), "not monotone at {w:?}");
        }
        for v in values {
            let q = quantised_cost(v);
            assert!((q - v).abs() <= v.abs() * 2f64.powi(-40), "{v} -> {q}");
        }
    }

    /// The integer-encoded heap key orders as (rounded cost by `total_cmp`, orientation, id) reversed (the max-heap
    /// pops the cheapest), and gives the rounded cost back.
    #[test]
    fn heap_key_orders_as_cost_orientation_id() {
        let costs = [
            f64::NEG_INFINITY,
            -1e300,
            -2.5,
            -0.0,
            0.0,
            1e-300,
            0.75,
            1.0,
            1.0000000000000002,
            8560.25,
            8560.25 * (1.0 + 1e-9),
            1e300,
            f64::INFINITY,
        ];
        let mut keys = Vec::new();
        for (a, &cost) in costs.iter().enumerate() {
            for orientation in [0usize, 1, 359, (1 << 24) - 1] {
                for id in [0u64, 1, 77, (1 << 40) - 1] {
                    keys.push(((cost, orientation, id), HeapKey::new(cost, orientation, id, a as u32)));
                }
            }
        }
        for (x, kx) in &keys {
            assert_eq!(kx.cost().to_bits(), quantised_cost(x.0).to_bits(), "{x:?}");
            for (y, ky) in &keys {
                let expected =
                    quantised_cost(y.0).total_cmp(&quantised_cost(x.0)).then(y.1.cmp(&x.1)).then(y.2.cmp(&x.2));
                assert_eq!((kx.rank_cost, kx.rank_tie).cmp(&(ky.rank_cost, ky.rank_tie)), expected, "{x:?} vs {y:?}");
            }
        }
    }
}
