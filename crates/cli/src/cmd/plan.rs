//! `stackplan plan [PART] [--count N] [--w W] [--floor X0,Y0,X1,Y1] [--height H] [--clearance MM] [--dtheta-deg D]
//! [--mu MU] [--cup-diameter MM] [--out DIR]`: a stacking plan for N identical parts, written as `plan.json` (a
//! stack file that `stackplan check` reads, with the plan's summary), `stack.svg`, `stack.png`, `stack.glb` and
//! `report.html`. With no arguments it plans the built-in default example: 15 Channel parts, w = 0.5, 5 mm
//! clearance, into `out/`. (Not the Triangle part: with a horizontal clearance its nested copies would have to float
//! above the walls below, since it has no horizontal face to rest on; `--clearance 0` nests it.)

use crate::Outcome;
use crate::input::load_part_spec;
use crate::output::{json_text, write_atomic};
use crate::render::{Marker, Scene, Solid, part_color, png, svg};
use anyhow::{Context, bail};
use serde_json::{Value, json};
use stackplan::planner::{FloorVolume, Plan, PlanOptions, stack_plan::plan_stack_with_progress};
use stackplan_geom::io::glb::{GlbItem, glb_bytes};
use stackplan_geom::sheet_metal::Decomposition;
use stackplan_geom::{DVec3, Part, Pose};
use std::path::PathBuf;

/// Arguments of `plan`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Part file or built-in example (`example:NAME`).
    #[arg(default_value = "example:channel")]
    pub part: String,
    /// Number of parts.
    #[arg(long, default_value_t = 15)]
    pub count: usize,
    /// Weight w of cost (1): 0 favours low c.g. (spread on the floor), 1 favours small floor use (columns).
    #[arg(long, default_value_t = 0.5)]
    pub w: f64,
    /// Floor rectangle X0,Y0,X1,Y1 (mm); default: 3 x 3 part footprints centred on the origin.
    #[arg(long, value_name = "X0,Y0,X1,Y1", allow_hyphen_values = true)]
    pub floor: Option<String>,
    /// Maximum stack height (mm); default: 6 part heights.
    #[arg(long)]
    pub height: Option<f64>,
    /// Clearance between parts for the robot's positioning error (mm).
    #[arg(long, default_value_t = 5.0)]
    pub clearance: f64,
    /// Step of the rotation about z (degrees).
    #[arg(long, default_value_t = 5.0)]
    pub dtheta_deg: f64,
    /// Friction coefficient.
    #[arg(long, default_value_t = 0.5)]
    pub mu: f64,
    /// Suction cup diameter (mm).
    #[arg(long, default_value_t = 10.0)]
    pub cup_diameter: f64,
    /// Interference-free candidates tested per part and stage.
    #[arg(long, default_value_t = 8)]
    pub candidates: usize,
    /// Split concave sheet-metal faces by plain triangulation (the seed's component counts).
    #[arg(long)]
    pub triangulate: bool,
    /// Output directory.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
}

fn parse_floor(s: &str) -> anyhow::Result<[f64; 4]> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>().with_context(|| format!("--floor: {x:?} is not a number")))
        .collect::<anyhow::Result<_>>()?;
    let [x0, y0, x1, y1] = v[..] else { bail!("--floor needs four numbers X0,Y0,X1,Y1, got {}", v.len()) };
    if !(x0 < x1 && y0 < y1) || v.iter().any(|x| !x.is_finite()) {
        bail!("--floor {s}: needs X0 < X1 and Y0 < Y1, finite");
    }
    Ok([x0, y0, x1, y1])
}

