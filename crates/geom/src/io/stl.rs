//! STL, ASCII and binary (see `docs/formats.md`).
//!
//! **Detection.** A file whose size is exactly `84 + 50 n`, `n` being the little-endian `u32` at byte 80, is binary
//! even if it starts with `solid` (many exporters write `solid` into the binary header). Otherwise a file that starts
//! with `solid` (after optional whitespace) and contains no NUL byte is ASCII; anything else is treated as binary, and
//! a size mismatch is reported as [`IoError::Truncated`] with the byte offset where the records stop matching.
//!
//! **Reading.** Triangles are welded exactly and split into closed shells; each shell must bound a convex solid (or
//! is decomposed on request): see [`super::mesh`], whose length tolerance is that of single precision for binary
//! files and for ASCII files with no coordinate of more than 9 significant digits. Binary coordinates are `f32`,
//! widened exactly to `f64`. Normals in
//! the file are ignored (the winding order defines the outside). O(file size) parsing.
//!
//! **Writing.** Every face of the exact convex hull of each component's vertices (the faces the reader rebuilds;
//! `mesh::exact_hull_faces`) is fanned from its first vertex into triangles (hull faces are strictly convex,
//! so no fan triangle is degenerate), with the face's outward normal. ASCII STL is written with the shortest text
//! that parses back to the same `f64`, so a part reads back as its exact form (see the JSON writer). Binary STL
//! stores `f32`: the vertices are rounded first and the hull taken of the rounded points, so the file reads back as
//! the read form of the rounded part (the same as ASCII's for coordinates representable in `f32`): bit for bit where
//! its faces are exactly planar in `f32`, else with those faces flattened (`super::snap`).

use super::mesh::{
    Mesh, MeshPolygon, Precision, Welder, mesh_tolerance, part_from_shells, scale_points, significant_digits,
    split_shells, written_faces,
};
use super::{IoError, Place, ReadOptions, check_coordinate, stem_name};
use crate::part::Part;
use glam::DVec3;
use std::fmt::Write as _;
use std::path::Path;

/// Reads an STL file (ASCII or binary).
pub fn read_stl(path: impl AsRef<Path>, options: &ReadOptions) -> Result<Part, IoError> {
    let path = path.as_ref();
    let bytes = super::read_bytes(path)?;
    parse_stl(&bytes, path, options)
}

/// Parses STL from memory; `file` is only used in error messages and as the default name.
pub fn parse_stl(bytes: &[u8], file: &Path, options: &ReadOptions) -> Result<Part, IoError> {
    let mesh = parse_stl_mesh(bytes, file, options)?;
    let shells = split_shells(&mesh.points, mesh.polygons, mesh.tolerance);
    part_from_shells(file, mesh.name, &mesh.points, shells, options, mesh.tolerance, true)
}

/// An STL file's welded triangles, in millimetres ([`ReadOptions::units`]), with its name and length tolerance.
pub(crate) fn parse_stl_mesh(bytes: &[u8], file: &Path, options: &ReadOptions) -> Result<Mesh, IoError> {
    let mut welder = Welder::default();
    let (name, triangles, precision) = if is_ascii(bytes) {
        let (name, triangles, digits) = parse_ascii(bytes, file, &mut welder)?;
        (name, triangles, Precision::of_text(digits))
    } else {
        (None, parse_binary(bytes, file, &mut welder)?, Precision::Single)
    };
    if triangles.is_empty() {
        return Err(IoError::Empty {
            file: file.to_path_buf(),
            at: Place::WholeFile,
            what: "the STL has no triangles",
        });
    }
    let points = scale_points(welder.points, options.units);
    let tolerance = mesh_tolerance(file, &points, precision, options)?;
    let name = name.filter(|n| !n.is_empty()).unwrap_or_else(|| stem_name(file));
    Ok(Mesh { name, points, polygons: triangles, tolerance })
}

fn binary_size(bytes: &[u8]) -> Option<(u64, u64)> {
    let count = u32::from_le_bytes(bytes.get(80..84)?.try_into().ok()?) as u64;
    Some((count, 84 + 50 * count))
}

fn is_ascii(bytes: &[u8]) -> bool {
    if let Some((_, expected)) = binary_size(bytes)
        && expected == bytes.len() as u64
    {
        return false;
    }
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(bytes.len());
    let head = &bytes[start..];
    head.len() >= 5 && head[..5].eq_ignore_ascii_case(b"solid") && !bytes.contains(&0)
}

