//! Channel configuration, under the controller's parameter names where the seed documents one:
//! `provide_channel_interface.track_cs` (P-CHAN-00399), `kin_trafo_display` (P-CHAN-00145) and
//! the start-up parameter `configuration.channel[i].interpolator.dyn_cs_history_max`
//! (P-STUP-00074, default 20).

pub use super::kin_config::KinematicsConfig;
use super::path::AxisLimits;
use crate::nc::decode::{check_channel_axes, AxisLayout};
use kinematics::{Kinematics, RotationOrder};
use serde::Deserialize;

/// The most diagnosis-history entries a channel keeps (each about 160 bytes, allocated at
/// start-up).
pub const MAX_HISTORY: u32 = 100_000;

/// One channel.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChannelConfig {
    /// Name for messages and traces.
    pub name: String,
    /// Axis names in channel order (1 to 16): where their values are kept is their
    /// [`AxisLayout`] (the pose X Y Z A B C first; with a kinematic transformation those are
    /// the robot's joints, and the tool pose's words when it is on).
    pub axes: Vec<String>,
    /// Whether the channel drives axis images (the default). `false`: its set-points go to no
    /// axis (a simulated channel, for loads beyond the image's 32 axes in benchmarks and
    /// tests).
    #[serde(default = "yes")]
    pub axis_images: bool,
    /// The channel's kinematics.
    #[serde(default)]
    pub kinematics: KinematicsConfig,
    /// Dynamic limits of every programmed coordinate (mm or degrees per second).
    #[serde(default = "default_limits")]
    pub limits: AxisLimits,
    /// Per axis (channel order), the axis's own limits: a robot's joints in degrees per
    /// second. Axes beyond the list take `limits`. The set-points the channel hands its axes
    /// are checked against these while tracking, and a failing channel brakes each axis with
    /// them.
    #[serde(default)]
    pub axis_limits: Vec<AxisLimits>,
    /// Axis values at start (joints for a robot), in channel order; missing ones are 0.
    #[serde(default)]
    pub start: Vec<f64>,
    /// P-CHAN-00399.
    #[serde(default)]
    pub provide_channel_interface: ProvideChannelInterface,
    /// P-CHAN-00145: 0 off, 1 (or 2) display the TCP position in `w0_position_r`.
    #[serde(default)]
    pub kin_trafo_display: u16,
    /// Orientation convention of A B C: 0 yaw-pitch-roll, 1 Euler Z-Y'-Z'', 2 CBA.
    #[serde(default)]
    pub ori_rotation_angle: u32,
    /// Start-up parameters of the channel's interpolator.
    #[serde(default)]
    pub interpolator: InterpolatorConfig,
    /// NC program the channel starts with, a path relative to the configuration file.
    #[serde(default)]
    pub program: Option<String>,
    /// The drive of every axis of the channel (simulated ideal when absent).
    #[serde(default)]
    pub drive: Option<crate::axis::sim_drive::DriveModel>,
    /// What NC programs of the channel use: zero offsets, tool table, tolerances, search path.
    #[serde(default)]
    pub nc: NcConfig,
    /// The folder the PLC selects programs from (`SELECT` of the channel control unit), a
    /// path relative to the configuration file; without one, SELECT is refused.
    #[serde(default)]
    pub programs: Option<String>,
    /// Who starts `program`: `"cnc"` (with the CNC, the default) or `"plc"` (selected, it
    /// waits for the PLC's START).
    #[serde(default)]
    pub program_start: ProgramStart,
    /// How long `#WAIT SYN` may wait (s) before the channel fails; none: as long as another
    /// channel runs.
    #[serde(default)]
    pub sync_timeout_s: Option<f64>,
    /// How far a tracking slave's axes may lag behind the compensation while they catch up
    /// with a step of it (a PLC frame step, a master that jumps) before the channel stops.
    #[serde(default)]
    pub track_lag_max: TrackLagMax,
}

/// `track_lag_max`: the bound of a tracking slave's catch-up lag, measured at its tool (the
/// distance and the angle between the pose its axes are commanded and the compensated one).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackLagMax {
    /// mm (default 5).
    #[serde(default = "default_lag")]
    pub translation: f64,
    /// Degrees (default 5).
    #[serde(default = "default_lag")]
    pub rotation: f64,
}

