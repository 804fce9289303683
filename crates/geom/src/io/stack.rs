//! The stack file (issue 6): one part and its placements.
//!
//! ```json
//! {"part": "channel.json",
//!  "placements": [{"position": [x, y, z], "rotation": [[r00, r01, r02], [r10, r11, r12], [r20, r21, r22]]}]}
//! ```
//!
//! `part` is a path relative to the stack file's directory (any format [`super::read_part`] reads) or an inline part
//! object (the part JSON of [`super::json`]). A placement maps a point `v` of the part file's coordinates to the world
//! point `rotation . v + position`, the rotation given by rows (`rotation[i][j]` is row `i`, column `j`); it must be
//! a proper rotation ([`Pose::check`]). Placements may carry extra keys (cost, theta, contacts...), which are kept in
//! [`StackFile::extras`] and written back; a top-level `plan` object (the summary of a plan file written by
//! `stackplan plan`) is accepted and ignored; other unknown top-level keys are rejected. O(file size) plus reading the part.

use super::json::{PartRecord, json_error, part_from_record, part_json_value_string};
use super::{IoError, Place, ReadOptions, check_coordinate};
use crate::part::Part;
use crate::pose::{Pose, PoseRecord};
use serde::Deserialize;
use serde_json::{Map, Value};
use std::path::{Path, PathBuf};

/// A stack file's contents.
#[derive(Debug, Clone, PartialEq)]
pub struct StackFile {
    /// The part.
    pub part: Part,
    /// The part file, resolved against the stack file's directory (`None` when the part is inline).
    pub part_path: Option<PathBuf>,
    /// The placements.
    pub placements: Vec<Pose>,
    /// The extra keys of each placement (parallel to `placements`).
    pub extras: Vec<Map<String, Value>>,
    /// The top-level `plan` summary of a plan file (`stackplan plan`), as written; `None` for a plain stack file.
    pub plan: Option<Value>,
}

/// How [`write_stack`] refers to the part.
#[derive(Debug, Clone, Copy)]
pub enum PlacedPart<'a> {
    /// A path, written as given (it should be relative to the stack file's directory).
    Path(&'a Path),
    /// The part inline, in the convex-pieces form.
    Inline(&'a Part),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StackRecord {
    part: Value,
    placements: Vec<PlacementRecord>,
    /// The summary a plan file (`stackplan plan`) carries beside its placements; not part of the stack.
    #[serde(default)]
    plan: Option<Value>,
}

#[derive(Debug, Deserialize)]
struct PlacementRecord {
    position: [f64; 3],
    rotation: [[f64; 3]; 3],
    #[serde(flatten)]
    extra: Map<String, Value>,
}

/// Reads a stack file with default part options.
pub fn read_stack(path: impl AsRef<Path>) -> Result<StackFile, IoError> {
    read_stack_with(path, &ReadOptions::default())
}

/// Reads a stack file; `options` apply to the part.
pub fn read_stack_with(path: impl AsRef<Path>, options: &ReadOptions) -> Result<StackFile, IoError> {
    let path = path.as_ref();
    let bytes = super::read_bytes(path)?;
    parse_stack(&bytes, path, options)
}

/// Parses a stack file from memory; a part path is resolved against `file`'s directory.
pub fn parse_stack(bytes: &[u8], file: &Path, options: &ReadOptions) -> Result<StackFile, IoError> {
    let record: StackRecord = serde_json::from_slice(bytes).map_err(|e| json_error(file, &e))?;
    let (part, part_path) = match record.part {
        Value::String(relative) => {
            let dir = file.parent().unwrap_or_else(|| Path::new(""));
            let part_path = dir.join(&relative);
            let part = super::read_part(&part_path, options)
                .map_err(|e| IoError::PlacedPart { file: file.to_path_buf(), source: Box::new(e) })?;
            (part, Some(part_path))
        }
        value @ Value::Object(_) => {
            let inline: PartRecord = serde_json::from_value(value).map_err(|e| IoError::Syntax {
                file: file.to_path_buf(),
                at: Place::Key("part".into()),
                message: e.to_string(),
            })?;
            (part_from_record(inline, file, "part.", options)?, None)
        }
        other => {
            return Err(IoError::Syntax {
                file: file.to_path_buf(),
                at: Place::Key("part".into()),
                message: format!("expected a path string or a part object, found {other}"),
            });
        }
    };
    let mut placements = Vec::with_capacity(record.placements.len());
    let mut extras = Vec::with_capacity(record.placements.len());
    for (i, p) in record.placements.into_iter().enumerate() {
        for &c in p.position.iter().chain(p.rotation.iter().flatten()) {
            check_coordinate(c, file, || Place::Placement(i))?;
        }
        let pose = Pose::try_from(PoseRecord { position: p.position, rotation: p.rotation })
            .map_err(|source| IoError::BadPose { file: file.to_path_buf(), placement: i, source })?;
        placements.push(pose);
        extras.push(p.extra);
    }
    Ok(StackFile { part, part_path, placements, extras, plan: record.plan })
}

/// The stack file text. `extras[i]` (if present) is merged into placement `i` (it cannot override the pose keys).
pub fn stack_json_string(part: PlacedPart<'_>, placements: &[Pose], extras: &[Map<String, Value>]) -> String {
    let part_text = match part {
        PlacedPart::Path(p) => Value::String(p.to_string_lossy().into_owned()).to_string(),
        PlacedPart::Inline(part) => part_json_value_string(part, "  "),
    };
    let mut lines = Vec::with_capacity(placements.len());
    for (i, pose) in placements.iter().enumerate() {
        let record = PoseRecord::from(pose);
        let mut object = Map::new();
        object.insert("position".into(), serde_json::json!(record.position));
        object.insert("rotation".into(), serde_json::json!(record.rotation));
        if let Some(extra) = extras.get(i) {
            for (k, v) in extra {
                if k != "position" && k != "rotation" {
                    object.insert(k.clone(), v.clone());
                }
            }
        }
        lines.push(format!("    {}", Value::Object(object)));
    }
    format!("{{\n  \"part\": {part_text},\n  \"placements\": [\n{}\n  ]\n}}\n", lines.join(",\n"))
}

/// Writes a stack file atomically.
pub fn write_stack(path: impl AsRef<Path>, part: PlacedPart<'_>, placements: &[Pose]) -> Result<(), IoError> {
    write_stack_with_extras(path, part, placements, &[])
}

/// Writes a stack file with extra keys per placement, atomically.
pub fn write_stack_with_extras(
    path: impl AsRef<Path>,
    part: PlacedPart<'_>,
    placements: &[Pose],
    extras: &[Map<String, Value>],
) -> Result<(), IoError> {
    super::atomic::write_atomic(path, stack_json_string(part, placements, extras).as_bytes())
}
