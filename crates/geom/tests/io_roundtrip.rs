//! Round trips through every format, GLB parse-back, stack files and atomic writes.

use proptest::prelude::*;
use stackplan_geom::io::glb::{GlbItem, glb_bytes};
use stackplan_geom::io::stack::{PlacedPart, read_stack, write_stack, write_stack_with_extras};
use stackplan_geom::io::{self, IoError, ReadOptions, atomic};
use stackplan_geom::{
    ConvexPolytope, DMat3, DVec3, Part, PartOrigin, Pose, convex_hull, convex_hull_merged, convex_hull_merged_within,
};
use std::path::Path;

const BRACKET: &str = r#"{
  "name": "bracket",
  "density": 7.85e-6,
  "sheet_metal": {
    "thickness": 1,
    "faces": [
      {"outline": [[0, 0, 0], [40, 0, 0], [40, 20, 0], [0, 20, 0]], "holes": [[[10, 5, 0], [14, 5, 0], [14, 9, 0], [10, 9, 0]]]},
      {"outline": [[0, 0, 4], [0, 20, 4], [0, 20, 30], [0, 10, 38], [0, 0, 30]]}
    ]
  }
}"#;

fn bracket() -> Part {
    io::parse_part_json(BRACKET.as_bytes(), Path::new("bracket.json"), &ReadOptions::default()).expect("bracket")
}

/// A component as its sorted vertex coordinates (bit patterns), which determine a convex polytope.
fn key(c: &ConvexPolytope) -> Vec<[u64; 3]> {
    let mut k: Vec<[u64; 3]> = c.vertices().iter().map(|v| (*v + DVec3::ZERO).to_array().map(f64::to_bits)).collect();
    k.sort_unstable();
    k
}

fn same_components(a: &Part, b: &Part) {
    let mut ka: Vec<_> = a.components().iter().map(key).collect();
    let mut kb: Vec<_> = b.components().iter().map(key).collect();
    ka.sort();
    kb.sort();
    assert_eq!(ka, kb, "components differ");
    for (x, y) in a.components().iter().zip(b.components()) {
        assert_eq!(x.faces().len(), y.faces().len());
    }
    let (va, vb) = (a.mass().volume, b.mass().volume);
    assert!((va - vb).abs() <= 1e-12 * va, "volume {va} vs {vb}");
    assert!((a.mass().center_of_gravity - b.mass().center_of_gravity).length() <= 1e-9);
}

/// The single-precision tolerance of the STL reader for `part`'s coordinates: 16 roundings to `f32` of the largest.
fn single_tolerance(part: &Part) -> f64 {
    8.0 * f64::from(f32::EPSILON) * part.all_vertices().map(|v| v.abs().max_element()).fold(0.0, f64::max)
}

/// Components read from single precision against the expected ones (each: its vertices rounded to `f32` and its face
/// count): the same number, matched one to one with the same face and vertex counts and every vertex within `tol`
/// (the reader moves the corners of faces planar only to single precision onto their planes, by at most `4 t`); and
/// every vertex of what was read lies on the planes of its faces within `1e-12` of the part's largest coordinate.
fn same_within(expected: &[(usize, Vec<DVec3>)], got: &Part, tol: f64, what: &str) {
    assert_eq!(got.components().len(), expected.len(), "{what}: components");
    let mut used = vec![false; expected.len()];
    // the flattening's own scale: the part's largest coordinate
    let scale = got.all_vertices().map(|v| v.abs().max_element()).fold(1.0, f64::max);
    for c in got.components() {
        let found = expected.iter().enumerate().position(|(k, (faces, vertices))| {
            !used[k]
                && *faces == c.faces().len()
                && vertices.len() == c.vertices().len()
                && vertices.iter().all(|p| c.vertices().iter().any(|q| (*p - *q).abs().max_element() <= tol))
        });
        let k = found.unwrap_or_else(|| panic!("{what}: a component read matches none expected"));
        used[k] = true;
        for f in c.faces() {
            for &v in f.vertices.iter() {
                let off = f.plane.signed_distance(c.vertices()[v]).abs();
                assert!(off <= 1e-12 * scale, "{what}: a corner {off:e} off its face's plane");
            }
        }
    }
}

#[test]
fn sheet_metal_json_builds_and_round_trips() {
    let part = bracket();
    assert_eq!(part.name, "bracket");
    assert_eq!(part.density(), 7.85e-6);
    assert!(part.components().len() >= 3, "a face with a hole needs several convex pieces");
    // volume: (40 x 20 - 4 x 4) x 1 + (pentagon area) x 1
    let pentagon = 20.0 * 26.0 + 0.5 * 20.0 * 8.0;
    let expected = 800.0 - 16.0 + pentagon;
    assert!((part.mass().volume - expected).abs() < 1e-9 * expected, "{} vs {expected}", part.mass().volume);
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("b.json");
    io::write_part_json(&path, &part).expect("write");
    let back = io::read_part(&path, &ReadOptions::default()).expect("read back");
    assert_eq!(back.origin, PartOrigin::ConvexPieces);
    assert_eq!(back.name, "bracket");
    assert_eq!(back.density(), part.density());
    same_components(&part, &back);
    // the options' density wins over the file's
    let heavy = io::read_part(&path, &ReadOptions { density: Some(2.0), ..Default::default() }).expect("read");
    assert_eq!(heavy.density(), 2.0);
}

#[test]
fn triangulation_option_reaches_the_sheet_metal_builder() {
    let merged = bracket();
    let options = ReadOptions { decomposition: stackplan_geom::Decomposition::Triangulation, ..Default::default() };
    let triangulated = io::parse_part_json(BRACKET.as_bytes(), Path::new("b.json"), &options).expect("bracket");
    assert!(triangulated.components().len() > merged.components().len());
    assert!((triangulated.mass().volume - merged.mass().volume).abs() < 1e-9 * merged.mass().volume);
}

