//! The sequential phase 1: is `{p : a_j . p <= b_j}` empty, decided from a known point `start` without a
//! Chebyshev LP, and a point of it when it is not.
//!
//! The inequalities violated at the current point are taken in order; for each, the LP `min a_j . p` over the
//! inequalities satisfied so far runs from the current point (a feasible start) and stops as soon as
//! `a_j . p <= b_j`; a minimum above that proves emptiness (the satisfied ones already exclude `j`). In 2 and 3
//! variables the LPs run in closed form (`Problem::seek_small`, [`crate::closed_form`]), the general active-set
//! method ([`crate::active_set`]) being the fallback. About one short LP per violated inequality, usually a single
//! move (a child cell of the planner's search violates one inequality at its parent's optimum). The cells use it on
//! their tolerance-grown inequalities to decide emptiness (`Cell::is_empty_with`) and on their own to find a point
//! of a child (`Cell::with_halfspaces_from`).

use crate::active_set::{ActiveSetError, Problem, Seek, default_tie};
use crate::halfspace::Tag;
use crate::linalg::{MAX_N, V4, dot_first, to_v4};

/// The sequential phase 1 on the inequalities `rows . p <= offsets` from `start` (`Cell::is_empty_with`): the
/// point reached (`None`: empty). `mask` (empty on entry) holds the satisfied set.
pub(crate) fn phase_one_rows<const D: usize>(
    rows: &[V4],
    offsets: &[f64],
    start: &[f64; D],
    mask: &mut Vec<bool>,
    length_scale: f64,
) -> Result<Option<V4>, ActiveSetError> {
    let mut point = to_v4(start);
    // the level over the D used lanes (the others are zeros: only the sign of a zero level can differ from the full
    // `dot4`, and `<=` does not see it)
    let satisfied_at = |j: usize, p: &V4| dot_first::<D>(&rows[j], p) <= offsets[j];
    // (a copy of the start point and zipped slices: no bounds checks, and the point stays in registers although
    // the mask's byte stores could alias it)
    let p0 = point;
    mask.extend(rows.iter().zip(offsets).map(|(row, &b)| dot_first::<D>(row, &p0) <= b));
    for j in 0..rows.len() {
        if mask[j] {
            continue;
        }
        if satisfied_at(j, &point) {
            mask[j] = true;
            continue;
        }
        let prob = Problem {
            n: D,
            rows,
            offsets,
            mask: Some(&mask[..]),
            h: [0.0; MAX_N],
            g: rows[j],
            tie: default_tie(D),
            length_scale,
        };
        // the closed-form iteration in 2-3 variables, the general one if it breaks down
        let seek = match prob.seek_small(point, offsets[j]) {
            Some(s) => s,
            None => prob.seek(point, offsets[j])?,
        };
        match seek {
            Seek::Reached(p) => point = p,
            Seek::Minimum { point: p, value } => {
                if value > offsets[j] {
                    return Ok(None);
                }
                point = p;
            }
        }
        mask[j] = true;
    }
    Ok(Some(point))
}

/// Per-thread lists for the LPs of a cell (rows, offsets, mask), reused between calls so that the hot paths
/// (`Cell::is_empty_with`, the Chebyshev LP of every new cell) allocate nothing once warm. Taken out of the
/// thread-local slot for the duration of a call and put back cleared, so a nested call simply finds an empty one.
#[derive(Default)]
pub(crate) struct Scratch {
    pub(crate) rows: Vec<V4>,
    pub(crate) offsets: Vec<f64>,
    pub(crate) mask: Vec<bool>,
    /// Offset and tag of each normalised extra inequality (`Cell::phase_one_in`).
    pub(crate) extra: Vec<(f64, Tag)>,
}

thread_local! {
    static SCRATCH: std::cell::Cell<Scratch> = std::cell::Cell::new(Scratch::default());
}

impl Scratch {
    pub(crate) fn take() -> Self {
        SCRATCH.with(std::cell::Cell::take)
    }

    fn clear(&mut self) {
        self.rows.clear();
        self.offsets.clear();
        self.mask.clear();
        self.extra.clear();
    }

    pub(crate) fn put_back(mut self) {
        self.clear();
        SCRATCH.with(|s| s.set(self));
    }
}
