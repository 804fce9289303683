//! A face's vertex cycle with its first few indices stored inline.
//!
//! Sheet-metal components are boxes and thin prisms, and the c-space obstacles of their pairs are prisms too: almost
//! every face is a triangle or a quadrilateral. A `Vec<usize>` per face costs one heap allocation to build, one to
//! clone and one to free for each of them; a c-space obstacle of two hexagonal prisms has 12 quadrilateral sides, and
//! those allocations would be a tenth of its construction time (`cargo bench -p stackplan-cspace --bench obstacle`). A
//! [`VertexCycle`] keeps up to [`VertexCycle::INLINE`] indices inside the face and spills longer cycles to the heap.
//!
//! It reads like a `[usize]` (it dereferences to one) and prints, compares, serialises and deserialises exactly like
//! a `Vec<usize>` (a JSON array of indices), so files and `Debug` output are those of a plain list. The inline
//! storage is an implementation detail: `smallvec` does not appear in the public API.

use serde::{Deserialize, Serialize};
use smallvec::SmallVec;
use std::fmt;
use std::ops::{Deref, DerefMut};

/// The vertex indices of a face, in order (for [`crate::Face`]: counter-clockwise seen from outside).
///
/// Up to [`Self::INLINE`] indices are stored without a heap allocation. Dereferences to `[usize]`; build one with
/// `From<Vec<usize>>`, `From<[usize; N]>`, `From<&[usize]>` or by collecting an iterator.
#[derive(Clone, Default, PartialEq, Eq, Hash)]
pub struct VertexCycle(SmallVec<[usize; VertexCycle::INLINE]>);

impl VertexCycle {
    /// How many indices are stored inline (a quadrilateral).
    pub const INLINE: usize = 4;

    /// An empty cycle.
    pub fn new() -> Self {
        Self(SmallVec::new())
    }

    /// An empty cycle with room for `capacity` indices (no allocation up to [`Self::INLINE`]).
    pub fn with_capacity(capacity: usize) -> Self {
        Self(SmallVec::with_capacity(capacity))
    }

    /// Appends an index.
    #[inline]
    pub fn push(&mut self, index: usize) {
        self.0.push(index);
    }

    /// Inserts an index at position `at`, shifting the later ones. Panics if `at > len`, as `Vec::insert` does.
    pub fn insert(&mut self, at: usize, index: usize) {
        self.0.insert(at, index);
    }

    /// Whether the indices are stored inline (no heap allocation).
    pub fn is_inline(&self) -> bool {
        !self.0.spilled()
    }

    /// The indices as a `Vec` (moved without copying when they are already on the heap).
    pub fn into_vec(self) -> Vec<usize> {
        self.0.into_vec()
    }

    /// The indices as a slice.
    #[inline]
    pub fn as_slice(&self) -> &[usize] {
        self.0.as_slice()
    }
}

impl Deref for VertexCycle {
    type Target = [usize];

    #[inline]
    fn deref(&self) -> &[usize] {
        self.0.as_slice()
    }
}

impl DerefMut for VertexCycle {
    #[inline]
    fn deref_mut(&mut self) -> &mut [usize] {
        self.0.as_mut_slice()
    }
}

impl AsRef<[usize]> for VertexCycle {
    fn as_ref(&self) -> &[usize] {
        self
    }
}

impl fmt::Debug for VertexCycle {
    /// As a `Vec<usize>` prints: `[0, 1, 2]`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.0.iter()).finish()
    }
}

impl From<Vec<usize>> for VertexCycle {
    /// Keeps the vector's allocation when it is longer than [`Self::INLINE`], else moves the indices inline.
    fn from(v: Vec<usize>) -> Self {
        if v.len() <= Self::INLINE { Self(SmallVec::from_slice(&v)) } else { Self(SmallVec::from_vec(v)) }
    }
}

impl From<&[usize]> for VertexCycle {
    fn from(v: &[usize]) -> Self {
        Self(SmallVec::from_slice(v))
    }
}

impl<const N: usize> From<[usize; N]> for VertexCycle {
    fn from(v: [usize; N]) -> Self {
        Self(SmallVec::from_slice(&v))
    }
}

