//! The files of a stacking plan: the plan file (`plan.json`) and everything drawn from it (`stack.svg`,
//! `stack.png`, `build.svg`, `build.png`, `stack.glb`, `report.html`). Shared by `stackplan plan` (which writes the
//! plan file and then draws from the very text it wrote) and `stackplan render` (which draws from a plan file on
//! disk), so the two produce byte-identical pictures for the same plan.
//!
//! The build strip is the seed's Fig. 3 (\[A\] section II-B): one small isometric frame per added part, the new part in
//! its colour and numbered, the earlier ones grey; for more than [`MAX_BUILD_FRAMES`] parts one frame per `k` parts
//! (`k = ceil(n / MAX_BUILD_FRAMES)`), each frame captioned with its part count. All frames share one scale and floor
//! line so the stack's growth can be compared frame to frame.

use crate::output::write_all_atomic;
use crate::render::{
    CG_MARK, Figure, FigurePanel, ISOMETRIC, LegendItem, MUTED, Marker, Scene, Solid, Swatch, figure_png, figure_svg,
    part_color, parts_legend, three_views,
};
use serde_json::{Map, Value, json};
use stackplan::planner::{FloorVolume, Plan};
use stackplan_geom::io::glb::{GlbItem, glb_bytes};
use stackplan_geom::io::{IoError, ReadOptions};
use stackplan_geom::{DVec3, Part, Pose};
use std::path::{Path, PathBuf};

/// At most this many frames in the build strip.
pub const MAX_BUILD_FRAMES: usize = 20;

/// Pixels per SVG unit of the PNG pictures.
pub const PNG_SCALE: f64 = 2.0;

/// A plan file that is not usable.
#[derive(Debug, thiserror::Error)]
pub enum PlanFileError {
    /// The file cannot be read.
    #[error("{}: cannot read the plan file: {source}", file.display())]
    Read {
        /// The plan file.
        file: PathBuf,
        /// The reason.
        source: std::io::Error,
    },
    /// Not a valid stack file (part and placements); the error names the file and the place.
    #[error(transparent)]
    Stack(#[from] IoError),
    /// A valid stack file without the `plan` summary that `stackplan plan` writes.
    #[error("{}: not a plan file: there is no `plan` summary (only files written by `stackplan plan` can be rendered)", file.display())]
    NotAPlan {
        /// The file.
        file: PathBuf,
    },
    /// The summary or the placements' planner fields are malformed.
    #[error("{}: malformed plan: {message}", file.display())]
    Malformed {
        /// The file.
        file: PathBuf,
        /// What is wrong (serde's message names the key).
        message: String,
    },
    /// The summary's part count disagrees with the placements.
    #[error(
        "{}: malformed plan: key `plan.placed`: the summary says {placed} parts were placed, but there are \
         {placements} placements",
        file.display()
    )]
    CountMismatch {
        /// The file.
        file: PathBuf,
        /// `plan.placed`.
        placed: u64,
        /// Number of placements.
        placements: usize,
    },
    /// No placements: nothing to draw.
    #[error("{}: the plan has no placed parts: nothing to draw", file.display())]
    Empty {
        /// The file.
        file: PathBuf,
    },
}

/// A plan file read back.
#[derive(Debug, Clone)]
pub struct PlanFile {
    /// The part (inline in the file).
    pub part: Part,
    /// The plan's summary (`plan.parts` is empty: the parts are `poses` and `placements`).
    pub plan: Plan,
    /// The placements as checked poses.
    pub poses: Vec<Pose>,
    /// The planner's fields of each placement (`cost`, `theta_deg`, `stage`, ...: [`stackplan::planner::PlannedPart`]
    /// without the pose), parallel to `poses`.
    pub placements: Vec<Map<String, Value>>,
    /// Planning time recorded in the file (s).
    pub seconds: f64,
    /// How the planned part was made (`plan.part_origin`; absent in older files and plain stack files).
    pub part_origin: Option<stackplan_geom::PartOrigin>,
}