pub(crate) fn parse_binary(bytes: &[u8], file: &Path, welder: &mut Welder) -> Result<Vec<MeshPolygon>, IoError> {
    let actual = bytes.len() as u64;
    let Some((triangles, expected)) = binary_size(bytes) else {
        return Err(IoError::Truncated {
            file: file.to_path_buf(),
            offset: actual,
            triangles: 0,
            expected: 84,
            actual,
        });
    };
    if expected != actual {
        // the first byte that does not fit: the start of the first incomplete record, or the first extra byte
        let offset = if actual < expected { 84 + (actual - 84) / 50 * 50 } else { expected };
        return Err(IoError::Truncated { file: file.to_path_buf(), offset, triangles, expected, actual });
    }
    let mut out = Vec::with_capacity(triangles as usize);
    for t in 0..triangles as usize {
        let record = 84 + 50 * t;
        let mut vertices = Vec::with_capacity(3);
        for k in 0..3 {
            let mut p = [0.0f64; 3];
            for (c, value) in p.iter_mut().enumerate() {
                let at = record + 12 + 12 * k + 4 * c;
                let raw: [u8; 4] = bytes[at..at + 4].try_into().expect("4-byte slice of a size-checked file");
                *value = check_coordinate(f32::from_le_bytes(raw) as f64, file, || Place::Byte(at as u64))?;
            }
            vertices.push(welder.index(DVec3::from_array(p)));
        }
        out.push(MeshPolygon { vertices, place: Place::Byte(record as u64) });
    }
    Ok(out)
}

/// Whitespace tokens with their 1-based line numbers.
struct Tokens<'a> {
    lines: std::iter::Enumerate<std::str::Lines<'a>>,
    current: Vec<&'a str>,
    position: usize,
    line: usize,
}

impl<'a> Tokens<'a> {
    fn new(text: &'a str) -> Self {
        Tokens { lines: text.lines().enumerate(), current: Vec::new(), position: 0, line: 0 }
    }

    fn next(&mut self) -> Option<(&'a str, usize)> {
        while self.position >= self.current.len() {
            let (i, l) = self.lines.next()?;
            self.line = i + 1;
            self.current = l.split_whitespace().collect();
            self.position = 0;
        }
        self.position += 1;
        Some((self.current[self.position - 1], self.line))
    }

    /// The rest of the current line (after the last token returned), joined by spaces.
    fn rest_of_line(&mut self) -> String {
        let rest = self.current[self.position.min(self.current.len())..].join(" ");
        self.position = self.current.len();
        rest
    }
}

/// The name, the triangles and the most significant digits of any vertex coordinate.
type AsciiStl = (Option<String>, Vec<MeshPolygon>, usize);

fn parse_ascii(bytes: &[u8], file: &Path, welder: &mut Welder) -> Result<AsciiStl, IoError> {
    let text = String::from_utf8_lossy(bytes);
    let mut tokens = Tokens::new(&text);
    let syntax =
        |line: usize, message: String| IoError::Syntax { file: file.to_path_buf(), at: Place::Line(line), message };
    let expect = |tokens: &mut Tokens<'_>, word: &str| -> Result<usize, IoError> {
        match tokens.next() {
            Some((t, line)) if t.eq_ignore_ascii_case(word) => Ok(line),
            Some((t, line)) => Err(syntax(line, format!("expected `{word}`, found `{t}`"))),
            None => Err(syntax(tokens.line.max(1), format!("expected `{word}`, found the end of the file"))),
        }
    };
    let number = |tokens: &mut Tokens<'_>, what: &str| -> Result<(f64, usize, usize), IoError> {
        match tokens.next() {
            Some((t, line)) => t
                .parse::<f64>()
                .map(|v| (v, line, significant_digits(t)))
                .map_err(|_| syntax(line, format!("expected a number ({what}), found `{t}`"))),
            None => Err(syntax(tokens.line.max(1), format!("expected a number ({what}), found the end of the file"))),
        }
    };
    let mut name = None;
    let mut triangles = Vec::new();
    let mut digits = 0;
    expect(&mut tokens, "solid")?;
    let first_name = tokens.rest_of_line();
    name.get_or_insert(first_name);
    loop {
        let Some((word, line)) = tokens.next() else {
            return Err(syntax(tokens.line.max(1), "expected `facet` or `endsolid`, found the end of the file".into()));
        };
        if word.eq_ignore_ascii_case("endsolid") {
            tokens.rest_of_line();
            match tokens.next() {
                None => break,
                Some((w, _)) if w.eq_ignore_ascii_case("solid") => {
                    tokens.rest_of_line();
                    continue;
                }
                Some((w, l)) => return Err(syntax(l, format!("expected `solid` or the end of the file, found `{w}`"))),
            }
        }
        if !word.eq_ignore_ascii_case("facet") {
            return Err(syntax(line, format!("expected `facet` or `endsolid`, found `{word}`")));
        }
        expect(&mut tokens, "normal")?;
        for c in ["normal x", "normal y", "normal z"] {
            number(&mut tokens, c)?;
        }
        expect(&mut tokens, "outer")?;
        expect(&mut tokens, "loop")?;
        let mut vertices = Vec::with_capacity(3);
        for _ in 0..3 {
            expect(&mut tokens, "vertex")?;
            let mut p = [0.0; 3];
            for (c, axis) in p.iter_mut().zip(["x", "y", "z"]) {
                let (v, l, d) = number(&mut tokens, axis)?;
                *c = check_coordinate(v, file, || Place::Line(l))?;
                digits = digits.max(d);
            }
            vertices.push(welder.index(DVec3::from_array(p)));
        }
        expect(&mut tokens, "endloop")?;
        expect(&mut tokens, "endfacet")?;
        triangles.push(MeshPolygon { vertices, place: Place::Line(line) });
    }
    Ok((name, triangles, digits))
}

