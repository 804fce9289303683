//! `stackplan plan [PART] [--count N] [--w W] [--floor X0,Y0,X1,Y1] [--height H] [--clearance MM] [--dtheta-deg D]
//! [--mu MU] [--cup-diameter MM] [--out DIR]`: a stacking plan for N identical parts, written as `plan.json` (a
//! stack file that `stackplan check` reads, with the plan's summary), `stack.svg`, `stack.png`, `build.svg`, `build.png`,
//! `stack.glb` and `report.html`. With no arguments it plans the built-in default example: 15 Channel parts, w = 0.5, 5 mm
//! clearance, into `out/`. (Not the Triangle part: with a horizontal clearance its nested copies would have to float
//! above the walls below, since it has no horizontal face to rest on; `--clearance 0` nests it.)

use crate::Outcome;
use crate::input::load_part_spec;
use crate::plan_files::write_plan_files;
use anyhow::{Context, bail};
use stackplan::planner::{FloorVolume, Plan, PlanOptions, stack_plan::plan_stack_with_progress};
use stackplan_geom::Part;
use std::path::PathBuf;

/// Arguments of `plan`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Part file or built-in example (`example:NAME`).
    #[arg(default_value = "example:channel")]
    pub part: String,
    /// Weight w, from 0 to 1, of the cost the planner minimises for each part: 0 spreads parts on the floor, keeping
    /// the centres of gravity low; 1 keeps the footprint small, building columns.
    #[arg(long, default_value_t = crate::input::DEFAULT_W)]
    pub w: f64,
    /// The planner's options.
    #[command(flatten)]
    pub planner: PlannerArgs,
    /// Output directory (created if missing).
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
}

/// What the weight w means, in words (`--w`'s help says the same).
pub const W_MEANING: &str =
    "0 spreads parts on the floor, keeping the centres of gravity low; 1 keeps the footprint small, building columns";

/// The planner's options, shared by `plan` and `sweep`.
#[derive(Debug, Clone, clap::Args)]
pub struct PlannerArgs {
    /// Number of parts.
    #[arg(long, default_value_t = 15)]
    pub count: usize,
    /// Floor rectangle X0,Y0,X1,Y1 (mm); default: a square of 3 part footprints plus 2 clearances, centred on 0.
    #[arg(long, value_name = "X0,Y0,X1,Y1", allow_hyphen_values = true)]
    pub floor: Option<String>,
    /// Maximum stack height (mm); default: 6 max(e_z, min(e_x, e_y)), with e_x, e_y, e_z the extents of the
    /// part's bounding box in its file coordinates (Channel, 200 x 102 x 51 mm: 612; Triangle: 6 x 195 = 1170).
    #[arg(long)]
    pub height: Option<f64>,
    /// Horizontal clearance between parts for the robot's positioning error (mm); parts may still rest on each
    /// other.
    #[arg(long, value_name = "MM", default_value_t = crate::input::DEFAULT_CLEARANCE_MM)]
    pub clearance: f64,
    /// Step of the turns about the vertical axis tried for each part (degrees, 0.01 to 360).
    #[arg(long, value_name = "DEG", default_value_t = crate::input::DEFAULT_DTHETA_DEG)]
    pub dtheta_deg: f64,
    /// Coulomb friction coefficient of the stability checks.
    #[arg(long, default_value_t = crate::input::DEFAULT_MU)]
    pub mu: f64,
    /// Suction cup diameter (mm).
    #[arg(long, value_name = "MM", default_value_t = crate::input::DEFAULT_CUP_DIAMETER_MM)]
    pub cup_diameter: f64,
    /// Interference-free candidates tested per part and stage (stage 2 after an accepted stage 1 tests every one
    /// cheaper than that part).
    #[arg(long, default_value_t = 8)]
    pub candidates: usize,
    /// Split concave sheet-metal faces by plain triangulation (the seed's component counts).
    #[arg(long)]
    pub triangulate: bool,
    /// Partitions of the placement search's orientations, searched in parallel (1 to 64; 1 is the sequential
    /// search). The first placement of every search is the exact optimum for any number; the plan depends on this
    /// number (ties and the open cells carried between searches), never on the thread count.
    #[arg(long, default_value_t = stackplan::planner::request::DEFAULT_PARTITIONS)]
    pub search_partitions: usize,
    /// Largest tilt from level of a face that holds the suction cup (degrees, 0 to 89): the cup approaches along the
    /// face's normal. Bent parts often rest with their largest face a degree or two off level.
    #[arg(long, value_name = "DEG", default_value_t = crate::input::DEFAULT_GRASP_TILT_DEG)]
    pub grasp_tilt_deg: f64,
    /// Seconds the plan may take (each plan, for several weights): past them the plan ends with the parts placed so
    /// far and says why. Default: no limit.
    #[arg(long, value_name = "SECONDS")]
    pub time_limit: Option<f64>,
    /// Search nodes one placement may take (per search partition): past them the plan ends with the parts placed
    /// so far and says why. The search's memory grows with its nodes: the default keeps it to a few GB.
    #[arg(long, value_name = "NODES", default_value_t = stackplan::planner::request::DEFAULT_NODE_BUDGET)]
    pub node_budget: usize,
}

