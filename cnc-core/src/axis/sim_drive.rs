//! The simulated drive and encoder: the embedded default in place of hardware. It reads the
//! drive outputs of the process image, moves a model motor with a configurable dynamic and
//! writes the encoder (and drive) inputs back, so the whole chain set-point -> increments ->
//! drive -> encoder -> overflow counting -> position controller runs as with a real axis.

use super::cia402;
use super::config::{DriveMode, DriveProtocol, ProbeInterface};
use super::encoder_reg;
use super::increments::{CounterWidth, IncrementCounter};
use super::sim_probe::SimProbes;
use hli::enums::DriveState;
use hli::layout::{NcDriveIn, NcDriveOut, NcEncoderIn, NcEncoderOut};
use serde::{Deserialize, Serialize};

/// Longest dead time the simulation holds, in ticks.
pub const MAX_DEAD_TIME_TICKS: u32 = 64;

/// How the motor answers its command.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case", tag = "type")]
pub enum Dynamic {
    /// Follows the command exactly.
    #[default]
    Ideal,
    /// First-order lag with time constant `t1_s`.
    Pt1 {
        /// Time constant in seconds.
        t1_s: f64,
    },
    /// Second-order lag with natural frequency and damping.
    Pt2 {
        /// Natural frequency in Hz.
        frequency_hz: f64,
        /// Damping ratio (1 = critically damped).
        damping: f64,
    },
}

/// A drive as machine files name it: a simulated model or an external drive.
///
/// ```toml
/// drive = { model = "pt2", frequency_hz = 80.0, damping = 0.7, dead_time_ticks = 1 }
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(rename_all = "snake_case", tag = "model", deny_unknown_fields)]
pub enum DriveModel {
    /// Simulated, follows its command exactly.
    Ideal {
        /// Ticks between command and motor.
        #[serde(default)]
        dead_time_ticks: u32,
    },
    /// Simulated first-order lag.
    Pt1 {
        /// Time constant, ms.
        t1_ms: f64,
        /// Ticks between command and motor.
        #[serde(default)]
        dead_time_ticks: u32,
    },
    /// Simulated second-order lag.
    Pt2 {
        /// Natural frequency, Hz.
        frequency_hz: f64,
        /// Damping ratio (1 = critically damped).
        damping: f64,
        /// Ticks between command and motor.
        #[serde(default)]
        dead_time_ticks: u32,
    },
    /// Something else writes the drive and encoder inputs (a field-bus task, a test).
    External,
}

impl DriveModel {
    /// The simulated drive of this model starting at `start` (None for an external drive).
    pub fn simulated(self, start: f64) -> Option<SimDriveConfig> {
        let (dynamic, dead_time_ticks) = match self {
            DriveModel::Ideal { dead_time_ticks } => (Dynamic::Ideal, dead_time_ticks),
            DriveModel::Pt1 {
                t1_ms,
                dead_time_ticks,
            } => (Dynamic::Pt1 { t1_s: t1_ms * 1e-3 }, dead_time_ticks),
            DriveModel::Pt2 {
                frequency_hz,
                damping,
                dead_time_ticks,
            } => (
                Dynamic::Pt2 {
                    frequency_hz,
                    damping,
                },
                dead_time_ticks,
            ),
            DriveModel::External => return None,
        };
        Some(SimDriveConfig {
            dynamic,
            dead_time_ticks,
            start_position: start,
            ..SimDriveConfig::default()
        })
    }
}

/// Configuration of a simulated drive.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub struct SimDriveConfig {
    /// The motor's answer to its command (to the velocity in velocity modes, to the position
    /// in position mode).
    #[serde(default)]
    pub dynamic: Dynamic,
    /// Ticks between the command and the motor seeing it.
    #[serde(default)]
    pub dead_time_ticks: u32,
    /// Position of the motor at start, units.
    #[serde(default)]
    pub start_position: f64,
    /// How long before the tick the encoder is sampled, ns (reported in `nDcInputTime`).
    #[serde(default)]
    pub input_delay_ns: u32,
    /// Sensors on the probe inputs 1 and 2: on while the motor stands in `[from, to]`, axis
    /// units.
    #[serde(default)]
    pub probe_windows: [Option<[f64; 2]>; 2],
    /// Noise on the encoder reading, axis units: each reading is off by up to this much,
    /// uniformly and the same in every run (a function of the tick alone, so every noisy
    /// axis draws the same sequence, scaled), before it is quantised to increments. 0: none.
    #[serde(default)]
    pub encoder_noise: f64,
}

