//! `stackplan cspace MOVING FIXED [--fixed-pose POSE.json] [--theta-deg T] [--extrapolate-from T0] [--pair I,J]
//! [--clearance MM] [--insertion] [--slice-z Z] [--json | --obj F | --svg F]`: the translational c-space obstacle of
//! every convex pair (\[A\] App. B); with `--extrapolate-from T0` each obstacle is built at `T0` and extrapolated to
//! `T` within its constant-structure interval (\[A\] IV-B, eq. 4), an error when `T` is outside that interval.
//!
//! Convention: the moving part's pose is the rotation about world z by `theta` applied to its file coordinates, then
//! the translation `p`; `p` is in the obstacle of a pair iff `normal . p <= offset` for every face of that pair.

use crate::Outcome;
use crate::input::{PartPair, load_pair};
use crate::output;
use anyhow::Context;
use serde::Serialize;
use stackplan::cspace::minkowski::{FaceKind, Feature, Obstacle, obstacle};
use stackplan::cspace::offset::{HalfSpaces, clearance, insertion, insertion_polytope, slice};
use stackplan::orient_interval::{ExtrapolateError, extrapolate_from};
use stackplan_geom::pose::radians_mod_turn;
use stackplan_geom::{ConvexPolytope, DMat3, DVec2, Plane};
use std::fmt::Write as _;
use std::path::PathBuf;

/// Arguments of `cspace`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The moving part (file or `example:NAME`).
    pub moving: String,
    /// The fixed part (file or `example:NAME`).
    pub fixed: String,
    /// Pose of the fixed part: JSON `{"position": [x, y, z], "rotation": [[row 0], [row 1], [row 2]]}`.
    #[arg(long, value_name = "POSE.json")]
    pub fixed_pose: Option<PathBuf>,
    /// Rotation of the moving part about world z (degrees; any finite angle, reduced exactly modulo 360).
    #[arg(long, default_value_t = 0.0)]
    pub theta_deg: f64,
    /// Build each obstacle at this angle (degrees, reduced modulo 360) and extrapolate it to --theta-deg (an error
    /// when --theta-deg is outside the obstacle's constant-structure interval around this angle).
    #[arg(long, value_name = "T0")]
    pub extrapolate_from: Option<f64>,
    /// Only this pair: moving component I, fixed component J.
    #[arg(long, value_name = "I,J")]
    pub pair: Option<String>,
    /// Grow every obstacle by this clearance (mm; mitred plane offset).
    #[arg(long, value_name = "MM")]
    pub clearance: Option<f64>,
    /// Also give the insertion obstacles (positions from which straight-down insertion is blocked).
    #[arg(long)]
    pub insertion: bool,
    /// Also give the slice of every obstacle at p_z = Z (mm; a convex polygon); the SVG draws this slice (default 0).
    #[arg(long, value_name = "Z")]
    pub slice_z: Option<f64>,
    /// Split concave sheet-metal faces by plain triangulation (the seed's component counts).
    #[arg(long)]
    pub triangulate: bool,
    /// JSON on stdout.
    #[arg(long, conflicts_with_all = ["obj", "svg"])]
    pub json: bool,
    /// Wavefront OBJ of the obstacles (insertion obstacles truncated 10% below the lowest obstacle with --insertion).
    #[arg(long, value_name = "F", conflicts_with = "svg")]
    pub obj: Option<PathBuf>,
    /// SVG of the obstacles' slices at --slice-z (default 0); clearance and insertion are not drawn.
    #[arg(long, value_name = "F")]
    pub svg: Option<PathBuf>,
}

/// One face in the JSON.
#[derive(Debug, Serialize)]
pub struct FaceJson {
    /// Unit outward normal.
    pub normal: [f64; 3],
    /// Offset: `normal . p <= offset` inside.
    pub offset: f64,
    /// Vertex indices, counter-clockwise seen from outside.
    pub vertices: Vec<usize>,
    /// `fixed_face`, `moving_face`, `edge_edge`, or a merged degenerate kind (`fixed_face_moving_edge`,
    /// `moving_face_fixed_edge`, `face_face`).
    pub kind: &'static str,
    /// Generating feature of the fixed component: `{"feature": "vertex"|"edge"|"face", "index": k}`.
    pub fixed_feature: Option<Feature>,
    /// Generating feature of the moving component.
    pub moving_feature: Option<Feature>,
}

