//! Couplings of an axis to an engine (or a channel): the lease's side on the axis, the
//! coupled set-point, and the way back to a free axis (MC_GearOut, MC_CamOut); and the
//! actual values' filter.

use super::*;

impl Axis {
    /// Couples the axis to an engine that hands in set-points with [`Axis::drive_coupled`].
    /// Refused while another command owns the axis is not needed: the coupling aborts it.
    pub(in crate::axis) fn couple(&mut self, coupling: Coupling) -> Result<(), AxisError> {
        self.may_move(true)?;
        self.book.finish(CommandResult::Aborted, None);
        self.drop_superimposed(CommandResult::Aborted, None);
        self.coupled_setpoint = self.generator.state();
        self.coupling = Some(coupling);
        self.coupling_epoch = self.coupling_epoch.wrapping_add(1);
        self.coupled_status = 0;
        Ok(())
    }

    /// The status bits of the engine that holds the axis (see `coupled_status`).
    pub(in crate::axis) fn set_coupled_status(&mut self, bits: u32) {
        self.coupled_status = bits;
    }

    /// Starts a coupling command of the engine that holds the axis (see
    /// [`AxisCommandKind::GearIn`]); the one before is aborted. Its id.
    pub(in crate::axis) fn begin_coupled(&mut self, kind: AxisCommandKind) -> u32 {
        self.book.begin(kind)
    }

    /// The number of the current coupling (see [`Axis::couple`]); changes with every one.
    pub(in crate::axis) fn coupling_epoch(&self) -> u32 {
        self.coupling_epoch
    }

    /// Changes what a coupled axis is coupled to, in place: the set-point goes on where it
    /// is (a new command of the same engine). `false` when the axis is not coupled.
    pub(in crate::axis) fn recouple(&mut self, coupling: Coupling) -> bool {
        match self.coupling.as_mut() {
            Some(c) => {
                *c = coupling;
                true
            }
            None => false,
        }
    }

    /// The coupled engine's set-point for this tick (ignored when not coupled).
    pub(in crate::axis) fn drive_coupled(&mut self, setpoint: Kinematic, phase: AxisState) {
        if let Some(c) = self.coupling.as_mut() {
            c.phase = phase;
            self.coupled_setpoint = setpoint;
        }
    }

    /// Ends a coupling (MC_GearOut, MC_CamOut): the axis becomes a free master and goes on at
    /// the velocity it had, acceleration-free, as after MC_MoveVelocity, until MC_Halt or
    /// MC_Stop.
    ///
    /// Between ticks (`handle`, `reset`) the generator takes over with the next tick. Inside
    /// an engine's tick (between `sense` and `act`, in place of this tick's `drive_coupled`)
    /// it steps at once from the last coupled set-point, so the motion goes on without a
    /// one-tick stall.
    pub(in crate::axis) fn decouple(&mut self) {
        if self.coupling.is_none() {
            return;
        }
        self.fold_superimposed();
        self.coupling = None;
        if self.book.active().map(|a| a.kind) == Some(AxisCommandKind::GearIn) {
            self.book.finish(CommandResult::Aborted, None);
        }
        self.resume_free();
        if self.sensed && self.enabled && self.error.is_none() {
            self.generate();
        }
    }

    /// The actual velocity and acceleration of this reading, through the configured
    /// first-order filter (none: taken as they are; a fresh count starts the filter there).
    pub(super) fn filter_actual(&mut self, first: bool, velocity: f64, acceleration: f64) {
        let t = self.config.io.actual_filter_s;
        if t <= 0.0 || first {
            self.actual_velocity = velocity;
            self.actual_acceleration = acceleration;
            return;
        }
        let k = self.cycle_s / (t + self.cycle_s);
        self.actual_velocity += (velocity - self.actual_velocity) * k;
        self.actual_acceleration += (acceleration - self.actual_acceleration) * k;
    }

    pub(super) fn resume_free(&mut self) {
        let d = self.config.dynamics;
        // Resume from the coupled state: position, velocity and acceleration carry over; an
        // acceleration beyond the axis's own (an encoder master's noise) is taken as its limit.
        let most = d.acceleration.max(d.deceleration);
        let s = Kinematic {
            acceleration: self.coupled_setpoint.acceleration.clamp(-most, most),
            ..self.coupled_setpoint
        };
        if s.velocity == 0.0 && s.acceleration == 0.0 {
            self.generator.hold(s.position);
        } else {
            let reached = velocity_reached(s.velocity, s.acceleration, d.jerk, d.velocity);
            self.generator.resume_from(s);
            let resumed = self.generator.run_at(
                reached,
                MoveLimits {
                    velocity: d.velocity,
                    acceleration: d.acceleration,
                    deceleration: d.deceleration,
                    jerk: d.jerk,
                },
            );
            if resumed.is_err() {
                self.fault(AxisError::GeneratorFailed);
            }
        }
    }
}

/// The velocity a decoupled axis goes on at: the one it reaches once its acceleration is taken
/// out with its jerk, so an accelerating slave settles there without overshooting and coming
/// back. A braking slave whose acceleration would carry it through standstill comes to rest
/// instead (0): it never runs on against the direction it was moving in.
fn velocity_reached(velocity: f64, acceleration: f64, jerk: f64, most: f64) -> f64 {
    let reached = velocity + acceleration * acceleration.abs() / (2.0 * jerk);
    if reached * velocity < 0.0 || !reached.is_finite() {
        0.0
    } else {
        reached.clamp(-most, most)
    }
}

#[cfg(test)]
mod tests {
    use super::velocity_reached;

    #[test]
    fn an_accelerating_slave_goes_on_at_the_velocity_it_reaches() {
        // 20 mm/s rising at 5000 mm/s^2, jerk 1e5: 20 + 5000^2 / 2e5 = 145.
        assert_eq!(velocity_reached(20.0, 5000.0, 1e5, 1000.0), 145.0);
        assert_eq!(velocity_reached(-20.0, -5000.0, 1e5, 1000.0), -145.0);
        assert_eq!(velocity_reached(900.0, 5000.0, 1e5, 1000.0), 1000.0);
    }

    #[test]
    fn a_braking_slave_slows_down_and_never_runs_backwards() {
        // Braking at 5000 mm/s^2 from 200 mm/s: 200 - 125 = 75, same direction.
        assert_eq!(velocity_reached(200.0, -5000.0, 1e5, 1000.0), 75.0);
        // From 20 mm/s the acceleration would carry it to -105 mm/s: it comes to rest.
        assert_eq!(velocity_reached(20.0, -5000.0, 1e5, 1000.0), 0.0);
        assert_eq!(velocity_reached(-20.0, 5000.0, 1e5, 1000.0), 0.0);
        // From standstill the acceleration is the direction it starts in.
        assert_eq!(velocity_reached(0.0, -5000.0, 1e5, 1000.0), -125.0);
    }
}
