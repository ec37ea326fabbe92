//! One axis: command validation, set-point generation, actual position from the encoder,
//! following-error monitoring, the position controller and the drive outputs.

mod coupled;
mod encoder;
mod image;
mod superimposed;

use super::cia402;
use super::commands::CommandBook;
use super::config::{AxisConfig, DriveMode, DriveProtocol};
use super::encoder_reg::{EncoderEvent, EncoderRegister};
use super::generator::{Goal, MoveLimits, Progress, SetpointGenerator};
use super::increments::IncrementCounter;
use super::inputs::DriveInputs;
use super::probe::Probes;
use crate::setpoint::Kinematic;
use hli::calls::axis::AxisCommandCall;
use hli::calls::probe::{ProbeAbortCall, ProbeArmCall};
use hli::enums::{
    axis_status, drive_flags, AxisCommandKind, AxisError, AxisState, CommandResult, CouplingState,
    DirectionBits, DriveState, IoState,
};
use hli::layout::{
    HliAxisCommandState, HliAxisDriveState, HliAxisLrState, NcDriveIn, NcDriveOut, NcEncoderIn,
    NcEncoderOut,
};

/// Ticks MC_Reset waits for a drive to leave Fault (pulsing fault reset every other tick)
/// before it ends with `ResetRefused`.
pub const DRIVE_RESET_TIMEOUT_TICKS: u32 = 100;

/// A coupling that drives the axis instead of its own generator (cam, gear, FIFO group,
/// channel): the engine hands in a set-point every tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coupling {
    /// What the axis is coupled to.
    pub kind: CouplingState,
    /// Index of the master axis, -1 when the master is not an axis.
    pub master: i32,
    /// Slave phase shown in `nAxisState` (11, 12, 13).
    pub phase: AxisState,
}

/// Everything the axis writes to the image in one tick.
#[derive(Debug, Clone, Copy)]
pub struct AxisOutputs {
    /// Cyclic state.
    pub lr_state: HliAxisLrState,
    /// Drive outputs.
    pub drive_out: NcDriveOut,
    /// Encoder outputs.
    pub enc_out: NcEncoderOut,
    /// Command book.
    pub command_state: HliAxisCommandState,
    /// The evaluated optional inputs and the touch probes.
    pub drive_state: HliAxisDriveState,
}

/// An axis.
#[derive(Debug)]
pub struct Axis {
    config: AxisConfig,
    cycle_s: f64,
    generator: SetpointGenerator,
    counter: IncrementCounter,
    /// The encoder's register interface (`nCtrl2`/`nStatus2`).
    encoder_reg: EncoderRegister,
    /// The count MC_SetPosition asked for, until the encoder answered.
    new_count: Option<i64>,
    book: CommandBook,
    /// MC_Power's level; with a CiA 402 drive the axis is enabled once the drive is in
    /// operation.
    power_requested: bool,
    enabled: bool,
    /// MC_Reset of a drive fault under way: ticks since it began.
    drive_reset: Option<u32>,
    inputs: DriveInputs,
    probes: Probes,
    /// The encoder's position as read, before dead-time compensation.
    raw_actual: f64,
    stop_lock: bool,
    error: Option<AxisError>,
    coupling: Option<Coupling>,
    /// Counts couplings: an engine that holds the number it coupled with knows the axis is
    /// still its own (and not re-coupled by another engine in between).
    /// Status bits the engine that holds the axis reports (`axis_status::CAM_DATA_QUEUED`),
    /// shown while it holds it.
    coupled_status: u32,
    coupling_epoch: u32,
    coupled_setpoint: Kinematic,
    superimposed: superimposed::Superimposed,
    /// The set-point handed out by the last tick (what the actual position must match now).
    last_set: Kinematic,
    /// The encoder count read in `sense`, mirrored to `enc_out` in `act`.
    encoder_echo: i32,
    /// Between `sense` and `act` of a tick (an engine decoupling now steps the generator).
    sensed: bool,
    io_fault: Option<AxisError>,
    actual: f64,
    actual_velocity: f64,
    /// From the last two actual velocities (0 until two were measured).
    actual_acceleration: f64,
    /// Encoder readings since the count (re)started, up to 3, and the last velocity from raw
    /// readings (without the dead-time compensation, which would show as acceleration).
    readings: u8,
    raw_velocity: f64,
    following_error: f64,
    output_velocity: f64,
}

