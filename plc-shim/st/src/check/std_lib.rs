//! The standard library as the checker knows it: the standard function blocks with their
//! inputs and outputs, and the standard functions' names (their typing is in `expr`).

use crate::types::Elem;

/// A standard function block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StdFb {
    /// On-delay timer.
    Ton,
    /// Off-delay timer.
    Tof,
    /// Pulse timer.
    Tp,
    /// Rising edge.
    RTrig,
    /// Falling edge.
    FTrig,
    /// Up counter.
    Ctu,
    /// Down counter.
    Ctd,
    /// Up-down counter.
    Ctud,
    /// Reset-dominant bistable.
    Rs,
    /// Set-dominant bistable.
    Sr,
}

/// A member of a standard function block: name, type, whether it is an input.
pub type Member = (&'static str, Elem, bool);

const TIMER: &[Member] = &[
    ("IN", Elem::Bool, true),
    ("PT", Elem::Time, true),
    ("Q", Elem::Bool, false),
    ("ET", Elem::Time, false),
];
const TRIG: &[Member] = &[("CLK", Elem::Bool, true), ("Q", Elem::Bool, false)];

impl StdFb {
    /// The block of a type name (ASCII case ignored).
    pub fn named(name: &str) -> Option<StdFb> {
        Some(match name.to_ascii_uppercase().as_str() {
            "TON" => StdFb::Ton,
            "TOF" => StdFb::Tof,
            "TP" => StdFb::Tp,
            "R_TRIG" => StdFb::RTrig,
            "F_TRIG" => StdFb::FTrig,
            "CTU" => StdFb::Ctu,
            "CTD" => StdFb::Ctd,
            "CTUD" => StdFb::Ctud,
            "RS" => StdFb::Rs,
            "SR" => StdFb::Sr,
            _ => return None,
        })
    }

    /// Its inputs and outputs.
    pub fn members(self) -> &'static [Member] {
        match self {
            StdFb::Ton | StdFb::Tof | StdFb::Tp => TIMER,
            StdFb::RTrig | StdFb::FTrig => TRIG,
            StdFb::Ctu => &[
                ("CU", Elem::Bool, true),
                ("RESET", Elem::Bool, true),
                ("PV", Elem::Int, true),
                ("Q", Elem::Bool, false),
                ("CV", Elem::Int, false),
            ],
            StdFb::Ctd => &[
                ("CD", Elem::Bool, true),
                ("LOAD", Elem::Bool, true),
                ("PV", Elem::Int, true),
                ("Q", Elem::Bool, false),
                ("CV", Elem::Int, false),
            ],
            StdFb::Ctud => &[
                ("CU", Elem::Bool, true),
                ("CD", Elem::Bool, true),
                ("RESET", Elem::Bool, true),
                ("LOAD", Elem::Bool, true),
                ("PV", Elem::Int, true),
                ("QU", Elem::Bool, false),
                ("QD", Elem::Bool, false),
                ("CV", Elem::Int, false),
            ],
            StdFb::Rs => &[
                ("SET", Elem::Bool, true),
                ("RESET1", Elem::Bool, true),
                ("Q1", Elem::Bool, false),
            ],
            StdFb::Sr => &[
                ("SET1", Elem::Bool, true),
                ("RESET", Elem::Bool, true),
                ("Q1", Elem::Bool, false),
            ],
        }
    }

    /// Member `name` (ASCII case ignored).
    pub fn member(self, name: &str) -> Option<Member> {
        self.members()
            .iter()
            .find(|(n, _, _)| n.eq_ignore_ascii_case(name))
            .copied()
    }
}

/// The standard functions by name.
pub const FUNCTIONS: &[&str] = &[
    "ABS",
    "SQRT",
    "LN",
    "LOG",
    "EXP",
    "SIN",
    "COS",
    "TAN",
    "ASIN",
    "ACOS",
    "ATAN",
    "MIN",
    "MAX",
    "LIMIT",
    "SEL",
    "MUX",
    "TRUNC",
    "TRUNC_INT",
    "SHL",
    "SHR",
    "ROL",
    "ROR",
    "ADR",
    "SIZEOF",
    "EXPT",
    "MOVE",
    "TIME",
    "LTIME",
    "MEMCPY",
    "MEMMOVE",
    "MEMSET",
    "MEMCMP",
    "UPPER_BOUND",
    "LOWER_BOUND",
];

/// Whether `upper` (a name in upper case) is a standard function or function block, which no
/// declaration may take.
pub fn is_reserved_name(upper: &str) -> bool {
    FUNCTIONS.contains(&upper)
        || super::text::TEXT_FUNCTIONS.contains(&upper)
        || super::text::text_conversion(upper).is_some()
        || crate::types::conversion(upper).is_some()
        || super::to_type::target(upper).is_some()
        || StdFb::named(upper).is_some()
}
