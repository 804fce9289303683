//! Subtraction of a convex obstacle from a convex cell: disjoint convex pieces (\[A\] VI-A-3, Fig. 13).
//!
//! \[A\] section 6.1.3 (Ayyadevara et al. 2002): free-space components completely inside the obstacle are eliminated;
//! a component that intersects the obstacle is decomposed "by manipulating the sign of the inequalities describing
//! the obstacle"; components not affected are kept. With the obstacle `O = {n_k . p <= d_k + delta}` (unit normals,
//! faces optionally grown by a clearance `delta`, \[A\] eq. 10-11 and section 6.1.2) and a cell `F`:
//!
//! ```text
//! F \ int(O) = U_k  F ∩ {n_k . p >= d_k + delta} ∩ {n_j . p <= d_j + delta : j before k}
//! ```
//!
//! The pieces have pairwise disjoint interiors (piece k lies on the outer side of face k and the inner side of
//! every earlier face) and cover `F \ int(O)`: a point outside `O` violates some face; it belongs to the piece of
//! the first face it violates.
//!
//! Steps (each a small LP by the exact active-set method, O(m) per iteration):
//! 1. **untouched test**: `max r` s.t. `p in F`, `n_k . p + r <= d_k + delta`: the deepest penetration of `F` into
//!    `O`. If it is at most the tolerance, `F` is returned as is (touching is not interference);
//! 2. **face selection**: faces with `max_F n_k . p <= d_k + delta + tol` have `F` on their inner side; their pieces
//!    would be empty or flat and their cuts redundant, so they are skipped;
//! 3. **ordering** (heuristic for few pieces): the remaining faces by decreasing `max_F n_k . p - d_k`, i.e. the
//!    faces that cut off most of `F` first;
//! 4. **pieces**: empty pieces are dropped, and so are flat ones when `F` is solid (a measure-zero sliver on the
//!    obstacle's boundary adds no free volume); a cell wholly inside `O` leaves no piece ("eliminated").
//!
//! Inequality tags: the flipped face `n_k . p >= d_k + delta` is [`Tag::ObstacleFace`] (a contact when active), an
//! earlier face kept as `n_j . p <= d_j + delta` is [`Tag::ObstacleCut`] (an artificial cut).

use crate::active_set::{ActiveSetError, MAX_N, Outcome, Problem};
use crate::cell::{Cell, CellError, CellShape, Halfspace, Tag, default_tie, to_v4};
use geom::ConvexPolytope;
use stackplan_geom as geom;

/// A convex obstacle `{p : n_k . p <= d_k}` with an identifier for the tags of the pieces.
#[derive(Debug, Clone, PartialEq)]
pub struct Obstacle<const D: usize> {
    id: u64,
    faces: Vec<([f64; D], f64)>,
}

/// Why a subtraction failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SubtractError {
    /// An obstacle face has a zero or non-finite normal or offset.
    #[error("obstacle {obstacle}: face {face} has a zero or non-finite normal or offset")]
    BadFace {
        /// Obstacle id.
        obstacle: u64,
        /// Face index.
        face: usize,
    },
    /// The clearance is negative or not finite.
    #[error("clearance must be finite and >= 0, got {0}")]
    BadClearance(f64),
    /// An LP failed.
    #[error("subtraction LP failed: {0}")]
    Solver(#[from] ActiveSetError),
    /// Building or analysing a piece failed.
    #[error(transparent)]
    Cell(#[from] CellError),
}

impl<const D: usize> Obstacle<D> {
    /// An obstacle from its faces `normal . p <= offset` (normals scaled to unit length).
    pub fn new(id: u64, faces: impl IntoIterator<Item = ([f64; D], f64)>) -> Result<Self, SubtractError> {
        let mut out = Vec::new();
        for (face, (n, d)) in faces.into_iter().enumerate() {
            let len = n.iter().map(|c| c * c).sum::<f64>().sqrt();
            if !(len > 0.0 && len.is_finite() && d.is_finite()) {
                return Err(SubtractError::BadFace { obstacle: id, face });
            }
            out.push((n.map(|c| c / len), d / len));
        }
        Ok(Self { id, faces: out })
    }

    /// The obstacle's identifier.
    pub fn id(&self) -> u64 {
        self.id
    }

    /// The faces `(unit normal, offset)`.
    pub fn faces(&self) -> &[([f64; D], f64)] {
        &self.faces
    }
}

impl Obstacle<3> {
    /// The obstacle bounded by a convex polytope's face planes (face indices are the polytope's).
    pub fn from_polytope(id: u64, polytope: &ConvexPolytope) -> Result<Self, SubtractError> {
        Self::new(id, polytope.planes().map(|pl| (pl.normal.to_array(), pl.offset)))
    }
}

/// Options of a subtraction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SubtractOptions {
    /// Clearance `delta >= 0` added to every face offset (robot positioning error, \[A\] eq. 10-11).
    pub clearance: f64,
    /// Remove redundant inequalities from each piece (one LP per inequality; keeps later QPs fast).
    pub remove_redundant: bool,
}