/// Runs `plan`.
pub fn run(args: &Args) -> anyhow::Result<Outcome> {
    if args.count == 0 {
        bail!("--count must be at least 1");
    }
    if !(0.0..=1.0).contains(&args.w) {
        bail!("--w must lie in [0, 1], got {}", args.w);
    }
    if !(args.dtheta_deg > 0.0 && args.dtheta_deg <= 360.0) {
        bail!("--dtheta-deg must lie in (0, 360], got {}", args.dtheta_deg);
    }
    let decomposition = if args.triangulate { Decomposition::Triangulation } else { Decomposition::ConvexMerge };
    let part = load_part_spec(&args.part, decomposition, false)?;
    let (lo, hi) = part.aabb();
    let size = hi - lo;
    let footprint = size.x.max(size.y);
    let [x0, y0, x1, y1] = match &args.floor {
        Some(s) => parse_floor(s)?,
        None => [-1.5 * footprint, -1.5 * footprint, 1.5 * footprint, 1.5 * footprint],
    };
    let height = args.height.unwrap_or(6.0 * size.z.max(size.x.min(size.y)));
    let mut options = PlanOptions::new(args.count, FloorVolume::rectangle(x0, y0, x1, y1, height));
    options.w = args.w;
    options.clearance = args.clearance;
    options.dtheta = args.dtheta_deg.to_radians();
    options.mu = args.mu;
    options.cup_diameter = args.cup_diameter;
    options.candidates = args.candidates;

    let bar = indicatif::ProgressBar::new(args.count as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} planning {pos}/{len} parts [{elapsed_precise}] {wide_bar}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let started = std::time::Instant::now();
    let plan = plan_stack_with_progress(&part, &options, &mut |done, _| bar.set_position(done as u64))?;
    bar.finish_and_clear();
    let seconds = started.elapsed().as_secs_f64();
    if plan.parts.is_empty() {
        bail!("no part could be placed: {}", plan.stopped.as_deref().unwrap_or("unknown reason"));
    }

    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let poses: Vec<Pose> = plan
        .parts
        .iter()
        .map(|p| Pose::from_rows(p.rotation, DVec3::from_array(p.position)))
        .collect::<Result<_, _>>()
        .context("the planner returned an improper rotation")?;
    // every output is prepared first, then written atomically: a failure leaves no partial set behind
    let plan_json = plan_document(&part, &plan, seconds)?;
    let scene = stack_scene(&part, &poses, &plan, &options.floor);
    let items: Vec<GlbItem<'_>> = poses
        .iter()
        .enumerate()
        .map(|(i, pose)| {
            let c = part_color(i);
            GlbItem {
                part: &part,
                pose: *pose,
                color: [c[0] as f32 / 255.0, c[1] as f32 / 255.0, c[2] as f32 / 255.0, 1.0],
            }
        })
        .collect();
    let svg_text = svg(&scene);
    let png_bytes = png(&scene, 2.0)?;
    let glb = glb_bytes(&items);
    let html = report_html(&part, &plan, seconds, &svg_text);
    write_atomic(&args.out.join("plan.json"), json_text(&plan_json)?.as_bytes())?;
    write_atomic(&args.out.join("stack.svg"), svg_text.as_bytes())?;
    write_atomic(&args.out.join("stack.png"), &png_bytes)?;
    write_atomic(&args.out.join("stack.glb"), &glb)?;
    write_atomic(&args.out.join("report.html"), html.as_bytes())?;
    crate::output::print_text(&format!(
        "{} of {} parts placed ({}), height {:.1} mm, footprint {:.1} x {:.1} mm, total cost {:.1}, {:.1} s; wrote {}\n",
        plan.parts.len(),
        args.count,
        plan.stopped.as_deref().unwrap_or("complete"),
        plan.height,
        plan.footprint[1][0] - plan.footprint[0][0],
        plan.footprint[1][1] - plan.footprint[0][1],
        plan.total_cost,
        seconds,
        args.out.display()
    ))?;
    Ok(if plan.stopped.is_some() { Outcome::ChecksFailed } else { Outcome::Success })
}

/// The plan file: a stack file (`part` inline, `placements`) plus the `plan` summary.
fn plan_document(part: &Part, plan: &Plan, seconds: f64) -> anyhow::Result<Value> {
    let inline: Value = serde_json::from_str(&stackplan_geom::io::json::part_json_string(part))?;
    let placements = serde_json::to_value(&plan.parts)?;
    let mut summary = serde_json::to_value(plan)?;
    if let Value::Object(m) = &mut summary {
        m.remove("parts");
        m.insert("part_name".into(), json!(part.name));
        m.insert("placed".into(), json!(plan.parts.len()));
        m.insert("seconds".into(), json!(seconds));
    }
    Ok(json!({ "part": inline, "placements": placements, "plan": summary }))
}

