//! The conventions of docs/formats.md ("Conventions") end to end: one numbering of parts in every picture, report,
//! table and file; one default per option; stderr without escape codes and with each warning once; picture labels
//! that never overlap.

use crate::common;
use common::*;
use serde_json::Value;
use stackplan_cli::plan_files::{PNG_SCALE, read_plan_file, stack_scene};
use stackplan_cli::render::{LabelBox, figure_png, label_layout, three_views};
use std::collections::BTreeMap;
use std::path::Path;

fn read_json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The label boxes of a plan's `stack.png`, checked to be the ones in the written file: the stack figure drawn again
/// from the plan file gives the same bytes, and every box's outline is dark in the PNG.
fn stack_png_labels(plan_dir: &Path) -> Vec<LabelBox> {
    let file = read_plan_file(&plan_dir.join("plan.json")).expect("plan file");
    let scene = stack_scene(&file, true);
    let figure = three_views(&scene);
    let png = std::fs::read(plan_dir.join("stack.png")).expect("stack.png");
    assert!(figure_png(&figure, PNG_SCALE).expect("png") == png, "stack.png is the figure whose labels are checked");
    let rgba = stackplan_cli::render::decode_png(&png).expect("decodes");
    let width = (figure.size().0 * PNG_SCALE).ceil() as usize;
    let boxes = label_layout(&figure);
    for b in &boxes {
        // the middle of the box's top edge, in pixels
        let (x, y) = (((b.min.x + b.max.x) / 2.0 * PNG_SCALE) as usize, (b.min.y * PNG_SCALE).floor() as usize);
        let red = rgba[(y * width + x) * 4];
        assert!(red < 200, "label {} in view {}: no box outline at ({x}, {y})", b.number, b.panel);
    }
    boxes
}

