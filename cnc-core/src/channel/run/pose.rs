//! The pose pipeline (programmed words -> `#CS` -> dynamic CS -> kinematics) and the values
//! the channel shows the PLC after its tick.

use super::*;

impl Channel {
    /// The pose pipeline. Under SIMU the tracked pose is computed and shown (history,
    /// `position_dyncs_r`) while the set-points stay on the untracked pose.
    pub(super) fn update_pose(&mut self) {
        let n = self.programmed.len();
        let compensation = *self.tracker.applied();
        let simulating = self.tracker.simulating();
        if self.trafo {
            self.pose_in = self.cs_frame() * self.programmed_frame();
            self.pose_out = self.tracker.option().apply(&compensation, &self.pose_in);
            let commanded = if simulating {
                self.pose_in
            } else {
                self.pose_out
            };
            match self.kinematics.inverse(&commanded, &self.joints) {
                Ok(j) => self.joints = j,
                Err(e) => {
                    // A running program, or a tracking that moves an idle channel: it fails
                    // (once) and the guard brakes its axes.
                    let tracking = self.tracker.state() != DynCsState::Inactive;
                    let failed = self.state == RunState::Error;
                    if !failed && (self.state == RunState::Running || tracking) {
                        self.fail(ChannelErrorId::Kinematics, format!("pose unreachable: {e}"));
                    }
                }
            }
            self.set_points[..6].copy_from_slice(&self.joints);
            self.tool = self.kinematics.forward(&self.joints).unwrap_or(self.tool);
        } else {
            let tracking = self.tracker.state() != DynCsState::Inactive;
            let mut c = if tracking {
                words(&compensation)
            } else {
                [0.0; 6]
            };
            if self.tracker.option() == TrackingOption::TranslationOnly {
                c[3..].fill(0.0); // OPTION=1: the orientation axes keep their programmed values
            }
            let mut tracked = [0.0; 6];
            for (i, c) in c.iter().enumerate() {
                tracked[i] = self.programmed[i] + c;
                self.set_points[i] = if simulating {
                    self.programmed[i]
                } else {
                    tracked[i]
                };
                self.joints[i] = self.set_points[i];
            }
            if tracking {
                let mut plain = [0.0; 6];
                plain.copy_from_slice(&self.programmed[..6]);
                self.pose_in = self.kinematics.forward(&plain).unwrap_or(self.pose_in);
            }
            self.tool = self.kinematics.forward(&self.joints).unwrap_or(self.tool);
            self.pose_out = if simulating {
                self.kinematics.forward(&tracked).unwrap_or(self.tool)
            } else {
                self.tool
            };
            if !tracking {
                // No compensation: the pose before the dynamic CS is the tool pose.
                self.pose_in = self.tool;
            }
        }
        self.set_points[6..n].copy_from_slice(&self.programmed[6..n]);
        self.tracker.record(&self.pose_in, &self.pose_out);
    }

    pub(super) fn fill_outputs(&mut self) {
        let out = &mut self.outputs;
        out.dyn_cs_state = self.tracker.state();
        out.dyn_cs_request = frame_to_hli(self.tracker.applied(), RotationOrder::Zyx).ok();
        let w0 = words_in(&self.tool, self.order);
        let dyncs = words_in(&self.pose_out, self.order);
        out.coord_count = self.programmed.len().min(out.coords.len());
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
                    to_hli(self.set_points[i])
                },
                command_position_r: to_hli(self.programmed[i]),
                fill_up_1: 0,
            };
        }
        let progress = &mut out.progress;
        progress.block_nr = self.line as i32;
        progress.program_state = match self.state {
            RunState::Idle => ProgramState::Idle,
            RunState::Running if self.wait.is_some() => ProgramState::Waiting,
            RunState::Running => ProgramState::Running,
            RunState::Finished => ProgramState::Finished,
            RunState::Error => ProgramState::Error,
        };
        progress.tick = self.tick;
        progress.path_feed_um_s = match &self.path {
            // mm/s to um/s; a velocity is finite and far inside the DINT range.
            Some(_) => (self.path_generator.state().velocity.abs() * 1000.0)
                .round()
                .min(f64::from(i32::MAX)) as i32,
            None => 0,
        };
        progress.error_id = self.error.as_ref().map_or(ChannelErrorId::None, |e| e.id);
        out.feed_override_applied = if self.path_override.feed_hold {
            0
        } else {
            self.path_override.feed_permille
        };
        out.interface = next_interface(
            &out.interface,
            self.published.map(|sample| (sample.frame, sample.live)),
        );
    }
}
