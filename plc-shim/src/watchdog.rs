//! The PLC's watch over the CNC, in CNC cycles.
//!
//! ```text
//!  wake-up ─ new heartbeat? ─ yes ─► alive (silence starts over)
//!                 │ no
//!                 ├─ silent ≥ 2 cycles and the CNC process is gone ─► lost (dead)
//!                 └─ silent > patience ─────────────────────────────► lost (silent)
//!  patience = limit × the CNC's cycle (from the header); at least 10 s before the first
//!  heartbeat and in lockstep, where ticks follow the PLC and keep no clock.
//! ```
//!
//! Time comes from the caller (the monotonic clock in the runtime), so the rules are tested
//! with made-up instants.

use core::time::Duration;
use hli_transport::segment::CncTiming;

/// Default limit, CNC cycles: a CNC that stopped ticking is noticed within this many cycles
/// of its last tick (plus the one wait in which it is seen).
pub const DEFAULT_WATCHDOG_CYCLES: u32 = 40;

/// The patience before the first heartbeat and in lockstep.
pub const SLOW_PATIENCE: Duration = Duration::from_secs(10);

/// Why the CNC counts as lost.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CncLoss {
    /// Its process is gone.
    Dead {
        /// CNC cycles since its last heartbeat.
        silent_cycles: u64,
    },
    /// Its process runs, but it has not ticked for longer than the patience (hung, stopped).
    Silent {
        /// CNC cycles since its last heartbeat.
        silent_cycles: u64,
    },
}

impl CncLoss {
    /// CNC cycles between its last heartbeat and the verdict.
    pub fn silent_cycles(&self) -> u64 {
        match *self {
            CncLoss::Dead { silent_cycles } | CncLoss::Silent { silent_cycles } => silent_cycles,
        }
    }
}

impl core::fmt::Display for CncLoss {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            CncLoss::Dead { silent_cycles } => write!(
                f,
                "the CNC process is gone (no heartbeat for {silent_cycles} CNC cycles)"
            ),
            CncLoss::Silent { silent_cycles } => write!(
                f,
                "no CNC heartbeat for {silent_cycles} CNC cycles, the process is alive (hung)"
            ),
        }
    }
}

/// See the module documentation.
#[derive(Debug, Clone)]
pub struct CncWatch {
    timing: CncTiming,
    limit: u32,
    beat: u64,
    since: Duration,
    started: bool,
}

impl CncWatch {
    /// A watch over a CNC of `timing` that last beat `beat`, seen at `now`; `limit` cycles
    /// (at least 1) of silence make it lost.
    pub fn new(timing: CncTiming, limit: u32, beat: u64, now: Duration) -> Self {
        Self {
            timing,
            limit: limit.max(1),
            beat,
            since: now,
            started: false,
        }
    }

    /// How long the CNC may stay silent now.
    pub fn patience(&self) -> Duration {
        let cycles = self.timing.cycle() * self.limit;
        if self.timing.lockstep || !self.started {
            cycles.max(SLOW_PATIENCE)
        } else {
            cycles
        }
    }

    /// One wake-up at `now` finding heartbeat `beat`. `alive` (a look at the CNC process) is
    /// asked only once the CNC is at least two cycles late.
    pub fn observe(
        &mut self,
        beat: u64,
        now: Duration,
        alive: impl FnOnce() -> bool,
    ) -> Result<(), CncLoss> {
        if beat != self.beat {
            self.beat = beat;
            self.since = now;
            self.started = true;
            return Ok(());
        }
        let silent = now.saturating_sub(self.since);
        let cycle_ns = u128::from(self.timing.cycle_ns.max(1));
        let silent_cycles = u64::try_from(silent.as_nanos() / cycle_ns).unwrap_or(u64::MAX);
        if silent_cycles >= 2 && !alive() {
            return Err(CncLoss::Dead { silent_cycles });
        }
        if silent > self.patience() {
            return Err(CncLoss::Silent { silent_cycles });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: Duration = Duration::from_millis(1);

    fn watch(lockstep: bool) -> CncWatch {
        let timing = CncTiming {
            cycle_ns: 1_000_000,
            lockstep,
        };
        CncWatch::new(timing, 40, 7, Duration::ZERO)
    }

    #[test]
    fn a_silent_cnc_is_lost_after_the_limit_once_it_ticked() {
        let mut w = watch(false);
        assert_eq!(w.observe(8, MS, || true), Ok(()));
        assert_eq!(w.observe(8, 41 * MS, || true), Ok(()));
        assert_eq!(
            w.observe(8, 42 * MS, || true),
            Err(CncLoss::Silent { silent_cycles: 41 })
        );
        // A tick starts the silence over.
        assert_eq!(w.observe(9, 43 * MS, || true), Ok(()));
        assert_eq!(w.observe(9, 80 * MS, || true), Ok(()));
    }

    #[test]
    fn before_the_first_tick_and_in_lockstep_the_patience_is_long() {
        let mut w = watch(false);
        assert_eq!(w.patience(), SLOW_PATIENCE);
        assert_eq!(w.observe(7, 9_000 * MS, || true), Ok(()));
        assert!(w.observe(7, 10_001 * MS, || true).is_err());
        let mut w = watch(true);
        w.observe(8, MS, || true).unwrap();
        assert_eq!(w.patience(), SLOW_PATIENCE);
        assert_eq!(w.observe(8, 5_000 * MS, || true), Ok(()));
    }

    #[test]
    fn a_dead_cnc_is_lost_two_cycles_after_its_last_tick() {
        let mut w = watch(true);
        w.observe(8, MS, || true).unwrap();
        // Within a cycle of the last tick the process is not even looked at.
        assert_eq!(w.observe(8, 2 * MS, || panic!("asked too early")), Ok(()));
        assert_eq!(
            w.observe(8, 3 * MS, || false),
            Err(CncLoss::Dead { silent_cycles: 2 })
        );
    }

    #[test]
    fn the_loss_names_its_cause() {
        let dead = CncLoss::Dead { silent_cycles: 3 };
        assert_eq!(dead.silent_cycles(), 3);
        assert!(dead.to_string().contains("gone"));
        assert!(CncLoss::Silent { silent_cycles: 41 }
            .to_string()
            .contains("41 CNC cycles"));
    }
}
