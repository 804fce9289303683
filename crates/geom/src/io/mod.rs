//! File formats: part JSON (sheet-metal and convex-pieces forms), STL (ASCII and binary), OBJ, binary glTF export,
//! the stack file, and STEP B-reps read into [`crate::cad::Brep`]. The formats are specified precisely in
//! `docs/formats.md`; what the STEP reader takes from ISO 10303-21 files is described in [`step`].
//!
//! Every reader returns an [`IoError`] that names the file and the place (line, line and column, byte offset, piece,
//! shell, face or placement index) and never panics on any input. Every writer goes through
//! [`atomic::write_atomic`]: the bytes go to a temporary file in the target's directory, which is then renamed over
//! the target, so a failed write never leaves a partial file behind; files that belong together go through
//! [`atomic::write_all_atomic`], which renames none of them until all are written.
//!
//! Mesh inputs (STL shells, OBJ groups) must be convex: [`mesh`] checks it exactly (hull with exact predicates, every
//! polygon on a hull face plane by exact `orient3d`, enclosed volume equal to the hull's) unless
//! [`ReadOptions::decompose_mesh`] asks for parry3d's approximate convex decomposition (VHACD).
//!
//! Complexity: parsing is linear in the file size; the convexity check costs a hull (expected O(n log n)) plus
//! O(polygons x hull faces) exact plane tests in the worst case (usually O(polygons), see [`mesh`]).

pub mod atomic;
pub mod glb;
pub mod json;
pub mod mesh;
pub mod obj;
pub mod sheet;
mod snap;
pub mod stack;
pub mod step;
pub mod stl;

use crate::hull::HullError;
use crate::part::{Part, PartError};
use crate::polytope::PolytopeError;
use crate::pose::PoseError;
use crate::sheet_metal::{Decomposition, SheetMetalError};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::{Path, PathBuf};

pub use atomic::{write_all_atomic, write_atomic};
pub use glb::{GlbItem, write_glb};
pub use json::{parse_part_json, part_json_string, read_part_json, write_part_json};
pub use obj::{obj_scene_string, obj_string, parse_obj, read_obj, write_obj, write_obj_scene};
pub use stack::{PlacedPart, StackFile, read_stack, read_stack_with, write_stack};
pub use stl::{parse_stl, read_stl, stl_ascii_string, stl_binary_bytes, write_stl_ascii, write_stl_binary};

/// Largest accepted coordinate magnitude (mm): 10^9 mm = 1000 km. Larger values are certainly input errors and would
/// overflow volumes and inertia tensors (which grow with the fifth power of lengths).
pub const MAX_COORDINATE: f64 = 1e9;

/// Where in a file an error is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Place {
    /// A 1-based line (OBJ, ASCII STL).
    Line(usize),
    /// A 1-based line and column (JSON, as reported by serde_json).
    LineColumn {
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
    },
    /// A 0-based byte offset (binary STL).
    Byte(u64),
    /// A 0-based convex piece index (part JSON `convex_pieces`, OBJ group in file order).
    Piece(usize),
    /// A point of a piece (both 0-based).
    PiecePoint {
        /// Piece index.
        piece: usize,
        /// Point index within the piece.
        point: usize,
    },
    /// A point of a sheet-metal face outline (`hole: None`) or hole.
    FacePoint {
        /// Face index.
        face: usize,
        /// Hole index, `None` for the outline.
        hole: Option<usize>,
        /// Point index.
        point: usize,
    },
    /// A 0-based placement index of a stack file.
    Placement(usize),
    /// A JSON key path such as `sheet_metal.thickness`.
    Key(String),
    /// A STEP entity instance by its instance number (`#17` is 17).
    Entity(u64),
    /// The file as a whole (empty file, no geometry).
    WholeFile,
}

impl fmt::Display for Place {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Place::Line(l) => write!(f, "line {l}"),
            Place::LineColumn { line, column } => write!(f, "line {line}, column {column}"),
            Place::Byte(b) => write!(f, "byte {b}"),
            Place::Piece(p) => write!(f, "piece {p}"),
            Place::PiecePoint { piece, point } => write!(f, "piece {piece}, point {point}"),
            Place::FacePoint { face, hole: None, point } => write!(f, "face {face}, outline point {point}"),
            Place::FacePoint { face, hole: Some(h), point } => write!(f, "face {face}, hole {h}, point {point}"),
            Place::Placement(i) => write!(f, "placement {i}"),
            Place::Key(k) => write!(f, "key `{k}`"),
            Place::Entity(n) => write!(f, "entity #{n}"),
            Place::WholeFile => write!(f, "whole file"),
        }
    }
}

