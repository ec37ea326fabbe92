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

mod execute;
mod pose;
mod safety;
mod tool;
mod transition;

pub use safety::ResetError;

use super::config::{ChannelConfig, ChannelConfigError};
use super::dyn_cs::{words, MasterSample, MasterSource, TrackError, TrackSetup, Tracker};
use super::guard::JointGuard;
use super::kin_config::ToolKinematics;
use super::path::{ArcSpec, AxisLimits, PathMove};
use super::plc_io::{
    hli_value, next_interface, words_in, ChannelInputs, ChannelOutputs, OverrideInput, Wanted,
};
use super::program::LoadedProgram;
use super::sync::SyncBoard;
use crate::axis::generator::{MoveLimits, Progress, SetpointGenerator};
use crate::nc::decode::{SyncIds, TrackSource, Vars, DEFAULT_FILTER_TICKS, KNOWN_VARIABLES};
use crate::nc::interp::{Interpreter, Step};
use crate::nc::{Decoded, DecoderState, MotionMode};
use crate::setpoint::AxisValues;
use hli::enums::{ChannelErrorId, DynCsState, ProgramState};
use hli::layout::{HliCoordState, HliMFunctionAck, HliMFunctionRequest};
use hli::views::{PathOverride, DEFAULT_PATH_OVERRIDE};
use kinematics::frame::{frame_to_hli, offset_frame};
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

/// What the interpreter waits for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Wait {
    /// The PLC's acknowledge of M function `code` announced with `id`.
    MFunction { code: u32, id: u32 },
    /// The announcement of `code` could not be posted yet (the previous one is unread).
    MAnnounce { code: u32 },
    /// `#WAIT SYN` for the ids in `wait_ids`.
    Sync,
    /// `#TRACK CS ... WAIT`.
    Tracking,
    /// `#WAIT INDP ALL` or an `INDP_SYN` move.
    Independent,
    /// `G04` / `#TIME`: until the channel's tick counter reaches this.
    Dwell { until: u64 },
}

/// Why a channel stopped: the block and the reason.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChannelError {
    /// Source line of the block.
    pub line: u32,
    /// The kind of cause, as `error_id_r` reports it.
    pub id: ChannelErrorId,
    /// What went wrong.
    pub message: String,
}

/// The variables a block sees when it is decoded.
struct ChannelVars {
    track_cs: [f64; 6],
}

impl Vars for ChannelVars {
    fn get(&self, name: &str) -> Option<f64> {
        KNOWN_VARIABLES
            .iter()
            .position(|v| *v == name)
            .map(|i| self.track_cs[i])
    }
}