/// A 4-part plan's parts are 1 to 4 in the PNG's labels (each view), the SVG's labels, the report's table, `check`'s
/// table and the glTF node names, and 0 to 3 as `index` in plan.json and in `check --json`.
#[test]
fn part_numbers_agree_between_pictures_report_check_and_json() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = run_in(dir.path(), &["plan", "example:channel", "--count", "4", "--dtheta-deg", "30", "--out", "p"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let p = dir.path().join("p");
    let expected: Vec<usize> = (1..=4).collect();

    let boxes = stack_png_labels(&p);
    for view in 0..3 {
        let numbers: Vec<usize> = boxes.iter().filter(|b| b.panel == view).map(|b| b.number).collect();
        assert_eq!(numbers, expected, "PNG view {view}");
    }
    let svg = std::fs::read_to_string(p.join("stack.svg")).expect("svg");
    for n in &expected {
        let label = format!(">{n}</text>");
        let count = svg.lines().filter(|l| l.starts_with("<text class=\"label\"") && l.ends_with(&label)).count();
        assert_eq!(count, 3, "SVG label {n} in each view");
    }
    assert_eq!(svg.matches("<text class=\"label\"").count(), 12);

    let html = std::fs::read_to_string(p.join("report.html")).expect("report");
    let rows: Vec<usize> = html
        .lines()
        .filter_map(|l| l.strip_prefix("<tr><td>"))
        .map(|l| l.split('<').next().expect("cell").parse().expect("a part number"))
        .collect();
    assert_eq!(rows, expected, "the report's # column");

    let o = run_in(dir.path(), &["check", "p/plan.json"]);
    assert!(o.status.success(), "{}", stdout(&o));
    let table: Vec<usize> =
        stdout(&o).lines().skip(2).filter_map(|l| l.split_whitespace().next()?.parse().ok()).collect();
    assert_eq!(table, expected, "check's part column:\n{}", stdout(&o));

    let plan = read_json(&p.join("plan.json"));
    let indices: Vec<u64> = plan["placements"]
        .as_array()
        .expect("placements")
        .iter()
        .map(|x| x["index"].as_u64().expect("index"))
        .collect();
    assert_eq!(indices, [0, 1, 2, 3]);
    let o = run_in(dir.path(), &["check", "p/plan.json", "--json"]);
    let report: Value = serde_json::from_str(&stdout(&o)).expect("json");
    let indices: Vec<u64> =
        report["parts"].as_array().expect("parts").iter().map(|x| x["index"].as_u64().expect("index")).collect();
    assert_eq!(indices, [0, 1, 2, 3]);

    let glb = std::fs::read(p.join("stack.glb")).expect("glb");
    let glb = String::from_utf8_lossy(&glb);
    for n in &expected {
        assert!(glb.contains(&format!("\"channel #{n}\"")), "glTF node {n}");
    }
    assert!(!glb.contains("\"channel #0\""));
}

/// The default of an option as its help shows it: clap's `[default: X]`, or the last number of a `[default: ...]`
/// written in the help text (an option whose default depends on a plan file: `else 10`).
fn shown_default(arg: &clap::Arg) -> Option<String> {
    let values: Vec<String> = arg.get_default_values().iter().map(|v| v.to_string_lossy().into_owned()).collect();
    if let Some(v) = values.first() {
        return Some(v.clone());
    }
    let help = arg.get_long_help().or(arg.get_help())?.to_string();
    let inner = help.split("[default: ").nth(1)?.split(']').next()?;
    let text = inner.split(", which differs").next().unwrap_or(inner);
    let numbers: Vec<&str> = text
        .split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .filter(|w| !w.is_empty() && w.chars().any(|c| c.is_ascii_digit()))
        .collect();
    numbers.last().map(|n| n.trim_end_matches('.').to_string())
}

/// Every subcommand (with its path, `part poses`) and its options by long name.
fn options_by_command() -> Vec<(String, clap::Command)> {
    let mut out = Vec::new();
    fn walk(prefix: &str, c: &clap::Command, out: &mut Vec<(String, clap::Command)>) {
        for sub in c.get_subcommands() {
            let name = format!("{prefix}{}", sub.get_name()).trim().to_string();
            if sub.has_subcommands() {
                walk(&format!("{name} "), sub, out);
            } else {
                out.push((name, sub.clone()));
            }
        }
    }
    walk("", &stackplan_cli::command(), &mut out);
    out
}

/// The same option has the same default in every command's help, or the help of each command whose default differs
/// says so and why ("differs from ... because"); and the shared numbers are the documented ones.
#[test]
fn an_option_has_one_default_in_every_command() {
    let mut defaults: BTreeMap<String, Vec<(String, String, String)>> = BTreeMap::new();
    for (command, c) in options_by_command() {
        for arg in c.get_arguments() {
            let (Some(long), Some(default)) = (arg.get_long(), shown_default(arg)) else { continue };
            let help = arg.get_long_help().or(arg.get_help()).map(|h| h.to_string()).unwrap_or_default();
            defaults.entry(long.to_string()).or_default().push((command.clone(), default, help));
        }
    }
    let documented = [("w", "0.5"), ("clearance", "5"), ("dtheta-deg", "5"), ("mu", "0.5"), ("cup-diameter", "10")];
    for (option, value) in documented {
        let uses = &defaults[option];
        assert!(uses.len() >= 2, "--{option} is shared: {uses:?}");
        for (command, default, help) in uses {
            let same = default.parse::<f64>().ok() == value.parse::<f64>().ok();
            assert!(
                same || (help.contains("differs from") && help.contains("because")),
                "--{option} of {command}: default {default}, not {value}, and its help does not say why: {help}"
            );
        }
    }
    let grasp = &defaults["grasp-tilt-deg"];
    assert!(grasp.len() >= 3 && grasp.iter().all(|(_, d, _)| d == "5"), "{grasp:?}");
    // the commands in the table of docs/formats.md
    let users = |option: &str| -> Vec<&str> { defaults[option].iter().map(|(c, _, _)| c.as_str()).collect() };
    assert_eq!(users("cup-diameter"), ["part poses", "plan", "sweep", "check"]);
    assert_eq!(users("dtheta-deg"), ["plan", "sweep", "place"]);
    // --w is explained in words
    let plan = options_by_command().into_iter().find(|(n, _)| n == "plan").expect("plan").1;
    let w = plan.get_arguments().find(|a| a.get_long() == Some("w")).expect("--w");
    let help = w.get_long_help().or(w.get_help()).expect("help").to_string();
    assert!(help.contains(stackplan_cli::cmd::plan::W_MEANING), "{help}");
}

/// Stderr carries no escape codes when it is not a terminal, with the libraries' messages (`-vv`) and a warning on
/// it, also with `NO_COLOR`; the warning is there once, as `warning: ...`.
#[test]
fn stderr_has_no_escape_codes_when_redirected() {
    let dir = tempfile::tempdir().expect("tempdir");
    // the 1 mm fixture cube: a warning that the part is small for millimetres
    let cube = fixture("cube");
    let cube = cube.to_str().expect("utf-8");
    for no_color in [None, Some("1")] {
        let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_stackplan-under-test"));
        command.args(["-vv", "part", "poses", cube, "--cup-diameter", "0.5"]).current_dir(dir.path());
        command.env_remove("STACKPLAN_LOG").env_remove("NO_COLOR");
        if let Some(v) = no_color {
            command.env("NO_COLOR", v);
        }
        let o = command.output().expect("runs");
        assert!(o.status.success(), "{}", stderr(&o));
        let err = stderr(&o);
        assert!(err.contains(" DEBUG resting poses"), "-vv writes the libraries' messages: {err}");
        assert!(!err.contains('\u{1b}'), "escape codes on a redirected stderr: {err:?}");
        assert_eq!(err.matches("warning: ").count(), 1, "{err}");
        assert!(err.contains("only 1 mm across"), "{err}");
    }
}

/// A Triangle plan of 15 nested parts: the label boxes its stack.png draws (the c.g.s lie almost on one vertical
/// line, so every view but the side one would stack the numbers on each other) are pairwise disjoint in each view,
/// and all fifteen numbers are there in each.
#[test]
fn labels_of_a_15_part_triangle_stack_do_not_overlap() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = run_in(
        dir.path(),
        &["plan", "example:triangle", "--count", "15", "--w", "0.9", "--dtheta-deg", "30", "--out", "tri"],
    );
    assert!(o.status.success(), "{}\n{}", stdout(&o), stderr(&o));
    let boxes = stack_png_labels(&dir.path().join("tri"));
    assert_eq!(boxes.len(), 45);
    for view in 0..3 {
        let numbers: Vec<usize> = boxes.iter().filter(|b| b.panel == view).map(|b| b.number).collect();
        assert_eq!(numbers, (1..=15).collect::<Vec<_>>());
    }
    for (k, a) in boxes.iter().enumerate() {
        for b in &boxes[k + 1..] {
            assert!(
                a.panel != b.panel || !a.overlaps(b),
                "labels {} and {} overlap in view {}",
                a.number,
                b.number,
                a.panel
            );
        }
    }
    assert!(boxes.iter().any(|b| !b.at_anchor()), "a nested stack needs leader lines");
}