#[test]
fn obj_round_trip_is_exact() {
    let part = bracket();
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("bracket.obj");
    io::write_obj(&path, &part).expect("write");
    let back = io::read_part(&path, &ReadOptions::default()).expect("read");
    assert_eq!(back.origin, PartOrigin::Mesh);
    same_components(&part, &back);
}

/// A component as the readers rebuild it: the hull of its vertices with its rounding creases merged
/// ([`convex_hull_merged`]).
fn read_form(part: &Part) -> Part {
    let components =
        part.components().iter().map(|c| convex_hull_merged(c.vertices()).expect("hull").polytope).collect();
    Part::from_components(part.name.clone(), components, part.density(), PartOrigin::ConvexPieces).expect("part")
}

/// The number of faces of `part`'s components, and of the exact hulls of their vertices.
fn face_counts(part: &Part) -> (usize, usize) {
    let own = part.components().iter().map(|c| c.faces().len()).sum();
    let exact = part.components().iter().map(|c| convex_hull(c.vertices()).expect("hull").polytope.faces().len()).sum();
    (own, exact)
}

/// Every built-in example, in both decompositions, written in every format reads back: the same vertices per
/// component (binary STL: rounded to `f32`) and the faces of their hull, rounding creases merged. The sheet-metal
/// examples are rotated into place, so some of their faces are coplanar only to rounding (Triangle's quadrilaterals
/// are 5e-11 out of plane): written with the components' own faces their OBJ and STL files fail the reader's exact
/// convexity check ("the polygon at line 11 does not lie in a face plane of the shell's convex hull"), and without the
/// merge of rounding creases they read back split into their exact facets; each reads back as the one face it was
/// built as.
#[test]
fn every_example_reads_back_from_every_format() {
    let opts = ReadOptions::default();
    let single = |part: &Part| {
        let components = part
            .components()
            .iter()
            .map(|c| {
                let rounded: Vec<DVec3> = c.vertices().iter().map(|v| v.as_vec3().as_dvec3()).collect();
                // the binary STL reader's tolerance: 16 roundings to f32 of the largest coordinate
                let largest = part.all_vertices().map(|v| v.abs().max_element()).fold(0.0, f64::max);
                convex_hull_merged_within(&rounded, 8.0 * f64::from(f32::EPSILON) * largest).expect("hull").polytope
            })
            .collect();
        Part::from_components(part.name.clone(), components, part.density(), PartOrigin::ConvexPieces).expect("part")
    };
    let mut split_faces = 0;
    for name in stackplan_geom::examples::NAMES {
        for decomposition in [stackplan_geom::Decomposition::default(), stackplan_geom::Decomposition::Triangulation] {
            let part = stackplan_geom::examples::part_by_name(name, decomposition).expect("example");
            let exact = read_form(&part);
            let (own, exact_facets) = face_counts(&part);
            split_faces += exact_facets - own;
            // merging the creases gives back the faces the part was built with
            assert_eq!(exact.components().iter().map(|c| c.faces().len()).sum::<usize>(), own, "{name}");
            let json = io::parse_part_json(io::part_json_string(&part).as_bytes(), Path::new("e.json"), &opts);
            same_components(&exact, &json.unwrap_or_else(|e| panic!("{name}: json: {e}")));
            let obj = io::parse_obj(io::obj_string(&part).as_bytes(), Path::new("e.obj"), &opts);
            same_components(&exact, &obj.unwrap_or_else(|e| panic!("{name}: obj: {e}")));
            let ascii = io::parse_stl(io::stl_ascii_string(&part).as_bytes(), Path::new("e.stl"), &opts);
            same_components(&exact, &ascii.unwrap_or_else(|e| panic!("{name}: ascii stl: {e}")));
            let binary = io::parse_stl(&io::stl_binary_bytes(&part), Path::new("e.stl"), &opts)
                .unwrap_or_else(|e| panic!("{name}: binary stl: {e}"));
            let expected: Vec<(usize, Vec<DVec3>)> =
                single(&part).components().iter().map(|c| (c.faces().len(), c.vertices().to_vec())).collect();
            same_within(&expected, &binary, 4.0 * single_tolerance(&part), &format!("{name}: binary stl"));
            // a stack export for viewers reads back too: one convex piece per component, in world coordinates
            let pose = Pose {
                rotation: DMat3::from_rotation_z(0.3) * DMat3::from_rotation_x(0.2),
                position: DVec3::new(1.5, -2.0, 3.0),
            };
            let scene = io::obj_scene_string(&[(&part, pose), (&part, Pose::IDENTITY)]);
            let back = io::parse_obj(scene.as_bytes(), Path::new("s.obj"), &opts)
                .unwrap_or_else(|e| panic!("{name}: scene obj: {e}"));
            assert_eq!(back.components().len(), 2 * part.components().len());
        }
    }
    // the test has teeth: some example faces are coplanar only to rounding, and their exact hulls split them
    assert!(split_faces > 0);
}

#[test]
fn stl_round_trips_separate_touching_components() {
    // the bracket's prisms touch face to face: the shell splitter must still separate them
    let part = bracket();
    let dir = tempfile::tempdir().expect("tempdir");
    for ascii in [true, false] {
        let path = dir.path().join(if ascii { "a.stl" } else { "b.stl" });
        if ascii {
            io::write_stl_ascii(&path, &part).expect("write");
        } else {
            io::write_stl_binary(&path, &part).expect("write");
        }
        let back = io::read_part(&path, &ReadOptions::default()).expect("read");
        assert_eq!(back.components().len(), part.components().len(), "ascii = {ascii}");
        same_components(&part, &back); // coordinates are dyadic, so even f32 is exact
    }
}

