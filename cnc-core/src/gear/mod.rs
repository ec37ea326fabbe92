//! The gear engine: a slave axis follows a master axis as `slave = slave0 + ratio *
//! (master - master0)`, velocity and acceleration scaled alike (the linear coupling the
//! flying saw's synchronous phase reuses). A gear couples as soon as its slave is enabled
//! and free, and holds the positions both axes had at that tick as its origin, so coupling
//! causes no jump.
//!
//! MC_GearOut lets a gear's slave go: it runs on free at its velocity (its own generator, as
//! after the saw's MC_GearOut) and the gear stays out until the slave has been disabled; the
//! next time it is enabled and free, the gear couples again.
//!
//! Configured by the machine's `[[gear]]` tables, axes by name:
//!
//! ```toml
//! [[gear]]
//! master = "Conveyor"   # any axis: a single axis or CHANNEL.AXIS
//! slave = "Saw"         # a single axis (a channel drives its own)
//! ratio = 0.5
//! ```

use crate::axis::{AxisSet, Coupling, Lease};
use crate::machine::engine::{Engine, EngineIo};
use crate::machine::engines::{
    config_of, section, Config, ConfigInput, EngineDef, EngineSetup, SetupError,
};
use hli::enums::{AxisState, CouplingState};

/// One gear: axis indices in the machine's axis set and the ratio.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GearSpec {
    /// Master axis.
    pub master: usize,
    /// Slave axis.
    pub slave: usize,
    /// Slave units per master unit (negative reverses the slave).
    pub ratio: f64,
}

#[derive(Debug, Clone, Copy)]
struct Gear {
    spec: GearSpec,
    origin: Option<(f64, f64)>,
    /// The slave's coupling, while this gear holds it.
    lease: Option<Lease>,
    /// Let go by MC_GearOut: not coupled again until the slave has been disabled.
    out: bool,
}

/// Gear couplings between axes.
#[derive(Debug, Default)]
pub struct GearEngine {
    gears: Vec<Gear>,
}

/// A gear the machine cannot hold.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum GearError {
    /// An axis index outside the machine.
    #[error("gear: axis {0} does not exist")]
    NoSuchAxis(usize),
    /// A slave that is its own master.
    #[error("gear: axis {0} cannot be its own master")]
    OwnMaster(usize),
    /// A slave already driven by another gear.
    #[error("gear: axis {0} is already a gear slave")]
    SlaveTwice(usize),
    /// Ratio zero or not finite.
    #[error("gear: ratio {0} must be finite and not 0")]
    Ratio(f64),
}

/// The gear engine in the engine set ([`crate::machine::engines::STANDARD`]).
pub const ENGINE: EngineDef = EngineDef {
    name: "gear",
    sections: &["gear"],
    configure,
    build,
};

/// One `[[gear]]` table.
#[derive(Debug, Clone, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct GearFile {
    master: String,
    slave: String,
    ratio: f64,
}

/// The gears by axis index, checked against the machine's axes.
fn configure(input: &ConfigInput<'_>) -> Result<Config, SetupError> {
    let files: Vec<GearFile> = section(input.sections, "gear")?;
    let names = input.axis_names;
    let index = |n: &str, key: &str| {
        names.iter().position(|m| m == n).ok_or_else(|| {
            format!(
                "[[gear]] {key} {n:?}: no such axis (known: {})",
                names.join(", ")
            )
        })
    };
    let mut gears = Vec::with_capacity(files.len());
    for g in &files {
        let slave = index(&g.slave, "slave")?;
        if slave < input.channel_axes {
            return Err(format!(
                "[[gear]] slave {:?}: a channel axis is driven by its channel, not by a gear",
                g.slave
            )
            .into());
        }
        let master = index(&g.master, "master")?;
        gears.push(GearSpec {
            master,
            slave,
            ratio: g.ratio,
        });
    }
    GearEngine::new(&gears, names.len())?;
    Ok(std::sync::Arc::new(gears))
}

