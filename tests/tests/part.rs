//! `stackplan part info` and `stackplan part export`, end to end.

use crate::common;
use common::*;

#[test]
fn part_info_json_describes_the_fixture() {
    for (name, components) in [("channel", 3), ("triangle", 6), ("complex", 79)] {
        let path = fixture(name);
        let o = run(&["part", "info", path.to_str().expect("utf-8 path"), "--triangulate", "--json"]);
        assert!(o.status.success(), "{}", stderr(&o));
        let v: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("JSON");
        assert_eq!(v["components"], components, "{name}");
        assert_eq!(v["pieces"].as_array().map(Vec::len), Some(components));
        let volume = v["volume"].as_f64().expect("volume");
        let pieces: f64 =
            v["pieces"].as_array().expect("pieces").iter().map(|p| p["volume"].as_f64().expect("v")).sum();
        assert!((volume - pieces).abs() <= 1e-9 * volume, "{name}: {volume} vs {pieces}");
        let lo = &v["bounding_box"][0];
        let hi = &v["bounding_box"][1];
        let cg = &v["center_of_gravity"];
        for k in 0..3 {
            let (l, h, c) = (lo[k].as_f64().expect("lo"), hi[k].as_f64().expect("hi"), cg[k].as_f64().expect("cg"));
            assert!(l <= c && c <= h, "{name}: c.g. outside the bounding box");
        }
    }
}

