//! Why a block does not decode, as a value: the decoder runs in the channel's tick, where no
//! text is made; the text comes from `Display` when a diagnostic or a log line is written.
//!
//! Two kinds of causes share the type. Most depend only on the block's text (an unknown axis
//! or G code, a misplaced statement, a missing option): the check at load decodes every block
//! of a program, so a program that loaded never meets them at run time. The others depend on
//! values known only when the block is reached (a variable read before it is assigned, a
//! division by zero, a negative dwell, a feed of 0, an arc whose end misses its circle): those
//! are the decoder's run-time errors.

use crate::nc::arc::ArcError;
use crate::nc::ast::Name;
use crate::nc::eval::EvalError;
use core::fmt;

/// Why a block does not decode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DecodeError {
    // --- from the block's values (possible at run time) ---
    /// P parameter `number` is read before it is assigned.
    UnassignedParam {
        /// The parameter.
        number: u32,
    },
    /// A program variable (`V.P.`, `V.L.`) is read before it is assigned.
    UnassignedVariable {
        /// The variable.
        name: Name,
    },
    /// A variable the language does not know.
    UnknownVariable {
        /// The variable.
        name: Name,
    },
    /// The controller's tool variables (`V.G.WZ_AKT.*`): refused by name, tool data is the
    /// channel's D records (`nc.tools`), selected with `D..`.
    ToolVariable {
        /// The variable.
        name: Name,
    },
    /// An operator or function without a usable value (division by zero, ...).
    Eval(EvalError),
    /// A value that is not finite (it overflowed).
    NotFinite {
        /// The value.
        value: f64,
    },
    /// The expression has no value (a part of it failed without a cause of its own).
    NoValue,
    /// A value that must be a whole number within `min..=max`.
    NotWhole {
        /// What the value is (an option's key, `ID`, `CH`...).
        what: Name,
        /// The range.
        min: f64,
        /// The range.
        max: f64,
        /// The value found.
        value: f64,
    },
    /// `F` is not positive.
    FeedNotPositive {
        /// The value found.
        value: f64,
    },
    /// `S` is negative.
    SpindleNegative {
        /// The value found.
        value: f64,
    },
    /// `T` or `D` is no whole number in 0..=1000000.
    NotWholeAddress {
        /// `T` or `D`.
        letter: &'static str,
        /// The value found.
        value: f64,
    },
    /// `D<n>` names no record of the tool table.
    NoToolRecord {
        /// The record.
        d: u32,
    },
    /// G1/G2/G3 without a feed.
    NoFeed {
        /// "G1", "G2" or "G3".
        motion: &'static str,
    },
    /// A negative dwell (`G04`).
    DwellNegative {
        /// The time found (s).
        seconds: f64,
    },
    /// A `PATH_DEV` that is negative or not finite.
    PathDeviation {
        /// The value found.
        value: f64,
    },
    /// A negative `#TIME`.
    TimeNegative {
        /// The time found (s).
        seconds: f64,
    },
    /// The circle of a G2/G3 block.
    Arc(ArcError),
    /// An independent axis moving at G1 without a positive feed.
    IndependentNoFeed,

    // --- from the block's text (found by the check at load) ---
    /// An axis word of an axis the channel does not have.
    UnknownAxis {
        /// The name as written.
        name: Name,
        /// It looks like an axis with a value glued on (`XP1`): the hint says how to write it.
        glued: bool,
    },
    /// One axis twice in a block.
    AxisTwice {
        /// The axis.
        name: Name,
    },
    /// Two motion codes in one block.
    MotionTwice {
        /// The code given last.
        code: u32,
        /// The code given before.
        other: u32,
    },
    /// A G code this controller does not know.
    UnknownGCode {
        /// The code.
        code: u32,
    },
    /// `#CS` with more than six values.
    CsValues {
        /// How many were given.
        found: usize,
    },
    /// `#WAIT SYN` with more ids than it can wait for.
    WaitSynIds,
    /// A `#TRACK CS` option given twice.
    TrackOptionTwice {
        /// The option.
        key: Name,
    },
    /// A `#TRACK CS OFF` option that only ON takes.
    TrackOffOption {
        /// The option.
        key: Name,
    },
    /// A rule of the block's form, with its fixed text.
    Form(Form),
}