impl Default for TrackLagMax {
    fn default() -> Self {
        Self {
            translation: default_lag(),
            rotation: default_lag(),
        }
    }
}

fn yes() -> bool {
    true
}

fn default_lag() -> f64 {
    5.0
}

/// Who starts a channel's configured program.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ProgramStart {
    /// The CNC, when it starts.
    #[default]
    Cnc,
    /// The PLC, with START on the channel control unit.
    Plc,
}

/// `channel.nc.*`: the machine data NC programs refer to.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NcConfig {
    /// G54..G59: per offset, the value per channel axis (missing ones are 0).
    #[serde(default)]
    pub zero_offsets: ZeroOffsets,
    /// The tool table: length per D number, applied along the plane's normal.
    #[serde(default)]
    pub tools: Vec<ToolEntry>,
    /// How far an arc's end point may lie off its circle (mm; default 0.001).
    #[serde(default)]
    pub arc_tolerance: Option<f64>,
    /// Continuous path: the corner deviation (mm; default 0.05) until a program sets one with
    /// `#CONTOUR MODE [DEV PATH_DEV=..]`.
    #[serde(default)]
    pub path_dev: Option<f64>,
    /// Folders `L name` searches after the calling program's own.
    #[serde(default)]
    pub search_path: Vec<String>,
}

/// G54..G59 of [`NcConfig`].
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct ZeroOffsets {
    #[serde(default, rename = "G54")]
    pub g54: Vec<f64>,
    #[serde(default, rename = "G55")]
    pub g55: Vec<f64>,
    #[serde(default, rename = "G56")]
    pub g56: Vec<f64>,
    #[serde(default, rename = "G57")]
    pub g57: Vec<f64>,
    #[serde(default, rename = "G58")]
    pub g58: Vec<f64>,
    #[serde(default, rename = "G59")]
    pub g59: Vec<f64>,
}

/// One tool data record.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToolEntry {
    /// The D number that selects it (1 or more).
    pub d: u32,
    /// Tool length (mm): along the plane's normal without a transformation, along the
    /// flange's tool axis (Z) under one.
    pub length: f64,
    /// Orientation of the tool point against the flange under a transformation: A B C
    /// (degrees, Z-Y-X; C turns about the tool axis).
    #[serde(default)]
    pub orientation: [f64; 3],
}

impl NcConfig {
    /// The decoder's view of it.
    pub fn setup(&self) -> crate::nc::decode::DecoderSetup {
        let z = &self.zero_offsets;
        crate::nc::decode::DecoderSetup {
            zero_offsets: [
                z.g54.clone(),
                z.g55.clone(),
                z.g56.clone(),
                z.g57.clone(),
                z.g58.clone(),
                z.g59.clone(),
            ],
            tools: self.tools.iter().map(|t| (t.d, t.length)).collect(),
            // A channel's tool table is the machine's: a D it does not hold is refused.
            tools_unknown: false,
            arc_tolerance: self
                .arc_tolerance
                .unwrap_or(crate::nc::decode::DEFAULT_ARC_TOLERANCE),
            path_dev: self.path_dev.unwrap_or(crate::nc::decode::DEFAULT_PATH_DEV),
        }
    }
}

/// `provide_channel_interface.*`.
#[derive(Debug, Clone, Copy, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProvideChannelInterface {
    /// Publish the dynamic CS from program start, as `#CHANNEL INTERFACE ON [DYN_CS]` would.
    #[serde(default)]
    pub track_cs: bool,
}

/// `configuration.channel[i].interpolator.*`.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InterpolatorConfig {
    /// Entries of the dynamic-CS diagnosis history.
    #[serde(default = "default_history")]
    pub dyn_cs_history_max: u32,
    /// The largest distance between an arc and the chord between two set-points (mm): arcs
    /// run no faster than keeps it.
    #[serde(default = "default_chordal_tolerance")]
    pub chordal_tolerance: f64,
    /// Continuous path: straight blocks decoded ahead of the one under way (1..=128).
    #[serde(default = "default_lookahead")]
    pub lookahead: u32,
}

impl Default for InterpolatorConfig {
    fn default() -> Self {
        Self {
            dyn_cs_history_max: default_history(),
            chordal_tolerance: default_chordal_tolerance(),
            lookahead: default_lookahead(),
        }
    }
}

fn default_chordal_tolerance() -> f64 {
    0.001
}

