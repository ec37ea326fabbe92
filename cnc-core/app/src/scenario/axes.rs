//! Single axes in a scenario (the `[[gear]]` tables beside them are the gear engine's:
//! `cnc_core::gear`).
//!
//! ```toml
//! [[axis]]
//! name = "Feed"                 # unique among all axes (channel axes are CHANNEL.AXIS)
//! kind = "linear"               # or "rotary" (endless, modulo 360 unless `modulo`)
//! soft_limits = [-100.0, 500.0] # linear only; default [-1000, 1000]
//! velocity = 500.0              # limits of every move: units/s, /s^2, /s^3
//! acceleration = 5000.0
//! deceleration = 5000.0
//! jerk = 100000.0
//! following_error_limit = 2.0
//! drive = { model = "pt2", frequency_hz = 80.0, damping = 0.7 }   # ideal when absent
//! io = { protocol = "cia402", probe = "canopen", dc_compensation = true }  # see docs/axes.md
//! start = 0.0                   # where the (simulated) axis stands at start
//! power = true                  # enabled at start (as if MC_Power had run)
//! id = 12                       # axis ID; default: next after the channel axes
//! encoder_noise = 0.00005       # simulated encoder: each reading off by up to this, units
//!
//! [[gear]]
//! master = "conveyor.X"         # any axis by name
//! slave = "Feed"
//! ratio = 2.0
//! ```
//!
//! Every other value of the axis layer's configuration (scaling, encoder width, drive mode,
//! controller gains) may be given under its own name; absent ones take the defaults of a
//! linear or rotary axis.

use cnc_core::axis::config::{AxisConfig, AxisKind, DriveLink, DriveMode, ImageOptions};
use cnc_core::axis::increments::CounterWidth;
use cnc_core::axis::sim_drive::DriveModel;
use cnc_core::channel::ChannelConfig;
use serde::Deserialize;

/// One `[[axis]]` table.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisFile {
    name: String,
    #[serde(default = "linear")]
    kind: String,
    modulo: Option<f64>,
    soft_limits: Option<[f64; 2]>,
    increments_per_unit: Option<f64>,
    encoder_bits: Option<u8>,
    drive_mode: Option<DriveMode>,
    velocity_increments_per_unit: Option<f64>,
    acceleration_increments_per_unit: Option<f64>,
    velocity: Option<f64>,
    acceleration: Option<f64>,
    deceleration: Option<f64>,
    jerk: Option<f64>,
    following_error_limit: Option<f64>,
    in_target_window: Option<f64>,
    position_gain: Option<f64>,
    feed_forward: Option<f64>,
    drive: Option<DriveModel>,
    io: Option<ImageOptions>,
    #[serde(default)]
    start: f64,
    #[serde(default)]
    power: bool,
    /// The axis ID (1..=255); default: the next after the channel axes and the axes before.
    id: Option<u32>,
    /// Noise on the simulated encoder's readings, units (an actual-value master's encoder).
    #[serde(default)]
    encoder_noise: f64,
}

fn linear() -> String {
    "linear".into()
}

/// A single axis of a scenario: its configuration and whether it is enabled at start.
#[derive(Debug, Clone)]
pub struct ScenarioAxis {
    /// The axis layer's configuration, validated.
    pub config: AxisConfig,
    /// Enabled before the first tick.
    pub power: bool,
}

/// Builds the single axes (ids after the channel axes): `Err` names the axis, the key and
/// what is wrong.
pub fn axes(files: &[AxisFile], first_id: u32) -> Result<Vec<ScenarioAxis>, String> {
    let mut out = Vec::with_capacity(files.len());
    for (i, f) in files.iter().enumerate() {
        if f.name.is_empty() || f.name.contains('.') {
            return Err(f.key("name: not empty, without '.' (CHANNEL.AXIS names channel axes)"));
        }
        let id = f.id(first_id, i)?;
        let c = f.config(id)?;
        if out.iter().any(|a: &ScenarioAxis| a.config.name == f.name) {
            return Err(f.key("name: given twice"));
        }
        if out.iter().any(|a: &ScenarioAxis| a.config.id == id) {
            return Err(f.key(&format!("id: {id} is another axis's already")));
        }
        out.push(ScenarioAxis {
            config: c,
            power: f.power,
        });
    }
    Ok(out)
}

impl AxisFile {
    /// An error at key `k` of this axis.
    fn key(&self, k: &str) -> String {
        format!("[[axis]] {:?}: {k}", self.name)
    }