impl Axis {
    /// An axis from a validated configuration, standing where it is (its first encoder reading
    /// sets the set-point), disabled.
    pub fn new(config: AxisConfig, cycle_s: f64) -> Self {
        let mut generator = SetpointGenerator::new(cycle_s, 0.0);
        generator.set_jerk_ceiling(config.dynamics.jerk);
        Self {
            inputs: DriveInputs::new(&config, cycle_s),
            probes: Probes::new(config.io.probe, config.encoder_width),
            counter: IncrementCounter::new(config.encoder_width),
            encoder_reg: {
                let mut r = EncoderRegister::default();
                if config.io.encoder_absolute {
                    r.read_absolute();
                }
                r
            },
            new_count: None,
            superimposed: superimposed::Superimposed::new(cycle_s, config.dynamics.jerk),
            generator,
            config,
            cycle_s,
            book: CommandBook::default(),
            power_requested: false,
            enabled: false,
            drive_reset: None,
            raw_actual: 0.0,
            stop_lock: false,
            error: None,
            coupling: None,
            coupled_status: 0,
            coupling_epoch: 0,
            coupled_setpoint: Kinematic::default(),
            last_set: Kinematic::default(),
            encoder_echo: 0,
            sensed: false,
            io_fault: None,
            actual: 0.0,
            actual_velocity: 0.0,
            actual_acceleration: 0.0,
            readings: 0,
            raw_velocity: 0.0,
            following_error: 0.0,
            output_velocity: 0.0,
        }
    }

    /// Its configuration.
    pub fn config(&self) -> &AxisConfig {
        &self.config
    }
    /// The set-point of the last tick.
    pub fn setpoint(&self) -> Kinematic {
        match self.coupling {
            Some(_) => superimposed::with_offset(self.coupled_setpoint, self.superimposed.state()),
            None => self.generator.state(),
        }
    }
    /// The actual position of the last tick.
    pub fn actual(&self) -> f64 {
        self.actual
    }
    /// The actual velocity (from the last two encoder readings).
    pub fn actual_velocity(&self) -> f64 {
        self.actual_velocity
    }
    /// Position, velocity and acceleration from the encoder alone (the last three readings;
    /// through `io.actual_filter_s`'s filter, if any: else quantisation and noise show in
    /// velocity and more in acceleration; the acceleration 0 with `io.actual_acceleration`
    /// off).
    pub fn actual_kinematic(&self) -> Kinematic {
        Kinematic {
            position: self.actual,
            velocity: self.actual_velocity,
            acceleration: self.actual_acceleration,
            jerk: 0.0,
        }
    }
    /// Set minus actual position of the last tick.
    pub fn following_error(&self) -> f64 {
        self.following_error
    }
    /// The error that stopped the axis, if any.
    pub fn error(&self) -> Option<AxisError> {
        self.error
    }
    /// Whether the axis is enabled.
    pub fn enabled(&self) -> bool {
        self.enabled
    }
    /// Whether the axis has read its encoder once (before that its position is unknown).
    pub fn has_position(&self) -> bool {
        self.counter.started()
    }
    /// The coupling that drives the axis, if any.
    pub fn coupling(&self) -> Option<Coupling> {
        self.coupling
    }
    /// The command book.
    pub fn book(&self) -> &CommandBook {
        &self.book
    }

