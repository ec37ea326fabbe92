//! MC_MoveSuperimposed: a relative move added on top of the motion a cam or gear engine
//! hands in (phase shifts of a slave), beside the command that owns the axis. Its own
//! jerk-limited profile runs from the offset superimposed so far; the axis's set-point is the
//! engine's plus that offset. A new MC_MoveSuperimposed aborts the one running and goes on
//! from where its offset stands (with its velocity); the coupling's end keeps the offset
//! reached in the free axis's position and aborts a move still running, and so does an
//! axis error. The offset since coupling is MC_CamInfo's `SumOfSuperpositionDistance`.

use super::*;

/// The superimposed part of a coupled axis's set-point.
#[derive(Debug)]
pub(super) struct Superimposed {
    /// Position = the offset superimposed since the axis was coupled.
    generator: SetpointGenerator,
    /// The running MC_MoveSuperimposed's id, 0 when none.
    id: u32,
}

impl Superimposed {
    pub(super) fn new(cycle_s: f64, jerk_ceiling: f64) -> Self {
        let mut generator = SetpointGenerator::new(cycle_s, 0.0);
        generator.set_jerk_ceiling(jerk_ceiling);
        Self { generator, id: 0 }
    }

    /// The offset, its velocity and acceleration now.
    pub(super) fn state(&self) -> Kinematic {
        self.generator.state()
    }

    /// The running move's id, 0 when none.
    pub(super) fn id(&self) -> u32 {
        self.id
    }
}

impl Axis {
    /// Takes MC_MoveSuperimposed: `call.position` is the distance, `call.velocity` the
    /// largest velocity difference to the coupled motion.
    pub(super) fn superimpose(&mut self, call: &AxisCommandCall) -> Result<u32, AxisError> {
        if self.error.is_some() {
            return Err(AxisError::AxisInError);
        }
        if !self.enabled {
            return Err(AxisError::NotEnabled);
        }
        let held_by_engine = self.coupling.is_some_and(|c| {
            matches!(
                c.kind,
                CouplingState::Cam | CouplingState::GearVelocity | CouplingState::GearPosition
            )
        });
        // A flying saw stopping or standing after a rollback has no motion to add to.
        if !held_by_engine || self.in_prephase() {
            return Err(AxisError::SuperimposedNotCoupled);
        }
        if !call.position.is_finite() {
            return Err(AxisError::TargetOutsideLimits);
        }
        let limits = self.move_limits(call)?;
        // The velocity difference on top of the engine's velocity now must stay within the
        // axis's velocity; the offset's end on top of the engine's position now within its
        // software limits.
        let engine = self.coupled_setpoint;
        if engine.velocity.abs() + limits.velocity > self.config.dynamics.velocity {
            return Err(AxisError::InvalidVelocity);
        }
        let target = self.superimposed.state().position + call.position;
        if let Some([min, max]) = self.config.soft_limits {
            if !(min..=max).contains(&(engine.position + target)) {
                return Err(AxisError::TargetOutsideLimits);
            }
        }
        self.superimposed
            .generator
            .move_to(target, limits)
            .map_err(|_| AxisError::GeneratorFailed)?;
        self.end_superimposed(CommandResult::Aborted, None);
        self.superimposed.id = self.book.begin_beside();
        Ok(self.superimposed.id)
    }

    /// One tick of the superimposed move (while coupled, before the set-point is taken). A
    /// flying saw that goes into its pre-phase (a rollback: stop and stand) brakes a running
    /// move with the axis's deceleration and jerk and aborts it.
    pub(super) fn step_superimposed(&mut self) {
        if self.in_prephase() && self.superimposed.id != 0 {
            let d = self.config.dynamics;
            if self
                .superimposed
                .generator
                .brake(d.deceleration, d.jerk)
                .is_err()
            {
                return self.fault(AxisError::GeneratorFailed);
            }
            self.end_superimposed(CommandResult::Aborted, None);
        }
        if self.superimposed.generator.step() == Progress::Reached && self.superimposed.id != 0 {
            self.end_superimposed(CommandResult::Done, None);
        }
    }

    /// A slave in its pre-phase (`SlavePrephase`: a cam slave held until its activation, a
    /// flying saw stopping or standing after a rollback).
    fn in_prephase(&self) -> bool {
        self.coupling
            .is_some_and(|c| c.phase == AxisState::SlavePrephase)
    }

    /// Ends the running move (if any) with `result`; the offset stays where it is.
    pub(super) fn end_superimposed(&mut self, result: CommandResult, error: Option<AxisError>) {
        let id = core::mem::take(&mut self.superimposed.id);
        if id != 0 {
            self.book
                .end_beside(id, AxisCommandKind::MoveSuperimposed, result, error);
        }
    }

    /// The coupling ended: the offset reached goes into the coupled set-point the free axis
    /// resumes from, and the next coupling starts from no offset (a move still running is
    /// aborted).
    pub(super) fn fold_superimposed(&mut self) {
        self.end_superimposed(CommandResult::Aborted, None);
        self.coupled_setpoint = with_offset(self.coupled_setpoint, self.superimposed.state());
        self.superimposed.generator.hold(0.0);
    }

    /// An axis error (the axis stands where it is) or a new coupling: the move ends and the
    /// offset starts again from 0.
    pub(super) fn drop_superimposed(&mut self, result: CommandResult, error: Option<AxisError>) {
        self.end_superimposed(result, error);
        self.superimposed.generator.hold(0.0);
    }

    /// The offset superimposed since the axis was last coupled (MC_CamInfo's
    /// `SumOfSuperpositionDistance`); 0 after the coupling's end.
    pub fn superimposed_offset(&self) -> f64 {
        self.superimposed.state().position
    }

    /// The set-point the engine that holds the axis handed in last (without the superimposed
    /// offset): what an engine measures its own motion against. A free axis's set-point.
    pub fn engine_setpoint(&self) -> Kinematic {
        match self.coupling {
            Some(_) => self.coupled_setpoint,
            None => self.generator.state(),
        }
    }
}

/// A set-point with a superimposed offset added (position, velocity, acceleration, jerk).
pub(super) fn with_offset(base: Kinematic, offset: Kinematic) -> Kinematic {
    Kinematic {
        position: base.position + offset.position,
        velocity: base.velocity + offset.velocity,
        acceleration: base.acceleration + offset.acceleration,
        jerk: base.jerk + offset.jerk,
    }
}
