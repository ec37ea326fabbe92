//! The PLC operates the channel through its control unit (`gpCh[i]^channel_control`): each
//! command taken in the tick is carried out, refused with a code, or left Busy until it is
//! done. Loading a program and starting one allocate, so the tick only notes them
//! ([`Pending`]) and the machine carries them out between ticks ([`Channel::serve`]).
//!
//! States (`ChannelState`): IDLE (no program), SELECTED, RUNNING, HOLDING (feed hold or a
//! single-block stop), STOPPING (a stop or reset decelerating, or a machine stop), ERROR.

use super::*;
use crate::channel::folder::{
    Job, Loaded, Loader, ProgramFolder, ProgramName, SelectRefusal, StartPoint,
};
use hli::enums::{
    ChannelCommand, ChannelCommandError, ChannelCommandState, ChannelMode, ChannelSignal,
    ChannelState,
};
use hli::layout::{HliChannelCommand, CONTROL_MESSAGE_LEN, PROGRAM_NAME_LEN};

/// Work a channel asks the machine to do between ticks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Pending {
    /// Load and check a program from the folder; start at a source line (0: the first block).
    Select {
        /// The file name.
        name: ProgramName,
        /// The line.
        start_line: u32,
    },
    /// The program is being loaded on the loader's thread.
    Loading {
        /// The file name.
        name: ProgramName,
        /// The line.
        start_line: u32,
    },
    /// Start the selected program.
    Start,
}

/// What the PLC steers and what the channel tells it back.
pub(super) struct Control {
    pub(super) mode: ChannelMode,
    pub(super) single_block: bool,
    /// A block ran since the last START: with single block on, the next one waits.
    pub(super) block_ran: bool,
    /// A single-block stop: the channel waits for START between two blocks.
    pub(super) block_stop: bool,
    /// FEED_HOLD: the path decelerates and holds.
    pub(super) held: bool,
    /// A STOP or RESET decelerates; the program ends at rest.
    pub(super) plc_stop: bool,
    /// A RESET follows at rest.
    pub(super) reset_after_stop: bool,
    /// Work for the machine between ticks.
    pub(super) pending: Option<Pending>,
    /// The command the state block reports.
    pub(super) command: Option<ChannelCommand>,
    /// The program ran to its end (until the next START).
    pub(super) program_ended: bool,
    /// Where SELECT loads from.
    pub(super) folder: Option<ProgramFolder>,
    /// The selected program's file name.
    pub(super) program_name: [u8; PROGRAM_NAME_LEN],
    /// The machine resets the channel's axes after this tick (a RESET was carried out).
    pub(super) axis_reset: bool,
    /// Where the started program begins (a block search's result; None: its beginning).
    pub(super) start: Option<Box<StartPoint>>,
    /// The channel was stopped, reset or failed while it ran (for `#WAIT SYN` partners).
    pub(super) aborted: bool,
    /// The channel failed and its text is not in the state block yet.
    pub(super) error_unshown: bool,
    /// The machine stopped (supervision, a lost PLC) and has not been re-armed: no command.
    pub(super) machine_stopped: bool,
    /// The selected program has not been started since it was selected (a partner that
    /// may still signal a `#WAIT SYN`).
    pub(super) fresh: bool,
}

impl Control {
    pub(super) fn new() -> Control {
        Control {
            mode: ChannelMode::Automatic,
            single_block: false,
            block_ran: false,
            block_stop: false,
            held: false,
            plc_stop: false,
            reset_after_stop: false,
            pending: None,
            command: None,
            program_ended: false,
            folder: None,
            program_name: [0; PROGRAM_NAME_LEN],
            axis_reset: false,
            start: None,
            aborted: false,
            error_unshown: false,
            machine_stopped: false,
            fresh: false,
        }
    }
}

type Outcome = Result<bool, ChannelCommandError>;

/// Why a channel is in ERROR after a RESET its axes did not follow.
pub const AXIS_NOT_RESET: &str = "RESET: a channel axis keeps its fault (see its error_id_r)";

impl Channel {
    /// Where SELECT finds programs (set when the machine is built).
    pub fn set_program_folder(&mut self, folder: ProgramFolder) {
        self.control.folder = Some(folder);
    }

