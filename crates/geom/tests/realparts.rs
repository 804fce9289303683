//! The six real bent parts of `fixtures/realparts/` (BenDFM), read from STEP and from STL and recognised as sheet
//! metal, against the dataset's labels: thickness, bend count and radii, volume, the same plates both ways, and
//! points of the solid inside the pieces.

use stackplan_geom::cad::recognise::Recognition;
use stackplan_geom::io::{IoError, ReadOptions, Units, read_part, sheet::read_sheet};
use stackplan_geom::{DVec3, Part};
use std::path::{Path, PathBuf};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/realparts")
}

struct Labels {
    thickness: f64,
    volume: f64,
    bends: usize,
    radii: Vec<f64>,
}

fn labels(n: usize) -> Labels {
    let read = |name: String| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir().join(name)).expect("labels")).expect("json")
    };
    let l = read(format!("bendfm_{n}_labels.json"));
    let seq = read(format!("bendfm_{n}_sequence.json"));
    let mut radii: Vec<f64> = seq
        .as_array()
        .expect("sequence")
        .iter()
        .filter_map(|b| b.get("bend_radius").and_then(serde_json::Value::as_f64))
        .collect();
    radii.sort_by(f64::total_cmp);
    Labels {
        thickness: l["sheet_thickness"].as_f64().expect("thickness"),
        volume: l["part_volume_3d"].as_f64().expect("volume") * 1000.0,
        bends: l["total_bends"].as_u64().expect("bends") as usize,
        radii,
    }
}

