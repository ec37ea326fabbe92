//! Motion: the path block on its set-point generator, independent axes on theirs, the PLC's
//! override and feed hold, and the controlled stop.

use super::*;

/// The channel's motion generators and what steers them.
pub(super) struct Motion {
    /// Per-axis limits of the channel (velocity, acceleration, jerk).
    pub(super) limits: AxisLimits,
    /// Programmed position (channel coordinates, after offsets).
    pub(super) programmed: AxisValues,
    /// Its velocity and acceleration this tick, from the path's and the independent axes'
    /// generators (0 for an axis at rest).
    pub(super) velocity: AxisValues,
    pub(super) acceleration: AxisValues,
    /// The set-points are the programmed position this tick (no transformation, no dynamic CS
    /// on them, the guard not holding them): `velocity` and `acceleration` are theirs.
    pub(super) rates_apply: bool,
    pub(super) path: Option<PathMove>,
    /// Runs the path parameter of every block (one generator, re-targeted: no allocation).
    pub(super) path_generator: SetpointGenerator,
    /// Per axis: its generator for independent moves and whether one is under way.
    pub(super) independent: Vec<(SetpointGenerator, bool)>,
    /// The PLC's override and feed hold in effect (its last valid value).
    pub(super) path_override: PathOverride,
    /// Override values out of range the PLC wrote (each tick one is read, counted once).
    pub(super) override_refused: u64,
}

impl Motion {
    /// At rest at `start`, with `limits`, ticking every `cycle_s`.
    pub(super) fn new(limits: AxisLimits, start: &AxisValues, cycle_s: f64) -> Self {
        Self {
            limits,
            programmed: *start,
            velocity: AxisValues::zeros(start.len()),
            acceleration: AxisValues::zeros(start.len()),
            rates_apply: false,
            path: None,
            path_generator: SetpointGenerator::new(cycle_s, 0.0),
            independent: (0..start.len())
                .map(|_| (SetpointGenerator::new(cycle_s, 0.0), false))
                .collect(),
            path_override: DEFAULT_PATH_OVERRIDE,
            override_refused: 0,
        }
    }
}

impl Channel {
    /// Programmed position (channel coordinates).
    pub fn programmed(&self) -> &AxisValues {
        &self.motion.programmed
    }

    /// The velocity and acceleration of the set-points this tick (channel order), when the
    /// channel knows them exactly: without a transformation, without the dynamic CS acting on
    /// the set-points and without the guard holding them, they are the path's and the
    /// independent axes' own. `None` otherwise (the axes take differences then).
    pub fn set_point_rates(&self) -> Option<(&AxisValues, &AxisValues)> {
        let m = &self.motion;
        m.rates_apply.then_some((&m.velocity, &m.acceleration))
    }

    /// The PLC's override and feed hold in effect.
    pub fn path_override(&self) -> PathOverride {
        self.motion.path_override
    }

    /// Ticks in which the PLC's override unit held a value out of range (the last valid value
    /// stayed in effect).
    pub fn override_refused_count(&self) -> u64 {
        self.motion.override_refused
    }

    /// Whether a motion or wait is in progress.
    pub fn is_moving(&self) -> bool {
        self.motion.path.is_some()
            || self.motion.independent.iter().any(|(_, active)| *active)
            || self.safety.guard.braking()
    }

    /// A controlled stop (supervision, signals): the path brakes along its block with the
    /// channel's acceleration and jerk, independent axes brake, no further block starts; at
    /// rest the channel ends in ERROR with `reason`. A tracking slave's tracking goes to ERROR
    /// and the guard brakes each axis on its own limits instead (the compensation may be
    /// moving). Does not allocate until the channel is at rest.
    pub fn stop(&mut self, reason: &'static str) {
        if self.stopping.is_some() {
            return;
        }
        let (dec, jerk) = (self.motion.limits.acceleration, self.motion.limits.jerk);
        if let Some(path) = self.motion.path.as_mut() {
            path.brake(&mut self.motion.path_generator);
        }
        for (g, active) in &mut self.motion.independent {
            if *active && g.brake(dec, jerk).is_err() {
                *active = false;
            }
        }
        if self.pose.tracker.state() != DynCsState::Inactive {
            self.pose.tracker.fail(TrackError::MachineStop);
            self.safety.latch_pending = true;
        }
        self.abort_plc_command();
        self.stopping = Some(reason);
    }

