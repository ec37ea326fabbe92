//! Streaming a position file through a FIFO group, as the seed's sample program does
//! (seed 002, chapter 8) in our own code: a step sequence over the FIFO blocks, fed from a
//! file that a reader thread loads into two alternating buffers ([`Feeder`]).
//!
//! ```text
//! Power     MC_Power every axis of the machine (gpAx 0..N: for machines of single axes,
//!           no channels)                                                -> Status
//! Dimension FiFoGetDimension: N and Z; the file must have N columns     -> Done
//! Integrate FiFoGroupIntegrate axis k at position k+1, k = 0..N          -> Done each
//! Fill      FiFoWrite blocks until the FIFO is full or the file is read
//! Override  FiFoSetChannelOverride (when one is given)                  -> Done
//! Start     FiFoStart                                                   -> Done
//! Run       FiFoWrite whenever a quarter of the FIFO is free; the file read and every row
//!           executed (at rest, or held after a file that ends in motion)  ->
//! Stop      FiFoStop                                                    -> Idle
//! Dissolve  FiFoGroupDisintegrate                                       -> Done: Finished
//! ```
//!
//! A block never carries more rows than the FIFO showed free in the image (a refusal as
//! `Full` is still harmless: nothing was queued, the same rows go again). Only one block is
//! on its way at a time, so the rows arrive in the file's order. Any other error ends the
//! sequence in `Failed`.

use crate::blocks::fifo::{
    FifoGetDimension, FifoGroupDisintegrate, FifoGroupIntegrate, FifoSetChannelOverride, FifoStart,
    FifoStop, FifoWrite,
};
use crate::blocks::motion::McPower;
use crate::fifo_file::{Buffer, Fed, Feeder, FileError};
use crate::runtime::{PlcIo, PlcProgram};
use hli::calls::fifo::FifoError;
use hli::calls::fifo::{
    FifoDimensionCall, FifoDisintegrateCall, FifoIntegrateCall, FifoOverrideCall, FifoStartCall,
    FifoStopCall, FIFO_BLOCK_VALUES, FIFO_MAX_DIMENSION,
};
use hli::enums::FifoGroupState;
use hli::layout::{FIFO_FLAG_AT_END, FIFO_FLAG_UNDERRUN};

/// The steps of the sequence.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Step {
    /// MC_Power.
    #[default]
    Power,
    /// FiFoGetDimension.
    Dimension,
    /// FiFoGroupIntegrate, axis by axis.
    Integrate,
    /// First fill.
    Fill,
    /// FiFoSetChannelOverride.
    Override,
    /// FiFoStart.
    Start,
    /// Refilling while the group runs.
    Run,
    /// FiFoStop.
    Stop,
    /// FiFoGroupDisintegrate.
    Dissolve,
    /// The file ran through.
    Finished,
    /// A block or the file failed.
    Failed {
        /// The step it failed in.
        at: u8,
        /// The block's ErrorID (0: the file, see the summary).
        error_id: u32,
    },
}

/// The program.
#[derive(Debug)]
pub struct FifoStream {
    /// Where the sequence stands.
    pub step: Step,
    /// FIFO group.
    pub group: u32,
    /// Override to set before the start, ppm (None: leave it).
    pub override_ppm: Option<u32>,
    /// Rows the CNC accepted.
    pub rows_written: u64,
    /// Blocks the CNC accepted.
    pub blocks: u64,
    /// Blocks refused as Full (sent again).
    pub refused_full: u64,
    /// Most underrun ticks the group reported.
    pub underrun_ticks: u32,
    /// What went wrong with the file.
    pub file_error: Option<FileError>,
    feeder: Feeder,
    dimension: u32,
    capacity: u32,
    next_axis: u32,
    power: Vec<McPower>,
    get_dimension: FifoGetDimension,
    integrate: FifoGroupIntegrate,
    set_override: FifoSetChannelOverride,
    start: FifoStart,
    stop: FifoStop,
    dissolve: FifoGroupDisintegrate,
    write: FifoWrite,
    /// The buffer being drained and the values of it already accepted.
    buffer: Option<Buffer>,
    taken: usize,
    /// Values of the block on its way.
    sending: usize,
    writing: Writing,
    /// FiFoGroupIntegrate's Execute.
    raise: bool,
    file_read: bool,
}

/// FiFoWrite's Execute: high while a block is on its way, low for one cycle after.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Writing {
    Idle,
    Sending,
    Lowering,
}