/// Every command that writes files says so, and `demo` writes to `demo/`.
#[test]
fn commands_say_what_they_wrote() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = run_in(dir.path(), &["demo"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).starts_with("wrote 25 files for 6 example parts to demo"), "{}", stdout(&o));
    assert!(dir.path().join("demo/channel.png").exists() && !dir.path().join("out").exists());
    let o = run_in(dir.path(), &["part", "export", "example:cube", "--obj", "c.obj", "--stl", "c.stl"]);
    assert_eq!(stdout(&o), "wrote c.obj, c.stl\n");
    let o = run_in(dir.path(), &["plan", "example:cube", "--count", "2", "--cup-diameter", "0.5", "--out", "p"]);
    assert!(stdout(&o).contains("wrote p: plan.json, stack.svg"), "{}", stdout(&o));
    let o = run_in(dir.path(), &["render", "p/plan.json", "--png", "s.png"]);
    assert_eq!(stdout(&o), "wrote s.png\n");
    let o = run_in(dir.path(), &["-q", "render", "p/plan.json", "--png", "s.png"]);
    assert_eq!(stdout(&o), "", "-q leaves it out");
}

/// A warning raised twice by one command (the 1 mm fixture cube read as the moving and as the fixed part) is printed
/// once, with its count; a real bracket whose pictures raised tiny-skia's warning about empty paths once for every
/// face seen almost edge-on (262 times for `bendfm_2.stl`) plans with nothing on stderr.
#[test]
fn identical_warnings_print_once() {
    let cube = fixture("cube");
    let cube = cube.to_str().expect("utf-8");
    let o = run(&["interference", cube, cube, "--position", "0,0,1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.starts_with("warning: ") && err.contains("only 1 mm across") && err.ends_with("(2 times)\n"), "{err}");

    let dir = tempfile::tempdir().expect("tempdir");
    let bracket = root().join("fixtures/realparts/bendfm_2.stl");
    let o = run_in(dir.path(), &["plan", bracket.to_str().expect("utf-8"), "--out", "b"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stderr(&o), "", "a plan of a real bracket is quiet");
}

/// Every key of `value` (nested), with its path.
fn keys(value: &Value, path: &str, out: &mut Vec<String>) {
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                out.push(format!("{path}.{k}"));
                keys(v, &format!("{path}.{k}"), out);
            }
        }
        Value::Array(items) => items.iter().for_each(|v| keys(v, &format!("{path}[]"), out)),
        _ => {}
    }
}