    /// The state the PLC reads.
    pub fn channel_state(&self) -> ChannelState {
        let c = &self.control;
        match self.state {
            _ if self.stopping() || c.plc_stop => ChannelState::Stopping,
            RunState::Error => ChannelState::Error,
            RunState::Running if c.held || c.block_stop || self.motion.path_override.feed_hold => {
                ChannelState::Holding
            }
            RunState::Running => ChannelState::Running,
            RunState::Idle | RunState::Finished if self.run.program.is_some() => {
                ChannelState::Selected
            }
            RunState::Idle | RunState::Finished => ChannelState::Idle,
        }
    }

    /// Whether the channel may still signal a `#WAIT SYN` of another channel: it runs its
    /// program, or holds one selected and not started yet.
    pub fn may_signal(&self) -> bool {
        matches!(
            self.channel_state(),
            ChannelState::Running | ChannelState::Holding
        ) || (self.control.fresh && self.channel_state() == ChannelState::Selected)
    }

    /// Programs that ran to their end since the CNC started.
    pub fn programs_ended(&self) -> u32 {
        self.plc.outputs.control.programs_ended
    }

    /// Whether [`Channel::serve`] has something to do: pending work, or the text of a new
    /// error to show in the state block.
    pub fn wants_service(&self) -> bool {
        matches!(
            self.control.pending,
            Some(Pending::Select { .. } | Pending::Start)
        ) || self.control.error_unshown
    }

    /// Takes the command the PLC posted this tick: carried out, refused, or Busy.
    pub(super) fn take_command(&mut self) {
        let Some(command) = self.plc.inputs.command else {
            return;
        };
        let out = &mut self.plc.outputs.control;
        out.command_id = command.command_id;
        out.states_seen = 0;
        let outcome = match ChannelCommand::decode(command.command) {
            Ok(kind) => {
                self.control.command = Some(kind);
                self.carry_out_command(kind, &command)
            }
            Err(_) => Err(ChannelCommandError::UnknownCommand),
        };
        match outcome {
            Ok(true) => self.command_ended(ChannelCommandError::None),
            Ok(false) => self.plc.outputs.control.command_state = ChannelCommandState::Busy.raw(),
            Err(error) => self.command_ended(error),
        }
    }

    fn command_ended(&mut self, error: ChannelCommandError) {
        let out = &mut self.plc.outputs.control;
        out.command_error = error.raw();
        out.command_state = match error {
            ChannelCommandError::None => ChannelCommandState::Done,
            _ => ChannelCommandState::Refused,
        }
        .raw();
    }

    fn command_busy(&self, kind: ChannelCommand) -> bool {
        self.control.command == Some(kind)
            && self.plc.outputs.control.command_state == ChannelCommandState::Busy.raw()
    }

    fn carry_out_command(&mut self, kind: ChannelCommand, command: &HliChannelCommand) -> Outcome {
        use ChannelCommandError as E;
        // A machine stop owns the channel until the machine is re-armed (a PLC must not undo
        // it), and until its braking has latched and ended.
        if self.control.machine_stopped || self.stopping() || self.guard_pending() {
            return Err(E::MachineStop);
        }
        let running = self.state == RunState::Running && !self.control.plc_stop;
        match kind {
            ChannelCommand::Select => self.select_command(command, running),
            ChannelCommand::Start => self.start_command(running),
            ChannelCommand::Stop if running => {
                self.begin_plc_stop();
                Ok(false)
            }
            // Nothing runs: nothing to stop (a stop under way goes on).
            ChannelCommand::Stop => Ok(!self.control.plc_stop),
            ChannelCommand::FeedHold | ChannelCommand::Resume if !running => Err(E::NotRunning),
            ChannelCommand::FeedHold => {
                self.control.held = true;
                Ok(!self.path_active())
            }
            ChannelCommand::Resume => {
                self.control.held = false;
                Ok(true)
            }
            ChannelCommand::Reset => Ok(self.reset_command()),
            // Off during a single-block stop: the channel still waits for START there.
            ChannelCommand::SingleBlock => match command.value {
                0 | 1 => {
                    self.control.single_block = command.value == 1;
                    Ok(true)
                }
                _ => Err(E::BadValue),
            },
            ChannelCommand::Mode => {
                let mode = ChannelMode::decode(command.value).map_err(|_| E::BadValue)?;
                if running {
                    return Err(E::Running);
                }
                self.control.mode = mode;
                Ok(true)
            }
        }
    }

