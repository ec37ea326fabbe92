//! Why a cycle stopped a program ([`Fault`]) and where ([`FaultAt`]): small and `Copy`, made
//! in the cycle; their text is made outside it.

use crate::diag::Pos;

/// Why a cycle stopped the program.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fault {
    /// An integer or real divided by zero.
    DivisionByZero,
    /// An index outside its array's bounds.
    IndexOutOfRange {
        /// The index.
        index: i64,
        /// The lower bound.
        lo: i64,
        /// The upper bound.
        hi: i64,
    },
    /// A pointer that is NULL or points outside the program's memory.
    BadPointer,
    /// A conversion of a value the target type cannot hold (or that is not finite).
    OutOfRange,
    /// The cycle's budget of steps is spent (an endless loop).
    Budget(u64),
    /// MUX's selector names no value.
    MuxSelector(i64),
    /// A write to a leaf of the image the CNC or the drives write.
    ReadOnly,
    /// A whole structure or array copied to or from the image (assign its leaves).
    ImageCopy,
    /// A library block called without its host (a cycle without the PLC runtime).
    NoHost,
    /// A real that is not finite read from the image, or written to it (beyond REAL's range).
    NotFinite,
}

/// A fault and where it happened: small and `Copy`, made in the cycle; its text is made
/// outside it ([`Program::fault_text`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FaultAt {
    /// What.
    pub fault: Fault,
    /// The file's index among the program's files.
    pub file: u16,
    /// The statement's place.
    pub pos: Pos,
}

impl core::fmt::Display for Fault {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Fault::DivisionByZero => write!(f, "division by zero"),
            Fault::IndexOutOfRange { index, lo, hi } => {
                write!(f, "index {index} outside [{lo}..{hi}]")
            }
            Fault::BadPointer => write!(f, "a pointer that is NULL or points outside the program"),
            Fault::OutOfRange => write!(f, "a conversion of a value its type cannot hold"),
            Fault::Budget(steps) => write!(f, "the cycle ran {steps} steps: an endless loop?"),
            Fault::MuxSelector(k) => write!(f, "MUX selector {k} names no value"),
            Fault::ReadOnly => write!(f, "a write to a leaf of the image the CNC writes"),
            Fault::ImageCopy => write!(f, "a whole structure copied to or from the image"),
            Fault::NoHost => write!(f, "a library block without the PLC runtime to run it"),
            Fault::NotFinite => write!(f, "a real of the image that is not finite"),
        }
    }
}
