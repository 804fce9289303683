//! Robust 3-D convex hull: Quickhull with exact visibility, then exact coplanar-facet merging.
//!
//! The triangulation is in `quickhull.rs`, the merge of its facets into faces in `hull_faces.rs`.
//!
//! Algorithm: C. B. Barber, D. P. Dobkin, H. Huhdanpaa, *The Quickhull Algorithm for Convex Hulls*, ACM TOMS 22(4),
//! 1996 — with every combinatorial decision made by Shewchuk's exact `orient3d` ([`crate::predicates`]) instead of
//! Barber's thick facets. Expected O(n log n) for random input (O(n^2) worst case), plus O(h) for merging.
//!
//! Why it is correct on sheet-metal input without any tolerance:
//! * a point is *visible* from a triangle only if it lies strictly above its plane (exact sign). A point outside the
//!   current hull is strictly above at least one triangle, so no extreme point is ever lost; a point on the boundary
//!   is never added, so duplicates and points inside faces or on edges never become vertices;
//! * a new triangle joins the point `p` to a horizon edge `e` of a visible triangle `t`. It cannot be degenerate:
//!   `p` collinear with `e` would put `p` in the plane of `t`, contradicting strict visibility;
//! * afterwards, adjacent triangles that are exactly coplanar (exact `orient3d == 0`) are merged into one polygonal
//!   face (on a convex surface such a group is a single convex polygon), and a vertex is kept only if at least three
//!   distinct faces meet there: a vertex with one face lies inside it, with two it lies inside an edge. What remains is
//!   exactly the set of extreme points, and every face is strictly convex to its neighbours.
//!
//! Flat, collinear and coincident input has no 3-D hull and returns a [`HullError`].
//!
//! **Face planes.** A face's plane is computed from its best-conditioned triangle with an accurate cross product
//! ([`crate::accurate_normal`]): where rounding moved points off a common plane, the exact hull has sliver facets a
//! few ulps wide, whose plain `f64` normals can point anywhere (planes that cut the hull by tens of millimetres).
//!
//! **Creases.** The points of a rotated sheet-metal face are coplanar only to rounding, so the exact hull splits the
//! face into facets that meet at creases of about 1e-16 rad, with slivers a few ulps wide where a point lies next to
//! an edge; no real part has such folds, and downstream they make near-parallel faces within one polytope (the c-space
//! overlay cannot pair them with the other summand's faces; its exact-hull fallback is correct but fragmented) and
//! split a resting face so that no facet holds the c.g. [`convex_hull_merged`], the hull the part readers build, joins
//! adjacent facets that lie in one plane within the kernel's length tolerance (`1e-9 x` the points' extent,
//! [`crate::tolerance`]): a facet whose vertices all lie within it of its larger neighbour's plane joins that
//! neighbour, and a joined face is kept only when all its vertices lie within the tolerance of its plane (the
//! area-weighted normal of its facets); else its facets stay apart. So a fold is merged only when it moves no vertex
//! by more than the tolerance (between faces 100 mm across, a crease of about 1e-9 rad). Every decision of the hull
//! itself stays exact, only facets are grouped; a vertex where fewer than three faces meet is dropped, as in the exact
//! merge (it lies within the tolerance of an edge or a face). Should the merged faces not close up into a polytope,
//! the exact hull is returned.
//!
//! The exact predicates are exact only while products of coordinate differences neither underflow nor overflow: a
//! coordinate below [`MIN_COORDINATE`] (1e-50) in magnitude is taken as 0 (the hull's vertices carry the zero), and
//! one above [`MAX_HULL_COORDINATE`] (1e50) is [`HullError::OutOfRange`].

use crate::hull_faces::merge;
use crate::polytope::{ConvexPolytope, PolytopeError};
use crate::quickhull::{Degenerate, triangulate};
use glam::DVec3;

