//! The PLC task runtime.
//!
//! ```text
//!  attach segment ─► open events + acyclic client ─► loop:
//!     wait "tick done" (timeout = one CNC cycle, at most the wait step)
//!     CNC-owned header changed?  ─► last cycle (not operational), stop (segment corrupt)
//!     CNC closed?  ─► stop (orderly)
//!     CNC gone, or silent for `watchdog_cycles` of its cycles ([`crate::watchdog`])
//!                  ─► last cycle (not operational), stop (CNC lost)
//!     task due (every `period_ticks` NC ticks)? ─► program.cycle(io), timed
//!     heartbeat += 1 ─► notify "cycle done"
//! ```
//!
//! The last cycle after a loss runs with [`PlcIo::link`] = [`Link::NotOperational`], as a
//! fieldbus master reports a lost slave: the program can see it, and every block of the
//! kernel ([`crate::kernel`]) ends what it was doing with an error.
//!
//! The task runs on the CNC's "tick done" event: every tick (`period_ticks` = 1), or every
//! N-th tick like a PLC task whose cycle is a multiple of the NC cycle. The heartbeat is
//! raised after every tick either way, so a CNC in lockstep (tick N waits for the PLC's
//! N-th heartbeat) runs with any period. Each cycle is timed on CLOCK_MONOTONIC
//! ([`CycleStats`]); an overrun is a task slot the program missed because the CNC had
//! already finished more ticks than the period when the cycle started.

use core::time::Duration;

use hli::calls::CallError;
use hli::enums::SegmentState;
use hli::layout::HliSegmentHeader;
use hli::views::PlcView;
use hli_transport::events::{EventError, EventLink, Side};
use hli_transport::rpc::AcyclicClient;
use hli_transport::segment::{AttachError, HeaderFault, PlcSegment};

use crate::realtime::WakePath;
use crate::wakeups::{Wakeup, WorstWakeups};
pub use crate::watchdog::CncLoss;
use crate::watchdog::CncWatch;

/// With `WakePath::Spin` the PLC wakes this long before a tick is due (at most a quarter of
/// the cycle) and spins until the tick is done: a wake-up up to this late still finds the
/// tick.
const SPIN_LEAD_NS: u64 = 100_000;
/// The spin ends at most this long (or half a cycle) after the tick's due time: a CNC that
/// is late by more is waited for on the futex, so a stalled CNC does not keep a core busy.
const SPIN_PAST_DUE_MAX_NS: u64 = 500_000;

/// Why the runtime could not start or had to stop.
#[derive(Debug, thiserror::Error)]
pub enum RuntimeError {
    /// Attaching to the segment failed.
    #[error("attach: {0}")]
    Attach(#[from] AttachError),
    /// The event services failed.
    #[error("events: {0}")]
    Events(#[from] EventError),
    /// The acyclic service failed.
    #[error("acyclic calls: {0}")]
    Call(#[from] CallError),
    /// The futex wait for a tick was refused.
    #[error("tick wait: {0}")]
    Wait(String),
}

/// What a PLC program sees each cycle.
///
/// `io.view` is the PLC's side of the image; [`PlcIo::gp_ch`] and [`PlcIo::gp_ax`] narrow it
/// to one channel or axis as the seeds write `gpCh[i]^` and `gpAx[i]^`.
pub struct PlcIo<'a> {
    /// The PLC's side of the image.
    pub view: PlcView<'a>,
    /// The image itself, for leaves reached by ST path ([`hli::access`]).
    pub memory: &'a hli::ImageMemory,
    /// Acyclic calls to the CNC (use sparingly: each call waits for the CNC's next tick).
    pub acyclic: &'a mut AcyclicClient,
    /// Cycles run so far (0 in the first cycle).
    pub cycle: u64,
    /// Whether the CNC is there ([`Link::NotOperational`] in the last cycle after a loss).
    pub link: Link,
}

/// The state of the link to the CNC a program sees, like a fieldbus's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Link {
    /// The CNC ticks; the image is live.
    #[default]
    Operational,
    /// The CNC is lost or its segment is corrupted: nothing written reaches a machine, nothing
    /// read is current. The runtime stops after this cycle.
    NotOperational,
}

impl<'a> PlcIo<'a> {
    /// Channel `index` (`gpCh[index]^`), or `None` beyond the configured channels.
    pub fn gp_ch(&self, index: usize) -> Option<hli::views::PlcChannel<'a>> {
        self.view.gp_ch(index)
    }

