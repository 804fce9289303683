//! Convex free-space cells: H-polytopes `{p : a_j . p <= b_j}` in 2 or 3 variables with provenance tags.
//!
//! \[A\] VI-A-1 (Ayyadevara et al. 2002, section 6.1.1): "each convex component of free space is represented as a set
//! of linear inequalities that describe the bounding faces of the component". A [`Cell`] stores its inequalities with
//! unit normals, a [`Tag`] per inequality (so the planner can map an active constraint back to an obstacle face or a
//! side of the floor volume), the problem's [`Tolerance`], and its [`CellShape`], computed once at construction from
//! the Chebyshev LP
//!
//! ```text
//! max r   s.t.   a_j . c + r <= b_j  (|a_j| = 1),   r <= cap
//! ```
//!
//! (ties broken by the lowest centre z, then y, then x, so the centre is deterministic). `r* < -tol`: empty;
//! `|r*| <= tol`: flat (a face, an edge or a point, within the tolerance); `r* > tol`: solid with centre `c*` and
//! inradius `r*`. The LP is solved by the exact active-set method of `active_set.rs` (one extra variable):
//! O(m) per iteration, a handful of iterations.
//!
//! **Boundedness.** Every non-empty cell is bounded: [`Cell::new`] checks it (2D LPs `max +-p_i`) and returns
//! [`CellError::Unbounded`] otherwise. Cells derived from a bounded cell (Omega, subtraction pieces, intersections)
//! are subsets of it and skip the check. So the QP on a cell always has a minimiser and every tie-break terminates.
//!
//! **Known points.** [`Cell::is_empty_with`] decides the emptiness of a child cell by a phase 1 from a point of its
//! parent (closed-form LPs in 2-3 variables, no Chebyshev LP); [`Cell::with_halfspaces_from`] also builds the
//! non-empty child from a point found that way ([`CellShape::Known`]), skipping its Chebyshev LP.
//!
//! Redundancy removal costs one LP per inequality (O(m) iterations of O(m) each); membership is O(m).

use crate::active_set::{ActiveSetError, Outcome, Problem, default_tie};
use crate::clarabel::clarabel_qp;
use crate::halfspace::{Halfspace, Tag};
use crate::linalg::{MAX_N, V4, from_v4, to_v4};
use crate::phase_one::{Scratch, phase_one_rows};
use geom::{Containment, Tolerance};
use stackplan_geom as geom;

/// The shape of a cell, from its Chebyshev LP.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CellShape<const D: usize> {
    /// No point satisfies all inequalities (by more than the tolerance).
    Empty,
    /// Lower-dimensional within the tolerance (a face, an edge or a point); `point` is in the cell within tolerance.
    Flat {
        /// A point of the cell.
        point: [f64; D],
    },
    /// Non-empty, built from a known point of it without the Chebyshev LP ([`Cell::with_halfspaces_from`]): flat or
    /// solid, not classified. `point` is in the cell (within rounding), on its boundary in general.
    Known {
        /// A point of the cell.
        point: [f64; D],
    },
    /// Full-dimensional: the centre and radius of the largest inscribed ball.
    Solid {
        /// Chebyshev centre.
        centre: [f64; D],
        /// Inradius (> tolerance).
        radius: f64,
    },
}

/// Why a cell cannot be built or analysed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CellError {
    /// An inequality has a NaN or infinite coefficient.
    #[error("inequality {index} has a non-finite coefficient")]
    NonFinite {
        /// Index of the inequality.
        index: usize,
    },
    /// The cell is non-empty and unbounded (cells must be bounded, e.g. by Omega).
    #[error("the cell is unbounded; intersect it with Omega (or another bounded cell) first")]
    Unbounded,
    /// The LP solver gave up.
    #[error("LP for {purpose} failed: {source}")]
    Solver {
        /// What the LP was for.
        purpose: &'static str,
        /// The solver's error.
        source: ActiveSetError,
    },
}

/// A convex cell in `D` (2 or 3) variables. See the module documentation.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell<const D: usize> {
    halfspaces: Vec<Halfspace<D>>,
    /// The solvers' lists in one buffer: the `m` normals as 4-vectors, then the `m` offsets packed four to an entry
    /// (see [`Cell::rows`], [`Cell::offsets`]).
    lists: Vec<V4>,
    tolerance: Tolerance,
    shape: CellShape<D>,
    /// Whether every normal is a fixed point of [`unit_halfspace`] (its computed length is exactly 1.0), so that
    /// normalising the inequalities again is the identity ([`Cell::extended`] then copies them). A function of the
    /// inequalities (so the derived equality of cells is the one of their lists).
    unit: bool,
}

/// Euclidean length of a normal as the cells compute it (sum of squares in order, then the square root).
#[inline]
fn length<const D: usize>(normal: &[f64; D]) -> f64 {
    normal.iter().map(|c| c * c).sum::<f64>().sqrt()
}

