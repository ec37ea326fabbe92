//! Switching the tracking on and off, the tick (following the master, FREEZE and resume,
//! the soft transitions) and the diagnosis history it records.

use super::{
    interpolate, BadParameter, Blend, HistoryEntry, MasterSample, MasterSource, TrackError,
    TrackEvent, TrackSetup, Tracker,
};
use hli::enums::DynCsState;
use kinematics::tracking::{track_cs_values, Tracking, TrackingMode, TrackingOption};
use kinematics::{PoseWords, RotationOrder};
use nalgebra::Isometry3;

impl Tracker {
    /// Switches tracking on with the master's current `master` frame (`None` when the master
    /// offers none yet: the reference is then taken from its first live frame). A refusal
    /// changes nothing; the caller decides whether it is a fault (the NC's) or a refused
    /// request (the PLC's).
    pub fn switch_on(
        &mut self,
        setup: TrackSetup,
        master: Option<&Isometry3<f64>>,
    ) -> Result<(), TrackError> {
        if matches!(
            self.state,
            DynCsState::Activating | DynCsState::Active | DynCsState::Error
        ) {
            return Err(TrackError::AlreadyOn);
        }
        let reference = master.copied().unwrap_or_else(Isometry3::identity);
        let tracking = build_tracking(&setup, setup.counts_from_switch_on().then_some(&reference))?;
        if setup.set_zero {
            self.zero_values = track_cs_values(&reference, self.order);
        }
        self.event(TrackEvent::On {
            source: setup.source,
            filter_ticks: setup.filter_ticks,
            wait: setup.wait,
            relative: setup.relative,
            simu: setup.simu,
            master: words(&reference),
        });
        self.on_values_pending = Some(words(&reference));
        self.tracking = Some(tracking);
        self.setup = Some(setup);
        self.last_master = master.copied();
        self.master_live = master.is_some();
        self.state = DynCsState::Activating;
        self.landing = false;
        self.blend = Some(Blend {
            from: self.applied,
            follow: false,
            done: 0,
            total: setup.filter_ticks,
        });
        Ok(())
    }

    /// Switches tracking off over `filter_ticks` (`None`: the switch-on filter). From ERROR
    /// this releases the held compensation the same way.
    pub fn switch_off(&mut self, filter_ticks: Option<u32>) {
        if self.state == DynCsState::Inactive {
            return;
        }
        let total = filter_ticks
            .or(self.setup.map(|s| s.filter_ticks))
            .unwrap_or(0);
        self.event(TrackEvent::Off {
            source: self.setup.map_or(MasterSource::Plc, |s| s.source),
            filter_ticks: total,
            axes: self.axes,
            applied: words(&self.applied),
        });
        let follow = self.state == DynCsState::Active;
        self.state = DynCsState::Deactivating;
        self.landing = false;
        self.blend = Some(Blend {
            from: self.applied,
            follow,
            done: 0,
            total,
        });
    }

    /// One tick: the compensation to apply, given the master's sample (`None` when the source
    /// offers nothing). `input` and `output` poses are recorded by [`Tracker::record`].
    pub fn tick(&mut self, master: Option<MasterSample>) -> Isometry3<f64> {
        self.tick += 1;
        match self.state {
            DynCsState::Inactive | DynCsState::Error => return self.applied,
            _ => {}
        }
        // The master's frame, held while it is frozen; a resume is taken over softly.
        self.follow_master(master);
        let target = match (self.state, &self.tracking, &self.last_master) {
            (DynCsState::Deactivating, _, _) => Isometry3::identity(),
            (_, Some(tracking), Some(m)) => tracking.compensation(m),
            _ => self.applied,
        };
        self.fade_from_live();
        if !target.translation.vector.iter().all(|v| v.is_finite())
            || !target.rotation.coords.iter().all(|v| v.is_finite())
        {
            self.fail(TrackError::BadFrame);
            return self.applied;
        }
        self.blend_towards(&target);
        // The transition ends with [`Tracker::land`], once the axes stand on it.
        self.landing = self.blend.is_none()
            && matches!(
                self.state,
                DynCsState::Activating | DynCsState::Deactivating
            );
        self.applied
    }

    /// The master's sample of this tick: a live frame is taken (after a freeze, a coupling
    /// in takes it over softly, and a switch-on without a frame takes it as the reference);
    /// none freezes the master's last frame.
    fn follow_master(&mut self, master: Option<MasterSample>) {
        let live = master.filter(|m| m.live);
        match (live, self.master_live) {
            (Some(m), false) => {
                self.master_live = true;
                // A resume while coupling in restarts the soft take-over from where the
                // compensation stands, so the jump of the master's frame is smoothed too.
                if self.last_master.is_some()
                    && matches!(self.state, DynCsState::Active | DynCsState::Activating)
                {
                    self.event(TrackEvent::MasterResumed);
                    self.state = DynCsState::Activating;
                    self.blend = Some(Blend {
                        from: self.applied,
                        follow: false,
                        done: 0,
                        total: self.setup.map_or(0, |s| s.filter_ticks),
                    });
                }
                if self.last_master.is_none()
                    && self.setup.is_some_and(|s| s.counts_from_switch_on())
                {
                    // No frame at switch-on: the first live one is the reference.
                    if let Some(setup) = self.setup {
                        self.tracking = None;
                        let _ = self.rebuild_reference(setup, &m.frame);
                    }
                }
                self.last_master = Some(m.frame);
            }
            (Some(m), true) => self.last_master = Some(m.frame),
            (None, true) => {
                self.master_live = false;
                self.event(TrackEvent::MasterFrozen);
            }
            (None, false) => {}
        }
    }

