//! `stackplan batch JOBS.jsonl --out DIR [--pictures]`: many stacking plans, one per line of a JSON Lines file, run
//! in parallel on the machine's cores with a progress bar (format in `docs/formats.md`, "Batch runs").
//!
//! A job is a JSON object whose keys are `plan`'s options without the leading `--` (`part`, `count`, `w`, `floor`,
//! `clearance`, `dtheta_deg`, ...), plus an optional `id`. Its keys are turned into `plan`'s own arguments and parsed
//! by `plan`'s parser ([`plan_args`]), so a job and `stackplan plan` with the same options make the same plan, with
//! the same defaults and the same messages for bad values. Each job writes `DIR/ID/plan.json` (`plan`'s plan file
//! with its timings 0, so that the same line always gives the same file, byte for byte), `DIR/ID/error.txt` when it
//! fails (a failing job never stops the others), and last `DIR/ID/job.json`, its record. A job whose `job.json`
//! records the same line is finished and skipped when the batch runs again. `DIR/summary.csv` lists every job in
//! file order. Cost: the plans' own, spread over the cores (the jobs are independent; each plan's searches take
//! more cores when they are free).

use crate::Outcome;
use crate::cmd::plan::{Args as PlanArgs, run_planner};
use crate::output::{print_summary, write_all_atomic, write_atomic};
use crate::plan_files::{plan_document_text, untimed, write_plan_files};
use anyhow::{Context, bail};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Arguments of `batch`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The jobs: a JSON Lines file, one JSON object per line (`plan`'s options without `--`, and an optional `id`).
    pub jobs: PathBuf,
    /// Output directory: one directory per job and `summary.csv` (created if missing).
    #[arg(long, default_value = "batch")]
    pub out: PathBuf,
    /// Also draw each plan's pictures, 3-D model and report, as `plan` does (slower: the pictures take longer than
    /// a small plan).
    #[arg(long)]
    pub pictures: bool,
}

/// How a job ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Every part was placed.
    Complete,
    /// The plan ended early (`plan.stopped` says why) with at least one part placed.
    Stopped,
    /// The job failed: its error is in `error.txt` and `job.json`.
    Failed,
}

impl Status {
    fn as_str(self) -> &'static str {
        match self {
            Status::Complete => "complete",
            Status::Stopped => "stopped",
            Status::Failed => "failed",
        }
    }
}

/// `job.json`: the record of one finished job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JobRecord {
    /// The job's id (its directory's name).
    pub id: String,
    /// The job's line in the jobs file (1-based).
    pub line: usize,
    /// The job's line as given (the record belongs to this line only: a changed line is run again).
    pub job: String,
    /// How it ended.
    pub status: Status,
    /// Parts placed.
    pub placed: usize,
    /// Parts asked for (`null` when the job failed before its options were read).
    pub count: Option<usize>,
    /// Height of the stack's top (mm).
    pub height_mm: Option<f64>,
    /// Floor footprint of the stack `[[x_min, y_min], [x_max, y_max]]` (mm).
    pub footprint_mm: Option<[[f64; 2]; 2]>,
    /// Why the plan ended early (`plan.stopped`).
    pub stopped: Option<String>,
    /// The error of a failed job (the one line of `error.txt`).
    pub error: Option<String>,
    /// Wall time of the job: reading the part, planning and writing (s).
    pub seconds: f64,
}

/// One line of the jobs file.
#[derive(Debug, Clone)]
struct Job {
    id: String,
    line: usize,
    text: String,
}

/// Parses `plan`'s options given as a JSON object (keys: `plan`'s long options without `--`, `_` for `-`, plus
/// `part`) with `plan`'s own parser ([`crate::options::command_args`]). `part_base`: the directory relative part
/// paths are taken from. The messages are one line and name the key.
pub fn plan_args(options: &Map<String, Value>, part_base: Option<&Path>) -> Result<PlanArgs, String> {
    let mut options = options.clone();
    let mut positional = Vec::new();
    if let Some(value) = options.remove("part") {
        let Value::String(spec) = value else { return Err(format!("key `part`: expected a string, got {value}")) };
        positional.push(match part_base {
            Some(base) if !spec.starts_with("example:") && Path::new(&spec).is_relative() => {
                base.join(spec).display().to_string()
            }
            _ => spec,
        });
    }
    crate::options::command_args::<PlanArgs>(&options, &positional, &["out"], &["part"])
}

