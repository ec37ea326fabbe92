//! The optional inputs of the process image (seed 004), read into plain values: the drive's
//! own following error and torque, its state machine (CiA 402 protocol), and the
//! distributed-clock times for dead-time compensation. Every word is validated; one with
//! undefined bits or a time out of range is counted and not used.

use super::cia402;
use super::config::{AxisConfig, DriveMode, DriveProtocol, ImageOptions};
use hli::enums::DriveState;
use hli::layout::{HliAxisDriveState, HliAxisProbe, NcDriveIn, NcEncoderIn, HLI_AXIS_PROBES};
use hli::units::HLI_LENGTH_PER_MM;

/// Longest dead time a drive may report in `nDcOutputTime`, in ticks (as the simulation's).
pub const MAX_OUTPUT_SHIFT_TICKS: i64 = super::sim_drive::MAX_DEAD_TIME_TICKS as i64;

/// The evaluated optional inputs of one axis.
#[derive(Debug, Clone)]
pub struct DriveInputs {
    options: ImageOptions,
    mode: DriveMode,
    increments_per_unit: f64,
    cycle_ns: i64,
    /// Ticks sensed: the distributed clock of the CNC counts `ticks * cycle`.
    ticks: u64,
    /// The drive's state (CiA 402), NotEvaluated for a plain drive.
    pub state: DriveState,
    /// `drive_flags_r` bits.
    pub flags: u32,
    /// Actual torque, percent of the rated torque.
    pub torque_percent: f64,
    /// The drive's own following error (position mode), units.
    pub external_following_error: f64,
    /// How long before the tick the encoder was read, s (0 without compensation).
    pub input_lag_s: f64,
    /// How long after the end of the tick the drive applies its set-point, s (0 without
    /// compensation).
    pub output_shift_s: f64,
    /// Input words not used because of undefined bits or out-of-range times.
    pub undefined: u32,
}

impl DriveInputs {
    /// The inputs of an axis configured by `config`, ticking every `cycle_s`.
    pub fn new(config: &AxisConfig, cycle_s: f64) -> Self {
        Self {
            options: config.io,
            mode: config.drive_mode,
            increments_per_unit: config.increments_per_unit,
            cycle_ns: (cycle_s * 1e9).round() as i64,
            ticks: 0,
            state: DriveState::NotEvaluated,
            flags: 0,
            torque_percent: 0.0,
            external_following_error: 0.0,
            input_lag_s: 0.0,
            output_shift_s: 0.0,
            undefined: 0,
        }
    }

    /// The CNC's distributed-clock time of the current tick, ns, low 32 bits.
    fn now(&self) -> u32 {
        (self.ticks as i64 * self.cycle_ns) as u64 as u32
    }

    /// Reads this tick's inputs. Returns the decoded drive state: `Some(NotEvaluated)` for a
    /// plain drive, `None` when the status word has no defined state (counted).
    pub fn read(&mut self, enc_in: &NcEncoderIn, drive_in: &NcDriveIn) -> Option<DriveState> {
        let now = self.now();
        self.ticks += 1;
        self.torque_percent =
            f64::from(drive_in.nInData3) / self.options.torque_increments_per_percent;
        // The drive reports its own following error in cyclic position mode only.
        self.external_following_error = match self.mode {
            DriveMode::Position => f64::from(drive_in.nInData1) / self.increments_per_unit,
            DriveMode::Velocity | DriveMode::Universal => 0.0,
        };
        if self.options.dc_compensation {
            let cycle = self.cycle_ns;
            let lag = i64::from(now.wrapping_sub(enc_in.nDcInputTime as u32) as i32);
            self.input_lag_s = self.checked(lag, 0, 2 * cycle);
            let nominal = now.wrapping_add(cycle as u32);
            let shift = i64::from((drive_in.nDcOutputTime as u32).wrapping_sub(nominal) as i32);
            self.output_shift_s = self.checked(shift, -cycle, MAX_OUTPUT_SHIFT_TICKS * cycle);
        }
        match self.options.protocol {
            DriveProtocol::Plain => {
                self.state = DriveState::NotEvaluated;
                Some(DriveState::NotEvaluated)
            }
            DriveProtocol::Cia402 => {
                self.flags = cia402::flags(drive_in.nStatus1, drive_in.nStatus2);
                let decoded = cia402::decode_state(drive_in.nStatus1);
                match decoded {
                    Some(state) => self.state = state,
                    None => self.undefined = self.undefined.wrapping_add(1),
                }
                decoded
            }
        }
    }

    /// `value_ns` in seconds when inside `[min, max]`, else 0 and counted.
    fn checked(&mut self, value_ns: i64, min: i64, max: i64) -> f64 {
        if (min..=max).contains(&value_ns) {
            value_ns as f64 * 1e-9
        } else {
            self.undefined = self.undefined.wrapping_add(1);
            0.0
        }
    }

    /// The block `gpAx[i]^drive_state`.
    pub fn image(&self, probes: [HliAxisProbe; HLI_AXIS_PROBES]) -> HliAxisDriveState {
        let clamp = |v: f64| v.round().clamp(i32::MIN as f64, i32::MAX as f64) as i32;
        HliAxisDriveState {
            drive_following_error_r: clamp(self.external_following_error * HLI_LENGTH_PER_MM),
            actual_torque_r: clamp(self.torque_percent * 10.0),
            drive_state_r: self.state.raw(),
            drive_flags_r: self.flags,
            dc_input_lag_r: clamp(self.input_lag_s * 1e9),
            dc_output_shift_r: clamp(self.output_shift_s * 1e9),
            undefined_inputs_r: self.undefined,
            superimposed_id_r: 0,
            probe_r: probes,
        }
    }
}