/// A plane of an H-form in the JSON.
#[derive(Debug, Serialize)]
pub struct PlaneJson {
    /// Unit normal.
    pub normal: [f64; 3],
    /// Offset.
    pub offset: f64,
}

/// One convex pair in the JSON.
#[derive(Debug, Serialize)]
pub struct PairJson {
    /// Component of the moving part.
    pub moving_piece: usize,
    /// Component of the fixed part.
    pub fixed_piece: usize,
    /// Obstacle vertices.
    pub vertices: Vec<[f64; 3]>,
    /// `[i, j]` per vertex: vertex `j` of the (placed) fixed component minus the rotated vertex `i` of the moving one.
    pub vertex_pairs: Vec<[usize; 2]>,
    /// Faces.
    pub faces: Vec<FaceJson>,
    /// Volume of the obstacle (mm^3).
    pub volume: f64,
    /// With `--extrapolate-from`: the constant-structure interval `[start, end]` (degrees) the obstacle was
    /// extrapolated within.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub interval_deg: Option<[f64; 2]>,
    /// With `--clearance`: the grown obstacle's planes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub clearance_planes: Option<Vec<PlaneJson>>,
    /// With `--insertion`: the insertion obstacle's planes (unbounded below).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub insertion_planes: Option<Vec<PlaneJson>>,
    /// With `--slice-z`: the slice polygon `[[x, y], ...]`, counter-clockwise from above.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub slice: Option<Vec<[f64; 2]>>,
}

/// The whole output.
#[derive(Debug, Serialize)]
pub struct CspaceJson {
    /// Rotation of the moving part about z (degrees).
    pub theta_deg: f64,
    /// With `--extrapolate-from`: the angle (degrees) the obstacles were built at before extrapolation to `theta_deg`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub extrapolated_from_deg: Option<f64>,
    /// Clearance used (mm), if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub clearance: Option<f64>,
    /// Slice height, if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub slice_z: Option<f64>,
    /// Per convex pair.
    pub pairs: Vec<PairJson>,
}

fn planes_json(h: &HalfSpaces) -> Vec<PlaneJson> {
    h.planes.iter().map(plane_json).collect()
}

fn plane_json(p: &Plane) -> PlaneJson {
    PlaneJson { normal: p.normal.to_array(), offset: p.offset }
}

/// The obstacle of one convex pair.
#[derive(Debug)]
pub struct PairObstacle {
    /// Component of the moving part.
    pub moving_piece: usize,
    /// Component of the fixed part.
    pub fixed_piece: usize,
    /// The obstacle.
    pub obstacle: Obstacle,
    /// With `--extrapolate-from`: the constant-structure interval (degrees).
    pub interval_deg: Option<[f64; 2]>,
}

/// `--theta-deg` outside the constant-structure interval of the obstacle built at `--extrapolate-from`, in the
/// options' unit (the library reports radians).
#[derive(Debug, thiserror::Error)]
#[error(
    "--theta-deg {theta} is outside the constant-structure interval [{start}, {end}] degrees of the obstacle built at \
     --extrapolate-from {built_at}"
)]
pub struct OutsideInterval {
    /// The requested angle (degrees).
    pub theta: f64,
    /// Where the obstacle was built (degrees).
    pub built_at: f64,
    /// Interval start (degrees, around `built_at` reduced modulo 360, unwrapped: may be negative).
    pub start: f64,
    /// Interval end (degrees).
    pub end: f64,
}

