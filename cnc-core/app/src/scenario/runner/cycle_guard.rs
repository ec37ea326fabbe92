//! Whether the machine keeps its cycle in real time: a `--cycle-ms` below what the machine's
//! ticks need cannot be known before its ticks run (their work depends on the programs, the
//! tracking and the engines in use), so the loop watches the work of its last
//! [`WINDOW`] ticks (the machine's tick and the loop's work after it, until it sleeps); once
//! their mean reaches the cycle, the loop can no longer catch up with its deadlines and the
//! machine is stopped in the controlled way, naming the cycle and the work. A single tick
//! that runs long (a program loaded in place, an OS stall of any length) does not stop it:
//! each tick counts at most two cycles' work, and the mean over 64 ticks must reach one.
//! Fixed size, nothing allocated in the tick.

/// Ticks whose mean work is compared with the cycle.
pub(super) const WINDOW: usize = 64;

/// The last [`WINDOW`] ticks' work against the cycle.
pub(super) struct CycleGuard {
    /// Each tick's work as measured, and as counted (at most two cycles).
    work_ns: [(u64, u64); WINDOW],
    /// The window's sums of both.
    sum_ns: (u64, u64),
    seen: u64,
    cycle_ns: u64,
}

impl CycleGuard {
    /// A guard for a cycle of `cycle_ns`.
    pub(super) fn new(cycle_ns: u64) -> CycleGuard {
        CycleGuard {
            work_ns: [(0, 0); WINDOW],
            sum_ns: (0, 0),
            seen: 0,
            cycle_ns: cycle_ns.clamp(1, u64::MAX / 4),
        }
    }

    /// Counts one tick's work (ns; at most two cycles of it count): once the mean of what
    /// the last [`WINDOW`] ticks count reached the cycle (with a full window), their mean
    /// work as measured; `None` while the machine keeps its cycle.
    pub(super) fn record(&mut self, work_ns: u64) -> Option<u64> {
        let counted = work_ns.min(2 * self.cycle_ns);
        let slot = (self.seen % WINDOW as u64) as usize;
        let (old_work, old_counted) = self.work_ns[slot];
        self.sum_ns = (
            self.sum_ns
                .0
                .saturating_sub(old_work)
                .saturating_add(work_ns),
            self.sum_ns.1 - old_counted + counted,
        );
        self.work_ns[slot] = (work_ns, counted);
        self.seen += 1;
        let full = self.seen >= WINDOW as u64;
        (full && self.sum_ns.1 / WINDOW as u64 >= self.cycle_ns)
            .then_some(self.sum_ns.0 / WINDOW as u64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mean_below_the_cycle_and_single_long_ticks_keep_the_machine_running() {
        let mut g = CycleGuard::new(250_000);
        for k in 0..10_000u64 {
            // 200 us of work, and every 100th tick a stall (10 ms, or 10 s).
            let work = match k % 1000 {
                999 => 10_000_000_000,
                k if k % 100 == 99 => 10_000_000,
                _ => 200_000,
            };
            assert_eq!(g.record(work), None, "tick {k}");
        }
    }

    #[test]
    fn a_mean_at_the_cycle_stops_once_the_window_is_full() {
        let mut g = CycleGuard::new(250_000);
        for k in 0..WINDOW as u64 - 1 {
            assert_eq!(g.record(300_000), None, "tick {k}: the window is not full");
        }
        assert_eq!(g.record(300_000), Some(300_000));
        // Ticks of ten cycles count as two (and are said as they were).
        let mut g = CycleGuard::new(250_000);
        let stopped = (0..WINDOW).find_map(|_| g.record(2_500_000));
        assert_eq!(stopped, Some(2_500_000));
        // After running below the cycle, the old ticks leave the window one by one.
        let mut g = CycleGuard::new(250_000);
        for _ in 0..1000 {
            assert_eq!(g.record(100_000), None);
        }
        let stopped_after = (1..=WINDOW).find(|_| g.record(400_000).is_some());
        // 100 * (64 - n) + 400 * n >= 250 * 64 once n >= 32.
        assert_eq!(stopped_after, Some(32));
    }
}