/// The jobs of a jobs file: one per non-blank line, `id` or `job-LINE`. An unreadable file or two jobs with one id
/// are errors of the whole batch; a line that is not a job fails as that job.
fn read_jobs(path: &Path) -> anyhow::Result<Vec<Job>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read the jobs file {}", path.display()))?;
    let mut jobs: Vec<Job> = Vec::new();
    let mut seen = std::collections::HashMap::new();
    for (i, line) in text.lines().enumerate() {
        let line_no = i + 1;
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        let id = match serde_json::from_str::<Value>(line).ok().as_ref().and_then(|v| v.get("id")) {
            Some(Value::String(id)) => id.clone(),
            _ => format!("job-{line_no}"),
        };
        let valid = !id.is_empty()
            && id.len() <= 100
            && !id.starts_with('.')
            && id.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-'));
        if !valid {
            bail!(
                "{}:{line_no}: job id {id:?} must be 1 to 100 letters, digits, '.', '_' or '-', not starting with '.'",
                path.display()
            );
        }
        if let Some(first) = seen.insert(id.clone(), line_no) {
            bail!("{}:{line_no}: job id {id:?} is also the id of line {first}", path.display());
        }
        jobs.push(Job { id, line: line_no, text: line.to_string() });
    }
    Ok(jobs)
}

/// The record of a finished job in `dir`, if it belongs to `job`'s line.
fn finished(dir: &Path, job: &Job) -> Option<JobRecord> {
    let bytes = std::fs::read(dir.join("job.json")).ok()?;
    let record: JobRecord = serde_json::from_slice(&bytes).ok()?;
    (record.job == job.text && record.id == job.id).then_some(record)
}

/// Runs one job into `dir` and returns its record (a failure is a record too). `base`: the jobs file's directory.
fn run_job(job: &Job, dir: &Path, base: &Path, pictures: bool) -> anyhow::Result<JobRecord> {
    let started = Instant::now();
    // a job run again (its line changed, or it was interrupted) starts from an empty directory
    if dir.exists() {
        std::fs::remove_dir_all(dir).with_context(|| format!("cannot empty {}", dir.display()))?;
    }
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let mut record = JobRecord {
        id: job.id.clone(),
        line: job.line,
        job: job.text.clone(),
        status: Status::Failed,
        placed: 0,
        count: None,
        height_mm: None,
        footprint_mm: None,
        stopped: None,
        error: None,
        seconds: 0.0,
    };
    let planned =
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| plan_job(job, dir, base, pictures, &mut record)))
            .unwrap_or_else(|panic| {
                let what = panic
                    .downcast_ref::<String>()
                    .map(String::as_str)
                    .or_else(|| panic.downcast_ref::<&str>().copied())
                    .unwrap_or("unknown");
                Err(anyhow::anyhow!("internal error (please report it): {what}"))
            });
    if let Err(e) = planned {
        let message = format!("line {}: {}", job.line, crate::error_text(&e));
        write_atomic(&dir.join("error.txt"), format!("{message}\n").as_bytes())?;
        record.status = Status::Failed;
        record.error = Some(message);
    }
    record.seconds = started.elapsed().as_secs_f64();
    write_atomic(&dir.join("job.json"), crate::output::json_text(&record)?.as_bytes())?;
    Ok(record)
}

