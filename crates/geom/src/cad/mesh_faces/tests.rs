//! Unit tests of the planar regions, bends and loops recognised in a triangle mesh.
use super::*;
use crate::io::ReadOptions;
use crate::io::mesh::{Precision, Welder, mesh_tolerance};
use std::f64::consts::FRAC_PI_2;
use std::path::Path;

/// One step of a sheet's cross-section, walking along its side A.
#[derive(Debug, Clone, Copy)]
enum Step {
    /// Straight ahead, split into `pieces` collinear pieces.
    Straight { length: f64, pieces: usize },
    /// A bend turning by `angle` (positive: to the left, side A inside) of inner radius `radius`, in `facets`
    /// facets.
    Bend { angle: f64, radius: f64, facets: usize },
}

/// The closed mesh of a sheet of thickness `t` whose cross-section (in the xy-plane, side B to the right of side
/// A) follows `steps`, extruded along z by `length`; triangles counter-clockwise seen from outside.
fn bent_sheet(t: f64, steps: &[Step], length: f64) -> (Vec<DVec3>, Vec<MeshPolygon>) {
    let (mut p, mut dir) = (DVec2::ZERO, DVec2::X);
    let right = |dir: DVec2| DVec2::new(dir.y, -dir.x);
    let mut pairs = vec![(p, p + t * right(dir))];
    for &step in steps {
        match step {
            Step::Straight { length, pieces } => {
                for i in 1..=pieces {
                    let q = p + dir * length * i as f64 / pieces as f64;
                    pairs.push((q, q + t * right(dir)));
                }
                p += dir * length;
            }
            Step::Bend { angle, radius, facets } => {
                let centre = if angle > 0.0 { p - radius * right(dir) } else { p + (t + radius) * right(dir) };
                let (a0, b0) = (p - centre, p + t * right(dir) - centre);
                for i in 1..=facets {
                    let rot = DVec2::from_angle(angle * i as f64 / facets as f64);
                    pairs.push((centre + rot.rotate(a0), centre + rot.rotate(b0)));
                }
                let rot = DVec2::from_angle(angle);
                p = centre + rot.rotate(a0);
                dir = rot.rotate(dir);
            }
        }
    }
    // the cross-section loop, counter-clockwise: side B forwards, side A backwards
    let mut section: Vec<DVec2> = pairs.iter().map(|&(_, b)| b).collect();
    section.extend(pairs.iter().rev().map(|&(a, _)| a));
    let m = pairs.len();
    let n = section.len();
    let mut points = Vec::new();
    for z in [0.0, length] {
        points.extend(section.iter().map(|q| DVec3::new(q.x, q.y, z)));
    }
    let b = |i: usize| i; // index of side B's point i in the section
    let a = |i: usize| n - 1 - i;
    let mut tris: Vec<[usize; 3]> = Vec::new();
    for i in 0..m - 1 {
        let quad = [b(i), b(i + 1), a(i + 1), a(i)];
        tris.push([n + quad[0], n + quad[1], n + quad[2]]);
        tris.push([n + quad[0], n + quad[2], n + quad[3]]);
        tris.push([quad[0], quad[2], quad[1]]);
        tris.push([quad[0], quad[3], quad[2]]);
    }
    for i in 0..n {
        let j = (i + 1) % n;
        tris.push([i, j, n + j]);
        tris.push([i, n + j, n + i]);
    }
    (points, polygons(&tris))
}

fn polygons(tris: &[[usize; 3]]) -> Vec<MeshPolygon> {
    tris.iter()
        .enumerate()
        .map(|(t, v)| MeshPolygon { vertices: v.to_vec(), place: Place::Byte(84 + 50 * t as u64) })
        .collect()
}

fn cylinders(brep: &Brep) -> Vec<(DVec3, DVec3, f64, bool)> {
    brep.faces
        .iter()
        .filter_map(|f| match f.surface {
            Surface::Cylinder { point, axis, radius, convex } => Some((point, axis, radius, convex)),
            Surface::Plane { .. } => None,
        })
        .collect()
}

fn coaxial(p: DVec3, a: DVec3, q: DVec3, b: DVec3, distance: f64) -> bool {
    a.cross(b).length() <= 1e-6 && (q - p).cross(a).length() <= distance
}

