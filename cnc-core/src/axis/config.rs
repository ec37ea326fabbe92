//! Configuration of an axis: identity, kind, scaling, limits, dynamics, control and drive.

use super::increments::CounterWidth;
use super::io_map::{Block, ImageMap};
use super::sim_drive::SimDriveConfig;
use serde::{Deserialize, Serialize};

/// Linear or rotary.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "type")]
pub enum AxisKind {
    /// A linear axis in mm.
    Linear,
    /// A rotary axis in degree. With `modulo > 0` it turns endlessly: its displayed positions
    /// wrap into `[0, modulo)` and it has no software limits.
    Rotary {
        /// Modulo period in degree, 0 for none.
        modulo: f64,
    },
}

/// How the drive takes its set-point (`nOutData1`/`nOutData2`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum DriveMode {
    /// Cyclic position: the set position in increments (wrapping like the encoder).
    Position,
    /// Cyclic velocity: the total velocity (feed-forward + position controller) in
    /// velocity increments.
    #[default]
    Velocity,
    /// Universal drive: signed total velocity in `nOutData1`, its magnitude in `nOutData2`.
    Universal,
}

/// How the CNC drives and reads the drive's state machine (`drive_out.nCtrl1`,
/// `drive_in.nStatus1`/`nStatus2`), which the specification leaves to the drive type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum DriveProtocol {
    /// `nCtrl1` is 1 while the axis is enabled; the status bytes are not evaluated.
    #[default]
    Plain,
    /// CiA 402 (CANopen, CoE): `nCtrl1` is the control word's low byte, `nStatus1`/`nStatus2`
    /// the status word; the axis is enabled once the drive reports Operation enabled.
    Cia402,
}

/// The touch-probe interface of the encoder or drive, which the specification maps two ways.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum ProbeInterface {
    /// No touch probe.
    #[default]
    None,
    /// An encoder terminal's external latch: `enc_out.nCtrl1`, `enc_in.nStatus1` and the
    /// latched count in `enc_in.nInData2`; one probe, either edge.
    Terminal,
    /// CANopen 0x60B8/0x60B9: `nCtrl5`/`nCtrl6` and `nStatus5`/`nStatus6` are the control and
    /// status bytes of probes 1 and 2, the edges' positions in `nInData3..6`.
    Canopen,
    /// SERCOS S-0-0405/0406 (probe enable in `nCtrl5`/`nCtrl6`) and S-0-0409..0412 (one
    /// latched flag per probe and edge in `nStatus5..8`), positions in `nInData3..6`.
    Sercos,
}

/// What the axis makes of the optional signals of its process image.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ImageOptions {
    /// The drive's state machine.
    pub protocol: DriveProtocol,
    /// The touch probes.
    pub probe: ProbeInterface,
    /// Scaling of the actual torque `drive_in.nInData3`: increments per percent of the rated
    /// torque (10: CiA 402's per mille).
    pub torque_increments_per_percent: f64,
    /// Dead-time compensation from the distributed-clock times `nDcInputTime` and
    /// `nDcOutputTime`.
    pub dc_compensation: bool,
    /// What `drive_out.nOutData3` carries: the set-point's acceleration (in
    /// `acceleration_increments_per_unit`) or a torque set-point from the axis's dynamic
    /// model (the rated torque gives `dynamics.acceleration`; in
    /// `torque_increments_per_percent`).
    pub out_data3: OutData3,
    /// The encoder's register interface (`enc_out.nCtrl2` / `enc_in.nStatus2`, see
    /// `axis::encoder_reg`): read the absolute position at start-up.
    pub encoder_absolute: bool,
    /// The encoder can set its counter (MC_SetPosition through `nCtrl2`/`nOutData2`).
    pub encoder_set_counter: bool,
    /// The encoder's error bit(s) in `enc_in.nStatus1` (the manual leaves their coding to the
    /// device): while reported, an enabled axis stops with `EncoderError` and the reading is
    /// not used.
    pub encoder_error: Option<EncoderErrorBit>,
    /// Where each signal lies in the hardware's bytes of an external drive, for drives the
    /// fixed codings do not know (`axis::io_map`); empty: our layout.
    pub map: ImageMap,
    /// Time constant (s) of a first-order filter on the actual velocity and acceleration
    /// from the encoder; 0: none. Seed 001 asks for an encoder master's values to be
    /// carefully filtered: quantisation makes the raw acceleration jump by one increment per
    /// cycle squared.
    pub actual_filter_s: f64,
    /// The actual acceleration is computed from the encoder (false: it is 0, seed 001's
    /// encoder mode that switches it off).
    pub actual_acceleration: bool,
}

