//! Typed errors of the kinematics: never NaN, never a panic.

/// Why a kinematic computation has no answer.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum KinError {
    /// An input value is NaN or infinite.
    #[error("input value {index} is not finite")]
    NotFinite {
        /// Position of the value in the input.
        index: usize,
    },
    /// The pose is outside the workspace.
    #[error("pose unreachable: {reason}")]
    Unreachable {
        /// What failed.
        reason: &'static str,
    },
    /// The iteration could not leave a singular configuration.
    #[error("singular configuration: {reason}")]
    Singular {
        /// What was singular.
        reason: &'static str,
    },
    /// Every solution violates a joint limit; the nearest one's first violation is named.
    #[error("joint {joint} at {value:.4} outside its limits [{min}, {max}]")]
    JointLimit {
        /// Joint number, 1-based.
        joint: usize,
        /// Value the solution needs.
        value: f64,
        /// Lower limit.
        min: f64,
        /// Upper limit.
        max: f64,
    },
    /// A kinematic parameter is not acceptable.
    #[error("parameter {name} = {value}: {reason}")]
    BadParameter {
        /// Parameter name.
        name: &'static str,
        /// Its value.
        value: f64,
        /// Why it is refused.
        reason: &'static str,
    },
}