/// The plan file's JSON: a stack file (`part` inline, `placements` = the planned parts) plus the `plan` summary
/// (the [`Plan`] without its parts, with `part_name`, `placed` and `seconds`).
pub fn plan_document_text(part: &Part, plan: &Plan, seconds: f64) -> anyhow::Result<String> {
    let inline: Value = serde_json::from_str(&stackplan_geom::io::json::part_json_string(part))?;
    let placements = serde_json::to_value(&plan.parts)?;
    let mut summary = serde_json::to_value(plan)?;
    if let Value::Object(m) = &mut summary {
        m.remove("parts");
        m.insert("part_name".into(), json!(part.name));
        m.insert("placed".into(), json!(plan.parts.len()));
        m.insert("seconds".into(), json!(seconds));
        m.insert("part_origin".into(), serde_json::to_value(&part.origin)?);
    }
    // angles in radians carry the unit in their names (docs/formats.md, "Conventions")
    for (key, to) in RADIAN_OPTIONS {
        crate::output::rename_key(&mut summary, &["options", key], to);
    }
    crate::output::json_text(&json!({ "part": inline, "placements": placements, "plan": summary }))
}

/// `plan` without its timings (`stats.seconds_search` and `stats.seconds_checks` 0): with `seconds` 0 in
/// [`plan_document_text`], the plan file of a plan made twice with the same options is the same byte for byte
/// (`stackplan batch`, and the Python package's `Plan.to_json(timings=False)`).
pub fn untimed(plan: &Plan) -> Plan {
    let mut plan = plan.clone();
    plan.stats.seconds_search = 0.0;
    plan.stats.seconds_checks = 0.0;
    plan
}

/// Writes a plan's files into `dir` as `stackplan plan` does: `plan.json` ([`plan_document_text`]) and every picture
/// drawn from that very text, exactly as `stackplan render` draws them. Every output is prepared first, then written
/// atomically: a failure leaves no partial set behind.
pub fn write_plan_files(dir: &Path, part: &Part, plan: &Plan, seconds: f64) -> anyhow::Result<()> {
    let plan_text = plan_document_text(part, plan, seconds)?;
    let file = parse_plan_file(plan_text.as_bytes(), &dir.join("plan.json"))?;
    plan_pictures(&file)?.write_all(dir, plan_text.as_bytes())
}

/// The planner's options in radians, with their names in plan files: `PlanOptions` names them without the unit.
const RADIAN_OPTIONS: [(&str, &str); 2] = [("dtheta", "dtheta_rad"), ("grasp_tilt", "grasp_tilt_rad")];

/// Reads a plan file.
pub fn read_plan_file(path: &Path) -> Result<PlanFile, PlanFileError> {
    let bytes = std::fs::read(path).map_err(|source| PlanFileError::Read { file: path.to_path_buf(), source })?;
    parse_plan_file(&bytes, path)
}

/// Parses a plan file's bytes; `path` names it in errors.
pub fn parse_plan_file(bytes: &[u8], path: &Path) -> Result<PlanFile, PlanFileError> {
    let stack = stackplan_geom::io::stack::parse_stack(bytes, path, &ReadOptions::default())?;
    let Some(mut summary) = plan_summary(stack.plan.as_ref(), path)?.cloned() else {
        return Err(PlanFileError::NotAPlan { file: path.to_path_buf() });
    };
    let count = stack.placements.len();
    check_placed(&summary, path, count)?;
    let seconds = summary.get("seconds").and_then(Value::as_f64).unwrap_or(0.0);
    let part_origin = summary.get("part_origin").and_then(|v| serde_json::from_value(v.clone()).ok());
    // the summary is typed; the placements' planner fields (cost, theta, stage, ...) are read leniently for the
    // report: JSON has no infinity or NaN, so a non-finite number is written as `null` and shown as "-"
    summary.insert("parts".into(), Value::Array(Vec::new()));
    // `dtheta_rad` and `grasp_tilt_rad` are `PlanOptions`' `dtheta` and `grasp_tilt` (files written before the
    // names carried the unit hold those)
    let mut summary = Value::Object(summary);
    for (key, named) in RADIAN_OPTIONS {
        crate::output::rename_key(&mut summary, &["options", named], key);
    }
    // the error names the nested key (`plan.options.floor.height`), not only the summary, by its name in the file
    let plan: Plan = serde_path_to_error::deserialize(summary).map_err(|e| {
        let mut key = match e.path().to_string().as_str() {
            "." => "plan".to_string(),
            nested => format!("plan.{nested}"),
        };
        let mut message = e.inner().to_string();
        for (name, named) in RADIAN_OPTIONS {
            if key == format!("plan.options.{name}") {
                key = format!("plan.options.{named}");
            }
            message = message.replace(&format!("`{name}`"), &format!("`{named}`"));
        }
        PlanFileError::Malformed { file: path.to_path_buf(), message: format!("key `{key}`: {message}") }
    })?;
    if count == 0 {
        return Err(PlanFileError::Empty { file: path.to_path_buf() });
    }
    Ok(PlanFile { part: stack.part, plan, poses: stack.placements, placements: stack.extras, seconds, part_origin })
}

