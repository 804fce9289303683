//! Meshes to parts: welding, shell splitting, the convexity check and the optional VHACD decomposition.
//!
//! **Welding.** Vertices with exactly equal coordinates (`-0.0` and `0.0` identified) become one vertex; nothing is
//! merged within a tolerance, so the check below stays exact. O(n) expected (hashing).
//!
//! **Shells (STL).** Triangles are linked across edges: a triangle's directed edge `a -> b` is paired with a triangle
//! that traverses `b -> a`. When several do (convex components of one part touching along a face or an edge, as the
//! prisms of a sheet-metal part do), the partner is the first one met when the triangle's half-plane is rotated about
//! the edge into the solid (away from its outward normal); a triangle lying on the same half-plane (the touching face
//! of the neighbouring component: exact `orient3d == 0`, or its far vertex within the length tolerance (below) of the
//! plane, for a shared face planar only to rounding that each component triangulates along another diagonal) is met
//! last. This is the classical rule for separating closed shells that touch (each solid's interior lies between a
//! triangle and its partner). Shells are the connected components of these links (union-find), numbered by their first
//! triangle in file order. A directed edge with no partner means the shell is open, which is reported as not convex.
//! O(T log T).
//!
//! **Convexity.** A closed shell bounds a convex solid iff (1) its vertices have a 3-D hull (`convex_hull`, exact), (2)
//! every polygon of the shell lies in the plane of one hull face — decided by the exact `orient3d` of every polygon
//! vertex against three non-collinear vertices of that face ([`crate::polytope::ConvexPolytope::face_frame`]) — or,
//! failing that, lies within the length tolerance (below) of the plane of one face of the hull with its rounding
//! creases merged ([`convex_hull_merged_within`]: a face of a part exported in some orientation is planar only to
//! rounding, and another tool triangulates it along either diagonal, one of them across an exact crease), and (3) the
//! shell covers the hull boundary exactly once with outward orientation: its signed enclosed volume
//! `sum det(p0 - o, pi - o, pi+1 - o) / 6` equals the hull's volume. (1)-(2) are exact; (3) compares two rounded sums,
//! with the tolerance `1e-13 T d^3 + 1e-12 V + 2 t d^2` (T fan triangles, d the shell's bounding diagonal, V the hull
//! volume, t the length tolerance below), a few dozen times the worst rounding of the sum plus what a shell within the
//! length tolerance of the hull's boundary can enclose more or less; a missing, doubled or inverted polygon changes the
//! volume by far more. So a shell is accepted exactly when it is convex, up to the length tolerance in (2) only; a dent
//! or fold deeper than the tolerance is rejected. Cost: the hull plus, per polygon, exact plane tests against the faces
//! around one of its hull vertices (O(polygons x face degree) for a convex mesh); only polygons with no hull vertex
//! (fine subdivisions of a face) fall back to the best-aligned face and then to all faces, O(polygons x faces) in the
//! worst case.
//!
//! **The length tolerance** of the two tests above that use one (the shared-face rule and (2)'s fallback, and the merge
//! of rounding creases in the piece) is the largest of: the kernel's, `1e-9 x` the mesh's extent
//! ([`crate::tolerance`]); for single-precision coordinates, `16 x 2^-24 x` the largest coordinate magnitude, 16
//! roundings to `f32`; and [`super::ReadOptions::mesh_tolerance`] when given, for files written with fewer digits
//! still. Coordinates are single precision in binary STL (`f32`), and in a text file (ASCII STL, OBJ) when none is
//! written with more than 9 significant digits, the most an `f32` needs to be written exactly (`Precision`):
//! exporters write 6 to 9 (the STL specification says that ASCII STL is single precision too), while a file written
//! with the shortest text of `f64` values, as the writers here do, has 15 to 17 for a part turned into place, and is
//! then taken as written. The rounding of a face's corners moves them off its plane by at most one rounding each, and
//! its exact facets then fold by a few roundings.
//!
//! **Decomposition.** With [`super::ReadOptions::decompose_mesh`], a shell failing (2)-(3) is handed to parry3d-f64's
//! VHACD (voxel-based approximate convex decomposition, K. Mamou, *Volumetric hierarchical approximate convex
//! decomposition*, Game Engine Gems 3, 2016) with default parameters; each returned hull is rebuilt with our exact
//! hull, and the part is marked [`PartOrigin::ApproximateDecomposition`]: its components only approximate the mesh and
//! may overlap slightly.