/// Where an encoder reports an error in `enc_in.nStatus1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EncoderErrorBit {
    /// The bit(s) (not 0).
    pub mask: u8,
    /// The error is a cleared bit (any of the mask's bits 0), else a set one (any 1).
    #[serde(default)]
    pub active_low: bool,
}

impl EncoderErrorBit {
    /// Whether status byte `status` reports the error.
    pub fn reported(&self, status: u8) -> bool {
        if self.active_low {
            status & self.mask != self.mask
        } else {
            status & self.mask != 0
        }
    }
}

/// What `drive_out.nOutData3` carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OutData3 {
    /// The set-point's acceleration.
    #[default]
    Acceleration,
    /// A torque set-point (feed-forward from the dynamic model).
    Torque,
    /// Both added, each under its own scaling (the manual lets the two go out separately or
    /// as their sum, by the output scalings).
    Sum,
}

/// The reason a value that must be positive gives.
const POSITIVE: &str = "must be a finite number above 0";

impl AxisConfig {
    /// `drive_out.nOutData3` for a set-point acceleration of `acceleration` units/s^2.
    pub fn out_data3(&self, acceleration: f64) -> f64 {
        let as_acceleration = acceleration * self.acceleration_increments_per_unit;
        let as_torque = 100.0 * acceleration / self.dynamics.acceleration
            * self.io.torque_increments_per_percent;
        match self.io.out_data3 {
            OutData3::Acceleration => as_acceleration,
            OutData3::Torque => as_torque,
            OutData3::Sum => as_acceleration + as_torque,
        }
    }
}

impl Default for ImageOptions {
    fn default() -> Self {
        Self {
            protocol: DriveProtocol::Plain,
            probe: ProbeInterface::None,
            torque_increments_per_percent: 10.0,
            dc_compensation: false,
            out_data3: OutData3::Acceleration,
            encoder_absolute: false,
            encoder_set_counter: false,
            encoder_error: None,
            map: ImageMap::default(),
            actual_filter_s: 0.0,
            actual_acceleration: true,
        }
    }
}

/// Where the process image goes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "type")]
pub enum DriveLink {
    /// The built-in simulation closes the loop through the image.
    Simulated(SimDriveConfig),
    /// Something else (a field-bus task, a test) writes the inputs.
    External,
}

/// The limits of an axis and the defaults of its moves.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Dynamics {
    /// Maximum velocity, units/s.
    pub velocity: f64,
    /// Maximum acceleration, units/s^2.
    pub acceleration: f64,
    /// Maximum deceleration, units/s^2.
    pub deceleration: f64,
    /// Maximum jerk, units/s^3.
    pub jerk: f64,
}

/// Everything that configures an axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AxisConfig {
    /// Name (`X`, `Table`).
    pub name: String,
    /// Id of the axis (1-based, as in the PLC's axis references).
    pub id: u32,
    /// Linear or rotary.
    pub kind: AxisKind,
    /// Encoder scaling: increments per mm (or per degree).
    pub increments_per_unit: f64,
    /// Width of the encoder counter.
    #[serde(default)]
    pub encoder_width: CounterWidth,
    /// How the drive takes its set-point.
    #[serde(default)]
    pub drive_mode: DriveMode,
    /// Output scaling of velocity: velocity increments per unit/s.
    pub velocity_increments_per_unit: f64,
    /// Output scaling of acceleration (`nOutData3`): increments per unit/s^2.
    pub acceleration_increments_per_unit: f64,
    /// Software limits `[min, max]`, none when absent.
    pub soft_limits: Option<[f64; 2]>,
    /// Limits of every move.
    pub dynamics: Dynamics,
    /// Largest |set - actual| before the axis stops with an error, units.
    pub following_error_limit: f64,
    /// Window around the target within which a move counts as in target, units.
    pub in_target_window: f64,
    /// Proportional gain of the position controller (Kv), 1/s.
    pub position_gain: f64,
    /// Velocity feed-forward weight, 0..=1.
    pub feed_forward: f64,
    /// Simulated or external drive.
    pub drive: DriveLink,
    /// The optional signals of the process image: drive protocol, touch probes, torque
    /// scaling, dead-time compensation.
    #[serde(default)]
    pub io: ImageOptions,
}

