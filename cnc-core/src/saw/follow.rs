//! Running a planned synchronising phase tick by tick (no axes: the machine's saw engine
//! and `cnc saw plan` both drive it): the synchronising phase (`nAxisState` 12), the
//! synchronous phase (13), and the rollback behaviour of chapter 8 with the pre-phase (11).

use super::{plan, rollback_stop, Domain, Plan, Profile, SawRequest};
use crate::setpoint::Kinematic;
use hli::calls::saw::sync_mask;
use hli::enums::AxisState;

/// Where a coupled slave is.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// Running the planned phase; `t` is the time since coupling.
    Synchronizing { t: f64 },
    /// Synchronous: `slave = s_ref + ratio (master - m_ref)`.
    Synchron { m_ref: f64, s_ref: f64 },
    /// After a rollback: braking along the follower's `stop` profile (time since the stop
    /// began: `t`).
    Stopping { t: f64 },
    /// After a rollback: standing until the master comes forward over the coupling
    /// position again.
    Standing { position: f64 },
}

/// A slave following its master through the phases of one coupling command.
#[derive(Debug, Clone, Copy)]
pub struct Follower {
    request: SawRequest,
    profile: Profile,
    /// Master position at coupling, and its direction of travel then.
    m0: f64,
    dir: f64,
    phase: Phase,
    /// The stop of a rollback (while `Stopping`).
    stop: Profile,
    /// The slave's software limits (for a new plan after a rollback).
    soft: Option<[f64; 2]>,
    /// The characteristic values of a plan made in a tick (after a rollback), until taken.
    replanned: Option<(crate::cam::CharacValues, usize)>,
}

impl Follower {
    /// A follower for `plan`, made for `request` with the master at `master` at coupling.
    pub fn new(
        request: SawRequest,
        plan: &Plan,
        master: &Kinematic,
        soft: Option<[f64; 2]>,
    ) -> Follower {
        Follower {
            request,
            profile: plan.profile,
            m0: master.position,
            // A master at rest at coupling has no direction yet: it is the one it first moves in.
            dir: master.velocity.signum() * f64::from(master.velocity != 0.0),
            phase: Phase::Synchronizing { t: 0.0 },
            stop: plan.profile,
            soft,
            replanned: None,
        }
    }

    /// The characteristic values of the plan made in the last tick, once, with its number of
    /// pieces: the phase that runs now after a rollback, which a read of the values then
    /// describes.
    pub fn take_replanned(&mut self) -> Option<(crate::cam::CharacValues, usize)> {
        self.replanned.take()
    }

    /// The coupling command.
    pub fn request(&self) -> &SawRequest {
        &self.request
    }

    /// One tick of one slave: its set-point and phase for master set-point `m`; `None` when
    /// the coupling ends (a replan after a rollback that cannot be done).
    pub fn step(
        &mut self,
        m: &Kinematic,
        slave: Kinematic,
        dt: f64,
    ) -> Option<(Kinematic, AxisState)> {
        let ratio = self.request.ratio;
        if self.dir == 0.0 && m.velocity != 0.0 {
            self.dir = m.velocity.signum();
            self.m0 = m.position;
        }
        let tau = (m.position - self.m0) * self.dir;
        let backwards = m.velocity * self.dir < 0.0;
        let lock = self.request.mask & sync_mask::ROLLBACKLOCK != 0;
        let instant = self.request.mask & sync_mask::INSTANTSTOPONROLLBACK != 0;
        let rolled_back = self.dir != 0.0 && tau < 0.0 && backwards;
        match self.phase {
            Phase::Synchronizing { t } => {
                // Cases 2, 3, 5, 7: back over the coupling position before the sync phase.
                if rolled_back {
                    // The stop's first set-point is this tick's (t = dt).
                    self.phase = self.stop(&slave, instant);
                    return self.step(m, slave, dt);
                }
                let t = t + dt;
                // A master that lands on its sync position up to rounding is there: the sync
                // phase begins in this tick, not the next.
                let end = self.profile.length - 1e-9 * (1.0 + self.profile.length);
                let done = match self.profile.domain {
                    Domain::Master { .. } => tau >= end,
                    Domain::Time => t >= end,
                };
                if done {
                    let end = self.profile.eval(self.profile.length);
                    let m_ref = match self.profile.domain {
                        Domain::Master { m0, dir } => m0 + dir * self.profile.length,
                        // The master where the phase ended, between the ticks.
                        Domain::Time => m.position - m.velocity * (t - self.profile.length),
                    };
                    self.phase = Phase::Synchron {
                        m_ref,
                        s_ref: end[0],
                    };
                    return self.step(m, slave, 0.0);
                }
                self.phase = Phase::Synchronizing { t };
                Some((self.profile.slave_at(m, t), AxisState::SlaveSynchronizing))
            }
            Phase::Synchron { m_ref, s_ref } => {
                // Cases 6 and 8 (cases 1 and 4: the coupling holds for every master motion).
                if lock && rolled_back {
                    // The stop's first set-point is this tick's (t = dt).
                    self.phase = self.stop(&slave, instant);
                    return self.step(m, slave, dt);
                }
                Some((m.geared(ratio, (m_ref, s_ref)), AxisState::SlaveSynchronous))
            }
            Phase::Stopping { t } => {
                let t = t + dt;
                let stop = &self.stop;
                if t >= stop.length {
                    self.phase = Phase::Standing {
                        position: stop.eval(stop.length)[0],
                    };
                    return self.step(m, slave, 0.0);
                }
                self.phase = Phase::Stopping { t };
                Some((stop.slave_at(m, t), AxisState::SlavePrephase))
            }
            Phase::Standing { position } => {
                let held = Kinematic {
                    position,
                    ..Kinematic::default()
                };
                // Forward over the coupling position again: synchronise anew from standstill.
                if tau >= 0.0 && m.velocity * self.dir > 0.0 {
                    let next = plan(&self.request, m, &held, self.soft).ok()?;
                    self.profile = next.profile;
                    self.replanned = Some((next.charac.values, next.profile.pieces().len()));
                    self.m0 = m.position;
                    self.phase = Phase::Synchronizing { t: 0.0 };
                    return Some((held, AxisState::SlaveSynchronizing));
                }
                Some((held, AxisState::SlavePrephase))
            }
        }
    }
}

impl Follower {
    /// The stop of a rollback: within one tick (INSTANTSTOPONROLLBACK) or along a
    /// polynomial as fast as deceleration and jerk allow.
    fn stop(&mut self, slave: &Kinematic, instant: bool) -> Phase {
        if instant || (slave.velocity == 0.0 && slave.acceleration == 0.0) {
            Phase::Standing {
                position: slave.position,
            }
        } else {
            self.stop = rollback_stop(slave, &self.request.limits);
            Phase::Stopping { t: 0.0 }
        }
    }
}
