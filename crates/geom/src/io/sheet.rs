//! Sheet-metal parts from CAD files: a STEP solid, or one closed mesh (STL, OBJ) that is not convex, recognised as
//! a sheet of constant thickness ([`crate::cad::recognise`]) and decomposed conservatively.
//!
//! A STEP solid with faces on other surfaces than planes and cylinders is tessellated within a quarter of the bend
//! tolerance and its mesh segmented as a mesh's ([`super::step`]); the pieces are then made within the rest of the
//! bend tolerance ([`crate::cad::recognise`]).
//!
//! The recognition's length tolerance follows the source: for STEP `1e-7` of the solid's size (at least `1e-6`
//! mm: the files carry about 13 significant digits and an uncertainty of `1e-7` of their unit); for a mesh ten times
//! the mesh's own tolerance ([`super::mesh`]: about 16 roundings of its largest single-precision coordinate), since a
//! mesh's planes are fitted to rounded vertices.

use super::mesh::{Mesh, MeshPolygon};
use super::{IoError, Place, ReadOptions, extension, read_bytes, resolve_density, stem_name};
use crate::cad::Brep;
use crate::cad::recognise::{DEFAULT_BEND_TOLERANCE, RecogniseOptions, Recognition, recognise};
use crate::part::Part;
use glam::DVec3;
use std::path::Path;

/// Reads a STEP file or a mesh (STL, OBJ) and recognises it as sheet metal: the part and what was recognised.
pub fn read_sheet(path: impl AsRef<Path>, options: &ReadOptions) -> Result<(Part, Recognition), IoError> {
    let path = path.as_ref();
    match extension(path).as_deref() {
        Some("step" | "stp") => {
            // a solid with faces on other surfaces is tessellated within a quarter of the bend tolerance
            let chord = options.bend_tolerance.unwrap_or(DEFAULT_BEND_TOLERANCE) / 4.0;
            let step = super::step::StepOptions { solid: options.solid, chord_tolerance: Some(chord) };
            let brep = super::step::read_step(path, &step)?;
            let size = brep_size(&brep);
            recognise_brep(path, stem_name(path), &brep, options, (1e-7 * size).max(1e-6))
        }
        Some("stl") => {
            let bytes = read_bytes(path)?;
            let mesh = super::stl::parse_stl_mesh(&bytes, path, options)?;
            recognise_mesh(path, mesh.name, &mesh.points, &mesh.polygons, options, mesh.tolerance)
        }
        Some("obj") => {
            let bytes = read_bytes(path)?;
            let Mesh { name, points, polygons, tolerance } = super::obj::parse_obj_mesh(&bytes, path, options)?;
            recognise_mesh(path, name, &points, &polygons, options, tolerance)
        }
        _ => Err(IoError::UnsupportedExtension { file: path.to_path_buf(), expected: ".step, .stp, .stl or .obj" }),
    }
}

/// Recognises welded mesh polygons (fan-triangulated) as sheet metal.
pub(crate) fn recognise_mesh(
    file: &Path,
    name: String,
    points: &[DVec3],
    polygons: &[MeshPolygon],
    options: &ReadOptions,
    tolerance: f64,
) -> Result<(Part, Recognition), IoError> {
    let triangles: Vec<MeshPolygon> = polygons
        .iter()
        .flat_map(|p| {
            (1..p.vertices.len().saturating_sub(1)).map(move |k| MeshPolygon {
                vertices: vec![p.vertices[0], p.vertices[k], p.vertices[k + 1]],
                place: p.place.clone(),
            })
        })
        .collect();
    if triangles.is_empty() {
        return Err(IoError::Empty { file: file.to_path_buf(), at: Place::WholeFile, what: "the mesh has no faces" });
    }
    let brep = crate::cad::mesh_faces::mesh_faces(points, &triangles, tolerance)
        .map_err(|source| IoError::MeshFaces { file: file.to_path_buf(), source: Box::new(source) })?;
    recognise_brep(file, name, &brep, options, 10.0 * tolerance)
}

fn recognise_brep(
    file: &Path,
    name: String,
    brep: &Brep,
    options: &ReadOptions,
    tolerance: f64,
) -> Result<(Part, Recognition), IoError> {
    let density = resolve_density(file, None, options)?;
    let recognise_options = RecogniseOptions {
        bend_tolerance: options.bend_tolerance.unwrap_or(DEFAULT_BEND_TOLERANCE),
        decomposition: options.decomposition,
        tolerance,
        density,
    };
    recognise(brep, &name, &recognise_options)
        .map_err(|source| IoError::NotSheetMetal { file: file.to_path_buf(), source: Box::new(source) })
}

/// The diagonal of the box of a B-rep's boundary points.
fn brep_size(brep: &Brep) -> f64 {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for face in &brep.faces {
        for p in face.boundary_points(std::f64::consts::FRAC_PI_2) {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    let d = (hi - lo).length();
    if d.is_finite() { d } else { 0.0 }
}
