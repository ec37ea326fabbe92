//! The gear engine: a slave axis follows a master axis as `slave = slave0 + ratio *
//! (master - master0)`, velocity and acceleration scaled alike (the linear coupling the
//! flying saw's synchronous phase reuses). A gear couples as soon as its slave is enabled
//! and free, and holds the positions both axes had at that tick as its origin, so coupling
//! causes no jump.

use super::engine::{Engine, EngineIo};
use crate::axis::{AxisSet, Coupling};
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
    /// The slave's coupling number when this gear coupled it.
    epoch: u32,
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
                    epoch: 0,
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
            let Some(axis) = io.axes.axis_mut(slave) else {
                continue;
            };
            // A slave that lost its coupling (power off, error, reset) couples again only
            // once it is enabled and free.
            let owned = gear.origin.is_some()
                && axis.coupling().is_some()
                && axis.coupling_epoch() == gear.epoch;
            if !owned {
                gear.origin = None;
                let coupling = Coupling {
                    kind: CouplingState::GearVelocity,
                    master: master as i32,
                    phase: AxisState::SlaveSynchronous,
                };
                if !axis.enabled()
                    || !axis.has_position()
                    || axis.error().is_some()
                    || axis.couple(coupling).is_err()
                {
                    continue;
                }
                gear.origin = Some((m.position, axis.setpoint().position));
                gear.epoch = axis.coupling_epoch();
            }
            let Some(origin) = gear.origin else {
                continue;
            };
            axis.drive_coupled(m.geared(ratio, origin), AxisState::SlaveSynchronous);
        }
    }

    fn reset(&mut self, axes: &mut AxisSet) {
        for gear in &mut self.gears {
            if gear.origin.take().is_some() {
                if let Some(axis) = axes.axis_mut(gear.spec.slave) {
                    // Only its own coupling (another engine may hold the axis since).
                    if axis.coupling_epoch() == gear.epoch {
                        axis.decouple();
                    }
                }
            }
        }
    }
}
