//! The flying-saw engine (seed 001): MC_GearInVelo / MC_GearInPos couple a slave to a
//! moving master from whatever state the slave is in, run the planned synchronising phase
//! (`nAxisState` 12) and then the synchronous phase (13, slave = ratio x master); MC_GearOut
//! turns the slave into a free axis that keeps its velocity. A master that runs back over
//! the coupling position stops the slave (`nAxisState` 11, the pre-phase) as chapter 8 says
//! for the eight combinations of ROLLBACKLOCK, INSTANTSTOPONROLLBACK and whether the
//! synchronous phase was reached; when the master comes forward over the coupling position
//! again, the slave synchronises anew from where it stands.

use super::engine::{Engine, EngineIo};
use crate::axis::{AxisSet, Coupling};
use crate::cam::CharacValues;
use crate::saw::{self, Follower, Limits, SawRequest, SyncOn};
use hli::calls::{decode_body, reply, CallKind, ErrorCode, HandlerResult};
use hli::enums::{AxisState, CouplingState, SawError};
use hli::saw_calls::{
    SawCharacCall, SawCharacReply, SawGearInCall, SawGearOutCall, SawReply, SAW_CHARAC_PART,
    SAW_ON_POSITION, SAW_ON_VELOCITY, SYNC_POSITION_BASED, SYNC_TIME_BASED,
};
use hli::wire::AcyclicRequest;

#[derive(Debug, Clone, Copy)]
struct SawSlave {
    master: usize,
    follower: Follower,
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
            follower: Follower::new(request, &plan, &m, axis.config().soft_limits),
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
            match s.follower.step(&m, axis.setpoint(), dt) {
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