    fn select_command(&mut self, command: &HliChannelCommand, running: bool) -> Outcome {
        use ChannelCommandError as E;
        if running || self.control.plc_stop {
            return Err(E::Running);
        }
        if self.control.pending.is_some() {
            return Err(E::Busy);
        }
        let name = ProgramName::parse(&command.program)?;
        let start_line = u32::try_from(command.start_line).map_err(|_| E::BadValue)?;
        if self.control.folder.is_none() {
            return Err(E::NoProgramFolder);
        }
        self.control.pending = Some(Pending::Select { name, start_line });
        Ok(false)
    }

    fn start_command(&mut self, running: bool) -> Outcome {
        use ChannelCommandError as E;
        let c = &mut self.control;
        if running {
            if !(c.held || c.block_stop) {
                return Err(E::Running);
            }
            // Cycle start from a hold: the path goes on; from a single-block stop, the next
            // block runs.
            if c.block_stop {
                (c.block_stop, c.block_ran) = (false, false);
            }
            c.held = false;
            return Ok(true);
        }
        if c.plc_stop || c.pending.is_some() {
            return Err(E::Busy);
        }
        if self.state == RunState::Error {
            return Err(E::InError);
        }
        if c.mode != ChannelMode::Automatic {
            return Err(E::NotAutomatic);
        }
        if self.run.program.is_none() {
            return Err(E::NoProgram);
        }
        c.pending = Some(Pending::Start);
        Ok(false)
    }

    /// RESET: at rest at once; else the channel stops first and resets at rest. `true` when
    /// it is done.
    fn reset_command(&mut self) -> bool {
        self.control.pending = None;
        let tracking = !matches!(
            self.pose.tracker.state(),
            DynCsState::Inactive | DynCsState::Error
        );
        if self.state == RunState::Running || self.is_moving() || tracking {
            self.begin_plc_stop();
            self.control.reset_after_stop = true;
            return false;
        }
        self.finish_reset()
    }

    /// A stop of the PLC: the path and independent axes brake, no block starts, waits end (an
    /// M function announced stays announced: its late acknowledge is taken as stale). A
    /// tracking slave takes the safe path: its tracking stops (ERROR, reason PlcStop) and the
    /// guard brakes every axis on its own limits from its motion, so it comes to rest relative
    /// to the world; at rest the compensation becomes part of the programmed position and the
    /// tracking is INACTIVE. The program ends at rest.
    fn begin_plc_stop(&mut self) {
        self.control.aborted |= self.state == RunState::Running;
        let c = &mut self.control;
        (c.plc_stop, c.held, c.block_stop) = (true, false, false);
        let (dec, jerk) = (self.motion.limits.acceleration, self.motion.limits.jerk);
        self.brake_path();
        for (g, active) in &mut self.motion.independent {
            if *active && g.brake(dec, jerk).is_err() {
                *active = false;
            }
        }
        if matches!(
            self.pose.tracker.state(),
            DynCsState::Activating | DynCsState::Active | DynCsState::Deactivating
        ) {
            self.pose.tracker.fail(TrackError::PlcStop);
            self.safety.latch_pending = true;
        }
        self.run.wait = None;
    }

    /// A tracker in ERROR whose guard has not latched yet (it latches at the end of the tick
    /// it failed in): its axes may still move with the compensation.
    fn guard_pending(&self) -> bool {
        self.pose.tracker.state() == DynCsState::Error && !self.safety.guard.latched()
    }

    /// A machine stop ends a command of the PLC under way: the stop owns the channel.
    pub(super) fn abort_plc_command(&mut self) {
        let c = &mut self.control;
        (c.plc_stop, c.reset_after_stop, c.pending, c.held) = (false, false, None, false);
        if self.plc.outputs.control.command_state == ChannelCommandState::Busy.raw() {
            self.command_ended(ChannelCommandError::Aborted);
        }
    }

    /// Whether the machine has stopped the channel and not been re-armed (set by the
    /// machine; see [`crate::machine::Machine::stop`]).
    pub fn set_machine_stopped(&mut self, stopped: bool) {
        self.control.machine_stopped = stopped;
    }