impl FifoStream {
    /// Streams `path` through FIFO group `group`, its axes `gpAx[0..N]`.
    pub fn new(path: &std::path::Path, group: u32) -> Result<FifoStream, FileError> {
        Ok(FifoStream {
            step: Step::Power,
            group,
            override_ppm: None,
            rows_written: 0,
            blocks: 0,
            refused_full: 0,
            underrun_ticks: 0,
            file_error: None,
            feeder: Feeder::start(path)?,
            dimension: 0,
            capacity: 0,
            next_axis: 0,
            power: (0..FIFO_MAX_DIMENSION)
                .map(|_| McPower::default())
                .collect(),
            get_dimension: FifoGetDimension::default(),
            integrate: FifoGroupIntegrate::default(),
            set_override: FifoSetChannelOverride::default(),
            start: FifoStart::default(),
            stop: FifoStop::default(),
            dissolve: FifoGroupDisintegrate::default(),
            write: FifoWrite::default(),
            buffer: None,
            taken: 0,
            sending: 0,
            writing: Writing::Idle,
            raise: true,
            file_read: false,
        })
    }

    fn fail(&mut self, error_id: u32) {
        let at = match self.step {
            Step::Power => 0,
            Step::Dimension => 1,
            Step::Integrate => 2,
            Step::Fill => 3,
            Step::Override => 4,
            Step::Start => 5,
            Step::Run => 6,
            Step::Stop => 7,
            _ => 8,
        };
        self.step = Step::Failed { at, error_id };
    }

    /// Keeps the FIFO filled: one block at a time, never more rows than are free. Returns
    /// false when the file failed.
    fn feed(&mut self, io: &mut PlcIo<'_>) -> bool {
        let n = self.dimension as usize;
        if self.buffer.is_none() && !self.file_read {
            match self.feeder.try_next() {
                Fed::Rows(b) => {
                    self.buffer = Some(b);
                    self.taken = 0;
                }
                Fed::End => self.file_read = true,
                Fed::NotYet => {}
                Fed::Failed(e) => {
                    self.file_error = Some(e);
                    return false;
                }
            }
        }
        if self.writing == Writing::Idle {
            let free = io
                .view
                .fifo_group(self.group as usize)
                .map_or(0, |s| s.free_r as usize);
            if let Some(b) = &self.buffer {
                let left = (b.len - self.taken) / n;
                let rows = left.min(free).min(FIFO_BLOCK_VALUES / n);
                // Running: blocks of a quarter FIFO at least (fewer calls), unless the buffer's
                // rest. Filling: whatever fits, until the FIFO is full.
                let worth = self.step == Step::Fill
                    || rows >= (self.capacity as usize / 4).max(1)
                    || rows == left;
                if rows > 0 && worth {
                    self.sending = rows * n;
                    self.writing = Writing::Sending;
                }
            }
        }
        let data: &[f64] = match &self.buffer {
            Some(b) => &b.values[self.taken..b.len],
            None => &[],
        };
        let rows = (self.sending / n.max(1)) as u32;
        let execute = self.writing == Writing::Sending;
        let out = self
            .write
            .cycle(io, execute, self.group, data, self.dimension, rows);
        match self.writing {
            // Execute was low for this cycle: the next block may go.
            Writing::Lowering => self.writing = Writing::Idle,
            Writing::Sending if out.done => {
                self.rows_written += u64::from(out.extra.row);
                self.blocks += 1;
                self.taken += self.sending;
                self.sending = 0;
                self.writing = Writing::Lowering;
            }
            Writing::Sending if out.error => {
                self.sending = 0;
                self.writing = Writing::Lowering;
                if out.error_id == FifoError::Full.raw() {
                    self.refused_full += 1;
                } else {
                    self.fail(out.error_id);
                }
            }
            _ => {}
        }
        if let Some(b) = self.buffer.take_if(|b| self.taken >= b.len) {
            self.feeder.give_back(b);
        }
        true
    }

    /// Every row of the file is accepted.
    fn all_written(&self) -> bool {
        self.file_read && self.buffer.is_none() && self.writing == Writing::Idle
    }

