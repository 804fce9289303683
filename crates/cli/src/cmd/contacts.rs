//! `stackplan contacts MOVING FIXED --t-min X,Y,Z,RX,RY,RZ --t-max ... [--offset X,Y,Z] [--seed S]
//! [--population P] [--generations G] [--json] [--dot F]`: the assembly contact state graph of the moving part
//! against the fixed part within box bounds on `t = (x, y, z, rx, ry, rz)` (\[P\] Pan & Schimmels 2004). Angles in
//! the bounds are in degrees; the moving part's own origin is its reference point, `R = Rz Ry Rx`.

use crate::Outcome;
use crate::input::{PartPair, load_pair};
use crate::output;
use anyhow::Context;
use stackplan::contact_states::acsg::{Acsg, AcsgSettings, generate};
use stackplan::contact_states::criteria::ContactPart;
use stackplan::contact_states::ga::{GaSettings, MAX_GA_SIZE};
use stackplan::contact_states::pose::ConfigBox;
use stackplan_geom::{DMat3, DVec3, Part, PartOrigin};
use std::path::PathBuf;

/// Arguments of `contacts`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The moving part B (file or `example:NAME`).
    pub moving: String,
    /// The fixed part A (file or `example:NAME`).
    pub fixed: String,
    /// Lower bounds `X,Y,Z,RX,RY,RZ` (mm, degrees; rotations at most 360 in magnitude).
    #[arg(long, value_name = "X,Y,Z,RX,RY,RZ", allow_hyphen_values = true)]
    pub t_min: String,
    /// Upper bounds `X,Y,Z,RX,RY,RZ` (mm, degrees).
    #[arg(long, value_name = "X,Y,Z,RX,RY,RZ", allow_hyphen_values = true)]
    pub t_max: String,
    /// Translation applied to the fixed part first, to express it in the moving part's nominal frame (mm).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub offset: Option<String>,
    /// GA seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// GA population (4 to 100000; population x (generations + 1) at most 10 million).
    #[arg(long, default_value_t = GaSettings::default().population)]
    pub population: usize,
    /// GA generations (at most 100000; population x (generations + 1) at most 10 million).
    #[arg(long, default_value_t = GaSettings::default().generations)]
    pub generations: usize,
    /// Split concave sheet-metal faces by plain triangulation.
    #[arg(long)]
    pub triangulate: bool,
    /// The whole graph as JSON on stdout (see crates/contact-states/README.md).
    #[arg(long)]
    pub json: bool,
    /// Write the graph in Graphviz DOT to this file.
    #[arg(long, value_name = "FILE")]
    pub dot: Option<PathBuf>,
}

fn parse_list(s: &str, n: usize, what: &str) -> anyhow::Result<Vec<f64>> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("{what} must be {n} comma-separated numbers, got {s:?}"))?;
    anyhow::ensure!(v.len() == n && v.iter().all(|x| x.is_finite()), "{what} must be {n} finite numbers, got {s:?}");
    Ok(v)
}

/// The largest rotation bound in magnitude (degrees): a full turn either way. A bound is the end of a range, not an
/// angle that could be reduced modulo 360; beyond a turn the range repeats orientations, and at huge magnitudes the
/// conversion to radians alone is off by whole degrees.
pub const MAX_ROTATION_BOUND_DEG: f64 = 360.0;

fn config(s: &str, what: &str) -> anyhow::Result<[f64; 6]> {
    let v = parse_list(s, 6, what)?;
    crate::input::check_lengths(&format!("{what} (X,Y,Z)"), &v[..3])?;
    if let Some(r) = v[3..].iter().find(|r| r.abs() > MAX_ROTATION_BOUND_DEG) {
        anyhow::bail!(
            "{what} (RX,RY,RZ): {} is beyond {MAX_ROTATION_BOUND_DEG} degrees in magnitude",
            crate::input::short_number(*r)
        );
    }
    Ok([v[0], v[1], v[2], v[3].to_radians(), v[4].to_radians(), v[5].to_radians()])
}