    /// Takes a command; returns its id or why it was refused. A refused command changes
    /// nothing: a move in progress goes on.
    pub fn command(&mut self, call: &AxisCommandCall) -> Result<u32, AxisError> {
        let kind =
            AxisCommandKind::decode(call.command).map_err(|_| AxisError::InvalidParameter)?;
        if call.reserved != 0 {
            return Err(AxisError::InvalidParameter);
        }
        match kind {
            // An engine's coupling, not an axis command.
            AxisCommandKind::GearIn => Err(AxisError::InvalidParameter),
            AxisCommandKind::MoveSuperimposed => self.superimpose(call),
            AxisCommandKind::Power => self.power(call.enable),
            AxisCommandKind::Reset => self.reset(),
            AxisCommandKind::SetPosition => self.set_position(call.position),
            AxisCommandKind::StopRelease => {
                self.stop_lock = false;
                Ok(self.book.instant(kind))
            }
            AxisCommandKind::Stop => {
                self.may_move(false)?;
                let (dec, jerk) = self.braking(call)?;
                self.generator
                    .brake(dec, jerk)
                    .map_err(|_| AxisError::GeneratorFailed)?;
                self.stop_lock = true;
                Ok(self.book.begin(kind))
            }
            AxisCommandKind::Halt => {
                self.may_move(true)?;
                let (dec, jerk) = self.braking(call)?;
                self.generator
                    .brake(dec, jerk)
                    .map_err(|_| AxisError::GeneratorFailed)?;
                Ok(self.book.begin(kind))
            }
            AxisCommandKind::MoveAbsolute | AxisCommandKind::MoveRelative => {
                self.may_move(true)?;
                let limits = self.move_limits(call)?;
                let target = if kind == AxisCommandKind::MoveAbsolute {
                    call.position
                } else {
                    self.generator.state().position + call.position
                };
                self.check_target(target)?;
                self.generator
                    .move_to(target, limits)
                    .map_err(|_| AxisError::GeneratorFailed)?;
                Ok(self.book.begin(kind))
            }
            AxisCommandKind::MoveVelocity => {
                self.may_move(true)?;
                let limits = self.move_limits(call)?;
                let sign = match call.direction {
                    1 => 1.0,
                    -1 => -1.0,
                    _ => return Err(AxisError::InvalidDirection),
                };
                self.generator
                    .run_at(sign * limits.velocity, limits)
                    .map_err(|_| AxisError::GeneratorFailed)?;
                Ok(self.book.begin(kind))
            }
        }
    }

    fn power(&mut self, enable: u32) -> Result<u32, AxisError> {
        match enable {
            1 => {
                if self.error.is_some() {
                    return Err(AxisError::AxisInError);
                }
                if self.encoder_reg.reading_absolute() {
                    return Err(AxisError::EncoderNotReady);
                }
                self.power_requested = true;
                // A CiA 402 drive is enabled once it reports Operation enabled (`sense`).
                if self.config.io.protocol == DriveProtocol::Plain {
                    self.take_over();
                }
            }
            0 => {
                // Coupled: the engine's motion and a superimposed move count alike.
                let moving = match self.coupling {
                    Some(_) => self.setpoint().velocity != 0.0 || self.superimposed.id() != 0,
                    None => self.generator.goal() != Goal::Hold,
                };
                if moving {
                    return Err(AxisError::MovingWhileDisable);
                }
                // A disabled axis is nobody's slave: the coupling ends with the power.
                self.drop_superimposed(CommandResult::Aborted, None);
                self.coupling = None;
                self.stop_lock = false;
                self.power_requested = false;
                self.enabled = false;
                self.book.finish(CommandResult::Aborted, None);
            }
            _ => return Err(AxisError::InvalidParameter),
        }
        Ok(self.book.instant(AxisCommandKind::Power))
    }

    /// Enables the axis where it stands, without a jump.
    fn take_over(&mut self) {
        if !self.enabled {
            self.generator.hold(self.actual);
        }
        self.enabled = true;
    }

