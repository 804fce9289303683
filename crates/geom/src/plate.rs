//! Flat plates of a sheet-metal part, and when the convex pieces of two plates may stand for their filled outlines.
//!
//! A sheet-metal face with holes is split into convex pieces (\[A\] V-A-1, [`crate::sheet_metal`]), and a c-space
//! search then meets one obstacle per pair of pieces: a 300 x 200 mm plate with seven holes is 17 pieces, and two
//! such plates 289 pairs whose obstacles overlap. A [`Plate`] records which components of a part came from one face
//! with a convex outline, with the face's normal, its filled outline (the hull of the pieces) and the diameters of the
//! outline and of the largest hole.
//!
//! **When the pieces of two plates may be merged** ([`merges_exactly`]). Let the plates be `P = (Q \ H) x S` and
//! `P' = (Q' \ H') x S'`: convex outlines `Q`, `Q'`, open holes `H`, `H'` strictly inside them and pairwise apart,
//! slabs `S`, `S'` of one direction (the plates are parallel). The union over the pieces' pairs of the pairs'
//! c-space obstacles is the c-space obstacle of `P` against `P'` (Minkowski sums distribute over unions), and it
//! equals the obstacle of the filled prisms `Q x S` against `Q' x S'` unless one filled outline fits into a hole of
//! the other:
//!
//! *Proof.* Both obstacles need the slabs to overlap, so it is a claim about the plane: if the interiors of `Q + x`
//! and `Q'` meet but those of `R = (Q \ H) + x` and `R' = Q' \ H'` do not, the connected open set `int R` lies in the
//! complement of `int R'`, whose parts (the outside of `Q'` and each closed hole) are disjoint closed sets, so it
//! lies in one of them; in a hole, `Q + x` fits into that hole. Otherwise `int R` misses `int Q'`, and likewise
//! `int R'` misses `int (Q + x)` (or `Q'` fits into a hole of `Q + x`). Then the convex open set
//! `V = int (Q + x) n int Q'` misses both pieces' interiors, so it lies in one hole of `Q + x` and in one hole of
//! `Q'`; a hole keeps a positive distance from its outline, so the boundary of `V` lies on the boundary of `Q'`,
//! i.e. `V = int Q'`, and `Q'` fits into a hole of `Q + x`. `[]`
//!
//! A set that fits into a hole has at most the hole's diameter, so the test is `diameter(Q) > diameter(H'_k)` for
//! every hole of the other plate, both ways (a sufficient condition, independent of the relative turn). The plates
//! count as parallel when the tilt between their normals, over the larger outline, moves a point by no more than the
//! tolerance: a corner of a plate tilted by less than that dips into a hole by less than the tolerance, which the
//! search does not resolve anyway. Plates that are not parallel do not merge: a corner of one can always dip into a
//! hole of the other without touching it (the pockets the search has to visit).
//!
//! **One side merged** ([`slices_clear_holes`]). The pieces of one plate against a single convex set `B` (a piece of
//! another part, turned anyhow): the union of the pieces' obstacles against `B` is the filled plate's obstacle
//! against `B` unless a slice of `B` by a slab parallel to the plate fits into a hole (the argument above with `B`'s
//! slab slice in the place of the other outline: the part of `B` inside the filled plate lies in one hole, and its
//! shadow on the plate reaches the outline unless the whole slice lies in the hole).
//!
//! Cost: O(pieces' vertices) per face to build, O(1) per [`merges_exactly`], O(vertices) per
//! [`slices_clear_holes`].

use crate::hull::convex_hull_merged;
use crate::polytope::ConvexPolytope;
use glam::{DMat3, DVec3};
use serde::{Deserialize, Serialize};