impl Default for SubtractOptions {
    fn default() -> Self {
        Self { clearance: 0.0, remove_redundant: true }
    }
}

/// The result of subtracting an obstacle from one cell.
#[derive(Debug, Clone, PartialEq)]
pub enum Subtraction<const D: usize> {
    /// The cell does not meet the obstacle's interior: it is kept as is.
    Untouched,
    /// The cell lies inside the obstacle (or is empty): nothing is left.
    Eliminated,
    /// The disjoint convex pieces of the cell outside the obstacle.
    Pieces(Vec<Cell<D>>),
}

/// Subtracts `obstacle` (grown by `options.clearance`) from `cell`. See the module documentation.
pub fn subtract<const D: usize>(
    cell: &Cell<D>,
    obstacle: &Obstacle<D>,
    options: SubtractOptions,
) -> Result<Subtraction<D>, SubtractError> {
    let delta = options.clearance;
    if !(delta >= 0.0 && delta.is_finite()) {
        return Err(SubtractError::BadClearance(delta));
    }
    let Some(start) = cell.interior_point() else {
        return Ok(Subtraction::Eliminated);
    };
    let tol = cell.tolerance().linear;
    if penetration_depth(cell, obstacle, delta, &start)? <= tol {
        return Ok(Subtraction::Untouched);
    }
    // faces that cut the cell, with how far the cell reaches beyond them
    let mut cutting: Vec<(usize, f64)> = Vec::new();
    for (k, (n, d)) in obstacle.faces.iter().enumerate() {
        let reach = match cell.support(n)? {
            Some((max, _)) => max - (d + delta),
            None => return Ok(Subtraction::Eliminated),
        };
        if reach > tol {
            cutting.push((k, reach));
        }
    }
    cutting.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    let parent_solid = cell.is_solid();
    let mut pieces = Vec::new();
    for (i, &(k, _)) in cutting.iter().enumerate() {
        let (n, d) = obstacle.faces[k];
        let face = Tag::ObstacleFace { obstacle: obstacle.id, face: k as u32 };
        let mut extra = vec![Halfspace::new(n, d + delta, face).flipped(face)];
        for &(j, _) in &cutting[..i] {
            let (nj, dj) = obstacle.faces[j];
            extra.push(Halfspace::new(nj, dj + delta, Tag::ObstacleCut { obstacle: obstacle.id, face: j as u32 }));
        }
        let piece = cell.with_halfspaces(extra)?;
        let keep = match piece.shape() {
            CellShape::Empty => false,
            CellShape::Flat { .. } => !parent_solid,
            // (pieces come from the Chebyshev LP, never `Known`)
            CellShape::Solid { .. } | CellShape::Known { .. } => true,
        };
        if keep {
            pieces.push(if options.remove_redundant { piece.without_redundant()? } else { piece });
        }
    }
    tracing::trace!(obstacle = obstacle.id, cutting = cutting.len(), pieces = pieces.len(), "subtracted obstacle");
    if pieces.is_empty() { Ok(Subtraction::Eliminated) } else { Ok(Subtraction::Pieces(pieces)) }
}

/// Subtracts `obstacle` from every cell of a free space: untouched cells are kept as they are (in order), touched
/// ones replaced by their pieces, eliminated ones dropped.
pub fn subtract_from_all<const D: usize>(
    cells: Vec<Cell<D>>,
    obstacle: &Obstacle<D>,
    options: SubtractOptions,
) -> Result<Vec<Cell<D>>, SubtractError> {
    let mut out = Vec::with_capacity(cells.len());
    for cell in cells {
        match subtract(&cell, obstacle, options)? {
            Subtraction::Untouched => out.push(cell),
            Subtraction::Eliminated => {}
            Subtraction::Pieces(p) => out.extend(p),
        }
    }
    Ok(out)
}

