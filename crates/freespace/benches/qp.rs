//! Benchmarks: time per placement QP (exact active-set vs clarabel, same cells and costs, same run) for cells of
//! 6, 16, 32 and 64 inequalities, and time per emptiness test of a child cell.
//!
//! `exact` is `minimize` (strictly convex costs take the closed-form path of `active_set`), `general` is
//! `qp::minimize_general` (the general active-set method alone, what the closed-form path saves measured in the same
//! run), `clarabel` the interior-point cross-check. The on-CPU part also times
//! w = 1 (singular Hessian: `minimize` runs the general method with the lowest-z tie-break).
//!
//! Run: `cargo bench -p stackplan-freespace --bench qp -- --warm-up-time 1 --measurement-time 3`.
//!
//! Each benchmark runs twice: with criterion's wall clock (`*_wall`) and with the thread's on-CPU time
//! (`*_cpu`, from `/proc/thread-self/schedstat`, nanosecond resolution), because the benchmark machine is shared
//! (2 cores, often busy with other builds): wall-clock medians are inflated by time spent waiting for a core, CPU
//! time is not.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use stackplan_freespace::qp::minimize_general;
use stackplan_freespace::{Cell, Halfspace, SeparableCost, Tag, minimize, minimize_clarabel};
use stackplan_geom::{DVec3, Tolerance};
use std::hint::black_box;

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
    fn unit(&mut self) -> [f64; 3] {
        loop {
            let v = [self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0)];
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if l > 0.2 && l <= 1.0 {
                return v.map(|c| c / l);
            }
        }
    }
}

/// A box of half-size 50 around the origin (6 inequalities) cut by `m - 6` random planes at distance 20..50.
fn cell(rng: &mut Rng, m: usize) -> Cell<3> {
    let mut hs = Vec::new();
    for i in 0..3 {
        let mut n = [0.0; 3];
        n[i] = 1.0;
        hs.push(Halfspace::new(n, 50.0, Tag::User(hs.len() as u64)));
        n[i] = -1.0;
        hs.push(Halfspace::new(n, 50.0, Tag::User(hs.len() as u64)));
    }
    while hs.len() < m {
        let n = rng.unit();
        hs.push(Halfspace::new(n, rng.range(20.0, 50.0), Tag::User(hs.len() as u64)));
    }
    Cell::new(hs, Tolerance::for_scale(200.0)).expect("bounded cell")
}

/// Cost (1) with w = 0.7 and the reference outside the cell, so the optimum is on the boundary.
fn cost(rng: &mut Rng) -> SeparableCost<3> {
    cost_with_weight(rng, 0.7)
}

/// Cost (1) with weight `w` and the reference outside the cell, for a part with the extents x in [-10, 10], y in
/// [-5, 5] and its c.g. 3 above the position: `w [(p_x + 10 - x0)^2 + (p_x - 10 - x0)^2 + (p_y + 5 - y0)^2 +
/// (p_y - 5 - y0)^2] + 4 (1 - w) (p_z + 3 - z0)^2` expanded into `1/2 h p^2 + g p + c`.
fn cost_with_weight(rng: &mut Rng, w: f64) -> SeparableCost<3> {
    let t = rng.range(0.0, std::f64::consts::TAU);
    let reference = DVec3::new(120.0 * t.cos(), 120.0 * t.sin(), rng.range(-80.0, 0.0));
    let (ax, bx) = (10.0 - reference.x, -10.0 - reference.x);
    let (ay, by) = (5.0 - reference.y, -5.0 - reference.y);
    let e = 3.0 - reference.z;
    let h = [4.0 * w, 4.0 * w, 8.0 * (1.0 - w)];
    let g = [2.0 * w * (ax + bx), 2.0 * w * (ay + by), 8.0 * (1.0 - w) * e];
    let c = w * (ax * ax + bx * bx + ay * ay + by * by) + 4.0 * (1.0 - w) * e * e;
    SeparableCost::new(h, g, c).expect("cost")
}

/// On-CPU time of the current thread in nanoseconds (first field of `/proc/thread-self/schedstat`).
fn thread_cpu_ns() -> u64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next().and_then(|x| x.parse().ok()))
        .unwrap_or(0)
}

