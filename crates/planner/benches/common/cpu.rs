//! On-CPU time of the whole process, shared by the place bench and the `regress_place` example.

/// CPU time of every thread of the process (ns), from `/proc/self/task/*/schedstat`, where Linux reports it. On a
/// virtual machine whose scheduler accounts by tick the values move in steps of the tick (4 ms at 250 Hz).
pub fn process_cpu_ns() -> Option<u64> {
    let mut total = 0;
    for task in std::fs::read_dir("/proc/self/task").ok()? {
        let stat = std::fs::read_to_string(task.ok()?.path().join("schedstat")).ok()?;
        total += stat.split_whitespace().next()?.parse::<u64>().ok()?;
    }
    Some(total)
}