/// `h` scaled to a unit normal (`None` for a zero normal): the normal and the offset divided by the computed length.
/// The flag says whether the result is a fixed point: its computed length is exactly 1.0, so normalising it again
/// divides by 1.0 and leaves it unchanged, bit for bit. (About three in four normals; the others move by an ulp
/// when normalised again, some of them back and forth.) O(D).
#[inline]
fn unit_halfspace<const D: usize>(h: &Halfspace<D>) -> Option<(Halfspace<D>, bool)> {
    let len = length(&h.normal);
    (len > 0.0).then(|| {
        let u = Halfspace { normal: h.normal.map(|c| c / len), offset: h.offset / len, tag: h.tag };
        (u, length(&u.normal) == 1.0)
    })
}

/// The packed lists of a cell's (normalised) inequalities: their normals as 4-vectors, then their offsets four to an
/// entry. One allocation.
fn pack<const D: usize>(halfspaces: &[Halfspace<D>]) -> Vec<V4> {
    let m = halfspaces.len();
    let mut lists = Vec::with_capacity(m + m.div_ceil(MAX_N));
    lists.extend(halfspaces.iter().map(|h| to_v4(&h.normal)));
    for chunk in halfspaces.chunks(MAX_N) {
        let mut v = [0.0; MAX_N];
        for (slot, h) in v.iter_mut().zip(chunk) {
            *slot = h.offset;
        }
        lists.push(v);
    }
    lists
}

/// Appends `halfspaces` normalised ([`unit_halfspace`]) to `kept`, as [`Cell::new`] keeps them: a non-finite
/// coefficient is an error (index `first_index + k`); a zero normal is dropped when it holds (`0 <= offset + tol`)
/// and kept when it fails. Returns whether one failed (the cell is empty); `unit` is cleared when a kept inequality
/// is not a fixed point of the normalisation. O(1) per inequality.
fn push_normalised<const D: usize>(
    kept: &mut Vec<Halfspace<D>>,
    unit: &mut bool,
    halfspaces: &[Halfspace<D>],
    first_index: usize,
    tolerance: Tolerance,
) -> Result<bool, CellError> {
    let mut trivially_empty = false;
    for (k, h) in halfspaces.iter().enumerate() {
        if !h.offset.is_finite() || h.normal.iter().any(|c| !c.is_finite()) {
            return Err(CellError::NonFinite { index: first_index + k });
        }
        match unit_halfspace(h) {
            Some((u, fixed)) => {
                kept.push(u);
                *unit &= fixed;
            }
            None if h.offset < -tolerance.linear => {
                trivially_empty = true;
                kept.push(*h);
                *unit = false;
            }
            None => {}
        }
    }
    Ok(trivially_empty)
}

/// Result of a linear programme over a cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum LpResult<const D: usize> {
    /// Lexicographic optimum (objective, then lowest z, y, x).
    Optimal { point: [f64; D], value: f64 },
    /// The objective is unbounded below.
    Unbounded,
}

impl<const D: usize> Cell<D> {
    const DIM_OK: () = assert!(D == 2 || D == 3, "cells have 2 or 3 variables");

    /// A cell from inequalities under the tolerance policy `tolerance`; checks finiteness and boundedness.
    ///
    /// Normals are scaled to unit length (with their offsets). An inequality with a zero normal is dropped when it
    /// holds (`0 <= offset + tol`) and makes the cell empty when it does not.
    pub fn new(halfspaces: Vec<Halfspace<D>>, tolerance: Tolerance) -> Result<Self, CellError> {
        Self::build(halfspaces, tolerance, true)
    }

    /// [`Cell::new`] without the boundedness check (its `2 D` LPs), for a caller that knows the cell is bounded or
    /// checks it with [`Cell::check_bounded`]: e.g. many cells with the same normals and different offsets (a
    /// non-empty polyhedron `{A p <= b}` is bounded iff `{A p <= 0} = {0}`, which does not depend on `b`), checked once.
    pub fn new_unchecked_bounds(halfspaces: Vec<Halfspace<D>>, tolerance: Tolerance) -> Result<Self, CellError> {
        Self::build(halfspaces, tolerance, false)
    }

    /// Builds without the boundedness check: only for subsets of a bounded cell.
    pub(crate) fn build(
        halfspaces: Vec<Halfspace<D>>,
        tolerance: Tolerance,
        check_bounded: bool,
    ) -> Result<Self, CellError> {
        let mut cell = Self::normalised(halfspaces, tolerance)?;
        if cell.shape != CellShape::Empty {
            cell.shape = cell.chebyshev()?;
            if check_bounded && cell.shape != CellShape::Empty {
                cell.check_bounded()?;
            }
        }
        Ok(cell)
    }

    /// The cell of `halfspaces` with unit normals, before its shape is known: [`CellShape::Empty`] when an inequality
    /// with a zero normal fails, otherwise (provisionally) [`CellShape::Known`] at the origin.
    fn normalised(halfspaces: Vec<Halfspace<D>>, tolerance: Tolerance) -> Result<Self, CellError> {
        let () = Self::DIM_OK;
        let mut kept = Vec::with_capacity(halfspaces.len());
        let mut unit = true;
        let trivially_empty = push_normalised(&mut kept, &mut unit, &halfspaces, 0, tolerance)?;
        let lists = pack(&kept);
        let shape = if trivially_empty { CellShape::Empty } else { CellShape::Known { point: [0.0; D] } };
        Ok(Self { halfspaces: kept, lists, tolerance, shape, unit })
    }

