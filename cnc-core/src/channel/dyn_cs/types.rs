//! The values the tracker takes and gives: the setup of a switch-on, the master's sample,
//! the switching log's events and the diagnosis history's entries.

use super::TrackError;
use nalgebra::Isometry3;

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
    pub(super) fn counts_from_switch_on(&self) -> bool {
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
    /// The slave's axes began to catch up with a step of the compensation (the lag it made),
    /// or landed on it (`landed`, with the largest lag of the catch-up).
    CatchUp {
        /// Landed (else began).
        landed: bool,
        /// The lag at the tool: mm.
        translation: f64,
        /// The lag at the tool: degrees.
        rotation: f64,
    },
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
