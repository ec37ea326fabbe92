//! One channel: runs its program block by block (decoding each block when it is reached, with
//! the variables known then), interpolates the motion, applies coordinate systems, the
//! dynamic CS and the kinematic transformation, and talks to the PLC through its HLI units.
//!
//! Execution model: no look-ahead. A block starts when the previous one has finished, so every
//! `#FLUSH` is satisfied by construction and `SET_ZERO` always happens at standstill. Per tick:
//!
//! 1. PLC inputs of the channel's dynamic-CS unit (enable, `command_w`, `transition_w`), as
//!    the machine read them ([`super::plc_io`]);
//! 2. the interpreter runs blocks until one moves or waits (at most [`BLOCKS_PER_TICK`]);
//! 3. the path block and independent axes advance one tick;
//! 4. pose pipeline: programmed words -> `#CS` frames -> dynamic CS -> inverse kinematics
//!    (with `#TRAFO` on), or per-axis compensation (off);
//! 5. HLI outputs, as values the machine writes: display values, state, `request_r`, the
//!    channel interface, an M-function announcement.
//!
//! One file per job, each with the part of the channel's state it owns: `interpret` the run
//! loop and its waits (`ProgramRun`), `execute` a decoded element
//! (`ProgramValues`), `motion` the path and independent axes with the override
//! (`Motion`), `pose` the pose pipeline with `#CS`, `#TRAFO` and the dynamic CS
//! (`Pose`), `tool` the D record, `plc` the M-function handshake and the outputs
//! (`PlcLink`), `transition` the PLC's dynamic-CS transition, `safety` the guard, the
//! failure latch and the reset (`Safety`).

mod control;
mod error;
mod execute;
mod interpret;
mod joint_caps;
mod motion;
mod plc;
mod plc_frames;
mod pose;
mod safety;
mod tool;
mod transition;

pub use error::{ChannelError, ChannelFault};
pub use safety::{Lag, ResetError};

use control::Control;
use execute::ProgramValues;
use interpret::{ProgramRun, Wait};
use motion::Motion;
use plc::PlcLink;
use pose::Pose;
use safety::Safety;

use super::config::{ChannelConfig, ChannelConfigError};
use super::dyn_cs::{MasterSample, MasterSource, TrackError, TrackSetup, Tracker};
use super::guard::JointGuard;
use super::kin_config::ToolKinematics;
use super::path::contour::{ArcBlock, Contour, Segment};
use super::path::{ArcSpec, AxisLimits, PathMove};
use super::plc_io::{
    hli_value, next_interface, words_in, words_near, ChannelInputs, ChannelOutputs, OverrideInput,
    Wanted,
};
use super::program::LoadedProgram;
use super::sync::SyncBoard;
use crate::axis::generator::{MoveLimits, Progress, SetpointGenerator};
use crate::channel::hli_frame::frame_to_hli;
use crate::nc::arc::ArcMove;
use crate::nc::ast::AxisName;
use crate::nc::decode::{AxisLayout, MotionBlock};
use crate::nc::decode::{SyncIds, TrackSource, Vars, DEFAULT_FILTER_TICKS, KNOWN_VARIABLES};
use crate::nc::interp::{Interpreter, Step};
use crate::nc::{Decoded, DecoderState, MotionMode};
use crate::setpoint::AxisValues;
use hli::enums::{ChannelErrorId, DynCsState, ProgramState};
use hli::layout::{HliCoordState, HliMFunctionAck, HliMFunctionRequest};
use hli::views::{PathOverride, DEFAULT_PATH_OVERRIDE};
use kinematics::frame::offset_frame;
use kinematics::tracking::TrackingOption;
use kinematics::{Joints, Kinematics, PoseWords, RotationOrder};
use nalgebra::Isometry3;
use std::sync::Arc;

/// Most channels of a controller.
pub const MAX_CHANNELS: usize = 12;
/// Blocks without motion the interpreter runs in one tick before it yields (an endless loop of
/// non-moving blocks must not hang the tick).
pub const BLOCKS_PER_TICK: usize = 32;
/// Depth of the `#CS` stack.
pub const CS_DEPTH: usize = 8;

/// What a channel is doing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunState {
    /// No program, or not started.
    Idle,
    /// Executing.
    Running,
    /// Program ended (M30/M2 or its last block).
    Finished,
    /// Stopped by an error (see [`Channel::error`]).
    Error,
}

/// One channel: its identity and run state, and one part per job (see the module's text).
pub struct Channel {
    index: usize,
    config: ChannelConfig,
    /// Channels of the controller (a master beyond them does not exist).
    channels: usize,
    /// The channel's cycle (s).
    cycle_s: f64,
    tick: u64,
    state: RunState,
    error: Option<ChannelError>,
    /// A controlled stop in progress, with the reason the channel will end with.
    stopping: Option<&'static str>,
    run: ProgramRun,
    values: ProgramValues,
    motion: Motion,
    pose: Pose,
    safety: Safety,
    plc: PlcLink,
    control: Control,
}

impl core::fmt::Debug for Channel {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Channel")
            .field("name", &self.config.name)
            .field("state", &self.state)
            .field("line", &self.run.line)
            .finish()
    }
}