    /// After the tick's motion: a stop of the PLC that reached rest ends the program (and
    /// resets when asked to); a feed hold that reached rest is done.
    pub(super) fn follow_command(&mut self) {
        let settled = !self.is_moving() && !self.pose.tracker.in_transition();
        if self.control.plc_stop && settled && !self.guard_pending() {
            self.plc_stop_at_rest();
        }
        if self.command_busy(ChannelCommand::FeedHold) && self.path_at_rest() {
            self.command_ended(ChannelCommandError::None);
        }
    }

    fn plc_stop_at_rest(&mut self) {
        self.control.plc_stop = false;
        if self.state == RunState::Running {
            self.state = RunState::Finished;
        }
        self.run.wait = None;
        if self.pose.tracker.last_error() == Some(TrackError::PlcStop)
            && self.pose.tracker.state() == DynCsState::Error
        {
            // The safe path of a tracking slave ended: the axes hold where they braked to;
            // that becomes the programmed position, tracking INACTIVE.
            self.pose.tracker.reset();
            self.safety.guard.release();
        }
        if self.pose.tracker.state() == DynCsState::Inactive && !self.safety.guard.latched() {
            self.resync_to_set_points();
            self.safety.guard.accept(&self.pose.set_points);
        }
        let done = if std::mem::take(&mut self.control.reset_after_stop) {
            self.finish_reset()
        } else {
            true
        };
        // A STOP taken while a RESET decelerated ends with it.
        let busy =
            self.command_busy(ChannelCommand::Stop) || self.command_busy(ChannelCommand::Reset);
        if done && busy {
            self.command_ended(ChannelCommandError::None);
        }
    }

    /// The program ran to its end (M30, M2 or its last block).
    pub(super) fn program_end(&mut self) {
        self.state = RunState::Finished;
        self.control.program_ended = true;
        let out = &mut self.plc.outputs.control;
        out.programs_ended = out.programs_ended.wrapping_add(1);
    }

    fn path_at_rest(&self) -> bool {
        let contour_still = !self.motion.contour.active()
            || self.motion.contour.path_state().velocity.abs() <= 1e-12;
        contour_still
            && (self.motion.path.is_none() || self.motion.path_generator.state().velocity == 0.0)
    }

    /// Whether the channel was stopped, reset or failed while it ran since the last call.
    pub fn take_aborted(&mut self) -> bool {
        std::mem::take(&mut self.control.aborted)
    }

    /// Clears the errors where the channel stands (see [`Channel::reset`]); the machine resets
    /// the channel's axes after the tick. `false` (refused) only while something moves.
    fn finish_reset(&mut self) -> bool {
        if self.reset().is_err() {
            return false;
        }
        self.stopping = None;
        let c = &mut self.control;
        (c.held, c.block_stop, c.block_ran, c.program_ended) = (false, false, false, false);
        c.axis_reset = true;
        self.plc.outputs.control.message = [0; CONTROL_MESSAGE_LEN];
        true
    }

    /// Whether the machine should reset the channel's axes (once per RESET).
    pub fn take_axis_reset(&mut self) -> bool {
        std::mem::take(&mut self.control.axis_reset)
    }

    /// The machine could not reset one of the channel's axes: the RESET failed and the
    /// channel is in ERROR (it cannot start with an axis it does not drive).
    pub fn axis_reset_failed(&mut self) {
        if self.control.command == Some(ChannelCommand::Reset) {
            self.command_ended(ChannelCommandError::AxisFault);
        }
        self.fail(ChannelFault::MachineStop(AXIS_NOT_RESET));
    }

