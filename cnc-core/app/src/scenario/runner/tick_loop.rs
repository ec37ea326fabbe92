//! The tick loop of `cnc run`: tick N starts at its deadline (real time) or once the PLC ran
//! its cycle after tick N-1 (lockstep); the machine ticks, the trace takes its sample, the
//! acyclic calls are answered and "tick done" goes out; between ticks the PLC and the
//! termination signals are watched, and a stop runs on until the machine is at rest.

use super::cycle_guard::CycleGuard;
use super::restart::{Gap, GapEvent};
use super::{
    describe_plc, wait_for_plc_cycle, PlcLink, PlcWait, RunOptions, StopCause,
    DEFAULT_PLC_WATCHDOG_TICKS, DEFAULT_TICK_LIMIT, STOP_LIMIT_S, STOP_REASON_CYCLE,
    STOP_REASON_PLC, STOP_REASON_SEGMENT, STOP_REASON_SIGNAL,
};
use crate::progress::{Progress, TickCounter};
use crate::scenario::file::Scenario;
use crate::scenario::log_stream::LogStream;
use crate::scenario::machine::Machine;
use crate::scenario::trace::Trace;
use cnc_core::channel::folder::Loader;
use cnc_os::monotonic;
use core::time::Duration;
use hli::views::CncView;
use hli::ImageMemory;
use hli_transport::events::EventLink;
use hli_transport::rpc::AcyclicServer;
use hli_transport::segment::CncSegment;
use plc_shim::realtime::WakePath;
use std::process::Child;

/// How long a run may go: its ticks, the stop's, the PLC watchdog.
pub(super) struct Bounds {
    /// Ticks before the run ends (when no stop came).
    limit: u64,
    /// Ticks a stop may take to bring the machine to rest.
    stop_limit: u64,
    /// Rows of the trace and the timings: room for a stop that starts at the last tick.
    pub(super) rows: usize,
    /// Ticks without a PLC cycle before the PLC counts as lost (at least 1).
    pub(super) watchdog: u64,
    /// The CNC cycle.
    pub(super) period: Duration,
    /// `watchdog` ticks of time.
    watchdog_time: Duration,
}

impl Bounds {
    /// The bounds of `scenario` run with `options`; `Err` when the ticks do not fit.
    pub(super) fn of(scenario: &Scenario, options: &RunOptions) -> Result<Bounds, String> {
        // The default is a time: as many ticks as DEFAULT_TICK_LIMIT of 1 ms last.
        let limit = options
            .ticks
            .or(scenario.ticks)
            .unwrap_or((DEFAULT_TICK_LIMIT as f64 * 1e-3 / scenario.cycle_s).round() as u64);
        let stop_limit = (STOP_LIMIT_S / scenario.cycle_s) as u64;
        // Room for a stop that starts at the last tick.
        let rows = usize::try_from(limit.saturating_add(stop_limit))
            .map_err(|_| "--ticks too large".to_string())?;
        // The default is a time: 100 ticks of 1 ms at any cycle.
        let default = (DEFAULT_PLC_WATCHDOG_TICKS as f64 * 1e-3 / scenario.cycle_s).round() as u64;
        let watchdog = options
            .plc_watchdog_ticks
            .or(scenario.plc_watchdog_ticks)
            .unwrap_or(default)
            .max(1);
        let period = Duration::from_secs_f64(scenario.cycle_s);
        Ok(Bounds {
            limit,
            stop_limit,
            rows,
            watchdog,
            period,
            watchdog_time: period * watchdog.min(u64::from(u32::MAX)) as u32,
        })
    }
}

/// What the loop measures, every buffer sized before the first tick.
pub(super) struct Measured {
    /// The trace.
    pub(super) trace: Trace,
    /// Compute time of each tick, ns.
    pub(super) tick_ns: Vec<u64>,
    /// How late each tick started after its deadline, ns.
    pub(super) late_ns: Vec<u64>,
    /// Where a tick's time goes: machine tick, trace sample, acyclic calls, "tick done"
    /// event, and the loop's work after it ([`super::latency::PARTS`]).
    pub(super) stage_ns: [Vec<u64>; 5],
    /// Acyclic calls answered.
    pub(super) acyclic_answered: u64,
}