    /// The inequalities (unit normals), in order; active-constraint indices refer to this list.
    pub fn halfspaces(&self) -> &[Halfspace<D>] {
        &self.halfspaces
    }

    /// Number of inequalities.
    pub fn len(&self) -> usize {
        self.halfspaces.len()
    }

    /// Whether the cell has no inequalities (never true for a bounded cell).
    pub fn is_empty_list(&self) -> bool {
        self.halfspaces.is_empty()
    }

    /// The tolerance policy of the cell.
    pub fn tolerance(&self) -> Tolerance {
        self.tolerance
    }

    /// Empty, flat or solid.
    pub fn shape(&self) -> CellShape<D> {
        self.shape
    }

    /// Whether no point satisfies the inequalities.
    pub fn is_empty(&self) -> bool {
        self.shape == CellShape::Empty
    }

    /// Whether the cell is full-dimensional (inradius above the tolerance).
    pub fn is_solid(&self) -> bool {
        matches!(self.shape, CellShape::Solid { .. })
    }

    /// Chebyshev centre and inradius (`None` for empty and flat cells).
    pub fn chebyshev_centre(&self) -> Option<([f64; D], f64)> {
        match self.shape {
            CellShape::Solid { centre, radius } => Some((centre, radius)),
            _ => None,
        }
    }

    /// A point of the cell (the Chebyshev centre of a solid cell), `None` when empty.
    pub fn interior_point(&self) -> Option<[f64; D]> {
        match self.shape {
            CellShape::Empty => None,
            CellShape::Flat { point } | CellShape::Known { point } => Some(point),
            CellShape::Solid { centre, .. } => Some(centre),
        }
    }

    /// Where `p` is, under the cell's tolerance: interior (every slack > tol), boundary, or exterior.
    pub fn contains(&self, p: &[f64; D]) -> Containment {
        let mut worst = f64::NEG_INFINITY;
        for h in &self.halfspaces {
            worst = worst.max(h.excess(p));
        }
        if worst > self.tolerance.linear {
            Containment::Exterior
        } else if worst < -self.tolerance.linear {
            Containment::Interior
        } else {
            Containment::Boundary
        }
    }

    /// A cell with `extra` inequalities added (a subset of this one, so no boundedness check).
    pub fn with_halfspaces(&self, extra: impl IntoIterator<Item = Halfspace<D>>) -> Result<Self, CellError> {
        let extra = extra.into_iter();
        let mut hs = Vec::with_capacity(self.halfspaces.len() + extra.size_hint().0);
        hs.extend_from_slice(&self.halfspaces);
        hs.extend(extra);
        Self::build(hs, self.tolerance, false)
    }

    /// Whether this cell with `extra` inequalities added is empty, decided from `start`, a point of this cell (within
    /// the tolerance), without the Chebyshev LP: the sequential phase 1 on the cell grown by the tolerance (every
    /// `b_j + tol`; it is non-empty iff the Chebyshev radius is at least `-tol`, so the answer is the one of
    /// `self.with_halfspaces(extra)?.is_empty()`, up to rounding at that boundary). The inequalities violated at the
    /// current point by more than the tolerance are taken in order; for each, the LP `min a_j . p` over the
    /// inequalities satisfied so far runs from the current point (the active-set solver of `active_set.rs`)
    /// and stops on reaching `a_j . p = b_j + tol`. If its minimum stays above that, the satisfied inequalities
    /// already exclude `j`: empty. Otherwise the point moves there and `j` joins the satisfied set. Each LP starts
    /// feasible; about one LP per violated inequality, usually a single move (a child cell of the planner's search
    /// violates one inequality at its parent's optimum), against the Chebyshev LP's four variables from a cold start.
    /// `extra` is normalised as in [`Cell::new`].
    pub fn is_empty_with(
        &self,
        extra: impl IntoIterator<Item = Halfspace<D>>,
        start: &[f64; D],
    ) -> Result<bool, CellError> {
        if self.is_empty() {
            return Ok(true);
        }
        // the row, offset and mask lists live in a per-thread scratch (no allocation per call once warm)
        let mut scratch = Scratch::take();
        let result = self.phase_one_in(extra, start, self.tolerance.linear, &mut scratch);
        scratch.put_back();
        Ok(result?.is_none())
    }

