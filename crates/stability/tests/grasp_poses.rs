//! Grasp faces against closed forms and a brute-force sampled disc test; resting poses against a brute-force
//! enumeration of supporting planes.

use crate::common;

use common::{box_part, boxes_part};
use glam::{DMat3, DVec2, DVec3};
use proptest::prelude::*;
use stackplan_geom::{Part, PartOrigin, convex_hull};
use stackplan_stability::grasp::{GraspOptions, grasp_faces, is_graspable};
use stackplan_stability::polygon2d::signed_boundary_distance;
use stackplan_stability::resting_poses::resting_poses;

fn opts(cup: f64) -> GraspOptions {
    GraspOptions { cup_diameter: cup, ..GraspOptions::default() }
}

#[test]
fn box_top_is_exact() {
    let part = box_part("b", DVec3::new(100.0, 40.0, 10.0));
    let faces = grasp_faces(&part, DMat3::IDENTITY, DVec3::ZERO, &opts(30.0));
    assert_eq!(faces.len(), 1);
    let f = &faces[0];
    assert!(f.exact);
    assert!((f.inscribed_radius - 20.0).abs() < 1e-6, "{}", f.inscribed_radius);
    assert!((f.center.y - 20.0).abs() < 1e-5 && (f.height - 10.0).abs() < 1e-12);
    assert!(f.fits_cup);
    assert!(!grasp_faces(&part, DMat3::IDENTITY, DVec3::ZERO, &opts(41.0))[0].fits_cup);
    // upside down the top is the former bottom
    let flipped = grasp_faces(&part, DMat3::from_rotation_x(std::f64::consts::PI), DVec3::ZERO, &opts(30.0));
    assert_eq!(flipped.len(), 1);
    assert!((flipped[0].height - 0.0).abs() < 1e-9);
}

#[test]
fn a_face_tilted_within_the_grasp_tilt_holds_the_cup_in_its_own_plane() {
    let part = box_part("b", DVec3::new(100.0, 60.0, 10.0));
    for (deg, max_deg, found) in [(3.0, 5.0, true), (3.0, 0.0, false), (8.0, 5.0, false), (8.0, 10.0, true)] {
        let turn = DMat3::from_rotation_x(f64::to_radians(deg));
        let options = GraspOptions { max_tilt: f64::to_radians(max_deg), ..opts(30.0) };
        let faces = grasp_faces(&part, turn, DVec3::ZERO, &options);
        assert_eq!(!faces.is_empty(), found, "{deg} degrees, tilt up to {max_deg}: {faces:?}");
        if let Some(f) = faces.first() {
            // the top face, measured in its plane: the inscribed disc is half its 60 mm width
            assert!((f.tilt - f64::to_radians(deg)).abs() < 1e-9, "{}", f.tilt);
            assert!((f.inscribed_radius - 30.0).abs() < 1e-6, "{}", f.inscribed_radius);
            // its centre lies on the turned top face, and its polygons too
            let top = turn * DVec3::Z;
            let offset = top.dot(turn * DVec3::new(0.0, 0.0, 10.0));
            assert!((top.dot(f.center) - offset).abs() < 1e-9);
            assert!(f.polygons.iter().flatten().all(|p| (top.dot(*p) - offset).abs() < 1e-9));
            assert!((f.height - f.center.z).abs() < 1e-12);
            assert!(is_graspable(&faces, &options));
        }
    }
}

#[test]
fn triangle_top_inradius() {
    let (a, b) = (30.0, 40.0);
    let tri = [DVec3::ZERO, DVec3::new(a, 0.0, 0.0), DVec3::new(0.0, b, 0.0)];
    let pts: Vec<DVec3> = tri.iter().flat_map(|&p| [p, p + DVec3::Z * 5.0]).collect();
    let part =
        Part::from_components("t", vec![convex_hull(&pts).expect("prism").polytope], 1.0, PartOrigin::ConvexPieces)
            .expect("part");
    let faces = grasp_faces(&part, DMat3::IDENTITY, DVec3::ZERO, &opts(10.0));
    assert_eq!(faces.len(), 1);
    assert!(faces[0].exact);
    let r = (a + b - (a * a + b * b).sqrt()) / 2.0;
    assert!((faces[0].inscribed_radius - r).abs() < 1e-6);
}

