//! Hull benchmark: the exact Quickhull of stackplan-geom beside parry3d-f64's `try_convex_hull` on the same points.
//!
//! * `box_differences_64`: the 8 x 8 differences of two boxes (a c-space obstacle), full of exactly coplanar
//!   clusters;
//! * `random_400`: 400 uniformly random points in a cube;
//! * `disc_prism_800`: a 400-gon disc of radius 500 extruded 0.5 thick (sheet metal), where parry's hull is wrong
//!   (it drops one face; see `tests/hull_props.rs`), timed for completeness;
//! * `turned_disc_prism_800`: the same disc turned by a general rotation, so that its two 400-gons and side faces are
//!   planar only to rounding (`stackplan-merged` merges the exact hull's creased facets back into them).
//!
//! `stackplan-merged/*` is `convex_hull_merged` (the hull the part readers build: the exact hull, then its facets in
//! one plane within the length tolerance joined) on the same points.

use criterion::{Criterion, criterion_group, criterion_main};
use stackplan_geom::{DMat3, DVec3, convex_hull, convex_hull_merged};
use std::hint::black_box;

fn box_vertices(lo: DVec3, hi: DVec3) -> Vec<DVec3> {
    (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        })
        .collect()
}

fn random_points(n: usize, mut seed: u64) -> Vec<DVec3> {
    let mut next = move || {
        seed = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = seed;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64 * 200.0 - 100.0
    };
    (0..n).map(|_| DVec3::new(next(), next(), next())).collect()
}

fn bench(c: &mut Criterion) {
    let a = box_vertices(DVec3::ZERO, DVec3::new(40.0, 20.0, 2.0));
    let b = box_vertices(DVec3::new(-5.0, -5.0, 0.0), DVec3::new(60.0, 30.0, 2.0));
    let diffs: Vec<DVec3> = b.iter().flat_map(|vb| a.iter().map(move |va| *vb - *va)).collect();
    let random = random_points(400, 7);
    let disc: Vec<DVec3> = (0..400)
        .flat_map(|i| {
            let a = i as f64 * std::f64::consts::TAU / 400.0;
            let (x, y) = (500.0 * a.cos(), 500.0 * a.sin());
            [DVec3::new(x, y, 0.0), DVec3::new(x, y, 0.5)]
        })
        .collect();
    let turn = DMat3::from_euler(glam::EulerRot::ZYX, 0.3, 0.7, 1.1);
    let turned_disc: Vec<DVec3> = disc.iter().map(|&p| turn * p + DVec3::new(12.5, -7.0, 300.0)).collect();
    let mut g = c.benchmark_group("hull");
    for (name, pts) in [
        ("box_differences_64", &diffs),
        ("random_400", &random),
        ("disc_prism_800", &disc),
        ("turned_disc_prism_800", &turned_disc),
    ] {
        g.bench_function(format!("stackplan/{name}"), |bch| bch.iter(|| convex_hull(black_box(pts))));
        g.bench_function(format!("stackplan-merged/{name}"), |bch| bch.iter(|| convex_hull_merged(black_box(pts))));
        g.bench_function(format!("parry/{name}"), |bch| {
            bch.iter(|| parry3d_f64::transformation::try_convex_hull(black_box(pts)))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
