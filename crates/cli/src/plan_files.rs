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
    Figure, FigurePanel, ISOMETRIC, MUTED, Marker, Scene, Solid, figure_png, figure_svg, part_color, three_views,
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
    crate::output::json_text(&json!({ "part": inline, "placements": placements, "plan": summary }))
}

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
    // the error names the nested key (`plan.options.floor.height`), not only the summary
    let plan: Plan = serde_path_to_error::deserialize(Value::Object(summary)).map_err(|e| {
        let key = match e.path().to_string().as_str() {
            "." => "plan".to_string(),
            nested => format!("plan.{nested}"),
        };
        PlanFileError::Malformed { file: path.to_path_buf(), message: format!("key `{key}`: {}", e.inner()) }
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
    scene.title = format!(
        "{} x {}: w = {}, height {:.1} mm, total cost {:.1}",
        file.poses.len(),
        file.part.name,
        plan.options.w,
        plan.height,
        plan.total_cost
    );
    scene
}

/// The first `count` parts; parts from `new_from` on in their colour, numbered with their c.g. marked (only the last
/// one when a build frame adds several), earlier ones grey.
fn frame_scene(file: &PlanFile, count: usize, new_from: usize, floor: Vec<DVec3>, number_all: bool) -> Scene {
    let mut scene = Scene { floor, ..Scene::default() };
    for (i, pose) in file.poses.iter().enumerate().take(count) {
        let new = i >= new_from;
        let color = if new { part_color(i) } else { MUTED };
        for c in &file.part.components {
            scene.solids.push(Solid { polytope: c.transformed(pose.rotation, pose.position), color, part: i });
        }
        // every new part is numbered in the stack picture and in one-part frames; a frame adding several parts
        // numbers only its last one (small parts' numbers would cover each other)
        let numbered = new && (number_all || i + 1 == count);
        if numbered {
            let cg = pose.apply(file.part.mass.center_of_gravity);
            scene.labels.push((i + 1, cg));
            scene.markers.push(Marker { position: cg, color: [200, 0, 0] });
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
            (scene, format!("n = {count}"))
        })
        .collect()
}

fn build_figure<'a>(file: &PlanFile, frames: &'a [(Scene, String)]) -> Figure<'a> {
    let n = file.poses.len();
    let step = n.div_ceil(MAX_BUILD_FRAMES).max(1);
    Figure {
        title: format!(
            "Building the stack of {n} x {}: {}, the new part{} in colour",
            file.part.name,
            if step == 1 { "one frame per part".to_string() } else { format!("one frame per {step} parts") },
            if step == 1 { "" } else { "s" }
        ),
        panels: frames
            .iter()
            .map(|(scene, caption)| FigurePanel { scene, view: ISOMETRIC, caption: caption.clone() })
            .collect(),
        columns: 5,
        cell: (220.0, 170.0),
        common_scale: true,
    }
}

fn report_html(file: &PlanFile, svg_text: &str) -> String {
    let (part, plan, seconds) = (&file.part, &file.plan, file.seconds);
    let esc = |s: &str| s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;");
    let mut rows = String::new();
    for (i, p) in file.placements.iter().enumerate() {
        let number = |key: &str, digits: usize| match p.get(key).and_then(Value::as_f64) {
            Some(x) => format!("{x:.digits$}"),
            None => "-".to_string(),
        };
        let position = file.poses[i].position;
        rows.push_str(&format!(
            "<tr><td>{}</td><td>{:.2}, {:.2}, {:.2}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
            i + 1,
            position.x,
            position.y,
            position.z,
            number("theta_deg", 1),
            number("resting_pose", 0),
            number("stage", 0),
            number("cost", 2),
            number("cg_height", 2),
            number("stability_margin", 2),
            number("grasp_radius", 1),
            p.get("contacts").and_then(Value::as_array).map_or("-".to_string(), |c| c.len().to_string())
        ));
    }
    format!(
        r#"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>stackplan: {name}</title>
<style>body{{font-family:sans-serif;margin:2em}}table{{border-collapse:collapse}}td,th{{border:1px solid #ccc;padding:3px 8px;text-align:right}}img{{max-width:100%}}</style>
</head><body>
<h1>Stacking plan: {placed} x {name}</h1>
{origin}<p id="summary">{status}. Height {height:.1} mm, footprint {fx:.1} x {fy:.1} mm, total cost {cost:.1} (w = {w}),
clearance {clearance} mm, whole stack stable: {stable}. Planned in {seconds:.1} s
({searches} placement searches, {checked} candidates checked, {pairs} component pairs evaluated).</p>
<h2>Pictures</h2>
<p><img src="stack.png" alt="the stack: isometric, top and side views" width="1080"></p>
<details><summary>SVG</summary>{svg}</details>
<h2>Build</h2>
<p><img id="build" src="build.png" alt="the stack built part by part, the new part in colour" width="1100"></p>
<p>3-D model: <a href="stack.glb">stack.glb</a> (any glTF viewer). Plan: <a href="plan.json">plan.json</a>
(a stack file: <code>stackplan check plan.json</code>).</p>
<h2>Parts</h2>
<table id="parts"><tr><th>#</th><th>position (mm)</th><th>theta (deg)</th><th>pose</th><th>stage</th><th>cost</th><th>c.g. height</th><th>margin</th><th>grasp radius</th><th>contacts</th></tr>
{rows}</table>
</body></html>
"#,
        name = esc(&part.name),
        origin = file
            .part_origin
            .as_ref()
            .and_then(|o| crate::input::origin_note(o, part.mass.volume))
            .map(|n| format!("<p id=\"origin\">Part: {}.</p>\n", esc(&n)))
            .unwrap_or_default(),
        placed = file.poses.len(),
        status = esc(plan.stopped.as_deref().unwrap_or("All parts placed")),
        height = plan.height,
        fx = plan.footprint[1][0] - plan.footprint[0][0],
        fy = plan.footprint[1][1] - plan.footprint[0][1],
        cost = plan.total_cost,
        w = plan.options.w,
        clearance = plan.options.clearance,
        stable = plan.stack_stable,
        seconds = seconds,
        searches = plan.stats.searches,
        checked = plan.stats.candidates_checked,
        pairs = plan.stats.pairs_evaluated,
        svg = svg_text,
        rows = rows,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

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