    /// Whether a stop was requested and the channel has not ended yet (moving, or waiting
    /// to end in ERROR at its next tick).
    pub fn stopping(&self) -> bool {
        self.stopping.is_some() && (self.is_moving() || self.state == RunState::Running)
    }

    pub(super) fn start_path(
        &mut self,
        target: &AxisValues,
        motion: MotionMode,
        feed: f64,
        arc: Option<ArcSpec>,
    ) {
        let mut target = *target;
        // Axes moving independently are left to their own move.
        for (i, (_, active)) in self.motion.independent.iter().enumerate() {
            if *active {
                target[i] = self.motion.programmed[i];
            }
        }
        let limits = [self.motion.limits; crate::setpoint::MAX_CHANNEL_AXES];
        match PathMove::plan(
            &self.motion.programmed,
            &target,
            motion,
            feed,
            arc,
            &limits[..self.motion.programmed.len()],
            &mut self.motion.path_generator,
        ) {
            Ok(path) => self.motion.path = path,
            Err(e) => self.fail(ChannelFault::Path(e)),
        }
    }

    /// An independent axis moves to `target` on its own generator (rapid, or at `feed`
    /// mm/min); the block waits for it unless `asynchronous`.
    pub(super) fn independent_move(
        &mut self,
        axis: usize,
        target: f64,
        feed: f64,
        motion: MotionMode,
        asynchronous: bool,
    ) {
        let limits = self.motion.limits;
        let velocity = match motion {
            MotionMode::Rapid => limits.velocity,
            _ => (feed / 60.0).min(limits.velocity),
        };
        let (generator, active) = &mut self.motion.independent[axis];
        generator.hold(self.motion.programmed[axis]);
        let planned = generator.move_to(
            target,
            MoveLimits {
                velocity,
                acceleration: limits.acceleration,
                deceleration: limits.acceleration,
                jerk: limits.jerk,
            },
        );
        *active = planned.is_ok();
        if planned.is_err() {
            let axis = AxisName::from(self.config.axes[axis].as_str());
            self.fail(ChannelFault::IndependentNoProfile { axis });
            return;
        }
        if !asynchronous {
            self.run.wait = Some(Wait::Independent);
        }
    }

    /// The override unit of this tick: a valid value takes effect, one out of range is counted
    /// and the last valid value stays; without a unit the channel runs at 100 %.
    pub(super) fn take_override(&mut self) {
        match self.plc.inputs.path_override {
            OverrideInput::Valid(value) => self.motion.path_override = value,
            OverrideInput::Invalid(_) => self.motion.override_refused += 1,
            OverrideInput::Absent => self.motion.path_override = DEFAULT_PATH_OVERRIDE,
        }
    }

    /// The override factors (feed, rapid) in effect: 0 under feed hold.
    pub(super) fn override_factors(&self) -> (f64, f64) {
        let o = self.motion.path_override;
        if o.feed_hold || self.control.held {
            (0.0, 0.0)
        } else {
            (
                f64::from(o.feed_permille) / 1000.0,
                f64::from(o.rapid_permille) / 1000.0,
            )
        }
    }

    pub(super) fn advance(&mut self) {
        let (feed, rapid) = self.override_factors();
        let m = &mut self.motion;
        m.velocity.fill(0.0);
        m.acceleration.fill(0.0);
        if let Some(path) = m.path.as_mut() {
            path.set_override(feed, rapid, &mut m.path_generator);
            let ended = path.step(&mut m.path_generator, &mut m.programmed);
            path.rates(&m.path_generator, &mut m.velocity, &mut m.acceleration);
            if ended {
                m.path = None;
            }
        }
        for (i, (g, active)) in m.independent.iter_mut().enumerate() {
            if *active {
                let progress = g.step();
                let state = g.state();
                m.programmed[i] = state.position;
                m.velocity[i] = state.velocity;
                m.acceleration[i] = state.acceleration;
                if matches!(progress, Progress::Reached | Progress::Idle) {
                    *active = false;
                }
            }
        }
    }
}
