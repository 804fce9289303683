//! Flattening the faces of a part read from a mesh stored in single precision (or with a given mesh tolerance).
//!
//! A part turned into place and stored in `f32` has faces planar only to about one rounding of its coordinates
//! (1e-7 of their magnitude); the readers merge each face's creased facets back into one face within the mesh's
//! length tolerance ([`super::mesh`]), but its corners still lie up to a few roundings off its plane. Every later
//! test works with the kernel's tolerance, `1e-9 x` the part's size, a hundred times finer: a face resting on the
//! floor touches it at its lowest corners only, c-space faces come out parallel to the last bit, and plans of such
//! parts placed 2 or 3 of 6 Triangle parts where the same part stored in `f64` placed all. This step moves every
//! corner of such faces onto the planes it lies on, so that the part's faces are planar to `f64` rounding:
//!
//! 1. the faces of all components, and those of the whole part's hull (a face across several components, such as a
//!    resting face on the tips of two flanges), that lie in one plane within the tolerance `t` (a face and the
//!    touching face of the neighbouring component, coplanar faces of neighbouring components) form one **cluster**;
//!    faces parallel within `4 t / D` (D the part's bounding diagonal) share one normal, the area-weighted normal of
//!    their faces (signs aligned), and each cluster's plane goes through the mean of its corners;
//! 2. a cluster is **creased** unless all its corners are exactly coplanar (exact `orient3d`);
//! 3. every corner on a creased cluster moves by the least displacement `delta` that puts it on the planes of all
//!    clusters it lies on, in the least-squares sense: `(N^T N + eps I) delta = N^T (d - N v)` with
//!    `eps = 1e-12 tr(N^T N)` (two planes through an edge fix only its line); the planes are fitted again to the
//!    moved corners and the corners moved again, up to 200 rounds, until every corner lies on its planes within
//!    `1e-13` of the part's coordinates (more than three planes through one corner, the faces of three components
//!    around one edge, agree only after a few rounds). A corner that would move more than `4 t` from where it was
//!    read stays there (its faces stay as read). A corner shared by components moves once, for all of them;
//! 4. each component is rebuilt as the merged hull of its moved corners (within `t`); a component whose rebuild fails
//!    or loses faces is kept as read.
//!
//! When the planes of the whole hull's faces and the components' cannot all hold (the rounds end without agreeing:
//! the whole hull merged within `t` sliver facets of a long part that are not one face), steps 1-3 run again without
//! the whole hull's faces.
//!
//! Exactly planar faces and their corners are never moved, so a part whose faces are exactly planar (axis-aligned
//! parts in any precision) reads back bit for bit. Cost: O(F log F + V) for F faces and V corners, plus one merged
//! hull per component that has a moved corner.

use crate::hull::convex_hull_merged_within;
use crate::polytope::{ConvexPolytope, newell_normal};
use crate::predicates::side;
use glam::{DMat3, DVec3};
use std::cmp::Ordering;
use std::collections::HashMap;

/// Faces up to which direction classes and planes are sought among all pairs (beyond, among faces sharing a corner).
const MAX_ALL_PAIRS: usize = 4096;

/// Rounds of fitting planes and moving corners at most: the alternation gains a factor of about 0.7 per round on the
/// turned Triangle (1e-5 mm to 1e-13 of its coordinates in about 60 rounds).
const MAX_ROUNDS: usize = 200;

