//! Obstacle construction benchmarks: Gauss-map overlay vs exact hull vs parry hull of the differences.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{DMat3, DVec3};
use stackplan_cspace::minkowski::{obstacle, obstacle_by_hull};
use stackplan_geom::convex_hull;
use std::hint::black_box;

fn cuboid(hi: DVec3) -> stackplan_geom::ConvexPolytope {
    let pts: Vec<DVec3> = (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { 0.0 } else { hi.x },
                if i & 2 == 0 { 0.0 } else { hi.y },
                if i & 4 == 0 { 0.0 } else { hi.z },
            )
        })
        .collect();
    convex_hull(&pts).expect("box").polytope
}

fn bench(c: &mut Criterion) {
    let a = cuboid(DVec3::new(100.0, 50.0, 2.0));
    let b = cuboid(DVec3::new(80.0, 60.0, 2.0));
    let r = DMat3::from_rotation_z(0.3);
    c.bench_function("box_x_box/gauss_map", |bn| bn.iter(|| obstacle(black_box(&a), r, black_box(&b))));
    c.bench_function("box_x_box/exact_hull", |bn| bn.iter(|| obstacle_by_hull(black_box(&a), r, black_box(&b))));
}

criterion_group!(benches, bench);
criterion_main!(benches);
