//! The phase gear on the machine seam. A slave is coupled by a call (between ticks) to a
//! master at rest; every tick it is driven at `slave0 + ratio x (master - master0) + phase`,
//! the phase moved by a jerk-limited generator of its own from the old value to a new one.
//! The coupling is a lease of the axis set: another coupling, an error or a disable ends it,
//! and the engine forgets the slave.
//!
//! ```toml
//! [phase_gear]               # the engine exists when the machine configuration has this
//! shift_velocity = 20.0      # the phase shift's limits: units/s, /s^2, /s^3
//! shift_acceleration = 200.0
//! shift_jerk = 5000.0
//! ```

use crate::calls::{
    PhaseGearError, PhaseGearInCall, PhaseGearOutCall, PhaseGearReply, CALLS, PHASE_GEAR_IN,
    PHASE_GEAR_OUT,
};
use cnc_core::axis::generator::{MoveLimits, SetpointGenerator};
use cnc_core::axis::{AxisSet, Coupling, Lease};
use cnc_core::machine::engines::{
    config_of, Config, ConfigInput, EngineDef, EngineSetup, SetupError,
};
use cnc_core::machine::{Call, Engine, EngineIo};
use cnc_core::setpoint::Kinematic;
use hli::calls::{decode_body, reply, CallSpec, ErrorCode, HandlerResult};
use hli::enums::{AxisState, CouplingState};
use std::sync::Arc;

/// The phase gear in the machine's engine set (registered by [`crate::register`]).
pub const ENGINE: EngineDef = EngineDef {
    name: "phase_gear",
    sections: &["phase_gear"],
    configure,
    build,
};

/// The `[phase_gear]` table: the limits of a phase shift.
#[derive(Debug, Clone, Copy, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct PhaseGearFile {
    shift_velocity: f64,
    shift_acceleration: f64,
    shift_jerk: f64,
}

/// The shift limits, if the machine has a phase gear; an error names the key.
fn configure(input: &ConfigInput<'_>) -> Result<Config, SetupError> {
    let Some(section) = input.sections.get("phase_gear") else {
        return Ok(Arc::new(None::<MoveLimits>));
    };
    let file: PhaseGearFile = section
        .clone()
        .try_into()
        .map_err(|e: toml::de::Error| format!("[phase_gear]: {}", e.message()))?;
    for (key, value) in [
        ("shift_velocity", file.shift_velocity),
        ("shift_acceleration", file.shift_acceleration),
        ("shift_jerk", file.shift_jerk),
    ] {
        if !(value.is_finite() && value > 0.0) {
            return Err(format!("[phase_gear] {key} = {value}: a limit above 0").into());
        }
    }
    Ok(Arc::new(Some(MoveLimits {
        velocity: file.shift_velocity,
        acceleration: file.shift_acceleration,
        deceleration: file.shift_acceleration,
        jerk: file.shift_jerk,
    })))
}

/// The engine of a machine whose configuration has `[phase_gear]`.
fn build(setup: &EngineSetup, config: &Config) -> Result<Option<Box<dyn Engine>>, SetupError> {
    let limits: &Option<MoveLimits> = config_of(config)?;
    Ok(limits.map(|shift| {
        Box::new(PhaseGearEngine::new(setup.axes(), setup.cycle_s, shift)) as Box<dyn Engine>
    }))
}

/// One coupled slave.
#[derive(Debug)]
struct Slave {
    master: usize,
    ratio: f64,
    /// Master and slave positions at the coupling.
    origin: (f64, f64),
    /// The phase offset, shifted by its generator.
    phase: SetpointGenerator,
    lease: Lease,
}

/// Phase gears between the axes of a machine.
#[derive(Debug)]
pub struct PhaseGearEngine {
    slaves: Vec<Option<Slave>>,
    cycle_s: f64,
    shift: MoveLimits,
}

impl PhaseGearEngine {
    /// An engine for `axes` axes, tick `cycle_s`, phase shifts within `shift`.
    pub fn new(axes: usize, cycle_s: f64, shift: MoveLimits) -> PhaseGearEngine {
        PhaseGearEngine {
            slaves: (0..axes).map(|_| None).collect(),
            cycle_s,
            shift,
        }
    }

