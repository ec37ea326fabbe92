//! Why a channel stopped, as values: the channel fails in its tick, where no text is made.
//! `Display` renders the reason where it is shown (the run's report, a log line, a test).

use super::CS_DEPTH;
use crate::channel::dyn_cs::TrackError;
use crate::channel::guard::LimitViolation;
use crate::channel::path::contour::ContourError;
use crate::channel::path::PathError;
use crate::nc::ast::AxisName;
use crate::nc::interp::ProgramFault;
use core::fmt;
use hli::enums::ChannelErrorId;
use kinematics::KinError;

/// Why a channel stopped: the block and the reason.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelError {
    /// Source line of the block.
    pub line: u32,
    /// The kind of cause, as `error_id_r` reports it.
    pub id: ChannelErrorId,
    /// What went wrong.
    pub fault: ChannelFault,
}

impl ChannelError {
    /// What went wrong, as text (rendered when it is written, never in the tick).
    pub fn message(&self) -> impl fmt::Display + '_ {
        &self.fault
    }
}

impl fmt::Display for ChannelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.fault)
    }
}

/// A catch-up lag beyond `track_lag_max`: the lag at the tool and the bound.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LagExcess {
    /// Distance between the commanded and the compensated tool point (mm).
    pub translation: f64,
    /// Angle between their orientations (degrees).
    pub rotation: f64,
    /// The bound's distance (mm).
    pub max_translation: f64,
    /// The bound's angle (degrees).
    pub max_rotation: f64,
    /// In a switching, the smallest lag of its catch-up (mm, degrees) the bound counts from
    /// (0 while ACTIVE).
    pub floor: (f64, f64),
}

/// What went wrong in a channel, with the values that say why.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ChannelFault {
    /// The program cannot go on: a block that does not decode, an expression without a value,
    /// a jump or call that fails.
    Program(ProgramFault),
    /// The path of a motion block has no profile.
    Path(PathError),
    /// The continuous path cannot go on.
    Contour(ContourError),
    /// `#SIGNAL SYN` found the synchronisation board full.
    SyncBoardFull,
    /// An independent axis's move has no profile.
    IndependentNoProfile {
        /// The axis.
        axis: AxisName,
    },
    /// `#TRACK CS ON` refused.
    TrackRefused(TrackError),
    /// The tracking went to ERROR while the program ran.
    Tracking(TrackError),
    /// A tracked step beyond an axis's limit.
    TrackedStep(LimitViolation),
    /// The axes lagged behind the compensation beyond `track_lag_max`.
    TrackLag(LagExcess),
    /// The dynamic CS compensates on a pose axis the channel lacks.
    TrackAxisMissing {
        /// The axis lacked.
        axis: AxisName,
    },
    /// `#TRAFO ON` on a channel that lacks a pose axis.
    TrafoNeedsPoseAxes,
    /// `#CS` without a transformation.
    CsWithoutTrafo,
    /// More `#CS` frames than the stack holds.
    CsDepth,
    /// A `#CS` frame that is no frame.
    CsFrame(KinError),
    /// `#TRAFO [id]` of a kinematic the channel does not have.
    KinematicNotConfigured {
        /// The id programmed.
        id: u32,
        /// The channel's kinematic.
        configured: u32,
    },
    /// The inverse kinematics has no solution for the pose.
    PoseUnreachable(KinError),
    /// A controlled stop ended the program (the reason the machine gave).
    MachineStop(&'static str),
    /// `#WAIT SYN` waited longer than the channel's `sync_timeout_s` (seconds waited).
    SyncTimeout(f64),
    /// `#WAIT SYN`: the channels that could still signal were stopped, reset or failed.
    SyncPartnerStopped,
}