/// Why a file could not be read or written. Every variant names the file; see [`Place`] for the places.
#[derive(Debug, thiserror::Error)]
pub enum IoError {
    /// The operating system refused to read or write the file.
    #[error("{}: {source}", file.display())]
    Os {
        /// The file.
        file: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The extension does not name a supported format.
    #[error("{}: unsupported file extension (expected {expected})", file.display())]
    UnsupportedExtension {
        /// The file.
        file: PathBuf,
        /// The supported extensions.
        expected: &'static str,
    },
    /// Malformed text: bad JSON, an unknown key, a bad token in OBJ or ASCII STL, a bad number, a STEP entity whose
    /// arguments are not what its type requires (count, kinds, referenced types, a zero direction).
    #[error("{}: {at}: {message}", file.display())]
    Syntax {
        /// The file.
        file: PathBuf,
        /// Where.
        at: Place,
        /// What is wrong.
        message: String,
    },
    /// A NaN or infinite coordinate, one beyond [`MAX_COORDINATE`], or a nonzero one below
    /// [`crate::MIN_COORDINATE`] in magnitude.
    #[error(
        "{}: {at}: coordinate {} is not finite or outside the supported range (0, or a magnitude from 1e-50 to \
         {MAX_COORDINATE:e} mm)",
        file.display(),
        short_number(*value)
    )]
    BadCoordinate {
        /// The file.
        file: PathBuf,
        /// Where.
        at: Place,
        /// The offending value.
        value: f64,
    },
    /// A number that must be positive and finite is not (thickness, density).
    #[error("{}: {at}: {what} must be positive and finite, got {value}", file.display())]
    NotPositive {
        /// The file.
        file: PathBuf,
        /// Where.
        at: Place,
        /// Which quantity.
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// A binary STL whose size is not `84 + 50 n` for the triangle count `n` in its header.
    #[error(
        "{}: byte {offset}: binary STL truncated or padded: header announces {triangles} triangles = {expected} bytes, file has {actual}",
        file.display()
    )]
    Truncated {
        /// The file.
        file: PathBuf,
        /// Byte offset where the data stops matching the header (the start of the first incomplete record, or of
        /// the first extra byte).
        offset: u64,
        /// Triangle count from the header (0 when even the 84-byte header is incomplete).
        triangles: u64,
        /// Expected size.
        expected: u64,
        /// Actual size.
        actual: u64,
    },
    /// An OBJ face refers to a vertex that does not exist (or index 0).
    #[error("{}: line {line}: vertex index {index} is out of range (there are {count} vertices so far)", file.display())]
    BadIndex {
        /// The file.
        file: PathBuf,
        /// 1-based line.
        line: usize,
        /// The index as written.
        index: i64,
        /// Vertices defined before this line.
        count: usize,
    },
    /// An OBJ face with fewer than three vertices.
    #[error("{}: line {line}: a face needs at least 3 vertices, got {count}", file.display())]
    FaceTooSmall {
        /// The file.
        file: PathBuf,
        /// 1-based line.
        line: usize,
        /// Vertices given.
        count: usize,
    },
    /// No geometry at all (no pieces, no triangles, no faces).
    #[error("{}: {at}: {what}", file.display())]
    Empty {
        /// The file.
        file: PathBuf,
        /// Where.
        at: Place,
        /// What is empty.
        what: &'static str,
    },
    /// A piece (or mesh shell/group) whose points have no 3-D hull: flat, collinear or coincident.
    #[error("{}: {at}: degenerate piece: {source}", file.display())]
    DegeneratePiece {
        /// The file.
        file: PathBuf,
        /// Piece or shell place.
        at: Place,
        /// The hull's reason.
        source: HullError,
    },
    /// A mesh shell (STL) or group (OBJ) that is not the boundary of a convex solid.
    #[error("{}: shell {shell}{}: not convex: {detail}", file.display(), name.as_ref().map(|n| format!(" ({n})")).unwrap_or_default())]
    NotConvex {
        /// The file.
        file: PathBuf,
        /// 0-based shell (STL: connected shell in file order; OBJ: group in file order).
        shell: usize,
        /// The OBJ group name, if any.
        name: Option<String>,
        /// What fails, with the line/byte of the first offending polygon.
        detail: String,
    },
    /// The file names both part forms (`sheet_metal` and `convex_pieces`) or neither.
    #[error("{}: {at}: a part needs exactly one of `sheet_metal` and `convex_pieces` ({found})", file.display())]
    PartForm {
        /// The file.
        file: PathBuf,
        /// Where (the part object).
        at: Place,
        /// "both given" or "neither given".
        found: &'static str,
    },
    /// The sheet-metal model is invalid (non-planar face, hole outside outline, self-intersection...).
    #[error("{}: sheet metal: {source}", file.display())]
    SheetMetal {
        /// The file.
        file: PathBuf,
        /// The model's reason (names the face).
        source: SheetMetalError,
    },
    /// The components do not make a part.
    #[error("{}: {source}", file.display())]
    Part {
        /// The file.
        file: PathBuf,
        /// The reason.
        source: PartError,
    },
    /// A polytope could not be built (an internal consistency failure: a bug if it ever shows).
    #[error("{}: {at}: {source}", file.display())]
    Polytope {
        /// The file.
        file: PathBuf,
        /// Where.
        at: Place,
        /// The reason.
        source: PolytopeError,
    },
    /// The approximate convex decomposition produced nothing usable.
    #[error("{}: shell {shell}: approximate convex decomposition failed: {detail}", file.display())]
    Decomposition {
        /// The file.
        file: PathBuf,
        /// The shell.
        shell: usize,
        /// Why.
        detail: String,
    },
    /// The solid was read but is not recognised as sheet metal (the reason names the faces).
    #[error("{}: not recognised as sheet metal: {source}", file.display())]
    NotSheetMetal {
        /// The file.
        file: PathBuf,
        /// The reason.
        source: Box<crate::cad::recognise::RecogniseError>,
    },
    /// A mesh that cannot be split into the faces of a solid for sheet-metal recognition (open, non-manifold).
    #[error("{}: {source}", file.display())]
    MeshFaces {
        /// The file.
        file: PathBuf,
        /// The reason (names the triangle).
        source: Box<crate::cad::mesh_faces::MeshFaceError>,
    },
    /// A stack placement whose rotation is not a proper rotation.
    #[error("{}: placement {placement}: {source}", file.display())]
    BadPose {
        /// The stack file.
        file: PathBuf,
        /// 0-based placement index.
        placement: usize,
        /// The reason.
        source: PoseError,
    },
    /// A STEP entity reached from the solid whose type the reader does not handle: a surface or curve that is none
    /// of those [`step`] reads, a solid with voids.
    #[error(
        "{}: {at}: {kind} {role} are not supported{}",
        file.display(),
        face.map(|f| format!(" (face #{f})")).unwrap_or_default()
    )]
    Unsupported {
        /// The file.
        file: PathBuf,
        /// The entity of the unsupported type.
        at: Place,
        /// Its type name as written (`CONICAL_SURFACE`), or a description (`B_SPLINE_CURVE_WITH_KNOTS of degree 3`).
        kind: String,
        /// What it would have been: `faces`, `edges`, `loops`, `solids`.
        role: &'static str,
        /// The STEP face it belongs to, if any.
        face: Option<u64>,
    },
    /// A STEP face whose exact surface and edges could not be tessellated: a boundary point off its surface, loops
    /// that bound no area of its parameter domain, a face around the apex of a cone or the pole of a sphere.
    #[error("{}: {at}: this face cannot be tessellated: {message}", file.display())]
    Tessellation {
        /// The file.
        file: PathBuf,
        /// The face.
        at: Place,
        /// Why.
        message: String,
    },
    /// A STEP reference to an instance that the file does not define.
    #[error("{}: {at}: refers to #{target}, which is not in the file", file.display())]
    MissingReference {
        /// The file.
        file: PathBuf,
        /// The referring entity.
        at: Place,
        /// The missing instance number.
        target: u64,
    },
    /// A STEP file with several solids and no choice among them.
    #[error(
        "{}: whole file: the file holds {count} solids; choose one with --solid N (0 to {}, in file order)",
        file.display(),
        count.saturating_sub(1)
    )]
    SeveralSolids {
        /// The file.
        file: PathBuf,
        /// How many solids it holds.
        count: usize,
    },
    /// A STEP solid index beyond the file's solids.
    #[error("{}: whole file: --solid {index} asked, but the file holds {count} solid(s) (0-based)", file.display())]
    NoSuchSolid {
        /// The file.
        file: PathBuf,
        /// The index asked for.
        index: usize,
        /// How many solids the file holds.
        count: usize,
    },
    /// The part referenced by a stack file could not be read.
    #[error("{}: key `part`: {source}", file.display())]
    PlacedPart {
        /// The stack file.
        file: PathBuf,
        /// The part file's error (names the part file).
        source: Box<IoError>,
    },
}

