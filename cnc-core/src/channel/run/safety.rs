//! What a channel does when something goes wrong: the set-points pass the [`JointGuard`]
//! every tick, a failure latches it (the axes brake on their own limits and hold), and the
//! channel takes the held position over before it hands the set-points back. A reset clears
//! the channel's and the tracker's errors at rest.

use super::error::LagExcess;
use super::{Channel, ChannelError, ChannelFault, RunState};
use crate::channel::catch_up::NoProfile;
use crate::channel::dyn_cs::TrackError;
use crate::channel::guard::JointGuard;
use hli::enums::DynCsState;
use kinematics::Kinematics;
use nalgebra::Isometry3;

/// Why [`Channel::reset`] refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum ResetError {
    /// The channel's axes are still moving (a program runs, or they brake).
    #[error("the channel is moving: stop it and wait for rest first")]
    Moving,
    /// The dynamic CS is on and may be moving the axes: switch it off first.
    #[error("tracking is on: switch it off first")]
    Tracking,
}

/// The guard and a failure waiting to latch it.
pub(super) struct Safety {
    /// Checks the set-points while tracking and brakes the axes when the channel fails.
    pub(super) guard: JointGuard,
    /// The channel failed this tick: the guard latches at the end of it.
    pub(super) latch_pending: bool,
    /// The axes' lag behind the compensation at the tool this tick (0 when they follow it
    /// exactly), and the largest seen since start-up.
    pub(super) lag: Lag,
    pub(super) lag_peak: Lag,
    /// The smallest lag of the catch-up under way (`None`: none runs). A switching's step
    /// may be as large as the program or the PLC makes it, but its lag may only shrink: it
    /// grows back by at most `track_lag_max` above this floor.
    pub(super) lag_floor: Option<Lag>,
}

/// A lag at the tool: distance (mm) and angle (degrees).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Lag {
    /// mm.
    pub translation: f64,
    /// Degrees.
    pub rotation: f64,
}

impl Lag {
    /// Between the tool pose commanded and the one wanted.
    fn between(commanded: &Isometry3<f64>, wanted: &Isometry3<f64>) -> Self {
        Self {
            translation: (commanded.translation.vector - wanted.translation.vector).norm(),
            rotation: commanded.rotation.angle_to(&wanted.rotation).to_degrees(),
        }
    }
}

impl Channel {
    pub(super) fn fail(&mut self, fault: ChannelFault) {
        let id = fault.id();
        // A tracking slave that fails can no longer follow (the guard brakes its axes).
        if matches!(
            self.pose.tracker.state(),
            DynCsState::Activating | DynCsState::Active | DynCsState::Deactivating
        ) {
            self.pose.tracker.fail(TrackError::ChannelFailed(id));
        }
        self.error = Some(ChannelError {
            line: self.run.line,
            id,
            fault,
        });
        self.control.aborted |= self.state == RunState::Running;
        self.control.error_unshown = true;
        self.state = RunState::Error;
        self.drop_path();
        self.run.wait = None;
        self.safety.latch_pending = true;
        for (_, active) in &mut self.motion.independent {
            *active = false;
        }
    }

    /// The guard's stage of the tick, after the pose pipeline: checks the new set-points
    /// while tracking, latches on any failure, and while latched replaces the set-points by
    /// the guard's braking or held ones.
    pub(super) fn guard_set_points(&mut self, tracked: bool) {
        self.safety.lag = Lag::default();
        if !self.safety.guard.lagging() {
            self.safety.lag_floor = None;
        }
        if !self.safety.guard.latched() && (tracked || self.safety.guard.lagging()) {
            self.check_tracked_step();
        }
        if !self.safety.guard.latched()
            && (self.safety.latch_pending || self.pose.tracker.state() == DynCsState::Error)
        {
            self.safety.guard.latch();
        }
        self.safety.latch_pending = false;
        if self.safety.guard.latched() {
            self.safety.guard.step(&mut self.pose.set_points);
            self.take_joints_from_set_points();
            let settled = !self.safety.guard.braking()
                && self.pose.tracker.state() == DynCsState::Inactive
                && self.state != RunState::Running;
            if settled {
                self.resync_to_set_points();
                self.safety.guard.release();
            }
        } else {
            self.safety.guard.accept(&self.pose.set_points);
        }
        // Latched, the guard owns the set-points: nothing lags, a switch-off from ERROR
        // ends without the axes.
        let lagging = self.safety.guard.lagging();
        if !self.safety.guard.latched() {
            let lag = self.safety.lag;
            self.pose
                .tracker
                .note_lag(lagging.then_some((lag.translation, lag.rotation)));
        }
        self.pose.tracker.land(lagging);
        self.publish();
    }

