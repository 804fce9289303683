//! Part JSON, in two forms (see `docs/formats.md`):
//!
//! * `{"name", "sheet_metal": {"thickness", "faces": [{"outline": [[x,y,z],...], "holes": [[[x,y,z],...],...]}]},
//!   "density"?}` — the sheet-metal model of \[A\] V-A-1, built by [`SheetMetal::build_part`];
//! * `{"name", "convex_pieces": [[[x,y,z],...],...], "density"?}` — each piece is the exact convex hull of its
//!   points with its rounding creases merged ([`convex_hull_merged`]: facets lying in one plane within the length
//!   tolerance are one face); a flat, collinear or coincident piece is an error naming its index.
//!
//! Unknown keys are rejected (`deny_unknown_fields`) so typos do not pass silently; serde_json rejects `NaN` and
//! `Infinity` literals and numbers that overflow `f64` (`1e400`); every coordinate is further checked against
//! [`super::MAX_COORDINATE`]. Parsing is O(file size); building costs one hull per piece.
//!
//! The writer emits the convex-pieces form with every component's vertices. Floats are printed with the shortest
//! representation that parses back to the same `f64` (serde_json uses ryu), so a part reads back as its exact form:
//! the hull of each component's vertices, which has the component's vertices and faces (as sets; the order is the
//! hull's), a face that is planar only to rounding (a rotated sheet-metal face) included: its facets lie in one plane
//! within the length tolerance and are merged again. Its origin becomes `ConvexPieces`.

use super::{IoError, Place, ReadOptions, check_coordinate, resolve_density, stem_name};
use crate::hull::convex_hull_merged;
use crate::part::{Part, PartOrigin};
use crate::sheet_metal::{SheetFace, SheetMetal};
use glam::DVec3;
use serde::Deserialize;
use std::fmt::Write as _;
use std::path::Path;

/// The JSON record of a part (both forms), with strict keys.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartRecord {
    /// Part name (default: the file stem).
    #[serde(default)]
    pub name: Option<String>,
    /// The sheet-metal form.
    #[serde(default)]
    pub sheet_metal: Option<SheetMetalRecord>,
    /// The convex-pieces form.
    #[serde(default)]
    pub convex_pieces: Option<Vec<Vec<[f64; 3]>>>,
    /// Density (default 1.0).
    #[serde(default)]
    pub density: Option<f64>,
}

/// The `sheet_metal` object.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SheetMetalRecord {
    /// Sheet thickness (mm), > 0.
    pub thickness: f64,
    /// Mid-surface faces.
    pub faces: Vec<FaceRecord>,
}

/// One sheet-metal face.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FaceRecord {
    /// Outer boundary.
    pub outline: Vec<[f64; 3]>,
    /// Holes.
    #[serde(default)]
    pub holes: Vec<Vec<[f64; 3]>>,
}

/// Maps a serde_json error to [`IoError::Syntax`] with its line and column.
pub(crate) fn json_error(file: &Path, e: &serde_json::Error) -> IoError {
    let full = e.to_string();
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    let mut message = full.strip_suffix(&suffix).unwrap_or(&full).to_string();
    if message.contains("number out of range") {
        message.push_str(" (numbers must be finite f64 values)");
    }
    IoError::Syntax { file: file.to_path_buf(), at: Place::LineColumn { line: e.line(), column: e.column() }, message }
}

/// Reads a part JSON file.
pub fn read_part_json(path: impl AsRef<Path>, options: &ReadOptions) -> Result<Part, IoError> {
    let path = path.as_ref();
    let bytes = super::read_bytes(path)?;
    parse_part_json(&bytes, path, options)
}

/// Parses part JSON from memory; `file` is only used in error messages and as the default name.
pub fn parse_part_json(bytes: &[u8], file: &Path, options: &ReadOptions) -> Result<Part, IoError> {
    let record: PartRecord = serde_json::from_slice(bytes).map_err(|e| json_error(file, &e))?;
    part_from_record(record, file, "", options)
}

