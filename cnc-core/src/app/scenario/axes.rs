//! Single axes and gears in a scenario.
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

use crate::axis::config::{AxisConfig, AxisKind, DriveLink, DriveMode, ImageOptions};
use crate::axis::increments::CounterWidth;
use crate::axis::sim_drive::DriveModel;
use crate::channel::ChannelConfig;
use crate::machine::gear::GearSpec;
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
}

fn linear() -> String {
    "linear".into()
}

/// One `[[fifo_group]]` table: `gpFifo[i]^` in file order.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FifoGroupFile {
    /// N.
    dimension: usize,
    /// Z.
    rows: usize,
    /// T_f, ms.
    fifo_cycle_ms: f64,
    /// "instant" (default) or "pt2".
    #[serde(default = "instant", rename = "override")]
    override_type: String,
    /// T0 of the PT-2, ms.
    pt2_t0_ms: Option<f64>,
}

fn instant() -> String {
    "instant".into()
}

/// The FIFO groups' parameters, checked: `Err` names the group and what is wrong.
pub fn fifo_groups(files: &[FifoGroupFile]) -> Result<Vec<crate::fifo::FifoParams>, String> {
    use crate::fifo::{FifoParams, OverrideType};
    if files.len() > hli::layout::HLI_MAX_FIFO_GROUPS {
        return Err(format!(
            "{} [[fifo_group]]: the image holds {}",
            files.len(),
            hli::layout::HLI_MAX_FIFO_GROUPS
        ));
    }
    files
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let kind = match (f.override_type.as_str(), f.pt2_t0_ms) {
                ("instant", None) => OverrideType::Instant,
                ("pt2", Some(t0)) => OverrideType::Pt2 { t0_s: t0 * 1e-3 },
                ("pt2", None) => {
                    return Err(format!(
                        "[[fifo_group]] {i}: override = \"pt2\" needs pt2_t0_ms"
                    ))
                }
                ("instant", Some(_)) => {
                    return Err(format!(
                        "[[fifo_group]] {i}: pt2_t0_ms belongs to override = \"pt2\""
                    ))
                }
                (other, _) => {
                    return Err(format!(
                        "[[fifo_group]] {i}: override = {other:?}: \"instant\" or \"pt2\""
                    ))
                }
            };
            FifoParams::new(f.dimension, f.rows, f.fifo_cycle_ms * 1e-3, kind)
                .map_err(|e| format!("[[fifo_group]] {i}: {e}"))
        })
        .collect()
}

