//! Obstacle construction: Gauss-map overlay (the library route) vs the exact-predicate hull of the `nA * nB`
//! differences vs parry3d-f64's hull of the same differences, in the same run; and the convex-pair interference test.

#![allow(clippy::print_stderr)] // a benchmark program reports the case sizes on stderr

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{DMat3, DVec3};
use stackplan_cspace::interference::{PlacedConvex, classify_pair};
use stackplan_cspace::minkowski::{gauss_map_obstacle, obstacle, obstacle_by_hull};
use stackplan_geom::{ConvexPolytope, convex_hull};
use std::hint::black_box;

fn cuboid(hi: DVec3) -> ConvexPolytope {
    ConvexPolytope::cuboid(DVec3::ZERO, hi).expect("box")
}

/// A sheet-metal piece: a convex hexagon extruded by 2 mm.
fn hexagon_prism(scale: f64) -> ConvexPolytope {
    let outline = [(0.0, 0.0), (60.0, 0.0), (90.0, 30.0), (80.0, 70.0), (20.0, 80.0), (-10.0, 40.0)];
    let mut pts = Vec::new();
    for (x, y) in outline {
        pts.push(DVec3::new(x * scale, y * scale, 0.0));
        pts.push(DVec3::new(x * scale, y * scale, 2.0));
    }
    convex_hull(&pts).expect("prism").polytope
}

/// The hull of `n` pseudo-random points on a sphere of radius 50 (all extreme).
fn random_polytope(n: usize, seed: u64) -> ConvexPolytope {
    let mut s = seed;
    let mut next = || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let pts: Vec<DVec3> = (0..n)
        .map(|_| {
            let z = 2.0 * next() - 1.0;
            let phi = 2.0 * std::f64::consts::PI * next();
            let r = (1.0 - z * z).sqrt();
            DVec3::new(r * phi.cos(), r * phi.sin(), z) * 50.0
        })
        .collect();
    convex_hull(&pts).expect("random").polytope
}

fn parry_hull_route(a: &ConvexPolytope, r: DMat3, b: &ConvexPolytope) -> usize {
    let mut pts = Vec::with_capacity(a.vertices().len() * b.vertices().len());
    for x in a.vertices() {
        let ra = r * *x;
        for y in b.vertices() {
            pts.push(*y - ra);
        }
    }
    parry3d_f64::transformation::convex_hull(&pts).1.len()
}

fn bench(c: &mut Criterion) {
    let rz = DMat3::from_rotation_z(0.3);
    let general = DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
    let cases: Vec<(&str, ConvexPolytope, ConvexPolytope, DMat3)> = vec![
        ("box_x_box", cuboid(DVec3::new(100.0, 50.0, 2.0)), cuboid(DVec3::new(80.0, 60.0, 2.0)), rz),
        ("prism_x_prism", hexagon_prism(1.0), hexagon_prism(0.7), rz),
        ("random_20x20", random_polytope(20, 1), random_polytope(20, 2), general),
        ("random_50x50", random_polytope(50, 3), random_polytope(50, 4), general),
    ];
    for (name, a, b, r) in &cases {
        let o = obstacle(a, *r, b).expect("obstacle");
        assert!(gauss_map_obstacle(a, *r, b).is_ok(), "{name}: the Gauss-map route must succeed");
        eprintln!(
            "{name}: {} x {} vertices -> {} vertices, {} faces",
            a.vertices().len(),
            b.vertices().len(),
            o.polytope().vertices().len(),
            o.polytope().faces().len()
        );
        let mut g = c.benchmark_group(*name);
        g.bench_function("gauss_map", |bn| bn.iter(|| obstacle(black_box(a), *r, black_box(b))));
        g.bench_function("exact_hull", |bn| bn.iter(|| obstacle_by_hull(black_box(a), *r, black_box(b))));
        // the share of the assembly into a checked geom::ConvexPolytope (edge table, planes) in the gauss_map figure
        let verts = o.polytope().vertices().to_vec();
        let faces: Vec<Vec<usize>> = o.polytope().faces().iter().map(|f| f.vertices.clone()).collect();
        let planes: Vec<stackplan_geom::Plane> = o.polytope().planes().copied().collect();
        g.bench_function("polytope_assembly_only", |bn| {
            bn.iter(|| ConvexPolytope::with_planes(verts.clone(), faces.clone(), planes.clone()))
        });
        g.bench_function("parry_hull", |bn| bn.iter(|| parry_hull_route(black_box(a), *r, black_box(b))));
        g.finish();
    }

    let unit = cuboid(DVec3::new(100.0, 50.0, 2.0));
    let pa = PlacedConvex::new(&unit, DMat3::IDENTITY, DVec3::ZERO);
    let overlapping = PlacedConvex::new(&unit, rz, DVec3::new(50.0, 10.0, 1.0));
    let touching = PlacedConvex::new(&unit, DMat3::IDENTITY, DVec3::new(0.0, 0.0, 2.0));
    let apart = PlacedConvex::new(&unit, rz, DVec3::new(300.0, 0.0, 0.0));
    let tol = 1e-7;
    let mut g = c.benchmark_group("interference_box_pair");
    g.bench_function("penetrating", |bn| bn.iter(|| classify_pair(black_box(&pa), black_box(&overlapping), tol, 0.0)));
    g.bench_function("touching", |bn| bn.iter(|| classify_pair(black_box(&pa), black_box(&touching), tol, 0.0)));
    g.bench_function("separated", |bn| bn.iter(|| classify_pair(black_box(&pa), black_box(&apart), tol, 0.0)));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
