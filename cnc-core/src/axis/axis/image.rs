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
        let probe = self.probes.control();
        let drive_out = NcDriveOut {
            nOutData1: data1,
            nOutData2: data2,
            nCtrl1: control,
            nCtrl2: set_direction.raw(),
            nCtrl3: total_direction.raw(),
            nOutData3: saturate(cfg.out_data3(set.acceleration)),
            ..bytemuck::Zeroable::zeroed()
        };
        let (register, register_value) = self.encoder_reg.control();
        let enc_out = NcEncoderOut {
            nOutData1: self.encoder_echo,
            nOutData2: register_value,
            nCtrl2: register,
            nCtrl1: probe.ctrl1,
            nCtrl5: probe.ctrl5,
            nCtrl6: probe.ctrl6,
            ..bytemuck::Zeroable::zeroed()
        };
        let hli_scale = hli::units::HLI_LENGTH_PER_MM;
        // Wrapped in whole HLI units, so rounding never shows the period itself.
        let display = |p: f64| match cfg.modulo() {
            Some(m) => {
                let raw = (p * hli_scale).round() as i64;
                saturate(raw.rem_euclid((m * hli_scale).round() as i64) as f64)
            }
            None => saturate(p * hli_scale),
        };
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
        if !moving && self.following_error.abs() <= cfg.in_target_window {
            status |= axis_status::IN_TARGET;
        }
        if self.error.is_some() {
            status |= axis_status::ERROR;
        }
        if self.io_fault.is_some() {
            status |= axis_status::IO_INVALID;
        }
        let lr_state = HliAxisLrState {
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
            status_r: status,
            fill_up_1: 0,
        };
        AxisOutputs {
            lr_state,
            drive_out,
            enc_out,
            command_state: self.book.image(),
            drive_state: self.drive_state(),
        }
    }
}
