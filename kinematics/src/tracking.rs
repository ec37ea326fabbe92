//! Frame composition of the dynamic coordinate system (`#TRACK CS`).
//!
//! Notation: `M` is the master's frame (the dynamic CS as a master channel or the PLC
//! publishes it), `M0` the master's frame when tracking was switched on, `P` the programmed
//! tool pose of the tracking (slave) channel after its own offsets, `O` the static offset
//! `X Y Z A B C` (angles Z, then Y, then X; translation in the unrotated frame, or with
//! ROT_TRANS in the rotated one). `T(M)` keeps only the translation of `M`.
//!
//! 1. **Displacement** of the dynamic CS, the motion the slave has to follow:
//!    `D = M` (absolute), or `D = M * M0^-1` when the master position was taken over at
//!    switch-on (SET_ZERO); with OPTION=1 (translation only) `M` and `M0` are replaced by
//!    `T(M)` and `T(M0)` first.
//! 2. **Moving workpiece** (default): `O` is the master's base frame expressed in the slave's
//!    base frame (the seed's example 3 gives it as `X=400 Y=700 C=-90`). A point fixed on the
//!    workpiece moves by `D` in master coordinates, so the slave commands
//!    `P_out = O * D * O^-1 * P`.
//! 3. **Kinematic-base error** (KIN_BASE): `D` is the measured error of the base, acting at the
//!    error point whose frame relative to the kinematic base is `S` (the `X..C` of the
//!    command). The real base then sits at `S * D * S^-1` in the nominal base frame; to keep
//!    the tool on the programmed point the slave commands `P_out = S * D^-1 * S^-1 * P`.
//! 4. **SET_ZERO / `#TRACK CS ABS`**: at switch-on the master frame `M0` is handed to the NC
//!    program as `V.G.TRACK_CS.X..C` ([`track_cs_values`], in the channel's orientation
//!    convention). `#TRACK CS ABS` uses them as additive per-axis zero offsets
//!    ([`track_cs_abs`]): programming 0 on every axis reaches the centre of the dynamic CS; a
//!    rotation of the master is not turned into a position offset of the slave.
//!    `#CS ON [X, Y, Z, A, -B, C]` with those values (default convention) instead makes
//!    the full frame `M0` the program's zero.

use crate::error::KinError;
use crate::frame::{offset_frame, PoseWords, RotationOrder};
use nalgebra::{Isometry3, Translation3, UnitQuaternion};

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
    /// 1: translation only.
    TranslationOnly,
}

impl TrackingOption {
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
        let reference_inverse = set_zero_reference.map(|m0| apply_option(option, m0).inverse());
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
        let m = apply_option(self.option, master);
        match self.reference_inverse {
            Some(m0_inverse) => m * m0_inverse,
            None => m,
        }
    }

    /// The pose the slave commands for programmed pose `programmed` (formulas 2 and 3).
    pub fn compose(&self, master: &Isometry3<f64>, programmed: &Isometry3<f64>) -> Isometry3<f64> {
        let d = self.displacement(master);
        match self.mode {
            TrackingMode::MovingWorkpiece => self.offset * d * self.offset_inverse * programmed,
            TrackingMode::KinematicBase => {
                self.offset * d.inverse() * self.offset_inverse * programmed
            }
        }
    }
}

fn apply_option(option: TrackingOption, frame: &Isometry3<f64>) -> Isometry3<f64> {
    match option {
        TrackingOption::Full => *frame,
        TrackingOption::TranslationOnly => Isometry3::from_parts(
            Translation3::from(frame.translation.vector),
            UnitQuaternion::identity(),
        ),
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
