//! Functions shared by the end-to-end tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The repository root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("repository root").to_path_buf()
}

/// A fixture part file.
pub fn fixture(name: &str) -> PathBuf {
    root().join("fixtures").join("parts").join(format!("{name}.json"))
}

/// Runs the program with `args` in `cwd`.
pub fn run_in(cwd: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_stackplan-under-test"))
        .args(args)
        .current_dir(cwd)
        .env_remove("STACKPLAN_LOG")
        .output()
        .expect("the program starts")
}

/// Runs the program with `args` in the repository root.
pub fn run(args: &[&str]) -> Output {
    run_in(&root(), args)
}

/// Stdout as text.
pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Stderr as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// `v` turned by `Rz(a) Ry(b) Rx(c)` (glam's `from_euler(ZYX, a, b, c)`): a general rotation, for parts written turned
/// into place, whose faces are then planar only to rounding.
pub fn turned_zyx((a, b, c): (f64, f64, f64), v: [f64; 3]) -> [f64; 3] {
    let rz = [[a.cos(), -a.sin(), 0.0], [a.sin(), a.cos(), 0.0], [0.0, 0.0, 1.0]];
    let ry = [[b.cos(), 0.0, b.sin()], [0.0, 1.0, 0.0], [-b.sin(), 0.0, b.cos()]];
    let rx = [[1.0, 0.0, 0.0], [0.0, c.cos(), -c.sin()], [0.0, c.sin(), c.cos()]];
    let apply = |m: [[f64; 3]; 3], v: [f64; 3]| -> [f64; 3] {
        [0, 1, 2].map(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
    };
    apply(rz, apply(ry, apply(rx, v)))
}

/// Writes the built-in example `name` turned by `Rz(0.3) Ry(0.7) Rx(1.1)` and moved by (123.25, -45.5, 7) into `dir`
/// as `turned.json` (its convex pieces in `f64`) and `turned.stl` (binary: single precision), as `part info` and
/// `part export` give them.
pub fn write_turned_example(dir: &Path, name: &str) {
    let o = run_in(dir, &["part", "info", &format!("example:{name}"), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let info: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("json");
    let pieces: Vec<Vec<[f64; 3]>> = info["pieces"]
        .as_array()
        .expect("pieces")
        .iter()
        .map(|p| {
            p["vertices"]
                .as_array()
                .expect("vertices")
                .iter()
                .map(|v| {
                    let t = turned_zyx((0.3, 0.7, 1.1), [0, 1, 2].map(|k| v[k].as_f64().expect("coordinate")));
                    [t[0] + 123.25, t[1] - 45.5, t[2] + 7.0]
                })
                .collect()
        })
        .collect();
    let turned = serde_json::json!({ "name": "turned", "convex_pieces": pieces });
    std::fs::write(dir.join("turned.json"), turned.to_string()).expect("write");
    let o = run_in(dir, &["part", "export", "turned.json", "--stl", "turned.stl"]);
    assert!(o.status.success(), "{}", stderr(&o));
}