    /// Whether the channel's axes still move without a program: a soft coupling in or out,
    /// or the guard's braking.
    pub fn settling(&self) -> bool {
        self.pose.tracker.in_transition()
            || self.safety.guard.braking()
            || self.safety.guard.lagging()
    }

    /// The axes' lag behind the compensation this tick, and the largest since start-up.
    pub fn tracking_lag(&self) -> (Lag, Lag) {
        (self.safety.lag, self.safety.lag_peak)
    }

    /// A tracker that went to ERROR in its own tick (a frame it could not use) stops the
    /// program: a slave that can no longer follow must not go on as if it did.
    pub(super) fn fail_on_tracking_error(&mut self) {
        if self.pose.tracker.state() != DynCsState::Error
            || self.state != RunState::Running
            || self.stopping.is_some()
            || self.control.plc_stop
        {
            return;
        }
        let cause = self
            .pose
            .tracker
            .last_error()
            .unwrap_or(TrackError::BadFrame);
        self.fail(ChannelFault::Tracking(cause));
    }

    /// While the dynamic CS acts on the set-points (or the axes still catch up with a step
    /// of it): a step beyond an axis's limits is caught up within them (see
    /// `channel::catch_up`). The channel fails, and its axes brake, when following the master
    /// leaves a lag beyond `track_lag_max`, when no catch-up profile is found, or when what
    /// is commanded still breaks a limit.
    pub(super) fn check_tracked_step(&mut self) {
        if self.pose.tracker.state() == DynCsState::Error {
            return; // latched below; the first cause stays the reported one
        }
        let wanted = self.pose.tool;
        if let Err(NoProfile { axis }) = self.safety.guard.follow(&mut self.pose.set_points) {
            let error = TrackError::NoCatchUp { axis: axis as u8 };
            self.pose.tracker.fail(error);
            self.fail_unless_failed(ChannelFault::Tracking(error));
            return;
        }
        if self.safety.guard.lagging() {
            self.take_joints_from_set_points();
            self.note_lag(&wanted);
            if let Some(excess) = self.lag_excess() {
                self.pose.tracker.fail(TrackError::LagBeyondBound {
                    rotation: excess.rotation > excess.max_rotation,
                });
                self.fail_unless_failed(ChannelFault::TrackLag(excess));
                return;
            }
        }
        let Some(violation) = self.safety.guard.check(&self.pose.set_points) else {
            return;
        };
        self.pose.tracker.fail(TrackError::JointLimit {
            axis: violation.axis as u8,
            kind: violation.kind,
        });
        self.fail_unless_failed(ChannelFault::TrackedStep(violation));
    }

    /// Also a channel whose program ended in this tick fails: its last step was refused.
    fn fail_unless_failed(&mut self, fault: ChannelFault) {
        if self.state != RunState::Error {
            self.fail(fault);
        }
    }

    /// The lag between the tool pose commanded and the `wanted` one.
    fn note_lag(&mut self, wanted: &Isometry3<f64>) {
        let lag = Lag::between(&self.pose.tool, wanted);
        let peak = &mut self.safety.lag_peak;
        peak.translation = peak.translation.max(lag.translation);
        peak.rotation = peak.rotation.max(lag.rotation);
        self.safety.lag = lag;
        self.safety.lag_floor = Some(match self.safety.lag_floor {
            None => lag,
            Some(floor) => Lag {
                translation: floor.translation.min(lag.translation),
                rotation: floor.rotation.min(lag.rotation),
            },
        });
    }

