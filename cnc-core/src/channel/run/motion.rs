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
    /// Continuous path: the look-ahead window of straight blocks and the motion along it.
    pub(super) contour: Contour,
    /// The last block handed to the contour: where it ends and how its end may be blended
    /// (`None`: the contour ends there).
    pub(super) contour_end: AxisValues,
    pub(super) contour_blend: Option<f64>,
    /// Axes moving independently when the contour started: the contour leaves them alone
    /// (bit per axis).
    pub(super) contour_excluded: u32,
    /// Under `#TRAFO`: the joints at the end of the last piece the joint caps sampled.
    pub(super) contour_joints: kinematics::Joints,
}

impl Motion {
    /// At rest at `start`, with `limits`, ticking every `cycle_s`.
    pub(super) fn new(
        limits: AxisLimits,
        start: &AxisValues,
        cycle_s: f64,
        lookahead: usize,
    ) -> Self {
        let per_axis = vec![limits; start.len()];
        Self {
            contour: Contour::new(&per_axis, cycle_s, lookahead),
            contour_end: *start,
            contour_blend: None,
            contour_excluded: 0,
            contour_joints: [0.0; 6],
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

    /// Whether a path block (or a contour of them) is under way.
    pub(super) fn path_active(&self) -> bool {
        self.motion.path.is_some() || self.motion.contour.active()
    }

    /// The path brakes along itself to a stop (controlled stop, PLC stop).
    pub(super) fn brake_path(&mut self) {
        if let Some(path) = self.motion.path.as_mut() {
            path.brake(&mut self.motion.path_generator);
        }
        self.motion.contour.stop();
    }

    /// The path is dropped where it stands (the guard takes over, or the axes are at rest).
    pub(super) fn drop_path(&mut self) {
        self.motion.path = None;
        self.motion.contour.clear();
        self.motion.contour_blend = None;
    }

    /// Continuous path: a straight block `m` starts a contour (when it may be blended at its
    /// end); `false` when it runs on its own. Axes moving independently keep their own moves.
    pub(super) fn start_contour(&mut self, m: &MotionBlock) -> bool {
        if self.control.single_block || m.blend.is_none() {
            return false;
        }
        self.motion.contour.clear();
        self.motion.contour_end = self.motion.programmed;
        self.motion.contour_blend = None;
        self.motion.contour_joints = self.pose.joints;
        self.motion.contour_excluded = self
            .motion
            .independent
            .iter()
            .enumerate()
            .filter(|(_, (_, active))| *active)
            .fold(0, |bits, (i, _)| bits | 1 << i);
        self.join_contour(m)
    }

    /// A straight block joins the open contour (`false`: it cannot, and the contour ends
    /// before it).
    pub(super) fn join_contour(&mut self, m: &MotionBlock) -> bool {
        let mut end = m.target;
        for (i, e) in end.iter_mut().enumerate() {
            if self.motion.contour_excluded & (1 << i) != 0 {
                *e = self.motion.contour_end[i];
            }
        }
        let segment = Segment {
            start: self.motion.contour_end,
            end,
            feed: if m.motion == MotionMode::Rapid {
                f64::INFINITY
            } else {
                m.feed / 60.0
            },
            rapid: m.motion == MotionMode::Rapid,
            line: m.line,
            blend: self.motion.contour_blend,
            // Under #TRAFO the joints' limits are taken per block as it comes.
            chamfer: !self.pose.trafo,
            on_arc: false,
        };
        if let Some(arc) = m.arc {
            return self.join_arc(m, arc, end);
        }
        let seed = self.motion.contour_joints;
        let pushed =
            match joint_caps::joint_caps(&self.pose, &self.config, self.run.decoder.layout(), seed)
            {
                Some(mut caps) => {
                    let contour = &mut self.motion.contour;
                    let pushed = contour.push(&segment, &mut |p| caps.apply(p));
                    self.motion.contour_joints = caps.seed;
                    pushed
                }
                None => self.motion.contour.push(&segment, &mut |_| {}),
            };
        if pushed.is_err() {
            return false;
        }
        self.motion.contour_end = end;
        self.motion.contour_blend = m.blend;
        if m.blend.is_none() {
            self.motion.contour.close();
        }
        true
    }

    /// An arc block joins the open contour as its chords (`false`: it cannot, and runs on its
    /// own at exact stop): not under `#TRAFO`, not when the contour ends at it, not when an
    /// axis of its plane moves on its own.
    fn join_arc(&mut self, m: &MotionBlock, arc: ArcMove, end: AxisValues) -> bool {
        let [a, b, _] = arc.plane.axes();
        let plane_free = self.motion.contour_excluded & (1 << a | 1 << b) == 0;
        let Some(tolerance) = m.blend else {
            return false;
        };
        if self.pose.trafo || !plane_free {
            return false;
        }
        let block = ArcBlock {
            start: self.motion.contour_end,
            end,
            arc,
            feed: m.feed / 60.0,
            line: m.line,
            blend: self.motion.contour_blend,
            tolerance,
        };
        if self.motion.contour.push_arc(&block).is_err() {
            return false;
        }
        self.motion.contour_end = end;
        // The corner after it keeps half the tolerance, as its chords' corners do.
        self.motion.contour_blend = m.blend.map(|t| 0.5 * t);
        true
    }

    /// Whether a motion or wait is in progress.
    pub fn is_moving(&self) -> bool {
        self.path_active()
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
        self.brake_path();
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
            let axis = AxisName::from(self.run.decoder.axes()[axis].as_str());
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
        if m.contour.active() {
            m.contour.set_factors(feed, rapid);
            let kept = m.programmed;
            let stepped = m
                .contour
                .step(&mut m.programmed, &mut m.velocity, &mut m.acceleration);
            // Axes moving independently are their own generators' (set below).
            for i in (0..kept.len()).filter(|i| m.contour_excluded & (1 << i) != 0) {
                m.programmed[i] = kept[i];
            }
            if let Err(e) = stepped {
                self.fail(ChannelFault::Contour(e));
                return;
            }
        }
        let m = &mut self.motion;
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
