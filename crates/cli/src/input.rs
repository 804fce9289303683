//! Reading parts for every command: a file (`.json`, `.stl`, `.obj`) or a built-in example (`example:NAME`).

use anyhow::Context;
use stackplan_geom::Part;
use stackplan_geom::sheet_metal::Decomposition;

/// The weight w of the planner's cost in `plan`, `sweep` and `place`.
pub const DEFAULT_W: f64 = 0.5;
/// The horizontal clearance between parts of `plan` and `sweep` (mm); `check` takes a plan file's own.
pub const DEFAULT_CLEARANCE_MM: f64 = 5.0;
/// The step of the turns about the vertical axis of `plan`, `sweep` and `place` (degrees).
pub const DEFAULT_DTHETA_DEG: f64 = 5.0;
/// The friction coefficient of `plan`, `sweep` and `check`.
pub const DEFAULT_MU: f64 = 0.5;
/// The suction cup's diameter in `plan`, `sweep`, `check` and `part poses` (mm).
pub const DEFAULT_CUP_DIAMETER_MM: f64 = 10.0;
/// The largest tilt from level of a face that holds the cup, in `plan`, `sweep`, `check` and `part poses` (degrees).
pub const DEFAULT_GRASP_TILT_DEG: f64 = 5.0;

/// Where a part comes from, shared by every command that reads one.
#[derive(Debug, Clone, clap::Args)]
pub struct PartArgs {
    /// Part file (.step/.stp, .stl, .obj, .json) or a built-in example `example:NAME` (channel, triangle, complex,
    /// cube, l-corner, block). STEP solids and non-convex meshes are recognised as sheet metal.
    pub part: String,
    /// Split concave sheet-metal faces by plain triangulation (the seed's component counts) instead of merging
    /// triangles into larger convex pieces.
    #[arg(long)]
    pub triangulate: bool,
}

impl PartArgs {
    /// The decomposition the flags ask for.
    pub fn decomposition(&self) -> Decomposition {
        decomposition(self.triangulate)
    }
}

/// Reads the part named by `args`.
pub fn load_part(args: &PartArgs) -> anyhow::Result<Part> {
    load_part_spec(&args.part, args.decomposition())
}

/// How every part file is read: the global options `--mesh-tolerance`, `--units`, `--bend-tolerance`, `--solid`
/// and `--decompose`, set once by `main`.
#[derive(Debug, Clone, Copy, Default)]
pub struct ReadSettings {
    /// `--mesh-tolerance` (mm).
    pub mesh_tolerance: Option<f64>,
    /// `--units` of mesh files.
    pub units: stackplan_geom::io::Units,
    /// `--bend-tolerance` (mm).
    pub bend_tolerance: Option<f64>,
    /// `--solid` of a STEP file.
    pub solid: Option<usize>,
    /// `--decompose`: VHACD instead of sheet-metal recognition for non-convex meshes.
    pub decompose: bool,
}

static READ_SETTINGS: std::sync::OnceLock<ReadSettings> = std::sync::OnceLock::new();

/// Sets the read settings for every part read after it (once, from `main`), after checking them.
pub fn set_read_settings(settings: ReadSettings) -> anyhow::Result<()> {
    if let Some(t) = settings.mesh_tolerance
        && !(t > 0.0 && t.is_finite())
    {
        anyhow::bail!("--mesh-tolerance must be a positive, finite length (mm), got {}", short_number(t));
    }
    if let Some(t) = settings.bend_tolerance
        && !(t > 0.0 && t.is_finite())
    {
        anyhow::bail!("--bend-tolerance must be a positive, finite length (mm), got {}", short_number(t));
    }
    // a second call keeps the first settings (tests call main's pieces more than once)
    let _ = READ_SETTINGS.set(settings);
    Ok(())
}

/// The read options of a part file, from the global settings and `decomposition`.
pub fn read_options(decomposition: Decomposition) -> stackplan_geom::io::ReadOptions {
    let s = READ_SETTINGS.get().copied().unwrap_or_default();
    stackplan_geom::io::ReadOptions {
        decomposition,
        decompose_mesh: s.decompose,
        mesh_tolerance: s.mesh_tolerance,
        units: s.units,
        bend_tolerance: s.bend_tolerance,
        solid: s.solid,
        ..Default::default()
    }
}

