//! Obstacle construction: Gauss-map overlay (the library route) vs the exact-predicate hull of the `nA * nB`
//! differences vs parry3d-f64's hull of the same differences, in the same run (the convex-pair interference test is
//! `benches/interference.rs`).

#![allow(clippy::print_stderr)] // a benchmark program reports the case sizes on stderr

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{DMat3, DVec3};
use stackplan_cspace::minkowski::{gauss_map_obstacle, obstacle, obstacle_by_hull};
use stackplan_geom::ConvexPolytope;
use std::hint::black_box;

mod common;
use common::{cuboid, hexagon_prism, random_polytope};

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
        let faces: Vec<Vec<usize>> = o.polytope().faces().iter().map(|f| f.vertices.to_vec()).collect();
        let planes: Vec<stackplan_geom::Plane> = o.polytope().planes().copied().collect();
        g.bench_function("polytope_assembly_only", |bn| {
            bn.iter(|| ConvexPolytope::with_planes(verts.clone(), faces.clone(), planes.clone()))
        });
        g.bench_function("parry_hull", |bn| bn.iter(|| parry_hull_route(black_box(a), *r, black_box(b))));
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