impl IoError {
    /// The file the error is about.
    pub fn file(&self) -> &Path {
        match self {
            IoError::Os { file, .. }
            | IoError::UnsupportedExtension { file, .. }
            | IoError::Syntax { file, .. }
            | IoError::BadCoordinate { file, .. }
            | IoError::NotPositive { file, .. }
            | IoError::Truncated { file, .. }
            | IoError::BadIndex { file, .. }
            | IoError::FaceTooSmall { file, .. }
            | IoError::Empty { file, .. }
            | IoError::DegeneratePiece { file, .. }
            | IoError::NotConvex { file, .. }
            | IoError::PartForm { file, .. }
            | IoError::SheetMetal { file, .. }
            | IoError::Part { file, .. }
            | IoError::Polytope { file, .. }
            | IoError::Decomposition { file, .. }
            | IoError::NotSheetMetal { file, .. }
            | IoError::MeshFaces { file, .. }
            | IoError::BadPose { file, .. }
            | IoError::Unsupported { file, .. }
            | IoError::Tessellation { file, .. }
            | IoError::MissingReference { file, .. }
            | IoError::SeveralSolids { file, .. }
            | IoError::NoSuchSolid { file, .. }
            | IoError::PlacedPart { file, .. } => file,
        }
    }

    pub(crate) fn os(file: &Path, source: std::io::Error) -> Self {
        IoError::Os { file: file.to_path_buf(), source }
    }
}

