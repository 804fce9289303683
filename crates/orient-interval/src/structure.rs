//! Comparison of obstacle structures: faces identified by kind and generating features, each with its cycle of
//! vertex provenances `[i, j]` (rotated to a canonical start), compared as sets. Used by the tests, the sweep's
//! self-check and the benchmarks' interval-length measurement. O(size log size).

use stackplan_cspace::minkowski::Obstacle;
use std::collections::BTreeSet;

/// A face as kind (with features) and canonical provenance cycle.
pub type FaceKey = (String, Vec<[usize; 2]>);

/// The structure of an obstacle as a set of faces ([`Obstacle::structure`]).
pub fn structure_key(o: &Obstacle) -> BTreeSet<FaceKey> {
    o.structure()
}

/// Whether two obstacles have the same structure and provenance.
pub fn same_structure(a: &Obstacle, b: &Obstacle) -> bool {
    structure_key(a) == structure_key(b)
}

/// Largest vertex distance between two obstacles of the same structure (vertices matched by provenance), relative to
/// the larger bounding-box diagonal, and the largest difference of corresponding face planes (normal difference plus
/// offset difference relative to the diagonal), faces matched by kind. `None` when the structures differ.
pub fn relative_difference(a: &Obstacle, b: &Obstacle) -> Option<f64> {
    if !same_structure(a, b) {
        return None;
    }
    let scale = {
        let (lo, hi) = a.polytope().aabb();
        (hi - lo).length().max(1e-300)
    };
    let mut worst = 0.0f64;
    let mut by_pair = std::collections::HashMap::new();
    for (v, p) in b.vertex_pairs().iter().enumerate() {
        by_pair.insert(*p, b.polytope().vertices()[v]);
    }
    for (v, p) in a.vertex_pairs().iter().enumerate() {
        let other = by_pair.get(p)?;
        worst = worst.max((a.polytope().vertices()[v] - *other).length() / scale);
    }
    let mut planes_b = std::collections::HashMap::new();
    for (f, k) in b.face_kinds().iter().enumerate() {
        planes_b.insert(*k, b.polytope().faces()[f].plane);
    }
    for (f, k) in a.face_kinds().iter().enumerate() {
        let pa = a.polytope().faces()[f].plane;
        let pb = planes_b.get(k)?;
        worst = worst.max((pa.normal - pb.normal).length()).max((pa.offset - pb.offset).abs() / scale);
    }
    Some(worst)
}
