//! Carrying out one decoded block element: motion, dwell, independent axes, M functions,
//! `#TRACK CS`, `#CHANNEL INTERFACE`, `#CS`, `#TRAFO`, synchronisation.

use super::*;
use crate::nc::decode::TrackCommand;

impl Channel {
    pub(super) fn execute(
        &mut self,
        element: Decoded,
        masters: &[Option<MasterSample>; MAX_CHANNELS],
        sync: &mut SyncBoard,
    ) {
        match element {
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
                self.wait = Some(Wait::Dwell {
                    until: self.tick.saturating_add(ticks as u64),
                });
            }
            Decoded::Message { text, .. } => {
                self.messages += 1;
                self.message = Some(text);
            }
            Decoded::Spindle { speed, .. } => self.spindle_speed = speed,
            Decoded::Tool { number, .. } => self.tool_number = number,
            Decoded::ToolRecord { d, .. } => self.select_tool_record(d),
            Decoded::IndependentMove {
                axis,
                target,
                feed,
                motion,
                asynchronous,
                ..
            } => self.independent_move(axis, target, feed, motion, asynchronous),
            Decoded::WaitIndependent { .. } => self.wait = Some(Wait::Independent),
            Decoded::MFunction { code, .. } => self.m_function(code),
            Decoded::Track { command, .. } => self.track(command, masters),
            Decoded::TrackAbs { .. } => {
                let zero = self.tracker.zero_values();
                for (i, z) in zero.iter().enumerate().take(self.programmed.len()) {
                    self.decoder.set_g92(i, *z);
                }
            }
            Decoded::ChannelInterface { on, .. } => self.interface_on = on,
            Decoded::Cs { on, frame, .. } => self.coordinate_system(on, frame),
            Decoded::Trafo { on, id, .. } => self.switch_trafo(on, id),
            Decoded::SignalSyn { id, count, .. } => {
                if sync.signal(id, count).is_err() {
                    self.fail(
                        ChannelErrorId::Synchronisation,
                        "#SIGNAL SYN: too many synchronisation ids pending".to_string(),
                    );
                }
            }
            Decoded::WaitSyn { ids, .. } => {
                self.wait_ids = ids;
                self.wait = Some(Wait::Sync);
            }
            Decoded::Flush { .. } => {}
        }
    }

    /// An independent axis moves to `target` on its own generator (rapid, or at `feed`
    /// mm/min); the block waits for it unless `asynchronous`.
    fn independent_move(
        &mut self,
        axis: usize,
        target: f64,
        feed: f64,
        motion: MotionMode,
        asynchronous: bool,
    ) {
        let limits = self.limits;
        let velocity = match motion {
            MotionMode::Rapid => limits.velocity,
            _ => (feed / 60.0).min(limits.velocity),
        };
        let (generator, active) = &mut self.independent[axis];
        generator.hold(self.programmed[axis]);
        let planned = generator.move_to(
            target,
            MoveLimits {
                velocity,
                acceleration: limits.acceleration,
                deceleration: limits.acceleration,
                jerk: limits.jerk,
            },
        );
        *active = planned.is_ok();
        if planned.is_err() {
            self.fail(
                ChannelErrorId::IndependentAxis,
                format!("independent axis {}: no profile", self.config.axes[axis]),
            );
            return;
        }
        if !asynchronous {
            self.wait = Some(Wait::Independent);
        }
    }

    /// M30 and M2 end the program; any other M function is announced to the PLC (or waits
    /// for the request slot) and awaited.
    fn m_function(&mut self, code: u32) {
        if code == 30 || code == 2 {
            self.state = RunState::Finished;
            return;
        }
        if self.announce(code) {
            self.wait = Some(Wait::MFunction {
                code,
                id: self.m_next_id,
            });
        } else {
            self.wait = Some(Wait::MAnnounce { code });
        }
    }

    /// `#TRACK CS ON|OFF`: the dynamic CS switches on to the PLC's or a master channel's
    /// frame, or off over its filter.
    fn track(&mut self, command: TrackCommand, masters: &[Option<MasterSample>; MAX_CHANNELS]) {
        if !command.on {
            // Without FILTER the switch-off takes the switch-on's filter.
            self.tracker.switch_off(command.filter_ticks);
            if command.wait {
                self.wait = Some(Wait::Tracking);
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
            MasterSource::Plc => self.plc_frame,
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
            .tracker
            .switch_on(track_setup(&command, source), master.as_ref())
        {
            self.refuse_track(error);
            return;
        }
        if command.log_file.is_some() {
            // Written by the process after the run: no IO in the tick.
            self.log_file = command.log_file;
        }
        if command.wait {
            self.wait = Some(Wait::Tracking);
        }
    }

    /// `#TRACK CS ON` refused: the tracker goes to ERROR and the channel fails.
    fn refuse_track(&mut self, error: TrackError) {
        self.tracker.fail(error);
        self.fail(ChannelErrorId::Tracking, format!("#TRACK CS ON: {error}"));
    }

    /// `#CS ON|OFF`: a coordinate system pushed on the stack (`frame`: X Y Z A B C) or the
    /// last one taken off; the tool stays where it is.
    fn coordinate_system(&mut self, on: bool, frame: [f64; 6]) {
        if !self.trafo {
            self.fail(
                ChannelErrorId::CoordinateSystem,
                "#CS needs an active transformation (#TRAFO ON)".to_string(),
            );
            return;
        }
        let before = self.cs_frame();
        if on {
            if self.cs_len == CS_DEPTH {
                self.fail(
                    ChannelErrorId::CoordinateSystem,
                    format!("more than {CS_DEPTH} coordinate systems active"),
                );
                return;
            }
            let words = PoseWords {
                xyz: [frame[0], frame[1], frame[2]],
                abc: [frame[3], frame[4], frame[5]],
            };
            match offset_frame(&words, false) {
                Ok(f) => {
                    self.cs_stack[self.cs_len] = f;
                    self.cs_len += 1;
                }
                Err(e) => {
                    self.fail(ChannelErrorId::CoordinateSystem, format!("#CS: {e}"));
                    return;
                }
            }
        } else {
            self.cs_len = self.cs_len.saturating_sub(1);
        }
        // The tool stays where it is; its programmed words change.
        let base = before * self.programmed_frame();
        self.set_programmed_pose(&(self.cs_frame().inverse() * base));
    }

    /// `#TRAFO ON|OFF [id]`: the kinematic transformation switched on (the programmed words
    /// become the tool pose) or off (they become the joints again).
    fn switch_trafo(&mut self, on: Option<bool>, id: Option<u32>) {
        if let Some(id) = id {
            if id != self.config.kinematics.id {
                self.fail(
                    ChannelErrorId::Kinematics,
                    format!(
                        "kinematic {id} is not configured for this channel (configured: {})",
                        self.config.kinematics.id
                    ),
                );
                return;
            }
        }
        match on {
            Some(true) if !self.trafo => {
                self.trafo = true;
                self.program_tool_pose();
            }
            Some(false) if self.trafo => {
                self.trafo = false;
                self.cs_len = 0;
                for i in 0..6 {
                    self.programmed[i] = self.joints[i];
                    self.decoder.set_position(i, self.joints[i]);
                }
            }
            _ => {}
        }
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
