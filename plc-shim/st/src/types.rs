//! The types of the language: the elementary ones with their sizes and ranges, and the
//! implicit conversions between them (widening only, as TwinCAT allows without a cast:
//! within signed or unsigned integers, unsigned into a wider signed one, bit strings into
//! wider ones, any integer into REAL/LREAL, REAL into LREAL; every other conversion is a
//! `*_TO_*` function).

/// An elementary type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Elem {
    /// BOOL.
    Bool,
    /// BYTE.
    Byte,
    /// WORD.
    Word,
    /// DWORD.
    DWord,
    /// LWORD.
    LWord,
    /// SINT.
    SInt,
    /// INT.
    Int,
    /// DINT.
    DInt,
    /// LINT.
    LInt,
    /// USINT.
    USInt,
    /// UINT.
    UInt,
    /// UDINT.
    UDInt,
    /// ULINT.
    ULInt,
    /// REAL.
    Real,
    /// LREAL.
    LReal,
    /// TIME (milliseconds in 32 bits, as TwinCAT keeps it).
    Time,
    /// LTIME (nanoseconds in 64 bits).
    LTime,
}

/// What an elementary type is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Class {
    /// BOOL.
    Bool,
    /// BYTE .. LWORD.
    Bits,
    /// SINT .. LINT.
    Signed,
    /// USINT .. ULINT.
    Unsigned,
    /// REAL, LREAL.
    Float,
    /// TIME, LTIME.
    Duration,
}

/// Every elementary type with its name.
pub const ELEMENTARY: [(&str, Elem); 17] = [
    ("BOOL", Elem::Bool),
    ("BYTE", Elem::Byte),
    ("WORD", Elem::Word),
    ("DWORD", Elem::DWord),
    ("LWORD", Elem::LWord),
    ("SINT", Elem::SInt),
    ("INT", Elem::Int),
    ("DINT", Elem::DInt),
    ("LINT", Elem::LInt),
    ("USINT", Elem::USInt),
    ("UINT", Elem::UInt),
    ("UDINT", Elem::UDInt),
    ("ULINT", Elem::ULInt),
    ("REAL", Elem::Real),
    ("LREAL", Elem::LReal),
    ("TIME", Elem::Time),
    ("LTIME", Elem::LTime),
];

impl Elem {
    /// The type of a name (ASCII case ignored).
    pub fn named(name: &str) -> Option<Elem> {
        ELEMENTARY
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(_, e)| *e)
    }

    /// Its name as the standard writes it.
    pub fn name(self) -> &'static str {
        ELEMENTARY
            .iter()
            .find(|(_, e)| *e == self)
            .map_or("?", |(n, _)| n)
    }

    /// Bytes it takes.
    pub fn size(self) -> usize {
        use Elem::*;
        match self {
            Bool | Byte | SInt | USInt => 1,
            Word | Int | UInt => 2,
            DWord | DInt | UDInt | Real | Time => 4,
            LWord | LInt | ULInt | LReal | LTime => 8,
        }
    }

    /// Its class.
    pub fn class(self) -> Class {
        use Elem::*;
        match self {
            Bool => Class::Bool,
            Byte | Word | DWord | LWord => Class::Bits,
            SInt | Int | DInt | LInt => Class::Signed,
            USInt | UInt | UDInt | ULInt => Class::Unsigned,
            Real | LReal => Class::Float,
            Time | LTime => Class::Duration,
        }
    }

    /// Whether it is an integer type (signed, unsigned or a bit string).
    pub fn is_integer(self) -> bool {
        matches!(self.class(), Class::Signed | Class::Unsigned | Class::Bits)
    }

    /// Whether arithmetic applies (integers, reals, durations).
    pub fn is_numeric(self) -> bool {
        self.class() != Class::Bool
    }

    /// The values an integer type holds, `None` for the others.
    pub fn range(self) -> Option<(i128, i128)> {
        let bits = 8 * self.size() as u32;
        match self.class() {
            Class::Signed => Some((-(1i128 << (bits - 1)), (1i128 << (bits - 1)) - 1)),
            Class::Unsigned | Class::Bits => Some((0, (1i128 << bits) - 1)),
            Class::Bool => Some((0, 1)),
            _ => None,
        }
    }

    /// Whether a value of `self` may be used where `to` is wanted without a conversion
    /// function.
    pub fn widens_to(self, to: Elem) -> bool {
        if self == to {
            return true;
        }
        let wider = to.size() > self.size();
        match (self.class(), to.class()) {
            (Class::Signed, Class::Signed)
            | (Class::Unsigned, Class::Unsigned)
            | (Class::Bits, Class::Bits)
            | (Class::Float, Class::Float)
            | (Class::Duration, Class::Duration) => wider,
            (Class::Unsigned, Class::Signed) => wider,
            (Class::Signed | Class::Unsigned | Class::Bits, Class::Float) => true,
            _ => false,
        }
    }

    /// The type both operands of an arithmetic or comparison go to, if there is one: the
    /// wider of the two when one widens to the other.
    pub fn common(a: Elem, b: Elem) -> Option<Elem> {
        if a.widens_to(b) {
            Some(b)
        } else if b.widens_to(a) {
            Some(a)
        } else {
            None
        }
    }

    /// The smallest type an untyped integer literal `v` takes: DINT if it fits (TwinCAT
    /// computes with at least 32 bits), else LINT, else ULINT.
    pub fn of_literal(v: i128) -> Option<Elem> {
        [Elem::DInt, Elem::LInt, Elem::ULInt]
            .into_iter()
            .find(|e| e.range().is_some_and(|(lo, hi)| (lo..=hi).contains(&v)))
    }
}