fn plan_job(job: &Job, dir: &Path, base: &Path, pictures: bool, record: &mut JobRecord) -> anyhow::Result<()> {
    let options: Map<String, Value> = match serde_json::from_str(&job.text) {
        Ok(Value::Object(mut map)) => {
            map.remove("id");
            map
        }
        Ok(other) => bail!("expected a JSON object, got {other}"),
        Err(e) => bail!("not JSON: {e}"),
    };
    if !options.contains_key("part") {
        bail!("key `part` is missing (a part file or example:NAME)");
    }
    let args = plan_args(&options, Some(base)).map_err(anyhow::Error::msg)?;
    crate::cmd::plan::check_w("w", args.w)?;
    record.count = Some(args.planner.count);
    let part = args.planner.load_part(&args.part)?;
    let plan_options = args.planner.options(&part, args.w)?;
    let (plan, _) =
        run_planner(&part, &plan_options, &mut |_| {}).with_context(|| format!("planning {}", args.part))?;
    let plan = untimed(&plan);
    if pictures {
        write_plan_files(dir, &part, &plan, 0.0)?;
    } else {
        write_all_atomic([(dir.join("plan.json"), plan_document_text(&part, &plan, 0.0)?)])?;
    }
    record.status = if plan.stopped.is_some() { Status::Stopped } else { Status::Complete };
    record.placed = plan.parts.len();
    record.height_mm = Some(plan.height);
    record.footprint_mm = Some(plan.footprint);
    record.stopped = plan.stopped.clone();
    Ok(())
}

/// `summary.csv`: one row per job in file order (numbers empty for a failed job).
pub fn summary_csv(records: &[JobRecord]) -> String {
    let mut csv = String::from("job,status,placed,count,height_mm,footprint_x_mm,footprint_y_mm,seconds\n");
    for r in records {
        let number = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.3}"));
        let [[x0, y0], [x1, y1]] = r.footprint_mm.unwrap_or([[f64::NAN; 2]; 2]);
        let size = |d: f64| if d.is_finite() { format!("{d:.3}") } else { String::new() };
        csv.push_str(&format!(
            "{},{},{},{},{},{},{},{:.3}\n",
            r.id,
            r.status.as_str(),
            r.placed,
            r.count.map_or(String::new(), |c| c.to_string()),
            number(r.height_mm),
            size(x1 - x0),
            size(y1 - y0),
            r.seconds
        ));
    }
    csv
}

/// Runs `batch`.
pub fn run(args: &Args) -> anyhow::Result<Outcome> {
    let jobs = read_jobs(&args.jobs)?;
    let base = match args.jobs.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let done: Vec<Option<JobRecord>> = jobs.iter().map(|j| finished(&args.out.join(&j.id), j)).collect();
    let skipped = done.iter().filter(|d| d.is_some()).count();
    let bar = indicatif::ProgressBar::new(jobs.len() as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{spinner} jobs {pos}/{len} [{elapsed_precise}, {eta} left] {wide_bar}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar.set_position(skipped as u64);
    let ran: Vec<anyhow::Result<JobRecord>> = jobs
        .par_iter()
        .zip(done.par_iter())
        .filter(|(_, d)| d.is_none())
        .map(|(job, _)| {
            let record = run_job(job, &args.out.join(&job.id), &base, args.pictures);
            bar.inc(1);
            record
        })
        .collect();
    bar.finish_and_clear();
    let mut ran = ran.into_iter();
    let mut records = Vec::with_capacity(jobs.len());
    for d in done {
        match d {
            Some(record) => records.push(record),
            None => records.push(ran.next().context("a job's record is missing")??),
        }
    }
    let summary = args.out.join("summary.csv");
    write_atomic(&summary, summary_csv(&records).as_bytes())?;
    let count = |s: Status| records.iter().filter(|r| r.status == s).count();
    let (complete, stopped, failed) = (count(Status::Complete), count(Status::Stopped), count(Status::Failed));
    print_summary(&format!(
        "{} jobs: {complete} complete, {stopped} stopped early, {failed} failed ({skipped} finished before and \
         skipped)\nwrote {}\n",
        records.len(),
        summary.display()
    ))?;
    for r in records.iter().filter(|r| r.status == Status::Failed) {
        print_summary(&format!("job {} failed: {}\n", r.id, r.error.as_deref().unwrap_or("unknown error")))?;
    }
    Ok(if stopped + failed > 0 { Outcome::ChecksFailed } else { Outcome::Success })
}
