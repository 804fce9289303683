//! A 4-ary max-heap: the priority queue of the best-first search's open nodes ([`crate::search`]).
//!
//! The same interface and pop order as `std::collections::BinaryHeap` for a total order (for keys that compare
//! equal the order is unspecified in both; the search's keys never do: their ids are unique). Four children per node
//! halve the levels a pop walks down (`log4 n` instead of `log2 n`), and the four children's keys lie in one or two
//! cache lines: the search's heap holds up to millions of keys across a stacking plan, and a pop's cost is the cache
//! misses of its walk. Williams (1964) for the binary heap; Johnson (1975) for d-ary heaps. Push O(log4 n), pop
//! O(4 log4 n) comparisons.

/// Children per node.
const ARITY: usize = 4;

/// A 4-ary max-heap (the greatest element pops first).
#[derive(Debug, Clone)]
pub struct DaryHeap<T> {
    items: Vec<T>,
}

impl<T> Default for DaryHeap<T> {
    fn default() -> Self {
        Self { items: Vec::new() }
    }
}

impl<T: Ord> DaryHeap<T> {
    /// An empty heap.
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of elements.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Whether the heap is empty.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// The greatest element.
    pub fn peek(&self) -> Option<&T> {
        self.items.first()
    }

    /// Adds `item`. O(log4 n).
    pub fn push(&mut self, item: T) {
        self.items.push(item);
        let mut at = self.items.len() - 1;
        while at > 0 {
            let parent = (at - 1) / ARITY;
            if self.items[at] <= self.items[parent] {
                break;
            }
            self.items.swap(at, parent);
            at = parent;
        }
    }

    /// Removes and returns the greatest element. O(4 log4 n).
    pub fn pop(&mut self) -> Option<T> {
        let last = self.items.pop()?;
        if self.items.is_empty() {
            return Some(last);
        }
        let top = std::mem::replace(&mut self.items[0], last);
        self.sift_down_from_root();
        Some(top)
    }

    /// Replaces the greatest element by `item` and returns it (`None`, and `item` pushed, when empty): a pop and a
    /// push in one walk down. O(4 log4 n).
    pub fn replace_top(&mut self, item: T) -> Option<T> {
        if self.items.is_empty() {
            self.items.push(item);
            return None;
        }
        let top = std::mem::replace(&mut self.items[0], item);
        self.sift_down_from_root();
        Some(top)
    }

    /// Restores the heap order after the root was replaced: swaps it with its greatest child while that child is
    /// greater.
    fn sift_down_from_root(&mut self) {
        let n = self.items.len();
        let mut at = 0;
        loop {
            let first = ARITY * at + 1;
            if first >= n {
                break;
            }
            let end = (first + ARITY).min(n);
            let mut best = first;
            for child in first + 1..end {
                if self.items[child] > self.items[best] {
                    best = child;
                }
            }
            if self.items[best] <= self.items[at] {
                break;
            }
            self.items.swap(at, best);
            at = best;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::DaryHeap;
    use proptest::prelude::*;
    use std::collections::BinaryHeap;

    proptest! {
        /// Any interleaving of pushes, pops and replacements of the top gives the pops of `BinaryHeap` (distinct keys:
        /// a total order).
        #[test]
        fn pops_as_the_binary_heap(ops in proptest::collection::vec((0u8..3, 0u32..50), 0..400)) {
            let mut ours = DaryHeap::new();
            let mut std_heap = BinaryHeap::new();
            for (k, (op, value)) in ops.into_iter().enumerate() {
                // unique keys as in the search: (value, insertion index)
                match op {
                    0 => {
                        ours.push((value, k));
                        std_heap.push((value, k));
                    }
                    1 => prop_assert_eq!(ours.pop(), std_heap.pop()),
                    _ => {
                        // a pop and a push: the same as replace_top
                        let popped = std_heap.pop();
                        std_heap.push((value, k));
                        prop_assert_eq!(ours.replace_top((value, k)), popped);
                    }
                }
                prop_assert_eq!(ours.len(), std_heap.len());
                prop_assert_eq!(ours.peek(), std_heap.peek());
            }
            while let Some(x) = std_heap.pop() {
                prop_assert_eq!(ours.pop(), Some(x));
            }
            prop_assert!(ours.is_empty());
            prop_assert_eq!(ours.pop(), None);
        }
    }
}