/// A `*_TO_*` conversion function by name (`DINT_TO_REAL`), with its two types. `TO_*` and
/// `TRUNC` are not this.
pub fn conversion(name: &str) -> Option<(Elem, Elem)> {
    let upper = name.to_ascii_uppercase();
    let (from, to) = upper.split_once("_TO_")?;
    Some((Elem::named(from)?, Elem::named(to)?))
}

/// Why DATE, TIME_OF_DAY and DATE_AND_TIME are refused (types and literals alike).
pub const DATES_REFUSED: &str = "DATE, TIME_OF_DAY and DATE_AND_TIME are not supported: \
     the PLC's clock is TIME() or LTIME(), durations are TIME and LTIME";

/// Whether `upper` names one of the calendar types (IEC 61131-3's and their long forms).
pub fn is_date_type(upper: &str) -> bool {
    matches!(
        upper,
        "DATE"
            | "D"
            | "LDATE"
            | "LD"
            | "TIME_OF_DAY"
            | "TOD"
            | "LTIME_OF_DAY"
            | "LTOD"
            | "DATE_AND_TIME"
            | "DT"
            | "LDATE_AND_TIME"
            | "LDT"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widening_follows_the_classes() {
        assert!(Elem::SInt.widens_to(Elem::DInt));
        assert!(
            !Elem::DInt.widens_to(Elem::Int),
            "narrowing needs a conversion"
        );
        assert!(Elem::UInt.widens_to(Elem::DInt));
        assert!(
            !Elem::UDInt.widens_to(Elem::DInt),
            "not wider: no implicit conversion"
        );
        assert!(
            !Elem::DInt.widens_to(Elem::UDInt),
            "signed into unsigned needs one"
        );
        assert!(Elem::DInt.widens_to(Elem::LReal));
        assert!(!Elem::LReal.widens_to(Elem::Real));
        assert!(!Elem::Bool.widens_to(Elem::Int));
        assert!(!Elem::Time.widens_to(Elem::DInt));
        assert_eq!(Elem::common(Elem::Int, Elem::Real), Some(Elem::Real));
        assert_eq!(Elem::common(Elem::DInt, Elem::UDInt), None);
    }

    #[test]
    fn literals_and_conversions() {
        assert_eq!(Elem::of_literal(-13_059_200), Some(Elem::DInt));
        assert_eq!(Elem::of_literal(1 << 40), Some(Elem::LInt));
        assert_eq!(Elem::of_literal(u64::MAX as i128), Some(Elem::ULInt));
        assert_eq!(Elem::of_literal(1 << 70), None);
        assert_eq!(conversion("dint_to_real"), Some((Elem::DInt, Elem::Real)));
        assert_eq!(
            conversion("LREAL_TO_UDINT"),
            Some((Elem::LReal, Elem::UDInt))
        );
        assert_eq!(conversion("TO_INT"), None);
        assert_eq!(Elem::Int.range(), Some((-32768, 32767)));
        assert_eq!(Elem::Word.range(), Some((0, 65535)));
    }
}
