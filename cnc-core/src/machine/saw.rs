//! The flying-saw engine (seed 001): MC_GearInVelo / MC_GearInPos couple a slave to a
//! moving master from whatever state the slave is in, run the planned synchronising phase
//! (`nAxisState` 12) and then the synchronous phase (13, slave = ratio x master); MC_GearOut
//! turns the slave into a free axis that keeps its velocity. A master that runs back over
//! the coupling position stops the slave (`nAxisState` 11, the pre-phase) as chapter 8 says
//! for the eight combinations of ROLLBACKLOCK, INSTANTSTOPONROLLBACK and whether the
//! synchronous phase was reached; when the master comes forward over the coupling position
//! again, the slave synchronises anew from where it stands.

use super::engine::{Engine, EngineIo};
use crate::axis::generator::Kinematic;
use crate::axis::{AxisSet, Coupling};
use crate::cam::CharacValues;
use crate::saw::{self, Domain, Limits, Profile, SawRequest, SyncOn};
use hli::calls::{decode_body, reply, CallKind, ErrorCode, HandlerResult};
use hli::enums::{AxisState, CouplingState, SawError};
use hli::saw_calls::{
    sync_mask, SawCharacCall, SawCharacReply, SawGearInCall, SawGearOutCall, SawReply,
    SAW_CHARAC_PART, SAW_ON_POSITION, SAW_ON_VELOCITY, SYNC_POSITION_BASED, SYNC_TIME_BASED,
};
use hli::wire::AcyclicRequest;

/// Where a coupled slave is.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// Running the planned phase; `t` is the time since coupling.
    Synchronizing { t: f64 },
    /// Synchronous: `slave = s_ref + ratio (master - m_ref)`.
    Synchron { m_ref: f64, s_ref: f64 },
    /// After a rollback: braking along `profile` (time since the stop began: `t`).
    Stopping { profile: Profile, t: f64 },
    /// After a rollback: standing until the master comes forward over the coupling
    /// position again.
    Standing { position: f64 },
}

#[derive(Debug, Clone, Copy)]
struct SawSlave {
    master: usize,
    request: SawRequest,
    profile: Profile,
    /// Master position at coupling, and its direction of travel then.
    m0: f64,
    dir: f64,
    phase: Phase,
    /// The slave's software limits (for a new plan after a rollback).
    soft: Option<[f64; 2]>,
}

/// Flying-saw slaves by axis index.
#[derive(Debug)]
pub struct SawEngine {
    cycle_s: f64,
    slaves: Vec<Option<SawSlave>>,
    characs: Vec<Option<CharacValues>>,
}

fn refused(e: SawError) -> HandlerResult {
    reply(&SawReply {
        error_id: e.raw(),
        reserved: 0,
    })
}

fn accepted() -> HandlerResult {
    reply(&SawReply::default())
}

impl SawEngine {
    /// A saw engine for a machine of `axes` axes and tick `cycle_s`.
    pub fn new(axes: usize, cycle_s: f64) -> SawEngine {
        SawEngine {
            cycle_s,
            slaves: vec![None; axes],
            characs: vec![None; axes],
        }
    }

    /// The characteristic values of the last phase planned for `slave`.
    pub fn charac(&self, slave: usize) -> Option<&CharacValues> {
        self.characs.get(slave)?.as_ref()
    }

    /// Whether `slave` is coupled to a master by the saw.
    pub fn coupled(&self, slave: usize) -> bool {
        self.slaves.get(slave).is_some_and(Option::is_some)
    }

