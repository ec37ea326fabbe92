//! The pose pipeline: programmed words -> `#CS` frames -> dynamic CS -> kinematics (with
//! `#TRAFO` on) or per-axis compensation (off), the switching of `#CS` and `#TRAFO`, and the
//! frame the channel publishes on its interface.

use super::*;

/// The pose pipeline's state: kinematics, `#CS` stack, the dynamic CS and the set-points.
pub(super) struct Pose {
    pub(super) order: RotationOrder,
    /// The configured kinematics with the selected tool record on its flange.
    pub(super) kinematics: ToolKinematics,
    /// `#TRAFO` is on.
    pub(super) trafo: bool,
    pub(super) cs_stack: [Isometry3<f64>; CS_DEPTH],
    pub(super) cs_len: usize,
    /// The dynamic CS (tracking slave side).
    pub(super) tracker: Tracker,
    /// Set-points of the channel's axes (joints first under a transformation).
    pub(super) set_points: AxisValues,
    pub(super) joints: Joints,
    /// Tool pose before and after the dynamic CS (base coordinates).
    pub(super) pose_in: Isometry3<f64>,
    pub(super) pose_out: Isometry3<f64>,
    /// Tool pose of the set-points (forward kinematics, once per tick).
    pub(super) tool: Isometry3<f64>,
    /// `#CHANNEL INTERFACE ON`: the channel publishes its tool frame.
    pub(super) interface_on: bool,
    pub(super) published: Option<MasterSample>,
    /// The compensation's A, B, C words applied last tick (without `#TRAFO`): the next ones
    /// are the solution nearest them, so the axes pass a singular orientation continuously.
    pub(super) compensation_abc: [f64; 3],
}

impl Channel {
    /// Set-points of the channel's axes.
    pub fn set_points(&self) -> &AxisValues {
        &self.pose.set_points
    }

    /// Tool pose commanded (after the dynamic CS), base coordinates.
    pub fn pose_out(&self) -> &Isometry3<f64> {
        &self.pose.pose_out
    }

    /// Tool pose before the dynamic CS.
    pub fn pose_in(&self) -> &Isometry3<f64> {
        &self.pose.pose_in
    }

    /// The tool pose of the current set-points by forward kinematics.
    pub fn tool_pose(&self) -> Isometry3<f64> {
        self.pose.tool
    }

    /// The tool pose that the given actual axis positions (per slot of the layout) realise.
    pub fn realised_tool(&self, actual: &[f64]) -> Option<Isometry3<f64>> {
        let mut j = [0.0; 6];
        let n = actual.len().min(6);
        j[..n].copy_from_slice(&actual[..n]);
        self.pose.kinematics.forward(&j).ok()
    }

    /// The tracker.
    pub fn tracker(&self) -> &Tracker {
        &self.pose.tracker
    }

    /// What this channel publishes on its interface this tick.
    pub fn published(&self) -> Option<MasterSample> {
        self.pose.published
    }

    /// Whether the channel follows another channel's interface (it must tick after it).
    pub fn follows_channel(&self) -> Option<usize> {
        match self.pose.tracker.source() {
            Some(MasterSource::Channel(c)) => Some(c),
            _ => None,
        }
    }

    /// The dynamic-CS diagnosis as the text tables of the controller: the history (tick,
    /// state, input position, CS translation and rotation, output position) and the switching
    /// log.
    pub fn dyn_cs_diagnosis(&self) -> String {
        crate::channel::diagnosis::render(self.index, &self.pose.tracker)
    }