fn stack_scene(part: &Part, poses: &[Pose], plan: &Plan, floor: &FloorVolume) -> Scene {
    let mut solids = Vec::new();
    let mut labels = Vec::new();
    let mut markers = Vec::new();
    for (i, pose) in poses.iter().enumerate() {
        for c in &part.components {
            solids.push(Solid { polytope: c.transformed(pose.rotation, pose.position), color: part_color(i), part: i });
        }
        let cg = pose.apply(part.mass.center_of_gravity);
        labels.push((i + 1, cg));
        markers.push(Marker { position: cg, color: [200, 0, 0] });
    }
    Scene {
        solids,
        markers,
        floor: floor.polygon.iter().map(|p| DVec3::new(p.x, p.y, 0.0)).collect(),
        title: format!(
            "{} x {}: w = {}, height {:.1} mm, total cost {:.1}",
            plan.parts.len(),
            part.name,
            plan.options.w,
            plan.height,
            plan.total_cost
        ),
        labels,
    }
}

fn report_html(part: &Part, plan: &Plan, seconds: f64, svg_text: &str) -> String {
    let esc = |s: &str| s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;");
    let mut rows = String::new();
    for p in &plan.parts {
        rows.push_str(&format!(
            "<tr><td>{}</td><td>{:.2}, {:.2}, {:.2}</td><td>{:.1}</td><td>{}</td><td>{}</td><td>{:.2}</td><td>{:.2}</td><td>{}</td><td>{:.1}</td><td>{}</td></tr>\n",
            p.index + 1,
            p.position[0],
            p.position[1],
            p.position[2],
            p.theta_deg,
            p.resting_pose,
            p.stage,
            p.cost,
            p.cg_height,
            p.stability_margin.map_or("-".into(), |m| format!("{m:.2}")),
            p.grasp_radius,
            p.contacts.len()
        ));
    }
    format!(
        r#"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>stackplan: {name}</title>
<style>body{{font-family:sans-serif;margin:2em}}table{{border-collapse:collapse}}td,th{{border:1px solid #ccc;padding:3px 8px;text-align:right}}</style>
</head><body>
<h1>Stacking plan: {placed} x {name}</h1>
<p id="summary">{status}. Height {height:.1} mm, footprint {fx:.1} x {fy:.1} mm, total cost {cost:.1} (w = {w}),
clearance {clearance} mm, whole stack stable: {stable}. Planned in {seconds:.1} s
({searches} placement searches, {checked} candidates checked, {pairs} component pairs evaluated).</p>
<h2>Pictures</h2>
<p><img src="stack.png" alt="the stack: isometric, top and side views" width="1080"></p>
<details><summary>SVG</summary>{svg}</details>
<p>3-D model: <a href="stack.glb">stack.glb</a> (any glTF viewer). Plan: <a href="plan.json">plan.json</a>
(a stack file: <code>stackplan check plan.json</code>).</p>
<h2>Parts</h2>
<table id="parts"><tr><th>#</th><th>position (mm)</th><th>theta (deg)</th><th>pose</th><th>stage</th><th>cost</th><th>c.g. height</th><th>margin</th><th>grasp radius</th><th>contacts</th></tr>
{rows}</table>
</body></html>
"#,
        name = esc(&part.name),
        placed = plan.parts.len(),
        status = esc(plan.stopped.as_deref().unwrap_or("All parts placed")),
        height = plan.height,
        fx = plan.footprint[1][0] - plan.footprint[0][0],
        fy = plan.footprint[1][1] - plan.footprint[0][1],
        cost = plan.total_cost,
        w = plan.options.w,
        clearance = plan.options.clearance,
        stable = plan.stack_stable,
        seconds = seconds,
        searches = plan.stats.searches,
        checked = plan.stats.candidates_checked,
        pairs = plan.stats.pairs_evaluated,
        svg = svg_text,
        rows = rows,
    )
}
