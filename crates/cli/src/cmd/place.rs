//! `stackplan place PART --stack STACK.json [...]`: the best interference-free placements of one part in a stack
//! (the placement search of `stackplan-planner`, \[A\] sections V-VI).
//!
//! Output: `{"placements": [{"position", "rotation", "theta_deg", "resting_pose", "cost", "contacts"}...],
//! "exhausted": null | "empty_omega" | "fits_nowhere", "stats": {...}}` (`--json`), or a short text summary.

use crate::Outcome;
use crate::input::{PartArgs, load_part};
use crate::output;
use anyhow::{Context, bail};
use serde::Serialize;
use stackplan::planner::{Cost, FloorVolume, PlacedPart, PlacementRequest, PlacementResult, place, thetas_with_step};
use stackplan_geom::Part;
use stackplan_geom::io::stack::{StackFile, read_stack_with};
use stackplan_geom::{DVec2, DVec3};
use std::path::PathBuf;

/// Arguments of `place`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The part to place.
    #[command(flatten)]
    pub part: PartArgs,
    /// The stack file (`{"part": ..., "placements": [...]}`).
    #[arg(long)]
    pub stack: PathBuf,
    /// Rectangular floor area `X0,Y0,X1,Y1` (mm). Default: the stack's footprint grown by twice the part's diagonal.
    #[arg(long, conflicts_with = "floor_polygon", value_parser = parse_floor, allow_hyphen_values = true)]
    pub floor: Option<[f64; 4]>,
    /// Convex floor polygon: a JSON file with `[[x, y], ...]` (counter-clockwise) or `{"polygon": [[x, y], ...]}`.
    #[arg(long)]
    pub floor_polygon: Option<PathBuf>,
    /// Maximum stack height (mm). Default: the stack's top plus twice the part's diagonal.
    #[arg(long)]
    pub height: Option<f64>,
    /// Weight w, from 0 to 1, of the cost: 0 puts the part low, spreading the stack on the floor; 1 keeps the
    /// footprint small, building columns [default: 0.5, as in plan]. Not with --target.
    #[arg(long, conflicts_with = "target")]
    pub w: Option<f64>,
    /// Origin (x0, y0, z0) of cost (1) `X,Y,Z` (default: the mean of the floor polygon's corners at z = 0; not the
    /// area centroid, which can differ for a --floor-polygon).
    #[arg(long, conflicts_with = "target", value_parser = parse_point, allow_hyphen_values = true)]
    pub origin: Option<[f64; 3]>,
    /// Minimise the squared distance of the part's c.g. to `X,Y,Z` instead of cost (1).
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    pub target: Option<[f64; 3]>,
    /// Step of the turns about the vertical axis tried (degrees, 0.01 to 360).
    #[arg(long, value_name = "DEG", default_value_t = crate::input::DEFAULT_DTHETA_DEG)]
    pub dtheta_deg: f64,
    /// Minimum distance to the stack's parts in every direction (mm). The default differs from plan's 5 because
    /// this clearance is a distance in space, not only horizontal: any other value keeps the part off the parts it
    /// would rest on.
    #[arg(long, value_name = "MM", default_value_t = 0.0)]
    pub clearance: f64,
    /// Require a free vertical path from above (top-down insertion).
    #[arg(long)]
    pub insertion: bool,
    /// Fix the part's p_z (2-D search over p_x, p_y).
    #[arg(long, allow_hyphen_values = true)]
    pub fixed_z: Option<f64>,
    /// Number of placements (best first, one per free-space cell).
    #[arg(long, default_value_t = 1)]
    pub k: usize,
    /// JSON output.
    #[arg(long)]
    pub json: bool,
}

fn parse_numbers<const N: usize>(s: &str) -> Result<[f64; N], String> {
    let v: Vec<f64> =
        s.split(',').map(|x| x.trim().parse::<f64>().map_err(|e| format!("{x:?}: {e}"))).collect::<Result<_, _>>()?;
    let n = v.len();
    v.try_into().map_err(|_| format!("expected {N} comma-separated numbers, got {n}"))
}

fn parse_floor(s: &str) -> Result<[f64; 4], String> {
    parse_numbers::<4>(s)
}

fn parse_point(s: &str) -> Result<[f64; 3], String> {
    parse_numbers::<3>(s)
}

#[derive(serde::Deserialize)]
#[serde(untagged)]
enum PolygonFile {
    Bare(Vec<[f64; 2]>),
    Wrapped { polygon: Vec<[f64; 2]> },
}

#[derive(Debug, Serialize)]
struct Output<'a> {
    placements: &'a [stackplan::planner::Placement],
    exhausted: Option<stackplan::planner::NoPlacement>,
    stats: &'a stackplan::planner::PlacementStats,
}

