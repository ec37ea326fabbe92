//! The standard engine set of a machine, in its tick order: each engine's machine file has a
//! `build` that makes it from the [`EngineSetup`] (or leaves it out when the machine has
//! nothing for it), and [`STANDARD`] lists them, one line per engine. The order matters: an
//! engine later in the list sees the set-points of this tick of the axes the ones before it
//! drive (the flying saw, last, follows a master a cam or a FIFO group moves).

use super::Engine;
use crate::cam::CamProfile;
use crate::fifo::FifoParams;
use crate::machine::gear::GearSpec;

/// What the engines of a machine are made from: the machine's configuration beside its
/// channels and axes.
#[derive(Debug, Clone, Copy)]
pub struct EngineSetup<'a> {
    /// Axes of all channels, in the machine's axis numbering before the single axes.
    pub channel_axes: usize,
    /// Single axes (PLCopen axes), numbered after the channel axes.
    pub single_axes: usize,
    /// The CNC cycle in seconds.
    pub cycle_s: f64,
    /// Electronic gears between axes.
    pub gears: &'a [GearSpec],
    /// Cam tables loaded at start-up, by table ID.
    pub cam_tables: &'a [(u32, CamProfile)],
    /// FIFO axis groups `gpFifo[0..]`.
    pub fifo_groups: &'a [FifoParams],
}

impl EngineSetup<'_> {
    /// Every axis of the machine.
    pub fn axes(&self) -> usize {
        self.channel_axes + self.single_axes
    }
}

/// Why an engine could not be made from its configuration (the engine's own error, whose
/// text names the configuration key).
pub type SetupError = Box<dyn std::error::Error + Send + Sync>;

/// Makes an engine from the setup, or `None` when the machine has nothing for it.
pub type Build = fn(&EngineSetup<'_>) -> Result<Option<Box<dyn Engine>>, SetupError>;

/// The standard engines in their tick order: one line per engine.
pub const STANDARD: &[Build] = &[
    super::gear::build,
    super::cams::build,
    super::fifo::build,
    super::saw::build,
];

/// The standard engines of a machine, made from `setup` in their tick order.
pub fn standard(setup: &EngineSetup<'_>) -> Result<Vec<Box<dyn Engine>>, SetupError> {
    let mut engines = Vec::with_capacity(STANDARD.len());
    for build in STANDARD {
        engines.extend(build(setup)?);
    }
    Ok(engines)
}