    /// Axis `index` (`gpAx[index]^`), or `None` beyond the configured axes.
    pub fn gp_ax(&self, index: usize) -> Option<hli::views::PlcAxis<'a>> {
        self.view.gp_ax(index)
    }

    /// The CNC's clock: the ticks it has done times its cycle, in µs (from the segment's
    /// header). A program that waits a time counts on it, not on its own cycles, so it keeps
    /// its meaning at any CNC cycle and PLC task period.
    pub fn cnc_clock_us(&self) -> u64 {
        use hli::layout::image::HliSegmentHeader;
        let at = core::mem::offset_of!(HliSegmentHeader, cnc_cycle_ns);
        let cycle_ns = u64::from(self.memory.place::<u32>(at).load());
        let at = core::mem::offset_of!(HliSegmentHeader, cnc_heartbeat);
        let ticks = self.memory.place::<u64>(at).load();
        ticks.saturating_mul(cycle_ns) / 1000
    }
}

/// More CNC ticks than this between two wake-ups of the PLC are not a late PLC but a
/// heartbeat written over (hours of ticks at the shortest cycle).
const MAX_TICKS_BETWEEN_WAKE_UPS: u64 = 1 << 32;

/// When the task is due, on the CNC's heartbeat: a cycle every `period` ticks, and the slots
/// a late PLC missed counted. Pure arithmetic on the heartbeat, so a heartbeat written over
/// (one that went back, or leapt) can neither wrap the count nor stall the task.
#[derive(Debug, Clone, Copy)]
pub struct TaskSchedule {
    period: u64,
    /// 0 = "no tick seen yet": a tick the CNC finished before the loop started still gets its
    /// cycle (lockstep waits for exactly that cycle).
    last_beat: u64,
    /// The tick at which the task is due next (None: at the next tick seen).
    due: Option<u64>,
    /// The tick the last cycle that ran was due at.
    slot: u64,
}

impl TaskSchedule {
    /// A task every `period` ticks (at least 1).
    pub fn new(period: u64) -> Self {
        Self {
            period: period.max(1),
            last_beat: 0,
            due: None,
            slot: 0,
        }
    }

    /// A wake-up that found heartbeat `beat`: `None` when no new tick came; `Some(None)` when
    /// the task is not due; `Some(Some(missed))` when it runs now, `missed` slots after the
    /// one it was due at.
    pub fn wake(&mut self, beat: u64) -> Option<Option<u64>> {
        if beat == self.last_beat {
            return None;
        }
        // A heartbeat that went back or leapt: the schedule starts over instead of waiting
        // for a slot that never comes, or counting slots that never were.
        if beat < self.last_beat || beat - self.last_beat > MAX_TICKS_BETWEEN_WAKE_UPS {
            self.due = None;
        }
        self.last_beat = beat;
        let slot = self.due.unwrap_or(beat);
        if beat < slot {
            return Some(None);
        }
        self.due = Some(beat.saturating_add(self.period));
        self.slot = slot;
        Some(Some((beat - slot) / self.period))
    }

    /// The tick the cycle that runs now was due at (after a wake-up that runs one).
    pub fn slot(&self) -> u64 {
        self.slot
    }
}

/// Cycle durations up to this many microseconds are kept to the microsecond (longer ones
/// count in the last bucket; the maximum is exact).
const HISTOGRAM_US: usize = 2_000;