    /// A lag beyond `track_lag_max` while following the master (ACTIVE). A switching
    /// without filter (ACTIVATING, DEACTIVATING, a frozen master taken over again) is caught
    /// up whatever the size of its step, the program's or the PLC's choice, and its lag may
    /// grow while the axes take up the master's velocity; but a master faster than an axis
    /// may go (its lag can only grow) ends at the bound above the catch-up's smallest lag.
    fn lag_excess(&self) -> Option<LagExcess> {
        let bound = self.config.track_lag_max;
        let lag = self.safety.lag;
        let floor = match self.pose.tracker.state() {
            DynCsState::Active => Lag::default(),
            DynCsState::Activating | DynCsState::Deactivating
                if self.safety.guard.catch_up().outrun() =>
            {
                self.safety.lag_floor.unwrap_or(lag)
            }
            _ => return None,
        };
        let beyond = lag.translation > floor.translation + bound.translation
            || lag.rotation > floor.rotation + bound.rotation;
        beyond.then_some(LagExcess {
            translation: lag.translation,
            rotation: lag.rotation,
            max_translation: bound.translation,
            max_rotation: bound.rotation,
            floor: (floor.translation, floor.rotation),
        })
    }

    /// Joints and tool pose of the set-points the guard gave (under a transformation).
    pub(super) fn take_joints_from_set_points(&mut self) {
        let n = self.pose.joints.len().min(self.pose.set_points.len());
        self.pose.joints[..n].copy_from_slice(&self.pose.set_points[..n]);
        self.pose.tool = self
            .pose
            .kinematics
            .forward(&self.pose.joints)
            .unwrap_or(self.pose.tool);
    }

    /// The channel's programmed position becomes the position its axes stand at (the
    /// tracker is INACTIVE, so no compensation lies between them): the next program, or the
    /// next switch-on, starts from there without a step.
    pub(super) fn resync_to_set_points(&mut self) {
        self.drop_path();
        for (_, active) in &mut self.motion.independent {
            *active = false;
        }
        let n = self.motion.programmed.len();
        if self.pose.trafo {
            if let Ok(tool) = self.pose.kinematics.forward(&self.pose.joints) {
                self.pose.tool = tool;
                self.program_tool_pose();
            }
        } else {
            for i in 0..n.min(6) {
                self.motion.programmed[i] = self.pose.set_points[i];
                self.run.decoder.set_position(i, self.pose.set_points[i]);
            }
        }
        for i in 6..n {
            self.motion.programmed[i] = self.pose.set_points[i];
            self.run.decoder.set_position(i, self.pose.set_points[i]);
        }
        self.pose.pose_in = self.pose.tool;
        self.pose.pose_out = self.pose.tool;
    }

    /// After a RESET of its axes: the channel's set-points and programmed position become
    /// where the axes stand (an axis that faulted stood away from its set-point).
    /// `reset` has bit `i` set for each axis `i` that was reset (the others keep theirs).
    pub fn adopt_positions(&mut self, actual: &crate::setpoint::AxisValues, reset: u32) {
        let n = self.pose.set_points.len().min(actual.len()).min(32);
        if reset == 0 {
            return;
        }
        for i in (0..n).filter(|i| reset & (1 << i) != 0) {
            self.pose.set_points[i] = actual[i];
        }
        self.take_joints_from_set_points();
        self.resync_to_set_points();
        self.safety.guard.rest_at(&self.pose.set_points);
    }

    /// Clears the channel's error and the tracker's ERROR (tracking off at once: the
    /// compensation the axes hold becomes part of the programmed position), ends a program
    /// and leaves the channel idle where its axes stand. Refused while the axes move.
    pub fn reset(&mut self) -> Result<(), ResetError> {
        // A tracker that failed this tick: the guard latches at its end and brakes from the
        // compensation's motion; dropping the compensation now would be a step.
        let latch_due =
            self.pose.tracker.state() == DynCsState::Error && !self.safety.guard.latched();
        if latch_due
            || self.safety.guard.braking()
            || self.path_active()
            || self.motion.independent.iter().any(|g| g.1)
        {
            return Err(ResetError::Moving);
        }
        if !matches!(
            self.pose.tracker.state(),
            DynCsState::Inactive | DynCsState::Error
        ) {
            return Err(ResetError::Tracking);
        }
        self.pose.tracker.reset();
        self.error = None;
        self.state = RunState::Idle;
        self.run.wait = None;
        self.run.pending.clear();
        self.run.pending_at = 0;
        self.safety.latch_pending = false;
        self.resync_to_set_points();
        self.safety.guard.release();
        self.safety.guard.accept(&self.pose.set_points);
        Ok(())
    }
}
