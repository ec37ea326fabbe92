//! The axis's outputs into its process image and HLI state block.

use super::*;

fn saturate(value: f64) -> i32 {
    value.round().clamp(i32::MIN as f64, i32::MAX as f64) as i32
}

fn direction(value_in_increments: f64) -> DirectionBits {
    if value_in_increments >= 0.5 {
        DirectionBits::Plus
    } else if value_in_increments <= -0.5 {
        DirectionBits::Minus
    } else {
        DirectionBits::Stop
    }
}

impl Axis {
    pub(super) fn outputs(&self, set: Kinematic) -> AxisOutputs {
        let drive_out = self.drive_out(set);
        let enc_out = self.encoder_out();
        let lr_state = self.lr_state(set);
        AxisOutputs {
            lr_state,
            drive_out,
            enc_out,
            command_state: self.book.image(),
            drive_state: self.drive_state(),
        }
    }

    /// The drive's outputs for set-point `set`: the two data words of the drive mode, the
    /// control word, the direction bits, the acceleration or torque set-point.
    fn drive_out(&self, set: Kinematic) -> NcDriveOut {
        let cfg = &self.config;
        let vscale = cfg.velocity_increments_per_unit;
        let out_velocity = self.output_velocity * vscale;
        let set_direction = direction(set.velocity * vscale);
        let total_direction = direction(out_velocity);
        let set_count = |p: f64| {
            cfg.encoder_width
                .wrap((p * cfg.increments_per_unit).round() as i64)
        };
        let (data1, data2) = match cfg.drive_mode {
            DriveMode::Position => {
                // Dead-time compensation: the set-point of the moment the drive applies it.
                let s = self.inputs.output_shift_s;
                let applied = set.position + set.velocity * s + 0.5 * set.acceleration * s * s;
                (set_count(applied), saturate(set.velocity * vscale))
            }
            DriveMode::Velocity => (saturate(out_velocity), set_count(set.position)),
            DriveMode::Universal => {
                let v = saturate(out_velocity);
                (v, v.saturating_abs())
            }
        };
        let control = match cfg.io.protocol {
            DriveProtocol::Plain => u8::from(self.enabled),
            DriveProtocol::Cia402 => self.control_word(),
        };
        NcDriveOut {
            nOutData1: data1,
            nOutData2: data2,
            nCtrl1: control,
            nCtrl2: set_direction.raw(),
            nCtrl3: total_direction.raw(),
            nOutData3: saturate(cfg.out_data3(set.acceleration)),
            ..bytemuck::Zeroable::zeroed()
        }
    }

    /// The encoder's outputs: the counter echo, the register request, the probe control.
    fn encoder_out(&self) -> NcEncoderOut {
        let probe = self.probes.control();
        let (register, register_value) = self.encoder_reg.control();
        NcEncoderOut {
            nOutData1: self.encoder_echo,
            nOutData2: register_value,
            nCtrl2: register,
            nCtrl1: probe.ctrl1,
            nCtrl5: probe.ctrl5,
            nCtrl6: probe.ctrl6,
            ..bytemuck::Zeroable::zeroed()
        }
    }

    /// The axis's cyclic state for set-point `set`, in HLI units.
    fn lr_state(&self, set: Kinematic) -> HliAxisLrState {
        let cfg = &self.config;
        let hli_scale = hli::units::HLI_LENGTH_PER_MM;
        // Wrapped in whole HLI units, so rounding never shows the period itself.
        let display = |p: f64| match cfg.modulo() {
            Some(m) => {
                let raw = (p * hli_scale).round() as i64;
                saturate(raw.rem_euclid((m * hli_scale).round() as i64) as f64)
            }
            None => saturate(p * hli_scale),
        };
        HliAxisLrState {
            current_position_acs_r: display(self.actual),
            command_position_acs_r: display(set.position),
            current_velocity_r: saturate(self.actual_velocity * hli_scale),
            command_velocity_r: saturate(set.velocity * hli_scale),
            command_acceleration_r: saturate(set.acceleration * 1000.0),
            following_error_r: saturate(self.following_error * hli_scale),
            axis_state_r: self.motion_state(set).raw(),
            coupling_state_r: self
                .coupling
                .map_or(CouplingState::Uncoupled, |c| c.kind)
                .raw(),
            master_axis_r: self.coupling.map_or(-1, |c| c.master),
            error_id_r: self.error.map_or(0, AxisError::raw),
            status_r: self.status_bits(set),
            nc_axis_id_r: cfg.id,
        }
    }

    /// The status bits: enabled, moving, in target, error, I/O invalid.
    fn status_bits(&self, set: Kinematic) -> u32 {
        let mut status = 0;
        if self.enabled {
            status |= axis_status::ENABLED;
        }
        let moving = match self.coupling {
            Some(_) => set.velocity != 0.0,
            None => set.velocity != 0.0 || self.generator.goal() != Goal::Hold,
        };
        if moving {
            status |= axis_status::MOVING;
        }
        if !moving && self.following_error.abs() <= self.config.in_target_window {
            status |= axis_status::IN_TARGET;
        }
        if self.error.is_some() {
            status |= axis_status::ERROR;
        }
        if self.io_fault.is_some() {
            status |= axis_status::IO_INVALID;
        }
        if self.coupling.is_some() {
            status |= self.coupled_status;
        }
        status
    }
}
