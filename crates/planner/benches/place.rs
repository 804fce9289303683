//! End-to-end placement of the scenarios of [A] Figs. 15-17 (Channel and Triangle into a 3-part stack, Complex
//! into a 1-part stack at fixed p_z), 1-degree steps. The stacks are built once, outside the timing.

use criterion::{Criterion, criterion_group, criterion_main};
use stackplan_planner::regress::{SCENARIOS, run, scenario};

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("place");
    group.sample_size(10);
    for name in SCENARIOS {
        let sc = match scenario(name) {
            Ok(Some(sc)) => sc,
            other => panic!("scenario {name}: {other:?}"),
        };
        group.bench_function(name, |b| b.iter(|| run(&sc).expect("placement")));
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