#[test]
fn l_shaped_top_is_bounded() {
    let part = boxes_part(
        "L",
        &[(DVec3::ZERO, DVec3::new(100.0, 40.0, 10.0)), (DVec3::new(0.0, 40.0, 0.0), DVec3::new(40.0, 100.0, 10.0))],
    );
    let faces = grasp_faces(&part, DMat3::IDENTITY, DVec3::ZERO, &opts(30.0));
    assert_eq!(faces.len(), 1);
    let f = &faces[0];
    let exact = 40.0 * 2f64.sqrt() / (1.0 + 2f64.sqrt());
    assert!(!f.exact);
    assert!(f.inscribed_radius <= exact + 1e-9 && f.inscribed_radius > exact - 1e-3, "{}", f.inscribed_radius);
    assert!(f.radius_upper_bound >= exact);
    assert!(f.fits_cup);
}

/// A step whose top is covered exactly by a wall standing on it (the flanges of sheet-metal parts: a component's top
/// face under the next component, split by the convex decomposition) leaves no area for a cup: radius 0, not a
/// radius without a boundary (it was infinite, and the face counted as graspable).
#[test]
fn a_face_covered_by_material_above_has_no_disc() {
    let part = boxes_part(
        "covered",
        &[
            (DVec3::ZERO, DVec3::new(2.0, 40.0, 60.0)),
            (DVec3::new(0.0, 0.0, 60.0), DVec3::new(2.0, 40.0, 120.0)),
            (DVec3::new(300.0, 0.0, 0.0), DVec3::new(302.0, 40.0, 60.0)),
            (DVec3::new(300.0, 0.0, 60.0), DVec3::new(302.0, 40.0, 120.0)),
        ],
    );
    let faces = grasp_faces(&part, DMat3::IDENTITY, DVec3::ZERO, &opts(10.0));
    let covered = faces.iter().find(|f| (f.height - 60.0).abs() < 1e-9).expect("the covered step");
    assert_eq!(covered.inscribed_radius, 0.0);
    assert!(!covered.fits_cup);
    let top = faces.iter().find(|f| (f.height - 120.0).abs() < 1e-9).expect("the top");
    assert!(top.inscribed_radius.is_finite() && (top.inscribed_radius - 1.0).abs() < 1e-3, "{}", top.inscribed_radius);
    assert!(faces.iter().all(|f| f.inscribed_radius.is_finite() && f.radius_upper_bound.is_finite()), "{faces:?}");
    assert!(!is_graspable(&faces, &opts(10.0)), "2 mm wide strips hold no 10 mm cup");
}

