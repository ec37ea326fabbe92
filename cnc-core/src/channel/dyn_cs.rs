//! The tracking (slave) side of the dynamic coordinate system: the `#TRACK CS` state machine
//! with soft in- and out-coupling, take-over after a master FREEZE, the diagnosis history and
//! the switching log.
//!
//! The tracker turns the master's frame `M` into a *compensation* frame `C` that the channel
//! puts in front of its programmed pose: `P_out = C * P`. Fully coupled, `C` is
//! `O * D * O^-1` (moving workpiece) or `O * D^-1 * O^-1` (kinematic base), with `D` the
//! displacement of the dynamic CS (see `kinematics::tracking`). While coupling in, out, or
//! re-taking the master after a FREEZE, the applied compensation runs from where it was to
//! where it must be over the filter's ticks: translation linearly, rotation along the shortest
//! arc, with the weight of a quintic smoothing ramp (`6w^5 - 15w^4 + 10w^3` of the ticks done),
//! whose slope and curvature are zero at both ends. The compensation therefore starts from rest
//! and arrives at the master's velocity without a step in velocity or acceleration. Without a
//! filter (FILTER=0) the change is immediate.
//!
//! States (reported in `state_r`): INACTIVE, ACTIVATING (coupling in, or re-taking the master
//! after a FREEZE), ACTIVE, DEACTIVATING, ERROR (the compensation is held where it was: the
//! channel keeps a safe set-point).

pub use super::ring::{Ring, RingRead};
pub use super::track_error::{BadParameter, TrackError};
use hli::enums::DynCsState;
use kinematics::tracking::{track_cs_values, Tracking, TrackingMode, TrackingOption};
use kinematics::{PoseWords, RotationOrder};
use nalgebra::{Isometry3, Translation3};

/// Where a tracking channel takes the dynamic CS from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MasterSource {
    /// The PLC, through the channel's own `MC_CONTROL_DYN_CS_UNIT` (`ID=0`).
    Plc,
    /// The channel interface of another channel (index from 0; `CH=n`/`ID=n` is channel n-1).
    Channel(usize),
}

/// Everything `#TRACK CS ON [...]` or a PLC transition +1 fixes at switch-on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackSetup {
    /// The master.
    pub source: MasterSource,
    /// SET_ZERO/ABSOLUTE: the master frame at switch-on is the reference (`D = M * M0^-1`) and
    /// is handed to the program as `V.G.TRACK_CS.X..C`.
    pub set_zero: bool,
    /// OPTION=1: translation only.
    pub translation_only: bool,
    /// KIN_BASE: compensate an error of the kinematic base instead of following a workpiece.
    pub kin_base: bool,
    /// FILTER: ticks of the soft coupling (0 = immediate).
    pub filter_ticks: u32,
    /// WAIT: the program waits until the coupling is complete.
    pub wait: bool,
    /// ROT_TRANS: the offset's translation is measured in the rotated frame.
    pub rot_trans: bool,
    /// X..C: static offset between master and slave (or error point and kinematic base).
    pub offset: [f64; 6],
    /// RELATIVE: the displacement counts from the master frame at switch-on
    /// (`D = M * M0^-1`, as with SET_ZERO), without handing the frame to the program and
    /// without needing standstill.
    pub relative: bool,
    /// SIMU: the tracker runs (states, history, display values) but the channel does not
    /// apply the compensation to its set-points.
    pub simu: bool,
}

impl TrackSetup {
    /// Whether the master frame at switch-on is the reference of the displacement.
    fn counts_from_switch_on(&self) -> bool {
        self.set_zero || self.relative
    }
}