/// The JSON of `plan`, `place`, `check` and `part poses` names every angle with its unit: no key is one of the
/// libraries' unitless angle names, and the radians are where the docs say (`_rad`); a plan file with the older names
/// (`dtheta`, `grasp_tilt`) still renders and checks alike.
#[test]
fn angles_in_json_carry_their_unit() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = run_in(dir.path(), &["plan", "example:cube", "--count", "2", "--cup-diameter", "0.5", "--out", "p"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let plan = read_json(&dir.path().join("p/plan.json"));
    let place = run_in(dir.path(), &["place", "example:cube", "--stack", "p/plan.json", "--json"]);
    let check = run_in(dir.path(), &["check", "p/plan.json", "--json"]);
    let poses = run_in(dir.path(), &["part", "poses", "example:channel", "--json"]);
    let documents = [
        ("plan.json", plan.clone()),
        ("place", serde_json::from_str(&stdout(&place)).expect("place json")),
        ("check", serde_json::from_str(&stdout(&check)).expect("check json")),
        ("part poses", serde_json::from_str(&stdout(&poses)).expect("poses json")),
    ];
    let unitless = ["theta", "dtheta", "grasp_tilt", "max_tilt", "tilt", "angle", "start"];
    let mut all = Vec::new();
    for (name, doc) in &documents {
        let mut found = Vec::new();
        keys(doc, "", &mut found);
        for key in &found {
            let last = key.rsplit('.').next().expect("a key");
            assert!(!unitless.contains(&last), "{name}: {key} names an angle without its unit");
        }
        all.extend(found.into_iter().map(|k| format!("{name}{k}")));
    }
    for expected in [
        "plan.json.plan.options.dtheta_rad",
        "plan.json.plan.options.grasp_tilt_rad",
        "place.placements[].theta_rad",
        "place.placements[].theta_deg",
        "check.options.grasp.max_tilt_rad",
        "part poses.poses[].grasp_faces[].tilt_rad",
    ] {
        assert!(all.iter().any(|k| k == expected), "{expected} missing");
    }
    let dtheta = plan["plan"]["options"]["dtheta_rad"].as_f64().expect("dtheta_rad");
    assert!((dtheta - 5f64.to_radians()).abs() < 1e-15, "the default step, 5 degrees");

    // the older names read the same
    let mut older = plan.clone();
    let options = older["plan"]["options"].as_object_mut().expect("options");
    for (new, old) in [("dtheta_rad", "dtheta"), ("grasp_tilt_rad", "grasp_tilt")] {
        let v = options.remove(new).expect("present");
        options.insert(old.to_string(), v);
    }
    std::fs::write(dir.path().join("older.json"), older.to_string()).expect("write");
    let o = run_in(dir.path(), &["render", "older.json", "--png", "older.png"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read(dir.path().join("older.png")).ok(), std::fs::read(dir.path().join("p/stack.png")).ok());
    let o = run_in(dir.path(), &["check", "older.json", "--json"]);
    let report: Value = serde_json::from_str(&stdout(&o)).expect("json");
    let (a, b) = (&report["options"]["grasp"]["max_tilt_rad"], &documents[2].1["options"]["grasp"]["max_tilt_rad"]);
    assert_eq!(a, b);
}