/// The `plan` summary of a stack file (`StackFile::plan`; a JSON `null` reads as absent): `None` for a plain stack
/// file, the object for a plan file, an error naming the file and the key when it is anything else. Shared by
/// `stackplan render` and `stackplan check`, so the two agree on what a plan summary is.
pub fn plan_summary<'a>(plan: Option<&'a Value>, path: &Path) -> Result<Option<&'a Map<String, Value>>, PlanFileError> {
    match plan {
        None | Some(Value::Null) => Ok(None),
        Some(Value::Object(summary)) => Ok(Some(summary)),
        Some(other) => Err(PlanFileError::Malformed {
            file: path.to_path_buf(),
            message: format!("key `plan`: expected the plan summary (an object), got {}", json_kind(other)),
        }),
    }
}

/// `options.KEY` of a plan summary (`stackplan plan` writes the planner's options there): `None` when `options` or
/// the key is absent, the number when it is finite and non-negative, an error naming the file and the key otherwise
/// (a plan file's friction, clearance or cup that cannot be used is not silently replaced by a default).
pub fn plan_option(summary: &Map<String, Value>, key: &str, path: &Path) -> Result<Option<f64>, PlanFileError> {
    let malformed = |message: String| PlanFileError::Malformed { file: path.to_path_buf(), message };
    let options = match summary.get("options") {
        None | Some(Value::Null) => return Ok(None),
        Some(Value::Object(options)) => options,
        Some(other) => {
            return Err(malformed(format!("key `plan.options`: expected an object, got {}", json_kind(other))));
        }
    };
    match options.get(key) {
        None | Some(Value::Null) => Ok(None),
        Some(value) => match value.as_f64() {
            Some(v) if v >= 0.0 && v.is_finite() => Ok(Some(v)),
            _ => Err(malformed(format!("key `plan.options.{key}`: expected a finite number >= 0, got {value}"))),
        },
    }
}

/// `options.floor` of a plan summary (the floor volume the planner placed the parts in): `None` when `options` or
/// the floor is absent, an error naming the file and the nested key when it is not a floor volume (a polygon of at
/// least three finite corners and a finite height above 0).
pub fn plan_floor(summary: &Map<String, Value>, path: &Path) -> Result<Option<FloorVolume>, PlanFileError> {
    let malformed = |message: String| PlanFileError::Malformed { file: path.to_path_buf(), message };
    let Some(floor) = summary.get("options").and_then(|o| o.get("floor")).filter(|f| !f.is_null()) else {
        return Ok(None);
    };
    let floor: FloorVolume = serde_path_to_error::deserialize(floor.clone()).map_err(|e| {
        let key = match e.path().to_string().as_str() {
            "." => "plan.options.floor".to_string(),
            nested => format!("plan.options.floor.{nested}"),
        };
        malformed(format!("key `{key}`: {}", e.inner()))
    })?;
    let finite = floor.polygon.iter().all(|p| p.is_finite());
    if floor.polygon.len() < 3 || !finite || !(floor.height.is_finite() && floor.height > 0.0) {
        return Err(malformed(
            "key `plan.options.floor`: expected a polygon of at least 3 finite corners and a finite height > 0".into(),
        ));
    }
    Ok(Some(floor))
}

/// Checks the summary's `placed`: present, a non-negative integer, and equal to `placements`.
pub fn check_placed(summary: &Map<String, Value>, path: &Path, placements: usize) -> Result<(), PlanFileError> {
    let malformed = |message: String| PlanFileError::Malformed { file: path.to_path_buf(), message };
    let placed = match summary.get("placed") {
        None => return Err(malformed("key `plan.placed`: missing (the number of placed parts)".into())),
        Some(value) => value.as_u64().ok_or_else(|| {
            malformed(format!(
                "key `plan.placed`: expected the number of placed parts (a non-negative integer), got {value}"
            ))
        })?,
    };
    if placed != placements as u64 {
        return Err(PlanFileError::CountMismatch { file: path.to_path_buf(), placed, placements });
    }
    Ok(())
}