use super::{IoError, Place, ReadOptions, resolve_density};
use crate::accurate_normal::accurate_cross;
use crate::hull::{HullError, convex_hull, convex_hull_merged_within};
use crate::part::{Part, PartOrigin};
use crate::polytope::{ConvexPolytope, newell_normal};
use crate::predicates::side;
use crate::tolerance::{Tolerance, bounding_diagonal};
use crate::union_find::{find, union};
use glam::DVec3;
use std::cmp::Ordering;
use std::collections::HashMap;
use std::path::Path;

/// Exact vertex welding by coordinates.
#[derive(Debug, Default)]
pub(crate) struct Welder {
    map: HashMap<[u64; 3], usize>,
    pub points: Vec<DVec3>,
}

impl Welder {
    /// The index of `p`, adding it if new.
    pub fn index(&mut self, p: DVec3) -> usize {
        let p = p + DVec3::ZERO; // -0.0 + 0.0 = +0.0: identify signed zeros
        let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
        let next = self.points.len();
        let i = *self.map.entry(key).or_insert(next);
        if i == next {
            self.points.push(p);
        }
        i
    }
}

/// A mesh file's welded polygons, in millimetres, with the part name and the length tolerance ([`mesh_tolerance`]).
#[derive(Debug, Clone)]
pub(crate) struct Mesh {
    pub name: String,
    pub points: Vec<DVec3>,
    pub polygons: Vec<MeshPolygon>,
    pub tolerance: f64,
}

/// Welded points in `units`, converted to millimetres (unchanged for millimetres).
pub(crate) fn scale_points(points: Vec<DVec3>, units: super::Units) -> Vec<DVec3> {
    let factor = units.millimetres();
    if factor == 1.0 { points } else { points.into_iter().map(|p| p * factor).collect() }
}

/// One polygon of a mesh: welded vertex indices and where it came from in the file.
#[derive(Debug, Clone)]
pub(crate) struct MeshPolygon {
    pub vertices: Vec<usize>,
    pub place: Place,
}

/// A group of polygons that must bound one convex solid.
#[derive(Debug, Clone)]
pub(crate) struct Shell {
    pub name: Option<String>,
    pub polygons: Vec<MeshPolygon>,
}

/// Why a shell is not convex.
#[derive(Debug)]
enum Defect {
    Hull(HullError),
    OffHull { polygon: usize },
    Volume { shell: f64, hull: f64 },
}

/// The faces a writer emits for a convex component with vertices `points`: those of the exact convex hull of the
/// points (each face's vertex indices into `points`, counter-clockwise seen from outside, and its outward unit
/// normal), which is what the readers rebuild, so that every written polygon lies exactly in a face plane of the
/// hull the reader computes ([`convex_shell`]). A component's own faces can be coplanar only to rounding (a
/// sheet-metal face after rotation: the Triangle example's quadrilaterals are 5e-11 out of plane); the hull splits
/// such a face into its exact facets. `None` when the points have no 3-D hull (the caller then writes the
/// component's own faces). O(n log n) expected.
pub(crate) fn exact_hull_faces(points: &[DVec3]) -> Option<Vec<(Vec<usize>, DVec3)>> {
    let hull = convex_hull(points).ok()?;
    Some(
        hull.polytope
            .faces()
            .iter()
            .map(|f| (f.vertices.iter().map(|&v| hull.source[v]).collect(), f.plane.normal))
            .collect(),
    )
}