/// Builds a part from its record. `key_prefix` is prepended to key places (`"part."` for a part inline in a stack).
pub(crate) fn part_from_record(
    record: PartRecord,
    file: &Path,
    key_prefix: &str,
    options: &ReadOptions,
) -> Result<Part, IoError> {
    let key = |k: &str| Place::Key(format!("{key_prefix}{k}"));
    let name = record.name.unwrap_or_else(|| stem_name(file));
    let density = resolve_density(file, record.density, options).map_err(|e| match e {
        IoError::NotPositive { file, what, value, .. } => {
            IoError::NotPositive { file, at: key("density"), what, value }
        }
        other => other,
    })?;
    let whole =
        if key_prefix.is_empty() { Place::WholeFile } else { Place::Key(key_prefix.trim_end_matches('.').into()) };
    match (record.sheet_metal, record.convex_pieces) {
        (Some(_), Some(_)) => Err(IoError::PartForm { file: file.to_path_buf(), at: whole, found: "both given" }),
        (None, None) => Err(IoError::PartForm { file: file.to_path_buf(), at: whole, found: "neither given" }),
        (None, Some(pieces)) => {
            if pieces.is_empty() {
                return Err(IoError::Empty {
                    file: file.to_path_buf(),
                    at: key("convex_pieces"),
                    what: "the part has no convex pieces",
                });
            }
            let mut components = Vec::with_capacity(pieces.len());
            for (piece, points) in pieces.iter().enumerate() {
                let points = checked_points(points, file, |point| Place::PiecePoint { piece, point })?;
                let hull = convex_hull_merged(&points).map_err(|source| IoError::DegeneratePiece {
                    file: file.to_path_buf(),
                    at: Place::Piece(piece),
                    source,
                })?;
                components.push(hull.polytope);
            }
            Part::from_components(name, components, density, PartOrigin::ConvexPieces)
                .map_err(|source| IoError::Part { file: file.to_path_buf(), source })
        }
        (Some(sheet), None) => {
            if !(sheet.thickness > 0.0 && sheet.thickness.is_finite()) {
                return Err(IoError::NotPositive {
                    file: file.to_path_buf(),
                    at: key("sheet_metal.thickness"),
                    what: "thickness",
                    value: sheet.thickness,
                });
            }
            // (a thickness beyond the coordinate limit would give faces whose areas overflow)
            check_coordinate(sheet.thickness, file, || key("sheet_metal.thickness"))?;
            if sheet.faces.is_empty() {
                return Err(IoError::Empty {
                    file: file.to_path_buf(),
                    at: key("sheet_metal.faces"),
                    what: "the sheet-metal model has no faces",
                });
            }
            let mut faces = Vec::with_capacity(sheet.faces.len());
            for (face, record) in sheet.faces.iter().enumerate() {
                let outline =
                    checked_points(&record.outline, file, |point| Place::FacePoint { face, hole: None, point })?;
                let mut holes = Vec::with_capacity(record.holes.len());
                for (h, hole) in record.holes.iter().enumerate() {
                    holes.push(checked_points(hole, file, |point| Place::FacePoint { face, hole: Some(h), point })?);
                }
                faces.push(SheetFace { outline, holes });
            }
            let model = SheetMetal { thickness: sheet.thickness, faces };
            model
                .build_part(&name, density, options.decomposition)
                .map_err(|source| IoError::SheetMetal { file: file.to_path_buf(), source })
        }
    }
}

fn checked_points(points: &[[f64; 3]], file: &Path, place: impl Fn(usize) -> Place) -> Result<Vec<DVec3>, IoError> {
    points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            for &c in p {
                check_coordinate(c, file, || place(i))?;
            }
            Ok(DVec3::from_array(*p))
        })
        .collect()
}

/// The part in the convex-pieces form, one piece per line.
pub fn part_json_string(part: &Part) -> String {
    part_json_value_string(part, "")
}

/// The part object, indented by `indent` (used inline in stack files).
pub(crate) fn part_json_value_string(part: &Part, indent: &str) -> String {
    let mut s = String::new();
    let name = serde_json::Value::String(part.name.clone()).to_string();
    let _ = writeln!(s, "{{");
    let _ = writeln!(s, "{indent}  \"name\": {name},");
    let _ = writeln!(s, "{indent}  \"density\": {},", number(part.density));
    let _ = writeln!(s, "{indent}  \"convex_pieces\": [");
    for (i, c) in part.components.iter().enumerate() {
        let points: Vec<String> =
            c.vertices().iter().map(|v| format!("[{}, {}, {}]", number(v.x), number(v.y), number(v.z))).collect();
        let comma = if i + 1 < part.components.len() { "," } else { "" };
        let _ = writeln!(s, "{indent}    [{}]{comma}", points.join(", "));
    }
    let _ = writeln!(s, "{indent}  ]");
    let _ = write!(s, "{indent}}}");
    s
}

/// A finite f64 in JSON's shortest round-trip form (serde_json/ryu).
pub(crate) fn number(x: f64) -> String {
    serde_json::Number::from_f64(x).map(|n| n.to_string()).unwrap_or_else(|| "null".into())
}

/// Writes the part in the convex-pieces form, atomically.
pub fn write_part_json(path: impl AsRef<Path>, part: &Part) -> Result<(), IoError> {
    let mut text = part_json_string(part);
    text.push('\n');
    super::atomic::write_atomic(path, text.as_bytes())
}