/// What kind of JSON value `v` is, for messages.
fn json_kind(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// Every picture of a plan, ready to write.
#[derive(Debug, Clone)]
pub struct PlanPictures {
    /// `stack.svg`: isometric, top and side views, parts numbered.
    pub stack_svg: String,
    /// `stack.png`: the same picture.
    pub stack_png: Vec<u8>,
    /// `build.svg`: the step-by-step build strip.
    pub build_svg: String,
    /// `build.png`: the same strip.
    pub build_png: Vec<u8>,
    /// `stack.glb`: the stack as binary glTF.
    pub glb: Vec<u8>,
    /// `report.html`: the pictures and the tables.
    pub html: String,
}

impl PlanPictures {
    /// The standard file names with their contents, in writing order.
    pub fn files(&self) -> [(&'static str, &[u8]); 6] {
        [
            ("stack.svg", self.stack_svg.as_bytes()),
            ("stack.png", &self.stack_png),
            ("build.svg", self.build_svg.as_bytes()),
            ("build.png", &self.build_png),
            ("stack.glb", &self.glb),
            ("report.html", self.html.as_bytes()),
        ]
    }

    /// Writes `plan.json` (the given text) and every picture into `dir` (created if needed), all or none
    /// ([`write_all_atomic`]).
    pub fn write_all(&self, dir: &Path, plan_text: &[u8]) -> anyhow::Result<()> {
        use anyhow::Context;
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let mut files = vec![(dir.join("plan.json"), plan_text)];
        files.extend(self.files().into_iter().map(|(name, bytes)| (dir.join(name), bytes)));
        write_all_atomic(files)
    }
}

/// Draws every picture of a plan.
pub fn plan_pictures(file: &PlanFile) -> anyhow::Result<PlanPictures> {
    let scene = stack_scene(file, true);
    let stack_figure = three_views(&scene);
    let frames = build_frames(file);
    let build = build_figure(file, &frames);
    let stack_svg = figure_svg(&stack_figure);
    let items: Vec<GlbItem<'_>> = file
        .poses
        .iter()
        .enumerate()
        .map(|(i, pose)| {
            let c = part_color(i);
            GlbItem {
                part: &file.part,
                pose: *pose,
                color: [c[0] as f32 / 255.0, c[1] as f32 / 255.0, c[2] as f32 / 255.0, 1.0],
            }
        })
        .collect();
    // the two rasterisations are most of the pictures' time: one on each core (the bytes do not depend on it)
    let (stack_png, build_png) = rayon::join(|| figure_png(&stack_figure, PNG_SCALE), || figure_png(&build, PNG_SCALE));
    Ok(PlanPictures {
        stack_png: stack_png?,
        build_svg: figure_svg(&build),
        build_png: build_png?,
        glb: glb_bytes(&items),
        html: report_html(file, &stack_svg),
        stack_svg,
    })
}

fn floor_outline(floor: &FloorVolume) -> Vec<DVec3> {
    floor.polygon.iter().map(|p| DVec3::new(p.x, p.y, 0.0)).collect()
}

/// The stack as a scene: every part in its colour; with `annotate`, numbered and its c.g. marked.
pub fn stack_scene(file: &PlanFile, annotate: bool) -> Scene {
    let mut scene = frame_scene(file, file.poses.len(), 0, floor_outline(&file.plan.options.floor), true);
    if !annotate {
        scene.labels.clear();
        scene.markers.clear();
    }
    let plan = &file.plan;
    let [[x0, y0], [x1, y1]] = plan.footprint;
    scene.title = format!(
        "{} {} parts, w = {}: height {:.1} mm, footprint {:.1} x {:.1} mm, total cost {:.1} mm^2",
        file.poses.len(),
        file.part.name,
        crate::input::short_number(plan.options.w),
        plan.height,
        x1 - x0,
        y1 - y0,
        plan.total_cost
    );
    scene.legend = if annotate {
        parts_legend(true)
    } else {
        vec![
            LegendItem::new(Swatch::Square(part_color(0)), "one colour per part"),
            LegendItem::new(Swatch::Floor, "floor area"),
        ]
    };
    scene
}

/// The first `count` parts; parts from `new_from` on in their colour, numbered with their c.g. marked (only the last
/// one when a build frame adds several), earlier ones grey.
fn frame_scene(file: &PlanFile, count: usize, new_from: usize, floor: Vec<DVec3>, number_all: bool) -> Scene {
    let mut scene = Scene { floor, ..Scene::default() };
    for (i, pose) in file.poses.iter().enumerate().take(count) {
        let new = i >= new_from;
        let color = if new { part_color(i) } else { MUTED };
        for c in file.part.components() {
            scene.solids.push(Solid { polytope: c.transformed(pose.rotation, pose.position), color, part: i });
        }
        // every new part is numbered in the stack picture and in one-part frames; a frame adding several parts
        // numbers only its last one (small parts' numbers would cover each other)
        let numbered = new && (number_all || i + 1 == count);
        if numbered {
            let cg = pose.apply(file.part.mass().center_of_gravity);
            scene.labels.push((i + 1, cg));
            scene.markers.push(Marker { position: cg, color: CG_MARK });
        }
    }
    scene
}

/// Part counts shown by the build strip's frames: 1, 2, ..., n, or k, 2k, ..., n for more than
/// [`MAX_BUILD_FRAMES`] parts.
pub fn build_frame_counts(n: usize) -> Vec<usize> {
    let step = n.div_ceil(MAX_BUILD_FRAMES).max(1);
    let mut counts: Vec<usize> = (1..=n / step).map(|k| k * step).collect();
    if counts.last() != Some(&n) && n > 0 {
        counts.push(n);
    }
    counts
}

/// The build strip's scenes with their captions. The outline on the floor is the finished stack's footprint grown
/// by 10% on every side (the whole floor area would make the parts tiny).
fn build_frames(file: &PlanFile) -> Vec<(Scene, String)> {
    let [[x0, y0], [x1, y1]] = file.plan.footprint;
    let (mx, my) = (0.1 * (x1 - x0), 0.1 * (y1 - y0));
    let outline = vec![
        DVec3::new(x0 - mx, y0 - my, 0.0),
        DVec3::new(x1 + mx, y0 - my, 0.0),
        DVec3::new(x1 + mx, y1 + my, 0.0),
        DVec3::new(x0 - mx, y1 + my, 0.0),
    ];
    let mut previous = 0;
    build_frame_counts(file.poses.len())
        .into_iter()
        .map(|count| {
            let scene = frame_scene(file, count, previous, outline.clone(), count - previous == 1);
            previous = count;
            (scene, format!("{count} part{}", if count == 1 { "" } else { "s" }))
        })
        .collect()
}

fn build_figure<'a>(file: &PlanFile, frames: &'a [(Scene, String)]) -> Figure<'a> {
    let n = file.poses.len();
    let step = n.div_ceil(MAX_BUILD_FRAMES).max(1);
    let new = if step == 1 { "the part added" } else { "the parts added (the last one numbered)" };
    Figure {
        title: format!(
            "Building the stack of {n} {} parts: {}",
            file.part.name,
            if step == 1 { "one frame per part".to_string() } else { format!("one frame per {step} parts") },
        ),
        legend: vec![
            LegendItem::new(Swatch::Square(part_color(0)), new),
            LegendItem::new(Swatch::Square(MUTED), "parts placed before"),
            LegendItem::new(Swatch::Label, "part number"),
            LegendItem::new(Swatch::Disc(CG_MARK), "centre of gravity"),
        ],
        panels: frames
            .iter()
            .map(|(scene, caption)| FigurePanel { scene, view: ISOMETRIC, caption: caption.clone() })
            .collect(),
        columns: 5,
        cell: (220.0, 170.0),
        common_scale: true,
    }
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

/// What a part touches, for people: `the floor`, `part 3`, `a side of the floor`, `the maximum height` (parts
/// numbered from 1), each once, in the order of `contacts`.
pub fn contacts_text(contacts: Option<&Value>) -> String {
    let mut named: Vec<String> = Vec::new();
    for c in contacts.and_then(Value::as_array).into_iter().flatten() {
        let name = match c.get("with").and_then(Value::as_str) {
            Some("floor") => "the floor".to_string(),
            Some("stack") => match c.get("stack_part").and_then(Value::as_u64) {
                Some(k) => format!("part {}", k + 1),
                None => "a part".to_string(),
            },
            Some("floor_side") => "a side of the floor area".to_string(),
            Some("ceiling") => "the maximum height".to_string(),
            _ => continue,
        };
        if !named.contains(&name) {
            named.push(name);
        }
    }
    if named.is_empty() { "-".to_string() } else { named.join(", ") }
}

/// Why a part is where it is, for people: the stage that placed it, whether cheaper candidates of that stage were
/// rejected, and by which checks the candidates rejected while it was placed failed (`rejections` in plan.json).
pub fn placement_reason(p: &Map<String, Value>) -> String {
    let stage = match p.get("stage").and_then(Value::as_u64) {
        Some(1) => "stage 1 (within the stack's footprint)",
        Some(2) => "stage 2 (the whole floor)",
        _ => "stage unknown",
    };
    let rejected = p.get("rejected_candidates").and_then(Value::as_u64).unwrap_or(0);
    let why = match rejected {
        0 => "the cheapest candidate of its stage passed every check".to_string(),
        1 => "1 cheaper candidate of its stage failed a check".to_string(),
        k => format!("{k} cheaper candidates of its stage failed a check"),
    };
    let reasons = [
        ("not_stable", "not stable on their supports"),
        ("stack_not_stable", "the stack would not be stable"),
        ("not_graspable", "no face for the cup"),
        ("not_insertable", "not insertable from above"),
        ("clearance", "too close to another part"),
    ];
    let counts = p.get("rejections").and_then(Value::as_object);
    let failed: Vec<String> = reasons
        .iter()
        .filter_map(|(key, text)| {
            let k = counts?.get(*key).and_then(Value::as_u64).filter(|k| *k > 0)?;
            Some(format!("{k} {text}"))
        })
        .collect();
    let failed =
        if failed.is_empty() { String::new() } else { format!("; rejected in all its stages: {}", failed.join(", ")) };
    let drop = p.get("release_drop").and_then(Value::as_f64).unwrap_or(0.0);
    let drop =
        if drop > 0.0 { format!("; released {drop:.1} mm above its rest and drops into place") } else { String::new() };
    format!("{stage}: {why}{failed}{drop}")
}

/// The paragraph that says what the plan was asked, what it found, and why it stopped if it did.
pub fn plan_paragraph(file: &PlanFile) -> String {
    let (part, plan) = (&file.part, &file.plan);
    let o = &plan.options;
    let n = crate::input::short_number;
    let (lo, hi) = o.floor.polygon.iter().fold(([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]), |(lo, hi), p| {
        ([lo[0].min(p.x), lo[1].min(p.y)], [hi[0].max(p.x), hi[1].max(p.y)])
    });
    let asked = format!(
        "Asked: {count} {name} parts on a floor of {fx:.0} x {fy:.0} mm, at most {h:.0} mm high, with weight w = {w} \
         ({wmeaning}), {clearance} mm horizontal clearance between parts, turns in steps of {dtheta} degrees, a \
         {cup} mm suction cup on faces up to {tilt} degrees off level, and friction mu = {mu}.",
        count = o.count,
        name = part.name,
        fx = hi[0] - lo[0],
        fy = hi[1] - lo[1],
        h = o.floor.height,
        w = n(o.w),
        wmeaning = crate::cmd::plan::W_MEANING,
        clearance = n(o.clearance),
        dtheta = n((o.dtheta.to_degrees() * 1e6).round() / 1e6),
        cup = n(o.cup_diameter),
        tilt = n((o.grasp_tilt.to_degrees() * 1e6).round() / 1e6),
        mu = n(o.mu),
    );
    let [[x0, y0], [x1, y1]] = plan.footprint;
    let found = format!(
        "Found: {placed} of {count} parts placed, {height:.1} mm high on a footprint of {fx:.1} x {fy:.1} mm, total \
         cost {cost:.1} mm^2; the whole stack is {stable}.",
        placed = file.poses.len(),
        count = o.count,
        height = plan.height,
        fx = x1 - x0,
        fy = y1 - y0,
        cost = plan.total_cost,
        stable = if plan.stack_stable { "stable" } else { "not stable" },
    );
    let stopped = match &plan.stopped {
        Some(reason) => format!("The plan stopped early: {reason}."),
        None => "Every part was placed.".to_string(),
    };
    let st = &plan.stats;
    let rejected = [
        (st.rejected_not_stable, "not stable on its supports"),
        (st.rejected_stack_not_stable, "the stack with it not stable"),
        (st.rejected_not_graspable, "no face for the cup"),
        (st.rejected_not_insertable, "not insertable from above"),
        (st.rejected_clearance, "short of the clearance"),
    ];
    let total: usize = rejected.iter().map(|(k, _)| k).sum();
    let reasons: Vec<String> = rejected.iter().filter(|(k, _)| *k > 0).map(|(k, why)| format!("{k} {why}")).collect();
    let searched = format!(
        "The planner ran {searches} placement searches and checked {checked} candidates in {seconds:.1} s; {rejected}",
        searches = st.searches,
        checked = st.candidates_checked,
        seconds = file.seconds,
        rejected = if total == 0 {
            "none was rejected.".to_string()
        } else {
            format!("{total} were rejected: {}.", reasons.join(", "))
        },
    );
    format!("{asked} {found} {stopped} {searched}")
}

/// What each column of the report's table means.
pub const REPORT_COLUMNS: [(&str, &str); 11] = [
    ("#", "the part's number: 1 is placed first (plan.json: placements[# - 1], whose index is # - 1)"),
    ("position (mm)", "where the part's file origin comes to rest: x, y, z"),
    ("turn (deg)", "the part's turn about the vertical axis from its resting pose"),
    ("pose", "which stable resting pose it lies in: 1 has the lowest centre of gravity"),
    ("stage", "1: placed within the stack's footprint; 2: found by searching the whole floor"),
    ("cost (mm^2)", "the part's term of the cost the planner minimises (w weighs floor use against c.g. height)"),
    ("c.g. height (mm)", "the height of the part's centre of gravity"),
    (
        "margin",
        "the largest sideways push, as a fraction of the part's weight, that it resists on its supports (up to 10; \
         '-': not computed)",
    ),
    ("grasp radius (mm)", "the largest suction disc on its upward faces; the cup needs half its diameter"),
    ("touches", "what it rests on or touches"),
    ("why here", "the stage that placed it, and whether cheaper candidates were rejected"),
];

fn report_html(file: &PlanFile, svg_text: &str) -> String {
    let part = &file.part;
    let mut rows = String::new();
    for (i, p) in file.placements.iter().enumerate() {
        let number = |key: &str, digits: usize| match p.get(key).and_then(Value::as_f64) {
            Some(x) => format!("{x:.digits$}"),
            None => "-".to_string(),
        };
        let pose = p.get("resting_pose").and_then(Value::as_u64).map_or("-".to_string(), |k| (k + 1).to_string());
        let position = file.poses[i].position;
        rows.push_str(&format!(
            "<tr><td>{}</td><td>{:.2}, {:.2}, {:.2}</td><td>{}</td><td>{pose}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td class=\"text\">{}</td><td class=\"text\">{}</td></tr>\n",
            i + 1,
            position.x,
            position.y,
            position.z,
            number("theta_deg", 1),
            number("stage", 0),
            number("cost", 2),
            number("cg_height", 2),
            number("stability_margin", 2),
            number("grasp_radius", 1),
            esc(&contacts_text(p.get("contacts"))),
            esc(&placement_reason(p)),
        ));
    }
    let header: String = REPORT_COLUMNS.iter().map(|(c, _)| format!("<th>{}</th>", esc(c))).collect();
    let columns: String =
        REPORT_COLUMNS.iter().map(|(c, m)| format!("<dt>{}</dt><dd>{}</dd>\n", esc(c), esc(m))).collect();
    format!(
        r#"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>stackplan: {name}</title>
<style>body{{font-family:sans-serif;margin:2em;max-width:80em}}table{{border-collapse:collapse}}td,th{{border:1px solid #ccc;padding:3px 8px;text-align:right}}td.text{{text-align:left}}img{{max-width:100%}}dt{{font-weight:bold;float:left;clear:left;width:11em}}dd{{margin-left:12em}}</style>
</head><body>
<h1>Stacking plan: {placed} {name} parts</h1>
{origin}<p id="summary">{paragraph}</p>
<h2>Pictures</h2>
<p><img src="stack.png" alt="the stack: isometric, top and side views, parts numbered in placing order" width="1080"></p>
<details><summary>SVG</summary>{svg}</details>
<h2>Build</h2>
<p><img id="build" src="build.png" alt="the stack built part by part, the new part in colour" width="1100"></p>
<p>3-D model: <a href="stack.glb">stack.glb</a> (any glTF viewer; its nodes are named after the parts' numbers).
Plan: <a href="plan.json">plan.json</a> (a stack file: <code>stackplan check plan.json</code> checks it again).</p>
<h2>Parts</h2>
<table id="parts"><tr>{header}</tr>
{rows}</table>
<h3>Columns</h3>
<dl id="columns">
{columns}</dl>
</body></html>
"#,
        name = esc(&part.name),
        origin = file
            .part_origin
            .as_ref()
            .and_then(|o| crate::input::origin_note(o, part.mass().volume))
            .map(|n| format!("<p id=\"origin\">Part: {}.</p>\n", esc(&n)))
            .unwrap_or_default(),
        placed = file.poses.len(),
        paragraph = esc(&plan_paragraph(file)),
        svg = svg_text,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The report's "why here" names the stage, the cheaper candidates of the stage, and each check that rejected
    /// candidates while the part was placed, with its count; reasons without rejections are left out.
    #[test]
    fn why_here_names_the_checks_that_rejected_candidates() {
        let part = |v: Value| v.as_object().expect("object").clone();
        let passed = placement_reason(&part(serde_json::json!({"stage": 1, "rejected_candidates": 0})));
        assert_eq!(
            passed,
            "stage 1 (within the stack's footprint): the cheapest candidate of its stage passed every check"
        );
        let rejected = placement_reason(&part(serde_json::json!({
            "stage": 2, "rejected_candidates": 3, "release_drop": 0.31,
            "rejections": {"not_stable": 2, "stack_not_stable": 0, "not_graspable": 0, "not_insertable": 1, "clearance": 0}
        })));
        assert_eq!(
            rejected,
            "stage 2 (the whole floor): 3 cheaper candidates of its stage failed a check; rejected in all its stages: \
             2 not stable on their supports, 1 not insertable from above; released 0.3 mm above its rest and drops \
             into place"
        );
    }

    #[test]
    fn build_frames_cover_every_part_and_end_at_n() {
        assert_eq!(build_frame_counts(1), vec![1]);
        assert_eq!(build_frame_counts(15), (1..=15).collect::<Vec<_>>());
        assert_eq!(build_frame_counts(20).len(), 20);
        let c = build_frame_counts(121); // step 7: 7, 14, ..., 119, 121
        assert_eq!(c.first(), Some(&7));
        assert_eq!(c.last(), Some(&121));
        assert!(c.len() <= MAX_BUILD_FRAMES + 1);
        assert!(c.windows(2).all(|w| w[0] < w[1]));
        assert!(build_frame_counts(0).is_empty());
    }

    #[test]
    fn a_stack_file_without_summary_is_not_a_plan() {
        let part = stackplan_geom::io::json::part_json_string(
            &stackplan_geom::examples::part_by_name("cube", Default::default()).expect("cube"),
        );
        let text = format!(
            r#"{{"part": {part}, "placements": [{{"position": [0, 0, 0], "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}}]}}"#
        );
        let e = parse_plan_file(text.as_bytes(), Path::new("dir/p.json")).expect_err("no summary");
        assert!(matches!(e, PlanFileError::NotAPlan { .. }));
        assert!(e.to_string().starts_with("dir/p.json:"), "{e}");
        let with_bad_summary = text.replacen("{\"part\"", "{\"plan\": {\"w\": 1}, \"part\"", 1);
        let e = parse_plan_file(with_bad_summary.as_bytes(), Path::new("q.json")).expect_err("malformed");
        assert!(matches!(e, PlanFileError::Malformed { .. }), "{e}");
        assert!(e.to_string().starts_with("q.json: malformed plan"), "{e}");
        // a summary that is not an object is malformed, not missing; `null` counts as missing
        let not_an_object = text.replacen("{\"part\"", "{\"plan\": \"x\", \"part\"", 1);
        let e = parse_plan_file(not_an_object.as_bytes(), Path::new("s.json")).expect_err("malformed");
        assert_eq!(
            e.to_string(),
            "s.json: malformed plan: key `plan`: expected the plan summary (an object), got a string"
        );
        let null = text.replacen("{\"part\"", "{\"plan\": null, \"part\"", 1);
        let e = parse_plan_file(null.as_bytes(), Path::new("n.json")).expect_err("no summary");
        assert!(matches!(e, PlanFileError::NotAPlan { .. }), "{e}");
    }
}