#[test]
fn material_above_and_holes_are_excluded() {
    // a base plate with a block on top: the plate's top is a frame around the block
    let part = boxes_part(
        "stepped",
        &[(DVec3::ZERO, DVec3::new(100.0, 100.0, 10.0)), (DVec3::new(30.0, 30.0, 10.0), DVec3::new(70.0, 70.0, 30.0))],
    );
    let faces = grasp_faces(&part, DMat3::IDENTITY, DVec3::ZERO, &opts(30.0));
    assert_eq!(faces.len(), 2);
    let top = faces.iter().find(|f| (f.height - 30.0).abs() < 1e-9).expect("top");
    assert!(top.exact && (top.inscribed_radius - 20.0).abs() < 1e-6);
    let frame = faces.iter().find(|f| (f.height - 10.0).abs() < 1e-9).expect("frame");
    let exact = 30.0 * 2f64.sqrt() / (1.0 + 2f64.sqrt());
    assert!(
        frame.inscribed_radius <= exact + 1e-9 && frame.inscribed_radius > exact - 1e-3,
        "{}",
        frame.inscribed_radius
    );
    // a plate with a square hole made of four boxes
    let plate = boxes_part(
        "holed",
        &[
            (DVec3::ZERO, DVec3::new(40.0, 100.0, 5.0)),
            (DVec3::new(60.0, 0.0, 0.0), DVec3::new(100.0, 100.0, 5.0)),
            (DVec3::new(40.0, 0.0, 0.0), DVec3::new(60.0, 40.0, 5.0)),
            (DVec3::new(40.0, 60.0, 0.0), DVec3::new(60.0, 100.0, 5.0)),
        ],
    );
    let faces = grasp_faces(&plate, DMat3::IDENTITY, DVec3::ZERO, &opts(30.0));
    assert_eq!(faces.len(), 1);
    let exact = 40.0 * 2f64.sqrt() / (1.0 + 2f64.sqrt());
    let f = &faces[0];
    assert!(f.inscribed_radius <= exact + 1e-9 && f.inscribed_radius > exact - 1e-3, "{}", f.inscribed_radius);
    // the disc centre is not in the hole
    let c = DVec2::new(f.center.x, f.center.y);
    assert!(!(c.x > 40.0 && c.x < 60.0 && c.y > 40.0 && c.y < 60.0));
}

#[test]
fn cup_patterns() {
    let pattern = vec![DVec2::new(-30.0, 0.0), DVec2::new(30.0, 0.0)];
    let long = box_part("long", DVec3::new(100.0, 40.0, 10.0));
    let o = GraspOptions { cup_diameter: 30.0, pattern: pattern.clone(), ..GraspOptions::default() };
    let faces = grasp_faces(&long, DMat3::IDENTITY, DVec3::ZERO, &o);
    let fit = faces[0].pattern_fit.expect("fit");
    assert!(fit.slack >= 0.0 && is_graspable(&faces, &o), "{fit:?}");
    // a short top cannot hold two cups 60 apart
    let short = box_part("short", DVec3::new(60.0, 40.0, 10.0));
    let faces = grasp_faces(&short, DMat3::IDENTITY, DVec3::ZERO, &o);
    assert!(!is_graspable(&faces, &o));
    assert!(faces[0].fits_cup);
}

/// Brute-force check of a convex polygon's inscribed disc: the reported disc lies inside (sampled on its circle) and
/// no grid point has a larger distance to the boundary.
fn check_disc(poly: &[DVec2], centre: DVec2, r: f64) {
    for k in 0..64 {
        let a = std::f64::consts::TAU * k as f64 / 64.0;
        let p = centre + DVec2::new(a.cos(), a.sin()) * (r * (1.0 - 1e-6));
        assert!(signed_boundary_distance(p, poly) >= -1e-9);
    }
    let (lo, hi) = poly.iter().fold((poly[0], poly[0]), |(l, h), p| (l.min(*p), h.max(*p)));
    let n = 60;
    for i in 0..=n {
        for j in 0..=n {
            let p = lo + (hi - lo) * DVec2::new(i as f64 / n as f64, j as f64 / n as f64);
            assert!(signed_boundary_distance(p, poly) <= r + 1e-6 * (hi - lo).length());
        }
    }
}

