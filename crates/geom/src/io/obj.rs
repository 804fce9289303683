//! Wavefront OBJ (the geometric subset; see `docs/formats.md`), hand-written so every error carries its line number.
//!
//! **Reading.** `v x y z [w]` defines a vertex (extra numbers such as vertex colours are allowed and ignored),
//! `f i j k ...` a polygon with vertex references `i`, `i/t`, `i//n` or `i/t/n`; indices are 1-based, negative
//! indices count back from the last vertex defined so far (`-1` is the latest). `o` and `g` start a new object/group;
//! each non-empty object/group (faces before the first `o`/`g` form an unnamed one) is one convex piece and must bound
//! a convex solid, checked as for STL shells ([`super::mesh`]: exactly, or within the length tolerance, which is that
//! of single precision when no coordinate has more than 9 significant digits) unless decomposition is requested. `vt`,
//! `vn`, `vp`, `s`, `usemtl`, `mtllib`, `l`, `p` and other statements are ignored; `#` starts a comment. Vertices are
//! welded by exact coordinates. O(file size) parsing.
//!
//! **Writing.** One `o piece_<i>` per component with its vertices and the faces of their exact convex hull
//! (counter-clockwise seen from outside, 1-based absolute indices; `mesh::exact_hull_faces`), the faces the
//! reader rebuilds. Coordinates use Rust's shortest round-trip `f64` formatting, so a part reads back as its exact
//! form, component by component (the part's vertices and faces, as sets, when its faces are exactly planar; see the
//! JSON writer).

use super::mesh::{
    Mesh, MeshPolygon, Precision, Shell, Welder, mesh_tolerance, part_from_shells, scale_points, significant_digits,
    written_faces,
};
use super::{IoError, Place, ReadOptions, check_coordinate, stem_name};
use crate::part::{Part, PartOrigin};
use crate::pose::Pose;
use glam::DVec3;
use std::fmt::Write as _;
use std::path::Path;

/// Reads an OBJ file.
pub fn read_obj(path: impl AsRef<Path>, options: &ReadOptions) -> Result<Part, IoError> {
    let path = path.as_ref();
    let bytes = super::read_bytes(path)?;
    parse_obj(&bytes, path, options)
}

/// Parses OBJ from memory; `file` is only used in error messages and as the part name.
pub fn parse_obj(bytes: &[u8], file: &Path, options: &ReadOptions) -> Result<Part, IoError> {
    let (shells, points, tolerance) = parse_obj_groups(bytes, file, options)?;
    let recognise = shells.len() == 1;
    let mut part = part_from_shells(file, stem_name(file), &points, shells, options, tolerance, recognise)?;
    // a file written from an approximate or recognised part keeps its mark
    if part.origin == PartOrigin::Mesh
        && let Some(origin) = String::from_utf8_lossy(bytes)
            .lines()
            .find_map(|l| l.strip_prefix(ORIGIN_COMMENT))
            .and_then(|json| serde_json::from_str::<PartOrigin>(json.trim()).ok())
    {
        part.origin = origin;
    }
    Ok(part)
}

/// The comment line that carries a part's origin through an OBJ file (`# stackplan origin: {json}`).
const ORIGIN_COMMENT: &str = "# stackplan origin: ";

/// An OBJ file's polygons (all groups), in millimetres, for sheet-metal recognition.
pub(crate) fn parse_obj_mesh(bytes: &[u8], file: &Path, options: &ReadOptions) -> Result<Mesh, IoError> {
    let (shells, points, tolerance) = parse_obj_groups(bytes, file, options)?;
    let polygons = shells.into_iter().flat_map(|(s, _)| s.polygons).collect();
    Ok(Mesh { name: stem_name(file), points, polygons, tolerance })
}

