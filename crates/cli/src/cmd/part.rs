//! `stackplan part info PART [--json [--features]]` and `stackplan part export PART --glb F | --obj F | --stl F`.

use crate::Outcome;
use crate::input::{PartArgs, load_part};
use crate::output;
use serde::Serialize;
use stackplan_geom::io::glb::{GlbItem, glb_bytes};
use stackplan_geom::io::obj::obj_string;
use stackplan_geom::io::stl::stl_binary_bytes;
use stackplan_geom::{DVec3, Part};
use std::path::PathBuf;

/// `part` subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum PartCommand {
    /// Components, volume, centre of gravity and bounding box of a part.
    Info(InfoArgs),
    /// Writes the part as binary glTF, OBJ or STL.
    Export(ExportArgs),
    /// Stable resting poses with margins and suction-grasp faces.
    Poses(super::poses::PosesArgs),
}

/// Arguments of `part info`.
#[derive(Debug, clap::Args)]
pub struct InfoArgs {
    /// The part.
    #[command(flatten)]
    pub part: PartArgs,
    /// JSON output, including every convex component's vertices and faces.
    #[arg(long)]
    pub json: bool,
    /// With `--json`: also `features`, every face, edge and vertex of the merged surface that `contacts` names
    /// (`f3`, `e7`, `v2`).
    #[arg(long, requires = "json")]
    pub features: bool,
}

/// Arguments of `part export`.
#[derive(Debug, clap::Args)]
#[group(id = "target", required = true, multiple = true)]
pub struct ExportArgs {
    /// The part.
    #[command(flatten)]
    pub part: PartArgs,
    /// Binary glTF output file.
    #[arg(long, group = "target")]
    pub glb: Option<PathBuf>,
    /// Wavefront OBJ output file (one object per convex component).
    #[arg(long, group = "target")]
    pub obj: Option<PathBuf>,
    /// Binary STL output file.
    #[arg(long, group = "target")]
    pub stl: Option<PathBuf>,
}

/// Runs a `part` subcommand.
pub fn run(cmd: &PartCommand) -> anyhow::Result<Outcome> {
    match cmd {
        PartCommand::Info(a) => info(a),
        PartCommand::Export(a) => export(a),
        PartCommand::Poses(a) => super::poses::run_poses(a),
    }
}

/// The JSON of `part info --json` (documented in docs/formats.md).
#[derive(Debug, Serialize)]
pub struct PartInfo {
    /// Part name.
    pub name: String,
    /// How the part was made (`convex_pieces`, `sheet_metal` with thickness, `mesh`, `approximate_decomposition`).
    pub origin: stackplan_geom::PartOrigin,
    /// Number of convex components.
    pub components: usize,
    /// Volume (mm^3).
    pub volume: f64,
    /// Mass (density x volume).
    pub mass: f64,
    /// Density used.
    pub density: f64,
    /// Centre of gravity (mm).
    pub center_of_gravity: [f64; 3],
    /// Inertia tensor about the centre of gravity, rows.
    pub inertia: [[f64; 3]; 3],
    /// Bounding box `[min, max]`.
    pub bounding_box: [[f64; 3]; 2],
    /// Number of boundary faces of the whole part.
    pub boundary_faces: usize,
    /// Every convex component, only with `--json`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pieces: Option<Vec<PieceJson>>,
    /// What sheet-metal recognition found, for a STEP file or a non-convex mesh (absent otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub recognition: Option<stackplan_geom::cad::recognise::Recognition>,
}

/// One convex component in `part info --json`.
#[derive(Debug, Serialize)]
pub struct PieceJson {
    /// Vertices.
    pub vertices: Vec<[f64; 3]>,
    /// Faces: vertex indices counter-clockwise seen from outside, unit outward normal and offset
    /// (`normal . x <= offset` inside).
    pub faces: Vec<FaceJson>,
    /// Volume of the component.
    pub volume: f64,
}

/// A face in JSON.
#[derive(Debug, Serialize)]
pub struct FaceJson {
    /// Vertex indices, counter-clockwise seen from outside.
    pub vertices: Vec<usize>,
    /// Unit outward normal.
    pub normal: [f64; 3],
    /// Plane offset: `normal . x = offset` on the face, `<=` inside.
    pub offset: f64,
}

fn arr(v: DVec3) -> [f64; 3] {
    v.to_array()
}

/// The information shown by `part info`.
pub fn part_info(part: &Part, with_pieces: bool) -> PartInfo {
    let (lo, hi) = part.aabb();
    let i = part.mass().inertia;
    PartInfo {
        name: part.name.clone(),
        origin: part.origin.clone(),
        components: part.components().len(),
        volume: part.mass().volume,
        mass: part.mass().mass,
        density: part.density(),
        center_of_gravity: arr(part.mass().center_of_gravity),
        inertia: [
            [i.x_axis.x, i.y_axis.x, i.z_axis.x],
            [i.x_axis.y, i.y_axis.y, i.z_axis.y],
            [i.x_axis.z, i.y_axis.z, i.z_axis.z],
        ],
        bounding_box: [arr(lo), arr(hi)],
        boundary_faces: part.boundary().len(),
        pieces: with_pieces.then(|| {
            part.components()
                .iter()
                .map(|c| PieceJson {
                    vertices: c.vertices().iter().map(|v| arr(*v)).collect(),
                    faces: c
                        .faces()
                        .iter()
                        .map(|f| FaceJson {
                            vertices: f.vertices.to_vec(),
                            normal: arr(f.plane.normal),
                            offset: f.plane.offset,
                        })
                        .collect(),
                    volume: c.volume(),
                })
                .collect()
        }),
        recognition: None,
    }
}

