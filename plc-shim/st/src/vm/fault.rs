//! Why a cycle stopped a program ([`Fault`]) and where ([`FaultAt`]): small and `Copy`, made
//! in the cycle; their text is made outside it.

use crate::diag::Pos;

/// Why a cycle stopped the program. Without values of its own, so that a result in the
/// cycle is at most two words (returned in registers); the numbers a fault names are in
/// [`FaultAt::values`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fault {
    /// An integer or real divided by zero.
    DivisionByZero,
    /// An index outside its array's bounds ([`FaultAt::values`]: the index, the lower and
    /// the upper bound).
    IndexOutOfRange,
    /// A pointer that is NULL or points outside the program's memory.
    BadPointer,
    /// A conversion of a value the target type cannot hold (or that is not finite).
    OutOfRange,
    /// The cycle's budget of steps is spent (an endless loop; [`FaultAt::values`]: the
    /// steps).
    Budget,
    /// MUX's selector names no value ([`FaultAt::values`]: the selector).
    MuxSelector,
    /// A write to a leaf of the image the CNC or the drives write.
    ReadOnly,
    /// A whole structure or array copied to or from the image (assign its leaves), or
    /// MEMCPY, MEMSET or MEMCMP there.
    ImageCopy,
    /// A library block called without its host (a cycle without the PLC runtime).
    NoHost,
    /// A real that is not finite read from the image, or written to it (beyond REAL's range).
    NotFinite,
    /// A STRING read as a number (`STRING_TO_INT`, ...) that holds no number of the type.
    NoNumber,
}

impl Fault {
    /// Every fault, in the order of their declaration.
    const ALL: [Fault; 11] = [
        Fault::DivisionByZero,
        Fault::IndexOutOfRange,
        Fault::BadPointer,
        Fault::OutOfRange,
        Fault::Budget,
        Fault::MuxSelector,
        Fault::ReadOnly,
        Fault::ImageCopy,
        Fault::NoHost,
        Fault::NotFinite,
        Fault::NoNumber,
    ];

    /// The fault as native code returns it: one more than its place in the declaration
    /// (0 is no fault).
    pub(crate) fn code(self) -> u64 {
        self as u64 + 1
    }

    /// The fault of [`Fault::code`] `c` (a code no fault has: [`Fault::BadPointer`]).
    pub(crate) fn of_code(c: u64) -> Fault {
        let k = usize::try_from(c.wrapping_sub(1)).unwrap_or(usize::MAX);
        Fault::ALL.get(k).copied().unwrap_or(Fault::BadPointer)
    }
}

const _: () = {
    let mut k = 0;
    while k < Fault::ALL.len() {
        assert!(Fault::ALL[k] as usize == k);
        k += 1;
    }
};

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
    /// The numbers the fault names: an index and its array's bounds, the steps a cycle ran,
    /// a MUX selector (unused ones 0).
    pub values: [i64; 3],
}

impl core::fmt::Display for FaultAt {
    /// What happened, with its numbers (without the place).
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let [a, b, c] = self.values;
        match self.fault {
            Fault::DivisionByZero => write!(f, "division by zero"),
            Fault::IndexOutOfRange => write!(f, "index {a} outside [{b}..{c}]"),
            Fault::BadPointer => write!(f, "a pointer that is NULL or points outside the program"),
            Fault::OutOfRange => write!(f, "a conversion of a value its type cannot hold"),
            Fault::Budget => write!(f, "the cycle ran {a} steps: an endless loop?"),
            Fault::MuxSelector => write!(f, "MUX selector {a} names no value"),
            Fault::ReadOnly => write!(f, "a write to a leaf of the image the CNC writes"),
            Fault::ImageCopy => write!(
                f,
                "a whole structure, MEMCPY, MEMSET or MEMCMP to or from the image (its leaves \
                 are written one by one)"
            ),
            Fault::NoHost => write!(f, "a library block without the PLC runtime to run it"),
            Fault::NotFinite => write!(f, "a real of the image that is not finite"),
            Fault::NoNumber => write!(f, "a STRING read as a value that holds none"),
        }
    }
}

/// [`super::State::site`] when the tree walker's statement is the place.
pub(super) const TREE_SITE: u32 = u32::MAX;

impl super::Exec<'_> {
    /// Fault `fault` at the place of the statement being run.
    pub(super) fn fault_at(&self, fault: Fault) -> FaultAt {
        let named = matches!(
            fault,
            Fault::IndexOutOfRange | Fault::Budget | Fault::MuxSelector
        );
        let (file, pos) = match self.codes.sites.get(self.st.site as usize) {
            Some(&at) => at,
            None => self.st.at,
        };
        FaultAt {
            fault,
            file,
            pos,
            values: if named { self.st.values } else { [0; 3] },
        }
    }

    /// The tree walker's statement `at` is the place a fault names.
    #[inline]
    pub(super) fn tree_at(&mut self, at: (u16, Pos)) {
        self.st.at = at;
        self.st.site = TREE_SITE;
    }

    /// The place a fault would name now (saved around a call that moves it).
    pub(super) fn place(&self) -> (u32, (u16, Pos)) {
        (self.st.site, self.st.at)
    }

    pub(super) fn set_place(&mut self, (site, at): (u32, (u16, Pos))) {
        self.st.site = site;
        self.st.at = at;
    }
}
