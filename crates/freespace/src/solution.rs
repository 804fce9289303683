//! The answer of the placement QP ([`crate::qp`]): the optimum over a cell with its working set, multipliers and
//! tight inequalities, and why there may be none. O(m) to collect the tight set.

use crate::active_set::ActiveSetError;
use crate::cell::Cell;
use crate::linalg::MAX_N;

/// A short list read as a slice: up to [`ShortList::INLINE`] entries inline (the working set of the exact solver has
/// at most `D <= 3`), longer ones on the heap (clarabel's tight set), so that an exact QP solution allocates nothing
/// for its working set and multipliers. Compares equal to a `Vec`, an array or a slice with the same entries.
#[derive(Clone)]
pub struct ShortList<T> {
    inline: [T; ShortList::<()>::INLINE],
    len: usize,
    spill: Vec<T>,
}

impl ShortList<()> {
    /// The most entries kept inline.
    pub const INLINE: usize = MAX_N;
}

impl<T: Copy + Default> ShortList<T> {
    /// The list of `items` (inline when there are at most [`ShortList::INLINE`]).
    pub fn from_slice(items: &[T]) -> Self {
        let mut inline = [T::default(); ShortList::<()>::INLINE];
        if items.len() <= inline.len() {
            inline[..items.len()].copy_from_slice(items);
            Self { inline, len: items.len(), spill: Vec::new() }
        } else {
            Self { inline, len: items.len(), spill: items.to_vec() }
        }
    }
}

impl<T: Copy + Default> Default for ShortList<T> {
    fn default() -> Self {
        Self::from_slice(&[])
    }
}

impl<T> std::ops::Deref for ShortList<T> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        if self.len <= self.inline.len() { &self.inline[..self.len] } else { &self.spill }
    }
}

impl<'a, T> IntoIterator for &'a ShortList<T> {
    type Item = &'a T;
    type IntoIter = std::slice::Iter<'a, T>;
    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

impl<T: std::fmt::Debug> std::fmt::Debug for ShortList<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

impl<T: PartialEq> PartialEq for ShortList<T> {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

impl<T: PartialEq> PartialEq<Vec<T>> for ShortList<T> {
    fn eq(&self, other: &Vec<T>) -> bool {
        **self == **other
    }
}

impl<T: PartialEq> PartialEq<[T]> for ShortList<T> {
    fn eq(&self, other: &[T]) -> bool {
        **self == *other
    }
}

impl<T: PartialEq, const N: usize> PartialEq<[T; N]> for ShortList<T> {
    fn eq(&self, other: &[T; N]) -> bool {
        **self == other[..]
    }
}

/// An optimum over a cell.
#[derive(Debug, Clone, PartialEq)]
pub struct QpSolution<const D: usize> {
    /// The minimiser (the lexicographic one for the exact solver).
    pub point: [f64; D],
    /// The cost there.
    pub cost: f64,
    /// Indices (into [`Cell::halfspaces`]) of the working set at the optimum: linearly independent active
    /// inequalities (at most D), sorted. For the clarabel path: the tight inequalities.
    pub active: ShortList<usize>,
    /// Lagrange multipliers of `active` (same order; >= 0). Empty for the clarabel path.
    pub multipliers: ShortList<f64>,
    /// All inequalities within the cell's tolerance of equality at `point`, sorted.
    pub tight: Vec<usize>,
    /// Active-set iterations (0 for the clarabel path).
    pub iterations: usize,
}

/// Why a QP has no answer.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum QpError {
    /// The cell is empty.
    #[error("the cell is empty")]
    EmptyCell,
    /// The cost decreases without bound over the cell (impossible for bounded cells).
    #[error("the cost is unbounded below over the cell")]
    Unbounded,
    /// The active-set solver gave up.
    #[error(transparent)]
    Solver(#[from] ActiveSetError),
    /// The KKT check after the solve failed.
    #[error("KKT check failed: {what} (value {value:e}, allowed {allowed:e})")]
    Kkt {
        /// Which condition.
        what: &'static str,
        /// The offending value.
        value: f64,
        /// The allowed bound.
        allowed: f64,
    },
    /// clarabel did not report `Solved`.
    #[error("clarabel status {0}")]
    Clarabel(String),
}

/// The inequalities of `cell` within its tolerance of equality at `p`, in order. O(m).
pub(crate) fn tight_set<const D: usize>(cell: &Cell<D>, p: &[f64; D]) -> Vec<usize> {
    tight_set_within(cell, p, cell.tolerance().linear)
}

/// The inequalities of `cell` within `tol` of equality at `p`, in order. O(m).
pub(crate) fn tight_set_within<const D: usize>(cell: &Cell<D>, p: &[f64; D], tol: f64) -> Vec<usize> {
    (0..cell.len()).filter(|&j| cell.halfspaces()[j].excess(p).abs() <= tol).collect()
}