/// `max_{p in F} min_k (d_k + delta - n_k . p)`: how deep the cell reaches into the obstacle (negative when apart).
fn penetration_depth<const D: usize>(
    cell: &Cell<D>,
    obstacle: &Obstacle<D>,
    delta: f64,
    start: &[f64; D],
) -> Result<f64, SubtractError> {
    let cap = 1e6 * cell.length_scale();
    let mut rows = Vec::with_capacity(cell.len() + obstacle.faces.len() + 1);
    let mut offsets = Vec::with_capacity(rows.capacity());
    rows.extend_from_slice(cell.rows());
    offsets.extend_from_slice(cell.offsets());
    let mut r0 = cap;
    for (n, d) in &obstacle.faces {
        let mut row = to_v4(n);
        row[D] = 1.0;
        rows.push(row);
        offsets.push(d + delta);
        r0 = r0.min(d + delta - crate::cell::dot(n, start));
    }
    let mut cap_row = [0.0; MAX_N];
    cap_row[D] = 1.0;
    rows.push(cap_row);
    offsets.push(cap);
    let mut g = [0.0; MAX_N];
    g[D] = -1.0;
    let prob = Problem {
        n: D + 1,
        rows: &rows,
        offsets: &offsets,
        mask: None,
        h: [0.0; MAX_N],
        g,
        tie: default_tie(D),
        length_scale: cell.length_scale(),
    };
    let mut s = to_v4(start);
    s[D] = r0;
    Ok(match prob.solve(s)? {
        Outcome::Optimal { point, .. } | Outcome::Unbounded { point, .. } => point[D],
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use geom::Tolerance;

    fn boxed(lo: [f64; 3], hi: [f64; 3]) -> Vec<([f64; 3], f64)> {
        let mut hs = Vec::new();
        for i in 0..3 {
            let mut n = [0.0; 3];
            n[i] = 1.0;
            hs.push((n, hi[i]));
            n[i] = -1.0;
            hs.push((n, -lo[i]));
        }
        hs
    }

    fn cell(lo: [f64; 3], hi: [f64; 3]) -> Cell<3> {
        let hs = boxed(lo, hi).into_iter().enumerate().map(|(i, (n, d))| Halfspace::new(n, d, Tag::User(i as u64)));
        Cell::new(hs.collect(), Tolerance::for_scale(10.0)).expect("cell")
    }

    #[test]
    fn figure_13_cases() {
        let f = cell([0.0; 3], [4.0, 4.0, 4.0]);
        let opts = SubtractOptions::default();
        // wholly inside: eliminated
        let big = Obstacle::new(1, boxed([-1.0; 3], [5.0; 3])).expect("obstacle");
        assert_eq!(subtract(&f, &big, opts).expect("ok"), Subtraction::Eliminated);
        // apart, and touching along a face: untouched
        let apart = Obstacle::new(2, boxed([5.0, 0.0, 0.0], [6.0, 4.0, 4.0])).expect("obstacle");
        assert_eq!(subtract(&f, &apart, opts).expect("ok"), Subtraction::Untouched);
        let touching = Obstacle::new(3, boxed([4.0, 1.0, 1.0], [6.0, 2.0, 2.0])).expect("obstacle");
        assert_eq!(subtract(&f, &touching, opts).expect("ok"), Subtraction::Untouched);
        // but a clearance makes the touching one cut a slab of 0.5
        let grown = SubtractOptions { clearance: 0.5, ..opts };
        let Subtraction::Pieces(p) = subtract(&f, &touching, grown).expect("ok") else { panic!("pieces expected") };
        assert!(p.len() >= 3);
        // cutting off a slab: one convex piece (F2 -> F21)
        let slab = Obstacle::new(4, boxed([3.0, -1.0, -1.0], [5.0, 5.0, 5.0])).expect("obstacle");
        let Subtraction::Pieces(p) = subtract(&f, &slab, opts).expect("ok") else { panic!("pieces expected") };
        assert_eq!(p.len(), 1);
        let tags: Vec<Tag> = p[0].halfspaces().iter().map(|h| h.tag).collect();
        assert!(tags.contains(&Tag::ObstacleFace { obstacle: 4, face: 1 }), "{tags:?}");
        // a notch in an edge: concave rest, two pieces (F3 -> F31, F32)
        let notch = Obstacle::new(5, boxed([3.0, 3.0, -1.0], [5.0, 5.0, 5.0])).expect("obstacle");
        let Subtraction::Pieces(p) = subtract(&f, &notch, opts).expect("ok") else { panic!("pieces expected") };
        assert_eq!(p.len(), 2);
        // a hole through the middle: four pieces
        let hole = Obstacle::new(6, boxed([1.0, 1.0, -1.0], [3.0, 3.0, 5.0])).expect("obstacle");
        let Subtraction::Pieces(p) = subtract(&f, &hole, opts).expect("ok") else { panic!("pieces expected") };
        assert_eq!(p.len(), 4);
        assert!(Obstacle::<3>::new(7, [([0.0, 0.0, 0.0], 1.0)]).is_err());
        assert!(subtract(&f, &hole, SubtractOptions { clearance: -1.0, ..opts }).is_err());
    }
}