impl Measured {
    /// No trace and no samples (tests of what is computed from them).
    #[cfg(test)]
    pub(super) fn empty() -> Measured {
        Measured {
            trace: Trace::new(&[], 0),
            tick_ns: Vec::new(),
            late_ns: Vec::new(),
            stage_ns: Default::default(),
            acyclic_answered: 0,
        }
    }

    /// Room for `rows` ticks of `scenario`'s trace signals and timings.
    pub(super) fn new(scenario: &Scenario, rows: usize) -> Measured {
        Measured {
            trace: Trace::new(&scenario.signals, rows),
            tick_ns: Vec::with_capacity(rows),
            late_ns: Vec::with_capacity(rows),
            stage_ns: core::array::from_fn(|_| Vec::with_capacity(rows)),
            acyclic_answered: 0,
        }
    }

    /// One tick's timings: `t` are the instants before the machine tick, the trace sample,
    /// the acyclic calls and the event, after the event, and after the loop's work that
    /// follows it.
    fn push(&mut self, t: [Duration; 6], deadline: Duration) {
        let [t0, t1, t2, t3, t4, t5] = t;
        self.tick_ns.push((t4 - t0).as_nanos() as u64);
        for (stage, (a, b)) in
            self.stage_ns
                .iter_mut()
                .zip([(t0, t1), (t1, t2), (t2, t3), (t3, t4), (t4, t5)])
        {
            stage.push((b - a).as_nanos() as u64);
        }
        self.late_ns
            .push(t0.saturating_sub(deadline).as_nanos() as u64);
    }
}

/// How the loop ended.
pub(super) struct Ending {
    /// Why the run stopped early, and the tick the stop began.
    pub(super) stop: Option<(StopCause, u64)>,
    /// A second termination request ended the stop at once.
    pub(super) forced: bool,
    /// Ticks from the stop until the machine was at rest.
    pub(super) rest_after: Option<u64>,
    /// `--plc-restart`: PLC processes lost (killed if they still ran), to be reaped.
    pub(super) lost_plcs: Vec<Child>,
    /// `--plc-restart`: new PLCs that took over.
    pub(super) restarts: u64,
    /// `--plc-restart`: the run ended while no PLC ran.
    pub(super) without_plc: bool,
}

/// The loop's state over a run.
pub(super) struct TickLoop<'a> {
    scenario: &'a Scenario,
    options: &'a RunOptions,
    machine: &'a mut Machine,
    segment: &'a CncSegment,
    events: &'a EventLink,
    server: &'a AcyclicServer,
    child: &'a mut Option<Child>,
    bounds: &'a Bounds,
    measured: Measured,
    /// When tick 0 was due.
    start: Duration,
    /// The PLC heartbeat last seen to change, and when (wall clock: a CNC that stalled and
    /// catches up in a burst must not take the PLC for dead).
    plc_seen: (u64, Duration),
    /// Whether a PLC is expected to cycle (one was spawned, or took over after a loss).
    supervised: bool,
    /// `--plc-restart`: where the run is between two PLCs.
    gap: Gap,
    ending: Ending,
    log_stream: Option<LogStream>,
    counter: TickCounter,
    progress: Option<Progress>,
    /// Real time: programs the PLC selects are loaded on this thread, never between two
    /// ticks (lockstep loads them in place: its ticks wait for nothing else anyway).
    loader: Option<Loader>,
    /// The lateness figures the header shows tools.
    gauge: LatenessGauge,
    /// Real time: whether the ticks' work still fits the cycle.
    guard: CycleGuard,
    /// Real time with `--rt-wake futex` or `spin`: "tick done" wakes the PLC on the
    /// heartbeat's low word instead of the event.
    wake_futex: bool,
}