    /// PhaseGearIn for `slave`: a coupling, or a new phase of the one it has.
    fn gear_in(&mut self, slave: usize, call: &PhaseGearInCall, axes: &mut AxisSet) -> u32 {
        let master = call.master as usize;
        if master == slave || axes.axis(master).is_none() {
            return PhaseGearError::Master.raw();
        }
        if !(call.ratio.is_finite() && call.ratio != 0.0) {
            return PhaseGearError::Ratio.raw();
        }
        if !call.phase.is_finite() {
            return PhaseGearError::Phase.raw();
        }
        let shift = self.shift;
        if let Some(s) = self.slaves[slave].as_mut().filter(|s| axes.holds(s.lease)) {
            if s.master != master || s.ratio != call.ratio {
                return PhaseGearError::Coupled.raw();
            }
            return match s.phase.move_to(call.phase, shift) {
                Ok(()) => 0,
                Err(_) => PhaseGearError::Phase.raw(),
            };
        }
        self.couple(slave, master, call, axes)
    }

    /// A new coupling of a free slave to a master at rest.
    fn couple(
        &mut self,
        slave: usize,
        master: usize,
        call: &PhaseGearInCall,
        axes: &mut AxisSet,
    ) -> u32 {
        let m = axes.axis(master).map(|a| a.setpoint()).unwrap_or_default();
        if m.velocity != 0.0 || m.acceleration != 0.0 {
            return PhaseGearError::MasterMoving.raw();
        }
        let Some(axis) = axes.axis(slave) else {
            return PhaseGearError::NotFree.raw();
        };
        if !axis.enabled() || !axis.has_position() || axis.error().is_some() {
            return PhaseGearError::NotFree.raw();
        }
        let start = axis.setpoint().position;
        let coupling = Coupling {
            kind: CouplingState::GearVelocity,
            master: master as i32,
            phase: AxisState::SlaveSynchronous,
        };
        let Ok(lease) = axes.couple(slave, coupling) else {
            return PhaseGearError::NotFree.raw();
        };
        let mut phase = SetpointGenerator::new(self.cycle_s, 0.0);
        if phase.move_to(call.phase, self.shift).is_err() {
            axes.release(lease);
            return PhaseGearError::Phase.raw();
        }
        self.slaves[slave] = Some(Slave {
            master,
            ratio: call.ratio,
            origin: (m.position, start),
            phase,
            lease,
        });
        0
    }

    /// PhaseGearOut for `slave`.
    fn gear_out(&mut self, slave: usize, axes: &mut AxisSet) -> u32 {
        match self.slaves[slave].take() {
            Some(s) if axes.holds(s.lease) => {
                axes.release(s.lease);
                0
            }
            _ => PhaseGearError::NotCoupled.raw(),
        }
    }
}

impl Engine for PhaseGearEngine {
    fn name(&self) -> &'static str {
        "phase_gear"
    }

    fn calls(&self) -> &'static [CallSpec] {
        CALLS
    }

    fn tick(&mut self, io: &mut EngineIo<'_, '_>) {
        for slot in &mut self.slaves {
            let Some(s) = slot.as_mut() else { continue };
            let master = io.axes.axis(s.master).map(|a| a.setpoint());
            let (true, Some(m)) = (io.axes.holds(s.lease), master) else {
                *slot = None; // the coupling ended (error, disable, another coupling)
                continue;
            };
            s.phase.step();
            let p = s.phase.state();
            let g = m.geared(s.ratio, s.origin);
            let set = Kinematic {
                position: g.position + p.position,
                velocity: g.velocity + p.velocity,
                acceleration: g.acceleration + p.acceleration,
                jerk: g.jerk + p.jerk,
            };
            io.axes.drive(s.lease, set, AxisState::SlaveSynchronous);
        }
    }

    fn handle(&mut self, call: Call<'_>) -> HandlerResult {
        let slave = call.request.target as usize;
        if slave >= self.slaves.len() {
            return Err(ErrorCode::InvalidTarget);
        }
        let error_id = match call.kind {
            PHASE_GEAR_IN => {
                let body = decode_body::<PhaseGearInCall>(call.request)?;
                self.gear_in(slave, &body, call.axes)
            }
            PHASE_GEAR_OUT => {
                decode_body::<PhaseGearOutCall>(call.request)?;
                self.gear_out(slave, call.axes)
            }
            _ => return Err(ErrorCode::ServiceNotSupported),
        };
        reply(&PhaseGearReply {
            error_id,
            reserved: 0,
        })
    }

    fn release_slave(&mut self, axis: usize, axes: &mut AxisSet) -> bool {
        self.slaves.get(axis).is_some_and(Option::is_some) && self.gear_out(axis, axes) == 0
    }

    fn reset(&mut self, axes: &mut AxisSet) {
        for s in self.slaves.iter_mut().filter_map(Option::take) {
            axes.release(s.lease);
        }
    }
}