    /// Carries out what the tick left for between ticks: loads and checks a selected program
    /// from the folder (on `loader`'s thread when one is given, else here), or starts the
    /// selected one; and renders a new error's text. Allocates; never called in a tick.
    pub fn serve(&mut self, loader: Option<&Loader>) {
        if self.control.error_unshown {
            // The error's text, rendered here (never in the tick) for the state block.
            self.control.error_unshown = false;
            if let Some(e) = &self.error {
                let text = format!("line {}: {e}", e.line);
                self.plc.outputs.control.message = hli::layout::nul_padded(&text);
            }
        }
        match self.control.pending {
            Some(Pending::Select { name, start_line }) => {
                let Some(folder) = self.control.folder.clone() else {
                    self.control.pending = None;
                    return self.command_ended(ChannelCommandError::NoProgramFolder);
                };
                let job = Job {
                    channel: self.index,
                    folder,
                    axes: self.config.axes.clone(),
                    name,
                    start_line,
                };
                match loader {
                    None => self.finish_select(job.run()),
                    // A full queue: tried again after the next tick.
                    Some(loader) => {
                        if loader.send(job) {
                            self.control.pending = Some(Pending::Loading { name, start_line });
                        }
                    }
                }
            }
            Some(Pending::Start) => {
                self.control.pending = None;
                self.begin_selected();
                self.command_ended(ChannelCommandError::None);
            }
            Some(Pending::Loading { .. }) | None => {}
        }
    }

    /// A program the loader loaded: selected if the channel still waits for it (a STOP or
    /// RESET since dropped the wait: the result is dropped too).
    pub fn finish_select(&mut self, loaded: Loaded) {
        let waiting = matches!(
            self.control.pending,
            Some(Pending::Select { name, start_line } | Pending::Loading { name, start_line })
                if name == loaded.name && start_line == loaded.start_line
        );
        if !waiting {
            return;
        }
        self.control.pending = None;
        let outcome = loaded
            .result
            .map(|(program, start)| self.take_selected(program, &loaded.name, start));
        self.selected(outcome);
    }

    fn take_selected(
        &mut self,
        program: LoadedProgram,
        name: &ProgramName,
        start: Option<StartPoint>,
    ) {
        self.run.program = Some(program);
        self.control.program_name = *name.bytes();
        self.control.start = start.map(Box::new);
        self.control.program_ended = false;
        self.control.fresh = true;
        if self.state == RunState::Finished {
            self.state = RunState::Idle;
        }
    }

    fn selected(&mut self, outcome: Result<(), SelectRefusal>) {
        match outcome {
            Ok(()) => {
                self.plc.outputs.control.message = [0; CONTROL_MESSAGE_LEN];
                self.command_ended(ChannelCommandError::None);
            }
            Err(refusal) => {
                self.plc.outputs.control.message = hli::layout::nul_padded(&refusal.message);
                self.command_ended(refusal.code);
            }
        }
    }

    /// The state block of this tick (after the channel's tick).
    pub(super) fn fill_control_state(&mut self) {
        let state = self.channel_state();
        let signals = self.signals();
        let c = &self.control;
        let feed_hold = c.held || self.motion.path_override.feed_hold;
        let out = &mut self.plc.outputs.control;
        out.state = state.raw();
        out.mode = c.mode.raw();
        out.single_block = hli::Bool::from(c.single_block);
        out.feed_hold = hli::Bool::from(feed_hold);
        out.signals = signals;
        out.states_seen |= state.seen_bit();
        out.block_nr = self.run.line as i32;
        out.error_id = self.error.as_ref().map_or(0, |e| e.id.raw());
        out.program = c.program_name;
    }

    fn signals(&self) -> u32 {
        let wait = self.run.wait;
        let tracker = self.pose.tracker.state();
        [
            (self.control.program_ended, ChannelSignal::ProgramEnd),
            (
                matches!(wait, Some(Wait::MFunction { .. } | Wait::MAnnounce { .. })),
                ChannelSignal::WaitingMAck,
            ),
            (
                matches!(wait, Some(Wait::Sync { .. })),
                ChannelSignal::WaitingSync,
            ),
            (
                matches!(
                    tracker,
                    DynCsState::Activating | DynCsState::Active | DynCsState::Deactivating
                ),
                ChannelSignal::Tracking,
            ),
            (tracker == DynCsState::Error, ChannelSignal::TrackingError),
            (self.control.block_stop, ChannelSignal::SingleBlockStop),
            (self.is_moving(), ChannelSignal::Moving),
            (
                matches!(wait, Some(Wait::Dwell { .. } | Wait::Tracking)),
                ChannelSignal::Waiting,
            ),
        ]
        .into_iter()
        .filter(|(on, _)| *on)
        .fold(0, |bits, (_, signal)| bits | signal.raw())
    }
}