/// Every loop closes; a planar face's outer loop is counter-clockwise about its normal, its holes clockwise, and
/// its points within `off` of its plane.
fn check_loops(brep: &Brep, off: f64) {
    for face in &brep.faces {
        assert!(!face.loops.is_empty(), "{} has no loop", face.source);
        for lp in &face.loops {
            assert!(lp.len() >= 3);
            for (i, s) in lp.iter().enumerate() {
                assert_eq!(s.end(), lp[(i + 1) % lp.len()].start());
            }
        }
        if let Surface::Plane { point, normal } = face.surface {
            let pts: Vec<Vec<DVec3>> = face.loops.iter().map(|l| l.iter().map(Segment::start).collect()).collect();
            assert!(signed_area(&pts[0], normal) > 0.0, "{}: outer loop clockwise", face.source);
            for hole in &pts[1..] {
                assert!(signed_area(hole, normal) < 0.0, "{}: hole counter-clockwise", face.source);
            }
            for p in pts.iter().flatten() {
                assert!((*p - point).dot(normal).abs() < off, "{}: loop off the plane", face.source);
            }
        }
    }
}

fn check_bend(brep: &Brep, inner: f64, outer: f64) {
    let cyl = cylinders(brep);
    let i = cyl.iter().find(|c| (c.2 - inner).abs() < 1e-9).expect("inner cylinder");
    let o = cyl.iter().find(|c| (c.2 - outer).abs() < 1e-9).expect("outer cylinder");
    assert!(!i.3 && o.3, "convex flags: inner {}, outer {}", i.3, o.3);
    assert!(coaxial(i.0, i.1, o.0, o.1, 1e-9), "not coaxial: {i:?} {o:?}");
    assert!((i.1.z).abs() > 1.0 - 1e-12, "axis {}", i.1);
}

#[test]
fn l_profile_gives_two_coaxial_cylinders() {
    let (r, t) = (2.5, 1.5);
    for facets in [3, 4, 16] {
        let steps = [
            Step::Straight { length: 40.0, pieces: 2 },
            Step::Bend { angle: FRAC_PI_2, radius: r, facets },
            Step::Straight { length: 30.0, pieces: 1 },
        ];
        let (points, tris) = bent_sheet(t, &steps, 50.0);
        let brep = mesh_faces(&points, &tris, 1e-9).expect("segments");
        let cyl = cylinders(&brep);
        assert_eq!(cyl.len(), 2, "{facets} facets: {cyl:?}");
        check_bend(&brep, r, r + t);
        // two caps, four skins, two end walls
        assert_eq!(brep.faces.len() - cyl.len(), 8, "{facets} facets");
        check_loops(&brep, 1e-9);
        // the caps: one outer loop each, straight pieces merged
        let caps = brep
            .faces
            .iter()
            .filter(|f| matches!(f.surface, Surface::Plane { normal, .. } if normal.z.abs() > 0.5))
            .collect::<Vec<_>>();
        assert_eq!(caps.len(), 2);
        for cap in caps {
            assert_eq!(cap.loops.len(), 1);
            assert_eq!(cap.loops[0].len(), 6 + 2 * facets, "{facets} facets");
        }
        // the volume of the section times the length (the bend's area is that of its chords)
        let half = std::f64::consts::FRAC_PI_4 / facets as f64;
        let chords = facets as f64 * ((r + t).powi(2) - r * r) * half.sin() * half.cos();
        let expected = 50.0 * ((40.0 + 30.0) * t + chords);
        let volume = brep.volume.expect("volume");
        assert!((volume - expected).abs() < 1e-9 * expected, "{volume} vs {expected}");
        assert!(
            matches!(brep.faces[0].source, FaceSource::Mesh { region: 0, ref first_triangle } if first_triangle == "byte 84")
        );
    }
}

/// The mesh with the edge `a`-`b` split at its midpoint, each of its two triangles into two.
fn split_edge(points: &mut Vec<DVec3>, tris: &[MeshPolygon], a: usize, b: usize) -> Vec<MeshPolygon> {
    let m = points.len();
    points.push(0.5 * (points[a] + points[b]));
    let mut out: Vec<[usize; 3]> = Vec::new();
    for t in tris {
        let v = [t.vertices[0], t.vertices[1], t.vertices[2]];
        match (0..3).find(|&k| [v[k], v[(k + 1) % 3]] == [a, b] || [v[k], v[(k + 1) % 3]] == [b, a]) {
            Some(k) => {
                let (x, y, z) = (v[k], v[(k + 1) % 3], v[(k + 2) % 3]);
                out.push([x, m, z]);
                out.push([m, y, z]);
            }
            None => out.push(v),
        }
    }
    polygons(&out)
}