/// A configuration value out of its range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("axis {axis}: {field} = {value} is invalid: {reason}")]
pub struct ConfigError {
    /// Axis name.
    pub axis: String,
    /// Which setting.
    pub field: &'static str,
    /// Its value.
    pub value: f64,
    /// What it must be.
    pub reason: &'static str,
}

impl AxisConfig {
    /// A linear axis `name` with a simulated ideal drive and moderate dynamics (a typical
    /// machine-tool axis: 1 m/s, 10 m/s^2, 0.1 um resolution).
    pub fn linear(name: &str, id: u32) -> Self {
        Self {
            name: name.into(),
            id,
            kind: AxisKind::Linear,
            increments_per_unit: 10_000.0,
            encoder_width: CounterWidth::Bits32,
            drive_mode: DriveMode::Velocity,
            velocity_increments_per_unit: 10_000.0,
            acceleration_increments_per_unit: 1_000.0,
            soft_limits: Some([-1000.0, 1000.0]),
            dynamics: Dynamics {
                velocity: 1000.0,
                acceleration: 10_000.0,
                deceleration: 10_000.0,
                jerk: 200_000.0,
            },
            following_error_limit: 5.0,
            in_target_window: 0.001,
            position_gain: 50.0,
            feed_forward: 1.0,
            drive: DriveLink::Simulated(SimDriveConfig::default()),
            io: ImageOptions::default(),
        }
    }

    /// A rotary axis `name` turning endlessly (modulo 360).
    pub fn rotary(name: &str, id: u32) -> Self {
        Self {
            kind: AxisKind::Rotary { modulo: 360.0 },
            soft_limits: None,
            dynamics: Dynamics {
                velocity: 3600.0,
                acceleration: 36_000.0,
                deceleration: 36_000.0,
                jerk: 720_000.0,
            },
            ..Self::linear(name, id)
        }
    }

    fn check(
        &self,
        field: &'static str,
        value: f64,
        ok: bool,
        reason: &'static str,
    ) -> Result<(), ConfigError> {
        if ok && value.is_finite() {
            Ok(())
        } else {
            Err(ConfigError {
                axis: self.name.clone(),
                field,
                value,
                reason,
            })
        }
    }

