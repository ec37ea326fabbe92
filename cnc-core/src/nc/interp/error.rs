//! Why a step of the interpreter failed, as a value: a channel steps its program in the tick,
//! where no text is made. A check turns it into a [`Diagnostic`] with the file, line and
//! column; a channel keeps the value and renders it when its error is shown.

use super::{ProgramSet, MAX_CALL_DEPTH, MAX_VARIABLES};
use crate::nc::ast::{Name, Span};
use crate::nc::decode::DecodeError;
use crate::nc::Diagnostic;
use core::fmt;

/// Why a program cannot go on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ProgramFault {
    /// The block does not decode, or an expression of a `$` statement or an assignment has
    /// no value.
    Decode(DecodeError),
    /// A call whose subroutine was not loaded (the check at load refuses such a program).
    CallNotLoaded,
    /// Calls nest deeper than [`MAX_CALL_DEPTH`].
    CallDepth,
    /// `$FOR` with step 0.
    ForStepZero,
    /// An assignment to a P parameter beyond the last.
    NoSuchParam {
        /// The parameter.
        number: u32,
    },
    /// More than [`MAX_VARIABLES`] `V.P.` variables.
    TooManyGlobals,
    /// More than [`MAX_VARIABLES`] live `V.L.` variables.
    TooManyLocals,
    /// An assignment to a variable a program cannot assign.
    NotAssignable {
        /// The variable.
        name: Name,
    },
}

impl From<DecodeError> for ProgramFault {
    fn from(e: DecodeError) -> Self {
        ProgramFault::Decode(e)
    }
}

impl ProgramFault {
    /// The text with the channel's axis names where it lists them (see
    /// [`DecodeError::with_axes`]).
    pub fn with_axes<'a>(&'a self, axes: &'a [String]) -> impl fmt::Display + 'a {
        FaultWithAxes { fault: self, axes }
    }
}

struct FaultWithAxes<'a> {
    fault: &'a ProgramFault,
    axes: &'a [String],
}

impl fmt::Display for FaultWithAxes<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.fault {
            ProgramFault::Decode(e) => write!(f, "{}", e.with_axes(self.axes)),
            other => write!(f, "{other}"),
        }
    }
}

impl fmt::Display for ProgramFault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ProgramFault::Decode(e) => write!(f, "{e}"),
            ProgramFault::CallNotLoaded => f.write_str("the subroutine of this call was not loaded"),
            ProgramFault::CallDepth => write!(
                f,
                "subroutine calls nest deeper than {MAX_CALL_DEPTH} levels (a recursion without end?)"
            ),
            ProgramFault::ForStepZero => f.write_str("$FOR with step 0 never ends"),
            ProgramFault::NoSuchParam { number } => write!(f, "P{number} does not exist"),
            ProgramFault::TooManyGlobals => {
                write!(f, "more than {MAX_VARIABLES} V.P. variables")
            }
            ProgramFault::TooManyLocals => {
                write!(f, "more than {MAX_VARIABLES} live V.L. variables")
            }
            ProgramFault::NotAssignable { name } => write!(
                f,
                "\"{name}\" cannot be assigned: a program assigns P parameters, V.P. and V.L. variables"
            ),
        }
    }
}

/// A failed step: the fault and where it stands (unit of the set and span in its source).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepError {
    /// The unit of the [`ProgramSet`] (0: the main program).
    pub unit: u32,
    /// Where in the unit's source.
    pub span: Span,
    /// What went wrong.
    pub fault: ProgramFault,
}

impl StepError {
    /// The diagnostic a check reports (lines and columns not counted yet), with the
    /// subroutine file named and the channel's `axes` where the text lists them.
    pub fn diagnostic(&self, set: &ProgramSet, axes: &[String]) -> Diagnostic {
        let unit = &set.units[self.unit as usize];
        let message = self.fault.with_axes(axes).to_string();
        super::with_file(Diagnostic::new(self.span, message, &unit.src), unit)
    }
}