/// A state change or refusal of the tracker, kept in the switching log.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum TrackEvent {
    /// Switched on (tick, setup, master frame words at switch-on).
    On {
        /// Source.
        source: MasterSource,
        /// Filter ticks.
        filter_ticks: u32,
        /// WAIT.
        wait: bool,
        /// RELATIVE.
        relative: bool,
        /// SIMU.
        simu: bool,
        /// Master frame X..C at switch-on.
        master: [f64; 6],
    },
    /// Coupling complete.
    Active,
    /// The values that go with a switch-on, logged in the tick after it: the axis positions
    /// before the dynamic CS (0.1 um / 0.0001 degree) and the master frame at switch-on.
    OnValues {
        /// Positions X..C before the dynamic CS, HLI units.
        axes: [i64; 6],
        /// Master frame X..C at switch-on.
        master: [f64; 6],
    },
    /// Switched off.
    Off {
        /// Who switched it off.
        source: MasterSource,
        /// Filter ticks of the out-coupling.
        filter_ticks: u32,
        /// Positions X..C before the dynamic CS when switched off, HLI units.
        axes: [i64; 6],
        /// The compensation X..C when switched off.
        applied: [f64; 6],
    },
    /// Coupling released completely.
    #[default]
    Inactive,
    /// The master froze (or its values became invalid): compensation held.
    MasterFrozen,
    /// The master resumed: taken over softly.
    MasterResumed,
    /// An error: state ERROR.
    Error(TrackError),
    /// A PLC request refused without touching the tracking (state and compensation stay).
    Refused(TrackError),
    /// The channel started a program (`restart ... start`, then `... finished`).
    Restart {
        /// The second line of the pair.
        finished: bool,
    },
}

/// One line of the diagnosis history: what went in and out of the dynamic CS in one tick.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HistoryEntry {
    /// Tick.
    pub tick: u64,
    /// Raw `HLI_DYN_CS_*` state.
    pub state: i32,
    /// Pose before the dynamic CS (X..C, 0.1 um / 0.0001 degree).
    pub input: [i64; 6],
    /// Compensation translation (0.1 um).
    pub translation: [i64; 3],
    /// Compensation rotation (0.0001 degree, Z-Y-X).
    pub rotation: [i64; 3],
    /// Pose after the dynamic CS.
    pub output: [i64; 6],
}

/// What the master offers this tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MasterSample {
    /// The frame (mm, Z-Y-X as on the HLI).
    pub frame: Isometry3<f64>,
    /// The values are valid and updated (not frozen).
    pub live: bool,
}

/// A soft transition of the applied compensation.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Blend {
    from: Isometry3<f64>,
    /// Coupling out of ACTIVE: `from` follows the compensation the master asks for.
    follow: bool,
    /// Ticks done and total.
    done: u32,
    total: u32,
}

impl Blend {
    fn weight(&self) -> f64 {
        if self.total == 0 {
            1.0
        } else {
            smooth_ramp(f64::from(self.done) / f64::from(self.total))
        }
    }

    /// Whether the transition is over. Without a filter the change is made in the first
    /// tick but ACTIVATING / DEACTIVATING stays shown for that tick (the manual's PLC-only
    /// example sees 0 -> 1 -> 2 with the filter off).
    fn finished(&self) -> bool {
        self.done >= self.total.max(1) + u32::from(self.total == 0)
    }
}

/// The filter's weight over its progress `x` in [0, 1]: `6x^5 - 15x^4 + 10x^3`, rising from 0
/// to 1 with zero slope and zero curvature at both ends (its steepest slope, at the middle, is
/// 15/8).
pub fn smooth_ramp(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * x * (x * (6.0 * x - 15.0) + 10.0)
}

/// Interpolates between two frames: translation linearly, rotation along the shortest arc.
pub fn interpolate(a: &Isometry3<f64>, b: &Isometry3<f64>, w: f64) -> Isometry3<f64> {
    let t = a.translation.vector.lerp(&b.translation.vector, w);
    let r = a
        .rotation
        .try_slerp(&b.rotation, w, 1e-12)
        .unwrap_or(if w < 0.5 { a.rotation } else { b.rotation });
    Isometry3::from_parts(Translation3::from(t), r)
}