/// The library's extrapolation error, with an angle outside the interval given in degrees ([`OutsideInterval`]):
/// the interval's ends converted, the two angles as the options gave them (`theta_deg`, `built_at_deg`).
fn in_degrees(e: ExtrapolateError, theta_deg: f64, built_at_deg: f64) -> anyhow::Error {
    // 7 decimals: event windows are a few 1e-6 degrees wide; the user's own angles print as given
    let deg = |rad: f64| (rad.to_degrees() * 1e7).round() / 1e7;
    match e {
        ExtrapolateError::OutsideInterval { start, end, .. } => anyhow::Error::new(OutsideInterval {
            theta: theta_deg,
            built_at: built_at_deg,
            start: deg(start),
            end: deg(end),
        }),
        other => anyhow::Error::new(other),
    }
}

/// The obstacles of the requested pairs.
pub fn obstacles(args: &Args) -> anyhow::Result<Vec<PairObstacle>> {
    anyhow::ensure!(args.theta_deg.is_finite(), "--theta-deg must be finite");
    anyhow::ensure!(args.extrapolate_from.is_none_or(f64::is_finite), "--extrapolate-from must be finite");
    if let Some(z) = args.slice_z {
        crate::input::check_lengths("--slice-z", &[z])?;
    }
    let PartPair { moving, fixed, fixed_pose, only } =
        load_pair(&args.moving, &args.fixed, args.triangulate, args.fixed_pose.as_deref(), args.pair.as_deref())?;
    let (fixed_rotation, fixed_position) = (fixed_pose.rotation, fixed_pose.position);
    let theta = radians_mod_turn(args.theta_deg);
    let rotation = DMat3::from_rotation_z(theta);
    let placed: Vec<ConvexPolytope> =
        fixed.components().iter().map(|c| c.transformed(fixed_rotation, fixed_position)).collect();
    let mut out = Vec::new();
    for (i, a) in moving.components().iter().enumerate() {
        for (j, b) in placed.iter().enumerate() {
            if only.is_some_and(|o| o != (i, j)) {
                continue;
            }
            let what = || format!("obstacle of moving piece {i} / fixed piece {j}");
            let (o, interval) = match args.extrapolate_from {
                None => (obstacle(a, rotation, b).with_context(what)?, None),
                Some(t0) => {
                    let (o, iv) = extrapolate_from(a, b, radians_mod_turn(t0), theta)
                        .map_err(|e| in_degrees(e, args.theta_deg, t0))
                        .with_context(what)?;
                    (o, Some([iv.start.to_degrees(), iv.end.to_degrees()]))
                }
            };
            out.push(PairObstacle { moving_piece: i, fixed_piece: j, obstacle: o, interval_deg: interval });
        }
    }
    Ok(out)
}

fn pair_json(args: &Args, pair: &PairObstacle) -> PairJson {
    let (i, j, o) = (pair.moving_piece, pair.fixed_piece, &pair.obstacle);
    let c = o.polytope();
    let faces = c
        .faces()
        .iter()
        .zip(o.face_kinds())
        .map(|(f, k): (_, &FaceKind)| FaceJson {
            normal: f.plane.normal.to_array(),
            offset: f.plane.offset,
            vertices: f.vertices.to_vec(),
            kind: k.name(),
            fixed_feature: k.fixed_feature(),
            moving_feature: k.moving_feature(),
        })
        .collect();
    PairJson {
        moving_piece: i,
        fixed_piece: j,
        vertices: c.vertices().iter().map(|v| v.to_array()).collect(),
        vertex_pairs: o.vertex_pairs().to_vec(),
        faces,
        volume: c.volume(),
        interval_deg: pair.interval_deg,
        clearance_planes: args.clearance.map(|d| planes_json(&clearance(o, d))),
        insertion_planes: args.insertion.then(|| planes_json(&insertion(c))),
        slice: args.slice_z.map(|z| slice(c, z).iter().map(|p| p.to_array()).collect()),
    }
}