impl<'a> TickLoop<'a> {
    /// The loop of `machine` with the PLC of `link`; tick 0 is due now.
    pub(super) fn new(
        scenario: &'a Scenario,
        options: &'a RunOptions,
        machine: &'a mut Machine,
        link: &'a mut PlcLink,
        bounds: &'a Bounds,
        measured: Measured,
    ) -> TickLoop<'a> {
        let PlcLink {
            segment,
            events,
            server,
            child,
        } = link;
        // Ticks announced while the PLC started count as heartbeats already written.
        machine.start_heartbeat_at(segment.beats());
        let supervised = child.is_some();
        let log_stream = options
            .log_dir
            .as_ref()
            .map(|dir| LogStream::start(dir, machine.controller().channels().len()));
        let counter = TickCounter::default();
        let progress = Progress::start(
            &counter,
            options.ticks.or(scenario.ticks),
            &options.instance,
        );
        // Without a thread (the system refused one) programs load in place, between ticks.
        let loader = (!options.lockstep).then(|| Loader::spawn().ok()).flatten();
        // Tick 0 is due once everything above is set up (threads started, files opened), so
        // its lateness is the loop's, not the set-up's.
        let start = monotonic::now();
        publish_epoch(segment, segment.beats(), bounds.period);
        let plc_seen = (segment.plc_heartbeat(), monotonic::now());
        TickLoop {
            scenario,
            options,
            machine,
            segment,
            events,
            server,
            child,
            bounds,
            measured,
            start,
            plc_seen,
            supervised,
            gap: Gap::Closed,
            ending: Ending {
                stop: None,
                forced: false,
                rest_after: None,
                lost_plcs: Vec::new(),
                restarts: 0,
                without_plc: false,
            },
            log_stream,
            counter,
            progress,
            loader,
            gauge: LatenessGauge::new(),
            guard: CycleGuard::new(bounds.period.as_nanos() as u64),
            wake_futex: !options.lockstep
                && super::spawn::cnc_realtime(scenario, options)
                    .wake
                    .is_some_and(WakePath::on_the_word),
        }
    }

    /// "Tick done" to the PLC: its event, or a wake on the heartbeat's low word.
    fn tick_done(&self) {
        if self.wake_futex {
            let _ = cnc_os::futex::wake(hli::image::cnc_heartbeat_word(self.segment.memory()), 1);
        } else {
            let _ = self.events.notify();
        }
    }

    /// Ticks until the run ends; what it measured and how it ended.
    pub(super) fn run(mut self) -> (Measured, Ending) {
        let memory = self.segment.memory();
        let view = CncView::new(memory);
        for tick in 0.. {
            if self.ends_before(tick) {
                break;
            }
            let deadline = self.start + self.bounds.period * (tick as u32);
            self.pace(tick, deadline);
            let [t0, t1, t2, t3, t4] = self.step(tick, memory, &view);
            // Supervision, between ticks: the PLC's heartbeat (real time; lockstep waits on
            // it before the tick), its process now and then, and termination requests.
            if self.ending.stop.is_none() {
                self.check_header(tick);
            }
            if self.ending.stop.is_none() && !self.options.lockstep {
                if self.gap.open() {
                    self.mind_gap(tick);
                } else {
                    self.watch_plc(tick);
                }
            }
            let end_now = tick % 16 == 0 && self.take_signal(tick);
            let t5 = monotonic::now();
            self.measured.push([t0, t1, t2, t3, t4, t5], deadline);
            if !self.options.lockstep {
                self.gauge
                    .record(t0.saturating_sub(deadline), tick, self.segment);
                self.keep_cycle(tick, (t5 - t0).as_nanos() as u64);
            }
            if end_now {
                break;
            }
        }
        self.ending.without_plc = self.gap.open();
        if !self.options.lockstep {
            // Closed before the threads are joined: the PLC must not take the wait for a
            // silent CNC. (Lockstep: the PLC runs its last cycle first, see `PlcLink::close`.)
            self.segment.mark_closed();
        }
        drop(self.progress);
        if let Some(Err(e)) = self.log_stream.map(LogStream::finish) {
            eprintln!("cnc run: LOG_FILE while running: {e}");
        }
        (self.measured, self.ending)
    }

    /// Whether the run ends before `tick`: its ticks are done (or, without a tick count,
    /// every channel is idle), or a stop brought the machine to rest or ran out of time.
    fn ends_before(&mut self, tick: u64) -> bool {
        match &self.ending.stop {
            Some((_, since)) if self.machine.at_rest() => {
                self.ending.rest_after = Some(tick - since);
                true
            }
            Some((_, since)) if tick - since > self.bounds.stop_limit => true,
            Some(_) => false,
            // --plc-restart: a stop after a lost PLC runs to rest (or its limit) as any stop.
            None if self.gap_braking(tick) => false,
            None if tick >= self.bounds.limit => true,
            None if self.options.ticks.is_none()
                && self.scenario.ticks.is_none()
                && !self.options.plc_restart
                && self.machine.idle() =>
            {
                true
            }
            None => false,
        }
    }

    /// Whether the stop after a lost PLC (`--plc-restart`) still brakes at `tick`; once its
    /// limit runs out without rest, says so once and lets the run end.
    fn gap_braking(&self, tick: u64) -> bool {
        let Gap::Lost { since, .. } = self.gap else {
            return false;
        };
        if self.machine.at_rest() {
            return false;
        }
        if tick - since <= self.bounds.stop_limit {
            return true;
        }
        if tick - since == self.bounds.stop_limit + 1 {
            eprintln!("cnc run: machine NOT at rest when the stop limit ran out (PLC lost at tick {since})");
        }
        false
    }

    /// Waits for tick `tick`: lockstep for the PLC's cycle after the last tick (while the
    /// PLC is not lost), real time until `deadline`.
    fn pace(&mut self, tick: u64, deadline: Duration) {
        let plc_alive = self.ending.stop.is_none() && self.child.is_some();
        if self.options.lockstep && plc_alive {
            if let Some(child) = self.child.as_mut() {
                let (watchdog, period) = (self.bounds.watchdog, self.bounds.period);
                match wait_for_plc_cycle(self.segment, self.events, child, tick, watchdog, period) {
                    Ok(()) => {}
                    Err(PlcWait::Lost(detail)) => self.lose_plc(tick, detail),
                }
            }
        } else if !self.options.lockstep {
            monotonic::sleep_until(deadline);
        }
    }

    /// Tick `tick`: the machine, the trace sample, the acyclic calls, "tick done", the
    /// switching log handed on; the instants before each part and after the event.
    fn step(&mut self, tick: u64, memory: &ImageMemory, view: &CncView<'_>) -> [Duration; 5] {
        let t0 = monotonic::now();
        self.machine.tick(memory);
        let t1 = monotonic::now();
        let time = if self.options.lockstep {
            tick as f64 * self.scenario.cycle_s
        } else {
            (t0 - self.start).as_secs_f64()
        };
        self.measured.trace.record(memory, tick, time);
        let t2 = monotonic::now();
        self.measured.acyclic_answered += self
            .server
            .poll(|kind, request| self.machine.dispatch(view, kind, request))
            .unwrap_or(0) as u64;
        self.measured.acyclic_answered += self
            .server
            .poll_rows(|_, header, values| self.machine.dispatch_bulk(header, values))
            .unwrap_or(0) as u64;
        let t3 = monotonic::now();
        self.tick_done();
        let t4 = monotonic::now();
        if let Some(stream) = self.log_stream.as_mut() {
            stream.forward(self.machine.controller().channels());
        }
        // Program loading and starting for the channels' control units: after "tick done",
        // outside the measured tick; in real time the loading itself on the loader's thread.
        match &self.loader {
            Some(loader) => self.machine.serve_channels_with(loader),
            None => self.machine.serve_channels(),
        };
        self.counter.set(tick + 1);
        [t0, t1, t2, t3, t4]
    }

    /// Real time, after tick `tick`: a PLC whose heartbeat stood still for the watchdog's
    /// time, or whose process exited (looked at every 64 ticks), is lost.
    fn watch_plc(&mut self, tick: u64) {
        if !self.supervised {
            return;
        }
        let beat = self.segment.plc_heartbeat();
        let now = monotonic::now();
        if beat != self.plc_seen.0 {
            self.plc_seen = (beat, now);
        }
        let exited = match self.child.as_mut() {
            Some(child) if tick.is_multiple_of(64) => child.try_wait().ok().flatten(),
            _ => None,
        };
        let silent = now.saturating_sub(self.plc_seen.1);
        if exited.is_some() || silent > self.bounds.watchdog_time {
            let silent_ticks = (silent.as_secs_f64() / self.scenario.cycle_s) as u64;
            let detail = match self.child.as_mut() {
                Some(child) => describe_plc(child, exited, silent_ticks),
                // A PLC that took over after a loss is not this process's child.
                None => format!("no PLC cycle for {silent_ticks} ticks"),
            };
            self.lose_plc(tick, detail);
        }
    }

    /// After tick `tick`: the CNC-owned header must be as the CNC wrote it; a changed field
    /// stops the machine (the PLC sees the same change and stops on its side).
    fn check_header(&mut self, tick: u64) {
        if let Err(fault) = self.segment.check_header(self.machine.heartbeat()) {
            let cause = StopCause::SegmentCorrupt { tick, fault };
            eprintln!("cnc run: {}", cause.message());
            self.machine.stop(STOP_REASON_SEGMENT);
            self.ending.stop = Some((cause, tick));
        }
    }

    /// Real time, after tick `tick` whose work took `work_ns`: once the last ticks' mean
    /// work reached the cycle, the machine stops (the loop could never catch up).
    fn keep_cycle(&mut self, tick: u64, work_ns: u64) {
        let Some(work_ns) = self.guard.record(work_ns) else {
            return;
        };
        if self.ending.stop.is_some() {
            return;
        }
        let cycle_ns = self.bounds.period.as_nanos() as u64;
        let cause = StopCause::CycleTooShort {
            tick,
            work_ns,
            cycle_ns,
        };
        eprintln!("cnc run: {}", cause.message());
        self.machine.stop(STOP_REASON_CYCLE);
        self.ending.stop = Some((cause, tick));
    }

    /// The PLC is lost at `tick`: the machine stops. With `--plc-restart` the run goes on
    /// and waits for a new PLC ([`Gap`]); a PLC process of its own is killed (it may be hung)
    /// and reaped after the run.
    fn lose_plc(&mut self, tick: u64, detail: String) {
        if self.options.plc_restart && !self.options.lockstep {
            eprintln!(
                "cnc run: PLC lost at tick {tick}: {detail}; stopping the machine and waiting for a new PLC on instance {}",
                self.options.instance
            );
            self.machine.stop(STOP_REASON_PLC);
            if let Some(mut child) = self.child.take() {
                let _ = child.kill();
                self.ending.lost_plcs.push(child);
            }
            let pid = self
                .segment
                .header()
                .field::<u32>(core::mem::offset_of!(
                    hli::layout::HliSegmentHeader,
                    plc_pid
                ))
                .load_acquire();
            self.gap = Gap::Lost { pid, since: tick };
            self.supervised = false;
            return;
        }
        let cause = StopCause::PlcLost { tick, detail };
        eprintln!("cnc run: {}", cause.message());
        self.machine.stop(STOP_REASON_PLC);
        self.ending.stop = Some((cause, tick));
    }

    /// `--plc-restart`, after tick `tick` while no PLC runs: the gap's next step, said.
    fn mind_gap(&mut self, tick: u64) {
        let instance = &self.options.instance;
        let drives = self.scenario.plc_loss_drives;
        match self.gap.step(tick, self.machine, self.segment, drives) {
            GapEvent::None => {}
            GapEvent::Waiting { cleared, disabled } => eprintln!(
                "cnc run: machine at rest at tick {tick}; {cleared} PLC leaves cleared{}; waiting for a new PLC on instance {instance}",
                if disabled { "; drives disabled" } else { "" }
            ),
            GapEvent::Attached { pid } => {
                eprintln!("cnc run: PLC process {pid} attached at tick {tick}; machine re-armed")
            }
            GapEvent::Running { pid } => {
                self.ending.restarts += 1;
                self.supervised = true;
                self.plc_seen = (self.segment.plc_heartbeat(), monotonic::now());
                eprintln!("cnc run: PLC process {pid} runs its cycles since tick {tick}");
            }
            GapEvent::Lost { pid } => {
                self.machine.stop(STOP_REASON_PLC);
                eprintln!(
                    "cnc run: PLC process {pid} left or did not cycle at tick {tick}; stopping the machine, waiting for a new PLC"
                );
            }
        }
    }

    /// A termination request at `tick` stops the machine; a second one during the stop ends
    /// the run at once (true: end now).
    fn take_signal(&mut self, tick: u64) -> bool {
        let Some(signal) = hli_transport::signals::take() else {
            return false;
        };
        if self.ending.stop.is_some() {
            // A request during a stop: end now (the segment is still removed and the PLC
            // still reaped after the loop); the first cause stays the reported one.
            eprintln!("cnc run: {} during the stop: ending at once", signal.name());
            self.ending.forced = true;
            return true;
        }
        let cause = StopCause::Signal { tick, signal };
        eprintln!("cnc run: {}", cause.message());
        self.machine.stop(STOP_REASON_SIGNAL);
        self.ending.stop = Some((cause, tick));
        false
    }
}