/// The rules of a block's form whose text names everything (nothing to fill in).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Form {
    /// A call with anything but P assignments in its block.
    CallNotAlone,
    /// A `$` statement with anything else in its block.
    ControlNotAlone,
    /// I, J, K or R outside G2/G3.
    ArcWordsWithoutArc,
    /// G04 with a motion or other axes.
    DwellNotAlone,
    /// G04 with its time given twice.
    DwellTimeTwice,
    /// G04 without a time.
    DwellNoTime,
    /// G2/G3 in a channel that lacks an axis of the plane.
    ArcNeedsMainAxes,
    /// `#TRAFO ON` in a channel that lacks a pose axis.
    TrafoNeedsPoseAxes,
    /// A tool length in a channel that lacks the plane's normal axis.
    ToolLengthNeedsAxis,
    /// An option of an independent axis it does not take.
    IndependentOption,
    /// An independent axis without INDP_ASYN / INDP_SYN.
    IndependentMode,
    /// An independent axis without POS.
    IndependentPos,
    /// `#CS OFF` with values.
    CsOffValues,
    /// `#SIGNAL SYN` without ID or COUNT.
    SignalSynOptions,
    /// `#WAIT SYN` without an id.
    WaitSynNoId,
    /// An option without a value.
    ExpectedValue,
    /// `LOG_FILE` without a name.
    LogFileName,
    /// `#TRACK CS` with CH and ID.
    TrackSourceTwice,
    /// `#TRACK CS ON` without a source.
    TrackNoSource,
    /// `#TRACK CS` with SET_ZERO and ABSOLUTE.
    TrackSetZeroTwice,
}

impl Form {
    fn text(self) -> &'static str {
        match self {
            Form::CallNotAlone => "a subroutine call stands in its block with P assignments only",
            Form::ControlNotAlone => "a $ statement stands alone in its block",
            Form::ArcWordsWithoutArc => "I, J, K and R belong to G2/G3 blocks",
            Form::DwellNotAlone => "G04 stands alone in its block: its time is G04 <seconds> or G04 <first axis><seconds>",
            Form::DwellTimeTwice => "G04: give the time once (bare or with the first axis)",
            Form::DwellNoTime => "G04 needs a time in seconds: G04 2.5",
            Form::ArcNeedsMainAxes => "G2/G3 needs both axes of its plane (X Y under G17, Z X under G18, Y Z under G19)",
            Form::ToolLengthNeedsAxis => "D: a tool length goes on the plane's normal axis (Z under G17, Y under G18, X under G19), which this channel lacks",
            Form::TrafoNeedsPoseAxes => "#TRAFO ON needs the six pose axes X Y Z A B C; this channel lacks some",
            Form::IndependentOption => "independent axis: expected INDP_ASYN, INDP_SYN, POS=.., G0, G1, G90, G91 or F..",
            Form::IndependentMode => "independent axis: expected INDP_ASYN or INDP_SYN",
            Form::IndependentPos => "independent axis: expected POS=..",
            Form::CsOffValues => "#CS OFF takes no values",
            Form::SignalSynOptions => "#SIGNAL SYN needs ID.. and COUNT..",
            Form::WaitSynNoId => "#WAIT SYN needs at least one ID..",
            Form::ExpectedValue => "expected a value",
            Form::LogFileName => "#TRACK CS: LOG_FILE needs a file name in quotes, e.g. LOG_FILE=\"dyncs.log\"",
            Form::TrackSourceTwice => "#TRACK CS: give the source as CH=.. or ID=.., not both",
            Form::TrackNoSource => "#TRACK CS ON: expected a source, CH=.. or ID=..",
            Form::TrackSetZeroTwice => "#TRACK CS: SET_ZERO and ABSOLUTE are the same option; give one",
        }
    }
}

impl From<Form> for DecodeError {
    fn from(form: Form) -> Self {
        DecodeError::Form(form)
    }
}

impl From<EvalError> for DecodeError {
    fn from(e: EvalError) -> Self {
        DecodeError::Eval(e)
    }
}

impl DecodeError {
    /// The text with the channel's axis names where it lists them (an unknown axis): what the
    /// check prints. `Display` leaves the list out.
    pub fn with_axes<'a>(&'a self, axes: &'a [String]) -> impl fmt::Display + 'a {
        WithAxes { error: self, axes }
    }
}

struct WithAxes<'a> {
    error: &'a DecodeError,
    axes: &'a [String],
}

