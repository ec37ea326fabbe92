//! The PLC operates the channel through its control unit (`gpCh[i]^channel_control`): each
//! command taken in the tick is carried out, refused with a code, or left Busy until it is
//! done. Loading a program and starting one allocate, so the tick only notes them
//! ([`Pending`]) and the machine carries them out between ticks ([`Channel::serve`]).
//!
//! States (`ChannelState`): IDLE (no program), SELECTED, RUNNING, HOLDING (feed hold or a
//! single-block stop), STOPPING (a stop or reset decelerating, or a machine stop), ERROR.

use super::*;
use crate::channel::folder::{ProgramFolder, ProgramName, SelectRefusal};
use hli::enums::{
    ChannelCommand, ChannelCommandError, ChannelCommandState, ChannelMode, ChannelSignal,
    ChannelState,
};
use hli::layout::{HliChannelCommand, CONTROL_MESSAGE_LEN, PROGRAM_NAME_LEN};

/// Work a channel asks the machine to do between ticks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pending {
    /// Load and check a program from the folder; start at a source line (0: the first block).
    Select {
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
    /// Where the started program begins (a block index of the main program; None: its
    /// start).
    pub(super) start_block: Option<u32>,
    /// The channel was stopped, reset or failed while it ran (for `#WAIT SYN` partners).
    pub(super) aborted: bool,
    /// The channel failed and its text is not in the state block yet.
    pub(super) error_unshown: bool,
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
            start_block: None,
            aborted: false,
            error_unshown: false,
        }
    }
}

type Outcome = Result<bool, ChannelCommandError>;

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

    /// Programs that ran to their end since the CNC started.
    pub fn programs_ended(&self) -> u32 {
        self.plc.outputs.control.programs_ended
    }

    /// Work for the machine between ticks, if any ([`Channel::serve`]).
    pub fn pending(&self) -> Option<Pending> {
        self.control.pending
    }

    /// Whether [`Channel::serve`] has something to do: pending work, or the text of a new
    /// error to show in the state block.
    pub fn wants_service(&self) -> bool {
        self.control.pending.is_some() || self.control.error_unshown
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
        if self.stopping() {
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
                Ok(self.motion.path.is_none())
            }
            ChannelCommand::Resume => {
                self.control.held = false;
                Ok(true)
            }
            ChannelCommand::Reset => Ok(self.reset_command()),
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
            // Cycle start from a hold: the path goes on.
            (c.held, c.block_stop, c.block_ran) = (false, false, false);
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
    /// M function announced stays announced: its late acknowledge is taken as stale), and
    /// tracking switches off softly over its filter. The program ends at rest.
    fn begin_plc_stop(&mut self) {
        let c = &mut self.control;
        (c.plc_stop, c.held, c.block_stop) = (true, false, false);
        let (dec, jerk) = (self.motion.limits.acceleration, self.motion.limits.jerk);
        if let Some(path) = self.motion.path.as_mut() {
            path.brake(&mut self.motion.path_generator);
        }
        for (g, active) in &mut self.motion.independent {
            if *active && g.brake(dec, jerk).is_err() {
                *active = false;
            }
        }
        if matches!(
            self.pose.tracker.state(),
            DynCsState::Activating | DynCsState::Active
        ) {
            self.pose.tracker.switch_off(None);
        }
        self.run.wait = None;
        self.control.aborted = true;
    }

    /// After the tick's motion: a stop of the PLC that reached rest ends the program (and
    /// resets when asked to); a feed hold that reached rest is done.
    pub(super) fn follow_command(&mut self) {
        let settled = !self.is_moving() && !self.pose.tracker.in_transition();
        if self.control.plc_stop && settled {
            self.control.plc_stop = false;
            if self.state == RunState::Running {
                self.state = RunState::Finished;
            }
            self.run.wait = None;
            if self.pose.tracker.state() == DynCsState::Inactive {
                self.resync_to_set_points();
            }
            if std::mem::take(&mut self.control.reset_after_stop) {
                let done = self.finish_reset();
                if done && self.command_busy(ChannelCommand::Reset) {
                    self.command_ended(ChannelCommandError::None);
                }
            } else if self.command_busy(ChannelCommand::Stop) {
                self.command_ended(ChannelCommandError::None);
            }
        }
        if self.command_busy(ChannelCommand::FeedHold) && self.path_at_rest() {
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
        self.motion.path.is_none() || self.motion.path_generator.state().velocity == 0.0
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

    /// The machine could not reset one of the channel's axes: the RESET failed.
    pub fn axis_reset_failed(&mut self) {
        if self.control.command == Some(ChannelCommand::Reset) {
            self.command_ended(ChannelCommandError::AxisFault);
        }
    }

    /// Carries out what the tick left for between ticks: loads and checks a selected program
    /// from the folder, or starts the selected one. Allocates; never called in a tick.
    pub fn serve(&mut self) {
        if self.control.error_unshown {
            // The error's text, rendered here (never in the tick) for the state block.
            self.control.error_unshown = false;
            if let Some(e) = &self.error {
                let text = format!("line {}: {e}", e.line);
                self.plc.outputs.control.message = hli::layout::nul_padded(&text);
            }
        }
        match self.control.pending.take() {
            Some(Pending::Select { name, start_line }) => {
                let loaded = match &self.control.folder {
                    Some(folder) => folder.load(&name, &self.config.axes),
                    None => Err(SelectRefusal {
                        code: ChannelCommandError::NoProgramFolder,
                        message: String::new(),
                    }),
                };
                let outcome = loaded.and_then(|p| self.take_selected(p, &name, start_line));
                self.selected(outcome);
            }
            Some(Pending::Start) => {
                self.begin_selected();
                self.command_ended(ChannelCommandError::None);
            }
            None => {}
        }
    }

    fn take_selected(
        &mut self,
        program: LoadedProgram,
        name: &ProgramName,
        start_line: u32,
    ) -> Result<(), SelectRefusal> {
        let start_block = match start_line {
            0 => None,
            line => {
                let main = &program.set.main().tree;
                let found = main.blocks[main.main_start as usize..]
                    .iter()
                    .position(|b| b.line == line)
                    .map(|i| i as u32 + main.main_start);
                Some(found.ok_or_else(|| SelectRefusal {
                    code: ChannelCommandError::StartLineNotFound,
                    message: format!("{}: no block starts at line {line}", program.name),
                })?)
            }
        };
        self.run.program = Some(program);
        self.control.program_name = *name.bytes();
        self.control.start_block = start_block;
        self.control.program_ended = false;
        if self.state == RunState::Finished {
            self.state = RunState::Idle;
        }
        Ok(())
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