    /// Couples `slave` (MC_GearInVelo / MC_GearInPos). Refused with nothing changed.
    fn gear_in(&mut self, slave: usize, call: &SawGearInCall, axes: &mut AxisSet) -> HandlerResult {
        let master = call.master as usize;
        if master == slave || axes.axis(master).is_none() {
            return refused(SawError::NoSuchMaster);
        }
        let Some(axis) = axes.axis(slave) else {
            return Err(ErrorCode::InvalidTarget);
        };
        let ours = self.coupled(slave);
        if axis.coupling().is_some() && !ours {
            return reply(&SawReply {
                error_id: hli::enums::AxisError::Coupled.raw(),
                reserved: 0,
            });
        }
        let on = match call.target {
            SAW_ON_VELOCITY => SyncOn::Velocity,
            SAW_ON_POSITION => SyncOn::Position {
                master: call.master_sync_position,
                slave: call.slave_sync_position,
            },
            _ => return refused(SawError::Mode),
        };
        let time_based = match call.sync_mode {
            SYNC_POSITION_BASED => false,
            SYNC_TIME_BASED => true,
            _ => return refused(SawError::Mode),
        };
        let ratio = match saw::gear_ratio(call.ratio_numerator, call.ratio_denominator) {
            Ok(r) => r,
            Err(e) => return refused(e),
        };
        // 0 takes the axis's own limit (the seed: "if none is given").
        let own = axis.config().dynamics;
        let or = |given: f64, own: f64| if given == 0.0 { own } else { given };
        let request = SawRequest {
            on,
            time_based,
            mask: call.mask,
            ratio,
            limits: Limits {
                velocity: or(call.velocity, own.velocity),
                acceleration: or(call.acceleration, own.acceleration),
                deceleration: or(call.deceleration, own.deceleration),
                jerk: or(call.jerk, own.jerk),
            },
        };
        let m = axes.axis(master).map(|a| a.setpoint()).unwrap_or_default();
        let s = axis.setpoint();
        let plan = match saw::plan(&request, &m, &s, axis.config().soft_limits) {
            Ok(p) => p,
            Err(e) => return refused(e),
        };
        let kind = match on {
            SyncOn::Velocity => CouplingState::GearVelocity,
            SyncOn::Position { .. } => CouplingState::GearPosition,
        };
        let axis = axes.axis_mut(slave).expect("checked above");
        if ours {
            // A new command on a coupled slave: replanned from where it is, no jump.
            axis.decouple();
        }
        if let Err(e) = axis.couple(Coupling {
            kind,
            master: master as i32,
            phase: AxisState::SlaveSynchronizing,
        }) {
            self.slaves[slave] = None;
            return reply(&SawReply {
                error_id: e.raw(),
                reserved: 0,
            });
        }
        self.slaves[slave] = Some(SawSlave {
            master,
            request,
            profile: plan.profile,
            m0: m.position,
            dir: if m.velocity < 0.0 { -1.0 } else { 1.0 },
            phase: Phase::Synchronizing { t: 0.0 },
            soft: axis.config().soft_limits,
        });
        self.characs[slave] = Some(plan.charac.values);
        accepted()
    }

    fn gear_out(&mut self, slave: usize, axes: &mut AxisSet) -> HandlerResult {
        if self.slaves.get_mut(slave).and_then(Option::take).is_none() {
            return refused(SawError::NotCoupled);
        }
        if let Some(axis) = axes.axis_mut(slave) {
            axis.decouple();
        }
        accepted()
    }

    fn read_charac(&self, slave: usize, call: &SawCharacCall) -> HandlerResult {
        let Some(c) = self.charac(slave) else {
            return reply(&SawCharacReply {
                error_id: SawError::NotCoupled.raw(),
                ..SawCharacReply::default()
            });
        };
        let fields = c.fields();
        let from = call.part as usize * SAW_CHARAC_PART;
        if from >= fields.len() {
            return Err(ErrorCode::InvalidData);
        }
        let mut values = [0.0; SAW_CHARAC_PART];
        for (v, (_, f)) in values.iter_mut().zip(fields[from..].iter()) {
            *v = *f;
        }
        reply(&SawCharacReply {
            error_id: 0,
            part: call.part,
            values,
        })
    }
}