/// A flat plate of a part: the components that came from one sheet-metal face with a convex outline.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Plate {
    /// The plate's components (indices into [`crate::Part::components`], increasing).
    pub pieces: Vec<usize>,
    /// Unit normal of the face plane, in the part's coordinates.
    pub normal: DVec3,
    /// The filled outline: the convex hull of the pieces (the outline extruded by the thickness).
    pub filled: ConvexPolytope,
    /// Diameter of the outline (mm): the largest distance between two of its corners.
    pub outline_diameter: f64,
    /// Diameter of the largest hole (mm; 0 without holes).
    pub hole_diameter: f64,
}

impl Plate {
    /// The plate of one face: its components `pieces` (the prisms of the face), the face normal, and the corners of
    /// its outline and of each hole. `None` when the hull of the pieces cannot be built (no pieces).
    pub fn new(
        pieces: Vec<usize>,
        prisms: &[ConvexPolytope],
        normal: DVec3,
        outline: &[DVec3],
        holes: &[Vec<DVec3>],
    ) -> Option<Self> {
        let points: Vec<DVec3> = prisms.iter().flat_map(|p| p.vertices().iter().copied()).collect();
        let filled = convex_hull_merged(&points).ok()?.polytope;
        Some(Self {
            pieces,
            normal: normal.normalize_or_zero(),
            filled,
            outline_diameter: diameter(outline),
            hole_diameter: holes.iter().map(|h| diameter(h)).fold(0.0, f64::max),
        })
    }
}

/// The largest distance between two of `points` (0 for fewer than two). O(n^2).
pub fn diameter(points: &[DVec3]) -> f64 {
    let mut d2 = 0.0f64;
    for (i, a) in points.iter().enumerate() {
        for b in &points[i + 1..] {
            d2 = d2.max(a.distance_squared(*b));
        }
    }
    d2.sqrt()
}

/// Whether the c-space obstacles of every piece of plate `a` (turned by `rotation_a`) against every piece of plate
/// `b` (turned by `rotation_b`) together make exactly the obstacle of the filled plates (module documentation): the
/// turned normals are parallel within `tolerance` over the larger outline, and neither filled outline fits into a
/// hole of the other (`outline_diameter > hole_diameter + tolerance`, both ways). O(1).
pub fn merges_exactly(a: &Plate, rotation_a: DMat3, b: &Plate, rotation_b: DMat3, tolerance: f64) -> bool {
    let na = rotation_a * a.normal;
    let nb = rotation_b * b.normal;
    let reach = a.outline_diameter.max(b.outline_diameter);
    let tilt = na.cross(nb).length();
    let parallel = tilt * reach <= tolerance;
    let no_fit = a.outline_diameter > b.hole_diameter + tolerance && b.outline_diameter > a.hole_diameter + tolerance;
    parallel && no_fit && reach.is_finite()
}