#[test]
fn a_vertex_on_a_chord_is_part_of_the_cylinder() {
    let (r, t) = (2.5, 1.5);
    let steps = [
        Step::Straight { length: 40.0, pieces: 2 },
        Step::Bend { angle: FRAC_PI_2, radius: r, facets: 8 },
        Step::Straight { length: 30.0, pieces: 1 },
    ];
    let (mut points, tris) = bent_sheet(t, &steps, 50.0);
    // section points 3 and 4 bound the second facet of the outer surface, at z = 0
    let tris = split_edge(&mut points, &tris, 3, 4);
    let brep = mesh_faces(&points, &tris, 1e-9).expect("segments");
    assert_eq!(cylinders(&brep).len(), 2);
    check_bend(&brep, r, r + t);
    check_loops(&brep, 1e-9);
}

#[test]
fn shallow_bends_of_one_and_two_facets() {
    let (r, t) = (4.0, 1.0);
    for facets in [1, 2] {
        let steps = [
            Step::Straight { length: 12.0, pieces: 1 },
            Step::Bend { angle: 0.3, radius: r, facets },
            Step::Straight { length: 9.0, pieces: 1 },
        ];
        let (points, tris) = bent_sheet(t, &steps, 20.0);
        let brep = mesh_faces(&points, &tris, 1e-9).expect("segments");
        assert_eq!(cylinders(&brep).len(), 2, "{facets} facets");
        check_bend(&brep, r, r + t);
        check_loops(&brep, 1e-9);
    }
}

#[test]
fn u_channel_shares_its_base_between_two_bends() {
    let (r, t) = (3.0, 2.0);
    let steps = [
        Step::Straight { length: 20.0, pieces: 1 },
        Step::Bend { angle: FRAC_PI_2, radius: r, facets: 6 },
        Step::Straight { length: 35.0, pieces: 3 },
        Step::Bend { angle: FRAC_PI_2, radius: r, facets: 6 },
        Step::Straight { length: 25.0, pieces: 1 },
    ];
    let (points, tris) = bent_sheet(t, &steps, 80.0);
    let brep = mesh_faces(&points, &tris, 1e-9).expect("segments");
    let cyl = cylinders(&brep);
    assert_eq!(cyl.len(), 4, "{cyl:?}");
    let inner: Vec<_> = cyl.iter().filter(|c| !c.3).collect();
    let outer: Vec<_> = cyl.iter().filter(|c| c.3).collect();
    assert_eq!((inner.len(), outer.len()), (2, 2));
    for i in &inner {
        assert!((i.2 - r).abs() < 1e-9);
        let o = outer.iter().find(|o| coaxial(i.0, i.1, o.0, o.1, 1e-9)).expect("coaxial outer");
        assert!((o.2 - r - t).abs() < 1e-9);
    }
    // caps, three plates' two skins, two end walls
    assert_eq!(brep.faces.len() - 4, 2 + 6 + 2);
    check_loops(&brep, 1e-9);
}

#[test]
fn bends_both_ways_and_obtuse() {
    let (r, t) = (1.0, 3.0);
    let steps = [
        Step::Straight { length: 10.0, pieces: 1 },
        Step::Bend { angle: -2.0, radius: r, facets: 10 },
        Step::Straight { length: 15.0, pieces: 1 },
        Step::Bend { angle: 0.5, radius: 5.0 * r, facets: 3 },
        Step::Straight { length: 5.0, pieces: 1 },
    ];
    let (points, tris) = bent_sheet(t, &steps, 10.0);
    let brep = mesh_faces(&points, &tris, 1e-9).expect("segments");
    let mut radii: Vec<(f64, bool)> = cylinders(&brep).iter().map(|c| (c.2, c.3)).collect();
    radii.sort_by(|x, y| x.0.total_cmp(&y.0));
    let expected = [(r, false), (r + t, true), (5.0 * r, false), (5.0 * r + t, true)];
    assert_eq!(radii.len(), 4, "{radii:?}");
    for (got, want) in radii.iter().zip(expected) {
        assert!((got.0 - want.0).abs() < 1e-9 && got.1 == want.1, "{radii:?}");
    }
    check_loops(&brep, 1e-9);
}