proptest! {
    /// Random convex prisms: the exact grasp radius is the largest disc (sampled disc test).
    #[test]
    fn random_convex_tops(pts in prop::collection::vec((0.0f64..50.0, 0.0f64..50.0), 4..12)) {
        let base: Vec<DVec3> = pts.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect();
        let all: Vec<DVec3> = base.iter().flat_map(|&p| [p, p + DVec3::Z * 3.0]).collect();
        let Ok(hull) = convex_hull(&all) else { return Ok(()) };
        let part = Part::from_components("p", vec![hull.polytope], 1.0, PartOrigin::ConvexPieces).expect("part");
        prop_assume!(part.mass().volume > 30.0);
        let faces = grasp_faces(&part, DMat3::IDENTITY, DVec3::ZERO, &opts(1.0));
        prop_assert_eq!(faces.len(), 1);
        let f = &faces[0];
        prop_assert!(f.exact);
        let top = &f.polygons[0];
        let poly = stackplan_stability::polygon2d::convex_hull_2d(&top.iter().map(|p| DVec2::new(p.x, p.y)).collect::<Vec<_>>(), 1e-12);
        check_disc(&poly, DVec2::new(f.center.x, f.center.y), f.inscribed_radius);
    }

    /// Random point clouds: the stable resting faces and their margins agree with a brute force over all supporting
    /// planes through three points (support polygon edges found as supporting lines through two points).
    #[test]
    fn resting_poses_match_brute_force(pts in prop::collection::vec((-10.0f64..10.0, -10.0f64..10.0, -10.0f64..10.0), 5..11)) {
        let points: Vec<DVec3> = pts.iter().map(|&(x, y, z)| DVec3::new(x, y, z)).collect();
        let Ok(hull) = convex_hull(&points) else { return Ok(()) };
        prop_assume!(hull.polytope.volume() > 1.0);
        let part = Part::from_components("cloud", vec![hull.polytope], 1.0, PartOrigin::ConvexPieces).expect("part");
        let cg = part.mass().center_of_gravity;
        let verts: Vec<DVec3> = part.all_vertices().collect();
        let tol = 1e-9 * 40.0;
        let mut expected: Vec<(DVec3, f64)> = Vec::new();
        for i in 0..verts.len() {
            for j in i + 1..verts.len() {
                for k in j + 1..verts.len() {
                    let n = (verts[j] - verts[i]).cross(verts[k] - verts[i]);
                    if n.length() < 1e-9 { continue; }
                    let n = n.normalize();
                    for n in [n, -n] {
                        if expected.iter().any(|(m, _)| (*m - n).length() < 1e-6) { continue; }
                        let d = n.dot(verts[i]);
                        if verts.iter().any(|v| n.dot(*v) > d + tol) { continue; }
                        // support polygon: points on the plane; margin by supporting lines through two points
                        let on: Vec<DVec3> = verts.iter().copied().filter(|v| (n.dot(*v) - d).abs() <= tol).collect();
                        let q = cg - n * (n.dot(cg) - d);
                        let mut margin = f64::INFINITY;
                        for a in 0..on.len() {
                            for b in 0..on.len() {
                                if a == b { continue; }
                                let e = on[b] - on[a];
                                let inward = n.cross(e).normalize();
                                // supporting line iff every on-plane point lies on its inner side
                                if on.iter().all(|p| inward.dot(*p - on[a]) >= -tol) {
                                    margin = margin.min(inward.dot(q - on[a]));
                                }
                            }
                        }
                        expected.push((n, margin));
                    }
                }
            }
        }
        let stable: Vec<&(DVec3, f64)> = expected.iter().filter(|(_, m)| *m > 1e-6).collect();
        let poses = resting_poses(&part).expect("poses");
        let borderline = expected.iter().filter(|(_, m)| m.abs() <= 1e-6).count();
        prop_assume!(borderline == 0);
        prop_assert_eq!(poses.len(), stable.len());
        for (n, m) in stable {
            let pose = poses.iter().find(|p| (p.face_normal - *n).length() < 1e-6).expect("pose for a stable face");
            prop_assert!((pose.margin - m).abs() < 1e-6, "{} vs {}", pose.margin, m);
            // the pose puts the face down, the part above the floor, the c.g. over the origin
            prop_assert!((pose.rotation * *n - DVec3::NEG_Z).length() < 1e-9);
            let lowest = verts.iter().map(|v| (pose.rotation * *v + pose.position).z).fold(f64::INFINITY, f64::min);
            prop_assert!(lowest.abs() < 1e-9);
            let c = pose.rotation * cg + pose.position;
            prop_assert!((c - DVec3::new(0.0, 0.0, pose.cg_height)).length() < 1e-9);
        }
        for w in poses.windows(2) {
            prop_assert!(w[0].cg_height <= w[1].cg_height);
        }
    }
}