/// Whether no slice of the convex set with `vertices` by a slab parallel to a plate with unit normal `normal` (any
/// thickness, anywhere along the normal) fits into a hole of diameter `hole_diameter`: then the obstacles of that set
/// against each of the plate's pieces together make exactly its obstacle against the filled plate (a convex set that
/// meets the filled plate but no piece meets it inside one hole, and its slab slice, which reaches the plate's
/// outline unless it lies in the hole, must then fit into that hole; see the module documentation for the same
/// argument). Sufficient test, by Brunn-Minkowski: the width of a convex set's sections along a fixed direction `u`
/// is a concave function of the section's level, so every section is at least as wide along `u` as the narrower of
/// the two extreme features along `normal` (the vertices within `tolerance` of the lowest and of the highest level);
/// a slice contains a section, and a set that fits into the hole is at most as wide as its diameter. The directions
/// tried are those between two vertices of one extreme feature. A feature that is a single vertex (a corner can dip
/// into any hole) fails. O(v + f^2) for `v` vertices and `f` in the extreme features.
pub fn slices_clear_holes(vertices: &[DVec3], normal: DVec3, hole_diameter: f64, tolerance: f64) -> bool {
    let n = normal.normalize_or_zero();
    if n == DVec3::ZERO || vertices.is_empty() || !hole_diameter.is_finite() {
        return false;
    }
    let level = |v: &DVec3| n.dot(*v);
    let lo = vertices.iter().map(level).fold(f64::INFINITY, f64::min);
    let hi = vertices.iter().map(level).fold(f64::NEG_INFINITY, f64::max);
    if !(lo.is_finite() && hi.is_finite()) {
        return false;
    }
    let feature = |at: f64| -> Vec<DVec3> {
        vertices.iter().filter(|v| (level(v) - at).abs() <= tolerance).map(|v| *v - n * level(v)).collect()
    };
    let (bottom, top) = (feature(lo), feature(hi));
    let width = |points: &[DVec3], u: DVec3| {
        let (a, b) =
            points.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(u.dot(*p)), b.max(u.dot(*p))));
        b - a
    };
    let needed = hole_diameter + tolerance;
    for points in [&bottom, &top] {
        for (i, p) in points.iter().enumerate() {
            for q in &points[i + 1..] {
                let u = (*q - *p).normalize_or_zero();
                if u != DVec3::ZERO && width(&bottom, u) > needed && width(&top, u) > needed {
                    return true;
                }
            }
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plate(outline_diameter: f64, hole_diameter: f64, normal: DVec3) -> Plate {
        let filled = ConvexPolytope::cuboid(DVec3::ZERO, DVec3::ONE).expect("cube");
        Plate { pieces: vec![0, 1], normal, filled, outline_diameter, hole_diameter }
    }

    #[test]
    fn the_complex_part_has_six_plates_covering_its_pieces() {
        use crate::sheet_metal::Decomposition;
        let part = crate::examples::complex().build_part("complex", 1.0, Decomposition::ConvexMerge).expect("part");
        assert_eq!(part.plates.len(), 6);
        let mut seen: Vec<usize> = part.plates.iter().flat_map(|p| p.pieces.iter().copied()).collect();
        seen.sort_unstable();
        assert_eq!(seen, (0..part.components.len()).collect::<Vec<_>>(), "every piece in exactly one plate");
        let base = &part.plates[0];
        assert_eq!(base.pieces.len(), 17);
        assert!((base.normal.z.abs() - 1.0).abs() < 1e-12);
        // the 300 x 200 outline, its octagonal hole of diameter 50 the largest of its seven
        assert!((base.outline_diameter - 300f64.hypot(200.0)).abs() < 1e-9);
        assert!((base.hole_diameter - 50.0).abs() < 1e-9);
        // the filled plate is the outline extruded by the 2 mm thickness
        assert!((base.filled.volume() - 300.0 * 200.0 * 2.0).abs() < 1e-6);
        // the walls with two 40 x 60 holes; the short walls and the flange without holes
        assert_eq!(part.plates.iter().map(|p| p.pieces.len()).collect::<Vec<_>>(), vec![17, 5, 5, 1, 1, 1]);
        assert!((part.plates[1].hole_diameter - 40f64.hypot(60.0)).abs() < 1e-9);
        assert_eq!(part.plates[3].hole_diameter, 0.0);
    }

    #[test]
    fn a_plate_naming_a_missing_piece_is_left_out() {
        use crate::sheet_metal::Decomposition;
        let mut part = crate::examples::complex().build_part("complex", 1.0, Decomposition::ConvexMerge).expect("part");
        let before = part.plate_of_components();
        let mut bogus = part.plates[1].clone();
        bogus.pieces = vec![0, part.components.len()];
        part.plates.push(bogus.clone());
        bogus.pieces.clear();
        part.plates.push(bogus);
        assert_eq!(part.plate_of_components(), before);
    }

    #[test]
    fn a_concave_face_is_no_plate() {
        use crate::sheet_metal::{Decomposition, SheetFace, SheetMetal};
        let l = [(0.0, 0.0), (100.0, 0.0), (100.0, 30.0), (30.0, 30.0), (30.0, 100.0), (0.0, 100.0)];
        let face = SheetFace { outline: l.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect(), holes: vec![] };
        let sheet = SheetMetal { faces: vec![face], thickness: 2.0 };
        let part = sheet.build_part("l", 1.0, Decomposition::ConvexMerge).expect("part");
        assert!(part.components.len() >= 2);
        assert!(part.plates.is_empty(), "the hull of an L is not the L");
    }

    #[test]
    fn slices_of_a_long_bar_clear_a_small_hole_but_its_end_does_not() {
        let bar = ConvexPolytope::cuboid(DVec3::new(0.0, 0.0, 0.0), DVec3::new(200.0, 2.0, 150.0)).expect("bar");
        // a vertical wall 200 long against a horizontal plate: every horizontal slice is 200 x 2
        assert!(slices_clear_holes(bar.vertices(), DVec3::Z, 50.0, 1e-6));
        // against a plate parallel to its end (normal x): the slices are 2 x 150, wider than a 100 mm hole only along z
        assert!(slices_clear_holes(bar.vertices(), DVec3::X, 100.0, 1e-6));
        assert!(!slices_clear_holes(bar.vertices(), DVec3::X, 160.0, 1e-6));
        // turned so that a vertical edge leads (normal between x and y): a slice near it is thin
        let turned = DMat3::from_rotation_z(0.3);
        let vertices: Vec<DVec3> = bar.vertices().iter().map(|v| turned * *v).collect();
        assert!(slices_clear_holes(&vertices, DVec3::Z, 50.0, 1e-6));
        // against a wall across it a vertical edge leads: its slices are thin but 150 tall
        let across = DVec3::new(1.0, 1.0, 0.0).normalize();
        assert!(slices_clear_holes(&vertices, across, 100.0, 1e-6));
        assert!(!slices_clear_holes(&vertices, across, 160.0, 1e-6));
        // a corner leading (a tilted bar) never clears
        let tilted: Vec<DVec3> = bar.vertices().iter().map(|v| DMat3::from_rotation_x(0.2) * turned * *v).collect();
        assert!(!slices_clear_holes(&tilted, DVec3::Z, 1.0, 1e-6));
    }

    #[test]
    fn diameter_of_a_rectangle_is_its_diagonal() {
        let r = [DVec3::ZERO, DVec3::new(30.0, 0.0, 0.0), DVec3::new(30.0, 40.0, 0.0), DVec3::new(0.0, 40.0, 0.0)];
        assert!((diameter(&r) - 50.0).abs() < 1e-12);
        assert_eq!(diameter(&r[..1]), 0.0);
    }

    #[test]
    fn parallel_plates_too_large_for_the_holes_merge() {
        let a = plate(360.0, 50.0, DVec3::Z);
        let b = plate(360.0, 50.0, -DVec3::Z);
        assert!(merges_exactly(&a, DMat3::IDENTITY, &b, DMat3::from_rotation_z(0.7), 1e-6));
    }

    #[test]
    fn a_plate_that_may_fit_into_a_hole_does_not_merge() {
        let big = plate(360.0, 50.0, DVec3::Z);
        let small = plate(40.0, 0.0, DVec3::Z);
        assert!(!merges_exactly(&small, DMat3::IDENTITY, &big, DMat3::IDENTITY, 1e-6));
        assert!(!merges_exactly(&big, DMat3::IDENTITY, &small, DMat3::IDENTITY, 1e-6));
    }

    #[test]
    fn tilted_plates_do_not_merge() {
        let a = plate(360.0, 50.0, DVec3::Z);
        // a tilt of 1e-6 rad moves the far corner by 3.6e-4 mm: more than the tolerance
        assert!(!merges_exactly(&a, DMat3::from_rotation_x(1e-6), &a, DMat3::IDENTITY, 1e-6));
        // perpendicular plates never merge
        let wall = plate(360.0, 50.0, DVec3::X);
        assert!(!merges_exactly(&a, DMat3::IDENTITY, &wall, DMat3::IDENTITY, 1e-6));
        // a tilt below the tolerance over the outline does
        assert!(merges_exactly(&a, DMat3::from_rotation_x(1e-12), &a, DMat3::IDENTITY, 1e-6));
    }
}