/// A part as a file exported in another orientation would hold it: every component's vertices turned by a general
/// rotation (rounded), each piece the hull of its points with its rounding creases merged.
fn turned(part: &Part, rotation: DMat3) -> Part {
    let offset = DVec3::new(123.25, -45.5, 7.0);
    let components = part
        .components()
        .iter()
        .map(|c| {
            let points: Vec<DVec3> = c.vertices().iter().map(|&v| rotation * v + offset).collect();
            convex_hull_merged(&points).expect("hull").polytope
        })
        .collect();
    Part::from_components(part.name.clone(), components, part.density(), PartOrigin::ConvexPieces).expect("part")
}

/// Components touching along a face that is planar only to rounding: each component's exact hull splits the face
/// along another diagonal (the fold seen from the other side), so the STL holds the shared face twice, triangulated
/// differently. The shell splitter must still separate the components (the other component's triangle is on the
/// same half-plane within the length tolerance), and each shell passes the convexity check. Linked by the exact test
/// alone, two touching components become one shell and 48 of 114 turned parts fail to read back from STL ("the
/// polygon at byte 84 does not lie in a face plane of the shell's convex hull"), the built-in Triangle, Complex and
/// L-corner among them.
#[test]
fn turned_parts_with_touching_components_round_trip_through_stl() {
    let cube = |o: DVec3| {
        let pts: Vec<DVec3> =
            (0..8).map(|i| o + DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64)).collect();
        convex_hull(&pts).expect("cube").polytope
    };
    let two_cubes =
        Part::from_components("two", vec![cube(DVec3::ZERO), cube(DVec3::X)], 1.0, PartOrigin::ConvexPieces)
            .expect("part");
    let mut parts = vec![two_cubes, bracket()];
    for name in ["triangle", "complex", "l-corner", "channel"] {
        parts.push(stackplan_geom::examples::part_by_name(name, Default::default()).expect("example"));
    }
    let opts = ReadOptions::default();
    let mut split_shared_faces = 0;
    for (k, part) in parts.iter().enumerate() {
        for (i, angles) in [(0.3, 0.7, 1.1), (2.1, -0.4, 0.9), (-1.3, 0.25, 2.6)].into_iter().enumerate() {
            let rotation = DMat3::from_euler(glam::EulerRot::ZYX, angles.0, angles.1, angles.2);
            let turned = turned(part, rotation);
            let (own, exact) = face_counts(&turned);
            split_shared_faces += exact - own;
            let text = io::stl_ascii_string(&turned);
            let back = io::parse_stl(text.as_bytes(), Path::new("turned.stl"), &opts)
                .unwrap_or_else(|e| panic!("{} turned {i}: {e}", part.name));
            same_components(&turned, &back);
            assert_eq!(back.components().len(), part.components().len(), "part {k}");
        }
    }
    assert!(split_shared_faces > 0, "the test has teeth: some turned faces are split by their exact hulls");
}

/// The same turned parts through binary STL, whose coordinates are `f32`: each component comes back with its faces
/// (the folds that rounding to `f32` puts into a turned face, about 1e-7 of the coordinates, are within the STL
/// reader's single-precision tolerance and merged), its vertices rounded, and the touching components apart.
#[test]
fn turned_parts_read_back_from_binary_stl_with_their_faces() {
    let opts = ReadOptions::default();
    let mut parts = vec![bracket()];
    for name in ["triangle", "complex", "l-corner", "channel", "cube"] {
        parts.push(stackplan_geom::examples::part_by_name(name, Default::default()).expect("example"));
    }
    let mut split_by_rounding = 0;
    for part in &parts {
        for (i, angles) in
            [(0.3, 0.7, 1.1), (2.1, -0.4, 0.9), (-1.3, 0.25, 2.6), (0.05, 3.0, -0.7)].into_iter().enumerate()
        {
            let turned = turned(part, DMat3::from_euler(glam::EulerRot::ZYX, angles.0, angles.1, angles.2));
            let back = io::parse_stl(&io::stl_binary_bytes(&turned), Path::new("turned.stl"), &opts)
                .unwrap_or_else(|e| panic!("{} turned {i}: {e}", part.name));
            let expected: Vec<(usize, Vec<DVec3>)> = turned
                .components()
                .iter()
                .map(|c| {
                    let rounded: Vec<DVec3> = c.vertices().iter().map(|v| v.as_vec3().as_dvec3()).collect();
                    split_by_rounding += convex_hull(&rounded).expect("hull").polytope.faces().len() - c.faces().len();
                    (c.faces().len(), rounded)
                })
                .collect();
            let what = format!("{} turned {i}", part.name);
            same_within(&expected, &back, 4.0 * single_tolerance(&turned), &what);
            let (v0, v1) = (turned.mass().volume, back.mass().volume);
            assert!((v0 - v1).abs() <= 1e-5 * v0, "{} turned {i}: volume {v0} vs {v1}", part.name);
        }
    }
    assert!(split_by_rounding > 0, "the test has teeth: rounding to f32 splits some faces of the exact hulls");
}

