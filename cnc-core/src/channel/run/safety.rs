//! What a channel does when something goes wrong: the set-points pass the [`JointGuard`]
//! every tick, a failure latches it (the axes brake on their own limits and hold), and the
//! channel takes the held position over before it hands the set-points back. A reset clears
//! the channel's and the tracker's errors at rest.

use super::{Channel, RunState};
use crate::channel::dyn_cs::{MasterSample, TrackError};
use hli::enums::{ChannelErrorId, DynCsState};
use kinematics::Kinematics;

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

impl Channel {
    /// The guard's stage of the tick, after the pose pipeline: checks the new set-points
    /// while tracking, latches on any failure, and while latched replaces the set-points by
    /// the guard's braking or held ones.
    pub(super) fn guard_set_points(&mut self, tracked: bool) {
        if !self.guard.latched() && tracked {
            self.check_tracked_step();
        }
        if !self.guard.latched()
            && (self.latch_pending || self.tracker.state() == DynCsState::Error)
        {
            self.guard.latch();
        }
        self.latch_pending = false;
        if self.guard.latched() {
            self.guard.step(&mut self.set_points);
            self.take_joints_from_set_points();
            let settled = !self.guard.braking()
                && self.tracker.state() == DynCsState::Inactive
                && self.state != RunState::Running;
            if settled {
                self.resync_to_set_points();
                self.guard.release();
            }
        } else {
            self.guard.accept(&self.set_points);
        }
        self.publish();
    }

    /// Whether the channel's axes still move without a program: a soft coupling in or out,
    /// or the guard's braking.
    pub fn settling(&self) -> bool {
        self.tracker.in_transition() || self.guard.braking()
    }

    /// A tracker that went to ERROR in its own tick (a frame it could not use) stops the
    /// program: a slave that can no longer follow must not go on as if it did.
    pub(super) fn fail_on_tracking_error(&mut self) {
        if self.tracker.state() != DynCsState::Error
            || self.state != RunState::Running
            || self.stopping.is_some()
        {
            return;
        }
        let cause = self.tracker.last_error().unwrap_or(TrackError::BadFrame);
        self.fail(ChannelErrorId::Tracking, format!("tracking: {cause}"));
    }

    /// While the dynamic CS acts on the set-points, a step beyond an axis's velocity or
    /// acceleration limit is refused: the tracker goes to ERROR and the channel fails.
    fn check_tracked_step(&mut self) {
        if self.tracker.state() == DynCsState::Error {
            return; // latched below; the first cause stays the reported one
        }
        let Some(violation) = self.guard.check(&self.set_points) else {
            return;
        };
        self.tracker.fail(TrackError::JointLimit {
            axis: violation.axis as u8,
            kind: violation.kind,
        });
        // Also a channel whose program ended in this tick: its last step was refused.
        if self.state != RunState::Error {
            self.fail(
                ChannelErrorId::Tracking,
                format!("tracked step refused: {violation}"),
            );
        }
    }

    /// The programmed pose becomes the one of the current tool pose: `#CS` frames and the
    /// dynamic CS's compensation taken off (so that nothing moves on the next tick).
    pub(super) fn program_tool_pose(&mut self) {
        let untracked = if self.tracks_set_points() {
            self.tracker
                .option()
                .remove(self.tracker.applied(), &self.tool)
        } else {
            self.tool
        };
        let programmed = self.cs_frame().inverse() * untracked;
        self.set_programmed_pose(&programmed);
    }

    /// Whether the dynamic CS lays its compensation on the set-points (on, not SIMU).
    pub(super) fn tracks_set_points(&self) -> bool {
        self.tracker.state() != DynCsState::Inactive && !self.tracker.simulating()
    }

    /// Joints and tool pose of the set-points the guard gave (under a transformation).
    fn take_joints_from_set_points(&mut self) {
        let n = self.joints.len().min(self.set_points.len());
        self.joints[..n].copy_from_slice(&self.set_points[..n]);
        self.tool = self.kinematics.forward(&self.joints).unwrap_or(self.tool);
    }

    /// What the channel publishes on its interface: its tool frame, live while it runs or
    /// brakes, frozen once a failed channel stands.
    pub(super) fn publish(&mut self) {
        let live = self.state != RunState::Error || self.guard.braking();
        self.published = self.interface_on.then_some(MasterSample {
            frame: self.tool,
            live,
        });
    }

    /// The channel's programmed position becomes the position its axes stand at (the
    /// tracker is INACTIVE, so no compensation lies between them): the next program, or the
    /// next switch-on, starts from there without a step.
    fn resync_to_set_points(&mut self) {
        self.path = None;
        for (_, active) in &mut self.independent {
            *active = false;
        }
        let n = self.programmed.len();
        if self.trafo {
            if let Ok(tool) = self.kinematics.forward(&self.joints) {
                self.tool = tool;
                self.program_tool_pose();
            }
        } else {
            for i in 0..n.min(6) {
                self.programmed[i] = self.set_points[i];
                self.decoder.set_position(i, self.set_points[i]);
            }
        }
        for i in 6..n {
            self.programmed[i] = self.set_points[i];
            self.decoder.set_position(i, self.set_points[i]);
        }
        self.pose_in = self.tool;
        self.pose_out = self.tool;
    }

    /// Clears the channel's error and the tracker's ERROR (tracking off at once: the
    /// compensation the axes hold becomes part of the programmed position), ends a program
    /// and leaves the channel idle where its axes stand. Refused while the axes move.
    pub fn reset(&mut self) -> Result<(), ResetError> {
        if self.guard.braking() || self.path.is_some() || self.independent.iter().any(|g| g.1) {
            return Err(ResetError::Moving);
        }
        if !matches!(
            self.tracker.state(),
            DynCsState::Inactive | DynCsState::Error
        ) {
            return Err(ResetError::Tracking);
        }
        self.tracker.reset();
        self.error = None;
        self.state = RunState::Idle;
        self.wait = None;
        self.pending.clear();
        self.pending_at = 0;
        self.latch_pending = false;
        self.resync_to_set_points();
        self.guard.release();
        self.guard.accept(&self.set_points);
        Ok(())
    }
}