    /// The axis ID: the one given, or the next after the channel axes and the `index` axes
    /// before.
    fn id(&self, first_id: u32, index: usize) -> Result<u32, String> {
        match self.id {
            None => Ok(first_id + index as u32),
            // Channel axes hold 1..first_id; the saw's table is 256 - ID.
            Some(id) if (first_id..=255).contains(&id) => Ok(id),
            Some(_) => Err(self.key(&format!(
                "id: {first_id}..=255 (the channel axes hold the IDs below)"
            ))),
        }
    }

    /// The axis layer's configuration of this axis with ID `id`, validated.
    fn config(&self, id: u32) -> Result<AxisConfig, String> {
        let mut c = self.kind_config(id)?;
        self.apply_limits(&mut c)?;
        self.apply_values(&mut c);
        if !self.start.is_finite() {
            return Err(self.key("start: must be finite"));
        }
        let model = self
            .drive
            .unwrap_or(DriveModel::Ideal { dead_time_ticks: 0 });
        c.drive = match model.simulated(self.start) {
            Some(sim) => DriveLink::Simulated(cnc_core::axis::sim_drive::SimDriveConfig {
                encoder_noise: self.encoder_noise,
                ..sim
            }),
            None if self.encoder_noise != 0.0 => {
                return Err(self.key("encoder_noise: only for a simulated drive"))
            }
            None => DriveLink::External,
        };
        c.validate().map_err(|e| format!("[[axis]] {e}"))?;
        Ok(c)
    }

    /// The defaults of a linear or a rotary axis (with its modulo).
    fn kind_config(&self, id: u32) -> Result<AxisConfig, String> {
        match self.kind.as_str() {
            "linear" => {
                if self.modulo.is_some() {
                    return Err(self.key("modulo: a linear axis has no modulo (kind = \"rotary\")"));
                }
                Ok(AxisConfig::linear(&self.name, id))
            }
            "rotary" => {
                if self.soft_limits.is_some() {
                    return Err(
                        self.key("soft_limits: an endless rotary axis has no software limits")
                    );
                }
                let mut c = AxisConfig::rotary(&self.name, id);
                if let Some(m) = self.modulo {
                    c.kind = AxisKind::Rotary { modulo: m };
                }
                Ok(c)
            }
            other => Err(self.key(&format!("kind {other:?}: \"linear\" or \"rotary\""))),
        }
    }

    /// The software limits (the start inside them) and the encoder width, checked.
    fn apply_limits(&self, c: &mut AxisConfig) -> Result<(), String> {
        if let Some(l) = self.soft_limits {
            if l[0].partial_cmp(&l[1]) != Some(std::cmp::Ordering::Less) {
                return Err(self.key(&format!(
                    "soft_limits {l:?}: the minimum must lie below the maximum"
                )));
            }
            if !(l[0]..=l[1]).contains(&self.start) {
                return Err(self.key(&format!("start {}: outside soft_limits {l:?}", self.start)));
            }
            c.soft_limits = Some(l);
        }
        if let Some(bits) = self.encoder_bits {
            c.encoder_width = match bits {
                16 => CounterWidth::Bits16,
                32 => CounterWidth::Bits32,
                _ => return Err(self.key(&format!("encoder_bits {bits}: 16 or 32"))),
            };
        }
        Ok(())
    }

    /// Every other value given, over the defaults (checked with the whole configuration).
    fn apply_values(&self, c: &mut AxisConfig) {
        let set = |slot: &mut f64, v: Option<f64>| {
            if let Some(v) = v {
                *slot = v;
            }
        };
        set(&mut c.increments_per_unit, self.increments_per_unit);
        set(
            &mut c.velocity_increments_per_unit,
            self.velocity_increments_per_unit,
        );
        set(
            &mut c.acceleration_increments_per_unit,
            self.acceleration_increments_per_unit,
        );
        set(&mut c.dynamics.velocity, self.velocity);
        set(&mut c.dynamics.acceleration, self.acceleration);
        set(&mut c.dynamics.deceleration, self.deceleration);
        set(&mut c.dynamics.jerk, self.jerk);
        set(&mut c.following_error_limit, self.following_error_limit);
        set(&mut c.in_target_window, self.in_target_window);
        set(&mut c.position_gain, self.position_gain);
        set(&mut c.feed_forward, self.feed_forward);
        if let Some(m) = self.drive_mode {
            c.drive_mode = m;
        }
        if let Some(io) = self.io {
            c.io = io;
        }
    }
}

/// Every axis name of the machine in axis-set order: channel axes `CHANNEL.AXIS`, then the
/// single axes.
pub fn axis_names(channels: &[ChannelConfig], single: &[ScenarioAxis]) -> Vec<String> {
    let mut names = Vec::new();
    for c in channels.iter().filter(|c| c.axis_images) {
        names.extend(c.axes.iter().map(|a| format!("{}.{a}", c.name)));
    }
    names.extend(single.iter().map(|a| a.config.name.clone()));
    names
}