/// Timing of the program's cycles, kept without allocating in the cycle.
#[derive(Clone)]
pub struct CycleStats {
    /// Cycles timed.
    pub cycles: u64,
    /// Task slots missed (see the module documentation).
    pub overruns: u64,
    /// Longest cycle, ns.
    pub max_ns: u64,
    /// All cycles together, ns (for the mean, finer than the histogram's 1 us).
    pub total_ns: u64,
    histogram: Box<[u32; HISTOGRAM_US + 1]>,
}

impl Default for CycleStats {
    fn default() -> Self {
        Self {
            cycles: 0,
            overruns: 0,
            max_ns: 0,
            total_ns: 0,
            histogram: Box::new([0; HISTOGRAM_US + 1]),
        }
    }
}

impl core::fmt::Debug for CycleStats {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{self}")
    }
}

impl CycleStats {
    /// Records one cycle of `ns` nanoseconds.
    pub fn record(&mut self, ns: u64) {
        self.cycles += 1;
        self.max_ns = self.max_ns.max(ns);
        self.total_ns = self.total_ns.saturating_add(ns);
        let bucket = ((ns / 1_000) as usize).min(HISTOGRAM_US);
        self.histogram[bucket] = self.histogram[bucket].saturating_add(1);
    }

    /// The duration `q` (0..=1) of the cycles lie under, µs (the bucket's upper edge; the
    /// maximum beyond the histogram).
    pub fn quantile_us(&self, q: f64) -> f64 {
        if self.cycles == 0 {
            return 0.0;
        }
        let want = ((self.cycles as f64) * q.clamp(0.0, 1.0)).ceil().max(1.0) as u64;
        let mut seen = 0u64;
        for (us, n) in self.histogram.iter().enumerate() {
            seen += u64::from(*n);
            if seen >= want {
                return if us == HISTOGRAM_US {
                    self.max_ns as f64 / 1e3
                } else {
                    ((us + 1) as f64).min(self.max_ns as f64 / 1e3)
                };
            }
        }
        self.max_ns as f64 / 1e3
    }
}

impl core::fmt::Display for CycleStats {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "{} cycles, duration p50 {:.0} us p99 {:.0} us max {:.1} us mean {:.2} us, overruns {}",
            self.cycles,
            self.quantile_us(0.5),
            self.quantile_us(0.99),
            self.max_ns as f64 / 1e3,
            self.total_ns as f64 / 1e3 / self.cycles.max(1) as f64,
            self.overruns
        )
    }
}

/// A PLC program: called once per PLC cycle.
pub trait PlcProgram {
    /// One cycle. Must not block.
    fn cycle(&mut self, io: &mut PlcIo<'_>);
    /// A one-line summary printed when the runtime stops.
    fn summary(&self) -> String {
        String::new()
    }
    /// Whether the program stopped itself (a run-time fault of a Structured Text program):
    /// the runtime then ends without another heartbeat, and the CNC handles the PLC as lost
    /// (a controlled stop).
    fn halted(&self) -> bool {
        false
    }
}

/// How a run ended.
#[derive(Debug, Clone)]
pub struct RunSummary {
    /// Why the loop ended.
    pub end: RunEnd,
    /// Cycles executed, their durations and overruns.
    pub stats: CycleStats,
    /// From the wake-up ("tick done" received) to "cycle done" sent, for the cycles that ran
    /// the program: the PLC's whole answer to a tick (its overruns are not counted here).
    pub wake_to_done: CycleStats,
    /// The worst wake-ups, part by part (real time only).
    pub worst: WorstWakeups,
    /// From the due time of the tick a cycle was due at to the PLC woken, for the cycles
    /// that ran the program (real time only).
    pub due_to_woken: CycleStats,
}

impl RunSummary {
    /// Cycles executed.
    pub fn cycles(&self) -> u64 {
        self.stats.cycles
    }
}

/// Why the cyclic loop ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunEnd {
    /// The CNC marked the segment closed.
    CncClosed,
    /// The CNC process is gone or stopped ticking.
    CncLost(CncLoss),
    /// A CNC-owned header field changed (someone wrote where only the CNC writes).
    SegmentCorrupt(HeaderFault),
    /// Another PLC (this pid) claimed the segment: the CNC took a new PLC after it lost this
    /// one (a PLC that was hung and came back). This one stops without another cycle.
    Replaced(u32),
    /// The cycle limit was reached.
    CycleLimit,
    /// A termination signal arrived (see [`hli_transport::signals`]).
    Signal(hli_transport::signals::Termination),
    /// The program stopped itself ([`PlcProgram::halted`]): its summary says why.
    ProgramHalted,
}