impl SimDriveConfig {
    /// Checks the values: `(field, value, reason)` of the first bad one.
    pub fn validate(&self) -> Result<(), (&'static str, f64, &'static str)> {
        match self.dynamic {
            Dynamic::Ideal => {}
            Dynamic::Pt1 { t1_s } if !(t1_s > 0.0 && t1_s.is_finite()) => {
                return Err((
                    "drive.dynamic.t1_s",
                    t1_s,
                    "must be a finite number above 0",
                ))
            }
            Dynamic::Pt2 {
                frequency_hz,
                damping,
            } => {
                if !(frequency_hz > 0.0 && frequency_hz.is_finite()) {
                    return Err((
                        "drive.dynamic.frequency_hz",
                        frequency_hz,
                        "must be a finite number above 0",
                    ));
                }
                if !(damping > 0.0 && damping.is_finite()) {
                    return Err((
                        "drive.dynamic.damping",
                        damping,
                        "must be a finite number above 0",
                    ));
                }
            }
            Dynamic::Pt1 { .. } => {}
        }
        if !(self.encoder_noise >= 0.0 && self.encoder_noise.is_finite()) {
            return Err((
                "encoder_noise",
                self.encoder_noise,
                "must be a finite number, 0 or above",
            ));
        }
        if self.dead_time_ticks > MAX_DEAD_TIME_TICKS {
            return Err((
                "drive.dead_time_ticks",
                f64::from(self.dead_time_ticks),
                "must be at most 64",
            ));
        }
        for w in self.probe_windows.iter().flatten() {
            if !(w[0].is_finite() && w[1].is_finite() && w[0] < w[1]) {
                return Err((
                    "drive.probe_windows",
                    w[0],
                    "must be finite with from below to",
                ));
            }
        }
        if !self.start_position.is_finite() {
            return Err((
                "drive.start_position",
                self.start_position,
                "must be finite",
            ));
        }
        Ok(())
    }
}

/// Scaling the simulation shares with the axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimScaling {
    /// Encoder increments per unit.
    pub increments_per_unit: f64,
    /// Velocity increments per unit/s.
    pub velocity_increments_per_unit: f64,
    /// Acceleration increments per unit/s^2.
    pub acceleration_increments_per_unit: f64,
    /// Encoder counter width.
    pub width: CounterWidth,
    /// How the drive reads its set-point.
    pub mode: DriveMode,
    /// The drive's state machine.
    pub protocol: DriveProtocol,
    /// The probe interface of the encoder.
    pub probe: ProbeInterface,
    /// Actual torque scaling, increments per percent of the rated torque.
    pub torque_increments_per_percent: f64,
    /// The acceleration the rated torque gives, units/s^2 (the model's inertia).
    pub rated_acceleration: f64,
}

/// A simulated drive with its encoder.
#[derive(Debug, Clone)]
pub struct SimulatedDrive {
    config: SimDriveConfig,
    scaling: SimScaling,
    dt: f64,
    /// Motor position, velocity and acceleration.
    position: f64,
    velocity: f64,
    acceleration: f64,
    /// Rate of the quantity a PT2 follows (its own state).
    pt2_rate: f64,
    /// The command as the drive sees it, delayed.
    delay: [f64; MAX_DEAD_TIME_TICKS as usize + 1],
    delay_head: usize,
    /// Unwraps the position set-point of a position-mode drive.
    set_counter: IncrementCounter,
    /// Fault injection: report I/O data invalid on the encoder or drive.
    pub encoder_io_invalid: bool,
    /// Fault injection: report I/O data invalid on the drive.
    pub drive_io_invalid: bool,
    /// Fault injection: the drive goes to Fault (CiA 402) at its next step.
    pub inject_fault: bool,
    /// Fault injection: status word low byte reported instead of the state's (CiA 402).
    pub status_override: Option<u8>,
    /// CiA 402 state.
    state: DriveState,
    last_control: u8,
    probes: SimProbes,
    enc_out: NcEncoderOut,
    /// The encoder's count minus the motor position's (a counter set moves it).
    count_offset: i64,
    /// The offset the drive reads its position set-point with: the count's, taken over when
    /// the NC withdraws its set-counter request (from then on its set-points count anew).
    setpoint_offset: i64,
    /// The register answers in `nStatus2` (see `axis::encoder_reg`).
    register: u8,
    /// Steps taken: the reading it writes belongs to tick `steps`.
    steps: u64,
}

