//! Identity harness and profiling driver for speed work on the obstacle construction (a tool run by hand):
//!
//! * `cargo run --release -p stackplan-cspace --example obstacle_identity -- dump FILE` hashes the full `Debug` text
//!   of `gauss_map_obstacle` (the obstacle with its planes, edges, provenance and kinds, or the failure) on 100
//!   polytopes x 4 400 pairs x 86 rotations and writes one line per case to `FILE`: run it before and after a change,
//!   then `cmp` the two files;
//! * `... --example obstacle_identity -- profile box|prism|quarter|general|random [CALLS]` builds and drops `CALLS`
//!   (default 10 000) obstacles of the benchmark's box or prism pair (`quarter`: the boxes at a quarter turn about
//!   `z`, `general`: the boxes under a general rotation, `random`: two hulls of 20 and 24 points) in
//!   `build_and_drop`, for `valgrind --tool=callgrind --toggle-collect='*build_and_drop*'` or
//!   `perf stat -e task-clock`.

#![allow(clippy::print_stdout, clippy::print_stderr)] // a command-line tool reports its counts

use glam::{DMat3, DVec3};
use stackplan_cspace::minkowski::gauss_map_obstacle;
use stackplan_geom::{ConvexPolytope, Decomposition, ReadOptions, convex_hull, read_part};
use std::hash::{Hash, Hasher};
use std::io::Write;

// the shapes the tests share (the module allows the ones this tool does not use)
#[path = "../tests/common/mod.rs"]
mod common;

fn polytopes() -> Vec<ConvexPolytope> {
    let mut out = Vec::new();
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/parts");
    let mut names: Vec<_> = std::fs::read_dir(dir).expect("fixtures").map(|e| e.expect("entry").path()).collect();
    names.sort();
    for decomposition in [Decomposition::ConvexMerge, Decomposition::Triangulation] {
        for path in &names {
            let part = read_part(path, &ReadOptions { decomposition, ..Default::default() }).expect("part");
            for (k, c) in part.components().iter().cloned().enumerate() {
                if decomposition == Decomposition::ConvexMerge || k % 5 == 0 {
                    out.push(c);
                }
            }
        }
    }
    for (lo, hi) in [
        (DVec3::ZERO, DVec3::new(100.0, 50.0, 2.0)),
        (DVec3::ZERO, DVec3::new(80.0, 60.0, 2.0)),
        (DVec3::new(-1.0, 0.5, 0.0), DVec3::new(4.0, 5.0, 6.0)),
        (DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0)),
        (DVec3::new(0.3, -0.7, 1.1), DVec3::new(2.0, 0.1, 1.6)),
        (DVec3::ZERO, DVec3::ONE),
    ] {
        out.push(common::cuboid(lo, hi));
    }
    let hex = [(0.0, 0.0), (60.0, 0.0), (90.0, 30.0), (80.0, 70.0), (20.0, 80.0), (-10.0, 40.0)];
    for scale in [1.0, 0.7] {
        let o: Vec<(f64, f64)> = hex.iter().map(|&(x, y)| (x * scale, y * scale)).collect();
        out.push(common::prism(&o, 0.0, 2.0, 2).expect("prism"));
    }
    let mut s = 12345u64;
    let mut next = || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    for k in 0..10 {
        let n = 3 + k % 5;
        let outline: Vec<(f64, f64)> =
            (0..n).map(|_| ((next() * 8.0).round() * 0.5, (next() * 8.0).round() * 0.5)).collect();
        if let Some(p) = common::prism(&outline, 0.0, 0.25 * (1 + k % 3) as f64, k % 3) {
            out.push(p);
        }
        let reg: Vec<(f64, f64)> = (0..n + 1)
            .map(|i| {
                let t = i as f64 * std::f64::consts::TAU / (n + 1) as f64 + 0.1 * k as f64;
                (3.0 * t.cos(), 2.0 * t.sin())
            })
            .collect();
        if let Some(p) = common::prism(&reg, -1.0, 1.0, 2) {
            out.push(p);
        }
    }
    for (n, sphere) in [(8, true), (12, true), (20, true), (30, false), (12, false), (50, true)] {
        let pts: Vec<DVec3> = (0..n)
            .map(|_| {
                if sphere {
                    let z = 2.0 * next() - 1.0;
                    let phi = std::f64::consts::TAU * next();
                    let r = (1.0 - z * z).sqrt();
                    DVec3::new(r * phi.cos(), r * phi.sin(), z) * 50.0
                } else {
                    DVec3::new((next() * 8.0).round(), (next() * 8.0).round(), (next() * 8.0).round()) * 0.25
                }
            })
            .collect();
        if let Ok(h) = convex_hull(&pts) {
            out.push(h.polytope);
        }
    }
    out
}