impl Channel {
    /// Channel `index` (0-based) of `config`, ticking every `cycle_s` seconds.
    pub fn new(
        index: usize,
        config: ChannelConfig,
        cycle_s: f64,
    ) -> Result<Self, ChannelConfigError> {
        let kinematics = ToolKinematics::new(config.build_kinematics()?);
        let order = config.order()?;
        // Values per slot of the layout: pose slots X..C first, an absent one held at 0.
        let layout = config.layout();
        let mut set_points = AxisValues::zeros(layout.len());
        layout.place(&config.start, &mut set_points);
        let mut joints = [0.0; 6];
        joints.copy_from_slice(&set_points[..6]);
        let mut axis_limits = vec![config.limits; layout.len()];
        for (i, &slot) in layout.slots().iter().enumerate() {
            axis_limits[slot] = config.axis_limits(i);
        }
        let mut channel = Self {
            index,
            channels: MAX_CHANNELS,
            cycle_s,
            tick: 0,
            state: RunState::Idle,
            error: None,
            stopping: None,
            run: ProgramRun::new(&config.axes),
            values: ProgramValues::default(),
            motion: Motion::new(
                config.limits,
                &set_points,
                cycle_s,
                config.interpolator.lookahead as usize,
            ),
            pose: Pose {
                order,
                kinematics,
                trafo: false,
                cs_stack: [Isometry3::identity(); CS_DEPTH],
                cs_len: 0,
                tracker: Tracker::new(config.interpolator.dyn_cs_history_max as usize, order),
                set_points,
                joints,
                pose_in: Isometry3::identity(),
                pose_out: Isometry3::identity(),
                tool: Isometry3::identity(),
                interface_on: false,
                published: None,
                compensation_abc: [0.0; 3],
            },
            safety: Safety {
                guard: JointGuard::new(&set_points, &axis_limits, cycle_s),
                latch_pending: false,
                lag: Default::default(),
                lag_peak: Default::default(),
                lag_floor: None,
            },
            plc: PlcLink {
                inputs: ChannelInputs::default(),
                outputs: ChannelOutputs::default(),
                plc_frame: None,
                frames: Default::default(),
                plc_enabled: false,
                m_next_id: 0,
                m_functions_acked: 0,
            },
            control: Control::new(),
            config,
        };
        // The decoder takes the axes' positions when a program starts (`start`).
        channel.update_pose();
        channel.record_dyn_cs();
        Ok(channel)
    }

    /// Tells the channel how many channels its controller has (masters beyond them do not
    /// exist).
    pub fn set_channel_count(&mut self, channels: usize) {
        self.channels = channels.min(MAX_CHANNELS);
    }

    /// The channel's index (its units in the image).
    pub fn index(&self) -> usize {
        self.index
    }

    /// The configuration.
    pub fn config(&self) -> &ChannelConfig {
        &self.config
    }

    /// Where the channel keeps its axes' values ([`Channel::set_points`] and the others are
    /// per slot of it: pose slots X Y Z A B C first).
    pub fn layout(&self) -> &AxisLayout {
        self.run.decoder.layout()
    }

    /// Run state.
    pub fn state(&self) -> RunState {
        self.state
    }

    /// The error that stopped the channel.
    pub fn error(&self) -> Option<&ChannelError> {
        self.error.as_ref()
    }

    /// One tick on what the PLC gave (`inputs`). `masters` holds what every channel publishes
    /// (this tick for the channels that ticked before, else the last tick).
    pub fn tick(
        &mut self,
        inputs: &ChannelInputs,
        masters: &[Option<MasterSample>; MAX_CHANNELS],
        sync: &mut SyncBoard,
    ) {
        self.tick += 1;
        self.plc.inputs = *inputs;
        self.take_override();
        self.take_command();
        self.plc_inputs();
        if self.state == RunState::Running && self.stopping.is_none() && !self.control.plc_stop {
            self.hold_sync_clock();
            self.interpret(masters, sync);
        }
        self.advance();
        if let Some(line) = self.motion.contour.line() {
            self.run.line = line;
        }
        self.follow_command();
        if let Some(reason) = self.stopping {
            if self.state == RunState::Running && !self.is_moving() {
                self.fail(ChannelFault::MachineStop(reason));
            }
        }
        let master = self.master_sample(masters);
        // The dynamic CS acts on this tick's set-points if it was on before its tick (the
        // last step of a coupling out) or is on after it.
        let tracked_before = self.tracks_set_points();
        self.pose.tracker.tick(master);
        let tracked = tracked_before || self.tracks_set_points();
        self.fail_on_tracking_error();
        self.update_pose();
        self.guard_set_points(tracked);
        self.record_dyn_cs();
        self.motion.rates_apply = !self.pose.trafo && !tracked && !self.safety.guard.latched();
        self.note_dyn_cs_state();
        self.fill_outputs();
        self.fill_control_state();
    }

    fn master_sample(
        &self,
        masters: &[Option<MasterSample>; MAX_CHANNELS],
    ) -> Option<MasterSample> {
        match self.pose.tracker.source()? {
            MasterSource::Plc => self.plc.plc_frame.map(|frame| MasterSample {
                frame,
                live: self.plc.plc_enabled,
            }),
            MasterSource::Channel(c) => masters.get(c).copied().flatten(),
        }
    }
}