    /// Checks every value; the first one out of range is the error.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.check_scalings()?;
        self.check_dynamics()?;
        self.check_controller()?;
        self.check_kind_and_limits()?;
        self.check_encoder_error()?;
        self.check_map()?;
        let filter = self.io.actual_filter_s;
        if !(filter.is_finite() && (0.0..=10.0).contains(&filter)) {
            return Err(ConfigError {
                axis: self.name.clone(),
                field: "io.actual_filter_s",
                value: filter,
                reason: "must be 0 (none) up to 10 s",
            });
        }
        if let DriveLink::Simulated(sim) = self.drive {
            sim.validate()
                .map_err(|(field, value, reason)| ConfigError {
                    axis: self.name.clone(),
                    field,
                    value,
                    reason,
                })?;
        }
        Ok(())
    }

    /// The encoder-error bit: a mask, and not in a status byte the terminal probe owns.
    fn check_encoder_error(&self) -> Result<(), ConfigError> {
        let Some(bit) = self.io.encoder_error else {
            return Ok(());
        };
        let refuse = |field, reason| ConfigError {
            axis: self.name.clone(),
            field,
            value: f64::from(bit.mask),
            reason,
        };
        if bit.mask == 0 {
            return Err(refuse(
                "io.encoder_error.mask",
                "must name at least one bit",
            ));
        }
        if self.io.probe == ProbeInterface::Terminal {
            return Err(refuse(
                "io.encoder_error",
                "nStatus1 is the terminal probe's status (probe = \"terminal\")",
            ));
        }
        Ok(())
    }

    /// A map is an external drive's, and the encoder's counter in it is the counter the
    /// configuration names (16 or 32 bits, unscaled: its wraps are counted).
    fn check_map(&self) -> Result<(), ConfigError> {
        let map = &self.io.map;
        if map.is_empty() {
            return Ok(());
        }
        let refuse = |field, value, reason| ConfigError {
            axis: self.name.clone(),
            field,
            value,
            reason,
        };
        if self.drive != DriveLink::External {
            return Err(refuse("io.map", 0.0, "maps an external drive's image only"));
        }
        if let Some(counter) = map.signal(Block::EncIn, "nInData1") {
            let bits = match self.encoder_width {
                CounterWidth::Bits16 => 16,
                CounterWidth::Bits32 => 32,
            };
            if counter.width != bits || counter.scale != 1.0 || counter.signed != (bits == 32) {
                return Err(refuse(
                    "io.map",
                    f64::from(counter.width),
                    "enc_in.nInData1 must be the encoder_width's counter: 16 bits unsigned or 32 signed, scale 1",
                ));
            }
        }
        Ok(())
    }

    /// The increments per unit of position, velocity, acceleration and torque.
    fn check_scalings(&self) -> Result<(), ConfigError> {
        self.check(
            "increments_per_unit",
            self.increments_per_unit,
            self.increments_per_unit > 0.0,
            POSITIVE,
        )?;
        self.check(
            "velocity_increments_per_unit",
            self.velocity_increments_per_unit,
            self.velocity_increments_per_unit > 0.0,
            POSITIVE,
        )?;
        self.check(
            "acceleration_increments_per_unit",
            self.acceleration_increments_per_unit,
            self.acceleration_increments_per_unit > 0.0,
            POSITIVE,
        )?;
        self.check(
            "io.torque_increments_per_percent",
            self.io.torque_increments_per_percent,
            self.io.torque_increments_per_percent > 0.0,
            POSITIVE,
        )
    }

    /// Velocity, acceleration, deceleration and jerk limits.
    fn check_dynamics(&self) -> Result<(), ConfigError> {
        let d = self.dynamics;
        self.check("dynamics.velocity", d.velocity, d.velocity > 0.0, POSITIVE)?;
        self.check(
            "dynamics.acceleration",
            d.acceleration,
            d.acceleration > 0.0,
            POSITIVE,
        )?;
        self.check(
            "dynamics.deceleration",
            d.deceleration,
            d.deceleration > 0.0,
            POSITIVE,
        )?;
        self.check("dynamics.jerk", d.jerk, d.jerk > 0.0, POSITIVE)
    }

    /// Following-error limit, in-target window, position gain, feed-forward.
    fn check_controller(&self) -> Result<(), ConfigError> {
        self.check(
            "following_error_limit",
            self.following_error_limit,
            self.following_error_limit > 0.0,
            POSITIVE,
        )?;
        self.check(
            "in_target_window",
            self.in_target_window,
            self.in_target_window > 0.0,
            POSITIVE,
        )?;
        self.check(
            "position_gain",
            self.position_gain,
            self.position_gain >= 0.0,
            "must be finite and not negative",
        )?;
        self.check(
            "feed_forward",
            self.feed_forward,
            (0.0..=1.0).contains(&self.feed_forward),
            "must lie in 0..=1",
        )
    }

    /// A rotary axis's modulo, and the software limits (none on an endless axis).
    fn check_kind_and_limits(&self) -> Result<(), ConfigError> {
        if let AxisKind::Rotary { modulo } = self.kind {
            self.check(
                "kind.modulo",
                modulo,
                modulo == 0.0 || modulo >= 0.001,
                "must be 0 (none) or at least 0.001 degree (ten HLI units)",
            )?;
            if modulo > 0.0 && self.soft_limits.is_some() {
                return Err(ConfigError {
                    axis: self.name.clone(),
                    field: "soft_limits",
                    value: modulo,
                    reason: "an endless (modulo) axis has no software limits",
                });
            }
        }
        if let Some([min, max]) = self.soft_limits {
            self.check(
                "soft_limits[0]",
                min,
                min < max,
                "must be below the upper limit",
            )?;
            self.check("soft_limits[1]", max, true, "must be finite")?;
        }
        Ok(())
    }

    /// The modulo period, when the axis turns endlessly.
    pub fn modulo(&self) -> Option<f64> {
        match self.kind {
            AxisKind::Rotary { modulo } if modulo > 0.0 => Some(modulo),
            _ => None,
        }
    }
}