/// Announces in the header when the tick that writes heartbeat `beats + 1` (the loop's tick
/// 0, due now) was due, as wall-clock time: tools date the values of heartbeat N by it.
fn publish_epoch(segment: &CncSegment, beats: u64, period: Duration) {
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap_or_default();
    let back = period.saturating_mul(u32::try_from(beats + 1).unwrap_or(u32::MAX));
    segment.publish_epoch(now.saturating_sub(back).as_nanos() as u64);
}

/// Ticks between two refreshes of the header's lateness figures.
const GAUGE_EVERY: u64 = 1024;
/// Width of a lateness bucket, ns.
const GAUGE_BUCKET_NS: u64 = 1_000;
/// Buckets: 1 us each up to 8 ms; later ticks count in the last.
const GAUGE_BUCKETS: usize = 8_192;

/// The ticks' start lateness as a histogram of fixed size (allocated before the first
/// tick): p99 and max published in the header every [`GAUGE_EVERY`] ticks.
struct LatenessGauge {
    buckets: Box<[u32]>,
    count: u64,
    max_ns: u64,
}

impl LatenessGauge {
    fn new() -> LatenessGauge {
        LatenessGauge {
            buckets: vec![0; GAUGE_BUCKETS].into_boxed_slice(),
            count: 0,
            max_ns: 0,
        }
    }

