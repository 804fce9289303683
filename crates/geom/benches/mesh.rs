//! Mesh reading benchmark: parsing, welding, shell splitting and the convexity check of `stackplan_geom::io::mesh`.
//!
//! * `ball_4000_ascii_stl`: the hull of 4000 points on a sphere (a Fibonacci lattice, about 8000 triangles) as ASCII
//!   STL with full `f64` digits: every triangle is checked exactly against the faces around one of its hull vertices
//!   (the quadratic fallback against every face would take minutes here);
//! * `complex_turned_binary_stl`: the built-in Complex part (79 convex pieces touching face to face) turned by a
//!   general rotation, as binary STL: single-precision coordinates, so its faces are planar only to `f32` rounding,
//!   the pieces' shared faces are separated and their facets merged within the single-precision tolerance;
//! * `complex_obj`: the Complex part as OBJ, as written (exact faces).

use criterion::{Criterion, criterion_group, criterion_main};
use stackplan_geom::io::{self, ReadOptions};
use stackplan_geom::{DMat3, DVec3, Part, PartOrigin, convex_hull, convex_hull_merged};
use std::hint::black_box;
use std::path::Path;

fn bench(c: &mut Criterion) {
    let n = 4000;
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let points: Vec<DVec3> = (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let t = golden * i as f64;
            DVec3::new(r * t.cos(), r * t.sin(), z) * 50.0
        })
        .collect();
    let ball = convex_hull(&points).expect("ball").polytope;
    let ball = Part::from_components("ball", vec![ball], 1.0, PartOrigin::ConvexPieces).expect("ball part");
    let ball_stl = io::stl_ascii_string(&ball);

    let complex = stackplan_geom::examples::part_by_name("complex", Default::default()).expect("complex");
    let turn = DMat3::from_euler(glam::EulerRot::ZYX, 0.3, 0.7, 1.1);
    let turned: Vec<_> = complex
        .components()
        .iter()
        .map(|c| {
            let pts: Vec<DVec3> = c.vertices().iter().map(|&v| turn * v + DVec3::new(12.5, -7.0, 30.0)).collect();
            convex_hull_merged(&pts).expect("piece").polytope
        })
        .collect();
    let turned = Part::from_components("turned", turned, 1.0, PartOrigin::ConvexPieces).expect("turned part");
    let turned_stl = io::stl_binary_bytes(&turned);
    let complex_obj = io::obj_string(&complex);

    let options = ReadOptions::default();
    let mut g = c.benchmark_group("mesh");
    g.sample_size(20);
    g.bench_function("ball_4000_ascii_stl", |b| {
        b.iter(|| io::parse_stl(black_box(ball_stl.as_bytes()), Path::new("ball.stl"), &options).expect("ball"))
    });
    g.bench_function("complex_turned_binary_stl", |b| {
        b.iter(|| io::parse_stl(black_box(&turned_stl), Path::new("turned.stl"), &options).expect("turned"))
    });
    g.bench_function("complex_obj", |b| {
        b.iter(|| io::parse_obj(black_box(complex_obj.as_bytes()), Path::new("complex.obj"), &options).expect("obj"))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
