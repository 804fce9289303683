//! `stackplan check STACK.json [--mu MU] [--clearance MM] [--cup-diameter MM] [--json]`: interference, clearance,
//! stability, grasp, insertion and removal of every part of a stack (crate `stackplan-stability`; JSON documented in
//! `docs/formats.md`). A plan file is checked with the planner's friction, clearance and cup (its `plan.options`)
//! unless the command line gives them, and against its floor volume (every part inside the floor polygon and below
//! the maximum height). Exit status 1 when a check fails.

use crate::Outcome;
use crate::output;
use crate::plan_files::{plan_floor, plan_option, plan_summary};
use anyhow::Context;
use serde::Serialize;
use stackplan::geom::io::stack::StackFile;
use stackplan::planner::FloorVolume;
use stackplan::stability::check::{CheckOptions, StackCheck, check_stack};
use stackplan::stability::grasp::GraspOptions;
use stackplan::stability::world::PlacedPart;
use std::path::{Path, PathBuf};

/// Arguments of `check`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The stack file (JSON: a part and its placements).
    pub stack: PathBuf,
    /// Coulomb friction coefficient [default: a plan file's `options.mu`, else 0.5, as in plan].
    #[arg(long)]
    pub mu: Option<f64>,
    /// Required horizontal clearance between parts (mm); 0 disables the test [default: a plan file's
    /// `options.clearance`, else 0, which differs from plan's 5 because a plain stack file records no clearance it
    /// was built with].
    #[arg(long, value_name = "MM")]
    pub clearance: Option<f64>,
    /// Suction cup diameter (mm) [default: a plan file's `options.cup_diameter`, else 10, as in plan].
    #[arg(long, value_name = "MM")]
    pub cup_diameter: Option<f64>,
    /// Largest tilt from level of a face that holds the cup (degrees) [default: a plan file's
    /// `options.grasp_tilt_rad` in degrees, else 5, as in plan].
    #[arg(long, value_name = "DEG")]
    pub grasp_tilt_deg: Option<f64>,
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
    /// A plan file's floor volume, and the parts that leave it (`null` for a stack file without one).
    pub floor: Option<FloorCheck>,
    /// The report.
    #[serde(flatten)]
    pub report: StackCheck,
}

/// A plan file's floor volume (`plan.options.floor`) checked: every part inside the floor polygon and below the
/// maximum height, within the check's length tolerance.
#[derive(Debug, Serialize)]
pub struct FloorCheck {
    /// The floor polygon's corners (mm).
    pub polygon: Vec<[f64; 2]>,
    /// The maximum height (mm).
    pub height: f64,
    /// The parts that leave the floor volume by more than the tolerance.
    pub outside: Vec<FloorViolation>,
    /// No part leaves it.
    pub ok: bool,
}

/// A part that leaves the floor volume.
#[derive(Debug, Serialize)]
pub struct FloorViolation {
    /// The part's index in the stack (0-based: part `index + 1` of the table).
    pub index: usize,
    /// How far its farthest vertex lies outside the floor polygon, horizontally (mm; 0 when inside).
    pub beyond_sides: f64,
    /// How far its highest vertex lies above the maximum height (mm; 0 when below).
    pub above_height: f64,
}