/// OBJ files of a turned part whose faces are planar only to single precision. Written with six decimals (as
/// many exporters do: at most 9 significant digits) the reader takes the coordinates as single precision and reads
/// the part with its faces. Rounded to `f32` but written with the shortest text of the `f64` values (up to 17 digits,
/// as a program computing in `f32` may print them), the coordinates are taken as written: the folds of 1e-5 mm are
/// beyond the kernel's tolerance (1e-9 of the extent) and the file is rejected, with a message that names the mesh
/// tolerance, which reads it. A tolerance that is not positive and finite is an error naming it.
#[test]
fn obj_files_planar_only_to_single_precision_read_with_their_faces() {
    let part = stackplan_geom::examples::part_by_name("complex", Default::default()).expect("complex");
    let turned = turned(&part, DMat3::from_euler(glam::EulerRot::ZYX, 0.3, 0.7, 1.1));
    let rewritten = |coordinate: &dyn Fn(f64) -> String| -> String {
        io::obj_string(&turned)
            .lines()
            .map(|line| match line.strip_prefix("v ") {
                Some(rest) => {
                    let xs: Vec<String> =
                        rest.split_whitespace().map(|w| coordinate(w.parse::<f64>().expect("number"))).collect();
                    format!("v {}\n", xs.join(" "))
                }
                None => format!("{line}\n"),
            })
            .collect()
    };
    let faces = |p: &Part| {
        let mut f: Vec<usize> = p.components().iter().map(|c| c.faces().len()).collect();
        f.sort_unstable();
        f
    };
    let six_decimals = rewritten(&|x| format!("{x:.6}"));
    let back = io::parse_obj(six_decimals.as_bytes(), Path::new("six.obj"), &ReadOptions::default())
        .expect("six decimals are single precision");
    assert_eq!(faces(&back), faces(&turned));

    let f32_as_f64 = rewritten(&|x| format!("{:?}", x as f32 as f64));
    let err = io::parse_obj(f32_as_f64.as_bytes(), Path::new("f32.obj"), &ReadOptions::default())
        .expect_err("folds of 1e-5 mm are beyond the kernel's tolerance");
    assert!(matches!(err, IoError::NotConvex { .. }), "{err}");
    assert!(err.to_string().contains("mesh tolerance"), "the message says what to do: {err}");
    let options = ReadOptions { mesh_tolerance: Some(1e-3), ..Default::default() };
    let back = io::parse_obj(f32_as_f64.as_bytes(), Path::new("f32.obj"), &options).expect("within 1e-3 mm");
    assert_eq!(faces(&back), faces(&turned));
    for bad in [f64::NAN, -1.0, 0.0, f64::INFINITY] {
        let options = ReadOptions { mesh_tolerance: Some(bad), ..Default::default() };
        let err = io::parse_obj(six_decimals.as_bytes(), Path::new("six.obj"), &options).expect_err("bad tolerance");
        assert!(matches!(err, IoError::NotPositive { .. }) && err.to_string().contains("mesh_tolerance"), "{err}");
    }
}

/// A turned box as another tool writes it: each face (planar only to rounding) cut into two triangles along either
/// diagonal, one of which can cross an exact crease of the hull. It reads as the box: six faces, eight vertices.
#[test]
fn a_turned_box_triangulated_along_either_diagonal_reads_as_a_box() {
    let rotation = DMat3::from_euler(glam::EulerRot::ZYX, 0.41, -0.83, 1.37);
    let corner = |i: usize| {
        let c = |bit: usize, e: f64| if i & bit == 0 { 0.0 } else { e };
        rotation * DVec3::new(c(1, 40.0), c(2, 25.0), c(4, 3.0)) + DVec3::new(10.0, 20.0, 30.0)
    };
    let points: Vec<DVec3> = (0..8).map(corner).collect();
    // the six faces, counter-clockwise seen from outside
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let mut crossed_a_crease = false;
    for diagonals in 0..64u32 {
        let mut triangles = Vec::new();
        for (f, q) in quads.iter().enumerate() {
            if diagonals & (1 << f) == 0 {
                triangles.push([q[0], q[1], q[2]]);
                triangles.push([q[0], q[2], q[3]]);
            } else {
                triangles.push([q[1], q[2], q[3]]);
                triangles.push([q[1], q[3], q[0]]);
            }
        }
        crossed_a_crease |= !oracle_convex(&points, &triangles);
        let part =
            io::parse_stl(ascii_stl(&points, &triangles).as_bytes(), Path::new("box.stl"), &ReadOptions::default())
                .unwrap_or_else(|e| panic!("diagonals {diagonals:06b}: {e}"));
        assert_eq!(part.components().len(), 1);
        assert_eq!(part.components()[0].faces().len(), 6, "diagonals {diagonals:06b}");
        assert_eq!(part.components()[0].vertices().len(), 8);
        assert!((part.mass().volume - 3000.0).abs() < 1e-9, "{}", part.mass().volume);
    }
    assert!(crossed_a_crease, "the test has teeth: some triangulations are not exactly convex");
}

/// A dent or fold deeper than the length tolerance is still not convex: one corner of the turned box pushed in by
/// 1e-6 of its extent (a thousand tolerances).
#[test]
fn a_turned_box_with_a_corner_pushed_in_is_not_convex() {
    let rotation = DMat3::from_euler(glam::EulerRot::ZYX, 0.41, -0.83, 1.37);
    let mut points: Vec<DVec3> = (0..8)
        .map(|i: usize| {
            let c = |bit: usize, e: f64| if i & bit == 0 { 0.0 } else { e };
            rotation * DVec3::new(c(1, 40.0), c(2, 25.0), c(4, 3.0))
        })
        .collect();
    let inward = rotation * DVec3::new(-1.0, -1.0, -1.0).normalize();
    points[7] += inward * 5e-5; // the diagonal is 47.3: 1e-6 of it
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    // triangulated so that the pushed-in corner is a concave fold of each face it is on
    let triangles: Vec<[usize; 3]> = quads
        .iter()
        .flat_map(|q| {
            let k = q.iter().position(|&v| v == 7).unwrap_or(0);
            let r = [q[k], q[(k + 1) % 4], q[(k + 2) % 4], q[(k + 3) % 4]];
            [[r[0], r[1], r[2]], [r[0], r[2], r[3]]]
        })
        .collect();
    assert!(!oracle_convex(&points, &triangles));
    let err = io::parse_stl(ascii_stl(&points, &triangles).as_bytes(), Path::new("dent.stl"), &ReadOptions::default())
        .expect_err("a dent of a thousand tolerances");
    assert!(matches!(err, IoError::NotConvex { .. }), "{err}");
}