/// Reads a part from a path or `example:NAME`, with the global read settings.
pub fn load_part_spec(spec: &str, decomposition: Decomposition) -> anyhow::Result<Part> {
    if let Some(name) = spec.strip_prefix("example:") {
        return stackplan_geom::examples::part_by_name(name, decomposition).with_context(|| {
            format!("no built-in example named {name:?} (try channel, triangle, complex, cube, l-corner, block)")
        });
    }
    let part = stackplan_geom::io::read_part(std::path::Path::new(spec), &read_options(decomposition))?;
    warn_implausible_size(spec, &part);
    Ok(part)
}

/// Warns when a part's size is implausible for a sheet-metal part in millimetres: under 20 mm or over 20 m across,
/// most likely a file in inches or metres read as millimetres (mesh files carry no unit: `--units`).
pub fn warn_implausible_size(spec: &str, part: &Part) {
    let (lo, hi) = part.aabb();
    let size = (hi - lo).max_element();
    let units = READ_SETTINGS.get().map(|s| s.units).unwrap_or_default();
    if size < 20.0 {
        tracing::warn!(
            "{spec}: the part is only {} mm across, read as {units}; if the file is in inches or metres, say so with \
             --units in or --units m",
            short_number((size * 1000.0).round() / 1000.0)
        );
    } else if size > 20_000.0 {
        tracing::warn!(
            "{spec}: the part is {} m across, read as {units}; if the file is in smaller units, say so with --units",
            short_number((size / 10.0).round() / 100.0)
        );
    }
}

/// A sentence on how a part was made, for parts whose pieces are not the part exactly: recognised sheet metal
/// (conservative: the pieces contain the solid) or an approximate decomposition (VHACD). `None` for the others.
pub fn origin_note(origin: &stackplan_geom::PartOrigin, pieces_volume: f64) -> Option<String> {
    use stackplan_geom::PartOrigin;
    match origin {
        PartOrigin::RecognisedSheet { thickness, plates, bends, solid_volume, max_deviation } => Some(format!(
            "recognised sheet metal, {thickness:.3} mm thick, {plates} plates and {bends} bends; its convex pieces \
             contain the solid, hold {:+.3} % of its volume and stand out of it by at most {max_deviation:.3} mm",
            100.0 * (pieces_volume / solid_volume - 1.0)
        )),
        PartOrigin::ApproximateDecomposition { mesh_volume } => Some(match mesh_volume {
            Some(v) => format!(
                "approximate convex decomposition (VHACD) of a mesh: the pieces hold {:+.1} % of the mesh's volume, \
                 may fill its holes and stand outside it, so interference-free plans are not guaranteed in steel",
                100.0 * (pieces_volume / v - 1.0)
            ),
            None => "approximate convex decomposition (VHACD) of a mesh: the pieces may fill its holes and stand \
                     outside it, so interference-free plans are not guaranteed in steel"
                .to_string(),
        }),
        _ => None,
    }
}

/// The decomposition of `--triangulate`: plain triangulation (the seed's component counts) or convex merging.
pub fn decomposition(triangulate: bool) -> Decomposition {
    if triangulate { Decomposition::Triangulation } else { Decomposition::ConvexMerge }
}

pub use stackplan_geom::io::short_number;

/// Checks lengths or coordinates (mm) given by `what` (an option or a file and key): 0, or a magnitude from
/// [`MIN_COORDINATE`] (1e-50 mm) to [`MAX_COORDINATE`] (1e9 mm), the range the part readers accept. Outside it the
/// planner's solvers and hulls would fail with messages about their own internals instead.
///
/// [`MIN_COORDINATE`]: stackplan_geom::MIN_COORDINATE
/// [`MAX_COORDINATE`]: stackplan_geom::io::MAX_COORDINATE
pub fn check_lengths(what: &str, values: &[f64]) -> anyhow::Result<()> {
    let (min, max) = (stackplan_geom::MIN_COORDINATE, stackplan_geom::io::MAX_COORDINATE);
    if let Some(v) = values.iter().find(|v| !stackplan_geom::io::coordinate_in_range(**v)) {
        anyhow::bail!(
            "{what}: {} is not a finite length of 0 or a magnitude from {min:e} to {max:e} mm",
            short_number(*v)
        );
    }
    Ok(())
}