/// One channel.
pub struct Channel {
    index: usize,
    config: ChannelConfig,
    limits: AxisLimits,
    order: RotationOrder,
    /// The configured kinematics with the selected tool record on its flange.
    kinematics: ToolKinematics,
    program: Option<LoadedProgram>,
    decoder: DecoderState,
    /// Follows the program's control flow and calls.
    interp: Interpreter,
    line: u32,
    pending: Vec<Decoded>,
    pending_at: usize,
    state: RunState,
    wait: Option<Wait>,
    wait_ids: SyncIds,
    /// The last `#TRACK CS ON [LOG_FILE=..]` of the program.
    log_file: Option<Arc<str>>,
    error: Option<ChannelError>,
    /// Programmed position (channel coordinates, after offsets).
    programmed: AxisValues,
    path: Option<PathMove>,
    /// Runs the path parameter of every block (one generator, re-targeted: no allocation).
    path_generator: SetpointGenerator,
    /// Per axis: its generator for independent moves and whether one is under way.
    independent: Vec<(SetpointGenerator, bool)>,
    /// A controlled stop in progress, with the reason the channel will end with.
    stopping: Option<&'static str>,
    trafo: bool,
    cs_stack: [Isometry3<f64>; CS_DEPTH],
    cs_len: usize,
    tracker: Tracker,
    /// Channels of the controller (a master beyond them does not exist).
    channels: usize,
    /// Checks the set-points while tracking and brakes the axes when the channel fails.
    guard: JointGuard,
    /// The channel failed this tick: the guard latches at the end of it.
    latch_pending: bool,
    /// The PLC's override and feed hold in effect (its last valid value).
    path_override: PathOverride,
    /// Override values out of range the PLC wrote (each tick one is read, counted once).
    override_refused: u64,
    interface_on: bool,
    /// Set-points of the channel's axes (joints first under a transformation).
    set_points: AxisValues,
    joints: Joints,
    /// Tool pose before and after the dynamic CS (base coordinates).
    pose_in: Isometry3<f64>,
    pose_out: Isometry3<f64>,
    /// Tool pose of the set-points (forward kinematics, once per tick).
    tool: Isometry3<f64>,
    published: Option<MasterSample>,
    plc_frame: Option<Isometry3<f64>>,
    plc_enabled: bool,
    m_next_id: u32,
    m_functions_acked: u64,
    /// NC blocks the interpreter handed on (each block once, loops counted per pass).
    blocks_executed: u64,
    tick: u64,
    /// The channel's cycle (s).
    cycle_s: f64,
    /// `S..`: the spindle speed M03/M04 turn at.
    spindle_speed: f64,
    /// `T..`: the tool number last programmed.
    tool_number: u32,
    /// `#MSG`: the last message and how many there were.
    message: Option<Arc<str>>,
    messages: u64,
    /// What the PLC gave this tick (copied in at the start of the tick).
    inputs: ChannelInputs,
    outputs: ChannelOutputs,
}