/// The tracker of one channel.
#[derive(Debug, Clone)]
pub struct Tracker {
    state: DynCsState,
    setup: Option<TrackSetup>,
    tracking: Option<Tracking>,
    /// The compensation applied in the last tick.
    applied: Isometry3<f64>,
    blend: Option<Blend>,
    /// The last live master frame (held while the master is frozen).
    last_master: Option<Isometry3<f64>>,
    master_live: bool,
    /// `V.G.TRACK_CS.X..C` (SET_ZERO), in the channel's orientation convention.
    zero_values: [f64; 6],
    order: RotationOrder,
    history: Ring<HistoryEntry>,
    log: Ring<(u64, TrackEvent)>,
    tick: u64,
    /// The positions before the dynamic CS in the last recorded tick (HLI units).
    axes: [i64; 6],
    /// A switch-on whose values are logged with the next recorded tick.
    on_values_pending: Option<[f64; 6]>,
    /// PLC requests refused (see [`TrackEvent::Refused`]).
    refused: u64,
    /// Frames the PLC commanded while `enable_w` was FALSE (taken, not redirected).
    not_redirected: u64,
    /// State changes since start-up: switched on, active, switched off, inactive, error.
    state_changes: u64,
    /// Why the tracker last went to ERROR.
    last_error: Option<TrackError>,
}

/// Events kept for the switching log (each renders to one or more lines; the listing shows the
/// last [`LOG_LINES`] lines).
pub const LOG_CAPACITY: usize = 64;

/// Lines of the switching log's ring, as the controller's listing counts them.
pub const LOG_LINES: usize = 40;

impl Tracker {
    /// An inactive tracker; `history` entries of diagnosis (`dyn_cs_history_max`), angles of
    /// `V.G.TRACK_CS` in `order`.
    pub fn new(history: usize, order: RotationOrder) -> Self {
        Self {
            state: DynCsState::Inactive,
            setup: None,
            tracking: None,
            applied: Isometry3::identity(),
            blend: None,
            last_master: None,
            master_live: false,
            zero_values: [0.0; 6],
            order,
            history: Ring::new(history),
            log: Ring::new(LOG_CAPACITY),
            tick: 0,
            axes: [0; 6],
            on_values_pending: None,
            refused: 0,
            not_redirected: 0,
            state_changes: 0,
            last_error: None,
        }
    }

    /// The channel started a program: logged as the controller logs a restart.
    pub fn restart(&mut self) {
        self.event(TrackEvent::Restart { finished: false });
        self.event(TrackEvent::Restart { finished: true });
    }

    /// Refuses a PLC request without touching the tracking: logged and counted.
    pub fn refuse(&mut self, error: TrackError) {
        self.refused += 1;
        self.event(TrackEvent::Refused(error));
    }

    /// A frame the PLC commanded while `enable_w` was FALSE: the unit does not redirect it
    /// (the frame is dropped, the semaphore freed), which is no fault.
    pub fn not_redirected(&mut self) {
        self.not_redirected += 1;
    }

    /// PLC requests refused so far.
    pub fn refused_count(&self) -> u64 {
        self.refused
    }

    /// Frames commanded while the unit was not enabled, dropped.
    pub fn not_redirected_count(&self) -> u64 {
        self.not_redirected
    }

    /// The state as `state_r` reports it.
    pub fn state(&self) -> DynCsState {
        self.state
    }

    /// The setup while on.
    pub fn setup(&self) -> Option<&TrackSetup> {
        self.setup.as_ref()
    }

    /// The master this tracker follows (while on or coupling out).
    pub fn source(&self) -> Option<MasterSource> {
        self.setup.map(|s| s.source)
    }

    /// How the compensation acts on the tool pose (OPTION; full while off).
    pub fn option(&self) -> TrackingOption {
        match self.setup {
            Some(s) if s.translation_only => TrackingOption::TranslationOnly,
            _ => TrackingOption::Full,
        }
    }