/// The components with the corners of their creased faces moved onto their planes (module documentation); returns
/// the components and the number of corners moved.
pub(crate) fn flatten_faces(components: Vec<ConvexPolytope>, tolerance: f64) -> (Vec<ConvexPolytope>, usize) {
    // with the whole hull's faces; when their planes and the components' cannot all hold (the hull merged within `t`
    // facets that are not one face: a long part's hull has slivers folded by less than `t`), without them
    // (nothing creased with the whole hull's faces is nothing creased without them: no second attempt)
    let moves = match plan_moves(&components, tolerance, true) {
        None => return (components, 0),
        Some(m) if m.converged => m,
        Some(_) => match plan_moves(&components, tolerance, false) {
            Some(m) => m,
            None => return (components, 0),
        },
    };
    let Moves { ids, corners, moved_corner, .. } = moves;
    let moved = moved_corner.iter().filter(|m| m.is_some()).count();
    if moved == 0 {
        return (components, 0);
    }
    let rebuilt = components
        .into_iter()
        .zip(&ids)
        .map(|(comp, ids)| {
            if ids.iter().all(|&v| moved_corner[v].is_none()) {
                return comp;
            }
            let points: Vec<DVec3> = ids.iter().map(|&v| moved_corner[v].unwrap_or(corners[v])).collect();
            match convex_hull_merged_within(&points, tolerance) {
                Ok(h) if h.polytope.faces().len() == comp.faces().len() => h.polytope,
                _ => comp,
            }
        })
        .collect();
    (rebuilt, moved)
}

/// Where the corners of the components go (by global corner): [`flatten_faces`]'s steps 1-3.
struct Moves {
    /// Per component, per vertex: its global corner.
    ids: Vec<Vec<usize>>,
    /// The global corners as read.
    corners: Vec<DVec3>,
    /// Per global corner: where it moves, if it moves.
    moved_corner: Vec<Option<DVec3>>,
    /// Whether every moved corner lies on its planes within `1e-13` of the coordinates.
    converged: bool,
}

