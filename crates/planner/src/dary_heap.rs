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
        // sift the moved element down: swap with the greatest child while that child is greater
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
        Some(top)
    }
}

#[cfg(test)]
mod tests {
    use super::DaryHeap;
    use proptest::prelude::*;
    use std::collections::BinaryHeap;

    proptest! {
        /// Any interleaving of pushes and pops gives the pops of `BinaryHeap` (distinct keys: a total order).
        #[test]
        fn pops_as_the_binary_heap(ops in proptest::collection::vec((any::<bool>(), 0u32..50), 0..400)) {
            let mut ours = DaryHeap::new();
            let mut std_heap = BinaryHeap::new();
            for (k, (push, value)) in ops.into_iter().enumerate() {
                // unique keys as in the search: (value, insertion index)
                if push {
                    ours.push((value, k));
                    std_heap.push((value, k));
                } else {
                    prop_assert_eq!(ours.pop(), std_heap.pop());
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