impl ChannelFault {
    /// The kind of cause, as `error_id_r` reports it.
    pub fn id(&self) -> ChannelErrorId {
        match self {
            ChannelFault::Program(_) => ChannelErrorId::Program,
            ChannelFault::Path(_) | ChannelFault::Contour(_) => ChannelErrorId::Path,
            ChannelFault::SyncBoardFull => ChannelErrorId::Synchronisation,
            ChannelFault::IndependentNoProfile { .. } => ChannelErrorId::IndependentAxis,
            ChannelFault::TrackRefused(_)
            | ChannelFault::Tracking(_)
            | ChannelFault::TrackedStep(_)
            | ChannelFault::TrackLag(_)
            | ChannelFault::TrackAxisMissing { .. } => ChannelErrorId::Tracking,
            ChannelFault::CsWithoutTrafo | ChannelFault::CsDepth | ChannelFault::CsFrame(_) => {
                ChannelErrorId::CoordinateSystem
            }
            ChannelFault::KinematicNotConfigured { .. }
            | ChannelFault::PoseUnreachable(_)
            | ChannelFault::TrafoNeedsPoseAxes => ChannelErrorId::Kinematics,
            ChannelFault::MachineStop(_) => ChannelErrorId::MachineStop,
            ChannelFault::SyncTimeout(_) | ChannelFault::SyncPartnerStopped => {
                ChannelErrorId::SyncAbandoned
            }
        }
    }
}

impl fmt::Display for ChannelFault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ChannelFault::Program(p) => write!(f, "{p}"),
            ChannelFault::Path(e) => write!(f, "{e}"),
            ChannelFault::Contour(e) => write!(f, "{e}"),
            ChannelFault::SyncBoardFull => {
                f.write_str("#SIGNAL SYN: too many synchronisation ids pending")
            }
            ChannelFault::IndependentNoProfile { axis } => {
                write!(f, "independent axis {axis}: no profile")
            }
            ChannelFault::TrackRefused(e) => write!(f, "#TRACK CS ON: {e}"),
            ChannelFault::Tracking(e) => write!(f, "tracking: {e}"),
            ChannelFault::TrackedStep(v) => write!(f, "tracked step refused: {v}"),
            ChannelFault::TrackLag(l) => write!(
                f,
                "tracking: the axes lag {:.3} mm and {:.3} degree behind the compensation, \
                 beyond track_lag_max ({} mm, {} degree)",
                l.translation, l.rotation, l.max_translation, l.max_rotation
            )
            .and_then(|()| match l.floor {
                (0.0, 0.0) => Ok(()),
                (t, r) => write!(
                    f,
                    " above the smallest lag of the switching's catch-up ({t:.3} mm, {r:.3} degree)"
                ),
            }),
            ChannelFault::TrackAxisMissing { axis } => write!(
                f,
                "tracking: the master's motion needs axis {axis}, which this channel lacks \
                 (OPTION=1 follows the translation only)"
            ),
            ChannelFault::TrafoNeedsPoseAxes => {
                f.write_str("#TRAFO ON needs the six pose axes X Y Z A B C")
            }
            ChannelFault::CsWithoutTrafo => {
                f.write_str("#CS needs an active transformation (#TRAFO ON)")
            }
            ChannelFault::CsDepth => write!(f, "more than {CS_DEPTH} coordinate systems active"),
            ChannelFault::CsFrame(e) => write!(f, "#CS: {e}"),
            ChannelFault::KinematicNotConfigured { id, configured } => write!(
                f,
                "kinematic {id} is not configured for this channel (configured: {configured})"
            ),
            ChannelFault::PoseUnreachable(e) => write!(f, "pose unreachable: {e}"),
            ChannelFault::MachineStop(reason) => f.write_str(reason),
            ChannelFault::SyncTimeout(s) => {
                write!(f, "#WAIT SYN: no signal after {s} s (sync_timeout_s)")
            }
            ChannelFault::SyncPartnerStopped => f.write_str(
                "#WAIT SYN: every other channel that could signal was stopped, reset or failed",
            ),
        }
    }
}