    /// The pose pipeline. Under SIMU the tracked pose is computed and shown (history,
    /// `position_dyncs_r`) while the set-points stay on the untracked pose.
    pub(super) fn update_pose(&mut self) {
        let n = self.motion.programmed.len();
        let compensation = *self.pose.tracker.applied();
        let simulating = self.pose.tracker.simulating();
        if self.pose.trafo {
            self.pose.pose_in = self.cs_frame() * self.programmed_frame();
            self.pose.pose_out = self
                .pose
                .tracker
                .option()
                .apply(&compensation, &self.pose.pose_in);
            let commanded = if simulating {
                self.pose.pose_in
            } else {
                self.pose.pose_out
            };
            match self.pose.kinematics.inverse(&commanded, &self.pose.joints) {
                Ok(j) => self.pose.joints = j,
                Err(e) => {
                    // A running program, or a tracking that moves an idle channel: it fails
                    // (once) and the guard brakes its axes.
                    let tracking = self.pose.tracker.state() != DynCsState::Inactive;
                    let failed = self.state == RunState::Error;
                    if !failed && (self.state == RunState::Running || tracking) {
                        self.fail(ChannelFault::PoseUnreachable(e));
                    }
                }
            }
            self.pose.set_points[..6].copy_from_slice(&self.pose.joints);
            self.pose.tool = self
                .pose
                .kinematics
                .forward(&self.pose.joints)
                .unwrap_or(self.pose.tool);
        } else {
            let tracking = self.pose.tracker.state() != DynCsState::Inactive;
            // Axis by axis: the compensation's angles in the channel's own convention, the
            // one its A, B and C words (and the master's published frame) are written in.
            let mut c = [0.0; 6];
            if tracking {
                // Coupled out to no rotation at all (the switch-off's end): the words return
                // to 0 while the tracking is still on, so the guard catches up what the
                // nearest words kept (A-90 C90 is no rotation in Z-Y-Z, 360 none in any
                // order) and the switching lands on the programmed words, never stepping there.
                let landing = self.pose.tracker.state() == DynCsState::Deactivating
                    && compensation.rotation.angle() < 1e-9;
                let near = if landing {
                    [0.0; 3]
                } else {
                    self.pose.compensation_abc
                };
                c = words_near(&compensation, self.pose.order, near);
            }
            self.pose.compensation_abc = [c[3], c[4], c[5]];
            if self.pose.tracker.option() == TrackingOption::TranslationOnly {
                c[3..].fill(0.0); // OPTION=1: the orientation axes keep their programmed values
            }
            if !simulating {
                // SIMU moves no axis: only a compensation the set-points take can lack one.
                self.lacked_compensation(&mut c);
            }
            let mut tracked = [0.0; 6];
            for (i, c) in c.iter().enumerate() {
                tracked[i] = self.motion.programmed[i] + c;
                self.pose.set_points[i] = if simulating {
                    self.motion.programmed[i]
                } else {
                    tracked[i]
                };
                self.pose.joints[i] = self.pose.set_points[i];
            }
            if tracking {
                let mut plain = [0.0; 6];
                plain.copy_from_slice(&self.motion.programmed[..6]);
                self.pose.pose_in = self
                    .pose
                    .kinematics
                    .forward(&plain)
                    .unwrap_or(self.pose.pose_in);
            }
            self.pose.tool = self
                .pose
                .kinematics
                .forward(&self.pose.joints)
                .unwrap_or(self.pose.tool);
            self.pose.pose_out = if simulating {
                self.pose
                    .kinematics
                    .forward(&tracked)
                    .unwrap_or(self.pose.tool)
            } else {
                self.pose.tool
            };
            if !tracking {
                // No compensation: the pose before the dynamic CS is the tool pose.
                self.pose.pose_in = self.pose.tool;
            }
        }
        self.pose.set_points[6..n].copy_from_slice(&self.motion.programmed[6..n]);
    }

    /// A compensation on a pose slot the channel lacks (a 3-axis channel following a master
    /// that turns) cannot be carried out: the channel fails, naming the axis, and its axes
    /// brake; the slot stays at 0.
    fn lacked_compensation(&mut self, c: &mut [f64; 6]) {
        for (slot, v) in c.iter_mut().enumerate() {
            if v.abs() > 1e-9 && !self.layout().has(slot) {
                if self.state != RunState::Error {
                    let axis = AxisName::from(crate::nc::decode::POSE_AXES[slot]);
                    self.fail(ChannelFault::TrackAxisMissing { axis });
                }
                *v = 0.0;
            }
        }
    }

    /// The tick's diagnosis history entry, once the guard has taken the set-points (a
    /// transition that ends when the axes land shows its new state in the tick it ends).
    pub(super) fn record_dyn_cs(&mut self) {
        self.pose
            .tracker
            .record(&self.pose.pose_in, &self.pose.pose_out);
    }

    pub(super) fn cs_frame(&self) -> Isometry3<f64> {
        self.pose.cs_stack[..self.pose.cs_len]
            .iter()
            .fold(Isometry3::identity(), |acc, f| acc * f)
    }