fn rotations() -> Vec<DMat3> {
    let mut out = Vec::new();
    for k in 0..52 {
        out.push(DMat3::from_rotation_z((k * 7) as f64 * std::f64::consts::PI / 180.0));
    }
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_3, FRAC_PI_4, PI};
    for t in [FRAC_PI_2, PI, -FRAC_PI_2, FRAC_PI_4, FRAC_PI_3] {
        out.push(DMat3::from_rotation_z(t));
    }
    for t in [
        1e-12, 1e-10, 2.5e-10, 4e-10, 4.9e-10, 5e-10, 5.1e-10, 6e-10, 8e-10, 1e-9, 1.1e-9, 2e-9, 1e-8, 1e-7, 1e-6,
        -5e-10, -7e-10,
    ] {
        out.push(DMat3::from_rotation_z(t));
    }
    for (axis, angle) in [
        (DVec3::new(1.0, 2.0, 3.0), 0.7),
        (DVec3::new(-0.3, 0.2, 1.0), 2.1),
        (DVec3::new(0.0, 1.0, 0.1), -1.3),
        (DVec3::new(1.0, -1.0, 0.5), 0.2),
    ] {
        out.push(DMat3::from_axis_angle(axis.normalize(), angle));
    }
    out.push(DMat3::from_rotation_x(FRAC_PI_2));
    out.push(DMat3::from_rotation_y(FRAC_PI_2));
    out.push(DMat3::from_rotation_z(0.5) * DMat3::from_rotation_x(FRAC_PI_2));
    out.push(DMat3::from_rotation_x(7e-10));
    for k in [0, 5, 13, 22] {
        out.push(common::axis_rotation(k));
    }
    out
}

fn dump(path: &str) {
    let ps = polytopes();
    let rs = rotations();
    let mut file = std::io::BufWriter::new(std::fs::File::create(path).expect("dump file"));
    let (mut ok, mut err) = (0, 0);
    for (ia, a) in ps.iter().enumerate() {
        for (ib, b) in ps.iter().enumerate() {
            if (ia * 31 + ib) % 3 != 0 && !(ia < 40 && ib < 40) {
                continue;
            }
            for (ir, r) in rs.iter().enumerate() {
                let result = gauss_map_obstacle(a, *r, b);
                let mut h = std::hash::DefaultHasher::new();
                format!("{result:?}").hash(&mut h);
                if result.is_ok() {
                    ok += 1
                } else {
                    err += 1
                }
                writeln!(file, "{ia} {ib} {ir} {} {:016x}", u8::from(result.is_ok()), h.finish()).expect("write");
            }
        }
    }
    eprintln!("{} polytopes, {} rotations: {ok} ok, {err} failed", ps.len(), rs.len());
}

#[inline(never)]
fn build_and_drop(a: &ConvexPolytope, r: DMat3, b: &ConvexPolytope) -> usize {
    let o = gauss_map_obstacle(std::hint::black_box(a), r, std::hint::black_box(b)).expect("obstacle");
    o.polytope().faces().len()
}

fn profile(case: &str, n: usize) {
    let hex = [(0.0, 0.0), (60.0, 0.0), (90.0, 30.0), (80.0, 70.0), (20.0, 80.0), (-10.0, 40.0)];
    let prism = |s: f64| {
        let o: Vec<(f64, f64)> = hex.iter().map(|&(x, y)| (x * s, y * s)).collect();
        common::prism(&o, 0.0, 2.0, 2).expect("prism")
    };
    let (a, b, r) = match case {
        "box" => (
            common::cuboid(DVec3::ZERO, DVec3::new(100.0, 50.0, 2.0)),
            common::cuboid(DVec3::ZERO, DVec3::new(80.0, 60.0, 2.0)),
            DMat3::from_rotation_z(0.3),
        ),
        "prism" => (prism(1.0), prism(0.7), DMat3::from_rotation_z(0.3)),
        // a quarter turn: side faces merge, the pair is not tame (the z-prism route with the polygon merges)
        "quarter" => (
            common::cuboid(DVec3::ZERO, DVec3::new(100.0, 50.0, 2.0)),
            common::cuboid(DVec3::ZERO, DVec3::new(80.0, 60.0, 2.0)),
            DMat3::from_rotation_z(std::f64::consts::FRAC_PI_2),
        ),
        "random" => {
            // hulls of 20 and 24 points on ellipsoids (more than 64 obstacle vertices: the star-sort edge table)
            let cloud = |n: usize, seed: f64| {
                let pts: Vec<DVec3> = (0..n)
                    .map(|k| {
                        let t = k as f64 * 2.399 + seed;
                        let z = 1.0 - 2.0 * (k as f64 + 0.5) / n as f64;
                        let r = (1.0 - z * z).sqrt();
                        DVec3::new(r * t.cos() * 3.0, r * t.sin() * 2.0, z)
                    })
                    .collect();
                convex_hull(&pts).expect("hull").polytope
            };
            (cloud(20, 0.3), cloud(24, 0.7), DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7))
        }
        _ => (
            common::cuboid(DVec3::ZERO, DVec3::new(100.0, 50.0, 2.0)),
            common::cuboid(DVec3::ZERO, DVec3::new(80.0, 60.0, 2.0)),
            DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7),
        ),
    };
    let mut total = 0;
    for _ in 0..n {
        total += build_and_drop(&a, r, &b);
    }
    eprintln!("{case}: {n} calls, {total} faces");
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    match (args.get(1).map(String::as_str), args.get(2)) {
        (Some("dump"), Some(path)) => dump(path),
        (Some("profile"), Some(case)) => {
            profile(case, args.get(3).and_then(|s| s.parse().ok()).unwrap_or(10_000));
        }
        _ => {
            eprintln!(
                "usage: obstacle_identity dump FILE | obstacle_identity profile \
                 box|prism|quarter|general|random [CALLS]"
            );
            std::process::exit(2);
        }
    }
}
