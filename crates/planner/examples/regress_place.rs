//! Prints the placement regression scenarios (\[A\] Figs. 15-17) as JSON: `cargo run -p stackplan-planner --example
//! regress_place --release`.
//!
//! For profiling, `regress_place SCENARIO [REPEATS]` builds the one scenario (its stack) and then runs its search
//! `REPEATS` times (default 1), printing the statistics of the last run and the on-CPU time per search (the CPU
//! time of every thread of the process, from `/proc/self/task/*/schedstat`, median over the repeats).

#![allow(clippy::print_stdout)] // an example program prints its results

#[path = "../benches/common/cpu.rs"]
mod cpu;
use cpu::process_cpu_ns;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(name) = args.first() else {
        let value = stackplan_planner::paper_scenarios::regress_place();
        println!("{}", serde_json::to_string_pretty(&value).unwrap_or_default());
        return;
    };
    let repeats: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1).max(1);
    let sc = match stackplan_planner::paper_scenarios::scenario(name) {
        Ok(Some(sc)) => sc,
        other => {
            println!("scenario {name}: {other:?}");
            std::process::exit(2);
        }
    };
    let mut cpu = Vec::new();
    let mut last = None;
    for _ in 0..repeats {
        let before = process_cpu_ns();
        let out = stackplan_planner::paper_scenarios::run(&sc);
        if let (Some(b), Some(a)) = (before, process_cpu_ns()) {
            cpu.push((a - b) as f64 / 1e6);
        }
        last = Some(out);
    }
    match last {
        Some(Ok((_, report))) => println!("{}", serde_json::to_string_pretty(&report).unwrap_or_default()),
        Some(Err(e)) => println!("error: {e}"),
        None => {}
    }
    cpu.sort_by(f64::total_cmp);
    if let Some(median) = cpu.get(cpu.len() / 2) {
        println!("{name}: on-CPU median {median:.2} ms over {} searches (all threads)", cpu.len());
    }
}
