//! The PLC task runtime.
//!
//! ```text
//!  attach segment ─► open events + acyclic client ─► loop:
//!     wait "tick done" (timeout = one watchdog step)
//!     CNC closed?  ─► stop (orderly)
//!     CNC heartbeat unchanged for `watchdog_cycles` steps ─► stop (CNC lost)
//!     program.cycle(io) ─► heartbeat += 1 ─► notify "cycle done"
//! ```

use core::time::Duration;
use hli::enums::SegmentState;
use hli::events::{EventError, EventLink, Side};
use hli::rpc::{AcyclicClient, CallError};
use hli::segment::{AttachError, HeartbeatWatch, PeerLiveness, PlcSegment};
use hli::views::PlcView;

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
}

/// What a PLC program sees each cycle.
pub struct PlcIo<'a> {
    /// The PLC's side of the image.
    pub view: PlcView<'a>,
    /// The image itself, for leaves reached by ST path ([`hli::access`]).
    pub memory: &'a hli::ImageMemory,
    /// Acyclic calls to the CNC (use sparingly: each call waits for the CNC's next tick).
    pub acyclic: &'a mut AcyclicClient,
    /// Cycles run so far (0 in the first cycle).
    pub cycle: u64,
}

/// A PLC program: called once per PLC cycle.
pub trait PlcProgram {
    /// One cycle. Must not block.
    fn cycle(&mut self, io: &mut PlcIo<'_>);
    /// A one-line summary printed when the runtime stops.
    fn summary(&self) -> String {
        String::new()
    }
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RunSummary {
    /// Cycles executed.
    pub cycles: u64,
    /// Why the loop ended.
    pub end: RunEnd,
}

/// Why the cyclic loop ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunEnd {
    /// The CNC marked the segment closed.
    CncClosed,
    /// The CNC's heartbeat stopped (crash or hang).
    CncLost,
    /// The cycle limit was reached.
    CycleLimit,
}

/// The runtime over an attached segment.
pub struct PlcRuntime {
    segment: PlcSegment,
    events: EventLink,
    acyclic: AcyclicClient,
    watchdog_cycles: u32,
    wait_step: Duration,
}

impl PlcRuntime {
    /// Attaches to `instance`. `watchdog_cycles` wait steps of `wait_step` without a CNC
    /// heartbeat declare the CNC lost.
    pub fn attach(
        instance: &str,
        watchdog_cycles: u32,
        wait_step: Duration,
    ) -> Result<Self, RuntimeError> {
        let segment = PlcSegment::attach(instance)?;
        let events = EventLink::open(instance, Side::Plc)?;
        let acyclic = AcyclicClient::open(instance)?;
        Ok(Self {
            segment,
            events,
            acyclic,
            watchdog_cycles,
            wait_step,
        })
    }

    /// The attached segment.
    pub fn segment(&self) -> &PlcSegment {
        &self.segment
    }

    /// Runs `program` until the CNC closes or is lost, or `max_cycles` cycles ran.
    pub fn run(
        &mut self,
        program: &mut dyn PlcProgram,
        max_cycles: Option<u64>,
    ) -> Result<RunSummary, RuntimeError> {
        let mut watch = HeartbeatWatch::new(self.watchdog_cycles);
        let mut cycles = 0u64;
        // 0 = "no tick seen yet": a tick the CNC finished before this loop started still gets
        // its cycle (lockstep waits for exactly that cycle).
        let mut last_cnc_beat = 0;
        loop {
            if max_cycles.is_some_and(|max| cycles >= max) {
                return Ok(RunSummary {
                    cycles,
                    end: RunEnd::CycleLimit,
                });
            }
            self.events.wait(self.wait_step)?;
            if self.segment.cnc_state() != Ok(SegmentState::Ready) {
                return Ok(RunSummary {
                    cycles,
                    end: RunEnd::CncClosed,
                });
            }
            let beat = self.segment.cnc_heartbeat();
            if watch.observe(beat) == PeerLiveness::Lost {
                return Ok(RunSummary {
                    cycles,
                    end: RunEnd::CncLost,
                });
            }
            if beat == last_cnc_beat {
                continue; // woken without a new tick (timeout): no cycle
            }
            last_cnc_beat = beat;
            let mut io = PlcIo {
                view: PlcView::new(self.segment.memory()),
                memory: self.segment.memory(),
                acyclic: &mut self.acyclic,
                cycle: cycles,
            };
            program.cycle(&mut io);
            cycles += 1;
            self.segment.beat();
            self.events.notify()?;
        }
    }
}