/// Why a point set has no 3-D convex hull.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HullError {
    /// No points.
    #[error("no points")]
    Empty,
    /// A coordinate is NaN or infinite.
    #[error("point {index} has a non-finite coordinate")]
    NonFinite {
        /// Index of the offending point.
        index: usize,
    },
    /// All points coincide.
    #[error("all points coincide: the hull is a point, not a solid")]
    Coincident,
    /// All points lie on a line.
    #[error("all points are collinear: the hull is a segment, not a solid")]
    Collinear,
    /// All points lie in a plane.
    #[error("all points are coplanar: the hull is flat, not a solid")]
    Coplanar,
    /// A coordinate larger than [`MAX_HULL_COORDINATE`] in magnitude.
    #[error(
        "point {index} has the coordinate {value:e}, beyond the supported 1e50 in magnitude (where the exact \
         predicates' products would overflow)"
    )]
    OutOfRange {
        /// Index of the offending point.
        index: usize,
        /// The coordinate.
        value: f64,
    },
    /// Internal consistency failure (a bug): the triangulated surface could not be turned into a polytope.
    #[error("internal hull error: {0}")]
    Internal(#[from] PolytopeError),
}

/// A convex hull and, for each of its vertices, the index of the input point it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvexHull {
    /// The hull.
    pub polytope: ConvexPolytope,
    /// `source[i]` is the index in the input of `polytope.vertices()[i]` (the first such index when duplicated).
    pub source: Vec<usize>,
}

/// The smallest nonzero coordinate magnitude [`convex_hull`] keeps; smaller ones are taken as 0. The exact predicates
/// (Shewchuk's adaptive `orient3d`) are exact only while no product of coordinate differences underflows: a
/// coordinate that is 0 or at least 1e-50 in magnitude makes every nonzero difference at least `ulp(1e-50)`, about
/// 2^-218, and a product of three of them (with their expansion tails) stays far above the smallest normal double,
/// 2^-1022. Below it a product can round to zero, and a hull could come out inconsistent (a tetrahedron of edge
/// 1e-160 was "coplanar", two 1e-300 apart an "internal hull error"). Such coordinates arise from rounding (a part
/// turned by 1e-50 degree), never from a length that matters: moving a point by less than 1e-50 mm is no change.
/// The part readers reject them in files ([`crate::io`]), where they can only be mistakes.
pub const MIN_COORDINATE: f64 = 1e-50;

/// The largest coordinate magnitude [`convex_hull`] accepts: cubes of differences stay below 1e151, far from
/// overflow. (Part files are held to a tighter 1e9 mm, [`crate::io::MAX_COORDINATE`].)
pub const MAX_HULL_COORDINATE: f64 = 1e50;

/// The first coordinate beyond [`MAX_HULL_COORDINATE`], with its point's index.
fn out_of_range(points: &[DVec3]) -> Option<(usize, f64)> {
    points
        .iter()
        .enumerate()
        .find_map(|(i, p)| p.to_array().into_iter().find(|c| c.abs() > MAX_HULL_COORDINATE).map(|c| (i, c)))
}

/// `points` with every coordinate below [`MIN_COORDINATE`] in magnitude set to 0 (borrowed when there is none).
fn snap_tiny(points: &[DVec3]) -> std::borrow::Cow<'_, [DVec3]> {
    let tiny = |c: f64| c != 0.0 && c.abs() < MIN_COORDINATE;
    if !points.iter().any(|p| p.to_array().into_iter().any(tiny)) {
        return std::borrow::Cow::Borrowed(points);
    }
    let snap = |c: f64| if tiny(c) { 0.0 } else { c };
    std::borrow::Cow::Owned(points.iter().map(|p| DVec3::new(snap(p.x), snap(p.y), snap(p.z))).collect())
}

/// Convex hull of `points`. See the module documentation.
pub fn convex_hull(points: &[DVec3]) -> Result<ConvexHull, HullError> {
    hull_with(points, None)
}

/// [`convex_hull`] whose adjacent facets that lie in one plane within the length tolerance are one face: the hull of a
/// part's piece as the readers build it (see the module documentation, "Creases"). When the merged faces do not close
/// up into a polytope (a merge left a face with fewer than three corners), the exact hull.
pub fn convex_hull_merged(points: &[DVec3]) -> Result<ConvexHull, HullError> {
    convex_hull_merged_within(points, 0.0)
}

