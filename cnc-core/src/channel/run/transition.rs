//! The PLC's dynamic-CS transition (`transition_w`): taken, checked, carried out or refused,
//! and its outcome reported in `dyn_cs_result` with the tracking states passed since.

use super::Channel;
use crate::channel::dyn_cs::{words, BadParameter, MasterSource, TrackError, TrackSetup};
use crate::channel::hli_frame::frame_from_hli;
use crate::channel::plc_io::{hli_value, Transition};
use hli::enums::{DynCsCommand, DynCsTransitionError};
use hli::layout::HliDynCsTransition;
use kinematics::RotationOrder;

impl Channel {
    /// The PLC's side of the dynamic-CS unit (not taken during a stop: see [`Wanted`]).
    pub(super) fn plc_inputs(&mut self) {
        // The frames' clock runs on through a stop, so a frame after it is not taken as the
        // next of a steady writer.
        self.plc.frames.advance();
        if self.stopping.is_some() {
            return;
        }
        let enabled = self.plc.inputs.dyn_cs_enabled;
        self.plc.plc_enabled = enabled;
        if !enabled {
            self.plc.frames.forget_motion();
        }
        if let Some(cs) = self.plc.inputs.dyn_cs_command {
            // enable_w redirects the dynamic CS to the PLC; without it a commanded frame goes
            // nowhere (taken, so the PLC's semaphore is free again, and counted).
            if enabled {
                self.plc
                    .frames
                    .take(frame_from_hli(&cs, RotationOrder::Zyx));
            } else {
                self.pose.tracker.not_redirected();
            }
        }
        // Between the cycles of a slower PLC task, carried on (see `plc_frames`).
        self.plc.plc_frame = self.plc.frames.now();
        self.take_transition(enabled);
    }

    /// Takes this tick's transition, if the PLC posted one. A refusal is logged, counted and
    /// reported to the PLC; it never puts the tracking in ERROR, so it cannot block a later
    /// switch-on.
    pub(super) fn take_transition(&mut self, enabled: bool) {
        let (raw, result) = match self.plc.inputs.transition {
            None => return,
            Some(Transition::Garbage(raw)) => (
                raw,
                Err(TrackError::BadTransition(BadParameter::CommandWord)),
            ),
            Some(Transition::Taken(command, _)) if !enabled => {
                (command.raw(), Err(TrackError::PlcNotEnabled))
            }
            Some(Transition::Taken(command, params)) => {
                (command.raw(), self.carry_out(command, &params))
            }
        };
        if let Err(error) = result {
            self.pose.tracker.refuse(error);
        }
        let out = &mut self.plc.outputs.dyn_cs_result;
        out.taken_count_r = out.taken_count_r.wrapping_add(1);
        out.command_r = raw;
        out.error_id_r = result.err().map_or(0, |e| refusal_id(e).raw());
        out.states_seen_r = 0;
    }

    /// Adds the tracker's state of this tick to the states passed since the last transition.
    /// Beside it, the axes' catch-up lag of this tick and the catch-ups started.
    pub(super) fn note_dyn_cs_state(&mut self) {
        let lag = self.safety.lag;
        let out = &mut self.plc.outputs.dyn_cs_result;
        out.states_seen_r |= self.pose.tracker.state().seen_bit();
        out.lag_translation_r = hli_value(lag.translation, false);
        out.lag_rotation_r = hli_value(lag.rotation, true);
        out.catch_ups_r = self.safety.guard.catch_up().started() as u32;
    }

    fn carry_out(
        &mut self,
        command: DynCsCommand,
        params: &HliDynCsTransition,
    ) -> Result<(), TrackError> {
        match command {
            DynCsCommand::Activate => {
                let setup = self.plc_setup(params)?;
                let master = self.plc.plc_frame;
                self.pose.tracker.switch_on(setup, master.as_ref())?;
                if setup.wait {
                    self.hold_program_until_settled();
                }
            }
            DynCsCommand::Deactivate => {
                self.pose.tracker.switch_off(Some(params.filter_max_ticks));
                // f_wait on a switch-off, as `#TRACK CS OFF [WAIT]`; a byte that is no BOOL
                // is no request to wait.
                if params.f_wait.get() == Ok(true) {
                    self.hold_program_until_settled();
                }
            }
            DynCsCommand::None => {}
        }
        Ok(())
    }

    /// The switch-on a +1 asks for, checked.
    fn plc_setup(&self, params: &HliDynCsTransition) -> Result<TrackSetup, TrackError> {
        let flags = [
            params.f_wait.get(),
            params.f_set_zero.get(),
            params.f_kin_base.get(),
            params.f_rot_trans.get(),
        ];
        let bad = |p| TrackError::BadTransition(p);
        let [Ok(wait), Ok(set_zero), Ok(kin_base), Ok(rot_trans)] = flags else {
            return Err(bad(BadParameter::FlagByte));
        };
        if params.option > 1 {
            return Err(bad(BadParameter::OptionValue));
        }
        if set_zero && self.is_moving() {
            // The master frame becomes the program's zero: only at standstill.
            return Err(bad(BadParameter::SetZeroMoving));
        }
        let kb = frame_from_hli(&params.kinematic_base_cs, RotationOrder::Zyx);
        Ok(TrackSetup {
            source: MasterSource::Plc,
            set_zero,
            translation_only: params.option == 1,
            kin_base,
            filter_ticks: params.filter_max_ticks,
            wait,
            rot_trans,
            offset: words(&kb),
            // The transition has no flags for these: NC command only.
            relative: false,
            simu: false,
        })
    }
}

/// The id the PLC reads for a refusal.
fn refusal_id(error: TrackError) -> DynCsTransitionError {
    match error {
        TrackError::BadTransition(p) => match p {
            BadParameter::CommandWord => DynCsTransitionError::CommandWord,
            BadParameter::FlagByte => DynCsTransitionError::FlagByte,
            BadParameter::OptionValue => DynCsTransitionError::OptionValue,
            BadParameter::Offset => DynCsTransitionError::Offset,
            BadParameter::SetZeroMoving => DynCsTransitionError::SetZeroMoving,
        },
        TrackError::PlcNotEnabled => DynCsTransitionError::NotEnabled,
        TrackError::AlreadyOn => DynCsTransitionError::AlreadyOn,
        _ => DynCsTransitionError::Refused,
    }
}