impl SimulatedDrive {
    /// A drive standing at its configured start position.
    pub fn new(config: SimDriveConfig, scaling: SimScaling, cycle_s: f64) -> Self {
        let start_command = match scaling.mode {
            DriveMode::Position => config.start_position,
            DriveMode::Velocity | DriveMode::Universal => 0.0,
        };
        Self {
            position: config.start_position,
            velocity: 0.0,
            acceleration: 0.0,
            pt2_rate: 0.0,
            delay: [start_command; MAX_DEAD_TIME_TICKS as usize + 1],
            delay_head: 0,
            set_counter: {
                // Seeded with the start position, so a 16-bit set-point far from zero is not
                // read as a sign-extended first value.
                let mut counter = IncrementCounter::new(scaling.width);
                let start = (config.start_position * scaling.increments_per_unit).round() as i64;
                counter.seed(start, scaling.width.wrap(start));
                counter
            },
            encoder_io_invalid: false,
            drive_io_invalid: false,
            inject_fault: false,
            status_override: None,
            state: DriveState::SwitchOnDisabled,
            last_control: 0,
            probes: SimProbes::new(
                scaling.probe,
                scaling.width,
                scaling.increments_per_unit,
                config.probe_windows,
            ),
            enc_out: bytemuck::Zeroable::zeroed(),
            count_offset: 0,
            setpoint_offset: 0,
            register: 0,
            steps: 0,
            config,
            scaling,
            dt: cycle_s,
        }
    }

    /// The distributed-clock time of tick `tick`, ns (low 32 bits, as the image carries it).
    fn dc_time(&self, tick: u64) -> u32 {
        (tick as f64 * self.dt * 1e9).round() as u64 as u32
    }

    /// This tick's encoder noise: uniform in `±encoder_noise`, from the tick number alone
    /// (splitmix64), so every run reads the same.
    fn noise(&self) -> f64 {
        if self.config.encoder_noise == 0.0 {
            return 0.0;
        }
        let mut z = self.steps.wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        let unit = (z >> 11) as f64 / (1u64 << 53) as f64; // [0, 1)
        (2.0 * unit - 1.0) * self.config.encoder_noise
    }

    /// The motor's true position.
    pub fn position(&self) -> f64 {
        self.position
    }

    /// The motor's true velocity.
    pub fn velocity(&self) -> f64 {
        self.velocity
    }

    /// The encoder inputs of the motor's current position (what the NC reads next tick).
    ///
    /// The encoder is sampled `input_delay_ns` before the tick (the motor was that much
    /// behind at constant velocity), and says so in `nDcInputTime`.
    pub fn encoder_in(&self) -> NcEncoderIn {
        let delay = f64::from(self.config.input_delay_ns) * 1e-9;
        let sampled = self.position - self.velocity * delay + self.noise();
        let count = (sampled * self.scaling.increments_per_unit).round() as i64 + self.count_offset;
        let mut enc = NcEncoderIn {
            nInData1: self.scaling.width.wrap(count),
            nStatus2: self.register,
            nStatus4: u8::from(self.encoder_io_invalid),
            nDcInputTime: self
                .dc_time(self.steps)
                .wrapping_sub(self.config.input_delay_ns) as i32,
            ..bytemuck::Zeroable::zeroed()
        };
        self.probes.report(&self.enc_out, &mut enc);
        if self.register & encoder_reg::READ_ABSOLUTE != 0 {
            enc.nInData2 = count.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32;
        }
        enc
    }