/// [`convex_hull_merged`] with a length tolerance of at least `tolerance` (never below the kernel's, `1e-9 x` the
/// points' extent; a tolerance that is not finite counts as 0): for points known only to a coarser precision, such as
/// the single-precision coordinates of an STL file, whose faces are planar only to that precision.
pub fn convex_hull_merged_within(points: &[DVec3], tolerance: f64) -> Result<ConvexHull, HullError> {
    let kernel = crate::tolerance::Tolerance::for_scale(crate::tolerance::bounding_diagonal(points)).linear;
    let tol = if tolerance.is_finite() { tolerance.max(kernel) } else { kernel };
    match hull_with(points, Some(tol)) {
        Ok(hull) => Ok(hull),
        // the exact hull of the same points (its errors are the input's, reported as such)
        Err(HullError::Internal(_)) => hull_with(points, None),
        Err(e) => Err(e),
    }
}

fn hull_with(points: &[DVec3], merge_tolerance: Option<f64>) -> Result<ConvexHull, HullError> {
    if points.is_empty() {
        return Err(HullError::Empty);
    }
    if let Some(index) = points.iter().position(|p| !p.is_finite()) {
        return Err(HullError::NonFinite { index });
    }
    if let Some((index, value)) = out_of_range(points) {
        return Err(HullError::OutOfRange { index, value });
    }
    let snapped = snap_tiny(points);
    let points: &[DVec3] = &snapped;
    let tris = triangulate(points).map_err(|d| match d {
        Degenerate::Coincident => HullError::Coincident,
        Degenerate::Collinear => HullError::Collinear,
        Degenerate::Coplanar => HullError::Coplanar,
    })?;
    let (polytope, source) = merge(points, &tris, merge_tolerance)?;
    Ok(ConvexHull { polytope, source })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::predicates::side;
    use std::cmp::Ordering;

    /// A box turned by a general rotation: its faces are planar only to rounding. The exact hull splits some of them
    /// into facets; the merged hull has the box's 6 faces and 8 vertices, planes supporting every point.
    #[test]
    fn merged_hull_of_a_turned_box_has_its_six_faces() {
        let r = glam::DMat3::from_euler(glam::EulerRot::ZYX, 0.3, 0.2, 0.1);
        let mut split = 0;
        for (k, size) in [DVec3::new(40.0, 20.0, 2.0), DVec3::new(1.0, 1.0, 1.0), DVec3::new(300.0, 0.5, 7.0)]
            .into_iter()
            .enumerate()
        {
            let t = DVec3::new(k as f64 * 13.7, -5.3, 60.0);
            let pts: Vec<DVec3> = (0..8)
                .map(|i| {
                    let c = |bit: usize, e: f64| if i & bit == 0 { 0.0 } else { e };
                    r * DVec3::new(c(1, size.x), c(2, size.y), c(4, size.z)) + t
                })
                .collect();
            split += convex_hull(&pts).expect("hull").polytope.faces().len() - 6;
            let h = convex_hull_merged(&pts).expect("hull");
            assert_eq!((h.polytope.vertices().len(), h.polytope.faces().len()), (8, 6), "box {k}");
            h.polytope.validate().expect("valid within the tolerance");
            for f in h.polytope.faces() {
                let above = pts.iter().map(|p| f.plane.normal.dot(*p) - f.plane.offset).fold(f64::MIN, f64::max);
                assert!(above <= 1e-12 * 300.0, "box {k}: a point {above} above a face");
            }
        }
        // the test has teeth: the exact hull splits some of these faces
        assert!(split > 0);
    }

    /// A box with points on its edges (and at their midpoints), turned by general rotations: rounding puts each such
    /// point a few nanometres off its edge, where the exact hull makes it a vertex with sliver facets around it. The
    /// merged hull is the box: 8 vertices, 6 faces (the slivers joined to the faces they lie in, the points dropped).
    /// Joined by the angle between their normals instead of by distance, some slivers stay apart and leave a face
    /// of two corners ("internal hull error") in 20 of 30 turns.
    #[test]
    fn a_turned_box_with_points_on_its_edges_is_a_box() {
        let size = DVec3::new(40.0, 20.0, 10.0);
        let corner = |i: usize| {
            let c = |bit: usize, e: f64| if i & bit == 0 { 0.0 } else { e };
            DVec3::new(c(1, size.x), c(2, size.y), c(4, size.z))
        };
        let mut base: Vec<DVec3> = (0..8).map(corner).collect();
        // three points on the edge along x at y = z = 0, and the midpoint of every edge
        base.extend([0.25, 0.5, 0.75].map(|t| DVec3::new(t * size.x, 0.0, 0.0)));
        for i in 0..8 {
            for bit in [1, 2, 4] {
                if i & bit == 0 {
                    base.push(0.5 * (corner(i) + corner(i | bit)));
                }
            }
        }
        let mut exact_split = 0;
        for k in 0..30 {
            let r = glam::DMat3::from_euler(
                glam::EulerRot::ZYX,
                0.17 + 0.31 * k as f64,
                0.35 - 0.023 * k as f64,
                0.52 + 0.19 * k as f64,
            );
            let pts: Vec<DVec3> = base.iter().map(|v| r * *v + DVec3::new(3.0, -7.0, 11.0)).collect();
            exact_split += usize::from(convex_hull(&pts).expect("hull").polytope.faces().len() > 6);
            let h = convex_hull_merged(&pts).unwrap_or_else(|e| panic!("turn {k}: {e}"));
            assert_eq!((h.polytope.vertices().len(), h.polytope.faces().len()), (8, 6), "turn {k}");
            h.polytope.validate().expect("valid within the tolerance");
        }
        assert!(exact_split > 0, "the test has teeth: the exact hulls have slivers");
    }

    /// A real fold, however shallow (1e-6 rad over 10 mm: 1e-5 mm off the other face's plane), stays two faces; a
    /// bend of several creases each within the tolerance but adding up to more than it is not one face.
    #[test]
    fn merged_hull_keeps_real_folds() {
        // a wedge roof: two top faces meeting at a ridge with a 1e-6 rad fold
        let h = 1e-6 * 10.0;
        let pts = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(20.0, 0.0, 0.0),
            DVec3::new(0.0, 5.0, 0.0),
            DVec3::new(20.0, 5.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(20.0, 0.0, 1.0),
            DVec3::new(0.0, 5.0, 1.0),
            DVec3::new(20.0, 5.0, 1.0),
            DVec3::new(10.0, 0.0, 1.0 + h),
            DVec3::new(10.0, 5.0, 1.0 + h),
        ];
        let merged = convex_hull_merged(&pts).expect("hull");
        assert_eq!(merged.polytope.faces().len(), convex_hull(&pts).expect("hull").polytope.faces().len());
        assert_eq!(merged.polytope.faces().len(), 7);
        // a gentle arc of 11 points (coordinates near the origin so that its sagitta is representable): neighbouring
        // facets 1e-3 mm wide meet at 7e-7 rad, each within the tolerance (1.4e-9 mm) of the other's plane, but the
        // ten of them bend by 7e-6 rad, 8.8e-9 mm off one plane
        let (w, alpha) = (1e-3, 7e-7);
        let r = w / alpha;
        let arc: Vec<DVec3> = (0..=10)
            .flat_map(|k| {
                let t = (k as f64 - 5.0) * alpha;
                let (x, z) = (r * t.sin(), -2.0 * r * (0.5 * t).sin().powi(2));
                [DVec3::new(x, 0.0, z), DVec3::new(x, 1.0, z)]
            })
            .chain([DVec3::new(-5e-3, 0.0, -1.0), DVec3::new(5e-3, 0.0, -1.0), DVec3::new(0.0, 1.0, -1.0)])
            .collect();
        let top = |h: &ConvexHull| h.polytope.faces().iter().filter(|f| f.plane.normal.z > 0.9).count();
        assert_eq!(top(&convex_hull(&arc).expect("hull")), 10, "the arc's exact hull has ten top facets");
        // merged piecewise: some faces, none of them bent by more than the tolerance
        let merged = convex_hull_merged(&arc).expect("hull");
        assert!((2..10).contains(&top(&merged)), "{} top faces", top(&merged));
        let tol = crate::tolerance::Tolerance::for_scale(crate::tolerance::bounding_diagonal(&arc)).linear;
        for f in merged.polytope.faces() {
            for &v in &f.vertices {
                let off = f.plane.offset - f.plane.normal.dot(merged.polytope.vertices()[v]);
                assert!((0.0..=tol).contains(&off), "a vertex {off} off its face's plane (tolerance {tol})");
            }
        }
        // the same arc flattened a hundredfold (its sagitta 8.8e-11 mm) is one face
        let flat: Vec<DVec3> =
            arc.iter().map(|p| if p.z > -0.5 { DVec3::new(p.x, p.y, p.z * 0.01) } else { *p }).collect();
        assert_eq!(top(&convex_hull_merged(&flat).expect("hull")), 1, "a bend within the tolerance is one face");
    }

    fn grid_box(nx: usize, ny: usize, nz: usize) -> Vec<DVec3> {
        let mut v = Vec::new();
        for i in 0..=nx {
            for j in 0..=ny {
                for k in 0..=nz {
                    v.push(DVec3::new(i as f64, j as f64, k as f64));
                }
            }
        }
        v
    }

    #[test]
    fn grid_of_coplanar_points_gives_a_box() {
        let pts = grid_box(4, 3, 2);
        let h = convex_hull(&pts).expect("hull");
        assert_eq!(h.polytope.vertices().len(), 8);
        assert_eq!(h.polytope.faces().len(), 6);
        assert_eq!(h.polytope.edges().len(), 12);
        h.polytope.validate_exact().expect("valid");
        assert!((h.polytope.volume() - 24.0).abs() < 1e-12);
        for (i, &s) in h.source.iter().enumerate() {
            assert_eq!(pts[s], h.polytope.vertices()[i]);
        }
    }

    #[test]
    fn degenerate_inputs_are_typed_errors() {
        assert_eq!(convex_hull(&[]), Err(HullError::Empty));
        assert_eq!(convex_hull(&[DVec3::ONE; 5]), Err(HullError::Coincident));
        let line: Vec<DVec3> = (0..5).map(|i| DVec3::splat(i as f64)).collect();
        assert_eq!(convex_hull(&line), Err(HullError::Collinear));
        let plane: Vec<DVec3> = (0..9).map(|i| DVec3::new((i % 3) as f64, (i / 3) as f64, 2.0)).collect();
        assert_eq!(convex_hull(&plane), Err(HullError::Coplanar));
        assert_eq!(convex_hull(&[DVec3::ZERO, DVec3::new(f64::NAN, 0.0, 0.0)]), Err(HullError::NonFinite { index: 1 }));
    }

    #[test]
    fn coordinates_whose_products_would_underflow_are_zero_and_overflow_is_an_error() {
        let tetra = |s: f64| [DVec3::ZERO, DVec3::new(s, 0.0, 0.0), DVec3::new(0.0, s, 0.0), DVec3::new(0.0, 0.0, s)];
        // a tetrahedron of edge 1e-160: its volume determinant (1e-480) underflows; it was reported "coplanar", and
        // is now all zeros, coincident
        assert_eq!(convex_hull(&tetra(1e-160)), Err(HullError::Coincident));
        assert_eq!(convex_hull(&tetra(-1e60)), Err(HullError::OutOfRange { index: 1, value: -1e60 }));
        // the ends of the range are kept, and zeros anywhere
        for s in [MIN_COORDINATE, 1e-40, 1e40, MAX_HULL_COORDINATE] {
            assert_eq!(convex_hull(&tetra(s)).map(|h| h.polytope.vertices().len()), Ok(4), "edge {s:e}");
        }
        // two tetrahedra 1e-300 apart in z (the fuzzer's case: "internal hull error: face 3 is degenerate"): the
        // point 1e-300 above the origin is the origin, a duplicate
        let mut two = tetra(1.0).to_vec();
        two.push(DVec3::new(0.0, 0.0, 1e-300));
        let hull = convex_hull(&two).expect("a tetrahedron");
        assert_eq!(hull.polytope.vertices().len(), 4);
        assert!(hull.polytope.vertices().iter().all(|v| v.to_array().iter().all(|c| *c == 0.0 || *c == 1.0)));
        // a tiny coordinate beside normal ones: the vertex carries the zero
        let tilted = [DVec3::new(0.0, 1.5e-60, 0.0), DVec3::X, DVec3::Y, DVec3::Z];
        let hull = convex_hull(&tilted).expect("a tetrahedron");
        assert!(hull.polytope.vertices().contains(&DVec3::ZERO));
    }

    #[test]
    fn prism_with_duplicates_and_collinear_runs() {
        // an extruded hexagon (dyadic corners, so the edge samples are exactly collinear), every point twice
        let corners = [(2.0, 0.0), (1.0, 2.0), (-1.0, 2.0), (-2.0, 0.0), (-1.0, -2.0), (1.0, -2.0)];
        let mut pts = Vec::new();
        for layer in [0.0, 2.0] {
            for k in 0..6 {
                let (a, b) = (corners[k], corners[(k + 1) % 6]);
                let (pa, pb) = (DVec3::new(a.0, a.1, layer), DVec3::new(b.0, b.1, layer));
                for s in 0..4 {
                    let q = pa + (pb - pa) * (s as f64 / 4.0);
                    pts.push(q);
                    pts.push(q);
                }
            }
        }
        let h = convex_hull(&pts).expect("hull");
        assert_eq!(h.polytope.faces().len(), 8);
        assert_eq!(h.polytope.vertices().len(), 12);
        h.polytope.validate_exact().expect("valid");
    }

    #[test]
    fn sliver_faces_between_nearly_coincident_points() {
        // differences of two rotated boxes (a c-space obstacle): points one or two ulps apart make faces too thin
        // for Newell's normal; found by the cspace property tests
        let pts = vec![
            DVec3::new(-1.7500000000000004, -1.4999999999999998, 1.0),
            DVec3::new(-1.0000000000000004, -1.4999999999999998, 1.0),
            DVec3::new(-1.0000000000000004, 0.5000000000000002, -2.5),
            DVec3::new(-1.7500000000000004, 0.5000000000000002, -2.5),
            DVec3::new(-1.7500000000000004, -3.5, -1.0),
            DVec3::new(-1.0000000000000004, -3.5, -1.0),
            DVec3::new(-1.7500000000000004, -1.9999999999999998, -3.0),
            DVec3::new(-1.7500000000000004, -2.5, -2.5),
            DVec3::new(-1.0000000000000004, -1.9999999999999998, -3.0),
            DVec3::new(-1.0000000000000004, -2.5, -2.5),
            DVec3::new(-1.7500000000000002, -0.9999999999999998, -1.5),
            DVec3::new(-1.0000000000000002, -0.9999999999999998, -1.5),
            DVec3::new(-1.0000000000000002, 1.0000000000000002, -5.0),
            DVec3::new(-1.7500000000000002, 1.0000000000000002, -5.0),
            DVec3::new(-1.7500000000000002, -3.0, -3.5),
            DVec3::new(-1.0000000000000002, -3.0, -3.5),
            DVec3::new(-1.7500000000000002, -1.4999999999999998, -5.5),
            DVec3::new(-1.7500000000000002, -1.9999999999999998, -5.0),
            DVec3::new(-1.0000000000000002, -1.4999999999999998, -5.5),
            DVec3::new(-1.0000000000000002, -1.9999999999999998, -5.0),
            DVec3::new(-1.7499999999999996, 2.5, 0.5),
            DVec3::new(-0.9999999999999997, 2.5, 0.5),
            DVec3::new(-0.9999999999999997, 4.5, -3.0),
            DVec3::new(-1.7499999999999996, 4.5, -3.0),
            DVec3::new(-1.7499999999999996, 0.5, -1.5),
            DVec3::new(-0.9999999999999997, 0.5, -1.5),
            DVec3::new(-1.7499999999999996, 2.0, -3.5),
            DVec3::new(-1.7499999999999996, 1.5, -3.0),
            DVec3::new(-0.9999999999999997, 2.0, -3.5),
            DVec3::new(-0.9999999999999997, 1.5, -3.0),
            DVec3::new(-1.75, 0.5000000000000001, 2.5),
            DVec3::new(-1.0, 0.5000000000000001, 2.5),
            DVec3::new(-1.0, 2.5, -1.0),
            DVec3::new(-1.75, 2.5, -1.0),
            DVec3::new(-1.75, -1.4999999999999998, 0.5),
            DVec3::new(-1.0, -1.4999999999999998, 0.5),
            DVec3::new(-1.75, 1.3777276490407724e-16, -1.5),
            DVec3::new(-1.75, -0.4999999999999999, -1.0),
            DVec3::new(-1.0, 1.3777276490407724e-16, -1.5),
            DVec3::new(-1.0, -0.4999999999999999, -1.0),
            DVec3::new(-1.7500000000000002, -0.9999999999999998, 1.5),
            DVec3::new(-1.0000000000000002, -0.9999999999999998, 1.5),
            DVec3::new(-1.0000000000000002, 1.0000000000000002, -2.0),
            DVec3::new(-1.7500000000000002, 1.0000000000000002, -2.0),
            DVec3::new(-1.7500000000000002, -3.0, -0.5),
            DVec3::new(-1.0000000000000002, -3.0, -0.5),
            DVec3::new(-1.7500000000000002, -1.4999999999999998, -2.5),
            DVec3::new(-1.7500000000000002, -1.9999999999999998, -2.0),
            DVec3::new(-1.0000000000000002, -1.4999999999999998, -2.5),
            DVec3::new(-1.0000000000000002, -1.9999999999999998, -2.0),
            DVec3::new(-1.0000000000000004, -1.5, 1.0),
            DVec3::new(-0.2500000000000004, -1.5, 1.0),
            DVec3::new(-0.2500000000000004, 0.5, -2.5),
            DVec3::new(-1.0000000000000004, 0.5, -2.5),
            DVec3::new(-1.0000000000000004, -3.5, -1.0),
            DVec3::new(-0.2500000000000004, -3.5, -1.0),
            DVec3::new(-1.0000000000000004, -2.0, -3.0),
            DVec3::new(-1.0000000000000004, -2.5, -2.5),
            DVec3::new(-0.2500000000000004, -2.0, -3.0),
            DVec3::new(-0.2500000000000004, -2.5, -2.5),
            DVec3::new(-1.0000000000000002, -1.0, -1.5),
            DVec3::new(-0.2500000000000003, -1.0, -1.5),
            DVec3::new(-0.2500000000000003, 1.0, -5.0),
            DVec3::new(-1.0000000000000002, 1.0, -5.0),
            DVec3::new(-1.0000000000000002, -3.0, -3.5),
            DVec3::new(-0.2500000000000003, -3.0, -3.5),
            DVec3::new(-1.0000000000000002, -1.5, -5.5),
            DVec3::new(-1.0000000000000002, -2.0, -5.0),
            DVec3::new(-0.2500000000000003, -1.5, -5.5),
            DVec3::new(-0.2500000000000003, -2.0, -5.0),
            DVec3::new(-1.0000000000000002, -1.0, 1.5),
            DVec3::new(-0.2500000000000003, -1.0, 1.5),
            DVec3::new(-0.2500000000000003, 1.0, -2.0),
            DVec3::new(-1.0000000000000002, 1.0, -2.0),
            DVec3::new(-1.0000000000000002, -3.0, -0.5),
            DVec3::new(-0.2500000000000003, -3.0, -0.5),
            DVec3::new(-1.0000000000000002, -1.5, -2.5),
            DVec3::new(-1.0000000000000002, -2.0, -2.0),
            DVec3::new(-0.2500000000000003, -1.5, -2.5),
            DVec3::new(-0.2500000000000003, -2.0, -2.0),
            DVec3::new(-0.9999999999999997, 2.5, 0.5),
            DVec3::new(-0.24999999999999964, 2.5, 0.5),
            DVec3::new(-0.24999999999999964, 4.5, -3.0),
            DVec3::new(-0.9999999999999997, 4.5, -3.0),
            DVec3::new(-0.9999999999999997, 0.5, -1.5),
            DVec3::new(-0.24999999999999964, 0.5, -1.5),
            DVec3::new(-0.9999999999999997, 2.0, -3.5),
            DVec3::new(-0.9999999999999997, 1.5, -3.0),
            DVec3::new(-0.24999999999999964, 2.0, -3.5),
            DVec3::new(-0.24999999999999964, 1.5, -3.0),
            DVec3::new(-1.0, 0.5, 2.5),
            DVec3::new(-0.25, 0.5, 2.5),
            DVec3::new(-0.25, 2.5, -1.0),
            DVec3::new(-1.0, 2.5, -1.0),
            DVec3::new(-1.0, -1.5, 0.5),
            DVec3::new(-0.25, -1.5, 0.5),
            DVec3::new(-1.0, 0.0, -1.5),
            DVec3::new(-1.0, -0.5, -1.0),
            DVec3::new(-0.25, 0.0, -1.5),
            DVec3::new(-0.25, -0.5, -1.0),
        ];
        let h = convex_hull(&pts).expect("hull");
        h.polytope.validate_exact().expect("exact");
        for f in 0..h.polytope.faces().len() {
            let (a, b, c) = h.polytope.face_frame(f).expect("frame");
            for p in &pts {
                assert_ne!(side(a, b, c, *p), Ordering::Greater);
            }
        }
    }
}