impl FromIterator<usize> for VertexCycle {
    fn from_iter<I: IntoIterator<Item = usize>>(iter: I) -> Self {
        Self(iter.into_iter().collect())
    }
}

impl<'a> IntoIterator for &'a VertexCycle {
    type Item = &'a usize;
    type IntoIter = std::slice::Iter<'a, usize>;

    fn into_iter(self) -> Self::IntoIter {
        self.0.iter()
    }
}

impl IntoIterator for VertexCycle {
    type Item = usize;
    type IntoIter = IntoIter;

    fn into_iter(self) -> Self::IntoIter {
        IntoIter(self.0.into_iter())
    }
}

/// The owning iterator of a [`VertexCycle`] (its indices in order; the storage stays private).
#[derive(Debug, Clone)]
pub struct IntoIter(smallvec::IntoIter<[usize; VertexCycle::INLINE]>);

impl Iterator for IntoIter {
    type Item = usize;

    fn next(&mut self) -> Option<usize> {
        self.0.next()
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        self.0.size_hint()
    }
}

impl DoubleEndedIterator for IntoIter {
    fn next_back(&mut self) -> Option<usize> {
        self.0.next_back()
    }
}

impl ExactSizeIterator for IntoIter {}

impl std::iter::FusedIterator for IntoIter {}

impl PartialEq<[usize]> for VertexCycle {
    fn eq(&self, other: &[usize]) -> bool {
        self.as_slice() == other
    }
}

impl PartialEq<Vec<usize>> for VertexCycle {
    fn eq(&self, other: &Vec<usize>) -> bool {
        self.as_slice() == other.as_slice()
    }
}

impl<const N: usize> PartialEq<[usize; N]> for VertexCycle {
    fn eq(&self, other: &[usize; N]) -> bool {
        self.as_slice() == other.as_slice()
    }
}

impl Serialize for VertexCycle {
    /// A sequence of indices, as `Vec<usize>` serialises.
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.as_slice().serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for VertexCycle {
    /// A sequence of indices, as `Vec<usize>` deserialises.
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        Vec::<usize>::deserialize(deserializer).map(Self::from)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_cycles_are_inline_and_long_ones_keep_their_allocation() {
        let quad = VertexCycle::from(vec![3, 1, 4, 1]);
        assert!(quad.is_inline());
        assert_eq!(quad, [3, 1, 4, 1]);
        let hexagon = vec![0, 1, 2, 3, 4, 5];
        let address = hexagon.as_ptr();
        let long = VertexCycle::from(hexagon);
        assert!(!long.is_inline());
        assert_eq!(long.as_ptr(), address, "a spilled cycle reuses the vector's buffer");
        assert_eq!(long.into_vec(), vec![0, 1, 2, 3, 4, 5]);
    }

    #[test]
    fn prints_and_serialises_like_a_vec() {
        for v in [vec![], vec![7], vec![0, 2, 3, 1], vec![9, 8, 7, 6, 5, 4, 3]] {
            let cycle = VertexCycle::from(v.clone());
            assert_eq!(format!("{cycle:?}"), format!("{v:?}"));
            assert_eq!(format!("{cycle:#?}"), format!("{v:#?}"));
            let json = serde_json::to_string(&cycle).expect("a cycle serialises");
            assert_eq!(json, serde_json::to_string(&v).expect("a vec serialises"));
            let back: VertexCycle = serde_json::from_str(&json).expect("its own JSON reads back");
            assert_eq!(back, cycle);
        }
        assert!(serde_json::from_str::<VertexCycle>("[1, -2]").is_err(), "negative indices are refused");
    }

    #[test]
    fn builds_from_slices_arrays_and_iterators() {
        let a = VertexCycle::from([5, 6, 7]);
        let b = VertexCycle::from(&[5usize, 6, 7][..]);
        let c: VertexCycle = (5..8).collect();
        let mut d = VertexCycle::with_capacity(3);
        d.push(6);
        d.push(7);
        d.insert(0, 5);
        assert!(a == b && b == c && c == d);
        assert_eq!(d.iter().rev().copied().collect::<Vec<_>>(), vec![7, 6, 5]);
        let mut e = d.clone();
        e.reverse();
        assert_eq!(e, vec![7, 6, 5]);
        assert_eq!(d.into_iter().sum::<usize>(), 18);
    }
}