    /// This cell with `extra` inequalities added, built from `start`, a point of this cell (within the tolerance),
    /// without the Chebyshev LP; `None` when it is empty.
    ///
    /// Emptiness is decided exactly as by [`Cell::is_empty_with`] (the phase 1 on the tolerance-grown cell). For a
    /// non-empty cell a second phase 1 from `start` on the cell as it is (offsets not grown) gives a point of it (on
    /// the boundary of the inequalities `start` violated), which becomes the cell's interior point (the start of its
    /// QP and LPs) with the shape [`CellShape::Known`]. When only the grown cell is non-empty (the cell is thinner
    /// than the tolerance, or empty by less than it), the cell is built as by [`Cell::with_halfspaces`] (Chebyshev LP).
    /// Cost: about one short LP per inequality violated at `start` per phase (a child of the planner's search violates
    /// one), against the Chebyshev LP's four variables from a cold start.
    ///
    /// The QP over the cell then starts from another point than over `with_halfspaces(extra)`: its optimum is the
    /// same up to rounding in the last bits (the minimiser is unique for strictly convex costs), not bit for bit.
    pub fn with_halfspaces_from(&self, extra: &[Halfspace<D>], start: &[f64; D]) -> Result<Option<Self>, CellError> {
        if self.is_empty() {
            return Ok(None);
        }
        let mut scratch = Scratch::take();
        let grown = self.phase_one_in(extra.iter().copied(), start, self.tolerance.linear, &mut scratch);
        let grown = match grown {
            Ok(Some(_)) => Ok(()),
            Ok(None) => {
                scratch.put_back();
                return Ok(None);
            }
            Err(e) => Err(e),
        };
        // the child itself (`Cell::extended`, from the extra inequalities the grown phase 1 normalised); its exact
        // phase 1 runs on its own rows
        let built = grown.and_then(|()| self.extended(&scratch.rows[self.len()..], &scratch.extra));
        scratch.mask.clear();
        let exact = match &built {
            Ok(cell) if cell.shape != CellShape::Empty => {
                let mask = &mut scratch.mask;
                phase_one_rows(cell.rows(), cell.offsets(), start, mask, self.length_scale())
                    .map_err(|source| CellError::Solver { purpose: "phase 1", source })
            }
            Ok(_) => Ok(None),
            Err(e) => Err(e.clone()),
        };
        scratch.put_back();
        let mut cell = built?;
        if cell.shape == CellShape::Empty {
            return Ok(None);
        }
        match exact? {
            Some(point) => {
                cell.shape = CellShape::Known { point: from_v4(&point) };
                Ok(Some(cell))
            }
            None => {
                let cell = self.with_halfspaces(extra.iter().copied())?;
                Ok((!cell.is_empty()).then_some(cell))
            }
        }
    }

    /// This cell (non-empty) with extra inequalities added that are normalised already: the rows `extra_rows` with
    /// the offsets and tags of `extra` (as [`Cell::phase_one_in`] leaves them in its scratch: `unit_halfspace` of
    /// each extra inequality, zero normals that hold dropped). The result is `Cell::new` of all the inequalities
    /// (provisionally [`CellShape::Known`] at the origin, or [`CellShape::Empty`]), bit for bit: the extra
    /// inequalities went through the same normalisation, and this cell's are normalised again as `Cell::new` would.
    ///
    /// When every inequality of this cell is a fixed point of the normalisation (`unit`), normalising them again is
    /// the identity, so they are copied (`extend_from_slice` of the inequalities, the rows and the offsets: O(m)
    /// copies, no square root or division). Otherwise they are normalised again one by one. One allocation for the
    /// inequalities, one for the rows and offsets.
    fn extended(&self, extra_rows: &[V4], extra: &[(f64, Tag)]) -> Result<Self, CellError> {
        let mut halfspaces = Vec::with_capacity(self.halfspaces.len() + extra.len());
        let mut unit = true;
        let mut trivially_empty = false;
        if self.unit {
            // every inequality is a fixed point of `unit_halfspace`: normalising them again is the identity
            halfspaces.extend_from_slice(&self.halfspaces);
        } else {
            // (empty only if a normal vanished: an overflowing length made it zero)
            trivially_empty = push_normalised(&mut halfspaces, &mut unit, &self.halfspaces, 0, self.tolerance)?;
        }
        let m0 = halfspaces.len();
        for (row, &(offset, tag)) in extra_rows.iter().zip(extra) {
            let normal = from_v4(row);
            // the fixed-point flag of `unit_halfspace`
            unit &= length(&normal) == 1.0;
            halfspaces.push(Halfspace { normal, offset, tag });
        }
        let lists = if self.unit {
            // the parent's lists copied, the extra rows and offsets after them
            let m = halfspaces.len();
            let mut lists = Vec::with_capacity(m + m.div_ceil(MAX_N));
            lists.extend_from_slice(self.rows());
            lists.extend_from_slice(extra_rows);
            lists.resize(m + m.div_ceil(MAX_N), [0.0; MAX_N]);
            let offsets = &mut lists[m..].as_flattened_mut()[..m];
            offsets[..m0].copy_from_slice(self.offsets());
            for (b, e) in offsets[m0..].iter_mut().zip(extra) {
                *b = e.0;
            }
            lists
        } else {
            pack(&halfspaces)
        };
        let shape = if trivially_empty { CellShape::Empty } else { CellShape::Known { point: [0.0; D] } };
        Ok(Self { halfspaces, lists, tolerance: self.tolerance, shape, unit })
    }

