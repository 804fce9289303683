//! `batch` end to end: good jobs and bad ones in one file, the plans against `plan`'s, reproducibility byte for byte,
//! and resumption.

use crate::common;
use common::*;
use serde_json::Value;
use std::path::Path;

/// Five jobs: three good (one with a part path relative to the jobs file), one with a bad option, one that is not
/// JSON.
const JOBS: &str = r#"{"id": "channel-3", "part": "example:channel", "count": 3, "dtheta_deg": 30}
{"id": "bad-w", "part": "example:channel", "count": 2, "w": 1.5}

{"id": "file-part", "part": "parts/channel.json", "count": 2, "w": 1, "dtheta_deg": 45, "floor": [-300, -300, 300, 300]}
{"part": "example:channel", "count": 
{"id": "cube-4", "part": "example:cube", "count": 4, "clearance": 0, "dtheta_deg": 90, "cup_diameter": 0.5, "floor": "-2.5,-2.5,2.5,2.5", "height": 25, "search_partitions": 1}
"#;

fn setup(dir: &Path) {
    std::fs::create_dir_all(dir.join("parts")).expect("mkdir");
    std::fs::copy(fixture("channel"), dir.join("parts/channel.json")).expect("copy the part");
    std::fs::write(dir.join("jobs.jsonl"), JOBS).expect("write the jobs");
}

fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `plan.json` with its three timings 0, as `batch` writes them.
fn untimed(mut plan: Value) -> Value {
    plan["plan"]["seconds"] = 0.0.into();
    plan["plan"]["stats"]["seconds_search"] = 0.0.into();
    plan["plan"]["stats"]["seconds_checks"] = 0.0.into();
    plan
}

#[test]
fn batch_runs_good_jobs_past_bad_ones_reproducibly_and_resumes() {
    let dir = tempfile::tempdir().expect("tempdir");
    let dir = dir.path();
    setup(dir);
    let o = run_in(dir, &["batch", "jobs.jsonl", "--out", "out"]);
    // some jobs failed: exit status 1, no error message of the whole run
    assert_eq!(o.status.code(), Some(1), "{}\n{}", stdout(&o), stderr(&o));
    assert!(stdout(&o).contains("5 jobs: 3 complete, 0 stopped early, 2 failed (0 finished before"), "{}", stdout(&o));

    let summary = String::from_utf8(read(&dir.join("out/summary.csv"))).expect("utf-8");
    let rows: Vec<Vec<&str>> = summary.lines().map(|l| l.split(',').collect()).collect();
    assert_eq!(
        rows[0],
        ["job", "status", "placed", "count", "height_mm", "footprint_x_mm", "footprint_y_mm", "seconds"]
    );
    let ids: Vec<&str> = rows[1..].iter().map(|r| r[0]).collect();
    assert_eq!(ids, ["channel-3", "bad-w", "file-part", "job-5", "cube-4"], "file order, job-LINE without an id");
    let status: Vec<&str> = rows[1..].iter().map(|r| r[1]).collect();
    assert_eq!(status, ["complete", "failed", "complete", "failed", "complete"]);
    assert_eq!((rows[1][2], rows[1][3]), ("3", "3"));
    assert_eq!((rows[2][2], rows[2][4]), ("0", ""), "a failed job has no height");

    // the failed jobs' errors beside them, one line each, and no plan
    let bad = String::from_utf8(read(&dir.join("out/bad-w/error.txt"))).expect("utf-8");
    assert_eq!(bad, "line 2: w must lie in [0, 1], got 1.5\n");
    assert!(!dir.join("out/bad-w/plan.json").exists());
    let not_json = String::from_utf8(read(&dir.join("out/job-5/error.txt"))).expect("utf-8");
    assert!(not_json.starts_with("line 5: not JSON: ") && not_json.lines().count() == 1, "{not_json}");

    // every good job's plan is `plan`'s for the same options, with the timings 0
    let cases: [(&str, &[&str]); 3] = [
        ("channel-3", &["example:channel", "--count", "3", "--dtheta-deg", "30"]),
        (
            "file-part",
            &["parts/channel.json", "--count", "2", "--w", "1", "--dtheta-deg", "45", "--floor=-300,-300,300,300"],
        ),
        (
            "cube-4",
            &[
                "example:cube",
                "--count=4",
                "--clearance=0",
                "--dtheta-deg=90",
                "--cup-diameter=0.5",
                "--floor=-2.5,-2.5,2.5,2.5",
                "--height=25",
                "--search-partitions=1",
            ],
        ),
    ];
    for (id, args) in cases {
        let mut argv = vec!["plan"];
        argv.extend_from_slice(args);
        let out = format!("cli-{id}");
        argv.extend_from_slice(&["--out", &out]);
        let o = run_in(dir, &argv);
        assert!(o.status.success(), "{}", stderr(&o));
        let cli: Value = serde_json::from_slice(&read(&dir.join(&out).join("plan.json"))).expect("json");
        let batch: Value = serde_json::from_slice(&read(&dir.join("out").join(id).join("plan.json"))).expect("json");
        assert_eq!(batch, untimed(cli.clone()), "job {id} differs from plan's");
        assert!(cli["plan"]["seconds"].as_f64().is_some_and(|s| s > 0.0), "plan records its time");
        let record: Value = serde_json::from_slice(&read(&dir.join("out").join(id).join("job.json"))).expect("json");
        assert_eq!(record["placed"], cli["plan"]["placed"]);
        assert_eq!(record["height_mm"], cli["plan"]["height"]);
    }

    // a second run into another directory writes the same plans, byte for byte
    let o = run_in(dir, &["batch", "jobs.jsonl", "--out", "again"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    for id in ["channel-3", "file-part", "cube-4"] {
        let name = format!("{id}/plan.json");
        assert_eq!(read(&dir.join("out").join(&name)), read(&dir.join("again").join(&name)), "{id}");
    }

    // resumption: a job whose record is missing (interrupted) runs again, finished ones are skipped untouched, and
    // a job whose line changed runs again
    std::fs::remove_file(dir.join("out/channel-3/job.json")).expect("remove");
    let kept = read(&dir.join("out/cube-4/job.json"));
    let jobs = JOBS.replace(r#""count": 2, "w": 1.5"#, r#""count": 2, "w": 0.5"#);
    std::fs::write(dir.join("jobs.jsonl"), jobs).expect("write");
    let o = run_in(dir, &["batch", "jobs.jsonl", "--out", "out"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("5 jobs: 4 complete, 0 stopped early, 1 failed (3 finished before and skipped)"),
        "{}",
        stdout(&o)
    );
    assert_eq!(read(&dir.join("out/cube-4/job.json")), kept, "a finished job is not run again");
    assert_eq!(read(&dir.join("out/channel-3/plan.json")), read(&dir.join("again/channel-3/plan.json")));
    assert!(dir.join("out/bad-w/plan.json").exists() && !dir.join("out/bad-w/error.txt").exists());
    let summary = String::from_utf8(read(&dir.join("out/summary.csv"))).expect("utf-8");
    assert_eq!(summary.lines().filter(|l| l.contains(",complete,")).count(), 4, "{summary}");
}

#[test]
fn batch_names_an_unknown_key_and_rejects_a_duplicate_id() {
    let dir = tempfile::tempdir().expect("tempdir");
    let dir = dir.path();
    std::fs::write(dir.join("jobs.jsonl"), "{\"part\": \"example:cube\", \"cout\": 2}\n").expect("write");
    let o = run_in(dir, &["batch", "jobs.jsonl", "--out", "out"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let error = String::from_utf8(read(&dir.join("out/job-1/error.txt"))).expect("utf-8");
    assert!(error.starts_with("line 1: unknown key `cout` (the keys are part, w, count, floor,"), "{error}");
    std::fs::write(dir.join("jobs.jsonl"), "{\"id\": \"a\", \"part\": \"example:cube\"}\n{\"id\": \"a\"}\n")
        .expect("write");
    let o = run_in(dir, &["batch", "jobs.jsonl", "--out", "out"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("jobs.jsonl:2: job id \"a\" is also the id of line 1"), "{}", stderr(&o));
}