    fn reset(&mut self) -> Result<u32, AxisError> {
        if self.io_fault.is_some() {
            return Err(AxisError::ResetRefused);
        }
        if self.config.io.protocol == DriveProtocol::Cia402 && cia402::is_fault(self.inputs.state) {
            // The drive needs a fault reset first; the command ends when the drive leaves
            // Fault (`sense`).
            self.drive_reset = Some(0);
            return Ok(self.book.begin(AxisCommandKind::Reset));
        }
        self.reread_absolute();
        self.clear_error();
        Ok(self.book.instant(AxisCommandKind::Reset))
    }

    /// Clears the axis error; the axis takes over where it stands. Without an error there is
    /// nothing to clear: a moving axis goes on undisturbed.
    fn clear_error(&mut self) {
        if self.error.take().is_some() {
            self.generator.hold(self.actual);
            // The following error of the next tick is measured against where the axis was
            // taken over, not against the set-point the fault froze (the drive may have
            // drifted from it since): a reset does not fault again at once.
            self.last_set = Kinematic {
                position: self.actual,
                ..Kinematic::default()
            };
        }
    }

    fn may_move(&self, respect_stop_lock: bool) -> Result<(), AxisError> {
        if self.error.is_some() {
            return Err(AxisError::AxisInError);
        }
        if self.encoder_reg.setting_counter() {
            // The count changes under the move's feet when the encoder answers.
            return Err(AxisError::EncoderNotReady);
        }
        if !self.enabled {
            return Err(AxisError::NotEnabled);
        }
        if self.coupling.is_some() {
            return Err(AxisError::Coupled);
        }
        if respect_stop_lock && self.stop_lock {
            return Err(AxisError::StopActive);
        }
        Ok(())
    }

    fn within(value: f64, max: f64) -> bool {
        value > 0.0 && value <= max && value.is_finite()
    }

    fn braking(&self, call: &AxisCommandCall) -> Result<(f64, f64), AxisError> {
        let d = self.config.dynamics;
        if !Self::within(call.deceleration, d.deceleration) {
            return Err(AxisError::InvalidDeceleration);
        }
        if !Self::within(call.jerk, d.jerk) {
            return Err(AxisError::InvalidJerk);
        }
        Ok((call.deceleration, call.jerk))
    }

    fn move_limits(&self, call: &AxisCommandCall) -> Result<MoveLimits, AxisError> {
        let d = self.config.dynamics;
        if !Self::within(call.velocity, d.velocity) {
            return Err(AxisError::InvalidVelocity);
        }
        if !Self::within(call.acceleration, d.acceleration) {
            return Err(AxisError::InvalidAcceleration);
        }
        let (deceleration, jerk) = self.braking(call)?;
        Ok(MoveLimits {
            velocity: call.velocity,
            acceleration: call.acceleration,
            deceleration,
            jerk,
        })
    }

    fn check_target(&self, target: f64) -> Result<(), AxisError> {
        let inside = match self.config.soft_limits {
            Some([min, max]) => (min..=max).contains(&target),
            None => target.is_finite(),
        };
        if inside {
            Ok(())
        } else {
            Err(AxisError::TargetOutsideLimits)
        }
    }

    /// MC_TouchProbe: arms a probe (see [`Probes::arm`]).
    pub fn arm_probe(&mut self, call: &ProbeArmCall) -> Result<u32, AxisError> {
        self.probes.arm(call)
    }

    /// MC_AbortTrigger: disarms a probe.
    pub fn abort_probe(&mut self, call: &ProbeAbortCall) -> Result<u32, AxisError> {
        self.probes.abort(call)
    }

    /// The evaluated drive inputs.
    pub fn drive_state(&self) -> HliAxisDriveState {
        HliAxisDriveState {
            superimposed_id_r: self.superimposed.id(),
            ..self.inputs.image(self.probes.image())
        }
    }

