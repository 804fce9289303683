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
    // the plan file is a stack file: check reads it and every part passes
    let o = run_in(dir.path(), &["check", "p/plan.json", "--cup-diameter", "10", "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
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

/// The text table of `contacts` gives the extremal bounds in the JSON's units, mm and radians, and says so (the
/// bounds on the command line are in degrees).
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
    assert!(header.contains("lower bounds [x y z (mm) rx ry rz (rad)]"), "{header}");
    // a feasible cube-on-cube state tilts up to 2 degrees = 3.491e-2 rad
    assert!(text.contains("3.491e-2") && !text.contains("2.000e0"), "{text}");
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
        let start = std::time::Instant::now();
        let o = run(&[&["contacts", "example:cube", "example:cube"][..], &cube_box, &ga].concat());
        assert_eq!(o.status.code(), Some(2), "{ga:?}: {}", stderr(&o));
        assert!(stderr(&o).starts_with("error: --population / --generations: "), "{ga:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(message), "{ga:?}: {}", stderr(&o));
        assert!(stdout(&o).is_empty(), "{ga:?}");
        // no search ran
        assert!(start.elapsed().as_secs_f64() < 30.0, "{ga:?}: {:?}", start.elapsed());
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