/// [`exact_hull_faces`] of a component, else its own faces.
pub(crate) fn written_faces(component: &ConvexPolytope, points: &[DVec3]) -> Vec<(Vec<usize>, DVec3)> {
    exact_hull_faces(points).unwrap_or_else(|| {
        component.faces().iter().map(|f| (f.vertices.iter().copied().collect(), f.plane.normal)).collect()
    })
}

/// Splits triangles into closed shells. See the module documentation. Triangles with a repeated vertex are dropped.
/// Returns the shells and, per shell, the first open edge found (a polygon index within the shell), if any.
pub(crate) fn split_shells(
    points: &[DVec3],
    triangles: Vec<MeshPolygon>,
    tolerance: f64,
) -> Vec<(Shell, Option<usize>)> {
    let triangles: Vec<MeshPolygon> = triangles
        .into_iter()
        .filter(|t| {
            let v = &t.vertices;
            let ok = v.len() == 3 && v[0] != v[1] && v[1] != v[2] && v[0] != v[2];
            if !ok {
                tracing::debug!(place = %t.place, "dropping a triangle with a repeated vertex");
            }
            ok
        })
        .collect();
    let mut directed: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            directed.entry((tri.vertices[k], tri.vertices[(k + 1) % 3])).or_default().push(t);
        }
    }
    let mut parent: Vec<usize> = (0..triangles.len()).collect();
    let mut open: Vec<bool> = vec![false; triangles.len()];
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b, c) = (tri.vertices[k], tri.vertices[(k + 1) % 3], tri.vertices[(k + 2) % 3]);
            let candidates = directed.get(&(b, a)).map(Vec::as_slice).unwrap_or(&[]);
            let partner = match candidates {
                [] => None,
                [only] => Some(*only),
                many => Some(first_met(points, (a, b, c), many, &triangles, tolerance)),
            };
            match partner {
                Some(s) => union(&mut parent, t, s),
                None => open[t] = true,
            }
        }
    }
    let mut shell_of_root: HashMap<usize, usize> = HashMap::new();
    let mut shells: Vec<(Shell, Option<usize>)> = Vec::new();
    for (t, tri) in triangles.into_iter().enumerate() {
        let root = find(&mut parent, t);
        let next = shells.len();
        let s = *shell_of_root.entry(root).or_insert(next);
        if s == next {
            shells.push((Shell { name: None, polygons: Vec::new() }, None));
        }
        let (shell, first_open) = &mut shells[s];
        if open[t] && first_open.is_none() {
            *first_open = Some(shell.polygons.len());
        }
        shell.polygons.push(tri);
    }
    shells
}

/// Among triangles `candidates` (each traversing `b -> a`), the one first met when rotating the half-plane of
/// triangle `(a, b, c)` about the edge into its solid; one on that half-plane (within `tolerance`) is met last.
fn first_met(
    points: &[DVec3],
    (a, b, c): (usize, usize, usize),
    candidates: &[usize],
    tris: &[MeshPolygon],
    tolerance: f64,
) -> usize {
    let (pa, pb, pc) = (points[a], points[b], points[c]);
    let unit_normal = accurate_cross(pa, pb, pc).normalize_or_zero();
    let u = (pb - pa).normalize_or_zero();
    let reject = |p: DVec3| {
        let w = p - pa;
        w - u * u.dot(w)
    };
    let x = reject(pc).normalize_or_zero();
    let y = -(pb - pa).cross(pc - pa).normalize_or_zero();
    let angle = |s: usize| -> f64 {
        let Some(&d) = tris[s].vertices.iter().find(|&&v| v != a && v != b) else {
            return f64::INFINITY;
        };
        let pd = points[d];
        let w = reject(pd);
        let in_plane = side(pa, pb, pc, pd) == Ordering::Equal || (pd - pa).dot(unit_normal).abs() <= tolerance;
        if in_plane && w.dot(x) > 0.0 {
            return std::f64::consts::TAU; // on our own half-plane: the touching neighbour's face, met last
        }
        let theta = w.dot(y).atan2(w.dot(x));
        if theta <= 0.0 { theta + std::f64::consts::TAU } else { theta }
    };
    let mut best = candidates[0];
    let mut best_angle = angle(best);
    for &s in &candidates[1..] {
        let th = angle(s);
        if th < best_angle {
            best = s;
            best_angle = th;
        }
    }
    best
}