    /// Counts one tick's lateness; every [`GAUGE_EVERY`] ticks publishes the figures.
    fn record(&mut self, late: Duration, tick: u64, segment: &CncSegment) {
        let ns = late.as_nanos() as u64;
        let bucket = ((ns / GAUGE_BUCKET_NS) as usize).min(GAUGE_BUCKETS - 1);
        self.buckets[bucket] = self.buckets[bucket].saturating_add(1);
        self.count += 1;
        self.max_ns = self.max_ns.max(ns);
        if tick % GAUGE_EVERY == GAUGE_EVERY - 1 {
            segment.publish_lateness(self.p99_ns(), self.max_ns);
        }
    }

    /// The upper edge of the bucket that holds the 99th percentile, ns (at most the max).
    fn p99_ns(&self) -> u64 {
        let rank = self.count - self.count / 100;
        let mut seen = 0u64;
        for (k, n) in self.buckets.iter().enumerate() {
            seen += u64::from(*n);
            if seen >= rank {
                return ((k as u64 + 1) * GAUGE_BUCKET_NS).min(self.max_ns);
            }
        }
        self.max_ns
    }
}

#[cfg(test)]
mod gauge_tests {
    use super::*;

    #[test]
    fn the_gauges_p99_is_the_bucket_edge_of_the_99th_tick_of_100_and_at_most_the_max() {
        let mut g = LatenessGauge::new();
        for k in 0..100u64 {
            let ns = if k == 99 { 900_000 } else { k * 1_000 + 500 };
            let bucket = ((ns / GAUGE_BUCKET_NS) as usize).min(GAUGE_BUCKETS - 1);
            g.buckets[bucket] += 1;
            g.count += 1;
            g.max_ns = g.max_ns.max(ns);
        }
        assert_eq!(
            g.p99_ns(),
            99_000,
            "the 99th sample, 98.5 us, lies in [98, 99) us"
        );
        g.max_ns = 50_000;
        assert_eq!(g.p99_ns(), 50_000);
    }
}