    /// The sequential phase 1 of [`Cell::is_empty_with`] on this cell with `extra` added, every offset grown by
    /// `grow`: the point reached (`None`: empty), lists in `scratch` (the extra inequalities normalised: their rows
    /// after this cell's, their offsets (not grown) and tags in `scratch.extra`).
    fn phase_one_in(
        &self,
        extra: impl IntoIterator<Item = Halfspace<D>>,
        start: &[f64; D],
        grow: f64,
        scratch: &mut Scratch,
    ) -> Result<Option<V4>, CellError> {
        let tol = grow;
        let first_extra = self.len();
        let Scratch { rows, offsets: grown, mask, extra: normalised } = scratch;
        rows.extend_from_slice(self.rows());
        // the grown cell's offsets
        grown.extend(self.offsets().iter().map(|b| b + tol));
        for (k, h) in extra.into_iter().enumerate() {
            if !h.offset.is_finite() || h.normal.iter().any(|c| !c.is_finite()) {
                return Err(CellError::NonFinite { index: first_extra + k });
            }
            // normalised as by `Cell::new`
            if let Some((u, _)) = unit_halfspace(&h) {
                rows.push(to_v4(&u.normal));
                grown.push(u.offset + tol);
                normalised.push((u.offset, u.tag));
            } else if h.offset < -self.tolerance.linear {
                return Ok(None);
            }
        }
        phase_one_rows(rows, grown, start, mask, self.length_scale())
            .map_err(|source| CellError::Solver { purpose: "phase 1", source })
    }

    /// This cell with every offset grown by its tolerance: the cell on which emptiness is decided
    /// ([`Cell::is_empty_with`]; a cell that is non-empty within the tolerance has an exact common point here), for
    /// solvers that fail on a cell thinner than the tolerance (the planner's clarabel fallback;
    /// [`crate::qp::minimize`] retries on [`crate::outer_box::grown_without_near_duplicates`]).
    pub fn grown_by_tolerance(&self) -> Result<Self, CellError> {
        let tol = self.tolerance.linear;
        let grown = self.halfspaces.iter().map(|h| Halfspace { offset: h.offset + tol, ..*h }).collect();
        Self::new(grown, self.tolerance)
    }

    /// The intersection of two cells (inequalities of `self`, then of `other`); tolerance of `self`.
    pub fn intersection(&self, other: &Self) -> Result<Self, CellError> {
        self.with_halfspaces(other.halfspaces.iter().copied())
    }

    /// The same set without redundant inequalities.
    ///
    /// Inequality `j` is redundant when `max a_j . p` over the cell without `j` is at most `b_j + tol`; inequalities
    /// are tested in order and removed at once, so of two identical inequalities the later one is kept. One LP per
    /// inequality. An empty cell is returned unchanged.
    pub fn without_redundant(&self) -> Result<Self, CellError> {
        if self.is_empty() {
            return Ok(self.clone());
        }
        let m = self.halfspaces.len();
        let mut mask = vec![true; m];
        for j in 0..m {
            mask[j] = false;
            let objective = self.halfspaces[j].normal.map(|c| -c);
            let redundant = match self.lp_masked(&objective, Some(&mask), "redundancy test")? {
                LpResult::Optimal { value, .. } => -value <= self.halfspaces[j].offset + self.tolerance.linear,
                LpResult::Unbounded => false,
            };
            mask[j] = !redundant;
        }
        let hs: Vec<Halfspace<D>> =
            self.halfspaces.iter().zip(&mask).filter(|(_, keep)| **keep).map(|(h, _)| *h).collect();
        let lists = pack(&hs);
        let unit = hs.iter().all(|h| length(&h.normal) == 1.0);
        Ok(Self { halfspaces: hs, lists, tolerance: self.tolerance, shape: self.shape, unit })
    }

    /// This cell with only the inequalities `kept` (a sub-list of this cell's, in order, as the caller proved the
    /// others redundant): the same set, so the same shape and interior point. Lists packed again; O(m).
    pub(crate) fn with_only(&self, kept: Vec<Halfspace<D>>) -> Self {
        let lists = pack(&kept);
        let unit = self.unit || kept.iter().all(|h| length(&h.normal) == 1.0);
        Self { halfspaces: kept, lists, tolerance: self.tolerance, shape: self.shape, unit }
    }

    /// Maximum of `direction . p` over the cell with a maximiser (lowest z, y, x among maximisers); `None` if empty.
    pub fn support(&self, direction: &[f64; D]) -> Result<Option<(f64, [f64; D])>, CellError> {
        if self.is_empty() {
            return Ok(None);
        }
        match self.lp_masked(&direction.map(|c| -c), None, "support")? {
            LpResult::Optimal { point, value } => Ok(Some((-value, point))),
            LpResult::Unbounded => Err(CellError::Unbounded),
        }
    }

    /// The normals as 4-vectors (the solvers' rows), in the order of [`Cell::halfspaces`].
    pub(crate) fn rows(&self) -> &[V4] {
        &self.lists[..self.halfspaces.len()]
    }

    /// The offsets, in the order of [`Cell::halfspaces`].
    pub(crate) fn offsets(&self) -> &[f64] {
        let m = self.halfspaces.len();
        &self.lists[m..].as_flattened()[..m]
    }

    /// The characteristic length used for relative thresholds of the solvers.
    pub(crate) fn length_scale(&self) -> f64 {
        (self.tolerance.linear / geom::tolerance::RELATIVE).max(1.0)
    }