/// The exact convexity check of the module documentation; returns the shell's convex polytope.
fn convex_shell(points: &[DVec3], shell: &Shell, tolerance: f64) -> Result<ConvexPolytope, Defect> {
    let mut local: Vec<DVec3> = Vec::new();
    let mut local_of: HashMap<usize, usize> = HashMap::new(); // welded index -> index into `local`
    for p in &shell.polygons {
        for &v in &p.vertices {
            local_of.entry(v).or_insert_with(|| {
                local.push(points[v]);
                local.len() - 1
            });
        }
    }
    let hull = convex_hull(&local).map_err(Defect::Hull)?;
    let (hull, source) = (hull.polytope, hull.source);
    // input point -> hull vertex, and hull vertex -> incident faces
    let mut hull_vertex_of: HashMap<usize, usize> = HashMap::with_capacity(source.len());
    for (hv, &input) in source.iter().enumerate() {
        hull_vertex_of.insert(input, hv);
    }
    let mut faces_at: Vec<Vec<usize>> = vec![Vec::new(); hull.vertices().len()];
    for (f, face) in hull.faces().iter().enumerate() {
        for &v in &face.vertices {
            faces_at[v].push(f);
        }
    }
    let frames: Vec<Option<(DVec3, DVec3, DVec3)>> = (0..hull.faces().len()).map(|f| hull.face_frame(f)).collect();
    // the piece: the hull with its rounding creases merged; built lazily for the tolerant test, else at the end
    let mut merged: Option<ConvexPolytope> = None;
    let on_face = |f: usize, pts: &[DVec3]| {
        frames[f].is_some_and(|(a, b, c)| pts.iter().all(|&p| side(a, b, c, p) == Ordering::Equal))
    };
    for (i, polygon) in shell.polygons.iter().enumerate() {
        let pts: Vec<DVec3> = polygon.vertices.iter().map(|&v| points[v]).collect();
        // Candidates, cheapest first (the test itself is always exact): the faces around a polygon vertex that is a
        // hull vertex (a polygon on the hull boundary lies in one of them); then the face best aligned with the
        // polygon's float normal; then every face. A convex mesh almost always succeeds at the first step, so the
        // whole check is O(polygons x face degree) instead of O(polygons x faces).
        let around = polygon
            .vertices
            .iter()
            .find_map(|v| local_of.get(v).and_then(|l| hull_vertex_of.get(l)))
            .map(|&hv| faces_at[hv].as_slice())
            .unwrap_or(&[]);
        let mut found = around.iter().any(|&f| on_face(f, &pts));
        if !found {
            let normal = newell_normal(pts.iter().copied());
            let best = (0..hull.faces().len()).max_by(|&x, &y| {
                let (dx, dy) = (hull.faces()[x].plane.normal.dot(normal), hull.faces()[y].plane.normal.dot(normal));
                dx.partial_cmp(&dy).unwrap_or(Ordering::Equal)
            });
            found = best.is_some_and(|f| on_face(f, &pts)) || (0..hull.faces().len()).any(|f| on_face(f, &pts));
        }
        if !found {
            // a face planar only to rounding, triangulated across an exact crease: within the length tolerance of a
            // merged face's plane
            if merged.is_none() {
                merged = Some(convex_hull_merged_within(&local, tolerance).map_err(Defect::Hull)?.polytope);
            }
            found = merged.as_ref().is_some_and(|m| {
                m.faces().iter().any(|f| pts.iter().all(|&p| f.plane.signed_distance(p).abs() <= tolerance))
            });
        }
        if !found {
            return Err(Defect::OffHull { polygon: i });
        }
    }
    let o = hull.vertex_centroid();
    let mut shell_volume = 0.0;
    let mut fans = 0usize;
    for polygon in &shell.polygons {
        let p0 = points[polygon.vertices[0]] - o;
        for w in polygon.vertices[1..].windows(2) {
            shell_volume += p0.dot((points[w[0]] - o).cross(points[w[1]] - o)) / 6.0;
            fans += 1;
        }
    }
    let hull_volume = hull.volume();
    let d = bounding_diagonal(&local);
    // a shell within the length tolerance of the hull's boundary (test (2)) encloses a volume within the tolerance
    // times the hull's area of the hull's, and that area is at most the bounding box's, 2 d^2
    let tol = 1e-13 * fans as f64 * d * d * d + 1e-12 * hull_volume + 2.0 * tolerance * d * d;
    let within = (shell_volume - hull_volume).abs() <= tol; // false for NaN as well
    if !within {
        return Err(Defect::Volume { shell: shell_volume, hull: hull_volume });
    }
    // the shell bounds the exact hull; the piece is that hull with its rounding creases merged (as the JSON reader's
    // pieces): a face planar only to rounding is one face, not its exact facets
    match merged {
        Some(m) => Ok(m),
        None => convex_hull_merged_within(&local, tolerance).map(|h| h.polytope).map_err(Defect::Hull),
    }
}