/// The runtime over an attached segment.
pub struct PlcRuntime {
    segment: PlcSegment,
    events: EventLink,
    acyclic: AcyclicClient,
    watchdog_cycles: u32,
    wait_step: Duration,
    period_ticks: u64,
    wake: WakePath,
}

impl PlcRuntime {
    /// Attaches to `instance`. `watchdog_cycles` of the CNC's cycles (from the header) without
    /// a heartbeat declare the CNC lost ([`crate::watchdog`]); a wait for a tick lasts one CNC
    /// cycle, at most `wait_step`.
    pub fn attach(
        instance: &str,
        watchdog_cycles: u32,
        wait_step: Duration,
    ) -> Result<Self, RuntimeError> {
        let segment = PlcSegment::attach(instance)?;
        let events = EventLink::open(instance, Side::Plc)?;
        let acyclic = AcyclicClient::open(instance)?;
        let timing = segment.cnc_timing();
        let wait_step = if timing.lockstep {
            wait_step
        } else {
            wait_step.min(timing.cycle())
        };
        Ok(Self {
            segment,
            events,
            acyclic,
            watchdog_cycles,
            wait_step,
            period_ticks: 1,
            wake: WakePath::Event,
        })
    }

    /// Runs the task every `ticks` NC ticks instead of every tick (at least 1).
    pub fn set_period_ticks(&mut self, ticks: u64) {
        self.period_ticks = ticks.max(1);
    }

    /// How the CNC wakes this PLC for a tick (the CNC's own `--rt-wake`; a CNC in lockstep
    /// always uses the event).
    pub fn set_wake(&mut self, wake: WakePath) {
        self.wake = wake;
    }

    /// Sleeps until the CNC's next tick after heartbeat `seen`, at most one wait step: on its
    /// event, or on the low word of its heartbeat (`WakePath::Futex`, in real time; with
    /// `WakePath::Spin` after a timed sleep and a bounded spin on that word).
    fn wait_for_tick(&self, seen: u64) -> Result<(), RuntimeError> {
        let timing = self.segment.cnc_timing();
        if self.wake.on_the_word() && !timing.lockstep {
            let word = hli::image::cnc_heartbeat_word(self.segment.memory());
            if self.wake == WakePath::Spin && self.spin_for_tick(word, seen, timing.cycle_ns) {
                self.events.poll()?;
                return Ok(());
            }
            cnc_os::futex::wait(word, seen as u32, self.wait_step)
                .map_err(|e| RuntimeError::Wait(e.to_string()))?;
            // The CNC's events still arrive (lockstep keeps them): taken without waiting.
            self.events.poll()?;
            return Ok(());
        }
        self.events.wait(self.wait_step)?;
        Ok(())
    }