/// Runs the command.
pub fn run(args: &Args) -> anyhow::Result<Outcome> {
    let PartPair { moving, fixed, .. } = load_pair(&args.moving, &args.fixed, args.triangulate, None, None)?;
    let graph = contact_graph(args, &moving, fixed)?;
    if let Some(path) = &args.dot {
        output::write_atomic(path, graph.to_dot().as_bytes())?;
        output::print_wrote(&[path], args.json)?;
    }
    if args.json {
        output::print_json(&graph)?;
    } else {
        output::print_text(&contacts_text(&graph))?;
    }
    Ok(Outcome::Success)
}

/// The assembly contact state graph of `moving` against `fixed` with the options of `args` (its part names name
/// them in messages): shared with the Python package's `contacts`.
pub fn contact_graph(args: &Args, moving: &Part, mut fixed: Part) -> anyhow::Result<Acsg> {
    anyhow::ensure!(
        (4..=MAX_GA_SIZE).contains(&args.population),
        "--population must lie in 4..={MAX_GA_SIZE}, got {}",
        args.population
    );
    anyhow::ensure!(
        args.generations <= MAX_GA_SIZE,
        "--generations must be at most {MAX_GA_SIZE}, got {}",
        args.generations
    );
    let bounds = ConfigBox::new(config(&args.t_min, "--t-min")?, config(&args.t_max, "--t-max")?)
        .context("--t-min / --t-max")?;
    if let Some(o) = &args.offset {
        let v = parse_list(o, 3, "--offset")?;
        crate::input::check_lengths("--offset", &v)?;
        let shift = DVec3::new(v[0], v[1], v[2]);
        let components = fixed.components().iter().map(|c| c.transformed(DMat3::IDENTITY, shift)).collect();
        fixed = Part::from_components(fixed.name.clone(), components, fixed.density(), PartOrigin::ConvexPieces)?;
    }
    let moving = ContactPart::from_part(moving).with_context(|| format!("surface of {}", args.moving))?;
    let fixed = ContactPart::from_part(&fixed).with_context(|| format!("surface of {}", args.fixed))?;
    let settings = AcsgSettings {
        ga: GaSettings {
            population: args.population,
            generations: args.generations,
            seed: args.seed,
            ..GaSettings::default()
        },
        ..AcsgSettings::default()
    };
    // the GA's effort per search and per graph is bounded; a request beyond it names these options
    settings.ga.check().context("--population / --generations")?;
    generate(&fixed, &moving, bounds, settings).context("--population / --generations")
}

/// The text output of `contacts`: the counts, then a table of the states that were searched (the library's
/// `Acsg::extremal_table` in the units people read: mm and degrees).
pub fn contacts_text(graph: &stackplan::contact_states::acsg::Acsg) -> String {
    use std::fmt::Write as _;
    let per_level = graph.counts_per_level();
    let total: usize = per_level.iter().sum();
    let levels: Vec<String> = per_level.iter().enumerate().skip(1).map(|(k, n)| format!("{n} at level {k}")).collect();
    let mut text = format!(
        "{total} feasible contact states of {} evaluated ({}; the level is the number of principal contacts)\n",
        graph.states.len(),
        if levels.is_empty() { "none".to_string() } else { levels.join(", ") }
    );
    let _ = writeln!(
        text,
        "{:<32} {:>11} {:<11} {:<62} {:<62}",
        "state", "objective", "feasibility", "lowest x y z (mm) rx ry rz (deg)", "highest x y z (mm) rx ry rz (deg)"
    );
    let fmt = |b: &[f64; 6]| {
        (0..6)
            .map(|k| if k < 3 { format!("{:.4}", b[k]) } else { format!("{:.3}", b[k].to_degrees()) })
            .collect::<Vec<_>>()
            .join(" ")
    };
    for r in graph.states.iter().filter(|r| r.pruned.is_none()) {
        let (lo, hi) = match &r.range {
            Some(b) => (fmt(&b.min), fmt(&b.max)),
            None => (String::new(), String::new()),
        };
        let objective = r.objective.map_or("-".to_string(), |o| format!("{o:.3e}"));
        let feasibility = if r.feasible { "feasible" } else { "infeasible" };
        let name = if r.name.is_empty() { &r.label } else { &r.name };
        let _ = writeln!(text, "{name:<32} {objective:>11} {feasibility:<11} {lo:<62} {hi:<62}");
    }
    text
}
