//! STEP (ISO 10303-21 exchange files of the AP203, AP214 and AP242 schemas) read into a [`Brep`].
//!
//! Two private modules do the work: `p21` parses the clear-text encoding of ISO 10303-21 into entity instances,
//! and `brep` walks the entity graph from one solid down to its points and builds the faces.
//!
//! What is read, with the entity names of ISO 10303-42 (geometric and topological representation) as the AP214 and
//! AP242 schemas use them:
//! * the solid: a `MANIFOLD_SOLID_BREP`, or a `CLOSED_SHELL` that no solid uses, as a solid of its own
//!   (`BREP_WITH_VOIDS` is counted as a solid but refused). With several solids, [`StepOptions::solid`] picks one
//!   (0-based, in file order); without it they are an error;
//! * faces: `ADVANCED_FACE` and `FACE_SURFACE` (also through `ORIENTED_FACE`), bounded by `FACE_OUTER_BOUND` and
//!   `FACE_BOUND` of `EDGE_LOOP`s (or `POLY_LOOP`s) of `ORIENTED_EDGE`s of `EDGE_CURVE`s between `VERTEX_POINT`s;
//!   `VERTEX_LOOP`s (degenerate loops) are skipped;
//! * surfaces: `PLANE` and `CYLINDRICAL_SURFACE`; any other surface is [`IoError::Unsupported`] naming the entity;
//! * curves: `LINE`, `CIRCLE`, degree-1 `B_SPLINE_CURVE_WITH_KNOTS` and `POLYLINE` (straight segments through their
//!   points), each possibly inside a `SURFACE_CURVE` or `SEAM_CURVE` (the 3-D curve is taken, the parameter-space
//!   curves ignored). The edge's vertices are the exact ends of its segments; any other curve is
//!   [`IoError::Unsupported`].
//!
//! Orientation: a planar face's outward normal is its plane's placement axis, negated when the face's `same_sense` is
//! `.F.`; its loops are oriented from their geometry (the loop of largest absolute area is the outer one, made
//! counter-clockwise about the normal, and the others clockwise), not from the files' flags. A cylindrical face is
//! convex (outward normal away from the axis) when its `same_sense` is `.T.`; its loops follow the bound and edge
//! flags.
//!
//! Units: the length unit of the representation context (`GLOBAL_UNIT_ASSIGNED_CONTEXT`) of the shape
//! representation that holds the solid: an `SI_UNIT` of metres with its prefix, or a `CONVERSION_BASED_UNIT`
//! (`INCH`, `FOOT`, ...) defined by a `(LENGTH_)MEASURE_WITH_UNIT` of another length unit, recursively. When that
//! representation has none, the one length unit all the file's contexts agree on; failing that, millimetres with a
//! warning. Every coordinate and radius is scaled to millimetres and must pass [`super::coordinate_in_range`].
//!
//! Errors name the file and the place: a line for syntax errors, an entity (`entity #17`) for everything else.
//! Entities that the solid does not reach (products, presentation, parameter-space curves) are never looked at
//! beyond their syntax.
//!
//! Complexity: parsing is linear in the file size. Instances are kept in a hash map by instance number, and the
//! solid's graph is walked once per use of each entity (a face once per shell that lists it, an edge once per loop
//! that uses it, a vertex once per edge), which for a valid solid (each face listed once, each edge in two loops) is
//! linear in the file size too.
//!
mod brep;
mod p21;
mod tessellate;

use super::{IoError, Place, read_bytes};
use crate::cad::{Brep, Tessellation};
use std::path::Path;

/// The chord tolerance (mm) of tessellated faces when [`StepOptions::chord_tolerance`] gives none: a quarter of the
/// default bend tolerance ([`crate::cad::recognise::DEFAULT_BEND_TOLERANCE`]).
pub const DEFAULT_CHORD_TOLERANCE: f64 = crate::cad::recognise::DEFAULT_BEND_TOLERANCE / 4.0;

/// Options for reading a STEP file.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepOptions {
    /// Which solid to read when the file holds several: 0-based, in the order of the solids' instances in the file
    /// (the CLI's `--solid N`). `None`: the file must hold exactly one.
    pub solid: Option<usize>,
    /// The chord tolerance (mm, positive) of a solid that is tessellated: how far its triangles may stand from its
    /// exact faces. Default [`DEFAULT_CHORD_TOLERANCE`]; [`crate::io::sheet`] takes a quarter of the bend tolerance.
    pub chord_tolerance: Option<f64>,
}

/// Reads the solid of a STEP file: [`parse_step`] on the file's bytes.
pub fn read_step(path: impl AsRef<Path>, options: &StepOptions) -> Result<Brep, IoError> {
    let path = path.as_ref();
    let bytes = read_bytes(path)?;
    parse_step(&bytes, path, options)
}

/// Reads the solid of a STEP file from its bytes; `file` names it in errors. The B-rep's volume is `None`.
pub fn parse_step(bytes: &[u8], file: &Path, options: &StepOptions) -> Result<Brep, IoError> {
    if bytes.iter().all(u8::is_ascii_whitespace) {
        return Err(IoError::Empty { file: file.to_path_buf(), at: Place::WholeFile, what: "empty STEP file" });
    }
    let exchange = p21::parse(bytes).map_err(|e| IoError::Syntax {
        file: file.to_path_buf(),
        at: Place::Line(e.line),
        message: e.message,
    })?;
    brep::build(&exchange, file, options)
}

/// The B-rep of a tessellated solid: its mesh segmented into faces as a mesh is. The mesh's length tolerance is
/// `1e-9` of its size (at least `1e-6` mm): its points are on the exact faces to rounding.
fn tessellated_brep(graph: &brep::Graph<'_>, solid: u64, options: &StepOptions) -> Result<Brep, IoError> {
    let chord = options.chord_tolerance.filter(|c| c.is_finite() && *c > 0.0).unwrap_or(DEFAULT_CHORD_TOLERANCE);
    let mesh = tessellate::tessellate_solid(graph, solid, chord)?;
    let (mut lo, mut hi) = (glam::DVec3::INFINITY, glam::DVec3::NEG_INFINITY);
    for p in &mesh.points {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let size = (hi - lo).length();
    let tolerance = if size.is_finite() { (1e-9 * size).max(1e-6) } else { 1e-6 };
    let brep = crate::cad::mesh_faces::mesh_faces(&mesh.points, &mesh.triangles, tolerance)
        .map_err(|source| IoError::MeshFaces { file: graph.file.to_path_buf(), source: Box::new(source) })?;
    tracing::info!(
        file = %graph.file.display(),
        faces = mesh.faces,
        curved_faces = mesh.curved,
        triangles = mesh.triangles.len(),
        chord_tolerance = chord,
        "STEP solid tessellated: {} of its {} faces are on other surfaces than planes and cylinders",
        mesh.curved,
        mesh.faces
    );
    Ok(Brep {
        tessellation: Some(Tessellation {
            faces: mesh.faces,
            curved_faces: mesh.curved,
            triangles: mesh.triangles.len(),
            chord_tolerance: chord,
        }),
        ..brep
    })
}
