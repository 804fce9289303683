//! `stackplan interference MOVING FIXED --position X,Y,Z [--theta-deg T] [--fixed-pose POSE.json] [--clearance MM]
//! [--json]`: the convex component pairs whose interiors overlap (penetrating), whose boundaries touch, or (with a
//! clearance) that are closer than the clearance (\[A\] eq. 6-8).

use crate::Outcome;
use crate::input::{PartPair, load_pair};
use crate::output;
use anyhow::Context;
use serde::Serialize;
use stackplan::cspace::interference::{PairContact, PlacedScene};
use stackplan::geom::{PlacedPart, Pose};
use stackplan_geom::{DMat3, DVec3};
use std::fmt::Write as _;
use std::path::PathBuf;

/// Arguments of `interference`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The moving part (file or `example:NAME`).
    pub moving: String,
    /// The fixed part (file or `example:NAME`).
    pub fixed: String,
    /// Position of the moving part `X,Y,Z` (mm).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub position: String,
    /// Rotation of the moving part about world z (degrees; any finite angle, reduced exactly modulo 360), applied
    /// before the translation.
    #[arg(long, default_value_t = 0.0)]
    pub theta_deg: f64,
    /// Pose of the fixed part: JSON `{"position": [x, y, z], "rotation": [[row 0], [row 1], [row 2]]}`.
    #[arg(long, value_name = "POSE.json")]
    pub fixed_pose: Option<PathBuf>,
    /// Also report separated pairs closer than this (mm). The default differs from plan's 5 because this is a
    /// question, not a robot's tolerance: 0 reports penetrating and touching pairs only.
    #[arg(long, value_name = "MM", default_value_t = 0.0)]
    pub clearance: f64,
    /// Split concave sheet-metal faces by plain triangulation (the seed's component counts).
    #[arg(long)]
    pub triangulate: bool,
    /// JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// One pair in the JSON.
#[derive(Debug, Serialize)]
pub struct PairJson {
    /// Component of the moving part.
    pub moving_piece: usize,
    /// Component of the fixed part.
    pub fixed_piece: usize,
    /// `penetrating`, `touching` or `separated` (closer than the clearance).
    pub contact: &'static str,
    /// Penetration depth (mm) for `penetrating`: the minimum translation distance.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub depth: Option<f64>,
    /// Signed gap (mm) for `touching` (within the tolerance of 0) and `separated` (exact distance).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gap: Option<f64>,
}

/// The whole output.
#[derive(Debug, Serialize)]
pub struct InterferenceJson {
    /// Rotation of the moving part about z (degrees).
    pub theta_deg: f64,
    /// Position of the moving part (mm).
    pub position: [f64; 3],
    /// Clearance (mm).
    pub clearance: f64,
    /// Length tolerance used for touching (mm).
    pub tolerance: f64,
    /// Number of penetrating pairs.
    pub penetrating: usize,
    /// Number of touching pairs.
    pub touching: usize,
    /// The pairs, sorted by (moving_piece, fixed_piece).
    pub pairs: Vec<PairJson>,
}

fn parse_position(s: &str) -> anyhow::Result<DVec3> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("--position expects X,Y,Z, got {s:?}"))?;
    anyhow::ensure!(v.len() == 3 && v.iter().all(|x| x.is_finite()), "--position expects three finite numbers X,Y,Z");
    Ok(DVec3::new(v[0], v[1], v[2]))
}

/// Runs `interference`.
pub fn run(args: &Args) -> anyhow::Result<Outcome> {
    anyhow::ensure!(args.theta_deg.is_finite(), "--theta-deg must be finite");
    anyhow::ensure!(args.clearance.is_finite() && args.clearance >= 0.0, "--clearance must be a non-negative number");
    let position = parse_position(&args.position)?;
    let PartPair { moving, fixed, fixed_pose, .. } =
        load_pair(&args.moving, &args.fixed, args.triangulate, args.fixed_pose.as_deref(), None)?;
    let (fixed_rotation, fixed_position) = (fixed_pose.rotation, fixed_pose.position);
    let scene =
        PlacedScene::new(&[PlacedPart::new(&fixed, Pose { rotation: fixed_rotation, position: fixed_position })]);
    let rotation = DMat3::from_rotation_z(stackplan_geom::pose::radians_mod_turn(args.theta_deg));
    let found = scene.interference_pairs(&moving, rotation, position, args.clearance);
    let pairs: Vec<PairJson> = found
        .iter()
        .map(|p| {
            let (contact, depth, gap) = match p.contact {
                PairContact::Penetrating { depth } => ("penetrating", Some(depth), None),
                PairContact::Touching { gap } => ("touching", None, Some(gap)),
                PairContact::Separated { gap } => ("separated", None, Some(gap)),
            };
            PairJson { moving_piece: p.moving_piece, fixed_piece: p.fixed_piece, contact, depth, gap }
        })
        .collect();
    let (lo, hi) = moving.aabb();
    let tolerance = scene.tolerance().linear.max(stackplan_geom::Tolerance::for_scale((hi - lo).length()).linear);
    let json = InterferenceJson {
        theta_deg: args.theta_deg,
        position: position.to_array(),
        clearance: args.clearance,
        tolerance,
        penetrating: pairs.iter().filter(|p| p.contact == "penetrating").count(),
        touching: pairs.iter().filter(|p| p.contact == "touching").count(),
        pairs,
    };
    if args.json {
        output::print_json(&json)?;
    } else {
        let mut text = format!(
            "{} penetrating, {} touching pairs (pieces are indexed from 0, as in the JSON)\n",
            json.penetrating, json.touching
        );
        for p in &json.pairs {
            let (what, amount) = match (p.depth, p.gap) {
                (Some(depth), _) => ("depth", depth),
                (None, Some(gap)) => ("gap", gap),
                (None, None) => ("gap", 0.0),
            };
            let _ = writeln!(
                text,
                "moving piece {} / fixed piece {}: {} ({what} {amount:.6} mm)",
                p.moving_piece, p.fixed_piece, p.contact
            );
        }
        output::print_text(&text)?;
    }
    Ok(Outcome::Success)
}
