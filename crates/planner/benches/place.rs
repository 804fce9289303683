//! End-to-end placement of the scenarios of \[A\] Figs. 15-17 (Channel and Triangle into a 3-part stack, Complex
//! into a 1-part stack at fixed p_z), 1-degree steps. The stacks are built once, outside the timing.
//!
//! Besides criterion's wall-clock figures the bench prints the **on-CPU** median of each scenario (the CPU time of
//! every thread of the process, from `/proc/self/task/*/schedstat`, over 9 runs): on the shared 2-core machine the
//! wall clock mostly measures the wait for a core.

#![allow(clippy::print_stdout)] // a benchmark program reports its on-CPU medians beside criterion's figures

use criterion::{Criterion, criterion_group, criterion_main};
use stackplan_planner::paper_scenarios::{SCENARIOS, run, scenario};

#[path = "common/cpu.rs"]
mod cpu;
use cpu::process_cpu_ns;

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("place");
    group.sample_size(10);
    for name in SCENARIOS {
        let sc = match scenario(name) {
            Ok(Some(sc)) => sc,
            other => panic!("scenario {name}: {other:?}"),
        };
        group.bench_function(name, |b| b.iter(|| run(&sc).expect("placement")));
        let mut cpu: Vec<f64> = (0..9)
            .filter_map(|_| {
                let before = process_cpu_ns()?;
                run(&sc).expect("placement");
                Some((process_cpu_ns()? - before) as f64 / 1e6)
            })
            .collect();
        cpu.sort_by(f64::total_cmp);
        if let Some(median) = cpu.get(cpu.len() / 2) {
            println!("place/{name}: on-CPU median {median:.1} ms (all threads, {} runs)", cpu.len());
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
