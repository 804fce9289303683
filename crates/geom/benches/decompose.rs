//! Sheet-metal decomposition benchmark: building parts from zero-thickness models.
//!
//! * `complex/triangulation` and `complex/convex_merge`: the Complex Part of \[A\] Fig. 14c (see
//!   `stackplan_geom::examples::complex`), built into a `Part` (validation, triangulation, Delaunay flips, merging,
//!   extrusion, validation of every prism, mass properties, boundary faces);
//! * `plate_100_holes/*`: a 400 x 400 plate with a 10 x 10 grid of octagonal holes (n = 804 vertices), to show how
//!   the O(n^2)-worst-case steps scale on a large face.

use criterion::{Criterion, criterion_group, criterion_main};
use stackplan_geom::{DVec3, Decomposition, SheetFace, SheetMetal, examples};
use std::hint::black_box;

fn plate_with_holes(k: usize) -> SheetMetal {
    let size = 40.0 * k as f64;
    let outline = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(size, 0.0, 0.0),
        DVec3::new(size, size, 0.0),
        DVec3::new(0.0, size, 0.0),
    ];
    let mut holes = Vec::new();
    for i in 0..k {
        for j in 0..k {
            let c = DVec3::new(20.0 + 40.0 * i as f64, 20.0 + 40.0 * j as f64, 0.0);
            holes.push(
                (0..8)
                    .map(|m| {
                        let a = m as f64 * std::f64::consts::FRAC_PI_4 + 0.1;
                        c + DVec3::new(12.0 * a.cos(), 12.0 * a.sin(), 0.0)
                    })
                    .collect(),
            );
        }
    }
    SheetMetal { thickness: 2.0, faces: vec![SheetFace { outline, holes }] }
}

fn bench(c: &mut Criterion) {
    let complex = examples::complex();
    let mut group = c.benchmark_group("complex");
    for (label, d) in [("triangulation", Decomposition::Triangulation), ("convex_merge", Decomposition::ConvexMerge)] {
        group.bench_function(label, |b| {
            b.iter(|| black_box(complex.build_part("complex", 1.0, d).expect("valid example")))
        });
    }
    group.finish();
    let plate = plate_with_holes(10);
    let mut group = c.benchmark_group("plate_100_holes");
    group.sample_size(10);
    for (label, d) in [("triangulation", Decomposition::Triangulation), ("convex_merge", Decomposition::ConvexMerge)] {
        group.bench_function(label, |b| b.iter(|| black_box(plate.build_part("plate", 1.0, d).expect("valid plate"))));
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
