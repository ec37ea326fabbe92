//! The channel's PLC handshakes: the M-function announcement and its acknowledge, what the
//! channel takes from the PLC each tick and the values it shows after it.

use super::*;

/// What the channel exchanges with the PLC.
pub(super) struct PlcLink {
    /// What the PLC gave this tick (copied in at the start of the tick).
    pub(super) inputs: ChannelInputs,
    pub(super) outputs: ChannelOutputs,
    /// The frame the PLC last commanded on the dynamic-CS unit, and whether the unit is
    /// enabled.
    pub(super) plc_frame: Option<Isometry3<f64>>,
    pub(super) plc_enabled: bool,
    /// The frames the PLC wrote, carried on between its cycles into `plc_frame`.
    pub(super) frames: super::plc_frames::PlcFrames,
    /// Request id of the last M-function announcement.
    pub(super) m_next_id: u32,
    pub(super) m_functions_acked: u64,
}

impl Channel {
    /// M functions the PLC acknowledged (completed handshakes).
    pub fn m_functions_acked(&self) -> u64 {
        self.plc.m_functions_acked
    }

    /// What this channel takes from the PLC this tick (see [`super::plc_io::read_inputs`]).
    pub fn wanted(&self) -> Wanted {
        Wanted {
            dyn_cs: self.stopping.is_none() && !self.control.plc_stop,
            // Not during a stop: the channel interprets nothing then, and an acknowledge taken
            // now would be lost to the PLC's handshake.
            m_ack: self.stopping.is_none()
                && !self.control.plc_stop
                && matches!(self.run.wait, Some(Wait::MFunction { .. })),
        }
    }

    /// What the channel shows the PLC after its last tick, for the machine to write
    /// ([`super::plc_io::write_outputs`]).
    pub fn outputs_mut(&mut self) -> &mut ChannelOutputs {
        &mut self.plc.outputs
    }

    /// Queues an M-function announcement for the machine to post; `false` while the PLC has
    /// not read the previous one.
    pub(super) fn announce(&mut self, code: u32) -> bool {
        if !self.plc.inputs.has_m_unit {
            return true;
        }
        if !self.plc.inputs.m_request_free || self.plc.outputs.m_request.is_some() {
            return false;
        }
        let id = self.plc.m_next_id.wrapping_add(1).max(1);
        self.plc.outputs.m_request = Some(HliMFunctionRequest {
            m_code: code as i32,
            block_nr: self.run.line as i32,
            request_id: id,
        });
        self.plc.inputs.m_request_free = false;
        self.plc.m_next_id = id;
        true
    }

    pub(super) fn fill_outputs(&mut self) {
        let out = &mut self.plc.outputs;
        out.dyn_cs_state = self.pose.tracker.state();
        out.dyn_cs_request = frame_to_hli(self.pose.tracker.applied(), RotationOrder::Zyx).ok();
        let w0 = words_in(&self.pose.tool, self.pose.order);
        let dyncs = words_in(&self.pose.pose_out, self.pose.order);
        let input = words_in(&self.pose.pose_in, self.pose.order);
        out.coord_count = self.motion.programmed.len().min(out.coords.len());
        for i in 0..out.coord_count {
            let angle = (3..6).contains(&i);
            let to_hli = |v: f64| hli_value(v, angle);
            out.coords[i] = HliCoordState {
                w0_position_r: if self.config.kin_trafo_display > 0 && i < 6 {
                    to_hli(w0[i])
                } else {
                    0
                },
                position_dyncs_r: if i < 6 {
                    to_hli(dyncs[i])
                } else {
                    to_hli(self.pose.set_points[i])
                },
                command_position_r: to_hli(self.motion.programmed[i]),
                position_in_dyncs_r: if i < 6 {
                    to_hli(input[i])
                } else {
                    to_hli(self.motion.programmed[i])
                },
            };
        }
        let progress = &mut out.progress;
        progress.block_nr = self.run.line as i32;
        progress.program_state = match self.state {
            RunState::Idle => ProgramState::Idle,
            RunState::Running if self.run.wait.is_some() => ProgramState::Waiting,
            RunState::Running => ProgramState::Running,
            RunState::Finished => ProgramState::Finished,
            RunState::Error => ProgramState::Error,
        };
        progress.tick = self.tick;
        let speed = if self.motion.contour.active() {
            Some(self.motion.contour.path_state().velocity)
        } else {
            self.motion
                .path
                .as_ref()
                .map(|_| self.motion.path_generator.state().velocity)
        };
        // mm/s to um/s; a velocity is finite and far inside the DINT range.
        progress.path_feed_um_s = speed.map_or(0, |v| {
            (v.abs() * 1000.0).round().min(f64::from(i32::MAX)) as i32
        });
        progress.error_id = self.error.as_ref().map_or(ChannelErrorId::None, |e| e.id);
        out.feed_override_applied = if self.motion.path_override.feed_hold || self.control.held {
            0
        } else {
            self.motion.path_override.feed_permille
        };
        out.interface = next_interface(
            &out.interface,
            self.pose
                .published
                .map(|sample| (sample.frame, sample.live)),
        );
    }
}