/// The coordinate precision of a mesh file, for [`mesh_tolerance`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Precision {
    /// Coordinates as written: the kernel's tolerance.
    AsWritten,
    /// Single-precision coordinates (binary STL; text with at most 9 significant digits per coordinate).
    Single,
}

impl Precision {
    /// The precision of a text file whose coordinates have at most `digits` significant digits.
    pub(crate) fn of_text(digits: usize) -> Self {
        if digits <= 9 { Precision::Single } else { Precision::AsWritten }
    }
}

/// The number of significant digits of a decimal number as written (`-0.012500e3`: 5; leading zeros do not count,
/// trailing ones do). Text that is not a decimal number (`inf`, `NaN`) has none.
pub(crate) fn significant_digits(token: &str) -> usize {
    let mantissa = token.split(['e', 'E']).next().unwrap_or("");
    mantissa.bytes().filter(u8::is_ascii_digit).skip_while(|&b| b == b'0').count()
}

/// The length tolerance of the module documentation for a mesh with welded vertices `points`.
pub(crate) fn mesh_tolerance(
    file: &Path,
    points: &[DVec3],
    precision: Precision,
    options: &ReadOptions,
) -> Result<f64, IoError> {
    let kernel = Tolerance::for_points(points).linear;
    let format = match precision {
        Precision::AsWritten => 0.0,
        Precision::Single => {
            let largest = points.iter().map(|p| p.abs().max_element()).fold(0.0, f64::max);
            16.0 * f64::from(f32::EPSILON) / 2.0 * largest
        }
    };
    let given = match options.mesh_tolerance {
        None => 0.0,
        Some(t) if t > 0.0 && t.is_finite() => t,
        Some(value) => {
            return Err(IoError::NotPositive {
                file: file.to_path_buf(),
                at: super::Place::Key("mesh_tolerance".into()),
                what: "the mesh tolerance",
                value,
            });
        }
    };
    Ok(kernel.max(format).max(given))
}