fn default_lookahead() -> u32 {
    crate::channel::path::contour::DEFAULT_LOOKAHEAD as u32
}

fn default_history() -> u32 {
    20
}

fn default_limits() -> AxisLimits {
    AxisLimits {
        velocity: 1000.0,
        acceleration: 5000.0,
        jerk: 50_000.0,
    }
}

/// A configuration that cannot run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ChannelConfigError {
    /// Bad axis list.
    #[error("channel {channel}: axes: {reason}")]
    Axes {
        /// Channel name.
        channel: String,
        /// Why.
        reason: String,
    },
    /// A kinematic other than the Cartesian one needs the six pose axes as its joints.
    #[error(
        "channel {channel}: axes: kinematic {id} needs X Y Z A B C as its six joints, \
         missing: {missing}"
    )]
    MissingPoseAxes {
        /// Channel name.
        channel: String,
        /// Kinematic id.
        id: u32,
        /// The pose axes not configured ("A B C").
        missing: String,
    },
    /// Bad kinematics.
    #[error("channel {channel}: kinematics: {reason}")]
    Kinematics {
        /// Channel name.
        channel: String,
        /// Why.
        reason: String,
    },
    /// A parameter outside its range.
    #[error("channel {channel}: {name} = {value}: {reason}")]
    Parameter {
        /// Channel name.
        channel: String,
        /// Parameter name.
        name: &'static str,
        /// Value.
        value: f64,
        /// Why.
        reason: &'static str,
    },
}

impl ChannelConfig {
    /// The limits of channel axis `i` (its own, else the channel's).
    pub fn axis_limits(&self, i: usize) -> AxisLimits {
        self.axis_limits.get(i).copied().unwrap_or(self.limits)
    }

    /// Where the channel keeps its axes' values (pose slots X Y Z A B C first).
    pub fn layout(&self) -> AxisLayout {
        AxisLayout::new(&self.axes)
    }

    /// A channel with `axes` and defaults for everything else.
    pub fn new(name: &str, axes: &[&str]) -> Self {
        Self {
            name: name.to_string(),
            axes: axes.iter().map(|a| a.to_string()).collect(),
            axis_images: true,
            kinematics: KinematicsConfig::default(),
            limits: default_limits(),
            axis_limits: Vec::new(),
            start: Vec::new(),
            provide_channel_interface: ProvideChannelInterface::default(),
            kin_trafo_display: 0,
            ori_rotation_angle: 0,
            interpolator: InterpolatorConfig::default(),
            program: None,
            nc: NcConfig::default(),
            drive: None,
            programs: None,
            program_start: ProgramStart::Cnc,
            sync_timeout_s: None,
            track_lag_max: TrackLagMax::default(),
        }
    }

    /// The orientation convention.
    pub fn order(&self) -> Result<RotationOrder, ChannelConfigError> {
        RotationOrder::from_channel_parameter(self.ori_rotation_angle).map_err(|_| {
            ChannelConfigError::Parameter {
                channel: self.name.clone(),
                name: "ori_rotation_angle",
                value: f64::from(self.ori_rotation_angle),
                reason: "must be 0, 1 or 2",
            }
        })
    }

    /// Checks everything and builds the kinematics.
    pub fn build_kinematics(&self) -> Result<Box<dyn Kinematics + Send>, ChannelConfigError> {
        check_channel_axes(&self.axes).map_err(|reason| ChannelConfigError::Axes {
            channel: self.name.clone(),
            reason,
        })?;
        self.check_limits()?;
        self.check_nc_data()?;
        self.check_channel_data()?;
        let order = self.order()?;
        let layout = self.layout();
        if self.kinematics.id != 0 && !layout.has_pose() {
            return Err(ChannelConfigError::MissingPoseAxes {
                channel: self.name.clone(),
                id: self.kinematics.id,
                missing: layout.missing_pose(),
            });
        }
        self.kinematics
            .build(order)
            .map_err(|reason| ChannelConfigError::Kinematics {
                channel: self.name.clone(),
                reason,
            })
    }

    /// Parameter `name` of this channel refused: its value and why.
    fn parameter(
        &self,
        name: &'static str,
        value: f64,
        reason: &'static str,
    ) -> ChannelConfigError {
        ChannelConfigError::Parameter {
            channel: self.name.clone(),
            name,
            value,
            reason,
        }
    }