    /// Enables the axis as MC_Power would (for axes the CNC itself owns: channel axes).
    pub fn switch_on(&mut self) -> Result<(), AxisError> {
        self.power(1).map(|_| ())
    }

    fn fault(&mut self, error: AxisError) {
        if self.error.is_none() {
            self.error = Some(error);
        }
        self.book.finish(CommandResult::Error, Some(error));
        self.drop_superimposed(CommandResult::Error, Some(error));
        self.coupling = None;
        self.stop_lock = false;
        // A safe set-point: stand where the axis is; the output velocity is zero.
        self.generator.hold(self.actual);
    }

    /// One tick: [`Axis::sense`] then [`Axis::act`] (an engine that couples this axis hands
    /// its set-point in between).
    pub fn tick(&mut self, enc_in: &NcEncoderIn, drive_in: &NcDriveIn) -> AxisOutputs {
        self.sense(enc_in, drive_in);
        self.act()
    }

    /// First half of a tick: reads the inputs and, on a free axis, runs the generator one
    /// step, so engines coupled to this axis see its set-point of this tick.
    pub fn sense(&mut self, enc_in: &NcEncoderIn, drive_in: &NcDriveIn) {
        let scale = self.config.increments_per_unit;
        let drive_state = self.inputs.read(enc_in, drive_in);
        // Inputs: a status byte that is not a valid IoState counts as invalid too.
        let encoder_valid = IoState::decode(enc_in.nStatus4) == Ok(IoState::Valid);
        let encoder_error = self
            .config
            .io
            .encoder_error
            .is_some_and(|bit| bit.reported(enc_in.nStatus1));
        let encoder_ok = encoder_valid && !encoder_error;
        let drive_ok = IoState::decode(drive_in.nStatus4) == Ok(IoState::Valid);
        self.io_fault = if !encoder_valid {
            Some(AxisError::EncoderIoInvalid)
        } else if encoder_error {
            Some(AxisError::EncoderError)
        } else if !drive_ok {
            Some(AxisError::DriveIoInvalid)
        } else {
            None
        };
        if encoder_ok {
            // A re-based count starts afresh (no velocity from the jump).
            let rebased = self.encoder_answer(enc_in);
            let first = !self.counter.started() || rebased;
            let previous = self.actual;
            let count = self.counter.update(enc_in.nInData1);
            let raw = count as f64 / scale;
            // Dead-time compensation: the reading is `input_lag` old; the axis moved on at
            // the velocity of the last two readings.
            let raw_velocity = if first {
                0.0
            } else {
                (raw - self.raw_actual) / self.cycle_s
            };
            self.raw_actual = raw;
            self.actual = raw + raw_velocity * self.inputs.input_lag_s;
            let velocity = if first {
                0.0
            } else {
                (self.actual - previous) / self.cycle_s
            };
            // Two raw velocities since the count started make an acceleration.
            self.readings = if first { 1 } else { (self.readings + 1).min(3) };
            let acceleration = match self.readings {
                3 if self.config.io.actual_acceleration => {
                    (raw_velocity - self.raw_velocity) / self.cycle_s
                }
                _ => 0.0,
            };
            self.filter_actual(first, velocity, acceleration);
            self.raw_velocity = raw_velocity;
            let undefined = self.probes.sense(enc_in, enc_in.nInData1, count, scale);
            self.inputs.undefined = self.inputs.undefined.wrapping_add(undefined);
            if first {
                self.generator.hold(self.actual);
                self.last_set = Kinematic {
                    position: self.actual,
                    ..Kinematic::default()
                };
            }
        }
        if !encoder_ok {
            self.probes.lose_data(if encoder_valid {
                AxisError::EncoderError
            } else {
                AxisError::EncoderIoInvalid
            });
        }
        if let Some(cause) = self.io_fault {
            if self.enabled && self.error.is_none() {
                self.fault(cause);
            }
        }
        if drive_ok {
            self.follow_drive_state(drive_state);
        }
        self.encoder_echo = enc_in.nInData1;
        self.sensed = true;
        // This tick's generator step (or the coupled engine, between `sense` and `act`)
        // produces the set-point for the end of the coming tick.
        if !self.enabled {
            self.generator.hold(self.actual);
        } else if self.error.is_none() {
            self.generate();
        }
    }

