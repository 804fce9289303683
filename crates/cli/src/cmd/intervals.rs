//! `stackplan intervals MOVING FIXED [--fixed-pose POSE.json] [--pair I,J] [--from-deg A] [--to-deg B] [--json]`:
//! the constant-structure orientation intervals of every convex pair (moving component rotating about world z
//! against a fixed component), with the event that ends each (\[A\] section IV, Appendix C).

use crate::Outcome;
use crate::input::{PartPair, load_pair};
use crate::output;
use serde::Serialize;
use stackplan::orient_interval::{Event, PairEvents, TurnInterval};

/// Arguments of `intervals`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The moving part (file or `example:NAME`); it rotates about world z.
    pub moving: String,
    /// The fixed part (file or `example:NAME`).
    pub fixed: String,
    /// Pose of the fixed part: JSON `{"position": [x, y, z], "rotation": [[row 0], [row 1], [row 2]]}`.
    #[arg(long, value_name = "POSE.json")]
    pub fixed_pose: Option<std::path::PathBuf>,
    /// Only this pair: moving component I, fixed component J.
    #[arg(long, value_name = "I,J")]
    pub pair: Option<String>,
    /// Only intervals reaching past this angle (degrees; the window [A, B] is moved by whole turns so that A lies
    /// in (-360, 360)).
    #[arg(long, default_value_t = 0.0)]
    pub from_deg: f64,
    /// Only intervals starting before this angle (degrees).
    #[arg(long, default_value_t = 360.0)]
    pub to_deg: f64,
    /// Split concave sheet-metal faces by plain triangulation (the seed's component counts).
    #[arg(long)]
    pub triangulate: bool,
    /// JSON output.
    #[arg(long)]
    pub json: bool,
}

/// JSON of one interval.
#[derive(Debug, Serialize)]
pub struct IntervalJson {
    /// Start (degrees, in [0, 360)); the same number as the previous interval's `end_deg`.
    pub start_deg: f64,
    /// End (degrees, > start; above 360 for the interval that wraps, whose end is the first start plus 360).
    pub end_deg: f64,
    /// Whether this is an event window (overlapping degenerate configurations) rather than a constant interval.
    pub degenerate: bool,
    /// The event that ends a constant interval, or the first event of a window: `{"kind", "angle_deg", features}`.
    pub event: Option<serde_json::Value>,
}

/// JSON of one pair.
#[derive(Debug, Serialize)]
pub struct PairJson {
    /// Component of the moving part.
    pub moving_piece: usize,
    /// Component of the fixed part.
    pub fixed_piece: usize,
    /// Number of event bands over the full turn.
    pub events: usize,
    /// The intervals overlapping the requested range, in order.
    pub intervals: Vec<IntervalJson>,
}

/// The whole output.
#[derive(Debug, Serialize)]
pub struct IntervalsJson {
    /// Per convex pair.
    pub pairs: Vec<PairJson>,
}

fn event_json(e: &Event) -> serde_json::Value {
    let mut v = serde_json::to_value(e.kind).unwrap_or(serde_json::Value::Null);
    if let Some(map) = v.as_object_mut() {
        map.insert("angle_deg".into(), serde_json::json!(e.angle.to_degrees()));
    }
    v
}

/// The window `[--from-deg, --to-deg]` moved by whole turns so that its start lies in `(-360, 360)` (the start
/// reduced exactly, `from % 360`, the end by the same shift up to rounding), or `None` when it spans a turn or more
/// (every interval overlaps it). An error names an option that is not finite, or a start beyond the end.
pub fn window(from_deg: f64, to_deg: f64) -> anyhow::Result<Option<(f64, f64)>> {
    anyhow::ensure!(from_deg.is_finite(), "--from-deg must be a finite angle in degrees, got {from_deg}");
    anyhow::ensure!(to_deg.is_finite(), "--to-deg must be a finite angle in degrees, got {to_deg}");
    anyhow::ensure!(from_deg <= to_deg, "--from-deg ({from_deg}) must not exceed --to-deg ({to_deg})");
    let length = to_deg - from_deg;
    if length >= 360.0 {
        return Ok(None);
    }
    let from = from_deg % 360.0;
    Ok(Some((from, from + length)))
}

/// The full-turn partition in degrees: `(start_deg, end_deg, interval)`, each boundary converted once, so that an
/// interval's end is bit for bit the next one's start (`PairEvents::full_turn` shares the boundaries the same way in
/// radians), and the last one's end is the first start plus 360 exactly: the first start, the one boundary that is
/// written both ways, is rounded to the precision of numbers in `[360, 720)` (by less than 3e-14 degree), so that
/// `end - 360` gives it back.
fn turn_in_degrees(turn: &[TurnInterval]) -> Vec<(f64, f64, &TurnInterval)> {
    let mut starts: Vec<f64> = turn.iter().map(|t| t.start.to_degrees()).collect();
    if let Some(first) = starts.first_mut() {
        // `(s + 360) - 360` is exact (Sterbenz), so the rounded `s` and `s + 360` are both doubles
        *first = (*first + 360.0) - 360.0;
    }
    (0..turn.len())
        .map(|k| {
            let end = match starts.get(k + 1) {
                Some(&next) => next,
                None => starts[0] + 360.0,
            };
            (starts[k], end, &turn[k])
        })
        .collect()
}

/// Runs `intervals`.
pub fn run(args: &Args) -> anyhow::Result<Outcome> {
    let window = window(args.from_deg, args.to_deg)?;
    let PartPair { moving, fixed, fixed_pose, only } =
        load_pair(&args.moving, &args.fixed, args.triangulate, args.fixed_pose.as_deref(), args.pair.as_deref())?;
    let (rotation, translation) = (fixed_pose.rotation, fixed_pose.position);
    let mut pairs = Vec::new();
    for (i, a) in moving.components().iter().enumerate() {
        for (j, b) in fixed.components().iter().enumerate() {
            if only.is_some_and(|p| p != (i, j)) {
                continue;
            }
            let placed = b.transformed(rotation, translation);
            let events = PairEvents::new(a, &placed);
            let mut intervals = Vec::new();
            let turn = events.full_turn();
            for (s, e, t) in turn_in_degrees(&turn) {
                // the interval or its copy one turn earlier or later overlaps the window (starting in (-360, 360))
                let overlaps =
                    window.is_none_or(|(from, to)| [-360.0, 0.0, 360.0].iter().any(|k| s + k < to && e + k > from));
                if overlaps {
                    intervals.push(IntervalJson {
                        start_deg: s,
                        end_deg: e,
                        degenerate: t.degenerate,
                        event: t.events.first().map(event_json),
                    });
                }
            }
            pairs.push(PairJson { moving_piece: i, fixed_piece: j, events: events.bands().len(), intervals });
        }
    }
    let out = IntervalsJson { pairs };
    if args.json {
        output::print_json(&out)?;
    } else {
        let mut text = String::new();
        for p in &out.pairs {
            text.push_str(&format!(
                "moving piece {} / fixed piece {} (indexed from 0): {} events\n",
                p.moving_piece, p.fixed_piece, p.events
            ));
            for t in p.intervals.iter().filter(|t| !t.degenerate) {
                let kind = t.event.as_ref().and_then(|e| e["kind"].as_str()).unwrap_or("none");
                text.push_str(&format!("  [{:10.6}, {:10.6}) deg  ends by {kind}\n", t.start_deg, t.end_deg));
            }
        }
        output::print_text(&text)?;
    }
    Ok(Outcome::Success)
}