fn parse_floor(s: &str) -> anyhow::Result<[f64; 4]> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>().with_context(|| format!("--floor: {x:?} is not a number")))
        .collect::<anyhow::Result<_>>()?;
    let [x0, y0, x1, y1] = v[..] else { bail!("--floor needs four numbers X0,Y0,X1,Y1, got {}", v.len()) };
    crate::input::check_lengths("--floor", &v)?;
    if !(x0 < x1 && y0 < y1) {
        bail!("--floor {s}: needs X0 < X1 and Y0 < Y1");
    }
    Ok([x0, y0, x1, y1])
}

/// Checks a weight w of cost (1) given by the command-line option `option` (`--w`, `--w-values`), which the error
/// names with the value.
pub fn check_w(option: &str, w: f64) -> anyhow::Result<()> {
    if !(0.0..=1.0).contains(&w) {
        bail!("{option} must lie in [0, 1], got {}", crate::input::short_number(w));
    }
    Ok(())
}

impl PlannerArgs {
    /// Checks the options that do not depend on the part, then reads the part.
    pub fn load_part(&self, spec: &str) -> anyhow::Result<Part> {
        self.check()?;
        load_part_spec(spec, crate::input::decomposition(self.triangulate))
    }

    /// Checks the options that do not depend on the part (the messages name the command-line options).
    pub fn check(&self) -> anyhow::Result<()> {
        if self.count == 0 {
            bail!("--count must be at least 1");
        }
        if !(1..=stackplan::planner::request::MAX_PARTITIONS).contains(&self.search_partitions) {
            bail!(
                "--search-partitions must lie in 1..={}, got {}",
                stackplan::planner::request::MAX_PARTITIONS,
                self.search_partitions
            );
        }
        crate::input::check_dtheta_deg(self.dtheta_deg)?;
        if let Some(height) = self.height {
            crate::input::check_lengths("--height", &[height])?;
        }
        crate::input::check_lengths("--clearance", &[self.clearance])?;
        crate::input::check_lengths("--cup-diameter", &[self.cup_diameter])?;
        if let Some(t) = self.time_limit {
            anyhow::ensure!(t.is_finite() && t > 0.0, "--time-limit must be a positive number of seconds, got {t}");
        }
        anyhow::ensure!(self.node_budget > 0, "--node-budget must be at least 1");
        crate::input::check_grasp_tilt(self.grasp_tilt_deg)?;
        Ok(())
    }