#[test]
fn binary_stl_with_a_solid_header_is_binary() {
    let part = bracket();
    let mut bytes = io::stl_binary_bytes(&part);
    bytes[..12].copy_from_slice(b"solid bracke");
    let back = io::parse_stl(&bytes, Path::new("x.stl"), &ReadOptions::default()).expect("binary despite `solid`");
    same_components(&part, &back);
}

#[test]
fn two_cubes_sharing_a_face_are_two_shells_and_an_edge_touch_too() {
    let cube = |o: DVec3| {
        let pts: Vec<DVec3> =
            (0..8).map(|i| o + DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64)).collect();
        convex_hull(&pts).expect("cube").polytope
    };
    for offsets in [[DVec3::ZERO, DVec3::X], [DVec3::ZERO, DVec3::new(1.0, 1.0, 0.0)], [DVec3::ZERO, DVec3::ONE]] {
        let part =
            Part::from_components("two", offsets.iter().map(|&o| cube(o)).collect(), 1.0, PartOrigin::ConvexPieces)
                .expect("part");
        let text = io::stl_ascii_string(&part);
        let back = io::parse_stl(text.as_bytes(), Path::new("two.stl"), &ReadOptions::default()).expect("read");
        same_components(&part, &back);
    }
}

#[test]
fn glb_parses_back() {
    let part = bracket();
    let cube_pts: Vec<DVec3> =
        (0..8).map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64) * 10.0).collect();
    let cube =
        Part::from_components("cube", vec![convex_hull(&cube_pts).expect("cube").polytope], 1.0, PartOrigin::Mesh)
            .expect("cube");
    let items = [
        GlbItem::part(&part),
        GlbItem {
            part: &cube,
            pose: Pose::from_z_rotation(0.3).compose(&Pose::from_translation(DVec3::Z)),
            color: [1.0, 0.0, 0.0, 0.5],
        },
        GlbItem { part: &part, pose: Pose::from_translation(DVec3::new(0.0, 0.0, 5.0)), color: [0.0, 1.0, 0.0, 1.0] },
    ];
    let bytes = glb_bytes(&items);
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes")) as usize;
    assert_eq!(&bytes[0..4], b"glTF");
    assert_eq!(word(4), 2);
    assert_eq!(word(8), bytes.len());
    let json_len = word(12);
    assert_eq!(&bytes[16..20], b"JSON");
    assert_eq!(json_len % 4, 0);
    let json = &bytes[20..20 + json_len];
    let bin_header = 20 + json_len;
    let bin_len = word(bin_header);
    assert_eq!(&bytes[bin_header + 4..bin_header + 8], b"BIN\0");
    assert_eq!(bin_len % 4, 0);
    assert_eq!(bin_header + 8 + bin_len, bytes.len());
    let bin = &bytes[bin_header + 8..];

    // typed parse and validation by gltf-json, an independent implementation of the schema
    let root = gltf_json::Root::from_slice(json).expect("valid glTF JSON");
    let mut problems = Vec::new();
    gltf_json::validation::Validate::validate(&root, &root, gltf_json::Path::new, &mut |path, error| {
        problems.push(format!("{}: {error:?}", path()))
    });
    assert!(problems.is_empty(), "{problems:?}");
    assert_eq!(root.meshes.len(), 3);
    assert_eq!(root.nodes.len(), 4);
    assert!(root.buffers[0].byte_length.0 as usize <= bin_len);

    let value: serde_json::Value = serde_json::from_slice(json).expect("json");
    for (i, item) in items.iter().enumerate() {
        let triangles: usize =
            item.part.components().iter().flat_map(|c| c.faces()).map(|f| f.vertices.len() - 2).sum();
        let positions = &value["accessors"][2 * i];
        let normals = &value["accessors"][2 * i + 1];
        assert_eq!(positions["count"], 3 * triangles);
        assert_eq!(normals["count"], 3 * triangles);
        let (lo, hi) = item.part.aabb();
        for k in 0..3 {
            assert_eq!(positions["min"][k].as_f64(), Some(lo[k] as f32 as f64));
            assert_eq!(positions["max"][k].as_f64(), Some(hi[k] as f32 as f64));
        }
        // the stored floats lie within min/max and the normals are unit
        let view = &value["bufferViews"][positions["bufferView"].as_u64().expect("view") as usize];
        let offset = view["byteOffset"].as_u64().expect("offset") as usize;
        let floats: Vec<f32> = bin[offset..offset + 36 * triangles]
            .chunks(4)
            .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
            .collect();
        for p in floats.chunks(3) {
            for k in 0..3 {
                assert!(p[k] >= lo[k] as f32 && p[k] <= hi[k] as f32);
            }
        }
        let nview = &value["bufferViews"][normals["bufferView"].as_u64().expect("view") as usize];
        let noffset = nview["byteOffset"].as_u64().expect("offset") as usize;
        for n in bin[noffset..noffset + 36 * triangles].chunks(12) {
            let n: Vec<f32> = n.chunks(4).map(|c| f32::from_le_bytes(c.try_into().expect("4"))).collect();
            assert!(((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() - 1.0).abs() < 1e-6);
        }
    }
    // the node matrix of item 1 is its pose (column-major)
    let m = &value["nodes"][2]["matrix"];
    let pose = items[1].pose;
    assert_eq!(m[12].as_f64(), Some(pose.position.x));
    assert_eq!(m[1].as_f64(), Some(pose.rotation.x_axis.y));
    // JSON padding is spaces
    assert!(json.iter().rev().take_while(|&&b| b == b' ').count() < 4);
    let dir = tempfile::tempdir().expect("tempdir");
    io::write_part(dir.path().join("p.glb"), &part).expect("write glb");
    assert!(dir.path().join("p.glb").exists());
}