/// Fan triangles `(a, b, c, outward normal)` of every written face ([`written_faces`]: those of the exact hull of the
/// component's vertices) of every component; with `single`, of the vertices rounded to `f32` first (the binary
/// format's coordinates), so that the triangles lie in face planes of the hull the reader computes from them.
fn triangles(part: &Part, single: bool) -> Vec<[DVec3; 4]> {
    let mut out = Vec::new();
    for c in &part.components {
        let v: Vec<DVec3> =
            if single { c.vertices().iter().map(|p| p.as_vec3().as_dvec3()).collect() } else { c.vertices().to_vec() };
        for (idx, normal) in written_faces(c, &v) {
            for w in idx[1..].windows(2) {
                out.push([v[idx[0]], v[w[0]], v[w[1]], normal]);
            }
        }
    }
    out
}

/// The part as binary STL bytes (coordinates rounded to `f32`).
pub fn stl_binary_bytes(part: &Part) -> Vec<u8> {
    let tris = triangles(part, true);
    let mut out = Vec::with_capacity(84 + 50 * tris.len());
    let mut header = format!("stackplan binary STL: {}", part.name).into_bytes();
    header.resize(80, 0);
    out.extend_from_slice(&header);
    out.extend_from_slice(&(tris.len() as u32).to_le_bytes());
    for [a, b, c, n] in tris {
        for p in [n, a, b, c] {
            for x in p.to_array() {
                out.extend_from_slice(&(x as f32).to_le_bytes());
            }
        }
        out.extend_from_slice(&0u16.to_le_bytes());
    }
    out
}

/// The part as ASCII STL text (full `f64` precision).
pub fn stl_ascii_string(part: &Part) -> String {
    let name: String = part.name.chars().map(|c| if c.is_whitespace() { '_' } else { c }).collect();
    let mut s = String::new();
    let _ = writeln!(s, "solid {name}");
    for [a, b, c, n] in triangles(part, false) {
        let _ = writeln!(s, "  facet normal {:e} {:e} {:e}", n.x, n.y, n.z);
        let _ = writeln!(s, "    outer loop");
        for p in [a, b, c] {
            let _ = writeln!(s, "      vertex {:?} {:?} {:?}", p.x, p.y, p.z);
        }
        let _ = writeln!(s, "    endloop");
        let _ = writeln!(s, "  endfacet");
    }
    let _ = writeln!(s, "endsolid {name}");
    s
}

/// Writes binary STL atomically.
pub fn write_stl_binary(path: impl AsRef<Path>, part: &Part) -> Result<(), IoError> {
    super::atomic::write_atomic(path, &stl_binary_bytes(part))
}

/// Writes ASCII STL atomically.
pub fn write_stl_ascii(path: impl AsRef<Path>, part: &Part) -> Result<(), IoError> {
    super::atomic::write_atomic(path, stl_ascii_string(part).as_bytes())
}