    /// The encoder's side of the register interface: a request bit is answered in the step
    /// it comes (a counter set takes effect at once) and the answer falls with the request.
    fn serve_register(&mut self, enc_out: &NcEncoderOut) {
        for bit in [encoder_reg::SET_COUNTER, encoder_reg::READ_ABSOLUTE] {
            let asked = enc_out.nCtrl2 & bit != 0;
            if asked && self.register & bit == 0 {
                if bit == encoder_reg::SET_COUNTER {
                    let now = (self.position * self.scaling.increments_per_unit).round() as i64;
                    let width = self.scaling.width;
                    // The shortest way to the value: a 16-bit count keeps its unwrapping.
                    let old = width.wrap(now + self.count_offset);
                    self.count_offset += width.delta(old, enc_out.nOutData2);
                }
                self.register |= bit;
            } else if !asked {
                if self.register & bit != 0 && bit == encoder_reg::SET_COUNTER {
                    self.setpoint_offset = self.count_offset;
                }
                self.register &= !bit;
            }
        }
    }

    /// Takes the drive and encoder outputs of this tick, advances the motor one tick and
    /// returns the drive inputs.
    pub fn step(&mut self, out: &NcDriveOut, enc_out: &NcEncoderOut) -> NcDriveIn {
        let operational = match self.scaling.protocol {
            DriveProtocol::Plain => true,
            DriveProtocol::Cia402 => {
                let reset_edge = out.nCtrl1 & cia402::control::FAULT_RESET != 0
                    && self.last_control & cia402::control::FAULT_RESET == 0;
                self.last_control = out.nCtrl1;
                self.state = if std::mem::take(&mut self.inject_fault) {
                    DriveState::Fault
                } else {
                    cia402::next_state(self.state, out.nCtrl1, reset_edge)
                };
                self.state == DriveState::OperationEnabled
            }
        };
        self.enc_out = *enc_out;
        self.serve_register(enc_out);
        let from = self.position;
        let command = match self.scaling.mode {
            DriveMode::Position => {
                (self.set_counter.update(out.nOutData1) - self.setpoint_offset) as f64
                    / self.scaling.increments_per_unit
            }
            DriveMode::Velocity | DriveMode::Universal => {
                f64::from(out.nOutData1) / self.scaling.velocity_increments_per_unit
            }
        };
        // Dead time: the command enters a ring and leaves `dead_time_ticks` later.
        let len = self.config.dead_time_ticks as usize + 1;
        self.delay[self.delay_head] = command;
        self.delay_head = (self.delay_head + 1) % len;
        let mut seen = self.delay[self.delay_head];
        if !operational {
            // A drive that is not in operation holds: no velocity, the position where it is.
            seen = match self.scaling.mode {
                DriveMode::Position => self.position,
                DriveMode::Velocity | DriveMode::Universal => 0.0,
            };
        }
        let before = self.velocity;
        match self.scaling.mode {
            DriveMode::Position => {
                let old = self.position;
                self.position = self.follow(self.position, seen);
                self.velocity = (self.position - old) / self.dt;
            }
            DriveMode::Velocity | DriveMode::Universal => {
                self.velocity = self.follow(self.velocity, seen);
                self.position += self.velocity * self.dt;
            }
        }
        self.acceleration = (self.velocity - before) / self.dt;
        let following = match self.scaling.mode {
            DriveMode::Position => {
                ((seen - self.position) * self.scaling.increments_per_unit).round() as i32
            }
            _ => 0,
        };
        self.probes
            .step(enc_out, from, self.position, self.count_offset);
        self.steps += 1;
        // Torque in proportion to the acceleration: the rated torque gives the rated one.
        let torque_percent = 100.0 * self.acceleration / self.scaling.rated_acceleration;
        let (status1, status2) = match self.scaling.protocol {
            DriveProtocol::Plain => (0, 0),
            DriveProtocol::Cia402 => {
                let position_mode = self.scaling.mode == DriveMode::Position;
                let in_operation = self.state == DriveState::OperationEnabled;
                (
                    self.status_override
                        .unwrap_or(cia402::status_of(self.state)),
                    cia402::status_high(true, following == 0, in_operation && position_mode, false),
                )
            }
        };
        // The set-point taken now is applied after the dead time, at the end of that tick.
        let applied_at = self.dc_time(self.steps + 1 + u64::from(self.config.dead_time_ticks));
        NcDriveIn {
            nInData1: following,
            nStatus1: status1,
            nStatus2: status2,
            nStatus4: u8::from(self.drive_io_invalid),
            nInData3: (torque_percent * self.scaling.torque_increments_per_percent)
                .round()
                .clamp(i32::MIN as f64, i32::MAX as f64) as i32,
            nDcOutputTime: applied_at as i32,
            ..bytemuck::Zeroable::zeroed()
        }
    }