/// Median on-CPU time per call of `f` (nanoseconds) over 11 batches of about 100 ms each.
///
/// `/proc/thread-self/schedstat` of a running thread advances in scheduler ticks (a few ms), so it cannot time
/// single calls as a criterion measurement; batches of ~100 ms keep the tick error below a few per cent.
fn cpu_median_ns(mut f: impl FnMut()) -> f64 {
    let t0 = thread_cpu_ns();
    let mut calls = 0u64;
    while thread_cpu_ns() - t0 < 20_000_000 {
        f();
        calls += 1;
    }
    let per_batch = (calls * 5).max(1);
    let mut samples: Vec<f64> = (0..11)
        .map(|_| {
            let t = thread_cpu_ns();
            for _ in 0..per_batch {
                f();
            }
            (thread_cpu_ns() - t) as f64 / per_batch as f64
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    samples[5]
}

fn qp(c: &mut Criterion, name: &str) {
    let mut group = c.benchmark_group(format!("qp_{name}"));
    for m in [6usize, 16, 32, 64] {
        let mut rng = Rng(m as u64);
        let cases: Vec<(Cell<3>, SeparableCost<3>)> = (0..32).map(|_| (cell(&mut rng, m), cost(&mut rng))).collect();
        let mut i = 0;
        group.bench_function(BenchmarkId::new("exact", m), |b| {
            b.iter(|| {
                i = (i + 1) % cases.len();
                let (cell, cost) = &cases[i];
                black_box(minimize(black_box(cell), black_box(cost)).expect("exact"))
            })
        });
        let mut i = 0;
        group.bench_function(BenchmarkId::new("general", m), |b| {
            b.iter(|| {
                i = (i + 1) % cases.len();
                let (cell, cost) = &cases[i];
                black_box(minimize_general(black_box(cell), black_box(cost)).expect("general"))
            })
        });
        let mut i = 0;
        group.bench_function(BenchmarkId::new("clarabel", m), |b| {
            b.iter(|| {
                i = (i + 1) % cases.len();
                let (cell, cost) = &cases[i];
                black_box(minimize_clarabel(black_box(cell), black_box(cost)).expect("clarabel"))
            })
        });
    }
    group.finish();
}

/// Emptiness of a child cell as the planner's search builds it: a cell of 32 inequalities, its QP optimum as the
/// known point, and an obstacle-like split (the outside of one random plane through the optimum's neighbourhood plus
/// the inside of three others): `Cell::is_empty_with` (phase 1 from the optimum) against `with_halfspaces` (the
/// Chebyshev LP), same cases.
fn emptiness(c: &mut Criterion, name: &str) {
    let mut group = c.benchmark_group(format!("child_emptiness_{name}"));
    let mut rng = Rng(7);
    let cases: Vec<(Cell<3>, [f64; 3], Vec<Halfspace<3>>)> = (0..32)
        .map(|_| {
            let cell = cell(&mut rng, 32);
            let cost = cost(&mut rng);
            let at = minimize(&cell, &cost).expect("exact").point;
            let mut extra = Vec::new();
            for k in 0..4 {
                let n = rng.unit();
                let d: f64 = (0..3).map(|i| n[i] * at[i]).sum::<f64>() + rng.range(0.5, 20.0);
                let h = Halfspace::new(n, d, Tag::User(100 + k));
                extra.push(if k == 0 { h.flipped(Tag::User(100)) } else { h });
            }
            (cell, at, extra)
        })
        .collect();
    let mut i = 0;
    group.bench_function("phase_one", |b| {
        b.iter(|| {
            i = (i + 1) % cases.len();
            let (cell, at, extra) = &cases[i];
            black_box(cell.is_empty_with(extra.iter().copied(), black_box(at)).expect("phase 1"))
        })
    });
    let mut i = 0;
    group.bench_function("chebyshev", |b| {
        b.iter(|| {
            i = (i + 1) % cases.len();
            let (cell, _, extra) = &cases[i];
            black_box(cell.with_halfspaces(extra.iter().copied()).expect("cell").is_empty())
        })
    });
    // the child built from the known point (`with_halfspaces_from`: both phases 1, no Chebyshev LP)
    let mut i = 0;
    group.bench_function("from_known_point", |b| {
        b.iter(|| {
            i = (i + 1) % cases.len();
            let (cell, at, extra) = &cases[i];
            black_box(cell.with_halfspaces_from(extra, black_box(at)).expect("cell").is_none())
        })
    });
    group.finish();
}

fn wall(c: &mut Criterion) {
    qp(c, "wall");
    emptiness(c, "wall");
}

/// CPU-time medians of the same cases, printed (not a criterion benchmark: see [`cpu_median_ns`]).
#[allow(clippy::print_stdout)]
fn cpu(_c: &mut Criterion) {
    for m in [6usize, 16, 32, 64] {
        let mut rng = Rng(m as u64);
        let cases: Vec<(Cell<3>, SeparableCost<3>)> = (0..32).map(|_| (cell(&mut rng, m), cost(&mut rng))).collect();
        let mut i = 0;
        let exact = cpu_median_ns(|| {
            i = (i + 1) % cases.len();
            black_box(minimize(black_box(&cases[i].0), black_box(&cases[i].1)).expect("exact"));
        });
        let general = cpu_median_ns(|| {
            i = (i + 1) % cases.len();
            black_box(minimize_general(black_box(&cases[i].0), black_box(&cases[i].1)).expect("general"));
        });
        let clarabel = cpu_median_ns(|| {
            i = (i + 1) % cases.len();
            black_box(minimize_clarabel(black_box(&cases[i].0), black_box(&cases[i].1)).expect("clarabel"));
        });
        println!(
            "cpu qp m={m}: exact {exact:.0} ns, general {general:.0} ns, clarabel {clarabel:.0} ns, \
             clarabel/exact {:.0}x, general/exact {:.2}x",
            clarabel / exact,
            general / exact
        );
    }
    // w = 1: singular Hessian (z free), the general method with the lowest-z tie-break
    for m in [6usize, 32] {
        let mut rng = Rng(1000 + m as u64);
        let cases: Vec<(Cell<3>, SeparableCost<3>)> =
            (0..32).map(|_| (cell(&mut rng, m), cost_with_weight(&mut rng, 1.0))).collect();
        let mut i = 0;
        let exact = cpu_median_ns(|| {
            i = (i + 1) % cases.len();
            black_box(minimize(black_box(&cases[i].0), black_box(&cases[i].1)).expect("exact"));
        });
        let clarabel = cpu_median_ns(|| {
            i = (i + 1) % cases.len();
            black_box(minimize_clarabel(black_box(&cases[i].0), black_box(&cases[i].1)).expect("clarabel"));
        });
        println!("cpu qp w=1 m={m}: exact {exact:.0} ns, clarabel {clarabel:.0} ns, ratio {:.0}x", clarabel / exact);
    }
}

criterion_group!(wall_clock, wall, cpu);
criterion_main!(wall_clock);
