//! Where a run's tick time went: every part of the tick with p50, p99 and max, the ticks
//! that overran their cycle, and the worst ticks with their parts, computed after the run from
//! the samples the loop took (nothing of this runs in the tick).

use super::tick_loop::Measured;
use crate::stats::Percentiles;

/// The tick's parts as the loop times them: the four up to "tick done" (the tick's compute
/// time), then the loop's work after it until it sleeps for the next tick (the channels'
/// log stream and program service, the header check, the PLC watch, the signal check),
/// which delays the next tick when it runs long.
pub const PARTS: [&str; 5] = [
    "machine",
    "trace",
    "acyclic calls",
    "tick-done event",
    "after tick done",
];
/// How many of the worst ticks the report keeps.
pub const WORST: usize = 10;

/// One of the worst ticks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WorstTick {
    /// Its number.
    pub tick: u64,
    /// How late it started after its deadline, ns.
    pub late_ns: u64,
    /// Its compute time, ns.
    pub compute_ns: u64,
    /// Its parts ([`PARTS`]), ns.
    pub parts_ns: [u64; 5],
    /// The previous tick's work after "tick done", ns: when it ran long, it is why this tick
    /// started late.
    pub before_ns: u64,
}

impl WorstTick {
    /// When it finished after its deadline, ns (what ranks it).
    pub fn finish_ns(&self) -> u64 {
        self.late_ns + self.compute_ns
    }
}

/// The latency figures of a run.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Latency {
    /// The cycle, ns.
    pub cycle_ns: u64,
    /// Ticks measured.
    pub ticks: u64,
    /// Each part of the tick.
    pub parts: [Percentiles; 5],
    /// Ticks that finished after the next tick's deadline (start lateness + compute > cycle).
    pub overruns: u64,
    /// The worst ticks by finish time after their deadline, worst first.
    pub worst: Vec<WorstTick>,
    /// Real time (lateness means something) or lockstep.
    pub real_time: bool,
}

impl Latency {
    /// The figures of `measured` (before its samples are sorted for other percentiles).
    pub(super) fn of(measured: &Measured, cycle_ns: u64, real_time: bool) -> Latency {
        let n = measured.tick_ns.len();
        let late = |i: usize| {
            if real_time {
                measured.late_ns.get(i).copied().unwrap_or(0)
            } else {
                0
            }
        };
        let tick = |i: usize| WorstTick {
            tick: i as u64,
            late_ns: late(i),
            compute_ns: measured.tick_ns[i],
            parts_ns: core::array::from_fn(|k| measured.stage_ns[k].get(i).copied().unwrap_or(0)),
            before_ns: i
                .checked_sub(1)
                .and_then(|p| measured.stage_ns[4].get(p).copied())
                .unwrap_or(0),
        };
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by_key(|&i| std::cmp::Reverse(tick(i).finish_ns()));
        let worst = order.iter().take(WORST).map(|&i| tick(i)).collect();
        let overruns = (0..n)
            .filter(|&i| real_time && tick(i).finish_ns() > cycle_ns)
            .count() as u64;
        Latency {
            cycle_ns,
            ticks: n as u64,
            parts: core::array::from_fn(|k| Percentiles::of(&mut measured.stage_ns[k].clone())),
            overruns,
            worst,
            real_time,
        }
    }

    /// The share of ticks that overran, percent.
    pub fn overrun_percent(&self) -> f64 {
        if self.ticks == 0 {
            return 0.0;
        }
        100.0 * self.overruns as f64 / self.ticks as f64
    }

    /// The lines of the run's report: the parts, the overruns (a warning above 0.1 %), the
    /// three worst ticks.
    pub fn summary(&self) -> String {
        let mut out = String::from("tick parts p50/p99/max ns:");
        for (name, p) in PARTS.iter().zip(&self.parts) {
            out.push_str(&format!(" {name} {}/{}/{};", p.p50, p.p99, p.max));
        }
        out.pop();
        out.push('\n');
        if self.real_time {
            out.push_str(&format!(
                "ticks that overran their cycle: {} of {} ({:.3} %)\n",
                self.overruns,
                self.ticks,
                self.overrun_percent()
            ));
            if self.overrun_percent() > 0.1 {
                out.push_str(&format!(
                    "warning: more than 0.1 % of ticks overran the {} us cycle: this machine does not hold it (see --latency-report)\n",
                    self.cycle_ns / 1000
                ));
            }
            for w in self.worst.iter().take(3) {
                out.push_str(&format!("worst tick {}\n", render_tick(w)));
            }
        }
        out
    }

    /// The whole report (`--latency-report FILE`): the parts and the ten worst ticks.
    pub fn full(&self) -> String {
        let mut out = format!(
            "# Tick latency\n\ncycle {} us, {} ticks, {}\n\n| part | p50 ns | p99 ns | max ns |\n|---|---:|---:|---:|\n",
            self.cycle_ns / 1000,
            self.ticks,
            if self.real_time { "real time" } else { "lockstep (no lateness)" }
        );
        for (name, p) in PARTS.iter().zip(&self.parts) {
            out.push_str(&format!("| {name} | {} | {} | {} |\n", p.p50, p.p99, p.max));
        }
        out.push_str(&format!(
            "\nticks that overran their cycle: {} ({:.3} %)\n\n## The {} worst ticks (by finish after their deadline)\n\n| tick | late ns | after the previous tick | compute ns | machine | trace | acyclic | event | after this tick |\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
            self.overruns,
            self.overrun_percent(),
            self.worst.len()
        ));
        for w in &self.worst {
            let [m, t, a, e, after] = w.parts_ns;
            out.push_str(&format!(
                "| {} | {} | {} | {} | {m} | {t} | {a} | {e} | {after} |\n",
                w.tick, w.late_ns, w.before_ns, w.compute_ns
            ));
        }
        out
    }
}

fn render_tick(w: &WorstTick) -> String {
    let [m, t, a, e, after] = w.parts_ns;
    format!(
        "{}: late {} ns (the previous tick's work after tick done {} ns), compute {} ns (machine {m}, trace {t}, acyclic {a}, event {e}); after tick done {after} ns",
        w.tick, w.late_ns, w.before_ns, w.compute_ns
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_worst_ticks_rank_by_their_finish_and_overruns_count_past_the_cycle() {
        let mut m = Measured::empty();
        for (late, compute) in [(10, 100), (900, 200), (5, 50), (2_000, 10)] {
            m.tick_ns.push(compute);
            m.late_ns.push(late);
            for (k, s) in m.stage_ns.iter_mut().enumerate() {
                s.push(compute / 4 + k as u64);
            }
        }
        let l = Latency::of(&m, 1_000, true);
        let order: Vec<u64> = l.worst.iter().map(|w| w.tick).collect();
        assert_eq!(order, [3, 1, 0, 2]);
        assert_eq!(l.overruns, 2, "900 + 200 and 2000 + 10 pass 1000");
        assert_eq!(l.parts[0].max, 50);
        assert!(l.summary().contains("warning: more than 0.1 %"));
        assert!(l.full().contains("| 3 | 2000 | 16 | 10 |"), "{}", l.full());
        assert_eq!(
            l.worst[0].before_ns,
            50 / 4 + 4,
            "tick 2's work after tick done"
        );
        let lockstep = Latency::of(&m, 1_000, false);
        assert_eq!(lockstep.overruns, 0);
        assert!(!lockstep.summary().contains("warning"));
    }
}
