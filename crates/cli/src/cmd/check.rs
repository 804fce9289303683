//! `stackplan check STACK.json [--mu MU] [--clearance MM] [--cup-diameter MM] [--json]`: interference, clearance,
//! stability, grasp, insertion and removal of every part of a stack (crate `stackplan-stability`; JSON documented in
//! `docs/formats.md`). A plan file is checked with the planner's friction, clearance and cup (its `plan.options`)
//! unless the command line gives them. Exit status 1 when a check fails.

use crate::Outcome;
use crate::output;
use crate::plan_files::{plan_option, plan_summary};
use anyhow::Context;
use serde::Serialize;
use stackplan::stability::check::{CheckOptions, StackCheck, check_stack};
use stackplan::stability::grasp::GraspOptions;
use stackplan::stability::world::PlacedPart;
use std::path::{Path, PathBuf};

/// Arguments of `check`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The stack file (JSON: a part and its placements).
    pub stack: PathBuf,
    /// Coulomb friction coefficient [default: a plan file's `options.mu`, else 0.5].
    #[arg(long)]
    pub mu: Option<f64>,
    /// Required horizontal clearance between parts (mm); 0 disables the test [default: a plan file's
    /// `options.clearance`, else 0].
    #[arg(long)]
    pub clearance: Option<f64>,
    /// Suction cup diameter (mm) [default: a plan file's `options.cup_diameter`, else 30].
    #[arg(long)]
    pub cup_diameter: Option<f64>,
    /// Contact tolerance (mm) instead of the policy's 1e-9 x stack size (for stacks with rounded coordinates).
    #[arg(long)]
    pub contact_tolerance: Option<f64>,
    /// Horizontal directions sampled for the robustness margins (0 to 3600).
    #[arg(long, default_value_t = 8)]
    pub margin_directions: usize,
    /// JSON output.
    #[arg(long)]
    pub json: bool,
}

/// The JSON of `check --json`.
#[derive(Debug, Serialize)]
pub struct CheckJson {
    /// The stack file.
    pub stack_file: String,
    /// Options used.
    pub options: CheckOptions,
    /// The report.
    #[serde(flatten)]
    pub report: StackCheck,
}

/// The placements' `release_drop` (a plan file's parts released above their supports), or none when no placement
/// has one (then the clearance is checked symmetrically at the given positions); a placement without one drops 0.
/// Errors name the file and the placement of a value that is not a finite non-negative number.
fn release_drops(path: &Path, extras: &[serde_json::Map<String, serde_json::Value>]) -> anyhow::Result<Vec<f64>> {
    if extras.iter().all(|e| !e.contains_key("release_drop")) {
        return Ok(Vec::new());
    }
    extras
        .iter()
        .enumerate()
        .map(|(k, e)| match e.get("release_drop") {
            None => Ok(0.0),
            Some(value) => value.as_f64().filter(|d| d.is_finite() && *d >= 0.0).ok_or_else(|| {
                anyhow::anyhow!(
                    "{}: placements[{k}].release_drop must be a finite non-negative number (mm), got {value}",
                    path.display()
                )
            }),
        })
        .collect()
}

/// Runs `check`.
pub fn run(args: &Args) -> anyhow::Result<Outcome> {
    let file = stackplan::geom::io::stack::read_stack(&args.stack)
        .with_context(|| format!("reading the stack {}", args.stack.display()))?;
    let stack: Vec<PlacedPart<'_>> = file
        .placements
        .iter()
        .map(|pose| PlacedPart { part: &file.part, rotation: pose.rotation, position: pose.position })
        .collect();
    // a plan file is checked with the planner's own friction, clearance and cup unless the command line says otherwise;
    // a `plan` that is not a summary object is an error, as for `stackplan render` (`plan_summary`)
    let plan = plan_summary(file.plan.as_ref(), &args.stack)?;
    let option = |key: &str| match plan {
        Some(summary) => plan_option(summary, key, &args.stack),
        None => Ok(None),
    };
    let mu = match args.mu {
        Some(mu) => mu,
        None => option("mu")?.unwrap_or(0.5),
    };
    let clearance = match args.clearance {
        Some(clearance) => clearance,
        None => option("clearance")?.unwrap_or(0.0),
    };
    let cup_diameter = match args.cup_diameter {
        Some(cup) => cup,
        None => option("cup_diameter")?.unwrap_or(30.0),
    };
    let options = CheckOptions {
        mu,
        clearance,
        grasp: GraspOptions { cup_diameter, ..GraspOptions::default() },
        margin_directions: args.margin_directions,
        contact_tolerance: args.contact_tolerance,
        prefix_stability: true,
        release_drops: release_drops(&args.stack, &file.extras)?,
    };
    let report = check_stack(&stack, &options)?;
    let ok = report.ok;
    if args.json {
        output::print_json(&CheckJson { stack_file: args.stack.display().to_string(), options, report })?;
    } else {
        let mut text = format!(
            "stack {}: {} parts, {}\n  part  interference  clearance  stable  margin  stack_stable  grasp_radius  insertable  removable  ok\n",
            args.stack.display(),
            report.parts.len(),
            if ok { "all checks pass" } else { "CHECKS FAILED" }
        );
        for p in &report.parts {
            text.push_str(&format!(
                "  {:>4}  {:>12.6}  {:>9}  {:>6}  {:>6}  {:>12}  {:>12.3}  {:>10}  {:>9}  {}\n",
                p.index,
                p.interference,
                p.clearance_met,
                p.stable.is_stable(),
                p.margin.map_or("-".to_string(), |m| format!("{m:.3}")),
                p.stack_stable.is_stable(),
                p.grasp_radius,
                p.insertable,
                p.removable,
                p.ok
            ));
        }
        text.push_str(&format!(
            "  whole stack: {:?}, margin {}\n",
            report.stack.verdict,
            report.stack.margin.map_or("-".to_string(), |m| format!("{m:.3}"))
        ));
        output::print_summary(&text)?;
    }
    Ok(if ok { Outcome::Success } else { Outcome::ChecksFailed })
}