/// The gears of a machine, if it has any.
fn build(setup: &EngineSetup, config: &Config) -> Result<Option<Box<dyn Engine>>, SetupError> {
    let gears: &Vec<GearSpec> = config_of(config)?;
    if gears.is_empty() {
        return Ok(None);
    }
    Ok(Some(Box::new(GearEngine::new(gears, setup.axes())?)))
}

impl GearEngine {
    /// Gears between the axes of a machine with `axes` axes.
    pub fn new(specs: &[GearSpec], axes: usize) -> Result<GearEngine, GearError> {
        for (i, s) in specs.iter().enumerate() {
            for a in [s.master, s.slave] {
                if a >= axes {
                    return Err(GearError::NoSuchAxis(a));
                }
            }
            if s.master == s.slave {
                return Err(GearError::OwnMaster(s.slave));
            }
            if specs[..i].iter().any(|o| o.slave == s.slave) {
                return Err(GearError::SlaveTwice(s.slave));
            }
            if !(s.ratio.is_finite() && s.ratio != 0.0) {
                return Err(GearError::Ratio(s.ratio));
            }
        }
        Ok(GearEngine {
            gears: specs
                .iter()
                .map(|&spec| Gear {
                    spec,
                    origin: None,
                    lease: None,
                    out: false,
                })
                .collect(),
        })
    }

    /// Whether gear `i` is coupled now.
    pub fn coupled(&self, i: usize) -> bool {
        self.gears.get(i).is_some_and(|g| g.origin.is_some())
    }
}

impl Engine for GearEngine {
    fn name(&self) -> &'static str {
        "gear"
    }

    fn tick(&mut self, io: &mut EngineIo<'_, '_>) {
        for gear in &mut self.gears {
            let GearSpec {
                master,
                slave,
                ratio,
            } = gear.spec;
            let Some(m) = io.axes.axis(master).map(|a| a.setpoint()) else {
                continue;
            };
            // A slave that lost its coupling (power off, error, reset) couples again only
            // once it is enabled and free.
            let owned = gear.origin.is_some() && gear.lease.is_some_and(|l| io.axes.holds(l));
            if !owned {
                gear.origin = None;
                gear.lease = None;
                let Some(axis) = io.axes.axis(slave) else {
                    continue;
                };
                gear.out &= axis.enabled();
                if gear.out || !axis.enabled() || !axis.has_position() || axis.error().is_some() {
                    continue;
                }
                // Not to a master in error: its set-point stood at the fault (the axis set
                // let the slave go for that); once the master is reset it couples again.
                if io.axes.axis(master).is_some_and(|m| m.error().is_some()) {
                    continue;
                }
                let start = axis.setpoint().position;
                let coupling = Coupling {
                    kind: CouplingState::GearVelocity,
                    master: master as i32,
                    phase: AxisState::SlaveSynchronous,
                };
                let Ok(lease) = io.axes.couple(slave, coupling) else {
                    continue;
                };
                gear.origin = Some((m.position, start));
                gear.lease = Some(lease);
            }
            if let (Some(origin), Some(lease)) = (gear.origin, gear.lease) {
                let set = m.geared(ratio, origin);
                io.axes.drive(lease, set, AxisState::SlaveSynchronous);
            }
        }
    }

    fn release_slave(&mut self, axis: usize, axes: &mut AxisSet) -> bool {
        let held = |g: &&mut Gear| g.spec.slave == axis && g.lease.is_some_and(|l| axes.holds(l));
        let Some(gear) = self.gears.iter_mut().find(held) else {
            return false;
        };
        if let Some(lease) = gear.lease.take() {
            axes.release(lease);
        }
        (gear.origin, gear.out) = (None, true);
        true
    }

    fn reset(&mut self, axes: &mut AxisSet) {
        for gear in &mut self.gears {
            gear.origin = None;
            // Only its own coupling (another engine may hold the axis since).
            if let Some(lease) = gear.lease.take() {
                axes.release(lease);
            }
        }
    }
}
