//! The graspable poses of the real parts (`fixtures/realparts`, STEP and STL) against a brute-force reference, and
//! the STEP and STL twins against each other, with the plans' 10 mm cup on faces up to 5 degrees off level.
//!
//! The reference shares nothing with `grasp`'s regions, boundaries, grid and compass search, nor with its families of
//! faces: it groups the upward component faces into planes itself, takes as material above a plane every
//! component's part more than `CLEAR` above it (projected along the plane's normal), and tries cup centres on a grid
//! over the plane's faces. A disc fits at a centre when it keeps its radius from every obstacle (exact distance to a
//! convex polygon) and every point of a dense sample of the disc lies on one of the plane's faces. A plane holds the
//! cup when a disc of `(1 + MARGIN) r` fits at a grid centre, and does not when no disc of `(1 - MARGIN) r` does:
//! a disc of radius `r` at any centre leaves one of `r - g / sqrt 2` at the nearest grid centre, `g` the spacing,
//! which is `sqrt 2 MARGIN r`. The real parts' faces are all far from the cup's radius, so every plane is decided.

use glam::{DVec2, DVec3};
use stackplan_geom::{ConvexPolytope, Part};
use stackplan_stability::grasp::{GraspFace, GraspOptions, grasp_faces, is_graspable};
use stackplan_stability::resting_poses::resting_poses;
use std::path::PathBuf;

const CUP_DIAMETER: f64 = 10.0;
const MAX_TILT_DEG: f64 = 5.0;
/// Relative margin of the reference's verdicts.
const MARGIN: f64 = 0.2;
/// Material less than this above a plane (mm) is not in the way (the analysis' limit is the part's tolerance,
/// 5e-7 mm: only slivers along the plane's edges lie between).
const CLEAR: f64 = 1e-4;
/// Faces of one plane: normals within this angle (rad) and vertices within `PLANE_OFFSET` (mm) of the plane. The real
/// parts' distinct tilted faces are more than 1e-3 rad apart; one plane read from STL spreads over 1e-5 rad.
const PLANE_ANGLE: f64 = 1e-4;
const PLANE_OFFSET: f64 = 1e-3;
/// Spacing of the sample points on a disc's rings (mm).
const SAMPLE_SPACING: f64 = 0.5;

fn part(file: &str) -> Part {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/realparts").join(file);
    stackplan_geom::io::read_part(&path, &Default::default()).unwrap_or_else(|e| panic!("{file}: {e}"))
}

fn options() -> GraspOptions {
    GraspOptions { cup_diameter: CUP_DIAMETER, max_tilt: MAX_TILT_DEG.to_radians(), ..GraspOptions::default() }
}

/// Counter-clockwise convex hull (Andrew's monotone chain), collinear points dropped.
fn hull(mut pts: Vec<DVec2>) -> Vec<DVec2> {
    pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let turn = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let mut lower: Vec<DVec2> = Vec::new();
    for &p in &pts {
        while lower.len() >= 2 && turn(lower[lower.len() - 2], lower[lower.len() - 1], p) <= 0.0 {
            lower.pop();
        }
        lower.push(p);
    }
    let mut upper: Vec<DVec2> = Vec::new();
    for &p in pts.iter().rev() {
        while upper.len() >= 2 && turn(upper[upper.len() - 2], upper[upper.len() - 1], p) <= 0.0 {
            upper.pop();
        }
        upper.push(p);
    }
    lower.pop();
    upper.pop();
    lower.extend(upper);
    lower
}

fn polygon_area(poly: &[DVec2]) -> f64 {
    (0..poly.len()).map(|k| poly[k].perp_dot(poly[(k + 1) % poly.len()])).sum::<f64>() / 2.0
}

