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
//!
//! This module holds the tracker's state and what it reports; `types` the values it takes and
//! gives (setup, master sample, log events, history entries), `blend` the smoothing ramp and
//! the frame interpolation, and `switching` the switching itself and the tick.

mod blend;
mod switching;
mod types;

pub use super::ring::{Ring, RingRead};
pub use super::track_error::{BadParameter, TrackError};
pub use blend::{interpolate, smooth_ramp};
pub use switching::words;
pub use types::{HistoryEntry, MasterSample, MasterSource, TrackEvent, TrackSetup};

use blend::Blend;
use hli::enums::DynCsState;
use kinematics::tracking::{Tracking, TrackingOption};
use kinematics::RotationOrder;
use nalgebra::Isometry3;

/// The tracker of one channel.
#[derive(Debug, Clone)]
pub struct Tracker {
    state: DynCsState,
    setup: Option<TrackSetup>,
    tracking: Option<Tracking>,
    /// The compensation applied in the last tick.
    applied: Isometry3<f64>,
    blend: Option<Blend>,
    /// The largest lag of the catch-up under way (mm, degrees), `None` when the axes follow.
    catch_up_peak: Option<(f64, f64)>,
    /// The soft transition's blend is done; the state changes once the axes stand on the
    /// compensation (a step they catch up on, see [`Tracker::land`]).
    landing: bool,
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
            landing: false,
            catch_up_peak: None,
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
            DynCsState::Activating => (self.blend.is_some() || self.landing) && self.master_live,
            _ => false,
        }
    }

    /// The lag of the slave's axes at the tool this tick (mm, degrees; `None`: they follow
    /// exactly): the start of a catch-up and its landing are logged.
    pub fn note_lag(&mut self, lag: Option<(f64, f64)>) {
        match (lag, self.catch_up_peak) {
            (Some((t, r)), None) => {
                self.catch_up_peak = Some((t, r));
                self.event(TrackEvent::CatchUp {
                    landed: false,
                    translation: t,
                    rotation: r,
                });
            }
            (Some((t, r)), Some((pt, pr))) => self.catch_up_peak = Some((pt.max(t), pr.max(r))),
            (None, Some((pt, pr))) => {
                self.catch_up_peak = None;
                self.event(TrackEvent::CatchUp {
                    landed: true,
                    translation: pt,
                    rotation: pr,
                });
            }
            (None, None) => {}
        }
    }

    /// After the channel's axes took this tick's set-points: a transition whose blend is
    /// done ends (ACTIVE or INACTIVE) once the axes no longer lag behind the compensation,
    /// so a FILTER=0 switching that they catch up on stays ACTIVATING or DEACTIVATING until
    /// they stand on it.
    pub fn land(&mut self, axes_lagging: bool) {
        if self.landing && !axes_lagging {
            self.landing = false;
            self.end_transition();
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
        self.landing = false;
        self.catch_up_peak = None;
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
        self.landing = false;
        self.catch_up_peak = None;
        self.setup = None;
        self.tracking = None;
        self.last_master = None;
        self.master_live = false;
        self.event(TrackEvent::Inactive);
    }
}