    /// The dynamic limits, positive and finite, at most one entry per axis.
    fn check_limits(&self) -> Result<(), ChannelConfigError> {
        for (name, l) in core::iter::once(("limits", &self.limits))
            .chain(self.axis_limits.iter().map(|l| ("axis_limits", l)))
        {
            for v in [l.velocity, l.acceleration, l.jerk] {
                if !(v.is_finite() && v > 0.0) {
                    return Err(self.parameter(name, v, "must be positive and finite"));
                }
            }
        }
        let lag = self.track_lag_max;
        for (name, v) in [
            ("track_lag_max.translation", lag.translation),
            ("track_lag_max.rotation", lag.rotation),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(self.parameter(name, v, "must be positive and finite"));
            }
        }
        if self.axis_limits.len() > self.axes.len() {
            return Err(self.parameter(
                "axis_limits",
                self.axis_limits.len() as f64,
                "at most one entry per axis",
            ));
        }
        Ok(())
    }

    /// The NC machine data: tolerances, zero offsets, tool records.
    fn check_nc_data(&self) -> Result<(), ChannelConfigError> {
        // A tolerance that is not a positive number would let every arc through, or none.
        let tolerances = [
            (
                "interpolator.chordal_tolerance",
                self.interpolator.chordal_tolerance,
            ),
            (
                "nc.arc_tolerance",
                self.nc
                    .arc_tolerance
                    .unwrap_or(crate::nc::decode::DEFAULT_ARC_TOLERANCE),
            ),
        ];
        for (name, v) in tolerances {
            if !(v.is_finite() && v > 0.0) {
                return Err(self.parameter(name, v, "must be positive and finite"));
            }
        }
        let z = &self.nc.zero_offsets;
        let offsets = [&z.g54, &z.g55, &z.g56, &z.g57, &z.g58, &z.g59];
        for v in offsets.iter().flat_map(|o| o.iter()) {
            if !v.is_finite() || offsets.iter().any(|o| o.len() > self.axes.len()) {
                return Err(self.parameter(
                    "nc.zero_offsets",
                    *v,
                    "must be finite, at most one value per channel axis",
                ));
            }
        }
        for t in &self.nc.tools {
            if !t.length.is_finite() || t.d == 0 || !t.orientation.iter().all(|v| v.is_finite()) {
                return Err(self.parameter(
                    "nc.tools",
                    t.length,
                    "a record has a D of 1 or more and a finite length",
                ));
            }
        }
        Ok(())
    }

    /// The diagnosis history's size, the display mode, the start values.
    fn check_channel_data(&self) -> Result<(), ChannelConfigError> {
        // Every entry is allocated at start-up: a size the machine cannot hold is refused
        // here instead of aborting the process (the manual allows up to 2^32 - 1).
        if self.interpolator.dyn_cs_history_max > MAX_HISTORY {
            return Err(self.parameter(
                "interpolator.dyn_cs_history_max",
                f64::from(self.interpolator.dyn_cs_history_max),
                "more entries than this controller keeps (at most 100000, 16 MB a channel)",
            ));
        }
        let lookahead = self.interpolator.lookahead;
        if lookahead == 0 || lookahead as usize > crate::channel::path::contour::MAX_LOOKAHEAD {
            return Err(self.parameter(
                "interpolator.lookahead",
                f64::from(lookahead),
                "must be 1 to 128 blocks",
            ));
        }
        let dev = self
            .nc
            .path_dev
            .unwrap_or(crate::nc::decode::DEFAULT_PATH_DEV);
        if !(dev.is_finite() && dev >= 0.0) {
            return Err(self.parameter(
                "nc.path_dev",
                dev,
                "must be a finite distance of 0 or more (mm)",
            ));
        }
        if self.kin_trafo_display > 2 {
            return Err(self.parameter(
                "kin_trafo_display",
                f64::from(self.kin_trafo_display),
                "must be 0, 1 or 2",
            ));
        }
        if self.start.len() > self.axes.len() || self.start.iter().any(|v| !v.is_finite()) {
            return Err(self.parameter(
                "start",
                self.start.len() as f64,
                "at most one finite value per axis",
            ));
        }
        if let Some(t) = self.sync_timeout_s {
            if !(t.is_finite() && t > 0.0) {
                return Err(self.parameter("sync_timeout_s", t, "must be a finite time > 0"));
            }
        }
        Ok(())
    }
}