/// Runs `cspace`.
pub fn run(args: &Args) -> anyhow::Result<Outcome> {
    if let Some(d) = args.clearance {
        anyhow::ensure!(d.is_finite() && d >= 0.0, "--clearance must be a non-negative number of mm");
    }
    let obstacles = obstacles(args)?;
    if let Some(path) = &args.obj {
        output::write_atomic(path, obj_text(args, &obstacles)?.as_bytes())?;
        output::print_wrote(&[path], false)?;
        return Ok(Outcome::Success);
    }
    if let Some(path) = &args.svg {
        output::write_atomic(path, svg_text(args, &obstacles).as_bytes())?;
        output::print_wrote(&[path], false)?;
        return Ok(Outcome::Success);
    }
    let json = CspaceJson {
        theta_deg: args.theta_deg,
        extrapolated_from_deg: args.extrapolate_from,
        clearance: args.clearance,
        slice_z: args.slice_z,
        pairs: obstacles.iter().map(|pair| pair_json(args, pair)).collect(),
    };
    if args.json {
        output::print_json(&json)?;
    } else {
        let mut text = format!(
            "theta = {} deg, {} convex pairs (pieces are indexed from 0, as in --pair and the JSON)\n",
            args.theta_deg,
            json.pairs.len()
        );
        for p in &json.pairs {
            let _ = writeln!(
                text,
                "moving piece {} / fixed piece {}: {} vertices, {} faces, volume {:.6} mm^3",
                p.moving_piece,
                p.fixed_piece,
                p.vertices.len(),
                p.faces.len(),
                p.volume
            );
        }
        output::print_text(&text)?;
    }
    Ok(Outcome::Success)
}

fn obj_text(args: &Args, obstacles: &[PairObstacle]) -> anyhow::Result<String> {
    let floor = obstacles
        .iter()
        .map(|PairObstacle { obstacle: o, .. }| {
            let (lo, hi) = o.polytope().aabb();
            lo.z - 0.1 * (hi.z - lo.z).max(1.0)
        })
        .fold(f64::INFINITY, f64::min);
    let mut text = String::from("# stackplan c-space obstacles\n");
    let mut base = 1;
    for PairObstacle { moving_piece: i, fixed_piece: j, obstacle: o, .. } in obstacles {
        let truncated;
        let poly = if args.insertion {
            truncated = insertion_polytope(o.polytope(), floor).context("truncated insertion obstacle")?;
            &truncated
        } else {
            o.polytope()
        };
        let _ = writeln!(text, "o pair_{i}_{j}");
        for v in poly.vertices() {
            let _ = writeln!(text, "v {} {} {}", v.x, v.y, v.z);
        }
        for f in poly.faces() {
            let idx: Vec<String> = f.vertices.iter().map(|v| (v + base).to_string()).collect();
            let _ = writeln!(text, "f {}", idx.join(" "));
        }
        base += poly.vertices().len();
    }
    Ok(text)
}

fn svg_text(args: &Args, obstacles: &[PairObstacle]) -> String {
    let z = args.slice_z.unwrap_or(0.0);
    let polygons: Vec<(usize, usize, Vec<DVec2>)> =
        obstacles.iter().map(|p| (p.moving_piece, p.fixed_piece, slice(p.obstacle.polytope(), z))).collect();
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for (_, _, p) in &polygons {
        for q in p {
            lo = lo.min(*q);
            hi = hi.max(*q);
        }
    }
    if !lo.is_finite() {
        lo = DVec2::ZERO;
        hi = DVec2::ONE;
    }
    let size = (hi - lo).max(DVec2::splat(1e-9));
    let margin = 0.05 * size.max_element();
    let mut text = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"{} {} {} {}\">\n<title>c-space slices at p_z = {z}, \
         theta = {} deg</title>\n<g transform=\"scale(1,-1)\">\n",
        lo.x - margin,
        -(hi.y + margin),
        size.x + 2.0 * margin,
        size.y + 2.0 * margin,
        args.theta_deg
    );
    let stroke = 0.003 * size.max_element();
    for (i, j, p) in &polygons {
        if p.len() < 3 {
            continue;
        }
        let pts: Vec<String> = p.iter().map(|q| format!("{},{}", q.x, q.y)).collect();
        let _ = writeln!(
            text,
            "<polygon data-pair=\"{i},{j}\" points=\"{}\" fill=\"rgba(200,40,40,0.25)\" stroke=\"black\" \
             stroke-width=\"{stroke}\"/>",
            pts.join(" ")
        );
    }
    text.push_str("</g>\n</svg>\n");
    text
}
