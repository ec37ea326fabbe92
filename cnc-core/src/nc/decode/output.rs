//! What the decoder hands the channel: the [`Decoded`] elements of a block.

use super::MotionMode;
use crate::nc::ast::Name;
use crate::setpoint::AxisValues;
use std::sync::Arc;

/// A path motion with absolute targets for every axis of the channel.
#[derive(Debug, Clone, PartialEq)]
pub struct MotionBlock {
    /// Source line.
    pub line: u32,
    /// Block number.
    pub number: Option<u32>,
    /// G0, G1, G2 or G3.
    pub motion: MotionMode,
    /// Feed (mm/min).
    pub feed: f64,
    /// Target per channel axis, in channel order.
    pub target: AxisValues,
    /// For G2/G3: the circle (the block starts where the one before ended).
    pub arc: Option<crate::nc::arc::ArcMove>,
    /// Continuous path: the corner with the next block may be rounded by at most this
    /// distance (mm). `None`: the block ends at exact stop.
    pub blend: Option<f64>,
}

/// Where a tracking channel takes its dynamic coordinate system from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrackSource {
    /// `CH=n`: channel n's interface.
    Channel(u8),
    /// `ID=0`: the PLC; `ID=n`: master channel n.
    Id(u8),
}

/// `#TRACK CS ON|OFF [...]`, checked.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackCommand {
    /// ON or OFF.
    pub on: bool,
    /// Source (required for ON; optional for OFF).
    pub source: Option<TrackSource>,
    /// SET_ZERO / ABSOLUTE.
    pub set_zero: bool,
    /// OPTION (0 translation and rotation, 1 translation only).
    pub option: u32,
    /// KIN_BASE.
    pub kin_base: bool,
    /// FILTER in ticks; `None` when not given (ON then takes [`DEFAULT_FILTER_TICKS`], OFF
    /// the filter it switched on with).
    pub filter_ticks: Option<u32>,
    /// WAIT.
    pub wait: bool,
    /// ROT_TRANS.
    pub rot_trans: bool,
    /// RELATIVE.
    pub relative: bool,
    /// X Y Z A B C offset.
    pub offset: [f64; 6],
    /// SIMU.
    pub simu: bool,
    /// LOG_FILE: the file the diagnosis is written to (shared with the tree, so decoding the
    /// block in the tick does not allocate).
    pub log_file: Option<Arc<str>>,
}

/// The signal ids of one `#WAIT SYN`, inline (decoding allocates nothing).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SyncIds {
    ids: [u32; SyncIds::CAPACITY],
    len: u8,
}

impl SyncIds {
    /// Most ids one `#WAIT SYN` names.
    pub const CAPACITY: usize = 8;

    /// Adds `id`; false when full.
    pub fn push(&mut self, id: u32) -> bool {
        let Some(slot) = self.ids.get_mut(usize::from(self.len)) else {
            return false;
        };
        *slot = id;
        self.len += 1;
        true
    }

    /// The ids in the order given.
    pub fn as_slice(&self) -> &[u32] {
        &self.ids[..usize::from(self.len)]
    }
}

/// Default tracking filter, ticks.
pub const DEFAULT_FILTER_TICKS: u32 = 200;

/// One decoded block element.
#[derive(Debug, Clone, PartialEq)]
pub enum Decoded {
    /// Path motion.
    Motion(MotionBlock),
    /// An independent axis move `X1[INDP_ASYN POS=..]`.
    IndependentMove {
        /// Source line.
        line: u32,
        /// Channel axis index.
        axis: usize,
        /// Absolute target.
        target: f64,
        /// Feed.
        feed: f64,
        /// G0 or G1.
        motion: MotionMode,
        /// INDP_ASYN (true) or INDP_SYN.
        asynchronous: bool,
    },
    /// `#WAIT INDP ALL`.
    WaitIndependent {
        /// Source line.
        line: u32,
    },
    /// An M function.
    MFunction {
        /// Source line.
        line: u32,
        /// Code.
        code: u32,
    },
    /// `#TRACK CS ON|OFF`.
    Track {
        /// Source line.
        line: u32,
        /// The command.
        command: TrackCommand,
    },
    /// `#TRACK CS ABS`.
    TrackAbs {
        /// Source line.
        line: u32,
    },
    /// `#CHANNEL INTERFACE ON|OFF`.
    ChannelInterface {
        /// Source line.
        line: u32,
        /// ON or OFF.
        on: bool,
    },
    /// `#CS ON|OFF`.
    Cs {
        /// Source line.
        line: u32,
        /// ON or OFF.
        on: bool,
        /// Name, if given.
        name: Option<Name>,
        /// X Y Z A B C (missing values 0).
        frame: [f64; 6],
    },
    /// `#TRAFO` / `#KIN ID`.
    Trafo {
        /// Source line.
        line: u32,
        /// Transformation on (Some), off, or only the id selected (None).
        on: Option<bool>,
        /// Kinematic id.
        id: Option<u32>,
    },
    /// `#SIGNAL SYN`.
    SignalSyn {
        /// Source line.
        line: u32,
        /// Signal id.
        id: u32,
        /// How many channels it counts for.
        count: u32,
    },
    /// `#WAIT SYN`.
    WaitSyn {
        /// Source line.
        line: u32,
        /// Signal ids waited for.
        ids: SyncIds,
    },
    /// `#FLUSH WAIT|CONTINUE`.
    Flush {
        /// Source line.
        line: u32,
        /// WAIT.
        wait: bool,
    },
    /// `G04` / `#TIME`: wait, nothing moves.
    Dwell {
        /// Source line.
        line: u32,
        /// Seconds.
        seconds: f64,
    },
    /// `#MSG ["text"]`.
    Message {
        /// Source line.
        line: u32,
        /// The text.
        text: Arc<str>,
    },
    /// `S..`: the spindle speed (1/min) M03/M04 turn the spindle at.
    Spindle {
        /// Source line.
        line: u32,
        /// Speed.
        speed: f64,
    },
    /// `T..`: the tool the PLC is to prepare.
    Tool {
        /// Source line.
        line: u32,
        /// Tool number.
        number: u32,
    },
    /// `D..`: the tool data record selected (0: none). Under a transformation the channel
    /// puts it on the flange; without one the decoder offsets the plane's normal by its
    /// length.
    ToolRecord {
        /// Source line.
        line: u32,
        /// D number.
        d: u32,
    },
}