#[test]
fn stack_file_round_trip_and_row_convention() {
    let dir = tempfile::tempdir().expect("tempdir");
    let part = bracket();
    io::write_part_json(dir.path().join("bracket.json"), &part).expect("part");
    let poses = vec![
        Pose::IDENTITY,
        Pose::from_z_rotation(0.25).compose(&Pose::from_translation(DVec3::new(1.5, -2.0, 3.0))),
        Pose::new(DMat3::from_rotation_x(std::f64::consts::FRAC_PI_2), DVec3::new(0.0, 0.0, 40.0)).expect("pose"),
    ];
    let stack = dir.path().join("stack.json");
    write_stack(&stack, PlacedPart::Path(Path::new("bracket.json")), &poses).expect("write");
    let read = read_stack(&stack).expect("read");
    assert_eq!(read.placements, poses);
    assert_eq!(read.part_path.as_deref(), Some(dir.path().join("bracket.json").as_path()));
    same_components(&part, &read.part);

    // inline part with extra keys per placement
    let mut extra = serde_json::Map::new();
    extra.insert("cost".into(), serde_json::json!(12.5));
    extra.insert("theta_deg".into(), serde_json::json!(14));
    let inline = dir.path().join("inline.json");
    write_stack_with_extras(&inline, PlacedPart::Inline(&part), &poses, &[serde_json::Map::new(), extra.clone()])
        .expect("write");
    let read = read_stack(&inline).expect("read inline");
    assert_eq!(read.part_path, None);
    assert_eq!(read.placements, poses);
    assert_eq!(read.extras[1], extra);
    same_components(&part, &read.part);

    // rows as written: rotation[i][j] is row i; world = R v + p
    let text = r#"{"part": "bracket.json", "placements": [
        {"position": [10, 20, 30], "rotation": [[0, -1, 0], [1, 0, 0], [0, 0, 1]], "note": "quarter turn"}]}"#;
    let hand = dir.path().join("hand.json");
    std::fs::write(&hand, text).expect("write");
    let read = read_stack(&hand).expect("read");
    assert_eq!(read.placements[0].apply(DVec3::X), DVec3::new(10.0, 21.0, 30.0));
    assert_eq!(read.placements[0].apply(DVec3::Y), DVec3::new(9.0, 20.0, 30.0));
    assert_eq!(read.extras[0]["note"], "quarter turn");
}

#[test]
fn a_failing_write_leaves_no_file_and_keeps_the_old_one() {
    let dir = tempfile::tempdir().expect("tempdir");
    let target = dir.path().join("out.stl");
    let failing = |w: &mut dyn std::io::Write| -> std::io::Result<()> {
        w.write_all(&[1u8; 10_000])?;
        Err(std::io::Error::other("disk full (simulated)"))
    };
    let e = atomic::write_atomic_with(&target, failing).expect_err("fails");
    assert!(matches!(&e, IoError::Os { file, .. } if file == &target));
    assert!(e.to_string().contains("out.stl") && e.to_string().contains("disk full"));
    assert!(!target.exists());
    assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 0, "no temporary file left behind");

    atomic::write_atomic(&target, b"old").expect("write");
    assert!(atomic::write_atomic_with(&target, failing).is_err());
    assert_eq!(std::fs::read(&target).expect("read"), b"old");
    assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 1);

    let missing_dir = dir.path().join("no/such/dir/part.json");
    let e = io::write_part_json(&missing_dir, &bracket()).expect_err("no directory");
    assert!(matches!(e, IoError::Os { .. }) && e.to_string().contains("part.json"));
    assert!(!missing_dir.exists());
}

/// Files written together are written all or none: a target in a missing directory or a target that is a directory
/// fails the whole set before any target changes, with no temporary file left; then all are written.
#[test]
fn files_written_together_are_written_all_or_none() {
    let dir = tempfile::tempdir().expect("tempdir");
    let a = dir.path().join("a.json");
    let b = dir.path().join("b.png");
    std::fs::write(&a, b"old a").expect("write");
    let missing = dir.path().join("no/such/dir/c.svg");
    let e =
        atomic::write_all_atomic([(a.as_path(), &b"new a"[..]), (b.as_path(), b"new b"), (missing.as_path(), b"c")])
            .expect_err("a missing directory");
    assert!(matches!(&e, IoError::Os { file, .. } if file == &missing), "{e}");
    assert_eq!(std::fs::read(&a).expect("read"), b"old a", "the first target is untouched");
    assert!(!b.exists(), "the second target is not written");
    let names = |d: &std::path::Path| -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .expect("dir")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into())
            .collect();
        v.sort();
        v
    };
    assert_eq!(names(dir.path()), vec!["a.json".to_string()], "no temporary file left behind");
    let sub = dir.path().join("sub");
    std::fs::create_dir(&sub).expect("mkdir");
    let e = atomic::write_all_atomic([(a.as_path(), &b"new a"[..]), (sub.as_path(), b"x")]).expect_err("a directory");
    assert!(e.to_string().contains("sub"), "{e}");
    assert_eq!(std::fs::read(&a).expect("read"), b"old a");
    atomic::write_all_atomic([(a.as_path(), &b"new a"[..]), (b.as_path(), b"new b")]).expect("write both");
    assert_eq!(std::fs::read(&a).expect("read"), b"new a");
    assert_eq!(std::fs::read(&b).expect("read"), b"new b");
    assert_eq!(names(dir.path()), vec!["a.json".to_string(), "b.png".to_string(), "sub".to_string()]);
}