/// Runs `place`.
pub fn run(args: &Args) -> anyhow::Result<Outcome> {
    let part = load_part(&args.part)?;
    let stack_file = read_stack_with(&args.stack, &crate::input::read_options(args.part.decomposition()))?;
    let result = search(args, &part, &stack_file)?;
    if args.json {
        output::print_json(&placements_json(&result)?)?;
    } else {
        let unit = if args.target.is_some() { "mm^2 (squared distance to the target)" } else { "mm^2" };
        let mut text = String::new();
        for (i, p) in result.placements.iter().enumerate() {
            text.push_str(&format!(
                "placement {}: position ({:.3}, {:.3}, {:.3}) mm, turn {:.1} deg, cost {:.6} {unit}, {} contacts\n",
                i + 1,
                p.position[0],
                p.position[1],
                p.position[2],
                p.theta_deg,
                p.cost,
                p.contacts.len()
            ));
        }
        if let Some(reason) = result.exhausted {
            text.push_str(&format!("found {} of {} placement(s): {reason:?}\n", result.placements.len(), args.k));
        }
        let s = &result.stats;
        text.push_str(&format!(
            "orientations {} (searched {}), component pairs evaluated {} of {}, search nodes {}, {:.1} ms\n",
            s.orientations_requested,
            s.orientations_searched,
            s.pairs_evaluated,
            s.total_pairs,
            s.nodes_expanded,
            s.time_total_ms
        ));
        output::print_text(&text)?;
    }
    Ok(if result.placements.is_empty() { Outcome::ChecksFailed } else { Outcome::Success })
}

/// The placement search of `place` for `part` in the stack of `stack_file` with the options of `args` (its part and
/// stack name them in messages): shared with the Python package's `place`.
pub fn search(args: &Args, part: &Part, stack_file: &StackFile) -> anyhow::Result<PlacementResult> {
    crate::input::check_dtheta_deg(args.dtheta_deg)?;
    let check_lengths = crate::input::check_lengths;
    if let Some(floor) = &args.floor {
        check_lengths("--floor", floor)?;
    }
    if let Some(height) = args.height {
        check_lengths("--height", &[height])?;
    }
    if let Some(origin) = &args.origin {
        check_lengths("--origin", origin)?;
    }
    if let Some(target) = &args.target {
        check_lengths("--target", target)?;
    }
    if let Some(z) = args.fixed_z {
        check_lengths("--fixed-z", &[z])?;
    }
    check_lengths("--clearance", &[args.clearance])?;
    let diag = {
        let (lo, hi) = part.aabb();
        (hi - lo).length()
    };
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for pose in &stack_file.placements {
        for v in stack_file.part.all_vertices() {
            let w = pose.apply(v);
            lo = lo.min(w);
            hi = hi.max(w);
        }
    }
    if stack_file.placements.is_empty() {
        lo = DVec3::ZERO;
        hi = DVec3::ZERO;
    }
    let polygon: Vec<DVec2> = if let Some(path) = &args.floor_polygon {
        let bytes = std::fs::read(path).with_context(|| format!("reading the floor polygon {}", path.display()))?;
        let file: PolygonFile = serde_json::from_slice(&bytes)
            .with_context(|| format!("{}: expected [[x, y], ...] or {{\"polygon\": [[x, y], ...]}}", path.display()))?;
        let pts = match file {
            PolygonFile::Bare(p) | PolygonFile::Wrapped { polygon: p } => p,
        };
        check_lengths(&format!("{}: corners", path.display()), pts.as_flattened())?;
        pts.into_iter().map(|[x, y]| DVec2::new(x, y)).collect()
    } else if let Some([x0, y0, x1, y1]) = args.floor {
        if !(x1 > x0 && y1 > y0) {
            bail!("--floor needs X0 < X1 and Y0 < Y1, got {x0},{y0},{x1},{y1}");
        }
        FloorVolume::rectangle(x0, y0, x1, y1, 1.0).polygon
    } else {
        let m = 2.0 * diag;
        FloorVolume::rectangle(lo.x - m, lo.y - m, hi.x + m, hi.y + m, 1.0).polygon
    };
    let height = args.height.unwrap_or(hi.z.max(0.0) + 2.0 * diag);
    let floor = FloorVolume { polygon, height };
    let stack: Vec<PlacedPart<'_>> =
        stack_file.placements.iter().map(|pose| PlacedPart { part: &stack_file.part, pose: *pose }).collect();
    let mut request = PlacementRequest::new(part, stack, floor.clone());
    request.thetas = thetas_with_step(args.dtheta_deg.to_radians()).context("--dtheta-deg")?;
    request.clearance = args.clearance;
    request.insertion = args.insertion;
    request.fixed_z = args.fixed_z;
    request.k = args.k;
    request.cost = match args.target {
        Some(t) => Cost::Target { target: DVec3::from_array(t) },
        None => Cost::Stacking {
            w: args.w.unwrap_or(crate::input::DEFAULT_W),
            origin: args.origin.map(DVec3::from_array).unwrap_or_else(|| floor.centre()),
        },
    };
    let floor_source = match (&args.floor_polygon, &args.floor) {
        (Some(path), _) => format!("the floor polygon of {}", path.display()),
        (None, Some(_)) => "--floor".to_string(),
        (None, None) => "the default floor".to_string(),
    };
    place(&request).with_context(|| format!("placing {} on {floor_source}", args.part.part))
}

/// The JSON of `place --json` (radians named `_rad`).
pub fn placements_json(result: &PlacementResult) -> anyhow::Result<serde_json::Value> {
    let mut json = serde_json::to_value(Output {
        placements: &result.placements,
        exhausted: result.exhausted,
        stats: &result.stats,
    })?;
    output::rename_key(&mut json, &["placements", "*", "theta"], "theta_rad");
    Ok(json)
}
