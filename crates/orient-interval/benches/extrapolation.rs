//! Extrapolation vs construction per call on the example parts' component pairs (\[A\] Table I: extrapolation ~12% of
//! construction), and the sweep counters over 1-degree steps (intervals per turn, extrapolations per construction).

use criterion::{Criterion, criterion_group, criterion_main};
use stackplan_cspace::minkowski::obstacle;
use stackplan_geom::sheet_metal::Decomposition;
use stackplan_geom::{ConvexPolytope, DMat3, DVec3, examples};
use stackplan_orient_interval::{ExtrapolatedGeometry, ObstacleStructure, PairEvents, PairSweep, rotation_z};
use std::hint::black_box;

/// Component pairs: (name, moving, fixed placed beside/over it).
fn pairs() -> Vec<(String, ConvexPolytope, ConvexPolytope)> {
    let mut out = Vec::new();
    for name in ["channel", "triangle", "complex", "l-corner"] {
        let part = examples::part_by_name(name, Decomposition::Triangulation).expect("example");
        let c = &part.components();
        let (a, b) = (c[0].clone(), c[c.len() / 2].transformed(DMat3::from_rotation_z(0.3), DVec3::new(5.0, 3.0, 2.0)));
        out.push((name.to_string(), a, b));
    }
    out
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("orient_interval");
    for (name, a, b) in pairs() {
        let events = PairEvents::new(&a, &b);
        let t0 = 0.2;
        let s = ObstacleStructure::build(&a, &b, t0, &events).expect("structure");
        let t = t0 + 0.5 * (s.interval().end - t0).min(0.1);
        group.bench_function(format!("{name}/construction"), |bench| {
            bench.iter(|| obstacle(black_box(&a), rotation_z(black_box(t)), black_box(&b)).expect("obstacle"))
        });
        group.bench_function(format!("{name}/extrapolate_obstacle"), |bench| {
            bench.iter(|| s.extrapolate(black_box(&a), black_box(&b), black_box(t)).expect("inside"))
        });
        let mut geometry = ExtrapolatedGeometry::default();
        group.bench_function(format!("{name}/extrapolate_geometry"), |bench| {
            bench.iter(|| {
                s.extrapolate_geometry(black_box(&a), black_box(&b), black_box(t), &mut geometry).expect("inside")
            })
        });
        group.bench_function(format!("{name}/pair_events"), |bench| {
            bench.iter(|| PairEvents::new(black_box(&a), black_box(&b)))
        });
        group.bench_function(format!("{name}/sweep_360"), |bench| {
            bench.iter(|| {
                let mut sw = PairSweep::one_degree(a.clone(), b.clone());
                for k in 0..360 {
                    black_box(sw.obstacle_at(k));
                }
                sw.stats()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