/// The length unit of a mesh file (STL and OBJ carry none). Parts are in millimetres everywhere else: STEP files
/// say their unit, part JSON is in millimetres.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Units {
    /// Millimetres (the default).
    #[default]
    Mm,
    /// Centimetres.
    Cm,
    /// Metres.
    M,
    /// Inches (25.4 mm).
    In,
}

impl Units {
    /// Millimetres per unit.
    pub fn millimetres(self) -> f64 {
        match self {
            Units::Mm => 1.0,
            Units::Cm => 10.0,
            Units::M => 1000.0,
            Units::In => 25.4,
        }
    }
}

impl fmt::Display for Units {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Units::Mm => "mm",
            Units::Cm => "cm",
            Units::M => "m",
            Units::In => "in",
        })
    }
}

impl std::str::FromStr for Units {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "mm" => Ok(Units::Mm),
            "cm" => Ok(Units::Cm),
            "m" => Ok(Units::M),
            "in" | "inch" => Ok(Units::In),
            _ => Err(format!("unknown unit {s:?}: expected mm, cm, m or in")),
        }
    }
}

/// Options for reading a part.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ReadOptions {
    /// How sheet-metal faces are split into convex polygons.
    pub decomposition: Decomposition,
    /// Run parry3d's VHACD on mesh shells/groups that are not convex instead of rejecting them; the part is then
    /// marked [`crate::part::PartOrigin::ApproximateDecomposition`].
    pub decompose_mesh: bool,
    /// Density; when given it overrides the file's `density` (JSON). Default: the file's, else 1.0.
    pub density: Option<f64>,
    /// A length (mm, positive and finite) within which a mesh (STL, OBJ) polygon counts as lying in the plane of a
    /// hull face, and facets in one plane are one face, for meshes written with fewer digits than their geometry
    /// needs (a part turned into place and written with six decimals). The readers never use less than their own
    /// tolerance: the kernel's (`1e-9 x` the mesh's extent), and for STL, whose coordinates are single precision,
    /// 16 `f32` roundings of its largest coordinate ([`mesh`]).
    pub mesh_tolerance: Option<f64>,
    /// The length unit of mesh files (STL, OBJ); ignored for STEP (which names its unit) and part JSON (mm).
    pub units: Units,
    /// The bend tolerance of sheet-metal recognition (mm, positive): how far a piece may stand outside the solid
    /// at a bend or a rounded outline. Default [`crate::cad::recognise::DEFAULT_BEND_TOLERANCE`].
    pub bend_tolerance: Option<f64>,
    /// Which solid of a STEP file with several (0-based, in file order); without it several solids are an error.
    pub solid: Option<usize>,
}