/// Checks `--dtheta-deg`: at least 0.01 degree (the planner's [`MAX_THETAS`] angles per turn) and at most 360.
///
/// [`MAX_THETAS`]: stackplan::planner::request::MAX_THETAS
pub fn check_dtheta_deg(dtheta_deg: f64) -> anyhow::Result<()> {
    let min = 360.0 / stackplan::planner::request::MAX_THETAS as f64;
    anyhow::ensure!(
        (min..=360.0).contains(&dtheta_deg),
        "--dtheta-deg must lie in [{min}, 360] degrees, got {}",
        short_number(dtheta_deg)
    );
    Ok(())
}

/// Reads a pose file: JSON `{"position": [x, y, z], "rotation": [[row 0], [row 1], [row 2]]}` (a proper rotation).
pub fn read_pose(path: &std::path::Path) -> anyhow::Result<stackplan_geom::Pose> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let record: stackplan_geom::pose::PoseRecord =
        serde_json::from_str(&text).with_context(|| format!("parsing the pose in {}", path.display()))?;
    let pose = stackplan_geom::Pose::try_from(record).with_context(|| format!("the pose in {}", path.display()))?;
    check_lengths(&format!("{}: position", path.display()), &pose.position.to_array())?;
    Ok(pose)
}

/// Checks `--grasp-tilt-deg`: from 0 to 89 degrees.
pub fn check_grasp_tilt(degrees: f64) -> anyhow::Result<()> {
    anyhow::ensure!(
        (0.0..=89.0).contains(&degrees),
        "--grasp-tilt-deg must lie in [0, 89] degrees, got {}",
        short_number(degrees)
    );
    Ok(())
}

/// Parses `--pair I,J` (moving component I, fixed component J).
pub fn parse_pair(s: &str) -> anyhow::Result<(usize, usize)> {
    let (i, j) = s.split_once(',').with_context(|| format!("--pair expects I,J, got {s:?}"))?;
    Ok((i.trim().parse().context("--pair: moving index")?, j.trim().parse().context("--pair: fixed index")?))
}

/// A moving and a fixed part with the fixed part's pose: what `cspace`, `intervals` and `interference` read.
#[derive(Debug, Clone)]
pub struct PartPair {
    /// The moving part.
    pub moving: Part,
    /// The fixed part.
    pub fixed: Part,
    /// The fixed part's pose (identity without `--fixed-pose`).
    pub fixed_pose: stackplan_geom::Pose,
    /// `--pair I,J` if given, checked against the component counts.
    pub only: Option<(usize, usize)>,
}

/// Reads the two parts, the fixed part's pose file (if any) and the `--pair` option (if any; the indices are
/// checked against the parts' component counts).
pub fn load_pair(
    moving: &str,
    fixed: &str,
    triangulate: bool,
    fixed_pose: Option<&std::path::Path>,
    pair: Option<&str>,
) -> anyhow::Result<PartPair> {
    let decomposition = decomposition(triangulate);
    let moving = load_part_spec(moving, decomposition)?;
    let fixed = load_part_spec(fixed, decomposition)?;
    let fixed_pose = match fixed_pose {
        Some(p) => read_pose(p)?,
        None => stackplan_geom::Pose::IDENTITY,
    };
    let only = pair.map(parse_pair).transpose()?;
    if let Some((i, j)) = only {
        anyhow::ensure!(
            i < moving.components().len(),
            "--pair: the moving part has {} components",
            moving.components().len()
        );
        anyhow::ensure!(
            j < fixed.components().len(),
            "--pair: the fixed part has {} components",
            fixed.components().len()
        );
    }
    Ok(PartPair { moving, fixed, fixed_pose, only })
}
