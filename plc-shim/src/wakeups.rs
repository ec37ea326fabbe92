//! The PLC task's worst wake-ups, part by part, as the CNC's tick report names its worst
//! ticks: for each, the tick its cycle was due at, how long after that the PLC was woken
//! (the CNC's start lateness and compute, the "tick done" event and the PLC's own wake-up),
//! how long its cycle took from there to "cycle done", and the task slots it missed before.
//!
//! The due time is the CNC's: the tick that wrote heartbeat N was due at the header's
//! `cnc_epoch_ns + N * cnc_cycle_ns` (wall-clock time, which both processes read from the
//! same clock). In lockstep the ticks keep no clock, and nothing is kept. Recording allocates
//! nothing; only the report does.

/// How many wake-ups are kept.
pub const KEPT: usize = 10;

/// One wake-up of the task, in parts.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Wakeup {
    /// The tick the cycle was due at (the CNC's heartbeat; a late PLC woke to a later one,
    /// `missed` task slots on).
    pub tick: u64,
    /// From that tick's due time to the PLC woken, ns.
    pub due_to_woken_ns: u64,
    /// From woken to the cycle done (program, heartbeat, "cycle done" sent), ns.
    pub woken_to_done_ns: u64,
    /// Task slots missed before this cycle (its overruns).
    pub missed: u64,
}

impl Wakeup {
    /// From the tick's due time to the cycle done, ns.
    pub fn total_ns(&self) -> u64 {
        self.due_to_woken_ns.saturating_add(self.woken_to_done_ns)
    }
}

/// The [`KEPT`] wake-ups with the longest time from the tick's due time to the cycle done.
#[derive(Debug, Clone, Default)]
pub struct WorstWakeups {
    kept: [Wakeup; KEPT],
    len: usize,
}

impl WorstWakeups {
    /// Keeps `w` when it is among the worst so far. Does not allocate.
    pub fn record(&mut self, w: Wakeup) {
        if self.len < KEPT {
            self.kept[self.len] = w;
            self.len += 1;
            return;
        }
        let (least, _) = self
            .kept
            .iter()
            .enumerate()
            .min_by_key(|(_, k)| k.total_ns())
            .expect("KEPT > 0");
        if w.total_ns() > self.kept[least].total_ns() {
            self.kept[least] = w;
        }
    }

    /// The kept wake-ups, worst first.
    pub fn worst(&self) -> Vec<Wakeup> {
        let mut v = self.kept[..self.len].to_vec();
        v.sort_by_key(|w| core::cmp::Reverse(w.total_ns()));
        v
    }

    /// One line per kept wake-up, worst first; empty when none was kept (lockstep).
    pub fn render(&self) -> String {
        let mut out = String::new();
        if self.len == 0 {
            return out;
        }
        out.push_str(
            "plc: worst wake-ups (tick: tick due -> PLC woken + woken -> cycle done = total, us):\n",
        );
        for w in self.worst() {
            out.push_str(&format!(
                "plc:   {}: {:.1} + {:.1} = {:.1}{}\n",
                w.tick,
                w.due_to_woken_ns as f64 / 1e3,
                w.woken_to_done_ns as f64 / 1e3,
                w.total_ns() as f64 / 1e3,
                match w.missed {
                    0 => String::new(),
                    1 => ", woke 1 slot late".to_string(),
                    n => format!(", woke {n} slots late"),
                }
            ));
        }
        out
    }
}

/// The part of a wake-up before the PLC woke: from the due time of the tick that wrote
/// heartbeat `tick` (`epoch_ns + tick * cycle_ns`) to `woken_wall_ns`, both wall-clock time;
/// `None` before the CNC announced its epoch (0).
pub fn due_to_woken(epoch_ns: u64, tick: u64, cycle_ns: u64, woken_wall_ns: u64) -> Option<u64> {
    if epoch_ns == 0 {
        return None;
    }
    let due = epoch_ns.saturating_add(tick.saturating_mul(cycle_ns));
    Some(woken_wall_ns.saturating_sub(due))
}

/// The wall-clock time now, ns since the Unix epoch (a vDSO read, no system call).
pub fn wall_now_ns() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn w(tick: u64, before: u64, after: u64) -> Wakeup {
        Wakeup {
            tick,
            due_to_woken_ns: before,
            woken_to_done_ns: after,
            missed: 0,
        }
    }

    #[test]
    fn the_worst_are_kept_worst_first() {
        let mut worst = WorstWakeups::default();
        for tick in 0..100 {
            // Tick 37 is the worst, 80 the second.
            let before = match tick {
                37 => 900_000,
                80 => 500_000,
                t => 10_000 + t,
            };
            worst.record(w(tick, before, 2_000));
        }
        let kept = worst.worst();
        assert_eq!(kept.len(), KEPT);
        assert_eq!((kept[0].tick, kept[1].tick), (37, 80));
        assert!(kept.windows(2).all(|p| p[0].total_ns() >= p[1].total_ns()));
        assert_eq!(kept[2].tick, 99, "then the latest of the steady ones");
        let text = worst.render();
        assert!(text.contains("plc:   37: 900.0 + 2.0 = 902.0\n"), "{text}");
    }

    #[test]
    fn the_due_time_is_the_ticks_and_nothing_before_an_epoch() {
        assert_eq!(due_to_woken(0, 5, 1_000_000, 123), None);
        assert_eq!(
            due_to_woken(1_000, 5, 250_000, 1_000 + 1_250_000 + 40_000),
            Some(40_000)
        );
        assert_eq!(due_to_woken(1_000, 5, 250_000, 0), Some(0), "never below 0");
        assert!(WorstWakeups::default().render().is_empty());
    }
}