/// Reads a part, choosing the format by extension: `.json`, `.step`/`.stp`, `.stl`, `.obj` (case-insensitive). STEP
/// solids, and mesh shells that are not convex, are recognised as sheet metal ([`sheet`]).
pub fn read_part(path: impl AsRef<Path>, options: &ReadOptions) -> Result<Part, IoError> {
    let path = path.as_ref();
    match extension(path).as_deref() {
        Some("json") => json::read_part_json(path, options),
        Some("stl") => stl::read_stl(path, options),
        Some("obj") => obj::read_obj(path, options),
        Some("step" | "stp") => sheet::read_sheet(path, options).map(|(part, _)| part),
        _ => Err(IoError::UnsupportedExtension {
            file: path.to_path_buf(),
            expected: ".json, .step, .stp, .stl or .obj",
        }),
    }
}

/// Writes a part, choosing the format by extension: `.json` (convex-pieces form), `.stl` (binary), `.obj`, `.glb`.
pub fn write_part(path: impl AsRef<Path>, part: &Part) -> Result<(), IoError> {
    let path = path.as_ref();
    match extension(path).as_deref() {
        Some("json") => json::write_part_json(path, part),
        Some("stl") => stl::write_stl_binary(path, part),
        Some("obj") => obj::write_obj(path, part),
        Some("glb") => glb::write_glb(path, &[GlbItem::part(part)]),
        _ => Err(IoError::UnsupportedExtension { file: path.to_path_buf(), expected: ".json, .stl, .obj or .glb" }),
    }
}

pub(crate) fn extension(path: &Path) -> Option<String> {
    path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase)
}

/// Reads a whole file, mapping the OS error.
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>, IoError> {
    std::fs::read(path).map_err(|e| IoError::os(path, e))
}

/// The file stem as a default part name.
pub(crate) fn stem_name(path: &Path) -> String {
    path.file_stem().and_then(|s| s.to_str()).unwrap_or("part").to_string()
}

/// `value` as Rust prints it, in exponent form when that is shorter (`1e300` rather than 301 digits): numbers in
/// messages.
pub fn short_number(value: f64) -> String {
    let plain = value.to_string();
    let exponent = format!("{value:e}");
    if exponent.len() < plain.len() { exponent } else { plain }
}

/// Whether a coordinate or length (mm) is in the range the readers accept: 0, or a magnitude from
/// [`crate::MIN_COORDINATE`] to [`MAX_COORDINATE`] (so never NaN or infinite). The CLI holds its options to it too.
pub fn coordinate_in_range(value: f64) -> bool {
    value == 0.0 || (crate::MIN_COORDINATE..=MAX_COORDINATE).contains(&value.abs())
}

/// Checks one coordinate: [`coordinate_in_range`].
pub(crate) fn check_coordinate(value: f64, file: &Path, at: impl FnOnce() -> Place) -> Result<f64, IoError> {
    if coordinate_in_range(value) {
        Ok(value)
    } else {
        Err(IoError::BadCoordinate { file: file.to_path_buf(), at: at(), value })
    }
}

/// The density to use: the option, else the file's, else 1.0; checked positive and finite.
pub(crate) fn resolve_density(file: &Path, from_file: Option<f64>, options: &ReadOptions) -> Result<f64, IoError> {
    let density = options.density.or(from_file).unwrap_or(1.0);
    if density > 0.0 && density.is_finite() {
        Ok(density)
    } else {
        Err(IoError::NotPositive {
            file: file.to_path_buf(),
            at: Place::Key("density".into()),
            what: "density",
            value: density,
        })
    }
}