    /// The steps before the FIFO is filled: the axes powered, the group's dimension read,
    /// the axes integrated one by one.
    fn set_up(&mut self, io: &mut PlcIo<'_>) {
        let group = self.group;
        match self.step {
            Step::Power => {
                let n = (io.view.axis_count() as u32).min(FIFO_MAX_DIMENSION);
                let mut all = true;
                for axis in 0..n {
                    let p = &mut self.power[axis as usize];
                    p.enable = true;
                    p.call(io, axis);
                    all &= p.status;
                }
                if all {
                    self.step = Step::Dimension;
                }
            }
            Step::Dimension => {
                let out = self
                    .get_dimension
                    .cycle(io, true, group, FifoDimensionCall::default);
                if out.error {
                    self.fail(out.error_id);
                } else if out.done {
                    self.dimension = out.extra.dimension;
                    self.capacity = out.extra.capacity;
                    if self.feeder.columns() != self.dimension as usize {
                        self.fail(FifoError::Columns.raw());
                    } else {
                        self.step = Step::Integrate;
                    }
                }
            }
            Step::Integrate => {
                let axis = self.next_axis;
                let call = || FifoIntegrateCall {
                    axis,
                    group_position: axis + 1,
                };
                let out = self.integrate.cycle(io, self.raise, group, call);
                if !self.raise {
                    // Execute was low for a cycle: the next axis gets its edge.
                    self.raise = true;
                } else if out.error {
                    self.fail(out.error_id);
                } else if out.done {
                    self.raise = false;
                    self.next_axis += 1;
                    if self.next_axis == self.dimension {
                        self.step = Step::Fill;
                    }
                }
            }
            _ => {}
        }
    }
}

impl PlcProgram for FifoStream {
    fn cycle(&mut self, io: &mut PlcIo<'_>) {
        let status = io.view.fifo_group(self.group as usize).ok();
        if let Some(s) = status {
            self.underrun_ticks = self.underrun_ticks.max(s.underrun_ticks_r);
        }
        let group = self.group;
        match self.step {
            Step::Power | Step::Dimension | Step::Integrate => self.set_up(io),
            Step::Fill => {
                if !self.feed(io) {
                    return self.fail(0);
                }
                let full = status.is_some_and(|s| s.free_r == 0);
                let idle = self.writing == Writing::Idle;
                if matches!(self.step, Step::Fill) && idle && (full || self.all_written()) {
                    self.step = match self.override_ppm {
                        Some(_) => Step::Override,
                        None => Step::Start,
                    };
                }
            }
            Step::Override => {
                let ppm = self.override_ppm.unwrap_or(0);
                let out = self
                    .set_override
                    .cycle(io, true, group, || FifoOverrideCall { override_ppm: ppm });
                if out.error {
                    self.fail(out.error_id);
                } else if out.done {
                    self.step = Step::Start;
                }
            }
            Step::Start => {
                let out = self.start.cycle(io, true, group, FifoStartCall::default);
                if out.error {
                    self.fail(out.error_id);
                } else if out.done {
                    self.step = Step::Run;
                }
            }
            Step::Run => {
                if !self.feed(io) {
                    return self.fail(0);
                }
                // Every row executed: at rest (the normal end), or held after the last row
                // of a file that ends in motion (underrun: nothing more will come).
                let ended = status.is_some_and(|s| {
                    s.group_state_r == FifoGroupState::Running.raw()
                        && s.entries_r <= 1
                        && s.flags_r & (FIFO_FLAG_AT_END | FIFO_FLAG_UNDERRUN) != 0
                });
                if matches!(self.step, Step::Run) && self.all_written() && ended {
                    self.step = Step::Stop;
                }
                if status.is_some_and(|s| s.group_state_r == FifoGroupState::Error.raw()) {
                    self.fail(status.map_or(0, |s| s.error_id_r));
                }
            }
            Step::Stop => {
                let out = self.stop.cycle(io, true, group, FifoStopCall::default);
                let idle = status.is_some_and(|s| s.group_state_r == FifoGroupState::Idle.raw());
                if out.error {
                    self.fail(out.error_id);
                } else if out.done && idle {
                    self.step = Step::Dissolve;
                }
            }
            Step::Dissolve => {
                let out = self
                    .dissolve
                    .cycle(io, true, group, FifoDisintegrateCall::default);
                if out.error {
                    self.fail(out.error_id);
                } else if out.done {
                    self.step = Step::Finished;
                }
            }
            Step::Finished | Step::Failed { .. } => {}
        }
    }

    fn summary(&self) -> String {
        format!(
            "fifo-stream: {:?}; {} rows in {} blocks accepted ({} columns, FIFO of {} rows), {} blocks refused as full, {} underrun ticks{}",
            self.step,
            self.rows_written,
            self.blocks,
            self.dimension,
            self.capacity,
            self.refused_full,
            self.underrun_ticks,
            self.file_error
                .as_ref()
                .map_or(String::new(), |e| format!("; file: {e}"))
        )
    }
}