/// Checks every shell (or decomposes it) and builds the part.
/// With `recognise`, a closed mesh that is not convex is recognised as sheet metal ([`super::sheet`]): an STL's
/// shells, or an OBJ of one group (the groups of an OBJ are meant as convex pieces).
pub(crate) fn part_from_shells(
    file: &Path,
    name: String,
    points: &[DVec3],
    shells: Vec<(Shell, Option<usize>)>,
    options: &ReadOptions,
    tolerance: f64,
    recognise: bool,
) -> Result<Part, IoError> {
    if shells.is_empty() {
        return Err(IoError::Empty { file: file.to_path_buf(), at: Place::WholeFile, what: "the mesh has no faces" });
    }
    let density = resolve_density(file, None, options)?;
    let mut components = Vec::new();
    let mut approximate = false;
    let mut mesh_volume = 0.0;
    for (index, (shell, open)) in shells.iter().enumerate() {
        let not_convex = |detail: String| IoError::NotConvex {
            file: file.to_path_buf(),
            shell: index,
            name: shell.name.clone(),
            detail,
        };
        let checked = match open {
            Some(p) => Err(not_convex(format!(
                "the shell is open: the polygon at {} has an edge that no other polygon traverses backwards",
                shell.polygons[*p].place
            ))),
            None => convex_shell(points, shell, tolerance).map_err(|defect| match defect {
                Defect::Hull(source) => IoError::DegeneratePiece {
                    file: file.to_path_buf(),
                    at: shell.polygons.first().map(|p| p.place.clone()).unwrap_or(Place::Piece(index)),
                    source,
                },
                Defect::OffHull { polygon } => not_convex(format!(
                    "the polygon at {} does not lie in a face plane of the shell's convex hull (nor within {} mm \
                     of one; a mesh written with few digits may need a larger mesh tolerance)",
                    shell.polygons[polygon].place,
                    super::short_number(tolerance)
                )),
                Defect::Volume { shell: s, hull } => not_convex(format!(
                    "the shell encloses volume {s} but its convex hull has volume {hull} \
                     (a missing, doubled or inward-facing polygon, or a non-convex shape)"
                )),
            }),
        };
        match checked {
            Ok(polytope) => {
                mesh_volume += polytope.volume();
                components.push(polytope);
            }
            Err(IoError::NotConvex { file, shell, name: shell_name, detail })
                if !options.decompose_mesh && open.is_none() && recognise =>
            {
                // a closed shell that is not convex: a sheet-metal part from CAD, recognised from all the shells
                let polygons: Vec<MeshPolygon> = shells.iter().flat_map(|(s, _)| s.polygons.iter().cloned()).collect();
                return match super::sheet::recognise_mesh(&file, name.clone(), points, &polygons, options, tolerance) {
                    Ok((part, recognition)) => {
                        tracing::info!(
                            file = %file.display(),
                            thickness = recognition.thickness,
                            plates = recognition.plates.len(),
                            bends = recognition.bends.len(),
                            "mesh recognised as sheet metal"
                        );
                        Ok(part)
                    }
                    // both reasons: why it is no convex piece, and why it is no sheet
                    Err(e) => {
                        let sheet = match &e {
                            IoError::NotSheetMetal { source, .. } => source.to_string(),
                            IoError::MeshFaces { source, .. } => source.to_string(),
                            other => other.to_string(),
                        };
                        Err(IoError::NotConvex {
                            file,
                            shell,
                            name: shell_name,
                            detail: format!("{detail}; nor is it sheet metal: {sheet}"),
                        })
                    }
                };
            }
            Err(IoError::NotConvex { .. }) if options.decompose_mesh => {
                let pieces = decompose(points, shell, tolerance).map_err(|detail| IoError::Decomposition {
                    file: file.to_path_buf(),
                    shell: index,
                    detail,
                })?;
                tracing::info!(file = %file.display(), shell = index, pieces = pieces.len(), "VHACD decomposition");
                components.extend(pieces);
                approximate = true;
                mesh_volume += enclosed_volume(points, shell);
            }
            Err(e) => return Err(e),
        }
    }
    // faces planar only to a tolerance coarser than the kernel's (single precision): their corners moved onto their
    // planes (`snap`), so that every later test, at the kernel's tolerance, sees them planar
    if tolerance > Tolerance::for_points(points).linear {
        let (flat, moved) = super::snap::flatten_faces(components, tolerance);
        if moved > 0 {
            tracing::debug!(file = %file.display(), corners = moved, "corners moved onto their faces' planes");
        }
        components = flat;
    }
    let origin = if approximate {
        PartOrigin::ApproximateDecomposition { mesh_volume: Some(mesh_volume) }
    } else {
        PartOrigin::Mesh
    };
    Part::from_components(name, components, density, origin)
        .map_err(|source| IoError::Part { file: file.to_path_buf(), source })
}