    /// Sleeps to [`SPIN_LEAD_NS`] (at most a quarter cycle) before the tick after heartbeat
    /// `seen` is due, then spins on the heartbeat's `word` until it changes or half a cycle
    /// (at most [`SPIN_PAST_DUE_MAX_NS`]) has passed after the due time: whether it changed.
    /// Not before the CNC announced its epoch. Two clock reads (vDSO) and one
    /// `clock_nanosleep` per tick besides the spin's reads.
    fn spin_for_tick(
        &self,
        word: &core::sync::atomic::AtomicU32,
        seen: u64,
        cycle_ns: u32,
    ) -> bool {
        use core::sync::atomic::Ordering;
        let at = core::mem::offset_of!(HliSegmentHeader, cnc_epoch_ns);
        let epoch = self.segment.memory().place::<u64>(at).load();
        if epoch == 0 {
            return false;
        }
        let (wall, mono) = (crate::wakeups::wall_now_ns(), cnc_os::monotonic::now());
        let (wake, until) = spin_window(epoch, seen, cycle_ns, wall);
        let to_mono = |t: u64| mono + core::time::Duration::from_nanos(t.saturating_sub(wall));
        cnc_os::monotonic::sleep_until(to_mono(wake));
        let until = to_mono(until);
        let seen = seen as u32;
        loop {
            // Several reads between clock reads: the word is the thing to watch.
            for _ in 0..64 {
                if word.load(Ordering::Acquire) != seen {
                    return true;
                }
                core::hint::spin_loop();
            }
            if cnc_os::monotonic::now() >= until {
                return false;
            }
        }
    }

    /// Leaves the segment: the PLC's pid leaves the header, the event and call services
    /// close. The CNC, which supervises the heartbeat, then sees no PLC.
    pub fn detach(self) {
        drop(self);
    }

    /// The attached segment.
    pub fn segment(&self) -> &PlcSegment {
        &self.segment
    }

    /// Runs `program` until the CNC closes or is lost, a termination signal arrives (when the
    /// caller captured them with [`hli_transport::signals::capture`]), or `max_cycles` cycles ran.
    pub fn run(
        &mut self,
        program: &mut dyn PlcProgram,
        max_cycles: Option<u64>,
    ) -> Result<RunSummary, RuntimeError> {
        let mut watch = CncWatch::new(
            self.segment.cnc_timing(),
            self.watchdog_cycles,
            self.segment.cnc_heartbeat(),
            cnc_os::monotonic::now(),
        );
        // What the run measures, its end set when it ends.
        let mut run = RunSummary {
            end: RunEnd::CycleLimit,
            stats: CycleStats::default(),
            wake_to_done: CycleStats::default(),
            worst: WorstWakeups::default(),
            due_to_woken: CycleStats::default(),
        };
        let end = |end, run: RunSummary| Ok(RunSummary { end, ..run });
        let mut schedule = TaskSchedule::new(self.period_ticks);
        let mut wakeups = 0u64;
        // The heartbeat the loop saw last (0: none yet, so a tick done before it counts).
        let mut seen = 0u64;
        loop {
            if max_cycles.is_some_and(|max| run.stats.cycles >= max) {
                return end(RunEnd::CycleLimit, run);
            }
            // Asking for a signal takes a lock inside iceoryx2: every 64th wake-up, outside
            // the program's cycle (as the CNC's tick loop does).
            wakeups += 1;
            if wakeups.is_multiple_of(64) {
                if let Some(signal) = hli_transport::signals::take() {
                    return end(RunEnd::Signal(signal), run);
                }
            }
            self.wait_for_tick(seen)?;
            let woke = cnc_os::monotonic::now();
            let woke_wall = crate::wakeups::wall_now_ns();
            let beat = self.segment.cnc_heartbeat();
            seen = beat;
            if let Some(ended) = self.supervise(&mut watch, beat) {
                if matches!(ended, RunEnd::CncLost(_) | RunEnd::SegmentCorrupt(_)) {
                    self.last_cycle(program, &mut run.stats);
                }
                return end(ended, run);
            }
            let Some(step) = schedule.wake(beat) else {
                continue; // woken without a new tick (timeout): no cycle
            };
            if let Some(missed) = step {
                run.stats.overruns = run.stats.overruns.saturating_add(missed);
                let mut io = PlcIo {
                    view: PlcView::new(self.segment.memory()),
                    memory: self.segment.memory(),
                    acyclic: &mut self.acyclic,
                    cycle: run.stats.cycles,
                    link: Link::Operational,
                };
                let start = cnc_os::monotonic::now();
                program.cycle(&mut io);
                let took = cnc_os::monotonic::now().saturating_sub(start);
                run.stats.record(took.as_nanos() as u64);
                if program.halted() {
                    // No heartbeat for this tick: the CNC stops as for a lost PLC.
                    return end(RunEnd::ProgramHalted, run);
                }
            }
            self.segment.beat();
            self.events.notify()?;
            if let Some(missed) = step {
                let took = cnc_os::monotonic::now().saturating_sub(woke).as_nanos() as u64;
                run.wake_to_done.record(took);
                if let Some(w) = self.wakeup(schedule.slot(), woke_wall, took, missed) {
                    run.worst.record(w);
                    run.due_to_woken.record(w.due_to_woken_ns);
                }
            }
        }
    }