    /// The planner's options for `part` and weight `w` (the floor and height defaults scale with the part).
    pub fn options(&self, part: &Part, w: f64) -> anyhow::Result<PlanOptions> {
        let (lo, hi) = part.aabb();
        let size = hi - lo;
        let footprint = size.x.max(size.y);
        // three parts side by side with the clearance between them: the first part sits at the centre, so a square
        // part has room beside it only when the clearance is counted (a bad clearance is reported by the planner)
        let clearance = if self.clearance.is_finite() { self.clearance.max(0.0) } else { 0.0 };
        let half = 1.5 * footprint + clearance;
        let [x0, y0, x1, y1] = match &self.floor {
            Some(s) => parse_floor(s)?,
            None => {
                // the default grows with --clearance, which alone could carry it past the readers' range
                crate::input::check_lengths("the default floor (1.5 part sizes plus --clearance)", &[half])?;
                [-half, -half, half, half]
            }
        };
        let height = self.height.unwrap_or(6.0 * size.z.max(size.x.min(size.y)));
        let mut options = PlanOptions::new(self.count, FloorVolume::rectangle(x0, y0, x1, y1, height));
        options.w = w;
        options.clearance = self.clearance;
        options.dtheta = self.dtheta_deg.to_radians();
        options.mu = self.mu;
        options.cup_diameter = self.cup_diameter;
        options.tuning.candidates = self.candidates;
        options.tuning.partitions = self.search_partitions;
        options.tuning.node_budget = self.node_budget;
        options.grasp_tilt = self.grasp_tilt_deg.to_radians();
        options.time_limit = self.time_limit;
        // (the repeated search never asks for fewer than the user's own candidate count)
        options.tuning.max_candidates = options.tuning.max_candidates.max(self.candidates);
        Ok(options)
    }
}

/// Runs the planner; `progress(parts placed)` after every part. Returns the plan and the seconds it took; an error
/// when not even the first part could be placed.
pub fn run_planner(
    part: &Part,
    options: &PlanOptions,
    progress: &mut (dyn FnMut(usize) + Send),
) -> anyhow::Result<(Plan, f64)> {
    let started = std::time::Instant::now();
    let plan = plan_stack_with_progress(part, options, &mut |done, _| progress(done))?;
    let seconds = started.elapsed().as_secs_f64();
    if plan.parts.is_empty() {
        bail!("no part could be placed: {}", plan.stopped.as_deref().unwrap_or("unknown reason"));
    }
    Ok((plan, seconds))
}

/// Runs `plan`.
pub fn run(args: &Args) -> anyhow::Result<Outcome> {
    check_w("--w", args.w)?;
    let part = args.planner.load_part(&args.part)?;
    let options = args.planner.options(&part, args.w)?;
    let bar = indicatif::ProgressBar::new(options.count as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} planning {pos}/{len} parts [{elapsed_precise}] {wide_bar}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let planned = run_planner(&part, &options, &mut |done| bar.set_position(done as u64));
    bar.finish_and_clear();
    let (plan, seconds) = planned.with_context(|| format!("planning {}", args.part))?;

    write_plan_files(&args.out, &part, &plan, seconds)?;
    let [[x0, y0], [x1, y1]] = plan.footprint;
    crate::output::print_summary(&format!(
        "{} of {} parts placed ({}): height {:.1} mm, footprint {:.1} x {:.1} mm, total cost {:.1} mm^2, {:.1} s\n\
         wrote {}: plan.json, stack.svg, stack.png, build.svg, build.png, stack.glb, report.html\n",
        plan.parts.len(),
        options.count,
        plan.stopped.as_deref().unwrap_or("complete"),
        plan.height,
        x1 - x0,
        y1 - y0,
        plan.total_cost,
        seconds,
        args.out.display()
    ))?;
    if let Some(note) = crate::input::origin_note(&part.origin, part.mass().volume) {
        crate::output::print_summary(&format!("part {}: {note}\n", part.name))?;
    }
    if plan.stats.cells_unsolved > 0 {
        crate::output::print_summary(&format!(
            "note: {} free-space cells could not be solved and were skipped (stats.cells_unsolved): each part is the \
             cheapest of the positions found, not proven the cheapest of all\n",
            plan.stats.cells_unsolved
        ))?;
    }
    Ok(if plan.stopped.is_some() { Outcome::ChecksFailed } else { Outcome::Success })
}
