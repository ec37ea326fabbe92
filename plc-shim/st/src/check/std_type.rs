//! The standard functions as the checker types them: each one's values and result, the
//! one type MIN, MAX, LIMIT, SEL and MUX compute in, and the bounds of an array.

use super::expr::{literal, literal_fits, not_literal, real_literal, untyped_literal, Ctx};
use super::{Checker, Type};
use crate::ast::{Arg, Expr};
use crate::diag::Pos;
use crate::types::{Class, Elem};

const BOOL: Type = Type::Elem(Elem::Bool);

impl Checker {
    /// The standard functions' types.
    pub(super) fn std_function(&mut self, name: &str, args: &[Arg], pos: Pos, ctx: Ctx) -> Type {
        let values = super::expr::positional(args);
        if values.len() != args.len() {
            return self.error(pos, format!("{name} takes its values by position"));
        }
        let count = |n: std::ops::RangeInclusive<usize>| n.contains(&values.len());
        let types: Vec<Type> = if name == "ADR" || name == "SIZEOF" {
            Vec::new()
        } else {
            values.iter().map(|v| self.expr(v, ctx)).collect()
        };
        if types.contains(&Type::Error) {
            return Type::Error;
        }
        let elem = |k: usize| match types.get(k) {
            Some(Type::Elem(e)) => Some(*e),
            _ => None,
        };
        match name {
            "ADR" if count(1..=1) && self.instance_place(values[0], ctx) => self.error(
                values[0].pos(),
                "ADR of a function block instance or its member: an instance is reached through its calls",
            ),
            // A VAR_IN_OUT is the caller's variable copied in for the call here: a pointer to
            // it would outlive the copy (REF= refuses it too).
            "ADR" if count(1..=1) && self.in_out_root(values[0], ctx) => self.error(
                values[0].pos(),
                "ADR of a VAR_IN_OUT: here it is a copy of the caller's variable for the call; \
                 take the caller's variable's address",
            ),
            "ADR" if count(1..=1) => match self.writable_silent(values[0], ctx) {
                Some(t) => Type::Pointer(Box::new(t)),
                None => self.error(values[0].pos(), "ADR of a variable, a field or an element"),
            },
            "SIZEOF" if count(1..=1) => match self.sizeof_type(values[0], ctx) {
                Type::Error => Type::Error,
                _ => Type::Elem(Elem::UDInt),
            },
            "ABS" if count(1..=1) && elem(0).is_some_and(|e| e.is_numeric()) => types[0].clone(),
            "SQRT" | "LN" | "LOG" | "EXP" | "SIN" | "COS" | "TAN" | "ASIN" | "ACOS" | "ATAN"
                if count(1..=1)
                    && elem(0).is_some_and(|e| e.is_numeric() && e.class() != Class::Duration) =>
            {
                match elem(0) {
                    Some(Elem::Real) => Type::Elem(Elem::Real),
                    _ => Type::Elem(Elem::LReal),
                }
            }
            // EXPT(ANY_REAL, ANY_NUM): a REAL or an LREAL to a real's or an integer's power.
            "EXPT"
                if count(2..=2)
                    && elem(0).is_some_and(|e| e.class() == Class::Float)
                    && elem(1).is_some_and(|e| {
                        matches!(e.class(), Class::Signed | Class::Unsigned | Class::Float)
                    }) =>
            {
                types[0].clone()
            }
            "MOVE" if count(1..=1) && elem(0).is_some() => types[0].clone(),
            "TIME" if count(0..=0) => Type::Elem(Elem::Time),
            "LTIME" if count(0..=0) => Type::Elem(Elem::LTime),
            "TRUNC" if count(1..=1) && elem(0).is_some_and(|e| e.class() == Class::Float) => {
                Type::Elem(Elem::DInt)
            }
            "TRUNC_INT" if count(1..=1) && elem(0).is_some_and(|e| e.class() == Class::Float) => {
                Type::Elem(Elem::Int)
            }
            "SHL" | "SHR" | "ROL" | "ROR"
                if count(2..=2)
                    && elem(0).is_some_and(Elem::is_integer)
                    && elem(1).is_some_and(Elem::is_integer) =>
            {
                types[0].clone()
            }
            // Tc2_System's byte functions, on pointers (ADR(..)) and a count of bytes.
            "MEMCPY" | "MEMMOVE" | "MEMSET" | "MEMCMP"
                if count(3..=3)
                    && matches!(types[0], Type::Pointer(_))
                    && (name == "MEMSET" || matches!(types[1], Type::Pointer(_)))
                    && (name != "MEMSET" || elem(1).is_some_and(Elem::is_integer))
                    && elem(2).is_some_and(Elem::is_integer) =>
            {
                Type::Elem(if name == "MEMCMP" { Elem::DInt } else { Elem::UDInt })
            }
            "UPPER_BOUND" | "LOWER_BOUND" if count(2..=2) => self.bound_type(values[1], &types[0]),
            "MIN" | "MAX" if values.len() >= 2 => self.common_of(&values, &types, pos),
            "LIMIT" if count(3..=3) => self.common_of(&values, &types, pos),
            "SEL" if count(3..=3) => {
                if types[0] != BOOL {
                    return self.error(values[0].pos(), "SEL's first value is BOOL");
                }
                self.common_of(&values[1..], &types[1..], pos)
            }
            "MUX" if values.len() >= 3 => {
                if !elem(0).is_some_and(Elem::is_integer) {
                    return self.error(values[0].pos(), "MUX's first value is an integer");
                }
                self.common_of(&values[1..], &types[1..], pos)
            }
            _ => self.error(pos, format!("{name} does not take these values")),
        }
    }