    /// The wake-up of the cycle due at tick `due`, woken at `woke_wall` (wall clock), its
    /// cycle done `took` ns later, in parts (`missed` task slots late); `None` in lockstep or
    /// before the CNC announced its epoch.
    fn wakeup(&self, due: u64, woke_wall: u64, took: u64, missed: u64) -> Option<Wakeup> {
        let timing = self.segment.cnc_timing();
        if timing.lockstep {
            return None;
        }
        let at = core::mem::offset_of!(HliSegmentHeader, cnc_epoch_ns);
        let epoch = self.segment.memory().place::<u64>(at).load();
        let cycle = u64::from(timing.cycle_ns);
        Some(Wakeup {
            tick: due,
            due_to_woken_ns: crate::wakeups::due_to_woken(epoch, due, cycle, woke_wall)?,
            woken_to_done_ns: took,
            missed,
        })
    }
}

/// When a spinning PLC wakes and when its spin ends (wall clock, ns) for the tick after
/// heartbeat `seen`, from the CNC's `epoch` and cycle, at `wall` now: [`SPIN_LEAD_NS`] (at
/// most a quarter cycle) before the tick is due, and half a cycle (at most
/// [`SPIN_PAST_DUE_MAX_NS`]) after. The epoch comes from the segment: whatever it says, the
/// tick is taken as due within a cycle from now, so the sleep is never longer than that.
fn spin_window(epoch: u64, seen: u64, cycle_ns: u32, wall: u64) -> (u64, u64) {
    let cycle = u64::from(cycle_ns);
    let due = epoch
        .saturating_add(seen.saturating_add(1).saturating_mul(cycle))
        .min(wall.saturating_add(cycle));
    let lead = SPIN_LEAD_NS.min(cycle / 4);
    let past = (cycle / 2).min(SPIN_PAST_DUE_MAX_NS);
    (due.saturating_sub(lead), due.saturating_add(past))
}

impl PlcRuntime {
    /// After a wake-up that found heartbeat `beat`: how the run ends, if it does (a corrupted
    /// header before an orderly close, a close before a silence).
    fn supervise(&self, watch: &mut CncWatch, beat: u64) -> Option<RunEnd> {
        if let Some(pid) = self.segment.replaced_by() {
            return Some(RunEnd::Replaced(pid));
        }
        match self.segment.check_header() {
            Err(fault) => return Some(RunEnd::SegmentCorrupt(fault)),
            Ok(SegmentState::Ready) => {}
            Ok(_) => return Some(RunEnd::CncClosed),
        }
        let now = cnc_os::monotonic::now();
        watch
            .observe(beat, now, || self.segment.cnc_process_alive())
            .err()
            .map(RunEnd::CncLost)
    }