/// Steps 1-3 of the module documentation, with the whole hull's faces among the faces when `hull_faces`; `None` when
/// no face is creased.
fn plan_moves(components: &[ConvexPolytope], tolerance: f64, hull_faces: bool) -> Option<Moves> {
    // global corners by exact coordinates (components touching share them bit for bit)
    let mut id_of: HashMap<[u64; 3], usize> = HashMap::new();
    let mut corners: Vec<DVec3> = Vec::new();
    let key = |p: DVec3| (p + DVec3::ZERO).to_array().map(f64::to_bits);
    let ids: Vec<Vec<usize>> = components
        .iter()
        .map(|c| {
            c.vertices()
                .iter()
                .map(|&p| {
                    *id_of.entry(key(p)).or_insert_with(|| {
                        corners.push(p);
                        corners.len() - 1
                    })
                })
                .collect()
        })
        .collect();
    // faces: their global corners and unit normals
    struct FaceRef {
        corners: Vec<usize>,
        normal: DVec3,
    }
    let mut faces: Vec<FaceRef> = Vec::new();
    for (c, comp) in components.iter().enumerate() {
        for f in comp.faces() {
            let corners_of: Vec<usize> = f.vertices.iter().map(|&v| ids[c][v]).collect();
            faces.push(FaceRef { corners: corners_of, normal: f.plane.normal });
        }
    }
    // the faces of the whole part's hull too (merged within the tolerance): a face across several components (a
    // resting face on the tips of two flanges) is no component's face, and its corners are to lie in one plane as well
    if hull_faces
        && components.len() > 1
        && let Ok(hull) = convex_hull_merged_within(&corners, tolerance)
    {
        for f in hull.polytope.faces() {
            let corners_of: Vec<usize> = f.vertices.iter().map(|&v| hull.source[v]).collect();
            faces.push(FaceRef { corners: corners_of, normal: f.plane.normal });
        }
    }
    // clusters: union of faces that share a corner and lie in one plane within the tolerance
    let mut parent: Vec<usize> = (0..faces.len()).collect();
    fn find(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    let mut faces_at: Vec<Vec<usize>> = vec![Vec::new(); corners.len()];
    for (i, f) in faces.iter().enumerate() {
        for &v in &f.corners {
            faces_at[v].push(i);
        }
    }
    let within = |f: &FaceRef, g: &FaceRef| {
        let at = corners[g.corners[0]];
        f.corners.iter().all(|&v| g.normal.dot(corners[v] - at).abs() <= tolerance)
    };
    // direction classes: faces whose normals are parallel (either sign) within `4 t / D` (a turn by that angle moves
    // no point of the part by more than `4 t`); all pairs when there are few faces, else only faces sharing a corner
    let extent = crate::tolerance::bounding_diagonal(&corners).max(f64::MIN_POSITIVE);
    let angle = 4.0 * tolerance / extent;
    let mut class_parent: Vec<usize> = (0..faces.len()).collect();
    let parallel = |f: &FaceRef, g: &FaceRef| f.normal.cross(g.normal).length() <= angle;
    let mut join = |i: usize, j: usize| {
        let (f, g) = (&faces[i], &faces[j]);
        if !parallel(f, g) {
            return;
        }
        let (ci, cj) = (find(&mut class_parent, i), find(&mut class_parent, j));
        if ci != cj {
            class_parent[ci.max(cj)] = ci.min(cj);
        }
        // one plane: every corner of each within the tolerance of the other's plane
        if within(f, g) && within(g, f) {
            let (ri, rj) = (find(&mut parent, i), find(&mut parent, j));
            if ri != rj {
                parent[ri.max(rj)] = ri.min(rj);
            }
        }
    };
    // (the pairs are visited, never collected: 4096 faces make 8 million of them)
    if faces.len() <= MAX_ALL_PAIRS {
        for i in 0..faces.len() {
            for j in i + 1..faces.len() {
                join(i, j);
            }
        }
    } else {
        for around in &faces_at {
            for (a, &i) in around.iter().enumerate() {
                for &j in &around[a + 1..] {
                    join(i, j);
                }
            }
        }
    }
    let class_of: Vec<usize> = (0..faces.len()).map(|i| find(&mut class_parent, i)).collect();
    // each cluster's faces and corners, and whether its corners are exactly coplanar
    let cluster_of: Vec<usize> = (0..faces.len()).map(|i| find(&mut parent, i)).collect();
    let mut cluster_corners: HashMap<usize, Vec<usize>> = HashMap::new();
    let mut cluster_faces: HashMap<usize, Vec<usize>> = HashMap::new();
    for (i, &r) in cluster_of.iter().enumerate() {
        cluster_corners.entry(r).or_default().extend(&faces[i].corners);
        cluster_faces.entry(r).or_default().push(i);
    }
    let mut creased: HashMap<usize, bool> = HashMap::new();
    for (&r, list) in &mut cluster_corners {
        list.sort_unstable();
        list.dedup();
        let pts: Vec<DVec3> = list.iter().map(|&v| corners[v]).collect();
        let exact = exact_frame(&pts).is_some_and(|(a, b, c)| pts.iter().all(|&p| side(a, b, c, p) == Ordering::Equal));
        creased.insert(r, !exact);
    }
    if !creased.values().any(|&c| c) {
        return None;
    }
    // a class with a creased cluster: all its clusters move (their common normal is fitted anew)
    let mut class_creased: HashMap<usize, bool> = HashMap::new();
    for (i, &r) in cluster_of.iter().enumerate() {
        *class_creased.entry(class_of[i]).or_insert(false) |= creased[&r];
    }
    for (i, &r) in cluster_of.iter().enumerate() {
        if class_creased[&class_of[i]] {
            creased.insert(r, true);
        }
    }
    let mut class_faces: HashMap<usize, Vec<usize>> = HashMap::new();
    for (i, &c) in class_of.iter().enumerate() {
        class_faces.entry(c).or_default().push(i);
    }
    let mut classes_sorted: Vec<usize> = class_faces.keys().copied().collect();
    classes_sorted.sort_unstable();
    // the corners to move (on a creased cluster) and the clusters each lies on
    let mut clusters_at: Vec<Vec<usize>> = Vec::with_capacity(corners.len());
    for around in &faces_at {
        let mut clusters: Vec<usize> = around.iter().map(|&i| cluster_of[i]).collect();
        clusters.sort_unstable();
        clusters.dedup();
        clusters_at.push(clusters);
    }
    let mut active: Vec<bool> = clusters_at.iter().map(|cs| cs.iter().any(|r| creased[r])).collect();
    // alternate: each cluster's plane fitted to its corners (area-weighted normal of its faces, signs aligned with
    // its first face; offset the mean over its corners), then each corner moved by the least displacement onto the
    // planes it lies on; the planes of more than three clusters through one corner (the faces of three components
    // around one edge) agree only after a few rounds
    let size = corners.iter().fold(0.0f64, |m, p| m.max(p.abs().max_element())).max(1.0);
    let mut position = corners.clone();
    let mut converged = false;
    let mut clusters_sorted: Vec<usize> = cluster_faces.keys().copied().collect();
    clusters_sorted.sort_unstable();
    for _round in 0..MAX_ROUNDS {
        let mut direction: HashMap<usize, DVec3> = HashMap::with_capacity(classes_sorted.len());
        for &c in &classes_sorted {
            let reference = faces[class_faces[&c][0]].normal;
            let mut n = DVec3::ZERO;
            for &i in &class_faces[&c] {
                let a = newell_normal(faces[i].corners.iter().map(|&v| position[v]));
                n += if a.dot(reference) >= 0.0 { a } else { -a };
            }
            direction.insert(c, n.normalize_or_zero());
        }
        let mut plane: HashMap<usize, (DVec3, f64)> = HashMap::with_capacity(clusters_sorted.len());
        for &r in &clusters_sorted {
            let n = direction[&class_of[cluster_faces[&r][0]]];
            let list = &cluster_corners[&r];
            let d = list.iter().map(|&v| n.dot(position[v])).sum::<f64>() / list.len() as f64;
            plane.insert(r, (n, d));
        }
        let mut worst = 0.0f64;
        for v in 0..position.len() {
            if !active[v] {
                continue;
            }
            let p = position[v];
            let mut ata = DMat3::ZERO;
            let mut atr = DVec3::ZERO;
            for r in &clusters_at[v] {
                let (n, d) = plane[r];
                ata += DMat3::from_cols(n * n.x, n * n.y, n * n.z);
                atr += n * (d - n.dot(p));
                worst = worst.max((n.dot(p) - d).abs());
            }
            let eps = 1e-12 * (ata.x_axis.x + ata.y_axis.y + ata.z_axis.z);
            let regularised = ata + DMat3::from_diagonal(DVec3::splat(eps));
            if regularised.determinant().abs() <= f64::MIN_POSITIVE {
                active[v] = false;
                position[v] = corners[v];
                continue;
            }
            let q = p + regularised.inverse() * atr;
            if q.is_finite() && (q - corners[v]).length() <= 4.0 * tolerance {
                position[v] = q;
            } else {
                active[v] = false;
                position[v] = corners[v];
            }
        }
        tracing::trace!(round = _round, worst, inactive = active.iter().filter(|a| !**a).count(), "flattening");
        if worst <= 1e-13 * size {
            converged = true;
            break;
        }
    }
    let moved_corner: Vec<Option<DVec3>> =
        (0..corners.len()).map(|v| (active[v] && position[v] != corners[v]).then_some(position[v])).collect();
    Some(Moves { ids, corners, moved_corner, converged })
}

/// Three points of `pts` that are not collinear (exactly), if any.
fn exact_frame(pts: &[DVec3]) -> Option<(DVec3, DVec3, DVec3)> {
    let a = *pts.first()?;
    let b = *pts.iter().find(|&&p| p != a)?;
    let c = *pts.iter().find(|&&p| !crate::predicates::collinear(a, b, p))?;
    Some((a, b, c))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hull::convex_hull;

    /// A box turned by a general rotation and rounded to `f32`: its faces are planar only to single precision. After
    /// flattening, every corner lies on every face plane it belongs to within 1e-12 of the size, and the box keeps
    /// its 6 faces and 8 corners; an axis-aligned box is returned bit for bit.
    #[test]
    fn a_turned_single_precision_box_comes_out_flat() {
        let turn = DMat3::from_euler(glam::EulerRot::ZYX, 0.3, 0.7, 1.1);
        let corners: Vec<DVec3> = (0..8)
            .map(|i: usize| {
                let c = |bit: usize, e: f64| if i & bit == 0 { 0.0 } else { e };
                (turn * DVec3::new(c(1, 40.0), c(2, 25.0), c(4, 3.0)) + DVec3::new(100.0, -50.0, 20.0))
                    .as_vec3()
                    .as_dvec3()
            })
            .collect();
        let tolerance = 16.0 * f64::from(f32::EPSILON) / 2.0 * 150.0;
        let read = convex_hull_merged_within(&corners, tolerance).expect("box").polytope;
        assert_eq!(read.faces().len(), 6);
        let worst = |c: &ConvexPolytope| {
            c.faces()
                .iter()
                .flat_map(|f| f.vertices.iter().map(move |&v| (f, v)))
                .map(|(f, v)| f.plane.signed_distance(c.vertices()[v]).abs())
                .fold(0.0f64, f64::max)
        };
        let before = worst(&read);
        assert!(before > 1e-9, "the test has teeth: the read box is planar only to {before:e}");
        let (flat, moved) = flatten_faces(vec![read], tolerance);
        assert!(moved > 0);
        assert_eq!((flat[0].faces().len(), flat[0].vertices().len()), (6, 8));
        let after = worst(&flat[0]);
        assert!(after <= 1e-12 * 150.0, "corners still {after:e} off their planes");
        // the exact hull of the moved corners has the box's faces again, each creased only by rounding
        let exact = convex_hull(flat[0].vertices()).expect("hull").polytope;
        assert!(exact.faces().len() <= 12);

        let axis: Vec<DVec3> =
            (0..8).map(|i: usize| DVec3::new((i & 1) as f64 * 4.0, (i >> 1 & 1) as f64, (i >> 2 & 1) as f64)).collect();
        let aligned = convex_hull_merged_within(&axis, tolerance).expect("box").polytope;
        let (same, moved) = flatten_faces(vec![aligned.clone()], tolerance);
        assert_eq!(moved, 0);
        assert_eq!(same[0], aligned);
    }

    /// Two turned single-precision boxes touching face to face: the shared corners move once, to the same place,
    /// so the components still share them bit for bit.
    #[test]
    fn touching_components_keep_their_shared_corners() {
        let turn = DMat3::from_euler(glam::EulerRot::ZYX, -1.3, 0.25, 2.6);
        let corner = |i: usize, x0: f64| {
            let c = |bit: usize, lo: f64, e: f64| if i & bit == 0 { lo } else { lo + e };
            (turn * DVec3::new(c(1, x0, 10.0), c(2, 0.0, 7.0), c(4, 0.0, 2.0))).as_vec3().as_dvec3()
        };
        let tolerance = 16.0 * f64::from(f32::EPSILON) / 2.0 * 30.0;
        let a: Vec<DVec3> = (0..8).map(|i| corner(i, 0.0)).collect();
        let b: Vec<DVec3> = (0..8).map(|i| corner(i, 10.0)).collect();
        let parts = vec![
            convex_hull_merged_within(&a, tolerance).expect("a").polytope,
            convex_hull_merged_within(&b, tolerance).expect("b").polytope,
        ];
        let shared_before: usize = parts[0].vertices().iter().filter(|p| parts[1].vertices().contains(p)).count();
        assert_eq!(shared_before, 4);
        let (flat, _) = flatten_faces(parts, tolerance);
        let shared_after: usize = flat[0].vertices().iter().filter(|p| flat[1].vertices().contains(p)).count();
        assert_eq!(shared_after, 4, "the shared face's corners moved differently");
        assert!(flat.iter().all(|c| c.faces().len() == 6));
    }
}