    /// A CiA 402 drive's state against what the axis expects: the axis is enabled once the
    /// drive is in operation; a drive that faults, or leaves operation on its own, or reports
    /// no defined state, stops the axis; MC_Reset of a drive fault ends here.
    fn follow_drive_state(&mut self, decoded: Option<DriveState>) {
        if self.config.io.protocol == DriveProtocol::Plain {
            return;
        }
        let Some(state) = decoded else {
            if self.enabled && self.error.is_none() {
                self.fault(AxisError::DriveStateInvalid);
            }
            return;
        };
        if let Some(ticks) = self.drive_reset {
            if !cia402::is_fault(state) {
                self.drive_reset = None;
                self.clear_error();
                self.book.finish(CommandResult::Done, None);
            } else if ticks >= DRIVE_RESET_TIMEOUT_TICKS {
                self.drive_reset = None;
                self.book
                    .finish(CommandResult::Error, Some(AxisError::ResetRefused));
            } else {
                self.drive_reset = Some(ticks + 1);
            }
        }
        if cia402::is_fault(state) {
            if self.error.is_none() {
                self.fault(AxisError::DriveFault);
            }
            self.enabled = false;
        } else if state == DriveState::OperationEnabled {
            if self.power_requested && self.error.is_none() {
                self.take_over();
            }
        } else if self.enabled {
            // The drive left operation on its own (quick stop, switched off locally).
            self.fault(AxisError::DriveStateInvalid);
            self.enabled = false;
        }
    }

    /// The control word's low byte for a CiA 402 drive (`nCtrl1`).
    fn control_word(&self) -> u8 {
        use cia402::control::*;
        if let Some(ticks) = self.drive_reset {
            // Fault reset acts on its rising edge: pulse every other tick.
            return if ticks % 2 == 1 { FAULT_RESET } else { 0 };
        }
        let operate = self.power_requested && (self.error.is_none() || self.enabled);
        match self.inputs.state {
            _ if !operate => SHUTDOWN,
            DriveState::SwitchOnDisabled | DriveState::NotReadyToSwitchOn => SHUTDOWN,
            _ => ENABLE_OPERATION,
        }
    }

    /// Second half of a tick: monitors the following error, runs the position controller on
    /// this tick's set-point and returns the outputs.
    pub fn act(&mut self) -> AxisOutputs {
        self.sensed = false;
        // The actual position belongs to the set-point of the previous tick.
        let previous = self.last_set;
        self.following_error = previous.position - self.actual;
        if self.enabled
            && self.error.is_none()
            && self.following_error.abs() > self.config.following_error_limit
        {
            self.fault(AxisError::FollowingError);
        }
        // The drive's own following error (cyclic position mode): its value or its bit.
        let external = self.inputs.external_following_error.abs()
            > self.config.following_error_limit
            || self.inputs.flags & drive_flags::FOLLOWING_ERROR != 0;
        if self.enabled
            && self.error.is_none()
            && self.config.drive_mode == DriveMode::Position
            && external
        {
            self.fault(AxisError::ExternalFollowingError);
        }
        // A coupled axis (cam, gear, FIFO, channel) follows set-points no generator braked
        // for: one beyond a software limit is a fault, the axis stops where it is.
        if self.coupling.is_some() {
            self.step_superimposed();
        }
        if let (Some(_), Some([min, max])) = (self.coupling, self.config.soft_limits) {
            let p = self.setpoint().position;
            if self.enabled && self.error.is_none() && !(min..=max).contains(&p) {
                self.fault(AxisError::SoftwareLimitReached);
            }
        }
        let set = self.setpoint();
        let active = self.enabled && self.error.is_none();
        // Feed-forward of the mean velocity over the coming tick: with an ideal drive the
        // actual position lands on the set-point exactly.
        let mean_velocity = (set.position - previous.position) / self.cycle_s;
        self.output_velocity = if active {
            self.config.feed_forward * mean_velocity
                + self.config.position_gain * (previous.position - self.actual)
        } else {
            0.0
        };
        self.last_set = set;
        self.outputs(set)
    }