/// One tick of one slave: its set-point and phase for master set-point `m`; `None` when
/// the coupling ends (a replan after a rollback that cannot be done).
fn step(
    s: &mut SawSlave,
    m: &Kinematic,
    slave: Kinematic,
    dt: f64,
) -> Option<(Kinematic, AxisState)> {
    let ratio = s.request.ratio;
    let tau = (m.position - s.m0) * s.dir;
    let backwards = m.velocity * s.dir < 0.0;
    let lock = s.request.mask & sync_mask::ROLLBACKLOCK != 0;
    let instant = s.request.mask & sync_mask::INSTANTSTOPONROLLBACK != 0;
    let rolled_back = tau < 0.0 && backwards;
    match s.phase {
        Phase::Synchronizing { t } => {
            // Cases 2, 3, 5, 7: back over the coupling position before the sync phase.
            if rolled_back {
                s.phase = stop(&slave, instant, &s.request.limits);
                return step(s, m, slave, 0.0);
            }
            let t = t + dt;
            // A master that lands on its sync position up to rounding is there: the sync
            // phase begins in this tick, not the next.
            let end = s.profile.length - 1e-9 * (1.0 + s.profile.length);
            let done = match s.profile.domain {
                Domain::Master { .. } => tau >= end,
                Domain::Time => t >= end,
            };
            if done {
                let end = s.profile.eval(s.profile.length);
                let m_ref = match s.profile.domain {
                    Domain::Master { m0, dir } => m0 + dir * s.profile.length,
                    // The master where the phase ended, between the ticks.
                    Domain::Time => m.position - m.velocity * (t - s.profile.length),
                };
                s.phase = Phase::Synchron {
                    m_ref,
                    s_ref: end[0],
                };
                return step(s, m, slave, 0.0);
            }
            s.phase = Phase::Synchronizing { t };
            Some((s.profile.slave_at(m, t), AxisState::SlaveSynchronizing))
        }
        Phase::Synchron { m_ref, s_ref } => {
            // Cases 6 and 8 (cases 1 and 4: the coupling holds for every master motion).
            if lock && rolled_back {
                s.phase = stop(&slave, instant, &s.request.limits);
                return step(s, m, slave, 0.0);
            }
            Some((
                Kinematic {
                    position: s_ref + ratio * (m.position - m_ref),
                    velocity: ratio * m.velocity,
                    acceleration: ratio * m.acceleration,
                    jerk: ratio * m.jerk,
                },
                AxisState::SlaveSynchronous,
            ))
        }
        Phase::Stopping { profile, t } => {
            let t = t + dt;
            if t >= profile.length {
                s.phase = Phase::Standing {
                    position: profile.eval(profile.length)[0],
                };
                return step(s, m, slave, 0.0);
            }
            s.phase = Phase::Stopping { profile, t };
            Some((profile.slave_at(m, t), AxisState::SlavePrephase))
        }
        Phase::Standing { position } => {
            let held = Kinematic {
                position,
                ..Kinematic::default()
            };
            // Forward over the coupling position again: synchronise anew from standstill.
            if tau >= 0.0 && m.velocity * s.dir > 0.0 {
                let plan = saw::plan(&s.request, m, &held, s.soft).ok()?;
                s.profile = plan.profile;
                s.m0 = m.position;
                s.phase = Phase::Synchronizing { t: 0.0 };
                return Some((held, AxisState::SlaveSynchronizing));
            }
            Some((held, AxisState::SlavePrephase))
        }
    }
}

/// The stop of a rollback: within one tick (INSTANTSTOPONROLLBACK) or along a 5th-order
/// polynomial as fast as deceleration and jerk allow.
fn stop(slave: &Kinematic, instant: bool, limits: &Limits) -> Phase {
    if instant || (slave.velocity == 0.0 && slave.acceleration == 0.0) {
        Phase::Standing {
            position: slave.position,
        }
    } else {
        Phase::Stopping {
            profile: saw::rollback_stop(slave, limits),
            t: 0.0,
        }
    }
}

impl Engine for SawEngine {
    fn name(&self) -> &'static str {
        "flying saw"
    }

    fn tick(&mut self, io: &mut EngineIo<'_, '_>) {
        let dt = self.cycle_s;
        for (i, slot) in self.slaves.iter_mut().enumerate() {
            let Some(s) = slot else { continue };
            let Some(m) = io.axes.axis(s.master).map(|a| a.setpoint()) else {
                continue;
            };
            let Some(axis) = io.axes.axis_mut(i) else {
                continue;
            };
            // A slave that lost its coupling (fault, power off) is no longer the saw's.
            let held = axis.coupling().is_some_and(|c| {
                matches!(
                    c.kind,
                    CouplingState::GearVelocity | CouplingState::GearPosition
                )
            });
            if !held {
                *slot = None;
                continue;
            }
            match step(s, &m, axis.setpoint(), dt) {
                Some((set, phase)) => axis.drive_coupled(set, phase),
                None => {
                    *slot = None;
                    axis.decouple();
                }
            }
        }
    }

    fn handle(
        &mut self,
        kind: CallKind,
        request: &AcyclicRequest,
        axes: &mut AxisSet,
    ) -> Option<HandlerResult> {
        let slave = request.target as usize;
        let known = slave < self.slaves.len();
        Some(match kind {
            CallKind::SawGearIn if !known => Err(ErrorCode::InvalidTarget),
            CallKind::SawGearIn => match decode_body::<SawGearInCall>(request) {
                Ok(call) => self.gear_in(slave, &call, axes),
                Err(e) => Err(e),
            },
            CallKind::SawGearOut => match decode_body::<SawGearOutCall>(request) {
                Ok(_) => self.gear_out(slave, axes),
                Err(e) => Err(e),
            },
            CallKind::SawCharac => match decode_body::<SawCharacCall>(request) {
                Ok(call) => self.read_charac(slave, &call),
                Err(e) => Err(e),
            },
            _ => return None,
        })
    }

    fn reset(&mut self, axes: &mut AxisSet) {
        for (i, slot) in self.slaves.iter_mut().enumerate() {
            if slot.take().is_some() {
                if let Some(axis) = axes.axis_mut(i) {
                    axis.decouple();
                }
            }
        }
    }
}