impl fmt::Display for WithAxes<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let DecodeError::UnknownAxis { name, glued } = self.error else {
            return write!(f, "{}", self.error);
        };
        write!(f, "unknown axis \"{name}\" for this channel")?;
        if !self.axes.is_empty() {
            f.write_str(" (axes:")?;
            for a in self.axes.iter().filter(|a| !a.is_empty()) {
                write!(f, " {a}")?;
            }
            f.write_str(")")?;
        }
        if *glued {
            let first = &name.as_str()[..1];
            write!(
                f,
                " (a value from a variable is written {first}=..., e.g. {first}=P1)"
            )?;
        }
        Ok(())
    }
}

impl fmt::Display for DecodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DecodeError::UnassignedParam { number } => {
                write!(f, "P{number} is read before it is assigned")
            }
            DecodeError::UnassignedVariable { name } => {
                write!(f, "variable \"{name}\" is read before it is assigned")
            }
            DecodeError::UnknownVariable { name } => {
                write!(
                    f,
                    "unknown variable \"{name}\" (known: V.P.* and V.L.* once assigned"
                )?;
                for v in super::KNOWN_VARIABLES {
                    write!(f, ", {v}")?;
                }
                f.write_str(")")
            }
            DecodeError::ToolVariable { name } => write!(
                f,
                "\"{name}\": the V.G.WZ_AKT tool variables are not supported; tool data are the \
                 channel's D records (nc.tools), selected with D.."
            ),
            DecodeError::Eval(e) => write!(f, "{e}"),
            DecodeError::NotFinite { value } => {
                write!(f, "the value is not a finite number ({value}): it overflowed")
            }
            DecodeError::NoValue => f.write_str("the value cannot be computed"),
            DecodeError::NotWhole {
                what,
                min,
                max,
                value,
            } => write!(
                f,
                "{what} must be a whole number in {min}..={max}, found {value}"
            ),
            DecodeError::FeedNotPositive { value } => {
                write!(f, "feed must be positive, found {value}")
            }
            DecodeError::SpindleNegative { value } => {
                write!(f, "spindle speed S must not be negative, found {value}")
            }
            DecodeError::NotWholeAddress { letter, value } => {
                write!(f, "{letter} must be a whole number 0..=1000000, found {value}")
            }
            DecodeError::NoToolRecord { d } => write!(
                f,
                "D{d}: no such tool data record in the tool table (D0 removes the offset)"
            ),
            DecodeError::NoFeed { motion } => {
                write!(f, "{motion} motion without a feed: program F.. first")
            }
            DecodeError::DwellNegative { seconds } => {
                write!(f, "dwell time must not be negative, found {seconds}")
            }
            DecodeError::PathDeviation { value } => write!(
                f,
                "#CONTOUR MODE: PATH_DEV must be a finite distance of 0 or more (mm), found {value}"
            ),
            DecodeError::TimeNegative { seconds } => {
                write!(f, "#TIME must not be negative, found {seconds}")
            }
            DecodeError::Arc(e) => write!(f, "{e}"),
            DecodeError::IndependentNoFeed => {
                f.write_str("independent axis: G1 needs a positive feed F..")
            }
            DecodeError::UnknownAxis { .. } => write!(f, "{}", self.with_axes(&[])),
            DecodeError::AxisTwice { name } => {
                write!(f, "axis {name} programmed twice in one block")
            }
            DecodeError::MotionTwice { code, other } => {
                write!(f, "G{code} and G{other} in one block: choose one motion")
            }
            DecodeError::UnknownGCode { code } => write!(
                f,
                "unknown G code G{code} (known: G0-G4, G9, G17-G19, G53-G61, G70, G71, G90-G92, G161, G162, G260, G261, G359, G360)"
            ),
            DecodeError::CsValues { found } => {
                write!(f, "#CS takes at most 6 values (X Y Z A B C), found {found}")
            }
            DecodeError::WaitSynIds => write!(
                f,
                "#WAIT SYN waits for at most {} ids",
                super::SyncIds::CAPACITY
            ),
            DecodeError::TrackOptionTwice { key } => {
                write!(f, "#TRACK CS: option {key} given twice")
            }
            DecodeError::TrackOffOption { key } => write!(
                f,
                "#TRACK CS OFF: option {key} is only allowed with ON (OFF takes WAIT, FILTER, ID, CH)"
            ),
            DecodeError::Form(form) => f.write_str(form.text()),
        }
    }
}