/// One `[[gear]]` table.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GearFile {
    master: String,
    slave: String,
    ratio: f64,
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
        let key = |k: &str| format!("[[axis]] {:?}: {k}", f.name);
        if f.name.is_empty() || f.name.contains('.') {
            return Err(key(
                "name: not empty, without '.' (CHANNEL.AXIS names channel axes)",
            ));
        }
        let id = match f.id {
            None => first_id + i as u32,
            // Channel axes hold 1..first_id; the saw's table is 256 - ID.
            Some(id) if (first_id..=255).contains(&id) => id,
            Some(_) => {
                return Err(key(&format!(
                    "id: {first_id}..=255 (the channel axes hold the IDs below)"
                )))
            }
        };
        let mut c = match f.kind.as_str() {
            "linear" => {
                if f.modulo.is_some() {
                    return Err(key(
                        "modulo: a linear axis has no modulo (kind = \"rotary\")",
                    ));
                }
                AxisConfig::linear(&f.name, id)
            }
            "rotary" => {
                if f.soft_limits.is_some() {
                    return Err(key(
                        "soft_limits: an endless rotary axis has no software limits",
                    ));
                }
                let mut c = AxisConfig::rotary(&f.name, id);
                if let Some(m) = f.modulo {
                    c.kind = AxisKind::Rotary { modulo: m };
                }
                c
            }
            other => return Err(key(&format!("kind {other:?}: \"linear\" or \"rotary\""))),
        };
        if let Some(l) = f.soft_limits {
            if l[0].partial_cmp(&l[1]) != Some(std::cmp::Ordering::Less) {
                return Err(key(&format!(
                    "soft_limits {l:?}: the minimum must lie below the maximum"
                )));
            }
            if !(l[0]..=l[1]).contains(&f.start) {
                return Err(key(&format!(
                    "start {}: outside soft_limits {l:?}",
                    f.start
                )));
            }
            c.soft_limits = Some(l);
        }
        if let Some(bits) = f.encoder_bits {
            c.encoder_width = match bits {
                16 => CounterWidth::Bits16,
                32 => CounterWidth::Bits32,
                _ => return Err(key(&format!("encoder_bits {bits}: 16 or 32"))),
            };
        }
        let set = |slot: &mut f64, v: Option<f64>| {
            if let Some(v) = v {
                *slot = v;
            }
        };
        set(&mut c.increments_per_unit, f.increments_per_unit);
        set(
            &mut c.velocity_increments_per_unit,
            f.velocity_increments_per_unit,
        );
        set(
            &mut c.acceleration_increments_per_unit,
            f.acceleration_increments_per_unit,
        );
        set(&mut c.dynamics.velocity, f.velocity);
        set(&mut c.dynamics.acceleration, f.acceleration);
        set(&mut c.dynamics.deceleration, f.deceleration);
        set(&mut c.dynamics.jerk, f.jerk);
        set(&mut c.following_error_limit, f.following_error_limit);
        set(&mut c.in_target_window, f.in_target_window);
        set(&mut c.position_gain, f.position_gain);
        set(&mut c.feed_forward, f.feed_forward);
        if let Some(m) = f.drive_mode {
            c.drive_mode = m;
        }
        if let Some(io) = f.io {
            c.io = io;
        }
        if !f.start.is_finite() {
            return Err(key("start: must be finite"));
        }
        let model = f.drive.unwrap_or(DriveModel::Ideal { dead_time_ticks: 0 });
        c.drive = match model.simulated(f.start) {
            Some(sim) => DriveLink::Simulated(sim),
            None => DriveLink::External,
        };
        c.validate().map_err(|e| format!("[[axis]] {e}"))?;
        if out.iter().any(|a: &ScenarioAxis| a.config.name == f.name) {
            return Err(key("name: given twice"));
        }
        if out.iter().any(|a: &ScenarioAxis| a.config.id == id) {
            return Err(key(&format!("id: {id} is another axis's already")));
        }
        out.push(ScenarioAxis {
            config: c,
            power: f.power,
        });
    }
    Ok(out)
}

/// Every axis name of the machine in axis-set order: channel axes `CHANNEL.AXIS` (while they
/// fit in the image), then the single axes.
pub fn axis_names(channels: &[ChannelConfig], single: &[ScenarioAxis]) -> Vec<String> {
    let mut names = Vec::new();
    for c in channels {
        if names.len() + c.axes.len() > hli::layout::HLI_MAX_AXES {
            continue;
        }
        names.extend(c.axes.iter().map(|a| format!("{}.{a}", c.name)));
    }
    names.extend(single.iter().map(|a| a.config.name.clone()));
    names
}

/// Resolves gears by axis name; a slave must be a single axis (the first `channel_axes`
/// names are the channels' axes, which their channels drive).
pub fn gears(
    files: &[GearFile],
    names: &[String],
    channel_axes: usize,
) -> Result<Vec<GearSpec>, String> {
    let index = |n: &str, key: &str| {
        names.iter().position(|m| m == n).ok_or_else(|| {
            format!(
                "[[gear]] {key} {n:?}: no such axis (known: {})",
                names.join(", ")
            )
        })
    };
    files
        .iter()
        .map(|g| {
            let slave = index(&g.slave, "slave")?;
            if slave < channel_axes {
                return Err(format!(
                    "[[gear]] slave {:?}: a channel axis is driven by its channel, not by a gear",
                    g.slave
                ));
            }
            Ok(GearSpec {
                master: index(&g.master, "master")?,
                slave,
                ratio: g.ratio,
            })
        })
        .collect()
}