/// The groups of an OBJ file as shells, the welded points in millimetres, and the length tolerance.
#[allow(clippy::type_complexity)]
fn parse_obj_groups(
    bytes: &[u8],
    file: &Path,
    options: &ReadOptions,
) -> Result<(Vec<(Shell, Option<usize>)>, Vec<DVec3>, f64), IoError> {
    let text = String::from_utf8_lossy(bytes);
    let syntax =
        |line: usize, message: String| IoError::Syntax { file: file.to_path_buf(), at: Place::Line(line), message };
    let mut welder = Welder::default();
    let mut vertex_ids: Vec<usize> = Vec::new(); // OBJ vertex k (0-based) -> welded index
    let mut digits = 0; // the most significant digits of any vertex coordinate
    let mut groups: Vec<Shell> = vec![Shell { name: None, polygons: Vec::new() }];
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let content = raw.split('#').next().unwrap_or("");
        let mut words = content.split_whitespace();
        let Some(keyword) = words.next() else { continue };
        match keyword {
            "v" => {
                let numbers: Vec<&str> = words.collect();
                if numbers.len() < 3 {
                    return Err(syntax(line, format!("a vertex needs 3 coordinates, got {}", numbers.len())));
                }
                let mut p = [0.0; 3];
                for (k, w) in numbers.iter().enumerate() {
                    let value: f64 = w.parse().map_err(|_| syntax(line, format!("`{w}` is not a number")))?;
                    if k < 3 {
                        p[k] = check_coordinate(value, file, || Place::Line(line))?;
                        digits = digits.max(significant_digits(w));
                    }
                }
                vertex_ids.push(welder.index(DVec3::from_array(p)));
            }
            "f" => {
                let mut vertices = Vec::new();
                for w in words {
                    let bad = || syntax(line, format!("`{w}` is not a vertex reference (i, i/t, i//n or i/t/n)"));
                    let mut parts = w.split('/');
                    let index: i64 = parts.next().unwrap_or("").parse().map_err(|_| bad())?;
                    // texture and normal indices are ignored, but must be integers (or empty) when present
                    let rest: Vec<&str> = parts.collect();
                    if rest.len() > 2 || rest.iter().any(|r| !r.is_empty() && r.parse::<i64>().is_err()) {
                        return Err(bad());
                    }
                    let count = vertex_ids.len();
                    let resolved = match index {
                        i if i > 0 && (i as u64) <= count as u64 => Some(i as usize - 1),
                        i if i < 0 && i.unsigned_abs() <= count as u64 => Some(count - i.unsigned_abs() as usize),
                        _ => None,
                    };
                    let Some(k) = resolved else {
                        return Err(IoError::BadIndex { file: file.to_path_buf(), line, index, count });
                    };
                    vertices.push(vertex_ids[k]);
                }
                if vertices.len() < 3 {
                    return Err(IoError::FaceTooSmall { file: file.to_path_buf(), line, count: vertices.len() });
                }
                let group = groups.last_mut().expect("groups starts non-empty and only grows");
                group.polygons.push(MeshPolygon { vertices, place: Place::Line(line) });
            }
            "o" | "g" => {
                let name: Vec<&str> = words.collect();
                let name = if name.is_empty() { None } else { Some(name.join(" ")) };
                groups.push(Shell { name, polygons: Vec::new() });
            }
            other => tracing::trace!(line, statement = other, "ignoring OBJ statement"),
        }
    }
    let shells: Vec<(Shell, Option<usize>)> =
        groups.into_iter().filter(|g| !g.polygons.is_empty()).map(|g| (g, None)).collect();
    if shells.is_empty() {
        return Err(IoError::Empty { file: file.to_path_buf(), at: Place::WholeFile, what: "the OBJ has no faces" });
    }
    let points = scale_points(welder.points, options.units);
    let tolerance = mesh_tolerance(file, &points, Precision::of_text(digits), options)?;
    Ok((shells, points, tolerance))
}

/// The part as OBJ text.
pub fn obj_string(part: &Part) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# stackplan part {:?}: {} convex components", part.name, part.components.len());
    // pieces that are not the solid exactly keep saying so (read back by `parse_obj`)
    if matches!(part.origin, PartOrigin::ApproximateDecomposition { .. } | PartOrigin::RecognisedSheet { .. })
        && let Ok(origin) = serde_json::to_string(&part.origin)
    {
        let _ = writeln!(s, "{ORIGIN_COMMENT}{origin}");
    }
    let mut base = 1usize;
    for (i, c) in part.components.iter().enumerate() {
        let _ = writeln!(s, "o piece_{i}");
        for v in c.vertices() {
            let _ = writeln!(s, "v {:?} {:?} {:?}", v.x, v.y, v.z);
        }
        for (face, _) in written_faces(c, c.vertices()) {
            let idx: Vec<String> = face.iter().map(|&v| (v + base).to_string()).collect();
            let _ = writeln!(s, "f {}", idx.join(" "));
        }
        base += c.vertices().len();
    }
    s
}

/// Several placed parts as one OBJ (a stack export for viewers): one `o <part>_<i>_piece_<j>` per component, with
/// world coordinates `pose.apply(v)`. Reading it back gives one convex piece per component (up to rounding of the
/// rotation).
pub fn obj_scene_string(items: &[(&Part, Pose)]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# stackplan scene: {} placed parts", items.len());
    let mut base = 1usize;
    for (i, (part, pose)) in items.iter().enumerate() {
        let name: String = part.name.chars().map(|c| if c.is_whitespace() { '_' } else { c }).collect();
        for (j, c) in part.components.iter().enumerate() {
            let _ = writeln!(s, "o {name}_{i}_piece_{j}");
            let world: Vec<DVec3> = c.vertices().iter().map(|v| pose.apply(*v)).collect();
            for w in &world {
                let _ = writeln!(s, "v {:?} {:?} {:?}", w.x, w.y, w.z);
            }
            for (face, _) in written_faces(c, &world) {
                let idx: Vec<String> = face.iter().map(|&v| (v + base).to_string()).collect();
                let _ = writeln!(s, "f {}", idx.join(" "));
            }
            base += c.vertices().len();
        }
    }
    s
}

/// Writes several placed parts as one OBJ atomically (see [`obj_scene_string`]).
pub fn write_obj_scene(path: impl AsRef<Path>, items: &[(&Part, Pose)]) -> Result<(), IoError> {
    super::atomic::write_atomic(path, obj_scene_string(items).as_bytes())
}

/// Writes the part as OBJ atomically.
pub fn write_obj(path: impl AsRef<Path>, part: &Part) -> Result<(), IoError> {
    super::atomic::write_atomic(path, obj_string(part).as_bytes())
}