    fn generate(&mut self) {
        if self.coupling.is_some() {
            return;
        }
        let progress = self.generator.step();
        let stopping = self.book.active().map(|a| a.kind) == Some(AxisCommandKind::Stop);
        match progress {
            Progress::Reached if stopping => self.book.mark_reached(),
            Progress::Reached => match self.generator.goal() {
                Goal::Velocity(v) if v != 0.0 => self.book.mark_reached(),
                _ => self.book.finish(CommandResult::Done, None),
            },
            Progress::Idle | Progress::Moving | Progress::AtVelocity => {}
        }
        if stopping && !self.stop_lock {
            // Released (Execute fell) after standstill, or released early: the stop is over.
            if self.generator.goal() == Goal::Hold {
                self.book.finish(CommandResult::Done, None);
            }
        }
        self.guard_soft_limits();
    }

    /// A velocity move brakes so that it comes to rest on a software limit, and ends with an
    /// error there.
    fn guard_soft_limits(&mut self) {
        let (Some([min, max]), Goal::Velocity(v)) =
            (self.config.soft_limits, self.generator.goal())
        else {
            return;
        };
        if v == 0.0 {
            return;
        }
        let s = self.generator.state();
        let d = self.config.dynamics;
        // Braking distance with the axis's deceleration, plus the jerk phase, plus one tick.
        let speed = s.velocity.abs();
        let reach = speed * speed / (2.0 * d.deceleration)
            + speed * (d.deceleration / d.jerk)
            + speed * self.cycle_s;
        let limit = if v > 0.0 { max } else { min };
        if (limit - s.position).abs() <= reach || (v > 0.0) == (s.position > limit) {
            let braked = self.generator.move_to(
                limit,
                MoveLimits {
                    velocity: v.abs(),
                    acceleration: d.acceleration,
                    deceleration: d.deceleration,
                    jerk: d.jerk,
                },
            );
            if braked.is_err() {
                return self.fault(AxisError::GeneratorFailed);
            }
            // The command ends with the error; the braking move runs on, owned by no command,
            // and the axis takes new commands (inside the limits) at once.
            self.book
                .finish(CommandResult::Error, Some(AxisError::SoftwareLimitReached));
        }
    }

    /// `nAxisState`: the slave phase while coupled, else the master state of the set-point.
    pub fn motion_state(&self, set: Kinematic) -> AxisState {
        if let Some(c) = self.coupling {
            return c.phase;
        }
        if !self.enabled || self.error.is_some() {
            return AxisState::Inactive;
        }
        motion_phase(set.velocity, set.acceleration)
    }
}

/// The master motion state of a set-point: standstill, accelerating, decelerating or
/// constant velocity. An acceleration below 1e-9 counts as none (set-points differenced
/// from positions carry that much noise at constant velocity).
pub fn motion_phase(velocity: f64, acceleration: f64) -> AxisState {
    let acceleration = if acceleration.abs() < 1e-9 {
        0.0
    } else {
        acceleration
    };
    if velocity == 0.0 && acceleration == 0.0 {
        return AxisState::Standstill;
    }
    let trend = acceleration * velocity;
    if trend > 0.0 || (velocity == 0.0 && acceleration != 0.0) {
        AxisState::Accelerating
    } else if trend < 0.0 {
        AxisState::Decelerating
    } else {
        AxisState::ConstantVelocity
    }
}