    /// The program's cycle after a loss: [`Link::NotOperational`], not timed as a task cycle
    /// and no heartbeat after it.
    fn last_cycle(&mut self, program: &mut dyn PlcProgram, stats: &mut CycleStats) {
        let mut io = PlcIo {
            view: PlcView::new(self.segment.memory()),
            memory: self.segment.memory(),
            acyclic: &mut self.acyclic,
            cycle: stats.cycles,
            link: Link::NotOperational,
        };
        program.cycle(&mut io);
    }
}

#[cfg(test)]
mod schedule_tests {
    use super::TaskSchedule;

    #[test]
    fn missed_slots_are_counted_and_a_heartbeat_written_over_never_wraps_the_count() {
        let mut s = TaskSchedule::new(1);
        assert_eq!(s.wake(1), Some(Some(0)));
        assert_eq!(s.wake(1), None, "no new tick");
        assert_eq!(s.wake(4), Some(Some(2)), "ticks 2 and 3 missed");
        // Written over: a leap to near the end of the range, then back.
        assert_eq!(s.wake(u64::MAX - 3), Some(Some(0)));
        assert_eq!(s.wake(5), Some(Some(0)));
        assert_eq!(s.wake(u64::MAX), Some(Some(0)));
        assert_eq!(s.wake(u64::MAX - 1), Some(Some(0)));
        let mut every_third = TaskSchedule::new(3);
        let ran: Vec<u64> = (1..=10)
            .filter(|&b| matches!(every_third.wake(b), Some(Some(_))))
            .collect();
        assert_eq!(ran, [1, 4, 7, 10]);
        let mut total = 0u64;
        let mut s = TaskSchedule::new(1);
        for beat in [1, 2, u64::MAX, 3, u64::MAX / 2, 4, 1 << 40, 5] {
            if let Some(Some(missed)) = s.wake(beat) {
                total = total.saturating_add(missed);
            }
        }
        assert_eq!(total, 0, "a corrupted heartbeat adds no overruns");
    }

    /// The slot a cycle was due at, for the wake-ups' parts: late by less than a period it
    /// misses nothing but is still counted from its slot.
    #[test]
    fn the_slot_is_the_tick_the_cycle_was_due_at() {
        let mut s = TaskSchedule::new(4);
        assert_eq!((s.wake(1), s.slot()), (Some(Some(0)), 1));
        assert_eq!(
            (s.wake(7), s.slot()),
            (Some(Some(0)), 5),
            "woken 2 ticks late"
        );
        // The next slot counts from the wake-up (7 + 4): 18 is one slot after it.
        assert_eq!(
            (s.wake(18), s.slot()),
            (Some(Some(1)), 11),
            "one slot missed"
        );
    }
}

#[cfg(test)]
mod spin_tests {
    use super::spin_window;

    #[test]
    fn the_spin_wakes_a_quarter_cycle_early_and_never_sleeps_past_a_cycle() {
        const MS: u64 = 1_000_000;
        // Tick 11 of a 250 us CNC whose epoch is at 1 s, now 1.0027 s: due at 1.00275 s,
        // woken 62.5 us before, spinning up to 125 us after.
        let (wake, until) = spin_window(1_000 * MS, 10, 250_000, 1_002_700_000);
        assert_eq!((wake, until), (1_002_687_500, 1_002_875_000));
        // At 10 ms: 100 us lead, 500 us past due at most.
        let (wake, until) = spin_window(1_000 * MS, 0, 10_000_000, 1_000 * MS);
        assert_eq!((wake, until), (1_009_900_000, 1_010_500_000));
        // A hostile epoch far in the future: the tick is taken as due within a cycle.
        let (wake, until) = spin_window(u64::MAX - 5, 3, 1_000_000, 7 * MS);
        assert_eq!((wake, until), (8 * MS - 100_000, 8 * MS + 500_000));
    }
}