    /// SIMU: the compensation is computed and shown but not applied.
    pub fn simulating(&self) -> bool {
        self.setup.is_some_and(|s| s.simu)
    }

    /// `V.G.TRACK_CS.X..C`.
    pub fn zero_values(&self) -> [f64; 6] {
        self.zero_values
    }

    /// The compensation applied in the last tick.
    pub fn applied(&self) -> &Isometry3<f64> {
        &self.applied
    }

    /// Whether a WAIT switching is complete (ON: ACTIVE; OFF: INACTIVE; ERROR ends a wait too).
    pub fn settled(&self) -> bool {
        matches!(
            self.state,
            DynCsState::Active | DynCsState::Inactive | DynCsState::Error
        ) && self.blend.is_none()
    }

    /// Whether a soft coupling in or out is under way (a switch-on waiting for a master
    /// that offers nothing is not).
    pub fn in_transition(&self) -> bool {
        match self.state {
            DynCsState::Deactivating => true,
            DynCsState::Activating => self.blend.is_some() && self.master_live,
            _ => false,
        }
    }

    /// The diagnosis history, oldest first.
    pub fn history(&self) -> impl Iterator<Item = &HistoryEntry> {
        self.history.iter()
    }

    /// The switching log, oldest first.
    pub fn log(&self) -> impl Iterator<Item = &(u64, TrackEvent)> {
        self.log.iter()
    }

    /// State changes since start-up (switched on, active, switched off, inactive, error),
    /// counted whether or not the log still holds them.
    pub fn state_changes(&self) -> u64 {
        self.state_changes
    }

    /// History entry `sequence` (or the oldest kept) and the window kept. For reads while
    /// running.
    pub fn history_at(&self, sequence: u64) -> RingRead<'_, HistoryEntry> {
        self.history.read(sequence)
    }

    /// Log event `sequence` (or the oldest kept), as [`Self::history_at`].
    pub fn log_at(&self, sequence: u64) -> RingRead<'_, (u64, TrackEvent)> {
        self.log.read(sequence)
    }

    fn event(&mut self, event: TrackEvent) {
        self.state_changes += u64::from(matches!(
            event,
            TrackEvent::On { .. }
                | TrackEvent::Active
                | TrackEvent::Off { .. }
                | TrackEvent::Inactive
                | TrackEvent::Error(_)
        ));
        self.log.push((self.tick, event));
    }

    /// Logs `event` at the current tick (tests of the log's readers).
    #[cfg(test)]
    pub(crate) fn log_for_test(&mut self, event: TrackEvent) {
        self.event(event);
    }

    /// Goes to ERROR for `error`, holding the applied compensation: no master frame is
    /// used any more until OFF or a reset.
    pub fn fail(&mut self, error: TrackError) {
        self.state = DynCsState::Error;
        self.blend = None;
        self.last_error = Some(error);
        self.event(TrackEvent::Error(error));
    }

    /// Why the tracker last went to ERROR.
    pub fn last_error(&self) -> Option<TrackError> {
        self.last_error
    }

    /// Tracking off at once (a channel reset at rest): INACTIVE, no compensation. The axes
    /// keep standing where they are; the channel takes that position over.
    pub fn reset(&mut self) {
        if self.state == DynCsState::Inactive {
            return;
        }
        self.state = DynCsState::Inactive;
        self.applied = Isometry3::identity();
        self.blend = None;
        self.setup = None;
        self.tracking = None;
        self.last_master = None;
        self.master_live = false;
        self.event(TrackEvent::Inactive);
    }

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
        if self.blend.is_none() {
            self.end_transition();
        }
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

    /// The blend is done: coupling in becomes ACTIVE, coupling out INACTIVE (everything
    /// released).
    fn end_transition(&mut self) {
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
