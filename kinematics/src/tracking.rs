//! Frame composition of the dynamic coordinate system (`#TRACK CS`).
//!
//! Notation: `M` is the master's frame (the dynamic CS as a master channel or the PLC
//! publishes it), `M0` the master's frame when tracking was switched on, `P` the programmed
//! tool pose of the tracking (slave) channel after its own offsets, `O` the static offset
//! `X Y Z A B C` (angles Z, then Y, then X; translation in the unrotated frame, or with
//! ROT_TRANS in the rotated one).
//!
//! 1. **Displacement** of the dynamic CS, the motion the slave has to follow:
//!    `D = M` (absolute), or `D = M * M0^-1` when the master position was taken over at
//!    switch-on (SET_ZERO).
//! 2. **Moving workpiece** (default): `O` is the master's base frame expressed in the slave's
//!    base frame (the seed's example 3 gives it as `X=400 Y=700 C=-90`). A point fixed on the
//!    workpiece moves by `D` in master coordinates, so the compensation is `C = O * D * O^-1`.
//! 3. **Kinematic-base error** (KIN_BASE): `D` is the measured error of the base, acting at the
//!    error point. `O` says where the kinematic base lies seen from the error point (the
//!    seed's example 4 gives the robot base as `X=-1305.92` from the turntable's centre and
//!    moves the tool to `X1305.92` to reach that centre), so the error point lies at `S = O^-1`
//!    in the kinematic base. The real base sits at `S * D * S^-1` in the nominal base frame;
//!    to keep the tool on the programmed point the compensation is `C = S * D^-1 * S^-1`.
//! 4. **OPTION**: 0 commands `C * P`; 1 follows only with the tool point: the position of
//!    `C * P` with the programmed orientation of `P` (the seed's turntable example: the tool
//!    circles with the table but keeps its orientation). See [`TrackingOption::apply`].
//! 5. **SET_ZERO / `#TRACK CS ABS`**: at switch-on the master frame `M0` is handed to the NC
//!    program as `V.G.TRACK_CS.X..C` ([`track_cs_values`], in the channel's orientation
//!    convention). `#TRACK CS ABS` uses them as additive per-axis zero offsets
//!    ([`track_cs_abs`]): programming 0 on every axis reaches the centre of the dynamic CS; a
//!    rotation of the master is not turned into a position offset of the slave.
//!    `#CS ON [X, Y, Z, A, -B, C]` with those values (default convention) instead makes
//!    the full frame `M0` the program's zero.

use crate::error::KinError;
use crate::frame::{offset_frame, PoseWords, RotationOrder};
use nalgebra::{Isometry3, Point3, Translation3};

/// What the tracking compensates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrackingMode {
    /// The slave machines a workpiece the master moves.
    MovingWorkpiece,
    /// The slave's kinematic base moves by a measured error (KIN_BASE).
    KinematicBase,
}

/// `OPTION=`: what of the dynamic CS is followed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrackingOption {
    /// 0: translation and rotation.
    Full,
    /// 1: translation only: the tool point follows, its orientation stays as programmed.
    TranslationOnly,
}

impl TrackingOption {
    /// The pose commanded for programmed pose `pose` under compensation `compensation`.
    pub fn apply(self, compensation: &Isometry3<f64>, pose: &Isometry3<f64>) -> Isometry3<f64> {
        match self {
            TrackingOption::Full => compensation * pose,
            TrackingOption::TranslationOnly => Isometry3::from_parts(
                // A point, not a vector: the compensation's translation applies too.
                Translation3::from(
                    compensation
                        .transform_point(&Point3::from(pose.translation.vector))
                        .coords,
                ),
                pose.rotation,
            ),
        }
    }

    /// The pose `P` that [`Self::apply`] turns into `commanded` (its inverse).
    pub fn remove(
        self,
        compensation: &Isometry3<f64>,
        commanded: &Isometry3<f64>,
    ) -> Isometry3<f64> {
        self.apply(&compensation.inverse(), commanded)
    }

    /// Decodes `OPTION=` / `transition_w.option`.
    pub fn from_raw(raw: u32) -> Result<Self, KinError> {
        match raw {
            0 => Ok(TrackingOption::Full),
            1 => Ok(TrackingOption::TranslationOnly),
            other => Err(KinError::BadParameter {
                name: "OPTION",
                value: f64::from(other),
                reason: "must be 0 or 1",
            }),
        }
    }
}

/// A switched-on tracking, with everything fixed at switch-on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tracking {
    mode: TrackingMode,
    option: TrackingOption,
    offset: Isometry3<f64>,
    offset_inverse: Isometry3<f64>,
    reference_inverse: Option<Isometry3<f64>>,
}

impl Tracking {
    /// Tracking with static offset words `offset` (X..C), ROT_TRANS per `rotated_translation`,
    /// and, with SET_ZERO, the master frame at switch-on.
    pub fn new(
        mode: TrackingMode,
        option: TrackingOption,
        offset: &PoseWords,
        rotated_translation: bool,
        set_zero_reference: Option<&Isometry3<f64>>,
    ) -> Result<Self, KinError> {
        let offset = offset_frame(offset, rotated_translation)?;
        let reference_inverse = set_zero_reference.map(|m0| m0.inverse());
        Ok(Self {
            mode,
            option,
            offset,
            offset_inverse: offset.inverse(),
            reference_inverse,
        })
    }

    /// The displacement `D` of the dynamic CS for master frame `master` (formula 1).
    pub fn displacement(&self, master: &Isometry3<f64>) -> Isometry3<f64> {
        match self.reference_inverse {
            Some(m0_inverse) => master * m0_inverse,
            None => *master,
        }
    }

    /// The compensation `C` for master frame `master` (formulas 2 and 3).
    pub fn compensation(&self, master: &Isometry3<f64>) -> Isometry3<f64> {
        let d = self.displacement(master);
        match self.mode {
            TrackingMode::MovingWorkpiece => self.offset * d * self.offset_inverse,
            TrackingMode::KinematicBase => self.offset_inverse * d.inverse() * self.offset,
        }
    }

    /// The pose the slave commands for programmed pose `programmed` (formulas 2 to 4).
    pub fn compose(&self, master: &Isometry3<f64>, programmed: &Isometry3<f64>) -> Isometry3<f64> {
        self.option.apply(&self.compensation(master), programmed)
    }

    /// OPTION of this tracking.
    pub fn option(&self) -> TrackingOption {
        self.option
    }
}

/// `V.G.TRACK_CS.X, Y, Z, A, B, C` of a master frame, angles in the channel's convention.
pub fn track_cs_values(master: &Isometry3<f64>, order: RotationOrder) -> [f64; 6] {
    let words = PoseWords::from_frame(master, order);
    [
        words.xyz[0],
        words.xyz[1],
        words.xyz[2],
        words.abc[0],
        words.abc[1],
        words.abc[2],
    ]
}

/// `#TRACK CS ABS`: programmed axis values plus the per-axis zero taken from the master.
pub fn track_cs_abs(programmed: &[f64; 6], zero: &[f64; 6]) -> [f64; 6] {
    core::array::from_fn(|i| programmed[i] + zero[i])
}