/// An atomically written file gets the permissions an ordinary new file gets (not the temporary file's owner-only
/// mode), and an overwritten file keeps its own.
#[cfg(unix)]
#[test]
fn atomic_writes_keep_ordinary_permissions() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().expect("tempdir");
    let mode = |p: &std::path::Path| std::fs::metadata(p).expect("metadata").permissions().mode() & 0o7777;
    let ordinary = dir.path().join("ordinary.json");
    std::fs::write(&ordinary, b"{}").expect("write");
    let atomic_new = dir.path().join("atomic.json");
    atomic::write_atomic(&atomic_new, b"{}").expect("write");
    assert_eq!(mode(&atomic_new), mode(&ordinary), "same mode as a file made by File::create (same umask)");
    let private = dir.path().join("private.json");
    std::fs::write(&private, b"old").expect("write");
    std::fs::set_permissions(&private, std::fs::Permissions::from_mode(0o600)).expect("chmod");
    atomic::write_atomic(&private, b"new").expect("write");
    assert_eq!(mode(&private), 0o600, "an overwritten file keeps its mode");
    std::fs::set_permissions(&private, std::fs::Permissions::from_mode(0o640)).expect("chmod");
    atomic::write_atomic(&private, b"newer").expect("write");
    assert_eq!(mode(&private), 0o640);
}

#[test]
fn unsupported_extensions() {
    let e = io::read_part("part.iges", &ReadOptions::default()).expect_err("iges");
    assert!(matches!(e, IoError::UnsupportedExtension { .. }) && e.to_string().contains("part.iges"));
    let e = io::write_part("part.txt", &bracket()).expect_err("txt");
    assert!(matches!(e, IoError::UnsupportedExtension { .. }));
}

/// Random convex pieces on a dyadic grid, well separated so that they are distinct shells.
fn random_part() -> impl Strategy<Value = Part> {
    prop::collection::vec(prop::collection::vec(prop::array::uniform3(-16i32..16), 4..24), 1..4).prop_filter_map(
        "flat pieces",
        |pieces| {
            let mut components = Vec::new();
            for (i, piece) in pieces.iter().enumerate() {
                let pts: Vec<DVec3> = piece
                    .iter()
                    .map(|p| DVec3::new(p[0] as f64 * 0.25 + 100.0 * i as f64, p[1] as f64 * 0.125, p[2] as f64 * 0.5))
                    .collect();
                components.push(convex_hull(&pts).ok()?.polytope);
            }
            Part::from_components("random", components, 1.0, PartOrigin::ConvexPieces).ok()
        },
    )
}

proptest! {
    #[test]
    fn random_parts_round_trip_through_every_format(part in random_part()) {
        let opts = ReadOptions::default();
        let json = io::part_json_string(&part);
        let back = io::parse_part_json(json.as_bytes(), Path::new("r.json"), &opts).expect("json");
        same_components(&part, &back);
        let obj = io::obj_string(&part);
        let back = io::parse_obj(obj.as_bytes(), Path::new("r.obj"), &opts).expect("obj");
        same_components(&part, &back);
        let stl = io::stl_ascii_string(&part);
        let back = io::parse_stl(stl.as_bytes(), Path::new("r.stl"), &opts).expect("ascii stl");
        same_components(&part, &back);
        let stl = io::stl_binary_bytes(&part);
        let back = io::parse_stl(&stl, Path::new("r.stl"), &opts).expect("binary stl");
        same_components(&part, &back);
    }

    /// The same parts turned by a random rotation, so that their faces are planar only to rounding (as a sheet-metal
    /// part rotated into place): every format reads back to the readers' form (binary STL: of the `f32`-rounded
    /// vertices), which has the faces of the part before it was turned.
    #[test]
    fn rotated_parts_read_back_from_every_format(part in random_part(), angles in prop::array::uniform3(-3.2f64..3.2)) {
        let rotation = DMat3::from_rotation_z(angles[0]) * DMat3::from_rotation_y(angles[1]) * DMat3::from_rotation_x(angles[2]);
        let components = part.components().iter().map(|c| c.transformed(rotation, DVec3::new(3.0, -1.0, 2.0))).collect();
        let turned = Part::from_components("turned", components, 1.0, PartOrigin::ConvexPieces).expect("part");
        let exact = read_form(&turned);
        for (c, t) in exact.components().iter().zip(turned.components()) {
            prop_assert_eq!(c.faces().len(), t.faces().len(), "the turn's creases are merged");
        }
        let opts = ReadOptions::default();
        let back = io::parse_part_json(io::part_json_string(&turned).as_bytes(), Path::new("r.json"), &opts).expect("json");
        same_components(&exact, &back);
        let back = io::parse_obj(io::obj_string(&turned).as_bytes(), Path::new("r.obj"), &opts).expect("obj");
        same_components(&exact, &back);
        let back = io::parse_stl(io::stl_ascii_string(&turned).as_bytes(), Path::new("r.stl"), &opts).expect("ascii stl");
        same_components(&exact, &back);
        // binary STL: the f32-rounded vertices (moved onto their faces' planes by at most 4 t), and (the rounding's
        // folds merged within the single-precision tolerance) the faces of the part before it was turned
        let back = io::parse_stl(&io::stl_binary_bytes(&turned), Path::new("r.stl"), &opts).expect("binary stl");
        let expected: Vec<(usize, Vec<DVec3>)> = turned
            .components()
            .iter()
            .map(|c| (c.faces().len(), c.vertices().iter().map(|v| v.as_vec3().as_dvec3()).collect()))
            .collect();
        same_within(&expected, &back, 4.0 * single_tolerance(&turned), "turned random part");
    }
}

#[test]
fn every_good_seed_file_reads() {
    let dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/good");
    let opts = ReadOptions::default();
    let two = io::read_part(dir.join("two_groups.obj"), &opts).expect("obj");
    assert_eq!(two.components().len(), 2);
    assert!((two.mass().volume - (1.0 / 6.0 + 8.0)).abs() < 1e-12);
    let cube = io::read_part(dir.join("cube.stl"), &opts).expect("stl");
    assert!((cube.mass().volume - 8.0).abs() < 1e-12);
    let tetra = io::read_part(dir.join("tetra_binary.stl"), &opts).expect("binary stl with a solid header");
    assert!((tetra.mass().volume - 1.0 / 6.0).abs() < 1e-12);
    let pieces = io::read_part(dir.join("pieces.json"), &opts).expect("pieces");
    assert_eq!(pieces.density(), 2.5);
    assert!((pieces.mass().mass - 2.5 * (1.0 / 6.0 + 8.0)).abs() < 1e-12);
    let sheet = io::read_part(dir.join("sheet.json"), &opts).expect("sheet");
    assert!((sheet.mass().volume - 1.5 * (600.0 - 25.0 + 20.0 * 23.0)).abs() < 1e-9);
    let stack = read_stack(dir.join("stack.json")).expect("stack");
    assert_eq!(stack.placements.len(), 2);
    assert_eq!(stack.extras[1]["cost"], 1.5);
}

