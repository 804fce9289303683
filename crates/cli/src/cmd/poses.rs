//! `stackplan part poses PART [--cup-diameter MM] [--json]`: the stable resting poses of a part with their grasp
//! faces (crate `stackplan-stability`, JSON documented in `crates/stability/README.md`).

use crate::Outcome;
use crate::input::{PartArgs, load_part};
use crate::output;
use serde::Serialize;
use stackplan::stability::grasp::{GraspFace, GraspOptions, grasp_faces, is_graspable};
use stackplan::stability::resting_poses::resting_poses;

/// Arguments of `part poses`.
#[derive(Debug, clap::Args)]
pub struct PosesArgs {
    /// The part.
    #[command(flatten)]
    pub part: PartArgs,
    /// Suction cup diameter (mm).
    #[arg(long, value_name = "MM", default_value_t = crate::input::DEFAULT_CUP_DIAMETER_MM)]
    pub cup_diameter: f64,
    /// Largest tilt from level of a face that holds the cup (degrees, 0 to 89): the cup approaches along the face's
    /// normal.
    #[arg(long, value_name = "DEG", default_value_t = crate::input::DEFAULT_GRASP_TILT_DEG)]
    pub grasp_tilt_deg: f64,
    /// JSON output.
    #[arg(long)]
    pub json: bool,
}

/// One pose in the JSON output.
#[derive(Debug, Serialize)]
pub struct PoseJson {
    /// Index of the face in the part's convex hull.
    pub hull_face: usize,
    /// Outward normal of that face in part coordinates.
    pub face_normal: [f64; 3],
    /// Rotation about x (degrees); the pose's rotation is Ry(psi) Rx(phi).
    pub phi_deg: f64,
    /// Rotation about y (degrees).
    pub psi_deg: f64,
    /// Rotation matrix, rows.
    pub rotation: [[f64; 3]; 3],
    /// Translation putting the face on z = 0 with the c.g. above the origin.
    pub position: [f64; 3],
    /// Height of the c.g. (mm).
    pub cg_height: f64,
    /// Distance from the projected c.g. to the face boundary (mm).
    pub margin: f64,
    /// Whether a cup of the given diameter fits on an upward face.
    pub graspable: bool,
    /// Upward horizontal faces, largest inscribed disc first.
    pub grasp_faces: Vec<GraspFace>,
}

/// The JSON of `part poses --json`.
#[derive(Debug, Serialize)]
pub struct PosesJson {
    /// Part name.
    pub part: String,
    /// Cup diameter used (mm).
    pub cup_diameter: f64,
    /// Stable resting poses, lowest c.g. first (then largest margin).
    pub poses: Vec<PoseJson>,
}

/// Runs `part poses`.
pub fn run_poses(args: &PosesArgs) -> anyhow::Result<Outcome> {
    anyhow::ensure!(
        args.cup_diameter >= 0.0 && args.cup_diameter.is_finite(),
        "--cup-diameter must be a non-negative number of millimetres"
    );
    let part = load_part(&args.part)?;
    crate::input::check_grasp_tilt(args.grasp_tilt_deg)?;
    let grasp = GraspOptions {
        cup_diameter: args.cup_diameter,
        max_tilt: args.grasp_tilt_deg.to_radians(),
        ..GraspOptions::default()
    };
    let mut poses = Vec::new();
    for pose in resting_poses(&part)? {
        let faces = grasp_faces(&part, pose.rotation, pose.position, &grasp);
        let r = pose.rotation.transpose(); // columns of the transpose are the rows
        poses.push(PoseJson {
            hull_face: pose.hull_face,
            face_normal: pose.face_normal.to_array(),
            phi_deg: pose.phi.to_degrees(),
            psi_deg: pose.psi.to_degrees(),
            rotation: [r.x_axis.to_array(), r.y_axis.to_array(), r.z_axis.to_array()],
            position: pose.position.to_array(),
            cg_height: pose.cg_height,
            margin: pose.margin,
            graspable: is_graspable(&faces, &grasp),
            grasp_faces: faces,
        });
    }
    let out = PosesJson { part: part.name.clone(), cup_diameter: args.cup_diameter, poses };
    if args.json {
        let mut json = serde_json::to_value(&out)?;
        output::rename_key(&mut json, &["poses", "*", "grasp_faces", "*", "tilt"], "tilt_rad");
        output::print_json(&json)?;
    } else {
        let mut text = format!(
            "part {}: {} stable resting poses, lowest centre of gravity first (cup {} mm)\n",
            out.part,
            out.poses.len(),
            out.cup_diameter
        );
        text.push_str("  pose  hull_face  phi_deg  psi_deg  cg_height_mm  margin_mm  grasp_radius_mm  graspable\n");
        for (k, p) in out.poses.iter().enumerate() {
            let radius = p.grasp_faces.first().map_or(0.0, |f| f.inscribed_radius);
            text.push_str(&format!(
                "  {:>4}  {:>9}  {:>7.3}  {:>7.3}  {:>12.3}  {:>9.3}  {:>15.3}  {}\n",
                k + 1,
                p.hull_face,
                p.phi_deg,
                p.psi_deg,
                p.cg_height,
                p.margin,
                radius,
                p.graspable
            ));
        }
        output::print_text(&text)?;
    }
    Ok(Outcome::Success)
}