    /// min `objective . p` over the (masked) cell, from the cell's interior point.
    pub(crate) fn lp_masked(
        &self,
        objective: &[f64; D],
        mask: Option<&[bool]>,
        purpose: &'static str,
    ) -> Result<LpResult<D>, CellError> {
        let Some(start) = self.interior_point() else {
            return Ok(LpResult::Unbounded);
        };
        let prob = Problem {
            n: D,
            rows: self.rows(),
            offsets: self.offsets(),
            mask,
            h: [0.0; MAX_N],
            g: to_v4(objective),
            tie: default_tie(D),
            length_scale: self.length_scale(),
        };
        let point = match prob.solve(to_v4(&start)) {
            Ok(Outcome::Optimal { point, .. }) => point,
            Ok(Outcome::Unbounded { .. }) => return Ok(LpResult::Unbounded),
            // a degenerate LP (a dozen nearly coincident planes through one vertex, the cells of parts whose faces
            // are a sliver out of line) can cycle to the iteration limit: clarabel's interior point solves it (some
            // optimal point, without the tie-break; an unbounded or unsolved LP keeps the active set's error)
            Err(source) => {
                tracing::debug!(error = %source, purpose, "LP: active set failed; clarabel");
                let keep = |j: &usize| mask.is_none_or(|m| m[*j]);
                let rows: Vec<V4> = (0..self.len()).filter(keep).map(|j| self.rows()[j]).collect();
                let offsets: Vec<f64> = (0..self.len()).filter(keep).map(|j| self.offsets()[j]).collect();
                let x = clarabel_qp::<D>(&[0.0; D], objective, &rows, &offsets)
                    .map_err(|_| CellError::Solver { purpose, source })?;
                let mut point = [0.0; MAX_N];
                point[..D].copy_from_slice(&x[..D]);
                point
            }
        };
        let p = from_v4::<D>(&point);
        let value = (0..D).map(|i| objective[i] * p[i]).sum();
        Ok(LpResult::Optimal { point: p, value })
    }

    fn chebyshev(&self) -> Result<CellShape<D>, CellError> {
        // the LP's rows live in a per-thread scratch (no allocation per call once warm)
        let mut scratch = Scratch::take();
        let result = self.chebyshev_in(&mut scratch);
        scratch.put_back();
        result
    }

    /// [`Cell::chebyshev`] with its rows in `scratch`.
    fn chebyshev_in(&self, scratch: &mut Scratch) -> Result<CellShape<D>, CellError> {
        let tol = self.tolerance.linear;
        // The cap on the radius tells an unbounded cell (the LP reaches it) from a bounded one. A bounded cell's
        // radius is at most max |b_i| (unit normals: a positive combination of the rows vanishes, and the same
        // combination of `a_i . c + r <= b_i` gives `r <= max |b_i|`), so twice that keeps a large bounded cell (a
        // floor 1e7 mm wide for a 1 mm part: found by fuzzing the CLI) from being reported unbounded.
        let largest_offset = self.offsets().iter().fold(0.0f64, |m, b| m.max(b.abs()));
        let cap = (1e6 * self.length_scale()).max(2.0 * largest_offset);
        let Scratch { rows, offsets, .. } = scratch;
        let mut r0 = cap;
        for (row, &b) in self.rows().iter().zip(self.offsets()) {
            let mut r = *row;
            r[D] = 1.0;
            rows.push(r);
            offsets.push(b);
            r0 = r0.min(b);
        }
        let mut capr = [0.0; MAX_N];
        capr[D] = 1.0;
        rows.push(capr);
        offsets.push(cap);
        let mut g = [0.0; MAX_N];
        g[D] = -1.0;
        let prob = Problem {
            n: D + 1,
            rows,
            offsets,
            mask: None,
            h: [0.0; MAX_N],
            g,
            tie: default_tie(D),
            length_scale: self.length_scale(),
        };
        let mut start = [0.0; MAX_N];
        start[D] = r0;
        let (point, bounded) = match prob.solve(start) {
            Ok(Outcome::Optimal { point, .. }) => (point, true),
            Ok(Outcome::Unbounded { point, .. }) => (point, false),
            // a degenerate LP (many nearly coincident planes through one vertex: the cells of parts whose faces are
            // a sliver out of line) can cycle to the iteration limit: clarabel's interior point solves it instead
            Err(source) => {
                tracing::debug!(error = %source, rows = rows.len(), "Chebyshev LP: active set failed; clarabel");
                let solved = match D {
                    2 => clarabel_qp::<3>(&[0.0; 3], &[0.0, 0.0, -1.0], rows, offsets),
                    3 => clarabel_qp::<4>(&[0.0; 4], &[0.0, 0.0, 0.0, -1.0], rows, offsets),
                    _ => return Err(CellError::Solver { purpose: "Chebyshev centre", source }),
                };
                let x = solved.map_err(|_| CellError::Solver { purpose: "Chebyshev centre", source })?;
                let mut point = [0.0; MAX_N];
                point[..=D].copy_from_slice(&x[..=D]);
                (point, true)
            }
        };
        let radius = point[D];
        if radius < -tol {
            return Ok(CellShape::Empty);
        }
        if !bounded || radius >= cap * (1.0 - 1e-9) {
            return Err(CellError::Unbounded);
        }
        let p = from_v4::<D>(&point);
        if radius <= tol { Ok(CellShape::Flat { point: p }) } else { Ok(CellShape::Solid { centre: p, radius }) }
    }