    /// Coupling out fades the compensation the master still asks for (not the one of the
    /// switch-off tick): a slave switched off while its master moves leaves the master's
    /// velocity along the ramp instead of stopping at once.
    fn fade_from_live(&mut self) {
        if let (DynCsState::Deactivating, Some(blend), Some(tracking), Some(m)) = (
            self.state,
            self.blend.as_mut(),
            &self.tracking,
            &self.last_master,
        ) {
            let live = tracking.compensation(m);
            if blend.follow && live.translation.vector.iter().all(|v| v.is_finite()) {
                blend.from = live;
            }
        }
    }

    /// The compensation applied this tick: `target`, or one step of the blend towards it.
    fn blend_towards(&mut self, target: &Isometry3<f64>) {
        // While the master is frozen a coupling-in pauses where it stands (the resume starts a
        // new ramp from there); a coupling-out goes on, it does not need the master. A master
        // that has offered no frame yet is no freeze: the coupling runs to the compensation
        // of an unmoved master (the manual's PLC commands its first frame once ACTIVE).
        // A master channel that has not published yet is waited for: the take-over starts
        // with its first frame.
        let waiting = self.last_master.is_some()
            || self
                .setup
                .is_some_and(|s| matches!(s.source, MasterSource::Channel(_)));
        let paused = !self.master_live && waiting && self.state == DynCsState::Activating;
        self.applied = match self.blend.as_mut() {
            Some(_) if paused => self.applied,
            Some(blend) => {
                blend.done = blend.done.saturating_add(1);
                let w = blend.weight();
                let from = blend.from;
                if blend.finished() {
                    self.blend = None;
                }
                interpolate(&from, target, w)
            }
            None => *target,
        };
    }

    /// The blend is done and the axes stand on it: coupling in becomes ACTIVE, coupling out
    /// INACTIVE (everything released).
    pub(super) fn end_transition(&mut self) {
        match self.state {
            DynCsState::Activating => {
                self.state = DynCsState::Active;
                self.event(TrackEvent::Active);
            }
            DynCsState::Deactivating => {
                self.state = DynCsState::Inactive;
                self.applied = Isometry3::identity();
                self.setup = None;
                self.tracking = None;
                self.last_master = None;
                self.master_live = false;
                self.event(TrackEvent::Inactive);
            }
            _ => {}
        }
    }

    fn rebuild_reference(
        &mut self,
        setup: TrackSetup,
        reference: &Isometry3<f64>,
    ) -> Result<(), TrackError> {
        self.tracking = Some(build_tracking(&setup, Some(reference))?);
        if setup.set_zero {
            self.zero_values = track_cs_values(reference, self.order);
        }
        Ok(())
    }

    /// Records one tick of the diagnosis history: the pose before and after the dynamic CS
    /// (nothing is computed while tracking is inactive).
    pub fn record(&mut self, before: &Isometry3<f64>, after: &Isometry3<f64>) {
        let input = words(before);
        self.axes = input.map(hli_units);
        if let Some(master) = self.on_values_pending.take() {
            self.event(TrackEvent::OnValues {
                axes: self.axes,
                master,
            });
        }
        if self.state == DynCsState::Inactive {
            return;
        }
        let output = words(after);
        let w = words(&self.applied);
        let mut entry = HistoryEntry {
            tick: self.tick,
            state: self.state.raw() as i32,
            ..HistoryEntry::default()
        };
        for i in 0..6 {
            entry.input[i] = hli_units(input[i]);
            entry.output[i] = hli_units(output[i]);
        }
        for i in 0..3 {
            entry.translation[i] = hli_units(w[i]);
            entry.rotation[i] = hli_units(w[3 + i]);
        }
        self.history.push(entry);
    }
}

/// The frame composition of `setup`, with the SET_ZERO reference when given.
fn build_tracking(
    setup: &TrackSetup,
    reference: Option<&Isometry3<f64>>,
) -> Result<Tracking, TrackError> {
    let mode = if setup.kin_base {
        TrackingMode::KinematicBase
    } else {
        TrackingMode::MovingWorkpiece
    };
    let option = if setup.translation_only {
        TrackingOption::TranslationOnly
    } else {
        TrackingOption::Full
    };
    let o = setup.offset;
    let offset = PoseWords {
        xyz: [o[0], o[1], o[2]],
        abc: [o[3], o[4], o[5]],
    };
    Tracking::new(mode, option, &offset, setup.rot_trans, reference)
        .map_err(|_| TrackError::BadTransition(BadParameter::Offset))
}

/// X..C words of a frame (Z-Y-X, as on the HLI).
pub fn words(frame: &Isometry3<f64>) -> [f64; 6] {
    let w = PoseWords::from_frame(frame, RotationOrder::Zyx);
    [w.xyz[0], w.xyz[1], w.xyz[2], w.abc[0], w.abc[1], w.abc[2]]
}

/// mm or degree to 0.1 um / 0.0001 degree, saturating (diagnosis only).
fn hli_units(value: f64) -> i64 {
    let v = (value * 10_000.0).round();
    if v.is_finite() {
        v as i64
    } else {
        0
    }
}