    /// The programmed X..C words as a frame (channel orientation convention).
    pub(super) fn programmed_frame(&self) -> Isometry3<f64> {
        let p = &self.motion.programmed;
        PoseWords {
            xyz: [p[0], p[1], p[2]],
            abc: [p[3], p[4], p[5]],
        }
        .to_frame(self.pose.order)
        .unwrap_or_else(|_| Isometry3::identity())
    }

    pub(super) fn set_programmed_pose(&mut self, pose: &Isometry3<f64>) {
        let w = PoseWords::from_frame(pose, self.pose.order);
        let values = [w.xyz[0], w.xyz[1], w.xyz[2], w.abc[0], w.abc[1], w.abc[2]];
        for (i, v) in values.iter().enumerate() {
            self.motion.programmed[i] = *v;
            self.run.decoder.set_position(i, *v);
        }
    }

    /// `#CS ON|OFF`: a coordinate system pushed on the stack (`frame`: X Y Z A B C) or the
    /// last one taken off; the tool stays where it is.
    pub(super) fn coordinate_system(&mut self, on: bool, frame: [f64; 6]) {
        if !self.pose.trafo {
            self.fail(ChannelFault::CsWithoutTrafo);
            return;
        }
        let before = self.cs_frame();
        if on {
            if self.pose.cs_len == CS_DEPTH {
                self.fail(ChannelFault::CsDepth);
                return;
            }
            let words = PoseWords {
                xyz: [frame[0], frame[1], frame[2]],
                abc: [frame[3], frame[4], frame[5]],
            };
            match offset_frame(&words, false) {
                Ok(f) => {
                    self.pose.cs_stack[self.pose.cs_len] = f;
                    self.pose.cs_len += 1;
                }
                Err(e) => {
                    self.fail(ChannelFault::CsFrame(e));
                    return;
                }
            }
        } else {
            self.pose.cs_len = self.pose.cs_len.saturating_sub(1);
        }
        // The tool stays where it is; its programmed words change.
        let base = before * self.programmed_frame();
        self.set_programmed_pose(&(self.cs_frame().inverse() * base));
    }

    /// `#TRAFO ON|OFF [id]`: the kinematic transformation switched on (the programmed words
    /// become the tool pose) or off (they become the joints again).
    pub(super) fn switch_trafo(&mut self, on: Option<bool>, id: Option<u32>) {
        if let Some(id) = id {
            if id != self.config.kinematics.id {
                let configured = self.config.kinematics.id;
                self.fail(ChannelFault::KinematicNotConfigured { id, configured });
                return;
            }
        }
        match on {
            // The decoder refuses it first; a channel never moves slots it lacks.
            Some(true) if !self.layout().has_pose() => self.fail(ChannelFault::TrafoNeedsPoseAxes),
            Some(true) if !self.pose.trafo => {
                self.pose.trafo = true;
                self.program_tool_pose();
            }
            Some(false) if self.pose.trafo => {
                self.pose.trafo = false;
                self.pose.cs_len = 0;
                for i in 0..6 {
                    self.motion.programmed[i] = self.pose.joints[i];
                    self.run.decoder.set_position(i, self.pose.joints[i]);
                }
            }
            _ => {}
        }
    }

    /// The programmed pose becomes the one of the current tool pose: `#CS` frames and the
    /// dynamic CS's compensation taken off (so that nothing moves on the next tick).
    pub(super) fn program_tool_pose(&mut self) {
        let untracked = if self.tracks_set_points() {
            self.pose
                .tracker
                .option()
                .remove(self.pose.tracker.applied(), &self.pose.tool)
        } else {
            self.pose.tool
        };
        let programmed = self.cs_frame().inverse() * untracked;
        self.set_programmed_pose(&programmed);
    }

    /// Whether the dynamic CS lays its compensation on the set-points (on, not SIMU).
    pub(super) fn tracks_set_points(&self) -> bool {
        self.pose.tracker.state() != DynCsState::Inactive && !self.pose.tracker.simulating()
    }

    /// What the channel publishes on its interface: its tool frame, live while it runs or
    /// brakes, frozen once a failed channel stands.
    pub(super) fn publish(&mut self) {
        let live = self.state != RunState::Error || self.safety.guard.braking();
        self.pose.published = self.pose.interface_on.then_some(MasterSample {
            frame: self.pose.tool,
            live,
        });
    }
}
