//! Carrying out one decoded block element: motion, dwell, independent axes, M functions,
//! `#TRACK CS`, `#CHANNEL INTERFACE`, `#CS`, `#TRAFO`, synchronisation, and the values a
//! program sets that the channel only reports (`S`, `T`, `#MSG`, the log file).

use super::*;
use crate::nc::decode::TrackCommand;

/// Values the program set that the channel reports and does not act on.
#[derive(Default)]
pub(super) struct ProgramValues {
    /// `S..`: the spindle speed M03/M04 turn at.
    pub(super) spindle_speed: f64,
    /// `T..`: the tool number last programmed.
    pub(super) tool_number: u32,
    /// `#MSG`: the last message and how many there were.
    pub(super) message: Option<Arc<str>>,
    pub(super) messages: u64,
    /// The last `#TRACK CS ON [LOG_FILE=..]` of the program.
    pub(super) log_file: Option<Arc<str>>,
}

impl Channel {
    /// `S..` last programmed (1/min).
    pub fn spindle_speed(&self) -> f64 {
        self.values.spindle_speed
    }

    /// `T..` last programmed.
    pub fn tool_number(&self) -> u32 {
        self.values.tool_number
    }

    /// The last `#MSG` text and how many messages the program gave.
    pub fn message(&self) -> (Option<&str>, u64) {
        (self.values.message.as_deref(), self.values.messages)
    }

    /// The file the program asked the dynamic-CS diagnosis to be written to
    /// (`#TRACK CS ON [LOG_FILE=..]`; the last one named).
    pub fn log_file(&self) -> Option<&str> {
        self.values.log_file.as_deref()
    }

    /// [`Self::log_file`] as the shared name (cloned without allocating).
    pub fn log_file_name(&self) -> Option<&Arc<str>> {
        self.values.log_file.as_ref()
    }

    pub(super) fn execute(
        &mut self,
        element: Decoded,
        masters: &[Option<MasterSample>; MAX_CHANNELS],
        sync: &mut SyncBoard,
    ) {
        match element {
            Decoded::Motion(m) if self.start_contour(&m) => {}
            Decoded::Motion(m) => {
                let arc = m.arc.map(|arc| ArcSpec {
                    arc,
                    cycle_s: self.cycle_s,
                    chordal_tolerance: self.config.interpolator.chordal_tolerance,
                });
                self.start_path(&m.target, m.motion, m.feed, arc)
            }
            Decoded::Dwell { seconds, .. } => {
                let ticks = (seconds / self.cycle_s).round();
                self.run.wait = Some(Wait::Dwell {
                    until: self.tick.saturating_add(ticks as u64),
                });
            }
            Decoded::Message { text, .. } => {
                self.values.messages += 1;
                self.values.message = Some(text);
            }
            Decoded::Spindle { speed, .. } => self.values.spindle_speed = speed,
            Decoded::Tool { number, .. } => self.values.tool_number = number,
            Decoded::ToolRecord { d, .. } => self.select_tool_record(d),
            Decoded::IndependentMove {
                axis,
                target,
                feed,
                motion,
                asynchronous,
                ..
            } => self.independent_move(axis, target, feed, motion, asynchronous),
            Decoded::WaitIndependent { .. } => self.run.wait = Some(Wait::Independent),
            Decoded::MFunction { code, .. } => self.m_function(code),
            Decoded::Track { command, .. } => self.track(command, masters),
            Decoded::TrackAbs { .. } => {
                let zero = self.pose.tracker.zero_values();
                for (i, z) in zero.iter().enumerate().take(self.motion.programmed.len()) {
                    self.run.decoder.set_g92(i, *z);
                }
            }
            Decoded::ChannelInterface { on, .. } => self.pose.interface_on = on,
            Decoded::Cs { on, frame, .. } => self.coordinate_system(on, frame),
            Decoded::Trafo { on, id, .. } => self.switch_trafo(on, id),
            Decoded::SignalSyn { id, count, .. } => {
                if sync.signal(id, count).is_err() {
                    self.fail(ChannelFault::SyncBoardFull);
                }
            }
            Decoded::WaitSyn { ids, .. } => {
                self.run.wait_ids = ids;
                self.run.wait = Some(Wait::Sync {
                    since: self.tick,
                    aborts: sync.aborts(),
                });
            }
            Decoded::Flush { .. } => {}
        }
    }

    /// M30 and M2 end the program; any other M function is announced to the PLC (or waits
    /// for the request slot) and awaited.
    pub(super) fn m_function(&mut self, code: u32) {
        if code == 30 || code == 2 {
            self.program_end();
            return;
        }
        if self.announce(code) {
            self.run.wait = Some(Wait::MFunction {
                code,
                id: self.plc.m_next_id,
            });
        } else {
            self.run.wait = Some(Wait::MAnnounce { code });
        }
    }

    /// `#TRACK CS ON|OFF`: the dynamic CS switches on to the PLC's or a master channel's
    /// frame, or off over its filter.
    pub(super) fn track(
        &mut self,
        command: TrackCommand,
        masters: &[Option<MasterSample>; MAX_CHANNELS],
    ) {
        if !command.on {
            // Without FILTER the switch-off takes the switch-on's filter.
            self.pose.tracker.switch_off(command.filter_ticks);
            if command.wait {
                self.run.wait = Some(Wait::Tracking);
            }
            return;
        }
        let source = match command.source {
            Some(TrackSource::Id(0)) => MasterSource::Plc,
            Some(TrackSource::Id(n) | TrackSource::Channel(n)) => {
                MasterSource::Channel(usize::from(n).saturating_sub(1))
            }
            None => MasterSource::Plc,
        };
        let master = match source {
            MasterSource::Plc => self.plc.plc_frame,
            MasterSource::Channel(c) => {
                // A master channel that does not publish yet is waited for
                // (ACTIVATING): its interface is taken over softly when it comes on,
                // whichever of the two channels ticks first.
                let refusal = if c == self.index {
                    Some(TrackError::OwnChannel)
                } else if c >= self.channels {
                    Some(TrackError::NoSuchChannel(c + 1))
                } else {
                    None
                };
                if let Some(error) = refusal {
                    self.refuse_track(error);
                    return;
                }
                masters[c].map(|m| m.frame)
            }
        };
        if let Err(error) = self
            .pose
            .tracker
            .switch_on(track_setup(&command, source), master.as_ref())
        {
            self.refuse_track(error);
            return;
        }
        if command.log_file.is_some() {
            // Written by the process after the run: no IO in the tick.
            self.values.log_file = command.log_file;
        }
        if command.wait {
            self.run.wait = Some(Wait::Tracking);
        }
    }

    /// `#TRACK CS ON` refused: the tracker goes to ERROR and the channel fails.
    pub(super) fn refuse_track(&mut self, error: TrackError) {
        self.pose.tracker.fail(error);
        self.fail(ChannelFault::TrackRefused(error));
    }
}

/// The tracker's setup of a `#TRACK CS ON` from `source`.
fn track_setup(command: &TrackCommand, source: MasterSource) -> TrackSetup {
    TrackSetup {
        source,
        set_zero: command.set_zero,
        translation_only: command.option == 1,
        kin_base: command.kin_base,
        filter_ticks: command.filter_ticks.unwrap_or(DEFAULT_FILTER_TICKS),
        wait: command.wait,
        rot_trans: command.rot_trans,
        offset: command.offset,
        relative: command.relative,
        simu: command.simu,
    }
}