    /// UPPER_BOUND and LOWER_BOUND: of an array (its type `array`), at a dimension a
    /// constant names (1 the first); DINT.
    fn bound_type(&mut self, dim: &Expr, array: &Type) -> Type {
        let Type::Array(dims, _) = array else {
            return self.error(dim.pos(), "UPPER_BOUND and LOWER_BOUND take an array");
        };
        match literal(dim) {
            Some(k) if k >= 1 && k <= dims.len() as i128 => Type::Elem(Elem::DInt),
            _ => {
                let why = format!(
                    "the dimension is a constant 1..{} of this array",
                    dims.len()
                );
                self.error(dim.pos(), why)
            }
        }
    }

    /// The bound `UPPER_BOUND(a, k)` or `LOWER_BOUND(a, k)` names, a constant (`callee` and
    /// `args` of the call): `to_type` puts it in the call's place before the bodies are
    /// checked, so it is an integer literal everywhere (`FOR i := 0 TO UPPER_BOUND(aBuf, 1)`
    /// of an INT `i`). `None` for any other call, or one `bound_type` refuses.
    pub(super) fn array_bound(&mut self, callee: &Expr, args: &[Arg], ctx: Ctx) -> Option<i64> {
        let Expr::Name(n) = callee else {
            return None;
        };
        let upper = n.text.eq_ignore_ascii_case("UPPER_BOUND");
        if !upper && !n.text.eq_ignore_ascii_case("LOWER_BOUND") {
            return None;
        }
        if self.meaning(&n.text, ctx).is_some() {
            return None;
        }
        let [Arg::Positional(array), Arg::Positional(dim)] = args else {
            return None;
        };
        let errors = self.errors.len();
        let ty = self.expr(array, ctx);
        self.errors.truncate(errors);
        let Type::Array(dims, _) = ty else {
            return None;
        };
        let k = usize::try_from(literal(dim)?).ok()?.checked_sub(1)?;
        dims.get(k).map(|&(lo, hi)| if upper { hi } else { lo })
    }

    pub(super) fn writable_silent(&mut self, e: &Expr, ctx: Ctx) -> Option<Type> {
        match e {
            Expr::Name(_) | Expr::Field(..) | Expr::Index(..) | Expr::Deref(..) => {
                Some(self.expr(e, ctx)).filter(|t| *t != Type::Error)
            }
            _ => None,
        }
    }

    /// The one type all `values` go to: that of the values that are not literals (the
    /// literals must fit it), or of all when all are literals.
    fn common_of(&mut self, values: &[&Expr], types: &[Type], pos: Pos) -> Type {
        let typed: Vec<&Type> = values
            .iter()
            .zip(types)
            .filter(|(v, _)| !untyped_literal(v))
            .map(|(_, t)| t)
            .collect();
        let pool: Vec<&Type> = if typed.is_empty() {
            types.iter().collect()
        } else {
            typed
        };
        let mut common = pool[0].clone();
        // An untyped real beside integers only keeps its own LREAL (`MAX(i, 2.5)`), as
        // before real literals took the real type they meet.
        let lreal = Type::Elem(Elem::LReal);
        let reals = values.iter().any(|v| real_literal(v).is_some());
        let extra = (reals && !pool.iter().any(|t| is_float(t))).then_some(&lreal);
        for t in pool[1..].iter().copied().chain(extra) {
            common = match (&common, t) {
                (Type::Elem(a), Type::Elem(b)) => match Elem::common(*a, *b) {
                    Some(c) => Type::Elem(c),
                    None => {
                        return self.error(pos, format!("values of {} and {}", a.name(), b.name()))
                    }
                },
                (a, b) if a == b => common,
                _ => return self.error(pos, "values of different types"),
            };
        }
        for v in values {
            if let Type::Elem(e) = &common {
                if untyped_literal(v) && !literal_fits(v, *e) {
                    let value = match (literal(v), not_literal(v)) {
                        (Some(x), _) => x.to_string(),
                        (_, Some(x)) => format!("NOT {x}"),
                        _ => format!("{:?}", real_literal(v).unwrap_or_default()),
                    };
                    return self.error(v.pos(), format!("{value} does not fit {}", e.name()));
                }
            }
        }
        common
    }
}

/// Whether `t` is REAL or LREAL.
fn is_float(t: &Type) -> bool {
    matches!(t, Type::Elem(e) if e.class() == Class::Float)
}
