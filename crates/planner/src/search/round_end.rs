//! The end of a round of the partitioned search: a partition that finishes its round first waits, spinning, for
//! the others still running it, so that both threads leave the round together and the next round finds them awake.
//!
//! Why: a round ([`crate::search`], "Rounds and determinism") is one `rayon` parallel loop over the partitions, and
//! its length is set by the slowest partition (a partition stops at its placement, at the bound or after its pops).
//! The rayon worker that finished first otherwise goes idle, yields a few times and sleeps on a futex; the next
//! round (a few microseconds of merging later) must then wake it, and on a virtual machine a wake-up takes tens to
//! hundreds of microseconds. The 15-part Complex plans run about 400-650 rounds, so those wake-ups would cost
//! several percent of the plan. Spinning until the round ends costs the CPU time the waiting thread would have slept
//! through, at most [`SPIN_LIMIT`] per round.
//!
//! Safety of the wait: a partition waits only for partitions *running* their round (started, not finished), and a
//! running partition is on another thread (this thread is inside its own, finished step; the steps call no parallel
//! code, so no other partition's step can run nested under it). A partition not started yet (one thread: rayon runs
//! the loop's items one after the other) is not waited for. The spin is bounded by [`SPIN_LIMIT`] anyway. Nothing
//! of the search's results depends on it: each round's work is fixed at its start.
//!
//! Cost: O(partitions) per check, at most [`SPIN_LIMIT`] of waiting per round: a few hundred spins, then
//! `yield_now` (the thread stays awake but gives its core to a runnable thread, such as the partition it waits for
//! when the machine has fewer free cores than rayon has threads).

use std::sync::atomic::{AtomicU8, Ordering};
use std::time::{Duration, Instant};

/// The longest a finished partition spins for the others (then it returns to rayon's own idle loop).
pub const SPIN_LIMIT: Duration = Duration::from_millis(2);

/// Spins before the wait starts yielding.
const PURE_SPINS: u32 = 256;

const IDLE: u8 = 0;
const RUNNING: u8 = 1;
const DONE: u8 = 2;

/// The phase of each partition in one round.
#[derive(Debug)]
pub struct RoundEnd {
    phases: Vec<AtomicU8>,
}

impl RoundEnd {
    /// A round of `partitions` partitions, none started.
    pub fn new(partitions: usize) -> Self {
        Self { phases: (0..partitions).map(|_| AtomicU8::new(IDLE)).collect() }
    }

    /// Partition `i` starts its round.
    pub fn start(&self, i: usize) {
        if let Some(phase) = self.phases.get(i) {
            phase.store(RUNNING, Ordering::Release);
        }
    }

    /// Partition `i` has finished its round: waits while another partition is running its round, at most
    /// [`SPIN_LIMIT`]. Returns whether the wait ended because no partition was running any more.
    pub fn finish(&self, i: usize) -> bool {
        if let Some(phase) = self.phases.get(i) {
            phase.store(DONE, Ordering::Release);
        }
        let started = Instant::now();
        let mut spins: u32 = 0;
        loop {
            if !self.phases.iter().any(|p| p.load(Ordering::Acquire) == RUNNING) {
                return true;
            }
            // a short spin, then yields: with more threads than free cores (a loaded machine, `--threads` above the
            // core count) the running partition may need this core, and a yield gives it; an idle core returns
            // from the yield at once, still awake
            if spins < PURE_SPINS {
                std::hint::spin_loop();
            } else {
                std::thread::yield_now();
            }
            spins = spins.wrapping_add(1);
            // the clock read costs more than a spin: every 64th
            if spins.is_multiple_of(64) && started.elapsed() >= SPIN_LIMIT {
                return false;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    #[test]
    fn partitions_not_started_or_finished_are_not_waited_for() {
        let round = RoundEnd::new(3);
        round.start(0);
        round.start(1);
        // partition 1 finishes while 0 runs: it spins up to the limit, then gives up
        let waited = Instant::now();
        assert!(!round.finish(1));
        assert!(waited.elapsed() >= SPIN_LIMIT);
        // partition 0 finishes: 1 is done and 2 never started (one thread runs the items in turn), nobody runs
        assert!(round.finish(0));
    }

    #[test]
    fn the_last_partition_to_finish_finds_nobody_running() {
        let round = Arc::new(RoundEnd::new(2));
        round.start(0);
        round.start(1);
        let other = Arc::clone(&round);
        let handle = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_micros(200));
            other.finish(1)
        });
        // partition 0 spins for 1 (returning when 1 finishes, or after the limit); 1 finishes last and finds no one
        // running
        let _ = round.finish(0);
        assert!(handle.join().expect("thread"));
        assert!(round.phases.iter().all(|p| p.load(Ordering::Acquire) == DONE));
    }

    #[test]
    fn out_of_range_partitions_are_ignored() {
        let round = RoundEnd::new(1);
        round.start(5);
        assert!(round.finish(5));
    }
}
