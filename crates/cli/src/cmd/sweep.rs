//! `stackplan sweep PART --count N --w-values 0,0.5,1 [--out DIR] [the plan options]`: the same stack planned for
//! several weights w of cost (1), like the seed's Fig. 2 (\[A\] section II-A: 121 cubes from a flat pattern at w = 0
//! through pyramids to a single column at w = 1). Writes `plan-w<W>.json` per weight (plan files: `stackplan check`
//! and `stackplan render` read them), `sweep.json` (per weight: parts placed, height, footprint, layers, total cost,
//! seconds) and `sweep.svg` / `sweep.png` (the stacks side by side at one scale, captioned with w).
//!
//! Layers: the parts grouped by the height of their lowest point, heights closer than 1% of the part's own height
//! counting as one layer (so a nested part a little above the one below starts a layer of its own only when it is
//! lifted by more than that). O(n log n) per plan besides planning.

use crate::Outcome;
use crate::cmd::plan::{PlannerArgs, check_w, run_planner};
use crate::input::short_number;
use crate::output::{json_text, write_all_atomic};
use crate::plan_files::{PNG_SCALE, PlanFile, parse_plan_file, plan_document_text, stack_scene};
use crate::render::{Figure, FigurePanel, ISOMETRIC, Scene, figure_png, figure_svg};
use anyhow::{Context, bail};
use serde::Serialize;
use stackplan_geom::{Part, Pose};
use std::path::PathBuf;

/// Arguments of `sweep`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Part file or built-in example (`example:NAME`).
    pub part: String,
    /// The weights w, comma-separated, each from 0 to 1: 0 spreads parts on the floor, keeping the centres of gravity
    /// low; 1 keeps the footprint small, building columns.
    #[arg(long, value_name = "W,W,...", default_value = "0,0.5,1")]
    pub w_values: String,
    /// The planner's options.
    #[command(flatten)]
    pub planner: PlannerArgs,
    /// Output directory (created if missing).
    #[arg(long, default_value = "sweep")]
    pub out: PathBuf,
}

/// One weight's result in `sweep.json`.
#[derive(Debug, Clone, Serialize)]
pub struct SweepRun {
    /// The weight w.
    pub w: f64,
    /// Parts placed.
    pub placed: usize,
    /// Why the plan ended early (`null` when every part was placed).
    pub stopped: Option<String>,
    /// Height of the stack's top (mm).
    pub height: f64,
    /// Floor footprint `[[x_min, y_min], [x_max, y_max]]` (mm).
    pub footprint: [[f64; 2]; 2],
    /// Footprint width and depth (mm).
    pub footprint_size: [f64; 2],
    /// Number of layers (see the module documentation).
    pub layers: usize,
    /// Parts per layer, bottom up.
    pub layer_counts: Vec<usize>,
    /// Total cost (1) of the stack.
    pub total_cost: f64,
    /// Planning time (s).
    pub seconds: f64,
    /// The plan file, relative to `sweep.json`.
    pub plan_file: String,
}

/// `sweep.json`.
#[derive(Debug, Clone, Serialize)]
pub struct SweepJson {
    /// The part's name.
    pub part_name: String,
    /// Parts asked for per plan.
    pub count: usize,
    /// Per weight, in the order given.
    pub runs: Vec<SweepRun>,
}

/// Parses `--w-values`.
pub fn parse_w_values(s: &str) -> anyhow::Result<Vec<f64>> {
    let values: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>().with_context(|| format!("--w-values: {x:?} is not a number")))
        .collect::<anyhow::Result<_>>()?;
    for (k, &w) in values.iter().enumerate() {
        check_w("--w-values", w)?;
        // each weight names its own plan file, and two runs of one weight would be the same plan
        if values[..k].contains(&w) {
            bail!("--w-values: {w} is given twice");
        }
    }
    Ok(values)
}

