//! The flying-saw engine (seed 001): MC_GearInVelo / MC_GearInPos couple a slave to a
//! moving master from whatever state the slave is in, run the planned synchronising phase
//! (`nAxisState` 12) and then the synchronous phase (13, slave = ratio x master); MC_GearOut
//! turns the slave into a free axis that keeps its velocity. A master that runs back over
//! the coupling position stops the slave (`nAxisState` 11, the pre-phase) as chapter 8 says
//! for the eight combinations of ROLLBACKLOCK, INSTANTSTOPONROLLBACK and whether the
//! synchronous phase was reached; when the master comes forward over the coupling position
//! again, the slave synchronises anew from where it stands.

use crate::axis::{AxisSet, Coupling, Lease};
use crate::cam::CharacValues;
use crate::machine::engine::{Call, Engine, EngineIo, Resource};
use crate::machine::engines::{no_config, Config, EngineDef, EngineSetup, SetupError};
use crate::saw::{self, Follower, Limits, SawRequest, SyncOn};
use crate::setpoint::Kinematic;
use hli::calls::cam::{TableOrganisation, TABLE_TYPE_MOTION_FUNCTION};
use hli::calls::saw::SawError;
use hli::calls::saw::{
    SawCharacCall, SawCharacReply, SawGearInCall, SawGearOutCall, SawReply, SawSyncMode,
    SawSyncTarget, SAW_CHARAC_PART,
};
use hli::calls::{decode_body, reply, CallKind, CallSpec, ErrorCode, HandlerResult};
use hli::enums::{AxisState, CouplingState};

#[derive(Debug, Clone, Copy)]
struct SawSlave {
    master: usize,
    /// Follows the master's actual values (an encoder master).
    actual: bool,
    follower: Follower,
    /// The slave's coupling: stale once another engine took the axis since (after a fault
    /// released it), and the slot with it.
    lease: Lease,
    /// The motion table the saw plans this slave in ([`own_table`]), which no cam may load
    /// while the saw drives the slave.
    table: Resource,
}

/// The characteristic values of a slave's last plan, as MC_ReadFlyingSawCharacteristics
/// reads them.
#[derive(Debug, Clone, Copy)]
struct Characs {
    values: CharacValues,
    /// The plan's number (a read in parts tells whether all belong to the same plan).
    plan: u32,
    /// The organisation fields: the saw's motion table (256 - axis ID) and the points of the
    /// synchronising phase's motion function.
    organisation: TableOrganisation,
}

/// The organisation fields of a plan of `pieces` pieces in motion table `table`.
fn organisation(table: Resource, pieces: usize) -> TableOrganisation {
    TableOrganisation {
        table_id: table.id,
        rows: pieces as u32 + 1,
        columns: 1,
        table_type: TABLE_TYPE_MOTION_FUNCTION,
        periodic: false,
    }
}

/// Flying-saw slaves by axis index.
#[derive(Debug)]
pub struct SawEngine {
    cycle_s: f64,
    slaves: Vec<Option<SawSlave>>,
    /// Per slave: the last plan's values.
    characs: Vec<Option<Characs>>,
    plans: u32,
}

fn refused(e: SawError) -> HandlerResult {
    reply(&SawReply {
        error_id: e.raw(),
        command_id: 0,
    })
}

fn accepted() -> HandlerResult {
    reply(&SawReply::default())
}

/// The flying saw in the engine set ([`crate::machine::engines::STANDARD`]): it has no keys of its
/// own.
pub const ENGINE: EngineDef = EngineDef {
    name: "saw",
    sections: &[],
    configure: no_config,
    build,
};

/// The flying saw of a machine with single axes.
fn build(setup: &EngineSetup, _: &Config) -> Result<Option<Box<dyn Engine>>, SetupError> {
    if setup.single_axes == 0 {
        return Ok(None);
    }
    Ok(Some(Box::new(SawEngine::new(setup.axes(), setup.cycle_s))))
}

impl SawEngine {
    /// A saw engine for a machine of `axes` axes and tick `cycle_s`.
    pub fn new(axes: usize, cycle_s: f64) -> SawEngine {
        SawEngine {
            cycle_s,
            slaves: vec![None; axes],
            characs: vec![None; axes],
            plans: 0,
        }
    }

    /// The characteristic values of the last phase planned for `slave`.
    pub fn charac(&self, slave: usize) -> Option<&CharacValues> {
        self.characs.get(slave)?.as_ref().map(|c| &c.values)
    }

