//! The convex-pair interference test (`interference::classify_pair`): box x box (two
//! 100 x 50 x 2 plates, the second turned 0.3 rad about z), sheet-metal hexagonal prisms turned about z, and hulls of
//! 20 random points under a general rotation. Besides criterion's wall-clock medians it prints each case's on-CPU
//! median per call (thread CPU time from `/proc/thread-self/schedstat`, 9 batches of at least 50 ms), since on the
//! shared machine the wall clock mostly measures the wait for a core.

#![allow(clippy::print_stdout)] // a benchmark program reports its on-CPU medians beside criterion's figures

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{DMat3, DVec3};
use stackplan_cspace::interference::{PlacedConvex, classify_pair};
use std::hint::black_box;

mod common;
use common::{cuboid, hexagon_prism, random_polytope};

/// CPU time of the calling thread (ns), where Linux reports it.
fn thread_cpu_ns() -> Option<u64> {
    let stat = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    stat.split_whitespace().next()?.parse().ok()
}

/// On-CPU median per call (ns) of `f` over 9 batches, each of at least 50 ms on the CPU (the kernel's accounting
/// can be as coarse as a scheduler tick).
fn on_cpu_median(mut f: impl FnMut()) -> Option<f64> {
    let mut n = 1000usize;
    loop {
        let t0 = thread_cpu_ns()?;
        for _ in 0..n {
            f();
        }
        if thread_cpu_ns()? - t0 >= 50_000_000 {
            break;
        }
        n *= 2;
    }
    let mut per_call = Vec::new();
    for _ in 0..9 {
        let t0 = thread_cpu_ns()?;
        for _ in 0..n {
            f();
        }
        per_call.push((thread_cpu_ns()? - t0) as f64 / n as f64);
    }
    per_call.sort_by(f64::total_cmp);
    Some(per_call[4])
}

fn bench(c: &mut Criterion) {
    let rz = DMat3::from_rotation_z(0.3);
    let tol = 1e-7;
    let plate = cuboid(DVec3::new(100.0, 50.0, 2.0));
    let prism = hexagon_prism(1.0);
    let ra = random_polytope(20, 7);
    let rb = random_polytope(20, 11);
    let general = DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
    let base = PlacedConvex::new(&plate, DMat3::IDENTITY, DVec3::ZERO);
    let prism_base = PlacedConvex::new(&prism, DMat3::IDENTITY, DVec3::ZERO);
    let random_base = PlacedConvex::new(&ra, DMat3::IDENTITY, DVec3::ZERO);
    let cases: Vec<(&str, &PlacedConvex, PlacedConvex)> = vec![
        ("box_penetrating", &base, PlacedConvex::new(&plate, rz, DVec3::new(50.0, 10.0, 1.0))),
        ("box_touching", &base, PlacedConvex::new(&plate, DMat3::IDENTITY, DVec3::new(0.0, 0.0, 2.0))),
        ("box_separated", &base, PlacedConvex::new(&plate, rz, DVec3::new(300.0, 0.0, 0.0))),
        ("prism_penetrating", &prism_base, PlacedConvex::new(&prism, rz, DVec3::new(30.0, 20.0, 1.0))),
        ("prism_touching", &prism_base, PlacedConvex::new(&prism, rz, DVec3::new(30.0, 20.0, 2.0))),
        ("random20_general_penetrating", &random_base, PlacedConvex::new(&rb, general, DVec3::new(40.0, 10.0, 5.0))),
    ];
    let mut g = c.benchmark_group("interference");
    for (name, a, b) in &cases {
        g.bench_function(*name, |bn| bn.iter(|| classify_pair(black_box(a), black_box(b), tol, 0.0)));
    }
    g.finish();
    for (name, a, b) in &cases {
        let median = on_cpu_median(|| {
            black_box(classify_pair(black_box(a), black_box(b), tol, 0.0));
        });
        match median {
            Some(ns) => println!("interference/{name}: on-CPU median {:.3} us per call", ns * 1e-3),
            None => println!("interference/{name}: no thread CPU time on this system"),
        }
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