#[test]
fn part_info_text_and_builtin_example() {
    let o = run(&["part", "info", "example:cube"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.contains("components      1"), "{text}");
    assert!(text.contains("volume"), "{text}");
}

#[test]
fn missing_and_broken_files_are_clear_errors() {
    let o = run(&["part", "info", "no/such/part.json"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("no/such/part.json"), "{}", stderr(&o));

    let dir = tempfile::tempdir().expect("tempdir");
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, "{\"name\": \"x\", \"sheet_metal\": {\"thickness\": 0, \"faces\": []}}").expect("write");
    let out = dir.path().join("bad.glb");
    let o = run_in(dir.path(), &["part", "export", "bad.json", "--glb", "bad.glb"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("bad.json"), "{}", stderr(&o));
    assert!(!out.exists(), "no output may be written for a failed run");
    assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 1, "no temporary files left behind");

    let o = run(&["part", "info", "example:no-such-example"]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn export_writes_readable_files() {
    let dir = tempfile::tempdir().expect("tempdir");
    let part = fixture("channel");
    let o = run_in(
        dir.path(),
        &["part", "export", part.to_str().expect("utf-8"), "--glb", "c.glb", "--obj", "c.obj", "--stl", "c.stl"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let glb = std::fs::read(dir.path().join("c.glb")).expect("glb");
    assert_eq!(&glb[0..4], b"glTF");
    assert_eq!(u32::from_le_bytes([glb[8], glb[9], glb[10], glb[11]]) as usize, glb.len());
    // the exported OBJ and STL read back as parts with the same volume
    let info = |p: &str| -> f64 {
        let o = run_in(dir.path(), &["part", "info", p, "--json"]);
        assert!(o.status.success(), "{p}: {}", stderr(&o));
        let v: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("JSON");
        v["volume"].as_f64().expect("volume")
    };
    let original = info(part.to_str().expect("utf-8"));
    let obj = info("c.obj");
    assert!((obj - original).abs() <= 1e-6 * original, "{obj} vs {original}");
    // a sheet-metal part rotated into place, whose faces are planar only to rounding, reads back from OBJ and STL too
    // (written with the components' own faces it would not: "not convex: the polygon at line 11 does not lie in a
    // face plane of the shell's convex hull")
    let o = run_in(dir.path(), &["part", "export", "example:triangle", "--obj", "t.obj", "--stl", "t.stl"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let original = info("example:triangle");
    for file in ["t.obj", "t.stl"] {
        let back = info(file);
        assert!((back - original).abs() <= 1e-6 * original, "{file}: {back} vs {original}");
    }
}

/// The formats of one export are written together or not at all: a target in a missing directory fails the run
/// (exit 2, naming it) before the other target is written.
#[test]
fn an_export_that_fails_for_one_format_writes_none() {
    let dir = tempfile::tempdir().expect("tempdir");
    let part = fixture("channel");
    let o = run_in(
        dir.path(),
        &["part", "export", part.to_str().expect("utf-8"), "--glb", "c.glb", "--obj", "no/such/dir/c.obj"],
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("c.obj"), "{}", stderr(&o));
    assert!(!dir.path().join("c.glb").exists(), "the GLB is not written when the OBJ cannot be");
    assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 0, "no temporary file left behind");
}

/// A turned box as an OBJ whose coordinates were rounded to `f32` but are written with all the digits of the `f64`
/// values (as a program computing in `f32` prints them): its quadrilateral faces are planar only to about 1e-5 mm,
/// beyond the default tolerance for coordinates taken as written. `part info` rejects it with a message that names
/// `--mesh-tolerance`, reads it as a box of six faces with `--mesh-tolerance 0.001`, and a bad tolerance is a clear
/// error (exit 2) before any file is read.
#[test]
fn mesh_tolerance_reads_a_mesh_planar_only_to_single_precision() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut text = String::from("o box\n");
    for i in 0..8usize {
        let bit = |k: usize, e: f64| if i & k == 0 { 0.0 } else { e };
        let p = turned_zyx((0.3, 0.7, 1.1), [bit(1, 40.0), bit(2, 25.0), bit(4, 3.0)]);
        let p = p.map(|x| (x + 100.0) as f32 as f64);
        text.push_str(&format!("v {:?} {:?} {:?}\n", p[0], p[1], p[2]));
    }
    for q in [[1, 3, 4, 2], [5, 6, 8, 7], [1, 2, 6, 5], [3, 7, 8, 4], [1, 5, 7, 3], [2, 4, 8, 6]] {
        text.push_str(&format!("f {} {} {} {}\n", q[0], q[1], q[2], q[3]));
    }
    let path = dir.path().join("turned.obj");
    std::fs::write(&path, &text).expect("write");
    let file = path.to_str().expect("utf-8 path");
    let o = run(&["part", "info", file]);
    assert_eq!(o.status.code(), Some(2), "{}", stdout(&o));
    assert!(stderr(&o).contains("turned.obj") && stderr(&o).contains("mesh tolerance"), "{}", stderr(&o));
    let o = run(&["part", "info", file, "--json", "--mesh-tolerance", "0.001"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let info: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("json");
    let pieces = info["pieces"].as_array().expect("pieces");
    assert_eq!(pieces.len(), 1);
    assert_eq!(pieces[0]["faces"].as_array().map(Vec::len), Some(6), "{info}");
    for bad in ["0", "-1", "NaN", "inf"] {
        let o = run(&["part", "info", file, &format!("--mesh-tolerance={bad}")]);
        assert_eq!(o.status.code(), Some(2), "{bad}");
        assert!(stderr(&o).contains("--mesh-tolerance must be a positive"), "{bad}: {}", stderr(&o));
    }
}

/// The built-in Triangle turned into place and stored as binary STL rests on the same faces with the same margins as
/// the same turned part stored in `f64`: the reader flattens its faces, including a resting face of the whole part
/// that is no component's face (its second pose, on the tips of two flanges, had a margin of 29.55 mm instead of
/// 30.89 mm while only the components' faces were flattened).
#[test]
fn a_part_turned_and_stored_in_single_precision_rests_as_in_double_precision() {
    let dir = tempfile::tempdir().expect("tempdir");
    write_turned_example(dir.path(), "triangle");
    let margins = |file: &str| -> Vec<f64> {
        let o = run_in(dir.path(), &["part", "poses", file, "--json"]);
        assert!(o.status.success(), "{}", stderr(&o));
        let poses: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("json");
        poses["poses"].as_array().expect("poses").iter().map(|p| p["margin"].as_f64().expect("margin")).collect()
    };
    let (double, single) = (margins("turned.json"), margins("turned.stl"));
    assert_eq!(double.len(), single.len(), "{double:?} vs {single:?}");
    for (d, s) in double.iter().zip(&single) {
        assert!((d - s).abs() <= 1e-3, "margins {double:?} (f64) vs {single:?} (f32)");
    }
}

/// `part info --json --features` lists the merged surface's elements that `contacts` names, and `contacts --json`
/// lists the same for both parts: a channel's faces are named after its plates; a block's faces have no names, its
/// face centroids are the face centres and its edges' end points lie on both of their faces.
#[test]
fn features_name_the_elements_of_contact_states() {
    let o = run(&["part", "info", "example:channel", "--json", "--features"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("JSON");
    let faces = v["features"]["faces"].as_array().expect("faces");
    let names: Vec<&str> = faces.iter().filter_map(|f| f["name"].as_str()).collect();
    assert_eq!(names.len(), faces.len(), "{names:?}");
    for name in ["plate1.front", "plate1.back", "plate2.front", "plate3.back"] {
        assert!(names.contains(&name), "{name} in {names:?}");
    }
    // without --json the flag is an error
    let o = run(&["part", "info", "example:channel", "--features"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));

    let o = run(&[
        "contacts",
        "example:cube",
        "example:block",
        "--t-min=-1,-1,100,-1,-1,-1",
        "--t-max=1,1,100.5,1,1,1",
        "--population",
        "8",
        "--generations",
        "2",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("JSON");
    let fixed = &v["fixed_features"];
    assert_eq!(fixed["faces"].as_array().map(Vec::len), Some(6));
    assert_eq!(fixed["edges"].as_array().map(Vec::len), Some(12));
    assert_eq!(fixed["vertices"].as_array().map(Vec::len), Some(8));
    let point = |p: &serde_json::Value| [0, 1, 2].map(|k| p[k].as_f64().expect("coordinate"));
    for f in fixed["faces"].as_array().expect("faces") {
        assert!(f["name"].is_null());
        let (c, n) = (point(&f["centroid"]), point(&f["normal"]));
        // the block [0, 80] x [0, 80] x [0, 100]: the face centre is the centre moved by half the size along n
        let expected = [40.0 + 40.0 * n[0], 40.0 + 40.0 * n[1], 50.0 + 50.0 * n[2]];
        assert!((0..3).all(|k| (c[k] - expected[k]).abs() < 1e-9), "{f}");
    }
    let faces = fixed["faces"].as_array().expect("faces");
    for e in fixed["edges"].as_array().expect("edges") {
        for end in e["endpoints"].as_array().expect("endpoints") {
            let p = point(end);
            for f in e["faces"].as_array().expect("faces") {
                let face = &faces[f.as_u64().expect("index") as usize];
                let (c, n) = (point(&face["centroid"]), point(&face["normal"]));
                let height: f64 = (0..3).map(|k| (p[k] - c[k]) * n[k]).sum();
                assert!(height.abs() < 1e-9, "{e}");
            }
        }
    }
    assert_eq!(v["moving_features"]["faces"].as_array().map(Vec::len), Some(6));
}
