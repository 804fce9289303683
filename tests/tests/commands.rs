//! `cspace`, `interference`, `place` and `check` end to end, on unit cubes where every answer is known by hand.

use crate::common;
use common::*;
use serde_json::Value;

fn json(o: &std::process::Output) -> Value {
    assert!(o.status.code().is_some(), "terminated by a signal");
    serde_json::from_str(&stdout(o)).unwrap_or_else(|e| panic!("not JSON ({e}): {}\n{}", stdout(o), stderr(o)))
}

#[test]
fn cspace_of_two_unit_cubes_is_the_cube_of_side_two() {
    let o = run(&["cspace", "example:cube", "example:cube", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&o);
    let pair = &v["pairs"][0];
    let faces = pair["faces"].as_array().expect("faces");
    assert_eq!(faces.len(), 6);
    // documented convention: p is in the obstacle iff normal . p <= offset for every face
    let inside = |p: [f64; 3]| {
        faces.iter().all(|f| {
            let n = &f["normal"];
            let d = f["offset"].as_f64().expect("offset");
            (0..3).map(|k| n[k].as_f64().expect("n") * p[k]).sum::<f64>() <= d + 1e-12
        })
    };
    assert!(inside([0.0, 0.0, 0.0]));
    assert!(inside([0.99, -0.99, 0.5]));
    assert!(!inside([1.01, 0.0, 0.0]));
    assert!((pair["volume"].as_f64().expect("volume") - 8.0).abs() < 1e-9);
}

/// Negative numbers are values, not flags, in every subcommand: `--theta-deg -30` is the turn by 330 degrees, and a
/// negative height reaches the planner's own check (exit 2 with its message) instead of a parser error.
#[test]
fn negative_numbers_are_values() {
    let at = |theta: &str| {
        let o = run(&["cspace", "example:block", "example:l-corner", "--theta-deg", theta, "--json"]);
        assert!(o.status.success(), "{theta}: {}", stderr(&o));
        json(&o)
    };
    let (minus, plus) = (at("-30"), at("330"));
    assert_eq!(minus["theta_deg"], -30.0);
    for (a, b) in minus["pairs"].as_array().expect("pairs").iter().zip(plus["pairs"].as_array().expect("pairs")) {
        let volume = |v: &Value| v["volume"].as_f64().expect("volume");
        assert!((volume(a) - volume(b)).abs() <= 1e-9 * volume(b), "{} vs {}", volume(a), volume(b));
    }
    let o = run(&["interference", "example:cube", "example:cube", "--position", "-0.5,0,0", "--theta-deg", "-5"]);
    assert!(o.status.success(), "{}", stderr(&o));
    // a signed exponent, which clap's own test for a negative number does not take
    let tiny = at("-1e-5");
    assert_eq!(tiny["theta_deg"], -1e-5);
    let o = run(&["cspace", "example:block", "example:l-corner", "--theta-deg", "-v", "--json"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("invalid value '-v' for '--theta-deg"), "{}", stderr(&o));
    let dir = tempfile::tempdir().expect("tempdir");
    let o = run_in(dir.path(), &["plan", "example:block", "--height", "-5"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("height must be positive"), "{}", stderr(&o));
    assert!(!dir.path().join("out").exists());
}

#[test]
fn cspace_extrapolated_obstacle_equals_the_built_one_inside_its_interval() {
    let base = ["cspace", "example:channel", "example:channel", "--pair", "0,1", "--json"];
    let with = |extra: &[&str]| run(&[&base[..], extra].concat());
    let built = with(&["--theta-deg", "12"]);
    assert!(built.status.success(), "{}", stderr(&built));
    let extrapolated = with(&["--theta-deg", "12", "--extrapolate-from", "10"]);
    assert!(extrapolated.status.success(), "{}", stderr(&extrapolated));
    let (b, e) = (json(&built), json(&extrapolated));
    assert_eq!(e["extrapolated_from_deg"], 10.0);
    let (pb, pe) = (&b["pairs"][0], &e["pairs"][0]);
    let interval = pe["interval_deg"].as_array().expect("interval");
    let (start, end) = (interval[0].as_f64().expect("start"), interval[1].as_f64().expect("end"));
    assert!(start < 10.0 && 12.0 < end, "interval [{start}, {end}] must contain 10 and 12");
    // same structure and provenance, coordinates within 1e-9 relative
    assert_eq!(pb["vertex_pairs"], pe["vertex_pairs"]);
    assert_eq!(pb["faces"].as_array().map(Vec::len), pe["faces"].as_array().map(Vec::len));
    let (vb, ve) = (pb["vertices"].as_array().expect("v"), pe["vertices"].as_array().expect("v"));
    for (x, y) in vb.iter().zip(ve) {
        for k in 0..3 {
            let (x, y) = (x[k].as_f64().expect("x"), y[k].as_f64().expect("y"));
            assert!((x - y).abs() <= 1e-9 * (1.0 + x.abs()), "{x} vs {y}");
        }
    }
    // the channel's box pieces change structure when their sides align (every 90 degrees): 100 is outside
    let outside = with(&["--theta-deg", "100", "--extrapolate-from", "10"]);
    assert!(!outside.status.success());
    // in the options' unit, degrees, naming the options
    let message = stderr(&outside);
    assert!(message.contains("--theta-deg 100 is outside the constant-structure interval ["), "{message}");
    assert!(message.contains("] degrees of the obstacle built at --extrapolate-from 10"), "{message}");
    assert!(!message.contains("rad"), "{message}");
}

#[test]
fn interference_reports_penetrating_touching_and_free() {
    let case = |pos: &str| {
        let o = run(&["interference", "example:cube", "example:cube", "--position", pos, "--json"]);
        assert!(o.status.code().is_some_and(|c| c == 0 || c == 1), "{}", stderr(&o));
        json(&o)
    };
    let v = case("0,0,0.5");
    assert_eq!(v["penetrating"], 1);
    let v = case("0,0,1");
    assert_eq!(v["penetrating"], 0);
    assert_eq!(v["touching"], 1);
    let v = case("0,0,2");
    assert_eq!(v["penetrating"], 0);
    assert_eq!(v["touching"], 0);
}

/// The audit's reproducers: pairs a few tolerances apart (tolerance 3.0e-7 mm) are `separated` at their distance
/// (parry's GJK answers 0 for the first two and leaves the third out, above the clearance).
#[test]
fn interference_gives_the_distance_of_pairs_a_few_tolerances_apart() {
    let cases: [(&[&str], (u64, u64), f64); 4] = [
        (&["example:triangle", "example:triangle", "--theta-deg", "0"], (0, 3), 5.0e-7),
        (&["example:channel", "example:complex", "--theta-deg", "0"], (2, 4), 2.0e-6),
        (&["example:triangle", "example:triangle", "--theta-deg", "17.3"], (2, 0), 1.0e-5),
        (&["example:triangle", "example:triangle", "--theta-deg", "0"], (1, 3), 5.0e-7),
    ];
    let positions = [
        "-7.269787197624776,4.19721359549996,-1.44721409549996",
        "32.49999943182334,-81.00000191759622,-25.0",
        "-104.57118181894764,-76.95584907443663,-20.000006905572395",
        "-7.269787197624776,4.19721359549996,-1.44721409549996",
    ];
    for ((parts, (i, j), distance), position) in cases.iter().zip(positions) {
        let position = format!("--position={position}");
        let o = run(&[&["interference"][..], parts, &[&position, "--clearance", "1", "--json"]].concat());
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let v = json(&o);
        let pairs = v["pairs"].as_array().expect("pairs");
        let pair = pairs.iter().find(|p| p["moving_piece"] == *i && p["fixed_piece"] == *j);
        let pair = pair.unwrap_or_else(|| panic!("{parts:?} {position}: pair ({i}, {j}) not listed: {pairs:?}"));
        assert_eq!(pair["contact"], "separated", "{pair}");
        let gap = pair["gap"].as_f64().expect("gap");
        // the positions are given to 17 digits of coordinates about 100: 1e-12 mm of rounding
        assert!((gap - distance).abs() < 1e-11, "{parts:?} {position}: gap {gap}, distance {distance}");
    }
}

/// NaN and infinities are errors (exit 2) that name the option, in every option that takes one number of the
/// geometry commands (`cspace --slice-z NaN` printed `slice_z: null` and empty slices; `intervals --from-deg NaN`
/// blamed the order of the window).
#[test]
fn non_finite_numbers_are_errors_naming_the_option() {
    let pair = ["example:block", "example:l-corner"];
    for value in ["NaN", "inf", "-inf"] {
        let cases: [(&[&str], &str); 9] = [
            (&["cspace", "--slice-z", value, "--json"], "--slice-z: "),
            (&["cspace", "--slice-z", value, "--svg", "never.svg"], "is not a finite length"),
            (&["cspace", "--theta-deg", value, "--json"], "--theta-deg"),
            (&["cspace", "--extrapolate-from", value, "--json"], "--extrapolate-from"),
            (&["cspace", "--clearance", value, "--json"], "--clearance"),
            (&["intervals", "--from-deg", value, "--json"], "--from-deg must be a finite angle"),
            (&["intervals", "--to-deg", value, "--json"], "--to-deg must be a finite angle"),
            (&["interference", "--position", "0,0,50", "--theta-deg", value], "--theta-deg"),
            (&["interference", "--position", "0,0,50", "--clearance", value], "--clearance"),
        ];
        for (args, option) in cases {
            let args = [&args[..1], &pair[..], &args[1..]].concat();
            let o = run(&args);
            assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
            let message = stderr(&o);
            assert!(message.contains(option) && !message.contains("panicked"), "{args:?}: {message}");
        }
    }
    assert!(!root().join("never.svg").exists());
    // the order of the window is checked after its numbers
    let o = run(&["intervals", "example:block", "example:l-corner", "--from-deg", "10", "--to-deg", "5"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--from-deg (10) must not exceed --to-deg (5)"), "{}", stderr(&o));
}

/// Angles in degrees are reduced modulo 360 exactly before they turn a part: `T` and `T + 360 k` give the same
/// obstacles, interference pairs and extrapolation bit for bit, for k up to 2^40 (a plain conversion to radians turns
/// a part by 4.4 degrees too much at 1e17 degrees and by 118 at 1e20); the window of `intervals` moves by whole turns;
/// the rotation bounds of `contacts` are at most a turn.
#[test]
fn angles_are_reduced_modulo_a_turn() {
    let turns = 360.0 * 2f64.powi(40);
    let cspace = |theta: f64, extra: &[&str]| {
        let theta = theta.to_string();
        let o =
            run(&[&["cspace", "example:block", "example:l-corner", "--theta-deg", &theta, "--json"][..], extra]
                .concat());
        assert_eq!(o.status.code(), Some(0), "{theta}: {}", stderr(&o));
        json(&o)
    };
    for (t, t_far) in [(17.25, 17.25 + turns), (-17.25, -17.25 - turns), (280.0, 1e20), (-280.0, -1e20)] {
        let (near, far) = (cspace(t, &[]), cspace(t_far, &[]));
        // the angle as given
        assert_eq!(far["theta_deg"].as_f64(), Some(t_far));
        for (a, b) in near["pairs"].as_array().expect("pairs").iter().zip(far["pairs"].as_array().expect("pairs")) {
            for key in ["vertices", "vertex_pairs", "faces", "volume"] {
                assert_eq!(a[key], b[key], "{t}: {key}");
            }
        }
    }
    // extrapolation from T0 + 360 k to T + 360 k
    let (near, far) = (cspace(12.0, &["--extrapolate-from", "10"]), cspace(372.0, &["--extrapolate-from", "3610"]));
    assert_eq!(near["pairs"], far["pairs"]);
    // interference pairs
    let interference = |theta: f64| {
        let theta = theta.to_string();
        let o = run(&[
            "interference",
            "example:triangle",
            "example:triangle",
            "--theta-deg",
            &theta,
            "--position",
            "10,5,3",
            "--clearance",
            "2",
            "--json",
        ]);
        assert_eq!(o.status.code(), Some(0), "{theta}: {}", stderr(&o));
        json(&o)["pairs"].clone()
    };
    assert_eq!(interference(17.25), interference(17.25 + turns));
    // the window of intervals, moved by 10 000 turns
    let intervals = |from: &str, to: &str| {
        let o = run(&["intervals", "example:block", "example:l-corner", "--from-deg", from, "--to-deg", to, "--json"]);
        assert_eq!(o.status.code(), Some(0), "{from} {to}: {}", stderr(&o));
        json(&o)
    };
    let (near, far) = (intervals("10", "100"), intervals("3600010", "3600100"));
    assert_eq!(near, far);
    assert!(near["pairs"][0]["intervals"].as_array().is_some_and(|v| !v.is_empty()));
    // bounds of a range are not reduced: beyond a turn they are errors
    let o = run(&[
        "contacts",
        "example:cube",
        "example:cube",
        "--t-min",
        "-0.1,-0.1,-0.1,-1,-1,-1e20",
        "--t-max",
        "0.1,0.1,0.1,1,1,1",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--t-min (RX,RY,RZ): -1e20 is beyond 360 degrees in magnitude"), "{}", stderr(&o));
}

/// `intervals` partitions the turn exactly: each `end_deg` is bit for bit the next `start_deg`, and the last one less
/// 360 the first (with each end computed on its own, 3 of the 21 joins of Block against L-corner and 15 of the 558 of
/// Triangle against Channel are a few ulps apart).
#[test]
fn intervals_share_their_boundaries() {
    for parts in [["example:block", "example:l-corner"], ["example:triangle", "example:channel"]] {
        let o = run(&["intervals", parts[0], parts[1], "--json"]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let v = json(&o);
        let mut joins = 0;
        for pair in v["pairs"].as_array().expect("pairs") {
            let intervals = pair["intervals"].as_array().expect("intervals");
            let number = |t: &Value, key: &str| t[key].as_f64().expect("a number");
            for (t, next) in intervals.iter().zip(&intervals[1..]) {
                assert_eq!(
                    number(t, "end_deg").to_bits(),
                    number(next, "start_deg").to_bits(),
                    "{parts:?}: {t} {next}"
                );
                joins += 1;
            }
            let (first, last) = (&intervals[0], &intervals[intervals.len() - 1]);
            assert_eq!(number(last, "end_deg") - 360.0, number(first, "start_deg"), "{parts:?}: {first} {last}");
        }
        assert!(joins > 20, "{parts:?}: {joins} joins");
    }
}

fn write_stack(dir: &std::path::Path, positions: &[[f64; 3]]) -> std::path::PathBuf {
    let placements: Vec<Value> = positions
        .iter()
        .map(|p| serde_json::json!({"position": p, "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}))
        .collect();
    let stack = serde_json::json!({"part": fixture("cube").to_str().expect("utf-8"), "placements": placements});
    let path = dir.join("stack.json");
    std::fs::write(&path, serde_json::to_string_pretty(&stack).expect("json")).expect("write");
    path
}

#[test]
fn place_puts_a_cube_on_a_cube_when_floor_space_is_expensive() {
    let dir = tempfile::tempdir().expect("tempdir");
    let stack = write_stack(dir.path(), &[[0.0, 0.0, 0.0]]);
    let cube = fixture("cube");
    // a 1 x 1 floor: the only free place is on top of the first cube
    let o = run(&[
        "place",
        cube.to_str().expect("utf-8"),
        "--stack",
        stack.to_str().expect("utf-8"),
        "--floor",
        "0,0,1,1",
        "--height",
        "5",
        "--w",
        "0.5",
        "--dtheta-deg",
        "90",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&o);
    let p = &v["placements"][0]["position"];
    let z = p[2].as_f64().expect("z");
    assert!((z - 1.0).abs() < 1e-6, "the cube goes on top: {v}");
}

#[test]
fn check_accepts_a_column_and_rejects_an_overlap() {
    let dir = tempfile::tempdir().expect("tempdir");
    let stack = write_stack(dir.path(), &[[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]]);
    let o = run(&["check", stack.to_str().expect("utf-8"), "--cup-diameter", "0.5", "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}\n{}", stdout(&o), stderr(&o));
    let stack = write_stack(dir.path(), &[[0.0, 0.0, 0.0], [0.0, 0.0, 0.5]]);
    let o = run(&["check", stack.to_str().expect("utf-8"), "--cup-diameter", "0.5", "--json"]);
    assert_eq!(o.status.code(), Some(1), "an interfering stack fails the check: {}", stdout(&o));
    // -q: the exit status alone, without the table; JSON asked for is still printed
    let o = run(&["check", stack.to_str().expect("utf-8"), "--cup-diameter", "0.5", "-q"]);
    assert_eq!((o.status.code(), stdout(&o).as_str()), (Some(1), ""), "check -q prints nothing");
    let o = run(&["check", stack.to_str().expect("utf-8"), "--cup-diameter", "0.5", "-q", "--json"]);
    assert_eq!(json(&o)["ok"], false);
    let o = run(&["check", "no/such/stack.json"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("no/such/stack.json"), "{}", stderr(&o));
}

#[test]
fn plan_writes_every_output_and_check_accepts_the_plan() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = run_in(dir.path(), &["plan", "example:channel", "--count", "4", "--dtheta-deg", "30", "--out", "p"]);
    assert!(o.status.success(), "{}\n{}", stdout(&o), stderr(&o));
    for f in ["plan.json", "stack.svg", "stack.png", "stack.glb", "report.html"] {
        let path = dir.path().join("p").join(f);
        assert!(path.metadata().is_ok_and(|m| m.len() > 0), "{f} is missing or empty");
    }
    let plan: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("p/plan.json")).expect("plan")).expect("JSON");
    assert_eq!(plan["placements"].as_array().map(Vec::len), Some(4));
    assert_eq!(plan["plan"]["placed"], 4);
    // the plan file is a stack file: check reads it and every part passes, inside the plan's floor volume
    let o = run_in(dir.path(), &["check", "p/plan.json", "--cup-diameter", "10", "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    let report = json(&o);
    assert_eq!(
        (report["floor"]["ok"].clone(), report["floor"]["height"].clone()),
        (Value::from(true), plan["plan"]["options"]["floor"]["height"].clone())
    );
    // a part moved off the floor polygon (1000 mm along x), or lifted above the maximum height, fails the check
    let height = plan["plan"]["options"]["floor"]["height"].as_f64().expect("height");
    for (axis, by, field) in [(0, 1000.0, "beyond_sides"), (2, height, "above_height")] {
        let mut moved = plan.clone();
        let p = moved["placements"][3]["position"][axis].as_f64().expect("coordinate");
        moved["placements"][3]["position"][axis] = Value::from(p + by);
        std::fs::write(dir.path().join("moved.json"), moved.to_string()).expect("write");
        let o = run_in(dir.path(), &["check", "moved.json", "--json"]);
        assert_eq!(o.status.code(), Some(1), "{field}: {}", stdout(&o));
        let report = json(&o);
        let outside = &report["floor"]["outside"];
        assert_eq!(outside.as_array().map(Vec::len), Some(1), "{field}: {report}");
        assert_eq!(outside[0]["index"], 3);
        // moved 1000 mm along x from inside a floor narrower than that, or lifted by the whole height
        let least = if field == "beyond_sides" { 100.0 } else { 1.0 };
        assert!(outside[0][field].as_f64().is_some_and(|d| d > least), "{field}: {report}");
        assert_eq!((report["ok"].clone(), report["parts"][3]["ok"].clone()), (Value::from(false), Value::from(false)));
        let o = run_in(dir.path(), &["check", "moved.json"]);
        // the table numbers parts from 1: index 3 is part 4
        assert!(stdout(&o).contains("floor volume: part 4 lies"), "{}", stdout(&o));
    }
    // a floor volume that is not one is an error naming the nested key
    let mut bad_floor = plan.clone();
    bad_floor["plan"]["options"]["floor"]["height"] = Value::from("tall");
    std::fs::write(dir.path().join("bad-floor.json"), bad_floor.to_string()).expect("write");
    let o = run_in(dir.path(), &["check", "bad-floor.json"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("bad-floor.json: malformed plan: key `plan.options.floor.height`"), "{}", stderr(&o));
    let html = std::fs::read_to_string(dir.path().join("p/report.html")).expect("html");
    assert!(html.contains("<table id=\"parts\">") && html.contains("stack.png"));
    // a release drop that is not a finite non-negative number is an error that names the file and the placement
    for bad in [serde_json::json!(-1.0), serde_json::json!("x"), serde_json::json!(null)] {
        let mut edited = plan.clone();
        edited["placements"][2]["release_drop"] = bad.clone();
        std::fs::write(dir.path().join("bad.json"), edited.to_string()).expect("write");
        let o = run_in(dir.path(), &["check", "bad.json"]);
        assert_eq!(o.status.code(), Some(2), "{bad}: {}", stderr(&o));
        assert!(stderr(&o).contains("bad.json: placements[2].release_drop"), "{bad}: {}", stderr(&o));
    }
}

#[test]
fn plan_rejects_bad_requests_without_writing_anything() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cases: [&[&str]; 4] = [
        &["plan", "example:channel", "--count", "0", "--out", "x"],
        &["plan", "example:channel", "--w", "1.5", "--out", "x"],
        &["plan", "no/such/part.json", "--out", "x"],
        &["plan", "example:channel", "--floor", "0,0,50,50", "--out", "x"],
    ];
    for args in cases {
        let o = run_in(dir.path(), args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).starts_with("error:"), "{args:?}: {}", stderr(&o));
        assert!(!dir.path().join("x").join("plan.json").exists(), "{args:?} wrote a partial plan");
    }
    // a request the planner cannot meet names the part it was planning
    let o = run_in(dir.path(), &["plan", "example:channel", "--floor", "0,0,50,50", "--out", "x"]);
    assert!(stderr(&o).starts_with("error: planning example:channel: "), "{}", stderr(&o));
    assert!(stderr(&o).contains("too small"), "{}", stderr(&o));
}

/// The text table of `contacts` gives the extremal bounds in mm and degrees, as the bounds on the command line, and
/// says so; its first line counts the feasible states and the states evaluated (the JSON's `states`).
#[test]
fn contacts_table_names_its_units() {
    let o = run(&[
        "contacts",
        "example:cube",
        "example:cube",
        "--t-min=-0.2,-0.2,0.99,-2,-2,-2",
        "--t-max=0.2,0.2,1.05,2,2,2",
        "--population",
        "8",
        "--generations",
        "5",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    let header = text.lines().nth(1).expect("a header line");
    assert!(header.contains("lowest x y z (mm) rx ry rz (deg)"), "{header}");
    // a feasible cube-on-cube state tilts up to 2 degrees (3.491e-2 rad): the rotation columns of the feasible rows
    // (the last 12 numbers: lowest and highest x y z rx ry rz) lie within the bounds in degrees and reach them
    let mut rotations = Vec::new();
    for line in text.lines().filter(|l| l.starts_with('{') && l.contains(" feasible ")) {
        let numbers: Vec<f64> = line.split_whitespace().rev().take(12).map(|t| t.parse().expect("a number")).collect();
        // reversed: highest rz ry rx z y x, then lowest rz ry rx z y x
        rotations.extend([numbers[0], numbers[1], numbers[2], numbers[6], numbers[7], numbers[8]]);
    }
    assert!(!rotations.is_empty(), "{text}");
    assert!(rotations.iter().all(|r| r.abs() <= 2.0005), "{text}");
    assert!(rotations.iter().any(|r| (r.abs() - 2.0).abs() < 5e-4), "{text}");
    let first = text.lines().next().expect("a first line");
    assert!(first.contains("feasible contact states of") && first.contains("evaluated"), "{first}");
}

/// The GA's effort is bounded (`--population 100000 --generations 100000`, each within its range, ran for hours):
/// per search, `population x (generations + 1)` at most 10 million, and per graph 1e9 evaluations, checked before
/// each level with every hypothesis counted as a search. Both are errors (exit 2) at once, naming the options.
#[test]
fn contacts_ga_effort_beyond_the_limits_is_an_error() {
    let cube_box = ["--t-min", "-1.5,-1.5,-1.5,-5,-5,-5", "--t-max", "1.5,1.5,1.5,5,5,5"];
    let cases = [
        (
            ["--population", "100000", "--generations", "100000"],
            "population x (generations + 1) = 100000 x (100000 + 1) = 10000100000 GA evaluations per search, more \
             than the limit of 10000000: lower population or generations",
        ),
        // 1e7 per search is allowed, but not for the hundreds of level-1 hypotheses of two cubes
        (
            ["--population", "10000", "--generations", "999"],
            "hypotheses of level 1 x 10001200 evaluations per GA search",
        ),
    ];
    for (ga, message) in cases {
        // (were the check made after the searches, this would run for hours: the test has no clock of its own)
        let o = run(&[&["contacts", "example:cube", "example:cube"][..], &cube_box, &ga].concat());
        assert_eq!(o.status.code(), Some(2), "{ga:?}: {}", stderr(&o));
        assert!(stderr(&o).starts_with("error: --population / --generations: "), "{ga:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(message), "{ga:?}: {}", stderr(&o));
        assert!(stdout(&o).is_empty(), "{ga:?}");
    }
}

/// Inputs found by fuzzing the command line that used to panic (capacity overflow: exit 101), run out of memory, or
/// fail deep in a solver: each is now an error (exit 2) that names the option, or the file and the place, and writes
/// nothing.
#[test]
fn fuzzed_inputs_are_clear_errors() {
    let dir = tempfile::tempdir().expect("tempdir");
    let plan = run_in(dir.path(), &["plan", "example:cube", "--count", "2", "--cup-diameter", "0.5", "--out", "p"]);
    assert!(plan.status.success(), "{}", stderr(&plan));
    let write = |name: &str, text: &str| std::fs::write(dir.path().join(name), text).expect("write");
    write("underflow.json", r#"{"convex_pieces": [[[0,0,0],[1e-160,0,0],[0,1e-160,0],[0,0,1e-160]]]}"#);
    write("huge_floor.json", "[[-1e300,-1e300],[1e300,-1e300],[1e300,1e300],[-1e300,1e300]]");
    write("clockwise.json", "[[0,0],[0,10],[10,10],[10,0]]");
    write("tiny_offsets.json", r#"{"convex_pieces": [[[0,1.5e-38,2e-39],[1,0,0],[0,1,0],[0,0,1]]]}"#);
    let mut negative_mu: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("p/plan.json")).expect("plan")).expect("JSON");
    negative_mu["plan"]["options"]["mu"] = serde_json::json!(-0.5);
    write("negative_mu.json", &negative_mu.to_string());
    let mut string_height = negative_mu.clone();
    string_height["plan"]["options"]["mu"] = serde_json::json!(0.5);
    string_height["plan"]["options"]["floor"]["height"] = serde_json::json!("high");
    write("string_height.json", &string_height.to_string());
    let max = u64::MAX.to_string();
    let cube_box = ["--t-min", "-0.1,-0.1,-0.1,-1,-1,-1", "--t-max", "0.1,0.1,0.1,1,1,1"];
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["plan", "example:cube", "--dtheta-deg", "1e-300", "--out", "x"], "--dtheta-deg must lie in [0.01, 360]"),
        (vec!["place", "example:cube", "--stack", "p/plan.json", "--dtheta-deg", "1e-9"], "--dtheta-deg"),
        (vec!["check", "p/plan.json", "--margin-directions", &max], "at most 3600 margin directions"),
        (
            [&["contacts", "example:cube", "example:cube"][..], &cube_box, &["--population", &max]].concat(),
            "--population must lie in 4..=100000",
        ),
        (vec!["part", "info", "underflow.json"], "underflow.json: piece 0, point 1: coordinate 1e-160"),
        (vec!["check", "negative_mu.json"], "negative_mu.json: malformed plan: key `plan.options.mu`"),
        (vec!["place", "example:cube", "--stack", "p/plan.json", "--floor-polygon", "huge_floor.json"], "huge_floor"),
        (vec!["place", "example:cube", "--stack", "p/plan.json", "--origin", "1e308,0,0"], "--origin: 1e308"),
        (vec!["plan", "example:cube", "--floor", "-1e300,-1,1,1", "--out", "x"], "--floor: -1e300"),
        (vec!["render", "p/plan.json", "--png", "s.png", "--svg", "./s.png"], "given for two outputs"),
        (
            vec!["render", "string_height.json", "--png", "h.png"],
            "string_height.json: malformed plan: key `plan.options.floor.height`: invalid type: string \"high\"",
        ),
        // the second round
        (
            vec!["plan", "example:cube", "--clearance", "1e9", "--cup-diameter", "0.5", "--out", "x"],
            "the default floor (1.5 part sizes plus --clearance): 1000000001.5",
        ),
        (
            [&["contacts", "example:cube", "example:cube"][..], &["--t-min=0.1,0,0,0,0,0", "--t-max=-0.1,0,0,0,0,0"]]
                .concat(),
            "--t-min / --t-max: bounds of variable x",
        ),
        (
            vec!["place", "example:cube", "--stack", "p/plan.json", "--floor-polygon", "clockwise.json"],
            "placing example:cube on the floor polygon of clockwise.json",
        ),
    ];
    for (args, message) in &cases {
        let o = run_in(dir.path(), args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(message), "{args:?}: {}", stderr(&o));
        assert!(!stderr(&o).contains("panicked"), "{args:?}: {}", stderr(&o));
    }
    assert!(
        !dir.path().join("x").exists() && !dir.path().join("s.png").exists() && !dir.path().join("h.png").exists(),
        "an error left output behind"
    );
    // valid requests that failed: a floor 2e7 mm wide for a 1 mm cube ("the cell is unbounded": the Chebyshev LP's
    // cap was relative to the part), and a part turned by 1e-20 degree whose rounded coordinates (1e-60) underflowed
    // the hull's exact predicates
    let wide = ["plan", "example:cube", "--count", "2", "--floor", "-1e7,-1e7,1e7,1e7", "--height", "1e7"];
    let o =
        run_in(dir.path(), &[&wide[..], &["--dtheta-deg", "90", "--cup-diameter", "0.5", "--out", "wide"]].concat());
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let o = run_in(dir.path(), &["cspace", "tiny_offsets.json", "example:cube", "--theta-deg", "1e-20", "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}