/// Parts per layer, bottom up: the parts' lowest points sorted, a new layer wherever the gap to the previous lowest
/// point exceeds 1% of the part's height.
pub fn layer_counts(part: &Part, poses: &[Pose]) -> Vec<usize> {
    let (lo, hi) = part.aabb();
    let gap = 0.01 * (hi - lo).max_element();
    let mut bottoms: Vec<f64> = poses
        .iter()
        .map(|pose| {
            part.components()
                .iter()
                .flat_map(|c| c.vertices().iter())
                .map(|v| pose.apply(*v).z)
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    bottoms.sort_by(f64::total_cmp);
    let mut counts: Vec<usize> = Vec::new();
    let mut previous = f64::NEG_INFINITY;
    for b in bottoms {
        if counts.is_empty() || b - previous > gap {
            counts.push(0);
        }
        if let Some(last) = counts.last_mut() {
            *last += 1;
        }
        previous = b;
    }
    counts
}

/// The file name of the plan at weight `w`: `plan-w<W>.json` with `W` as Rust prints the number (`plan-w0.5.json`),
/// or in scientific notation when that is long (`plan-w1e-300.json`, not three hundred zeros). Both are the shortest
/// digits that read back as `w`, so distinct weights get distinct names.
fn plan_file_name(w: f64) -> String {
    let plain = w.to_string();
    if plain.len() <= 24 { format!("plan-w{plain}.json") } else { format!("plan-w{w:e}.json") }
}

/// Runs `sweep`.
pub fn run(args: &Args) -> anyhow::Result<Outcome> {
    let ws = parse_w_values(&args.w_values)?;
    let part = args.planner.load_part(&args.part)?;
    let options: Vec<_> = ws.iter().map(|&w| args.planner.options(&part, w)).collect::<anyhow::Result<_>>()?;
    let bar = indicatif::ProgressBar::new(ws.len() as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{spinner} sweep {pos}/{len} weights, {msg} [{elapsed_precise}] {wide_bar}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let mut plans: Vec<(String, String, PlanFile)> = Vec::new();
    for (k, options) in options.iter().enumerate() {
        bar.set_message(format!("w = {}", short_number(options.w)));
        let count = options.count;
        let planned = run_planner(&part, options, &mut |done| {
            bar.set_message(format!("w = {}: {done}/{count}", short_number(options.w)))
        });
        let (plan, seconds) = match planned {
            Ok(p) => p,
            Err(e) => {
                bar.finish_and_clear();
                return Err(e.context(format!("sweeping {} at w = {}", args.part, short_number(options.w))));
            }
        };
        let name = plan_file_name(options.w);
        let text = plan_document_text(&part, &plan, seconds)?;
        let file = parse_plan_file(text.as_bytes(), &args.out.join(&name))?;
        plans.push((name, text, file));
        bar.set_position(k as u64 + 1);
    }
    bar.finish_and_clear();

    let runs: Vec<SweepRun> = plans
        .iter()
        .map(|(name, _, f)| {
            let counts = layer_counts(&f.part, &f.poses);
            let fp = f.plan.footprint;
            SweepRun {
                w: f.plan.options.w,
                placed: f.poses.len(),
                stopped: f.plan.stopped.clone(),
                height: f.plan.height,
                footprint: fp,
                footprint_size: [fp[1][0] - fp[0][0], fp[1][1] - fp[0][1]],
                layers: counts.len(),
                layer_counts: counts,
                total_cost: f.plan.total_cost,
                seconds: f.seconds,
                plan_file: name.clone(),
            }
        })
        .collect();
    let sweep = SweepJson { part_name: part.name.clone(), count: args.planner.count, runs };
    let scenes: Vec<Scene> = plans.iter().map(|(_, _, f)| stack_scene(f, false)).collect();
    let figure = Figure {
        title: format!(
            "{} {} parts for each weight w (0: spread low on the floor; 1: small footprint, columns)",
            args.planner.count, part.name
        ),
        legend: scenes.first().map(|s| s.legend.clone()).unwrap_or_default(),
        panels: scenes
            .iter()
            .zip(&sweep.runs)
            .map(|(scene, run)| FigurePanel { scene, view: ISOMETRIC, caption: format!("w = {}", short_number(run.w)) })
            .collect(),
        columns: 4,
        cell: (300.0, 300.0),
        common_scale: true,
    };
    let svg = figure_svg(&figure);
    let png = figure_png(&figure, PNG_SCALE)?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    // the plan files, sweep.json and the pictures: all or none
    let sweep_text = json_text(&sweep)?;
    let mut files: Vec<(std::path::PathBuf, &[u8])> =
        plans.iter().map(|(name, text, _)| (args.out.join(name), text.as_bytes())).collect();
    files.push((args.out.join("sweep.json"), sweep_text.as_bytes()));
    files.push((args.out.join("sweep.svg"), svg.as_bytes()));
    files.push((args.out.join("sweep.png"), &png));
    write_all_atomic(files)?;
    let mut text = String::new();
    for r in &sweep.runs {
        text.push_str(&format!(
            "w = {}: {} placed, {} layer{}, height {:.1} mm, footprint {:.1} x {:.1} mm, total cost {:.1} mm^2, {:.1} s\n",
            short_number(r.w),
            r.placed,
            r.layers,
            if r.layers == 1 { "" } else { "s" },
            r.height,
            r.footprint_size[0],
            r.footprint_size[1],
            r.total_cost,
            r.seconds
        ));
    }
    text.push_str(&format!(
        "wrote {}: {}, sweep.json, sweep.svg, sweep.png\n",
        args.out.display(),
        plans.iter().map(|(name, _, _)| name.as_str()).collect::<Vec<_>>().join(", ")
    ));
    crate::output::print_summary(&text)?;
    let complete = sweep.runs.iter().all(|r| r.stopped.is_none());
    Ok(if complete { Outcome::Success } else { Outcome::ChecksFailed })
}

#[cfg(test)]
mod tests {
    use super::*;
    use stackplan_geom::DVec3;

    #[test]
    fn layers_of_unit_cubes_count_distinct_resting_heights() {
        let cube = stackplan_geom::examples::part_by_name("cube", Default::default()).expect("cube");
        let (lo, _) = cube.aabb();
        let at = |x: f64, z: f64| Pose::from_translation(DVec3::new(x, 0.0, z - lo.z));
        let h = {
            let (lo, hi) = cube.aabb();
            hi.z - lo.z
        };
        // a pyramid 3-2-1
        let poses = [at(0.0, 0.0), at(2.0, 0.0), at(4.0, 0.0), at(1.0, h), at(3.0, h), at(2.0, 2.0 * h)];
        assert_eq!(layer_counts(&cube, &poses), vec![3, 2, 1]);
        assert_eq!(layer_counts(&cube, &poses[..1]), vec![1]);
        assert!(layer_counts(&cube, &[]).is_empty());
    }

    #[test]
    fn w_values_are_checked() {
        assert_eq!(parse_w_values("0, 0.5,1").expect("ok"), vec![0.0, 0.5, 1.0]);
        let e = parse_w_values("0,1.5").expect_err("1.5 is not a weight");
        assert_eq!(e.to_string(), "--w-values must lie in [0, 1], got 1.5");
        assert!(parse_w_values("0,x").is_err());
        let e = parse_w_values("0.5,1,0.5").expect_err("a repeated weight");
        assert!(e.to_string().contains("0.5 is given twice"), "{e}");
        assert_eq!(plan_file_name(0.5), "plan-w0.5.json");
        assert_eq!(plan_file_name(1.0), "plan-w1.json");
        assert_eq!(plan_file_name(1e-300), "plan-w1e-300.json");
    }
}