/// The floor check of `stack` against `floor` (see [`FloorCheck`]). O(parts x vertices x sides).
fn floor_check(stack: &[PlacedPart<'_>], floor: &FloorVolume, tolerance: f64) -> FloorCheck {
    let sides = floor.side_planes();
    let outside: Vec<FloorViolation> = stack
        .iter()
        .enumerate()
        .filter_map(|(index, p)| {
            let (mut beyond, mut top) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
            for v in p.part.all_vertices() {
                let w = p.pose.rotation * v + p.pose.position;
                top = top.max(w.z);
                for &(n, d) in &sides {
                    beyond = beyond.max(n.x * w.x + n.y * w.y - d);
                }
            }
            let (beyond_sides, above_height) = (beyond.max(0.0), (top - floor.height).max(0.0));
            (beyond_sides > tolerance || above_height > tolerance).then_some(FloorViolation {
                index,
                beyond_sides,
                above_height,
            })
        })
        .collect();
    FloorCheck {
        polygon: floor.polygon.iter().map(|c| c.to_array()).collect(),
        height: floor.height,
        ok: outside.is_empty(),
        outside,
    }
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
    let file =
        stackplan::geom::io::stack::read_stack_with(&args.stack, &crate::input::read_options(Default::default()))
            .with_context(|| format!("reading the stack {}", args.stack.display()))?;
    let checked = check_stack_file(&file, args)?;
    let ok = checked.report.ok;
    if args.json {
        output::print_json(&check_json_value(checked)?)?;
    } else {
        let CheckJson { options, floor, report, .. } = checked;
        let mut text = format!(
            "stack {}: {} parts (numbered from 1 in placing order), {}\n  part  interference_mm  clearance_met  \
             stable  margin  stack_stable  grasp_radius_mm  insertable  removable  ok\n",
            args.stack.display(),
            report.parts.len(),
            if ok { "all checks pass" } else { "CHECKS FAILED" }
        );
        for p in &report.parts {
            text.push_str(&format!(
                "  {:>4}  {:>15.6}  {:>13}  {:>6}  {:>6}  {:>12}  {:>15.3}  {:>10}  {:>9}  {}\n",
                p.index + 1,
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
            "  whole stack: {:?}, margin {}\n  (interference: penetration depth; margin: the largest sideways push, as \
             a fraction of the weight, that the part resists on its supports, up to 10; clearance {} mm, cup {} mm, \
             mu {})\n",
            report.stack.verdict,
            report.stack.margin.map_or("-".to_string(), |m| format!("{m:.3}")),
            crate::input::short_number(options.clearance),
            crate::input::short_number(options.grasp.cup_diameter),
            crate::input::short_number(options.mu),
        ));
        if let Some(f) = &floor {
            if f.ok {
                text.push_str("  floor volume: every part inside\n");
            }
            for v in &f.outside {
                text.push_str(&format!(
                    "  floor volume: part {} lies {:.6} mm beyond the floor polygon and {:.6} mm above the maximum height\n",
                    v.index + 1, v.beyond_sides, v.above_height
                ));
            }
        }
        output::print_summary(&text)?;
    }
    Ok(if ok { Outcome::Success } else { Outcome::ChecksFailed })
}

/// Checks a stack file read from `args.stack` (which names it in errors) with the options of `args` and, for a plan
/// file, its own friction, clearance, cup and floor volume: what `stackplan check` prints (shared with the Python
/// package's `check`).
pub fn check_stack_file(file: &StackFile, args: &Args) -> anyhow::Result<CheckJson> {
    let stack: Vec<PlacedPart<'_>> =
        file.placements.iter().map(|pose| PlacedPart { part: &file.part, pose: *pose }).collect();
    // a plan file is checked with the planner's own friction, clearance and cup unless the command line says otherwise;
    // a `plan` that is not a summary object is an error, as for `stackplan render` (`plan_summary`)
    let plan = plan_summary(file.plan.as_ref(), &args.stack)?;
    let option = |key: &str| match plan {
        Some(summary) => plan_option(summary, key, &args.stack),
        None => Ok(None),
    };
    let mu = match args.mu {
        Some(mu) => mu,
        None => option("mu")?.unwrap_or(crate::input::DEFAULT_MU),
    };
    let clearance = match args.clearance {
        Some(clearance) => clearance,
        None => option("clearance")?.unwrap_or(0.0),
    };
    let cup_diameter = match args.cup_diameter {
        Some(cup) => cup,
        None => option("cup_diameter")?.unwrap_or(crate::input::DEFAULT_CUP_DIAMETER_MM),
    };
    let max_tilt = match args.grasp_tilt_deg {
        Some(deg) => {
            crate::input::check_grasp_tilt(deg)?;
            deg.to_radians()
        }
        None => match option("grasp_tilt_rad")? {
            Some(rad) => rad,
            // (plan files written before the `_rad` names)
            None => option("grasp_tilt")?.unwrap_or(crate::input::DEFAULT_GRASP_TILT_DEG.to_radians()),
        },
    };
    let options = CheckOptions {
        mu,
        clearance,
        grasp: GraspOptions { cup_diameter, max_tilt, ..GraspOptions::default() },
        margin_directions: args.margin_directions,
        contact_tolerance: args.contact_tolerance,
        prefix_stability: true,
        release_drops: release_drops(&args.stack, &file.extras)?,
    };
    let mut report = check_stack(&stack, &options)?;
    // a plan file's floor volume: a part outside it fails (`check_stack` knows the floor plane only)
    let floor = match plan {
        Some(summary) => plan_floor(summary, &args.stack)?.map(|f| floor_check(&stack, &f, report.tolerance)),
        None => None,
    };
    if let Some(f) = &floor {
        for v in &f.outside {
            if let Some(part) = report.parts.get_mut(v.index) {
                part.ok = false;
            }
        }
        report.ok &= f.ok;
    }
    Ok(CheckJson { stack_file: args.stack.display().to_string(), options, floor, report })
}

/// The JSON of `check --json` (radians named `_rad`).
pub fn check_json_value(json: CheckJson) -> anyhow::Result<serde_json::Value> {
    let mut value = serde_json::to_value(json)?;
    output::rename_key(&mut value, &["options", "grasp", "max_tilt"], "max_tilt_rad");
    Ok(value)
}