fn info(args: &InfoArgs) -> anyhow::Result<Outcome> {
    let part = load_part(&args.part)?;
    let mut info = part_info(&part, args.json);
    if matches!(part.origin, stackplan_geom::PartOrigin::RecognisedSheet { .. }) {
        let options = crate::input::read_options(args.part.decomposition());
        info.recognition = Some(stackplan_geom::io::sheet::read_sheet(&args.part.part, &options)?.1);
    }
    if args.json {
        let mut json = serde_json::to_value(&info)?;
        if args.features {
            let surface = stackplan::contact_states::ContactPart::from_part(&part)
                .map_err(|e| anyhow::anyhow!("surface of {}: {e}", args.part.part))?;
            let features = stackplan::contact_states::features::Features::new(&surface.surface, &surface.face_names);
            json["features"] = serde_json::to_value(features)?;
        }
        for key in ["start", "angle"] {
            output::rename_key(&mut json, &["recognition", "bends", "*", "bend", key], &format!("{key}_rad"));
        }
        output::print_json(&json)?;
    } else {
        let text = format!(
            "part            {}\norigin          {}\ncomponents      {}\nvolume          {:.6} mm^3\nmass            {:.6} (density {} per mm^3)\ncentre of grav. [{:.6}, {:.6}, {:.6}] mm\nbounding box    [{:.3}, {:.3}, {:.3}] .. [{:.3}, {:.3}, {:.3}] mm\nboundary faces  {}\n",
            info.name,
            serde_json::to_string(&info.origin)?,
            info.components,
            info.volume,
            info.mass,
            info.density,
            info.center_of_gravity[0],
            info.center_of_gravity[1],
            info.center_of_gravity[2],
            info.bounding_box[0][0],
            info.bounding_box[0][1],
            info.bounding_box[0][2],
            info.bounding_box[1][0],
            info.bounding_box[1][1],
            info.bounding_box[1][2],
            info.boundary_faces,
        );
        let text = match &info.recognition {
            Some(r) => text + &recognition_text(r),
            None => text,
        };
        output::print_text(&text)?;
    }
    Ok(Outcome::Success)
}

/// The recognised sheet, plates and bends as text.
fn recognition_text(r: &stackplan_geom::cad::recognise::Recognition) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    let holes: usize = r.plates.iter().map(|p| p.holes).sum();
    let _ = writeln!(
        out,
        "sheet metal     thickness {:.4} mm, {} plates ({holes} holes), {} bends",
        r.thickness,
        r.plates.len(),
        r.bends.len()
    );
    for (k, p) in r.plates.iter().enumerate() {
        let _ = writeln!(
            out,
            "  plate {:<3}     {:.1} mm^2, {} holes, {} arcs, {} pieces (from {})",
            k + 1,
            p.area,
            p.holes,
            p.arcs,
            p.pieces.len(),
            p.faces.iter().map(ToString::to_string).collect::<Vec<_>>().join(", ")
        );
    }
    for (k, b) in r.bends.iter().enumerate() {
        let _ = writeln!(
            out,
            "  bend {:<3}      inner radius {:.4} mm, angle {:.2} deg, width {:.2} mm, {} pieces",
            k + 1,
            b.bend.inner_radius,
            b.bend.angle.to_degrees(),
            b.bend.axial[1] - b.bend.axial[0],
            b.pieces.len()
        );
    }
    let _ = writeln!(
        out,
        "solid volume    {:.1} mm^3\npieces volume   {:.1} mm^3 ({:+.3} %)\nlargest outward deviation {:.4} mm (bend tolerance {} mm)",
        r.solid_volume,
        r.pieces_volume,
        100.0 * (r.pieces_volume / r.solid_volume - 1.0),
        r.max_deviation,
        r.bend_tolerance
    );
    out
}

fn export(args: &ExportArgs) -> anyhow::Result<Outcome> {
    let part = load_part(&args.part)?;
    // the format follows the flag, whatever the extension; the files are written all or none
    let glb = args.glb.as_ref().map(|p| (p, glb_bytes(&[GlbItem::part(&part)])));
    let obj = args.obj.as_ref().map(|p| (p, obj_string(&part).into_bytes()));
    let stl = args.stl.as_ref().map(|p| (p, stl_binary_bytes(&part)));
    let written: Vec<PathBuf> = [&glb, &obj, &stl].into_iter().flatten().map(|(p, _)| p.to_path_buf()).collect();
    output::write_all_atomic([glb, obj, stl].into_iter().flatten())?;
    output::print_wrote(&written.iter().map(PathBuf::as_path).collect::<Vec<_>>(), false)?;
    Ok(Outcome::Success)
}