/// A regular `n`-gon plate of circumradius 30 with a regular `n`-gon hole of circumradius 10, thickness 2.
fn plate_with_hole(n: usize) -> (Vec<DVec3>, Vec<MeshPolygon>) {
    let ring = |radius: f64, z: f64| -> Vec<DVec3> {
        (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                DVec3::new(radius * a.cos(), radius * a.sin(), z)
            })
            .collect()
    };
    let mut points = ring(30.0, 0.0); // outer bottom: 0..n
    points.extend(ring(30.0, 2.0)); // outer top: n..2n
    points.extend(ring(10.0, 0.0)); // inner bottom: 2n..3n
    points.extend(ring(10.0, 2.0)); // inner top: 3n..4n
    let mut tris = Vec::new();
    for i in 0..n {
        let j = (i + 1) % n;
        let (ob, ot, ib, it) = (0, n, 2 * n, 3 * n);
        // top ring (normal +z): outer i, outer j, inner j, inner i counter-clockwise
        tris.push([ot + i, ot + j, it + j]);
        tris.push([ot + i, it + j, it + i]);
        // bottom ring (normal -z)
        tris.push([ob + i, ib + j, ob + j]);
        tris.push([ob + i, ib + i, ib + j]);
        // outer wall (normal outwards)
        tris.push([ob + i, ob + j, ot + j]);
        tris.push([ob + i, ot + j, ot + i]);
        // hole wall (normal towards the axis)
        tris.push([ib + i, it + j, ib + j]);
        tris.push([ib + i, it + i, it + j]);
    }
    (points, polygons(&tris))
}

#[test]
fn a_hole_is_a_clockwise_loop_of_its_skin() {
    for n in [6, 12, 40] {
        let (points, tris) = plate_with_hole(n);
        let brep = mesh_faces(&points, &tris, 1e-9).expect("segments");
        assert!(cylinders(&brep).is_empty(), "{n}-gon: closed chains of facets are not bends");
        assert_eq!(brep.faces.len(), 2 + 2 * n);
        check_loops(&brep, 1e-9);
        for skin in
            brep.faces.iter().filter(|f| matches!(f.surface, Surface::Plane { normal, .. } if normal.z.abs() > 0.5))
        {
            assert_eq!(skin.loops.len(), 2);
            assert_eq!(skin.loops[0].len(), n);
            assert_eq!(skin.loops[1].len(), n);
            let Surface::Plane { normal, .. } = skin.surface else { unreachable!() };
            let hole: Vec<DVec3> = skin.loops[1].iter().map(Segment::start).collect();
            assert!(signed_area(&hole, normal) < 0.0);
            assert!(hole.iter().all(|p| (p.truncate().length() - 10.0).abs() < 1e-9));
        }
        let area = |r: f64| 0.5 * n as f64 * r * r * (std::f64::consts::TAU / n as f64).sin();
        let expected = 2.0 * (area(30.0) - area(10.0));
        let volume = brep.volume.expect("volume");
        assert!((volume - expected).abs() < 1e-9 * expected);
    }
}

#[test]
fn open_and_bad_meshes_are_reported() {
    let (points, mut tris) = plate_with_hole(8);
    let removed = tris.remove(5);
    let err = mesh_faces(&points, &tris, 1e-9).expect_err("open");
    assert!(matches!(err, MeshFaceError::Open { .. }), "{err}");
    assert!(err.to_string().starts_with("open mesh: the triangle at byte "), "{err}");
    let mut doubled = tris.clone();
    doubled.push(tris[0].clone());
    doubled.push(removed);
    assert!(matches!(mesh_faces(&points, &doubled, 1e-9), Err(MeshFaceError::NonManifold { .. })));
    assert_eq!(mesh_faces(&points, &[], 1e-9), Err(MeshFaceError::Empty));
    let bad = |vertices: Vec<usize>| vec![MeshPolygon { vertices, place: Place::Line(7) }];
    assert!(matches!(mesh_faces(&points, &bad(vec![0, 1]), 1e-9), Err(MeshFaceError::NotTriangle { .. })));
    assert!(matches!(mesh_faces(&points, &bad(vec![0, 1, 999]), 1e-9), Err(MeshFaceError::BadIndex { .. })));
    assert!(matches!(mesh_faces(&points, &bad(vec![0, 1, 1]), 1e-9), Err(MeshFaceError::RepeatedVertex { .. })));
    let nan = [DVec3::NAN, DVec3::X, DVec3::Y];
    assert!(matches!(mesh_faces(&nan, &bad(vec![0, 1, 2]), 1e-9), Err(MeshFaceError::NotFinite { .. })));
    // a flat closed mesh: two triangles back to back
    let flat = polygons(&[[0, 1, 2], [0, 2, 1]]);
    assert!(mesh_faces(&[DVec3::ZERO, DVec3::X, DVec3::Y], &flat, 1e-9).is_ok());
}