/// The volume a closed shell encloses (divergence theorem over its polygons' fans, about its first vertex).
fn enclosed_volume(points: &[DVec3], shell: &Shell) -> f64 {
    let Some(o) = shell.polygons.first().and_then(|p| p.vertices.first()).map(|&v| points[v]) else { return 0.0 };
    let mut volume = 0.0;
    for polygon in &shell.polygons {
        let v = &polygon.vertices;
        for k in 1..v.len().saturating_sub(1) {
            let (a, b, c) = (points[v[0]] - o, points[v[k]] - o, points[v[k + 1]] - o);
            volume += a.dot(b.cross(c)) / 6.0;
        }
    }
    volume
}

/// VHACD on one shell; every output hull rebuilt with the exact hull.
fn decompose(points: &[DVec3], shell: &Shell, tolerance: f64) -> Result<Vec<ConvexPolytope>, String> {
    use parry3d_f64::transformation::vhacd::{VHACD, VHACDParameters};
    let mut local_index: HashMap<usize, u32> = HashMap::new();
    let mut local: Vec<DVec3> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    for polygon in &shell.polygons {
        let mut ids = Vec::with_capacity(polygon.vertices.len());
        for &v in &polygon.vertices {
            let next = local.len() as u32;
            let id = *local_index.entry(v).or_insert(next);
            if id == next {
                local.push(points[v]);
            }
            ids.push(id);
        }
        for w in ids[1..].windows(2) {
            triangles.push([ids[0], w[0], w[1]]);
        }
    }
    if local.len() < 4 || triangles.is_empty() {
        return Err("too few vertices".into());
    }
    let params = VHACDParameters::default();
    // VHACD is third-party code on arbitrary input: contain any panic and report it as a decomposition failure.
    let hulls = std::panic::catch_unwind(|| {
        let decomposition = VHACD::decompose(&params, &local, &triangles, true);
        decomposition.compute_exact_convex_hulls(&local, &triangles)
    })
    .map_err(|_| "VHACD panicked on this mesh".to_string())?;
    let pieces: Vec<ConvexPolytope> = hulls
        .iter()
        .filter_map(|(pts, _)| convex_hull_merged_within(pts, tolerance).ok().map(|h| h.polytope))
        .collect();
    if pieces.is_empty() {
        return Err(format!("VHACD returned {} hulls, none of them solid", hulls.len()));
    }
    Ok(pieces)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_digits_count_as_written() {
        for (token, digits) in [
            ("0", 0),
            ("12.5", 3),
            ("-0.012500e3", 5),
            ("1.234567e+01", 7),
            ("123.456789", 9),
            ("12.345678329467773", 17),
            ("+1E-7", 1),
            ("0.000001", 1),
            ("inf", 0),
            ("NaN", 0),
        ] {
            assert_eq!(significant_digits(token), digits, "{token}");
        }
        assert_eq!(Precision::of_text(9), Precision::Single);
        assert_eq!(Precision::of_text(10), Precision::AsWritten);
    }

    #[test]
    fn the_tolerance_is_the_largest_of_the_kernel_the_format_and_the_option() {
        let file = Path::new("t.stl");
        let points = [DVec3::new(1000.0, 0.0, 0.0), DVec3::new(1010.0, 10.0, 0.0)];
        let kernel = Tolerance::for_points(&points).linear;
        let as_written = mesh_tolerance(file, &points, Precision::AsWritten, &ReadOptions::default()).expect("ok");
        assert_eq!(as_written, kernel);
        let single = mesh_tolerance(file, &points, Precision::Single, &ReadOptions::default()).expect("ok");
        assert_eq!(single, 16.0 * 2f64.powi(-24) * 1010.0);
        let given = ReadOptions { mesh_tolerance: Some(0.5), ..Default::default() };
        assert_eq!(mesh_tolerance(file, &points, Precision::Single, &given).expect("ok"), 0.5);
        let small = ReadOptions { mesh_tolerance: Some(1e-12), ..Default::default() };
        assert_eq!(mesh_tolerance(file, &points, Precision::AsWritten, &small).expect("ok"), kernel);
    }
}