    /// [`CellError::Unbounded`] when the (non-empty) cell is unbounded: `2 D` LPs `max +-p_i`, as in [`Cell::new`].
    pub fn check_bounded(&self) -> Result<(), CellError> {
        for i in 0..D {
            for sign in [1.0, -1.0] {
                let mut dir = [0.0; D];
                dir[i] = sign;
                if self.lp_masked(&dir, None, "boundedness test")? == LpResult::Unbounded {
                    return Err(CellError::Unbounded);
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) fn boxed(lo: [f64; 3], hi: [f64; 3]) -> Vec<Halfspace<3>> {
        let mut hs = Vec::new();
        for i in 0..3 {
            let mut n = [0.0; 3];
            n[i] = 1.0;
            hs.push(Halfspace::new(n, hi[i], Tag::User(2 * i as u64)));
            n[i] = -1.0;
            hs.push(Halfspace::new(n, -lo[i], Tag::User(2 * i as u64 + 1)));
        }
        hs
    }

    #[test]
    fn chebyshev_of_a_box() {
        let c = Cell::new(boxed([0.0, 0.0, 0.0], [4.0, 2.0, 6.0]), Tolerance::for_scale(10.0)).expect("cell");
        let (centre, r) = c.chebyshev_centre().expect("solid");
        assert!((r - 1.0).abs() < 1e-12);
        // centre (x, 1, z) with x in [1, 3], z in [1, 5]: lowest z, then x
        assert!((centre[1] - 1.0).abs() < 1e-12 && (centre[2] - 1.0).abs() < 1e-12 && (centre[0] - 1.0).abs() < 1e-12);
        assert_eq!(c.contains(&[2.0, 1.0, 3.0]), Containment::Interior);
        assert_eq!(c.contains(&[4.0, 1.0, 3.0]), Containment::Boundary);
        assert_eq!(c.contains(&[4.1, 1.0, 3.0]), Containment::Exterior);
    }

    #[test]
    fn empty_flat_unbounded() {
        let tol = Tolerance::for_scale(10.0);
        let mut hs = boxed([0.0; 3], [1.0; 3]);
        hs.push(Halfspace::new([1.0, 1.0, 1.0], -0.5, Tag::User(9)));
        assert!(Cell::new(hs, tol).expect("cell").is_empty());
        let mut hs = boxed([0.0; 3], [1.0; 3]);
        hs.push(Halfspace::new([2.0, 0.0, 0.0], 0.0, Tag::User(9)));
        let c = Cell::new(hs, tol).expect("cell");
        assert!(matches!(c.shape(), CellShape::Flat { .. }), "{:?}", c.shape());
        let mut hs = boxed([0.0; 3], [1.0; 3]);
        hs.remove(4);
        assert_eq!(Cell::new(hs.clone(), tol), Err(CellError::Unbounded));
        hs.push(Halfspace::new([0.0; 3], -1.0, Tag::User(3)));
        assert!(Cell::new(hs, tol).expect("empty").is_empty());
        let nan = vec![Halfspace::new([f64::NAN, 0.0, 0.0], 1.0, Tag::Floor)];
        assert_eq!(Cell::new(nan, tol), Err(CellError::NonFinite { index: 0 }));
    }

    /// A small deterministic generator for the tests below.
    fn lcg(state: &mut u64) -> f64 {
        *state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((*state >> 11) as f64) / ((1u64 << 53) as f64) * 2.0 - 1.0
    }

    type Bits = (Vec<([u64; 3], u64, Tag)>, Vec<[u64; 4]>, Vec<u64>, bool);

    /// Bit patterns of everything the solvers read: inequalities, rows, offsets and the fixed-point flag.
    fn bits(c: &Cell<3>) -> Bits {
        (
            c.halfspaces().iter().map(|h| (h.normal.map(f64::to_bits), h.offset.to_bits(), h.tag)).collect(),
            c.rows().iter().map(|r| r.map(f64::to_bits)).collect(),
            c.offsets().iter().map(|b| b.to_bits()).collect(),
            c.unit,
        )
    }

    /// A normal that oscillates between two neighbours when normalised again and again (computed length
    /// `1 - 2^-53`, then `1 + 2^-52`, ...): never a fixed point.
    const OSCILLATING: [f64; 3] = [0.5449716003159704, 0.5644172136257368, 0.6200315829149431];

    #[test]
    fn normalisation_is_the_identity_on_its_fixed_points() {
        let mut state = 7u64;
        let mut fixed_count = 0;
        let total = 20_000;
        for k in 0..total {
            let scale = 10f64.powf(3.0 * lcg(&mut state));
            let mut n = [lcg(&mut state) * scale, lcg(&mut state) * scale, lcg(&mut state) * scale];
            if k % 5 == 0 {
                n[k % 3] = 0.0;
            }
            let h = Halfspace::new(n, 10.0 * lcg(&mut state), Tag::User(k as u64));
            let (u, fixed) = unit_halfspace(&h).expect("non-zero normal");
            assert!((length(&u.normal) - 1.0).abs() <= 1e-15, "{u:?}");
            assert_eq!(fixed, length(&u.normal) == 1.0);
            if fixed {
                fixed_count += 1;
                let (again, still) = unit_halfspace(&u).expect("unit");
                assert!(still);
                assert_eq!(again.normal.map(f64::to_bits), u.normal.map(f64::to_bits));
                assert_eq!(again.offset.to_bits(), u.offset.to_bits());
            }
        }
        assert!(fixed_count > total / 2, "{fixed_count} of {total} fixed");
        let (u, fixed) = unit_halfspace(&Halfspace::new(OSCILLATING, 1.0, Tag::User(0))).expect("unit");
        assert!(!fixed && u.normal != OSCILLATING);
        assert_eq!(unit_halfspace(&u).expect("unit").0.normal, OSCILLATING);
        assert_eq!(unit_halfspace(&Halfspace::new([0.0; 3], 1.0, Tag::Floor)), None);
    }

    /// `Cell::extended` (the parent's lists copied when they are fixed points) equals `Cell::new` of all the
    /// inequalities bit for bit, for parents whose normals are all fixed points (the box) and for parents with some
    /// that are not (then every inequality is normalised again), with extra inequalities of any length, dropped zero
    /// inequalities and an empty result.
    #[test]
    fn extended_equals_a_fresh_build_bit_for_bit() {
        let tol = Tolerance::for_scale(10.0);
        let mut state = 11u64;
        let (mut copied, mut children) = (0, 0);
        for case in 0..400 {
            let mut hs = boxed([-5.0, -4.0, -3.0], [5.0, 4.0, 3.0]);
            for k in 0..(case % 7) {
                let n = [lcg(&mut state), lcg(&mut state), lcg(&mut state)];
                hs.push(Halfspace::new(n.map(|c| 3.0 * c), 4.0 + lcg(&mut state), Tag::User(10 + k as u64)));
            }
            if case % 4 == 1 {
                hs.push(Halfspace::new(OSCILLATING, 4.0, Tag::User(99)));
            }
            let parent = Cell::new(hs, tol).expect("parent");
            assert!(!parent.is_empty());
            if case % 7 == 0 && case % 4 != 1 {
                assert!(parent.unit);
            }
            if case % 4 == 1 {
                assert!(!parent.unit);
            }
            let mut extra = Vec::new();
            for k in 0..(1 + case % 3) {
                // a cut through a point near the centre, at any scale (the child is non-empty)
                let n = [lcg(&mut state), lcg(&mut state), lcg(&mut state)];
                let s = 10f64.powf(2.0 * lcg(&mut state));
                let q = [lcg(&mut state), lcg(&mut state), lcg(&mut state)];
                extra.push(Halfspace::new(
                    n.map(|c| s * c),
                    s * (n[0] * q[0] + n[1] * q[1] + n[2] * q[2]),
                    Tag::User(50 + k as u64),
                ));
            }
            match case % 5 {
                2 => extra.push(Halfspace::new([0.0; 3], 1.0, Tag::User(70))),
                3 => extra.push(Halfspace::new([0.0; 3], -1.0, Tag::User(71))),
                _ => {}
            }
            let start = parent.interior_point().expect("a point");
            let all: Vec<Halfspace<3>> = parent.halfspaces().iter().chain(&extra).copied().collect();
            let fresh = Cell::normalised(all, tol).expect("fresh");
            // the child as the planner builds it: `Cell::extended` from the grown phase 1's normalised inequalities
            let child = parent.with_halfspaces_from(&extra, &start).expect("phase 1");
            let Some(child) = child else {
                assert!(fresh.is_empty() || Cell::new(fresh.halfspaces, tol).expect("cell").is_empty(), "case {case}");
                continue;
            };
            assert!(matches!(child.shape, CellShape::Known { .. }), "case {case}");
            assert_eq!(bits(&child), bits(&fresh), "case {case}");
            assert_eq!(child.unit, child.halfspaces().iter().all(|h| length(&h.normal) == 1.0));
            copied += usize::from(parent.unit);
            children += 1;
        }
        // both paths of `extended` ran
        assert!(children >= 300 && (50..=children - 50).contains(&copied), "{copied} of {children} copied");
    }

    #[test]
    fn redundancy_removal_keeps_the_set() {
        let tol = Tolerance::for_scale(10.0);
        let mut hs = boxed([0.0; 3], [1.0; 3]);
        hs.push(Halfspace::new([1.0, 1.0, 0.0], 5.0, Tag::User(20)));
        hs.push(Halfspace::new([1.0, 0.0, 0.0], 1.0, Tag::User(21))); // duplicate of the first
        hs.push(Halfspace::new([1.0, 1.0, 1.0], 2.5, Tag::User(22))); // cuts a corner
        let c = Cell::new(hs, tol).expect("cell");
        let r = c.without_redundant().expect("lp");
        let tags: Vec<Tag> = r.halfspaces().iter().map(|h| h.tag).collect();
        assert_eq!(r.len(), 7, "{tags:?}");
        assert!(tags.contains(&Tag::User(21)) && !tags.contains(&Tag::User(0)) && !tags.contains(&Tag::User(20)));
        assert!(tags.contains(&Tag::User(22)));
    }
}