/// Distance from `p` to the closed convex counter-clockwise polygon `poly` (0 inside).
fn distance_to_polygon(p: DVec2, poly: &[DVec2]) -> f64 {
    let n = poly.len();
    let inside = (0..n).all(|k| (poly[(k + 1) % n] - poly[k]).perp_dot(p - poly[k]) >= 0.0);
    if inside {
        return 0.0;
    }
    (0..n)
        .map(|k| {
            let (a, b) = (poly[k], poly[(k + 1) % n]);
            let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            (p - (a + (b - a) * t)).length()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Whether `p` lies in the convex counter-clockwise polygon `poly`, to 1e-6 mm.
fn on_polygon(p: DVec2, poly: &[DVec2]) -> bool {
    let n = poly.len();
    (0..n).all(|k| {
        let (a, b) = (poly[k], poly[(k + 1) % n]);
        (b - a).perp_dot(p - a) / (b - a).length() >= -1e-6
    })
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Verdict {
    Holds,
    DoesNot,
    Undecided,
}

/// A plane of upward faces of a posed part and whether it holds the cup.
#[derive(Debug)]
struct Plane {
    normal: DVec3,
    offset: f64,
    verdict: Verdict,
}

/// The reference: the planes of the posed components' faces within the tilt of level, each with its verdict.
fn reference_planes(components: &[ConvexPolytope], radius: f64) -> Vec<Plane> {
    let min_z = MAX_TILT_DEG.to_radians().cos();
    let mut faces: Vec<(DVec3, Vec<DVec3>, f64)> = Vec::new();
    for c in components {
        let v = c.vertices();
        for f in c.faces() {
            let n = f.plane.normal;
            if n.z < min_z {
                continue;
            }
            let poly: Vec<DVec3> = f.vertices.iter().map(|&i| v[i]).collect();
            let area = (0..poly.len()).map(|k| poly[k].cross(poly[(k + 1) % poly.len()])).sum::<DVec3>().length() / 2.0;
            faces.push((n, poly, area));
        }
    }
    faces.sort_by(|a, b| b.2.total_cmp(&a.2));
    let mut planes: Vec<(DVec3, f64, Vec<Vec<DVec3>>)> = Vec::new();
    for (n, poly, _) in faces {
        let joins = |(m, d, _): &(DVec3, f64, Vec<Vec<DVec3>>)| {
            n.angle_between(*m) <= PLANE_ANGLE && poly.iter().all(|p| (m.dot(*p) - *d).abs() <= PLANE_OFFSET)
        };
        match planes.iter().position(joins) {
            Some(k) => planes[k].2.push(poly),
            None => {
                let d = poly.iter().map(|p| n.dot(*p)).sum::<f64>() / poly.len() as f64;
                planes.push((n, d, vec![poly]));
            }
        }
    }
    planes
        .into_iter()
        .map(|(normal, offset, polys)| {
            let (u, w) = normal.any_orthonormal_pair();
            let flat = |p: DVec3| DVec2::new(u.dot(p), w.dot(p));
            let members: Vec<Vec<DVec2>> =
                polys.iter().map(|p| hull(p.iter().map(|&q| flat(q)).collect())).filter(|p| p.len() >= 3).collect();
            let obstacles: Vec<Vec<DVec2>> = components
                .iter()
                .map(|c| {
                    let v = c.vertices();
                    let level = offset + CLEAR;
                    let mut pts: Vec<DVec2> = v.iter().filter(|p| normal.dot(**p) > level).map(|&p| flat(p)).collect();
                    for e in c.edges() {
                        let (a, b) = (v[e.vertices[0]], v[e.vertices[1]]);
                        let (ha, hb) = (normal.dot(a) - level, normal.dot(b) - level);
                        if ha * hb < 0.0 {
                            pts.push(flat(a + (b - a) * (ha / (ha - hb))));
                        }
                    }
                    hull(pts)
                })
                .filter(|o| o.len() >= 3 && polygon_area(o) > 1e-9)
                .collect();
            let verdict = disc_verdict(&members, &obstacles, radius);
            Plane { normal, offset, verdict }
        })
        .collect()
}

/// Whether a disc of radius `rho` centred at `c` lies on the members and off the obstacles.
fn disc_fits(c: DVec2, rho: f64, members: &[Vec<DVec2>], obstacles: &[Vec<DVec2>]) -> bool {
    if obstacles.iter().any(|o| distance_to_polygon(c, o) < rho) {
        return false;
    }
    let covered = |p: DVec2| members.iter().any(|m| on_polygon(p, m));
    if !covered(c) {
        return false;
    }
    (1..=4).all(|ring| {
        let r = rho * ring as f64 / 4.0;
        let k = ((std::f64::consts::TAU * r / SAMPLE_SPACING).ceil() as usize).max(8);
        (0..k).all(|j| {
            let a = std::f64::consts::TAU * j as f64 / k as f64;
            covered(c + DVec2::new(a.cos(), a.sin()) * r)
        })
    })
}

fn disc_verdict(members: &[Vec<DVec2>], obstacles: &[Vec<DVec2>], radius: f64) -> Verdict {
    let spacing = std::f64::consts::SQRT_2 * MARGIN * radius;
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for p in members.iter().flatten() {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let (nx, ny) = (((hi.x - lo.x) / spacing).ceil() as usize, ((hi.y - lo.y) / spacing).ceil() as usize);
    let mut weak = false;
    for i in 0..=nx {
        for j in 0..=ny {
            let c = lo + DVec2::new(i as f64, j as f64) * spacing;
            if disc_fits(c, (1.0 - MARGIN) * radius, members, obstacles) {
                weak = true;
                if disc_fits(c, (1.0 + MARGIN) * radius, members, obstacles) {
                    return Verdict::Holds;
                }
            }
        }
    }
    if weak { Verdict::Undecided } else { Verdict::DoesNot }
}

/// The plane of an analysed face: unit normal (of its first polygon) and offset (at its disc's centre).
fn face_plane(f: &GraspFace) -> (DVec3, f64) {
    let p = &f.polygons[0];
    let n = (0..p.len()).map(|k| p[k].cross(p[(k + 1) % p.len()])).sum::<DVec3>().normalize();
    (n, n.dot(f.center))
}

fn same_plane(a: (DVec3, f64), b: (DVec3, f64), angle: f64, offset: f64) -> bool {
    a.0.angle_between(b.0) <= angle && (a.1 - b.1).abs() <= offset
}

/// One resting pose's grasp: its rotation, whether it is graspable and the planes of the faces that hold the cup.
struct PoseGrasp {
    rotation: glam::DMat3,
    graspable: bool,
    holding: Vec<(DVec3, f64)>,
}

/// Checks every resting pose of `file` against the reference and returns the poses' grasps.
fn check_against_reference(file: &str) -> Vec<PoseGrasp> {
    let part = part(file);
    let options = options();
    let radius = CUP_DIAMETER / 2.0;
    let mut out = Vec::new();
    for pose in resting_poses(&part).expect("resting poses") {
        let label = format!("{file} pose {} (c.g. at {:.1} mm)", pose.hull_face, pose.cg_height);
        let faces = grasp_faces(&part, pose.rotation, pose.position, &options);
        let components: Vec<ConvexPolytope> =
            part.components().iter().map(|c| c.transformed(pose.rotation, pose.position)).collect();
        let planes = reference_planes(&components, radius);
        let undecided: Vec<&Plane> = planes.iter().filter(|p| p.verdict == Verdict::Undecided).collect();
        assert!(undecided.is_empty(), "{label}: the reference leaves planes undecided: {undecided:?}");
        let holding: Vec<(DVec3, f64)> = faces.iter().filter(|f| f.fits_cup).map(face_plane).collect();
        for &h in &holding {
            let plane = planes.iter().find(|p| same_plane((p.normal, p.offset), h, 1e-3, 1e-2));
            assert!(
                plane.is_some_and(|p| p.verdict == Verdict::Holds),
                "{label}: the analysis holds the cup on the plane {h:?}, the reference on none there: {plane:?}"
            );
        }
        for p in planes.iter().filter(|p| p.verdict == Verdict::Holds) {
            assert!(
                holding.iter().any(|&h| same_plane((p.normal, p.offset), h, 1e-3, 1e-2)),
                "{label}: the reference holds the cup on {p:?}, the analysis does not: {faces:?}"
            );
        }
        let graspable = is_graspable(&faces, &options);
        assert_eq!(graspable, planes.iter().any(|p| p.verdict == Verdict::Holds), "{label}");
        out.push(PoseGrasp { rotation: pose.rotation, graspable, holding });
    }
    out
}

/// The STEP and STL twins: every pose of one whose rotation the other has too (within 2e-3: their hulls differ by
/// the bends' chords) is graspable in both or neither, by faces of the same planes. Poses that rest on a bend's
/// facets are not the same in the two (the chords of the STL and the arcs' hull points of the STEP are other
/// facets), so only the matched poses are compared, and each part has some.
fn check_twins(index: usize, step: &[PoseGrasp], stl: &[PoseGrasp]) {
    let mut matched = 0;
    for a in step {
        let Some(b) = stl.iter().find(|b| (a.rotation - b.rotation).to_cols_array().iter().all(|x| x.abs() <= 2e-3))
        else {
            continue;
        };
        matched += 1;
        assert_eq!(a.graspable, b.graspable, "bendfm_{index}: the twins' pose {:?}", a.rotation);
        for (x, y) in [(&a.holding, &b.holding), (&b.holding, &a.holding)] {
            for &h in x.iter() {
                assert!(
                    y.iter().any(|&k| same_plane(h, k, 2e-3, 0.1)),
                    "bendfm_{index}: a face {h:?} holds the cup in one twin only ({x:?} vs {y:?})"
                );
            }
        }
    }
    assert!(matched > step.len().min(stl.len()) / 2, "bendfm_{index}: {matched} poses matched");
}

fn check_part(index: usize) {
    let step = check_against_reference(&format!("bendfm_{index}.stp"));
    let stl = check_against_reference(&format!("bendfm_{index}.stl"));
    check_twins(index, &step, &stl);
}

#[test]
fn bendfm_0_grasps_as_the_reference_and_its_twin() {
    check_part(0);
}

#[test]
fn bendfm_1_grasps_as_the_reference_and_its_twin() {
    check_part(1);
}

#[test]
fn bendfm_2_grasps_as_the_reference_and_its_twin() {
    check_part(2);
}

#[test]
fn bendfm_3_grasps_as_the_reference_and_its_twin() {
    check_part(3);
}

#[test]
fn bendfm_4_grasps_as_the_reference_and_its_twin() {
    check_part(4);
}

#[test]
fn bendfm_5_grasps_as_the_reference_and_its_twin() {
    check_part(5);
}