/// A real part read as the STL reader reads it: welded points, triangles and the mesh tolerance.
fn read_real(n: usize) -> Option<(Vec<DVec3>, Vec<MeshPolygon>, f64)> {
    let path = format!(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/realparts/bendfm_{}.stl"), n);
    let path = Path::new(&path);
    // the parts are not in the repository's fixtures yet: skip where they are absent
    let bytes = std::fs::read(path).ok()?;
    let mut welder = Welder::default();
    let tris = crate::io::stl::parse_binary(&bytes, path, &mut welder).expect("binary STL");
    let tolerance =
        mesh_tolerance(path, &welder.points, Precision::Single, &ReadOptions::default()).expect("tolerance");
    Some((welder.points, tris, tolerance))
}

fn labels(n: usize, what: &str) -> Option<serde_json::Value> {
    let path = format!(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/realparts/bendfm_{}_{}.json"), n, what);
    serde_json::from_str(&std::fs::read_to_string(path).ok()?).ok()
}

#[test]
fn real_parts_bends_and_volume() {
    for n in 0..6 {
        let (Some((points, tris, tolerance)), Some(labels), Some(sequence)) =
            (read_real(n), labels(n, "labels"), labels(n, "sequence"))
        else {
            continue;
        };
        let brep = mesh_faces(&points, &tris, tolerance).expect("segments");
        check_loops(&brep, 10.0 * tolerance);
        let thickness = labels["sheet_thickness"].as_f64().expect("thickness");
        let bends = labels["total_bends"].as_u64().expect("bends") as usize;
        let cyl = cylinders(&brep);
        let mut used = vec![false; cyl.len()];
        let mut inner_radii = Vec::new();
        for i in cyl.iter().filter(|c| !c.3) {
            if let Some(o) = cyl.iter().enumerate().find(|(k, o)| {
                o.3 && !used[*k] && coaxial(i.0, i.1, o.0, o.1, 1e-3) && (o.2 - i.2 - thickness).abs() < 1e-3
            }) {
                used[o.0] = true;
                inner_radii.push(i.2);
            }
        }
        assert_eq!(inner_radii.len(), bends, "bendfm_{n}: bend pairs {inner_radii:?} of cylinders {cyl:?}");
        for bend in sequence.as_array().expect("sequence").iter().skip(1) {
            let radius = bend["bend_radius"].as_f64().expect("radius");
            let k = inner_radii.iter().position(|r| (r - radius).abs() < 0.02);
            let k = k.unwrap_or_else(|| panic!("bendfm_{n}: radius {radius} not among {inner_radii:?}"));
            inner_radii.remove(k);
        }
        // every fitted radius is that of a cylinder of the STEP twin, one to one
        let mut fitted: Vec<f64> = cyl.iter().map(|c| c.2).collect();
        let mut exact = step_radii(n);
        fitted.sort_by(f64::total_cmp);
        exact.sort_by(f64::total_cmp);
        assert_eq!(fitted.len(), exact.len(), "bendfm_{n}: {fitted:?} vs {exact:?}");
        for (f, e) in fitted.iter().zip(&exact) {
            assert!((f - e).abs() < 1e-4, "bendfm_{n}: fitted {f} vs STEP {e}");
        }
        let expected = labels["part_volume_3d"].as_f64().expect("volume") * 1000.0;
        let volume = brep.volume.expect("volume");
        assert!((volume - expected).abs() < 2e-4 * expected, "bendfm_{n}: volume {volume} vs {expected}");
    }
}

/// The radii of the `CYLINDRICAL_SURFACE`s of a real part's STEP twin.
fn step_radii(n: usize) -> Vec<f64> {
    let path = format!(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/realparts/bendfm_{}.stp"), n);
    let text = std::fs::read_to_string(path).expect("STEP twin");
    text.split("CYLINDRICAL_SURFACE(")
        .skip(1)
        .map(|rest| {
            let args = &rest[..rest.find(')').expect("closing parenthesis")];
            args.rsplit(',').next().expect("radius").trim().parse().expect("a number")
        })
        .collect()
}