impl core::fmt::Debug for Channel {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Channel")
            .field("name", &self.config.name)
            .field("state", &self.state)
            .field("line", &self.line)
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
        let n = config.axes.len();
        let mut set_points = AxisValues::zeros(n);
        set_points[..config.start.len()].copy_from_slice(&config.start);
        let mut joints = [0.0; 6];
        joints.copy_from_slice(&set_points[..6]);
        let decoder = DecoderState::new(&config.axes);
        let axis_limits: Vec<_> = (0..n).map(|i| config.axis_limits(i)).collect();
        let guard = JointGuard::new(&set_points, &axis_limits, cycle_s);
        let mut channel = Self {
            index,
            limits: config.limits,
            order,
            kinematics,
            program: None,
            decoder,
            interp: Interpreter::new(),
            line: 0,
            pending: Vec::with_capacity(16),
            pending_at: 0,
            state: RunState::Idle,
            wait: None,
            wait_ids: SyncIds::default(),
            log_file: None,
            error: None,
            programmed: set_points,
            path: None,
            path_generator: SetpointGenerator::new(cycle_s, 0.0),
            stopping: None,
            independent: (0..n)
                .map(|_| (SetpointGenerator::new(cycle_s, 0.0), false))
                .collect(),
            trafo: false,
            cs_stack: [Isometry3::identity(); CS_DEPTH],
            cs_len: 0,
            tracker: Tracker::new(config.interpolator.dyn_cs_history_max as usize, order),
            channels: MAX_CHANNELS,
            guard,
            latch_pending: false,
            path_override: DEFAULT_PATH_OVERRIDE,
            override_refused: 0,
            interface_on: false,
            set_points,
            joints,
            pose_in: Isometry3::identity(),
            pose_out: Isometry3::identity(),
            tool: Isometry3::identity(),
            published: None,
            plc_frame: None,
            plc_enabled: false,
            m_next_id: 0,
            m_functions_acked: 0,
            blocks_executed: 0,
            tick: 0,
            cycle_s,
            spindle_speed: 0.0,
            tool_number: 0,
            message: None,
            messages: 0,
            inputs: ChannelInputs::default(),
            outputs: ChannelOutputs::default(),
            config,
        };
        // The decoder takes the axes' positions when a program starts (`start`).
        channel.update_pose();
        Ok(channel)
    }

    /// `S..` last programmed (1/min).
    pub fn spindle_speed(&self) -> f64 {
        self.spindle_speed
    }

    /// `T..` last programmed.
    pub fn tool_number(&self) -> u32 {
        self.tool_number
    }

    /// The last `#MSG` text and how many messages the program gave.
    pub fn message(&self) -> (Option<&str>, u64) {
        (self.message.as_deref(), self.messages)
    }

    /// Loads `program` and starts it (a checked program; see [`LoadedProgram::load`]).
    /// A channel that failed is reset first (see [`Channel::reset`]): it starts again from
    /// where its axes came to rest, and is refused while they still move or track.
    pub fn start(&mut self, program: LoadedProgram) -> Result<(), ResetError> {
        if self.state == RunState::Error {
            self.reset()?;
        }
        // A new program starts from the modal defaults the check assumed (G90 G17 G71 G53 D0,
        // no feed), where the axes stand.
        self.decoder = DecoderState::new(&self.config.axes);
        for (i, p) in self.programmed.iter().enumerate() {
            self.decoder.set_position(i, *p);
        }
        self.decoder.configure(&program.setup);
        self.interp.start(&program.set);
        self.program = Some(program);
        self.pending.clear();
        self.pending_at = 0;
        self.state = RunState::Running;
        self.wait = None;
        self.error = None;
        if self.config.provide_channel_interface.track_cs {
            self.interface_on = true;
        }
        self.tracker.restart();
        Ok(())
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

    /// Run state.
    pub fn state(&self) -> RunState {
        self.state
    }

    /// The error that stopped the channel.
    pub fn error(&self) -> Option<&ChannelError> {
        self.error.as_ref()
    }

    /// Line of the block executing.
    pub fn line(&self) -> u32 {
        self.line
    }

    /// Set-points of the channel's axes.
    pub fn set_points(&self) -> &AxisValues {
        &self.set_points
    }

    /// Programmed position (channel coordinates).
    pub fn programmed(&self) -> &AxisValues {
        &self.programmed
    }

    /// Tool pose commanded (after the dynamic CS), base coordinates.
    pub fn pose_out(&self) -> &Isometry3<f64> {
        &self.pose_out
    }

    /// Tool pose before the dynamic CS.
    pub fn pose_in(&self) -> &Isometry3<f64> {
        &self.pose_in
    }

    /// The tool pose of the current set-points by forward kinematics.
    pub fn tool_pose(&self) -> Isometry3<f64> {
        self.tool
    }

    /// The tool pose that the given actual axis positions (channel order) realise.
    pub fn realised_tool(&self, actual: &[f64]) -> Option<Isometry3<f64>> {
        let mut j = [0.0; 6];
        let n = actual.len().min(6);
        j[..n].copy_from_slice(&actual[..n]);
        self.kinematics.forward(&j).ok()
    }

    /// M functions the PLC acknowledged (completed handshakes).
    pub fn m_functions_acked(&self) -> u64 {
        self.m_functions_acked
    }

    /// NC blocks run so far (a block in a loop counts once per pass).
    pub fn blocks_executed(&self) -> u64 {
        self.blocks_executed
    }

    /// The file the program asked the dynamic-CS diagnosis to be written to
    /// (`#TRACK CS ON [LOG_FILE=..]`; the last one named).
    pub fn log_file(&self) -> Option<&str> {
        self.log_file.as_deref()
    }

    /// [`Self::log_file`] as the shared name (cloned without allocating).
    pub fn log_file_name(&self) -> Option<&Arc<str>> {
        self.log_file.as_ref()
    }

    /// The PLC's override and feed hold in effect.
    pub fn path_override(&self) -> PathOverride {
        self.path_override
    }

    /// Ticks in which the PLC's override unit held a value out of range (the last valid value
    /// stayed in effect).
    pub fn override_refused_count(&self) -> u64 {
        self.override_refused
    }

    /// The tracker.
    pub fn tracker(&self) -> &Tracker {
        &self.tracker
    }

    /// What this channel publishes on its interface this tick.
    pub fn published(&self) -> Option<MasterSample> {
        self.published
    }

    /// Whether the channel follows another channel's interface (it must tick after it).
    pub fn follows_channel(&self) -> Option<usize> {
        match self.tracker.source() {
            Some(MasterSource::Channel(c)) => Some(c),
            _ => None,
        }
    }

    /// Whether a motion or wait is in progress.
    pub fn is_moving(&self) -> bool {
        self.path.is_some()
            || self.independent.iter().any(|(_, active)| *active)
            || self.guard.braking()
    }

    /// A controlled stop (supervision, signals): the path brakes along its block with the
    /// channel's acceleration and jerk, independent axes brake, no further block starts; at
    /// rest the channel ends in ERROR with `reason`. A tracking slave's tracking goes to ERROR
    /// and the guard brakes each axis on its own limits instead (the compensation may be
    /// moving). Does not allocate until the channel is at rest.
    pub fn stop(&mut self, reason: &'static str) {
        if self.stopping.is_some() {
            return;
        }
        let (dec, jerk) = (self.limits.acceleration, self.limits.jerk);
        if let Some(path) = self.path.as_mut() {
            path.brake(&mut self.path_generator);
        }
        for (g, active) in &mut self.independent {
            if *active && g.brake(dec, jerk).is_err() {
                *active = false;
            }
        }
        if self.tracker.state() != DynCsState::Inactive {
            self.tracker.fail(TrackError::MachineStop);
        }
        self.stopping = Some(reason);
    }

    /// Whether a stop was requested and the channel has not ended yet (moving, or waiting
    /// to end in ERROR at its next tick).
    pub fn stopping(&self) -> bool {
        self.stopping.is_some() && (self.is_moving() || self.state == RunState::Running)
    }

    fn fail(&mut self, id: ChannelErrorId, message: String) {
        // A tracking slave that fails can no longer follow (the guard brakes its axes).
        if matches!(
            self.tracker.state(),
            DynCsState::Activating | DynCsState::Active | DynCsState::Deactivating
        ) {
            self.tracker.fail(TrackError::ChannelFailed(id));
        }
        self.error = Some(ChannelError {
            line: self.line,
            id,
            message,
        });
        self.state = RunState::Error;
        self.path = None;
        self.wait = None;
        self.latch_pending = true;
        for (_, active) in &mut self.independent {
            *active = false;
        }
    }

    /// What this channel takes from the PLC this tick (see [`super::plc_io::read_inputs`]).
    pub fn wanted(&self) -> Wanted {
        Wanted {
            dyn_cs: self.stopping.is_none(),
            // Not during a stop: the channel interprets nothing then, and an acknowledge taken
            // now would be lost to the PLC's handshake.
            m_ack: self.stopping.is_none() && matches!(self.wait, Some(Wait::MFunction { .. })),
        }
    }

    /// What the channel shows the PLC after its last tick, for the machine to write
    /// ([`super::plc_io::write_outputs`]).
    pub fn outputs_mut(&mut self) -> &mut ChannelOutputs {
        &mut self.outputs
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
        self.inputs = *inputs;
        self.take_override();
        self.plc_inputs();
        if self.state == RunState::Running && self.stopping.is_none() {
            self.interpret(masters, sync);
        }
        self.advance();
        if let Some(reason) = self.stopping {
            if self.state == RunState::Running && !self.is_moving() {
                self.fail(ChannelErrorId::MachineStop, reason.to_string());
            }
        }
        let master = self.master_sample(masters);
        // The dynamic CS acts on this tick's set-points if it was on before its tick (the
        // last step of a coupling out) or is on after it.
        let tracked_before = self.tracks_set_points();
        self.tracker.tick(master);
        let tracked = tracked_before || self.tracks_set_points();
        self.fail_on_tracking_error();
        self.update_pose();
        self.guard_set_points(tracked);
        self.note_dyn_cs_state();
        self.fill_outputs();
    }

    fn master_sample(
        &self,
        masters: &[Option<MasterSample>; MAX_CHANNELS],
    ) -> Option<MasterSample> {
        match self.tracker.source()? {
            MasterSource::Plc => self.plc_frame.map(|frame| MasterSample {
                frame,
                live: self.plc_enabled,
            }),
            MasterSource::Channel(c) => masters.get(c).copied().flatten(),
        }
    }

    /// `f_wait` of a PLC transition, the counterpart of the NC command's WAIT: the program
    /// goes on to its next block only once the switching has finished (ACTIVE or INACTIVE).
    /// The block under way runs on; nothing waits when no program runs.
    fn hold_program_until_settled(&mut self) {
        if self.state == RunState::Running && self.wait.is_none() {
            self.wait = Some(Wait::Tracking);
        }
    }

    /// Runs blocks until one moves or waits.
    fn interpret(&mut self, masters: &[Option<MasterSample>; MAX_CHANNELS], sync: &mut SyncBoard) {
        for _ in 0..BLOCKS_PER_TICK {
            if let Some(wait) = self.wait {
                if !self.wait_done(wait, sync) {
                    return;
                }
                self.wait = None;
            }
            if self.path.is_some() || self.state != RunState::Running {
                return;
            }
            if self.pending_at < self.pending.len() {
                let element = core::mem::replace(
                    &mut self.pending[self.pending_at],
                    Decoded::Flush {
                        line: 0,
                        wait: false,
                    },
                );
                self.pending_at += 1;
                self.execute(element, masters, sync);
                continue;
            }
            self.pending.clear();
            self.pending_at = 0;
            if !self.next_block_decoded() {
                return;
            }
        }
    }

    /// Runs the interpreter one step (a block decoded into `pending`, or a `$` statement
    /// followed); `false` when the program ended or failed.
    fn next_block_decoded(&mut self) -> bool {
        let Some(program) = self.program.as_ref() else {
            self.state = RunState::Finished;
            return false;
        };
        let vars = ChannelVars {
            track_cs: self.tracker.zero_values(),
        };
        match self
            .interp
            .step(&program.set, &mut self.decoder, &vars, &mut self.pending)
        {
            Ok(Step::End) => {
                self.state = RunState::Finished;
                false
            }
            Ok(Step::Block { unit, block }) => {
                self.blocks_executed += 1;
                if let Some(b) = program
                    .set
                    .units
                    .get(unit as usize)
                    .and_then(|u| u.tree.blocks.get(block as usize))
                {
                    self.line = b.line;
                }
                true
            }
            // The channel's values are a running machine's: nothing is undecided here.
            Ok(Step::Control | Step::Undecided) => true,
            Err(d) => {
                self.fail(ChannelErrorId::Program, d.message);
                false
            }
        }
    }

    fn wait_done(&mut self, wait: Wait, sync: &mut SyncBoard) -> bool {
        match wait {
            Wait::MFunction { code, id } => {
                if !self.inputs.has_m_unit {
                    return true;
                }
                match self.inputs.m_ack.take() {
                    Some(HliMFunctionAck { m_code, request_id }) => {
                        // A stale acknowledge (other id) is consumed and ignored.
                        let done = request_id == id && m_code == code as i32;
                        self.m_functions_acked += u64::from(done);
                        done
                    }
                    None => false,
                }
            }
            Wait::MAnnounce { code } => {
                if self.announce(code) {
                    self.wait = Some(Wait::MFunction {
                        code,
                        id: self.m_next_id,
                    });
                }
                false
            }
            Wait::Sync => sync.try_wait(self.wait_ids.as_slice()),
            Wait::Tracking => self.tracker.settled(),
            Wait::Independent => self.independent.iter().all(|(_, active)| !*active),
            Wait::Dwell { until } => self.tick >= until,
        }
    }

    /// Queues an M-function announcement for the machine to post; `false` while the PLC has
    /// not read the previous one.
    fn announce(&mut self, code: u32) -> bool {
        if !self.inputs.has_m_unit {
            return true;
        }
        if !self.inputs.m_request_free || self.outputs.m_request.is_some() {
            return false;
        }
        let id = self.m_next_id.wrapping_add(1).max(1);
        self.outputs.m_request = Some(HliMFunctionRequest {
            m_code: code as i32,
            block_nr: self.line as i32,
            request_id: id,
        });
        self.inputs.m_request_free = false;
        self.m_next_id = id;
        true
    }

    fn cs_frame(&self) -> Isometry3<f64> {
        self.cs_stack[..self.cs_len]
            .iter()
            .fold(Isometry3::identity(), |acc, f| acc * f)
    }

    /// The programmed X..C words as a frame (channel orientation convention).
    fn programmed_frame(&self) -> Isometry3<f64> {
        let p = &self.programmed;
        PoseWords {
            xyz: [p[0], p[1], p[2]],
            abc: [p[3], p[4], p[5]],
        }
        .to_frame(self.order)
        .unwrap_or_else(|_| Isometry3::identity())
    }

    fn set_programmed_pose(&mut self, pose: &Isometry3<f64>) {
        let w = PoseWords::from_frame(pose, self.order);
        let values = [w.xyz[0], w.xyz[1], w.xyz[2], w.abc[0], w.abc[1], w.abc[2]];
        for (i, v) in values.iter().enumerate() {
            self.programmed[i] = *v;
            self.decoder.set_position(i, *v);
        }
    }

    fn start_path(
        &mut self,
        target: &AxisValues,
        motion: MotionMode,
        feed: f64,
        arc: Option<ArcSpec>,
    ) {
        let mut target = *target;
        // Axes moving independently are left to their own move.
        for (i, (_, active)) in self.independent.iter().enumerate() {
            if *active {
                target[i] = self.programmed[i];
            }
        }
        let limits = [self.limits; crate::setpoint::MAX_CHANNEL_AXES];
        match PathMove::plan(
            &self.programmed,
            &target,
            motion,
            feed,
            arc,
            &limits[..self.programmed.len()],
            &mut self.path_generator,
        ) {
            Ok(path) => self.path = path,
            Err(e) => self.fail(ChannelErrorId::Path, e.to_string()),
        }
    }

    /// The override unit of this tick: a valid value takes effect, one out of range is counted
    /// and the last valid value stays; without a unit the channel runs at 100 %.
    fn take_override(&mut self) {
        match self.inputs.path_override {
            OverrideInput::Valid(value) => self.path_override = value,
            OverrideInput::Invalid(_) => self.override_refused += 1,
            OverrideInput::Absent => self.path_override = DEFAULT_PATH_OVERRIDE,
        }
    }

    /// The override factors (feed, rapid) in effect: 0 under feed hold.
    fn override_factors(&self) -> (f64, f64) {
        let o = self.path_override;
        if o.feed_hold {
            (0.0, 0.0)
        } else {
            (
                f64::from(o.feed_permille) / 1000.0,
                f64::from(o.rapid_permille) / 1000.0,
            )
        }
    }

    fn advance(&mut self) {
        let (feed, rapid) = self.override_factors();
        if let Some(path) = self.path.as_mut() {
            path.set_override(feed, rapid, &mut self.path_generator);
            if path.step(&mut self.path_generator, &mut self.programmed) {
                self.path = None;
            }
        }
        for (i, (g, active)) in self.independent.iter_mut().enumerate() {
            if *active {
                let progress = g.step();
                self.programmed[i] = g.state().position;
                if matches!(progress, Progress::Reached | Progress::Idle) {
                    *active = false;
                }
            }
        }
    }

    /// The dynamic-CS diagnosis as the text tables of the controller: the history (tick,
    /// state, input position, CS translation and rotation, output position) and the switching
    /// log.
    pub fn dyn_cs_diagnosis(&self) -> String {
        super::diagnosis::render(self.index, &self.tracker)
    }
}