    /// One tick of the dynamic from `value` towards `command`.
    fn follow(&mut self, value: f64, command: f64) -> f64 {
        match self.config.dynamic {
            Dynamic::Ideal => command,
            Dynamic::Pt1 { t1_s } => {
                let alpha = 1.0 - (-self.dt / t1_s).exp();
                value + alpha * (command - value)
            }
            Dynamic::Pt2 {
                frequency_hz,
                damping,
            } => {
                // Semi-implicit Euler in 8 sub-steps: stable for w*h < 2.
                let w = 2.0 * core::f64::consts::PI * frequency_hz;
                let h = self.dt / 8.0;
                let mut x = value;
                let mut rate = self.pt2_rate;
                for _ in 0..8 {
                    rate += h * (w * w * (command - x) - 2.0 * damping * w * rate);
                    x += h * rate;
                }
                self.pt2_rate = rate;
                x
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drive(dynamic: Dynamic, dead_time_ticks: u32) -> SimulatedDrive {
        let config = SimDriveConfig {
            dynamic,
            dead_time_ticks,
            ..SimDriveConfig::default()
        };
        let scaling = SimScaling {
            increments_per_unit: 10_000.0,
            velocity_increments_per_unit: 10_000.0,
            acceleration_increments_per_unit: 1_000.0,
            width: CounterWidth::Bits32,
            mode: DriveMode::Velocity,
            protocol: DriveProtocol::Plain,
            probe: ProbeInterface::None,
            torque_increments_per_percent: 10.0,
            rated_acceleration: 10_000.0,
        };
        SimulatedDrive::new(config, scaling, 0.001)
    }

    fn velocity_step(d: &mut SimulatedDrive, ticks: usize) -> Vec<f64> {
        let out = NcDriveOut {
            nOutData1: 1_000_000,
            ..bytemuck::Zeroable::zeroed()
        }; // 100 mm/s
        (0..ticks)
            .map(|_| {
                d.step(&out, &bytemuck::Zeroable::zeroed());
                d.velocity()
            })
            .collect()
    }

    #[test]
    fn dead_time_delays_the_command_by_whole_ticks() {
        let v = velocity_step(&mut drive(Dynamic::Ideal, 3), 6);
        assert_eq!(v, [0.0, 0.0, 0.0, 100.0, 100.0, 100.0]);
    }

    #[test]
    fn pt1_reaches_63_percent_after_one_time_constant() {
        let v = velocity_step(&mut drive(Dynamic::Pt1 { t1_s: 0.02 }, 0), 20);
        assert!(
            (v[19] - 100.0 * (1.0 - (-1.0f64).exp())).abs() < 0.01,
            "{}",
            v[19]
        );
    }

    #[test]
    fn underdamped_pt2_overshoots_as_its_damping_says_and_settles() {
        let v = velocity_step(
            &mut drive(
                Dynamic::Pt2 {
                    frequency_hz: 20.0,
                    damping: 0.5,
                },
                0,
            ),
            1000,
        );
        let peak = v.iter().cloned().fold(f64::MIN, f64::max);
        // Overshoot of a second-order step: exp(-pi z / sqrt(1 - z^2)) = 16.3 % for z = 0.5.
        let expected = 100.0 * (1.0 + (-core::f64::consts::PI * 0.5 / 0.75f64.sqrt()).exp());
        assert!(
            (peak - expected).abs() < 0.5,
            "peak {peak}, expected {expected}"
        );
        assert!((v[999] - 100.0).abs() < 1e-3);
    }

    #[test]
    fn encoder_reports_io_invalid_when_told() {
        let mut d = drive(Dynamic::Ideal, 0);
        assert_eq!(d.encoder_in().nStatus4, 0);
        d.encoder_io_invalid = true;
        assert_eq!(d.encoder_in().nStatus4, 1);
    }
}