fn sheet(n: usize, ext: &str) -> (Part, Recognition) {
    let path = dir().join(format!("bendfm_{n}.{ext}"));
    read_sheet(&path, &ReadOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn inner_radii(r: &Recognition) -> Vec<f64> {
    let mut radii: Vec<f64> = r.bends.iter().map(|b| b.bend.inner_radius).collect();
    radii.sort_by(f64::total_cmp);
    radii
}

#[test]
fn step_gives_the_labelled_thickness_bends_radii_and_volume() {
    for n in 0..6 {
        let l = labels(n);
        let (part, r) = sheet(n, "stp");
        assert!(
            (r.thickness - l.thickness).abs() <= 1e-6 * l.thickness,
            "{n}: thickness {} vs {}",
            r.thickness,
            l.thickness
        );
        assert_eq!(r.bends.len(), l.bends, "{n}: bends");
        for (a, b) in inner_radii(&r).iter().zip(&l.radii) {
            assert!((a - b).abs() <= 1e-6, "{n}: radius {a} vs {b}");
        }
        let v = part.mass().volume;
        assert!(v >= l.volume * (1.0 - 1e-6), "{n}: pieces {v} below the solid's {}", l.volume);
        assert!(v <= l.volume * 1.01, "{n}: pieces {v} more than 1 % above the solid's {}", l.volume);
        assert!((r.solid_volume - l.volume).abs() <= 1e-5 * l.volume, "{n}: solid {} vs {}", r.solid_volume, l.volume);
        assert!(r.max_deviation <= r.bend_tolerance + 1e-12, "{n}");
    }
}

#[test]
fn stl_gives_the_labelled_thickness_bends_radii_and_volume() {
    for n in 0..6 {
        let l = labels(n);
        let (part, r) = sheet(n, "stl");
        // single-precision coordinates: the planes are fitted to rounded vertices
        assert!((r.thickness - l.thickness).abs() <= 2e-4, "{n}: thickness {} vs {}", r.thickness, l.thickness);
        assert_eq!(r.bends.len(), l.bends, "{n}: bends");
        for (a, b) in inner_radii(&r).iter().zip(&l.radii) {
            // the tessellation's vertices lie on the exact arcs, written in single precision
            assert!((a - b).abs() <= 2e-3, "{n}: radius {a} vs {b}");
        }
        // the mesh loses 0.005-0.012 % to its chords; the pieces contain the mesh
        let v = part.mass().volume;
        assert!(v >= l.volume * (1.0 - 2e-4), "{n}: pieces {v} below the solid's {}", l.volume);
        assert!(v <= l.volume * 1.01, "{n}: pieces {v} more than 1 % above the solid's {}", l.volume);
        assert!(v >= r.solid_volume * (1.0 - 1e-9), "{n}: pieces {v} below the mesh's {}", r.solid_volume);
    }
}

#[test]
fn step_and_stl_give_the_same_plates() {
    for n in 0..6 {
        let (_, a) = sheet(n, "stp");
        let (_, b) = sheet(n, "stl");
        assert_eq!(a.plates.len(), b.plates.len(), "{n}: plates");
        let areas = |r: &Recognition| {
            let mut v: Vec<(f64, usize)> = r.plates.iter().map(|p| (p.area, p.holes)).collect();
            v.sort_by(|x, y| x.0.total_cmp(&y.0));
            v
        };
        for ((x, hx), (y, hy)) in areas(&a).iter().zip(&areas(&b)) {
            // the mesh's holes are polygons inscribed in the circles
            assert!((x - y).abs() <= 2e-3 * x.max(*y) + 1.0, "{n}: plate areas {x} vs {y}");
            assert_eq!(hx, hy, "{n}: holes");
        }
    }
}

/// The triangles of a binary STL.
fn stl_triangles(path: &Path) -> Vec<[DVec3; 3]> {
    let bytes = std::fs::read(path).expect("stl");
    let count = u32::from_le_bytes(bytes[80..84].try_into().expect("count")) as usize;
    (0..count)
        .map(|t| {
            let rec = &bytes[84 + 50 * t..84 + 50 * (t + 1)];
            let f = |k: usize| f32::from_le_bytes(rec[k..k + 4].try_into().expect("f32")) as f64;
            [DVec3::new(f(12), f(16), f(20)), DVec3::new(f(24), f(28), f(32)), DVec3::new(f(36), f(40), f(44))]
        })
        .collect()
}

/// Whether `p` is inside the closed mesh: the parity of crossings of a ray in a generic direction.
fn inside_mesh(p: DVec3, triangles: &[[DVec3; 3]]) -> bool {
    let dir = DVec3::new(0.5773, 0.5774, 0.5775).normalize();
    let mut crossings = 0;
    for [a, b, c] in triangles {
        // Moller-Trumbore
        let (e1, e2) = (*b - *a, *c - *a);
        let h = dir.cross(e2);
        let det = e1.dot(h);
        if det.abs() < 1e-15 {
            continue;
        }
        let s = p - *a;
        let u = s.dot(h) / det;
        let q = s.cross(e1);
        let v = dir.dot(q) / det;
        let t = e2.dot(q) / det;
        if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0 {
            crossings += 1;
        }
    }
    crossings % 2 == 1
}

fn distance_to_triangle(p: DVec3, [a, b, c]: &[DVec3; 3]) -> f64 {
    let n = (*b - *a).cross(*c - *a);
    let len = n.length();
    if len == 0.0 {
        return f64::INFINITY;
    }
    let n = n / len;
    let q = p - n * (p - *a).dot(n);
    let inside = [(*a, *b), (*b, *c), (*c, *a)].iter().all(|(u, v)| (*v - *u).cross(q - *u).dot(n) >= 0.0);
    if inside {
        return (p - q).length();
    }
    [(*a, *b), (*b, *c), (*c, *a)]
        .iter()
        .map(|(u, v)| {
            let e = *v - *u;
            let s = ((p - *u).dot(e) / e.length_squared()).clamp(0.0, 1.0);
            (p - (*u + e * s)).length()
        })
        .fold(f64::INFINITY, f64::min)
}

fn in_pieces(part: &Part, p: DVec3, tol: f64) -> bool {
    part.components().iter().any(|c| c.planes().all(|pl| pl.signed_distance(p) <= tol))
}

/// Points inside the mesh (ray parity) lie in the pieces: exactly for the STL's own pieces, and, for the STEP's,
/// those farther from the mesh's surface than its chord error (the mesh's inner arcs stand inside the true bends).
#[test]
fn points_of_the_solid_lie_in_the_pieces() {
    // a deterministic low-discrepancy sequence over the box
    let halton = |i: usize, base: usize| {
        let (mut f, mut r, mut i) = (1.0, 0.0, i);
        while i > 0 {
            f /= base as f64;
            r += f * (i % base) as f64;
            i /= base;
        }
        r
    };
    for n in 0..6 {
        let triangles = stl_triangles(&dir().join(format!("bendfm_{n}.stl")));
        let (stl_part, _) = sheet(n, "stl");
        let (step_part, _) = sheet(n, "stp");
        let (lo, hi) = stl_part.aabb();
        let mut tested = 0;
        let mut i = 1;
        while tested < 400 && i < 200_000 {
            let p = lo + (hi - lo) * DVec3::new(halton(i, 2), halton(i, 3), halton(i, 5));
            i += 1;
            if !inside_mesh(p, &triangles) {
                continue;
            }
            tested += 1;
            assert!(in_pieces(&stl_part, p, 1e-6), "bendfm_{n}.stl: {p} inside the mesh but outside the pieces");
            let near = triangles.iter().map(|t| distance_to_triangle(p, t)).fold(f64::INFINITY, f64::min);
            if near > 0.06 {
                assert!(in_pieces(&step_part, p, 1e-6), "bendfm_{n}.stp: {p} inside the solid but outside the pieces");
            }
        }
        assert_eq!(tested, 400, "bendfm_{n}: too few points inside the mesh");
    }
}

/// An ASCII STL of `triangles` in `unit`, written with 9 significant digits (single precision, as exporters do).
fn ascii_stl(triangles: &[[DVec3; 3]], mm_per_unit: f64) -> String {
    let mut out = String::from("solid scaled\n");
    for t in triangles {
        out.push_str("facet normal 0 0 0\nouter loop\n");
        for v in t {
            let v = *v / mm_per_unit;
            out.push_str(&format!("vertex {:.8e} {:.8e} {:.8e}\n", v.x, v.y, v.z));
        }
        out.push_str("endloop\nendfacet\n");
    }
    out.push_str("endsolid scaled\n");
    out
}

#[test]
fn a_mesh_in_inches_or_metres_reads_to_the_same_part_in_millimetres() {
    let triangles = stl_triangles(&dir().join("bendfm_1.stl"));
    let tmp = tempfile::tempdir().expect("tmp");
    let mut parts = Vec::new();
    for (units, factor) in [(Units::Mm, 1.0), (Units::In, 25.4), (Units::M, 1000.0)] {
        let path = tmp.path().join(format!("bendfm_1_{units}.stl"));
        std::fs::write(&path, ascii_stl(&triangles, factor)).expect("write");
        let options = ReadOptions { units, ..Default::default() };
        let (part, r) = read_sheet(&path, &options).unwrap_or_else(|e| panic!("{units}: {e}"));
        parts.push((part, r));
    }
    let (base, rb) = &parts[0];
    for (part, r) in &parts[1..] {
        assert!((r.thickness - rb.thickness).abs() <= 1e-4, "{} vs {}", r.thickness, rb.thickness);
        assert_eq!(r.bends.len(), rb.bends.len());
        assert!((part.mass().volume - base.mass().volume).abs() <= 1e-4 * base.mass().volume);
        let (a, b) = (part.aabb(), base.aabb());
        assert!((a.0 - b.0).length() <= 1e-3 && (a.1 - b.1).length() <= 1e-3);
    }
}

fn write_stl(dir: &Path, name: &str, triangles: &[[DVec3; 3]]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, ascii_stl(triangles, 1.0)).expect("write");
    path
}

/// The 12 triangles of a box, counter-clockwise seen from outside.
fn box_triangles(lo: DVec3, hi: DVec3) -> Vec<[DVec3; 3]> {
    let c = |i: usize| {
        DVec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    };
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    quads.iter().flat_map(|q| [[c(q[0]), c(q[1]), c(q[2])], [c(q[0]), c(q[2]), c(q[3])]]).collect()
}

#[test]
fn solids_that_are_no_sheet_get_errors_that_name_the_file_and_the_faces() {
    let tmp = tempfile::tempdir().expect("tmp");
    // an open mesh: one triangle of a real part missing
    let mut triangles = stl_triangles(&dir().join("bendfm_1.stl"));
    triangles.remove(7);
    let open = write_stl(tmp.path(), "open.stl", &triangles);
    let err = read_part(&open, &ReadOptions::default()).expect_err("open mesh");
    let text = err.to_string();
    assert!(text.contains("open.stl") && text.contains("line"), "{text}");
    // two plates of different thickness in one mesh (two shells)
    let mut two = box_triangles(DVec3::ZERO, DVec3::new(100.0, 80.0, 2.0));
    two.extend(box_triangles(DVec3::new(0.0, 0.0, 10.0), DVec3::new(100.0, 80.0, 13.0)));
    let path = write_stl(tmp.path(), "two.stl", &two);
    let err = read_sheet(&path, &ReadOptions::default()).expect_err("two thicknesses");
    let text = err.to_string();
    assert!(matches!(err, IoError::NotSheetMetal { .. }), "{text}");
    assert!(text.contains("two.stl") && text.contains("--decompose") && text.contains("mesh region"), "{text}");
    // an L-shaped block: a leg 4 mm thick and a leg 10 mm thick, one closed shell
    let path = write_stl(tmp.path(), "block.stl", &l_block());
    let err = read_part(&path, &ReadOptions::default()).expect_err("no sheet");
    let text = err.to_string();
    assert!(matches!(err, IoError::NotConvex { .. }), "{text}");
    assert!(text.contains("block.stl") && text.contains("10.0000 mm apart") && text.contains("4.0000 mm"), "{text}");
    let err = read_sheet(&path, &ReadOptions::default()).expect_err("no sheet");
    assert!(matches!(err, IoError::NotSheetMetal { .. }), "{err}");
    // a cube with a dent: its opposite faces pair up twice, and the two plates would overlap
    let mut dent = box_triangles(DVec3::ZERO, DVec3::splat(20.0));
    dent.retain(|t| t.iter().any(|v| v.z < 20.0));
    let apex = DVec3::splat(10.0);
    for (a, b) in [(0.0, 0.0), (20.0, 0.0), (20.0, 20.0), (0.0, 20.0)]
        .windows(2)
        .map(|w| (w[0], w[1]))
        .chain([((0.0, 20.0), (0.0, 0.0))])
    {
        dent.push([DVec3::new(a.0, a.1, 20.0), DVec3::new(b.0, b.1, 20.0), apex]);
    }
    let path = write_stl(tmp.path(), "dent.stl", &dent);
    let err = read_sheet(&path, &ReadOptions::default()).expect_err("no sheet");
    assert!(matches!(err, IoError::NotSheetMetal { .. }), "{err}");
    assert!(err.to_string().contains("overlap"), "{err}");
}

/// An L-shaped profile extruded by 30 mm along z: legs 4 mm (horizontal) and 10 mm (vertical) thick.
fn l_block() -> Vec<[DVec3; 3]> {
    let profile = [(0.0, 0.0), (60.0, 0.0), (60.0, 4.0), (10.0, 4.0), (10.0, 20.0), (0.0, 20.0)];
    let m = profile.len();
    let at = |k: usize, z: f64| DVec3::new(profile[k % m].0, profile[k % m].1, z);
    let mut out = Vec::new();
    // caps: a fan from the reflex corner (index 3); the top counter-clockwise about +z, the bottom reversed
    for k in 4..m + 2 {
        let (a, b) = (k % m, (k + 1) % m);
        if a == 3 || b == 3 {
            continue;
        }
        out.push([at(3, 30.0), at(a, 30.0), at(b, 30.0)]);
        out.push([at(3, 0.0), at(b, 0.0), at(a, 0.0)]);
    }
    for k in 0..m {
        let (a, b) = (k, (k + 1) % m);
        out.push([at(a, 0.0), at(b, 0.0), at(b, 30.0)]);
        out.push([at(a, 0.0), at(b, 30.0), at(a, 30.0)]);
    }
    out
}