    /// Whether `slave` is coupled to a master by the saw (the axis still in the coupling
    /// the saw made).
    fn owns(&self, slave: usize, axes: &AxisSet) -> bool {
        let slot = self.slaves.get(slave).and_then(Option::as_ref);
        slot.is_some_and(|s| axes.holds(s.lease))
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
        let ours = self.owns(slave, axes);
        if axis.coupling().is_some() && !ours {
            return reply(&SawReply {
                error_id: hli::enums::AxisError::Coupled.raw(),
                command_id: 0,
            });
        }
        let on = match SawSyncTarget::from_raw(call.target) {
            Some(SawSyncTarget::Velocity) => SyncOn::Velocity,
            Some(SawSyncTarget::Position) => SyncOn::Position {
                master: call.master_sync_position,
                slave: call.slave_sync_position,
            },
            None => return refused(SawError::Mode),
        };
        let time_based = match SawSyncMode::from_raw(call.sync_mode) {
            Some(SawSyncMode::PositionBased) => false,
            Some(SawSyncMode::TimeBased) => true,
            None => return refused(SawError::Mode),
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
        let actual = match call.master_source {
            0 => false,
            1 => true,
            _ => return refused(SawError::Mode),
        };
        let m = master_values(axes, master, actual, self.cycle_s).unwrap_or_default();
        let s = axis.engine_setpoint();
        // Planned in the engine's frame: a slave re-coupled in place keeps its superimposed
        // offset (MC_MoveSuperimposed), so its software limits stand that much nearer there.
        let offset = if ours {
            axis.superimposed_offset()
        } else {
            0.0
        };
        let soft_limits = axis
            .config()
            .soft_limits
            .map(|[min, max]| [min - offset, max - offset]);
        let plan = match saw::plan(&request, &m, &s, soft_limits) {
            Ok(p) => p,
            Err(e) => return refused(e),
        };
        let kind = match on {
            SyncOn::Velocity => CouplingState::GearVelocity,
            SyncOn::Position { .. } => CouplingState::GearPosition,
        };
        let coupling = Coupling {
            kind,
            master: master as i32,
            phase: AxisState::SlaveSynchronizing,
        };
        let lease = match self.slaves[slave].as_ref().map(|s| s.lease) {
            // A new command on a coupled slave: planned from where it is, coupled in place.
            Some(lease) if ours => {
                axes.recouple(lease, coupling);
                lease
            }
            _ => match axes.couple(slave, coupling) {
                Ok(lease) => lease,
                Err(e) => {
                    return reply(&SawReply {
                        error_id: e.raw(),
                        command_id: 0,
                    })
                }
            },
        };
        let table = own_table(axes, slave);
        self.slaves[slave] = Some(SawSlave {
            master,
            actual,
            follower: Follower::new(request, &plan, &m, soft_limits),
            lease,
            table,
        });
        self.plans = self.plans.wrapping_add(1);
        self.characs[slave] = Some(Characs {
            values: plan.charac.values,
            plan: self.plans,
            organisation: organisation(table, plan.profile.pieces().len()),
        });
        // The coupling's command in the slave's book: the block follows it there, and a
        // coupling that replaces it (this engine's in place too) aborts it.
        let command_id = axes
            .begin_coupled(lease, hli::enums::AxisCommandKind::GearIn)
            .unwrap_or(0);
        reply(&SawReply {
            error_id: 0,
            command_id,
        })
    }

    fn gear_out(&mut self, slave: usize, axes: &mut AxisSet) -> HandlerResult {
        // A stale slot (the axis taken by another engine since) goes without touching it.
        let had = self.slaves.get_mut(slave).and_then(Option::take);
        match had {
            Some(s) if axes.release(s.lease) => accepted(),
            _ => refused(SawError::NotCoupled),
        }
    }

    fn read_charac(&self, slave: usize, call: &SawCharacCall) -> HandlerResult {
        let Some(c) = self.characs.get(slave).copied().flatten() else {
            return reply(&SawCharacReply {
                error_id: SawError::NotCoupled.raw(),
                ..SawCharacReply::default()
            });
        };
        let fields = c.values.fields().map(|(_, v)| v);
        let organisation = c.organisation.values();
        let from = call.part as usize * SAW_CHARAC_PART;
        let part: &[f64] = match call.part {
            0 | 1 => &fields[from..],
            2 => &organisation,
            _ => return Err(ErrorCode::InvalidData),
        };
        let mut values = [0.0; SAW_CHARAC_PART];
        for (v, f) in values.iter_mut().zip(part) {
            *v = *f;
        }
        reply(&SawCharacReply {
            error_id: 0,
            part: call.part,
            plan: c.plan,
            reserved: 0,
            values,
        })
    }
}

/// The master's values the saw plans from and follows: its set-point, or its encoder's with
/// the acceleration threshold of an encoder master ([`saw::encoder_master`]).
fn master_values(axes: &AxisSet, master: usize, actual: bool, cycle_s: f64) -> Option<Kinematic> {
    let m = axes.master(master, actual)?;
    Some(match (actual, axes.axis(master)) {
        (true, Some(a)) => saw::encoder_master(m, 1.0 / a.config().increments_per_unit, cycle_s),
        _ => m,
    })
}

/// The motion table the saw plans `slave`'s motion in: 256 - its axis ID (seed 001, chapter
/// 13); the axis ID 0 of a missing axis names no table a cam can hold.
fn own_table(axes: &AxisSet, slave: usize) -> Resource {
    let id = axes
        .axis(slave)
        .map_or(0, |a| 256u32.wrapping_sub(a.config().id));
    Resource {
        kind: hli::calls::cam::MOTION_TABLE,
        id,
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
            // An encoder master with the threshold in every tick too: a phase planned anew
            // after a rollback plans from the same kind of values as the coupling did.
            let Some(m) = master_values(io.axes, s.master, s.actual, dt) else {
                continue;
            };
            // A slave that lost its coupling (fault, power off), or was coupled by another
            // engine since, is no longer the saw's.
            let Some(now) = io.axes.axis(i).filter(|_| io.axes.holds(s.lease)) else {
                *slot = None;
                continue;
            };
            match s.follower.step(&m, now.engine_setpoint(), dt) {
                Some((set, phase)) => {
                    io.axes.drive(s.lease, set, phase);
                    // A new plan in the tick (after a rollback): the values describe it now.
                    if let Some((values, pieces)) = s.follower.take_replanned() {
                        self.plans = self.plans.wrapping_add(1);
                        self.characs[i] = Some(Characs {
                            values,
                            plan: self.plans,
                            organisation: organisation(s.table, pieces),
                        });
                    }
                }
                None => {
                    io.axes.release(s.lease);
                    *slot = None;
                }
            }
        }
    }