/// Independent oracle for a closed, consistently oriented triangle surface: it bounds a convex solid iff no vertex
/// lies strictly above the plane of any triangle (exact orient3d) and the enclosed volume is positive.
fn oracle_convex(points: &[DVec3], triangles: &[[usize; 3]]) -> bool {
    let all_below = triangles.iter().all(|t| {
        points.iter().all(|&p| {
            stackplan_geom::predicates::side(points[t[0]], points[t[1]], points[t[2]], p) != std::cmp::Ordering::Greater
        })
    });
    let volume: f64 = triangles.iter().map(|t| points[t[0]].dot(points[t[1]].cross(points[t[2]]))).sum::<f64>() / 6.0;
    all_below && volume > 0.0
}

fn ascii_stl(points: &[DVec3], triangles: &[[usize; 3]]) -> String {
    let mut s = String::from("solid t\n");
    for t in triangles {
        s.push_str("facet normal 0 0 0\nouter loop\n");
        for &v in t {
            s.push_str(&format!("vertex {:?} {:?} {:?}\n", points[v].x, points[v].y, points[v].z));
        }
        s.push_str("endloop\nendfacet\n");
    }
    s.push_str("endsolid t\n");
    s
}

proptest! {
    /// Fan-triangulate a random convex polytope, move one vertex to a random grid point (often making the surface
    /// non-convex, sometimes not), and compare the exact convexity check with the independent oracle.
    #[test]
    fn convexity_check_agrees_with_an_independent_oracle(
        pts in prop::collection::vec(prop::array::uniform3(-8i32..8), 5..16),
        which in any::<prop::sample::Index>(),
        target in prop::array::uniform3(-10i32..10),
    ) {
        let pts: Vec<DVec3> = pts.iter().map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64 * 0.5)).collect();
        let Ok(hull) = convex_hull(&pts) else { return Ok(()) };
        let poly = hull.polytope;
        let mut points = poly.vertices().to_vec();
        let mut triangles = Vec::new();
        for f in poly.faces() {
            for w in f.vertices[1..].windows(2) {
                triangles.push([f.vertices[0], w[0], w[1]]);
            }
        }
        let moved = which.index(points.len());
        let new_point = DVec3::new(target[0] as f64, target[1] as f64, target[2] as f64 * 0.5);
        prop_assume!(!points.contains(&new_point));
        points[moved] = new_point;
        // skip surfaces with a degenerate (collinear) triangle: both sides treat them specially
        prop_assume!(triangles.iter().all(|t| !stackplan_geom::predicates::collinear(points[t[0]], points[t[1]], points[t[2]])));
        let text = ascii_stl(&points, &triangles);
        let result = io::parse_stl(text.as_bytes(), Path::new("moved.stl"), &ReadOptions::default());
        let expected = oracle_convex(&points, &triangles);
        match &result {
            Ok(part) => {
                prop_assert!(expected, "accepted a non-convex surface");
                prop_assert_eq!(part.components().len(), 1);
            }
            Err(e) => {
                prop_assert!(!expected, "rejected a convex surface: {}", e);
                prop_assert!(matches!(e, IoError::NotConvex { .. } | IoError::DegeneratePiece { .. }), "{:?}", e);
            }
        }
    }
}

#[test]
fn a_large_convex_mesh_reads_back() {
    // 4000 points on a sphere (a Fibonacci lattice): about 8000 hull triangles, each checked exactly (its time is the
    // `mesh` benchmark's `ball_4000_ascii_stl`, 75 ms)
    let n = 4000;
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let pts: Vec<DVec3> = (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let t = golden * i as f64;
            DVec3::new(r * t.cos(), r * t.sin(), z) * 50.0
        })
        .collect();
    let ball = convex_hull(&pts).expect("ball").polytope;
    let part = Part::from_components("ball", vec![ball], 1.0, PartOrigin::ConvexPieces).expect("part");
    let back = io::parse_stl(io::stl_ascii_string(&part).as_bytes(), Path::new("ball.stl"), &ReadOptions::default())
        .expect("convex");
    same_components(&part, &back);
    let back = io::parse_obj(io::obj_string(&part).as_bytes(), Path::new("ball.obj"), &ReadOptions::default())
        .expect("convex");
    same_components(&part, &back);
}

#[test]
fn obj_scene_of_placed_parts_reads_back_as_their_components() {
    let part = bracket();
    let poses = [Pose::IDENTITY, Pose::from_translation(DVec3::new(0.0, 0.0, 64.0))];
    let items: Vec<(&Part, Pose)> = poses.iter().map(|&p| (&part, p)).collect();
    let text = io::obj_scene_string(&items);
    let back = io::parse_obj(text.as_bytes(), Path::new("scene.obj"), &ReadOptions::default()).expect("scene");
    assert_eq!(back.components().len(), 2 * part.components().len());
    assert!((back.mass().volume - 2.0 * part.mass().volume).abs() < 1e-9 * part.mass().volume);
    let (lo, hi) = back.aabb();
    let (plo, phi) = part.aabb();
    assert_eq!(lo, plo);
    assert_eq!(hi, phi + DVec3::new(0.0, 0.0, 64.0));
}