    fn calls(&self) -> &'static [CallSpec] {
        hli::calls::saw::CALLS
    }

    fn holds(&self, resource: Resource) -> bool {
        self.slaves.iter().flatten().any(|s| s.table == resource)
    }

    fn handle(&mut self, call: Call<'_>) -> HandlerResult {
        let Call {
            kind,
            request,
            axes,
            mut others,
        } = call;
        let slave = request.target as usize;
        let known = slave < self.slaves.len();
        match kind {
            // A slave beyond the engine's slots (an engine built for fewer axes).
            CallKind::SAW_GEAR_IN if !known => Err(ErrorCode::InvalidTarget),
            // The saw plans in table 256 - the slave's axis ID (chapter 13): not while another
            // engine (a cam) uses that table.
            CallKind::SAW_GEAR_IN if others.hold(own_table(axes, slave)) => reply(&SawReply {
                error_id: SawError::TableInUse.raw(),
                command_id: 0,
            }),
            CallKind::SAW_GEAR_IN => decode_body::<SawGearInCall>(request)
                .and_then(|call| self.gear_in(slave, &call, axes)),
            // MC_GearOut of a slave the saw does not hold: a gear coupling of another engine.
            CallKind::SAW_GEAR_OUT if !self.owns(slave, axes) => {
                decode_body::<SawGearOutCall>(request)?;
                match others.release_slave(slave, axes) {
                    true => accepted(),
                    false => refused(SawError::NotCoupled),
                }
            }
            CallKind::SAW_GEAR_OUT => {
                decode_body::<SawGearOutCall>(request).and_then(|_| self.gear_out(slave, axes))
            }
            CallKind::SAW_CHARAC => decode_body::<SawCharacCall>(request)
                .and_then(|call| self.read_charac(slave, &call)),
            _ => Err(ErrorCode::ServiceNotSupported),
        }
    }

    fn reset(&mut self, axes: &mut AxisSet) {
        for slot in &mut self.slaves {
            // Only its own coupling (another engine may hold the axis since).
            if let Some(s) = slot.take() {
                axes.release(s.lease);
            }
        }
    }
}
