//! The types of expressions. Untyped integer and real literals take the type their place
//! wants when they fit it (`x : INT; x := 5;`); every other mix of types must widen
//! ([`Elem::widens_to`]) or go through a conversion function.

use super::std_lib;
use super::{Checker, Type};
use crate::ast::{Arg, BinOp, Expr, Name, PouKind, Section, UnOp};
use crate::diag::Pos;
use crate::ir::Ex;
use crate::types::{conversion, Class, Elem};

/// Where an expression is checked: the POU and how many loops enclose it.
#[derive(Debug, Clone, Copy)]
pub(super) struct Ctx {
    pub(super) pou: usize,
    pub(super) loops: u32,
}

/// The context of a global variable's initial value: no POU, no locals.
pub(super) const GLOBAL: Ctx = Ctx {
    pou: usize::MAX,
    loops: 0,
};

/// What a name means in a POU.
pub(super) enum Meaning {
    /// A variable of the POU (index into its vars).
    Local(usize),
    /// A global variable.
    Global(usize),
    /// A function's own name inside it: its return value.
    Return(Type),
    /// A value of an enumeration.
    EnumValue(usize),
    /// A function.
    Function(usize),
    /// A type (an enumeration's name before `.value`).
    EnumType(usize),
}

const BOOL: Type = Type::Elem(Elem::Bool);

/// The values of a call given by position.
pub(super) fn positional(args: &[Arg]) -> Vec<&Expr> {
    args.iter()
        .filter_map(|a| match a {
            Arg::Positional(v) => Some(v),
            _ => None,
        })
        .collect()
}

/// An untyped integer literal's value (`5`, `-5`), or that of a constant expression of
/// them (`200 * 2`, `-(60 * 1000)`, `7 / 2`: folded at load as TwinCAT does, so that it
/// takes the type it meets as a literal does; integer division truncates, MOD takes the
/// dividend's sign). An expression that divides by zero or leaves the widest integer's
/// range is not folded (it keeps its own type and rules).
pub(super) fn literal(e: &Expr) -> Option<i128> {
    match e {
        Expr::Int(v, _) => Some(*v),
        Expr::Unary(UnOp::Neg, inner, _) => literal(inner).and_then(|v| in_range(-v)),
        Expr::Binary(op, l, r, _) => {
            let (a, b) = (in_range(literal(l)?)?, in_range(literal(r)?)?);
            let v = match op {
                BinOp::Add => a.checked_add(b),
                BinOp::Sub => a.checked_sub(b),
                BinOp::Mul => a.checked_mul(b),
                BinOp::Div => a.checked_div(b),
                BinOp::Mod => a.checked_rem(b),
                _ => None,
            };
            in_range(v?)
        }
        _ => None,
    }
}

/// `v` when an integer type holds it (LINT's least to ULINT's greatest).
fn in_range(v: i128) -> Option<i128> {
    (i128::from(i64::MIN)..=i128::from(u64::MAX))
        .contains(&v)
        .then_some(v)
}

/// An untyped real literal's value (`2.5`, `-0.5`), or that of a constant expression of
/// them and integer literals with a real among them (`100.0 / 60.0`, `2 * 1.5`), folded
/// in LREAL's arithmetic (a result that is no finite number is not folded). It takes the
/// type of the REAL or LREAL it meets, as an untyped integer literal takes an integer's:
/// `r := r / 2.0;` of a REAL `r` computes in REAL (`LREAL#2.0` stays an LREAL).
pub(super) fn real_literal(e: &Expr) -> Option<f64> {
    match e {
        Expr::Real(v, _) => Some(*v),
        Expr::Unary(UnOp::Neg, inner, _) => real_literal(inner).map(|v| -v),
        Expr::Binary(op, l, r, _) => {
            let (a, b) = (real_literal(l), real_literal(r));
            // `**` is a real's power (EXPT) even of two integers (`10 ** 2` is 100.0).
            if a.is_none() && b.is_none() && *op != BinOp::Pow {
                return None;
            }
            let number = |x: Option<f64>, e: &Expr| x.or_else(|| literal(e).map(|v| v as f64));
            let (a, b) = (number(a, l)?, number(b, r)?);
            let v = match op {
                BinOp::Add => a + b,
                BinOp::Sub => a - b,
                BinOp::Mul => a * b,
                BinOp::Div => a / b,
                BinOp::Pow => a.powf(b),
                _ => return None,
            };
            v.is_finite().then_some(v)
        }
        _ => None,
    }
}

/// The literal of `NOT <untyped integer literal>` (`w AND NOT 16#0F`): it takes the integer
/// or bit string type it meets, and NOT is taken in that type's width.
pub(super) fn not_literal(e: &Expr) -> Option<i128> {
    match e {
        Expr::Unary(UnOp::Not, inner, _) => literal(inner),
        _ => None,
    }
}

/// Whether `e` is an untyped literal, integer or real (or NOT of an integer).
pub(super) fn untyped_literal(e: &Expr) -> bool {
    literal(e).is_some() || real_literal(e).is_some() || not_literal(e).is_some()
}

/// A call of MIN, MAX, LIMIT, SEL or MUX whose values are all untyped literals (SEL's and
/// MUX's selector aside): the standard function's name in upper case and its values, the
/// selector first, and where its name is. It takes the type it meets as its literals would
/// (`n := SEL(bFast, 10, 100);` of an INT).
pub(super) fn literal_call(e: &Expr) -> Option<(String, Pos, Vec<&Expr>)> {
    let Expr::Call { callee, args, .. } = e else {
        return None;
    };
    let Expr::Name(n) = &**callee else {
        return None;
    };
    let upper = n.text.to_ascii_uppercase();
    let selected = match upper.as_str() {
        "SEL" | "MUX" => 1,
        "MIN" | "MAX" | "LIMIT" => 0,
        _ => return None,
    };
    let values = positional(args);
    let all = values.len() == args.len() && values.len() > selected;
    let literals = all && values[selected..].iter().all(|v| untyped_literal(v));
    literals.then_some((upper, n.pos, values))
}

/// Whether `e` is an untyped literal type `t` holds: an integer within `t`'s range (or of
/// a real type), or a real of a real type that holds it (a REAL: finite in 32 bits); or a
/// [`literal_call`] of such literals.
pub(super) fn literal_fits(e: &Expr, t: Elem) -> bool {
    if let Some((f, _, values)) = literal_call(e) {
        let skip = usize::from(matches!(f.as_str(), "SEL" | "MUX"));
        return values[skip..].iter().all(|v| literal_fits(v, t));
    }
    if let Some(v) = not_literal(e) {
        return t.is_integer() && t.range().is_some_and(|(lo, hi)| (lo..=hi).contains(&v));
    }
    if let Some(v) = literal(e) {
        return t.range().is_some_and(|(lo, hi)| (lo..=hi).contains(&v))
            || t.class() == Class::Float;
    }
    real_literal(e).is_some_and(|v| match t {
        Elem::LReal => true,
        Elem::Real => (v as f32).is_finite(),
        _ => false,
    })
}

/// The value of untyped literal `e` in the type `to` it meets (the checker found it fits).
pub(super) fn literal_value(e: &Expr, to: Elem) -> Option<Ex> {
    if let Some(v) = literal(e) {
        return Some(match to.class() {
            Class::Float => Ex::Real(v as f64),
            _ => Ex::Int(v as i64),
        });
    }
    // NOT of an integer literal: NOT in the width of the type it meets.
    if let (Some(v), true) = (not_literal(e), to.is_integer()) {
        return Some(Ex::Not(Box::new(Ex::Int(v as i64)), to));
    }
    // A real: REAL's rounding once here, as LREAL_TO_REAL would at every cycle.
    match (real_literal(e), to) {
        (Some(v), Elem::Real) => Some(Ex::Real(f64::from(v as f32))),
        (Some(v), Elem::LReal) => Some(Ex::Real(v)),
        _ => None,
    }
}

impl Checker {
    pub(super) fn meaning(&self, name: &str, ctx: Ctx) -> Option<Meaning> {
        if let Some(pou) = self.out.pous.get(ctx.pou) {
            if let Some(i) = pou
                .vars
                .iter()
                .position(|v| v.name.eq_ignore_ascii_case(name))
            {
                // VAR_EXTERNAL names the global of that name (`check_externals`).
                if pou.vars[i].section == crate::ast::Section::External {
                    if let Some(g) = self.globals.get(&name.to_ascii_uppercase()) {
                        return Some(Meaning::Global(*g));
                    }
                }
                return Some(Meaning::Local(i));
            }
            if pou.kind == PouKind::Function && pou.name.eq_ignore_ascii_case(name) {
                return pou.returns.clone().map(Meaning::Return);
            }
            // A method's own name inside it: its value.
            let named = (pou.method.as_ref()).is_some_and(|m| m.name.eq_ignore_ascii_case(name));
            if let (true, Some(t)) = (named, &pou.returns) {
                return Some(Meaning::Return(t.clone()));
            }
        }
        let upper = name.to_ascii_uppercase();
        if let Some(i) = self.globals.get(&upper) {
            return Some(Meaning::Global(*i));
        }
        match self.names.get(&upper) {
            Some(super::Named::Pou(i)) if self.out.pous[*i].kind == PouKind::Function => {
                return Some(Meaning::Function(*i))
            }
            Some(super::Named::Enum(i)) => return Some(Meaning::EnumType(*i)),
            _ => {}
        }
        // A bare enumeration value, if exactly one enumeration has it.
        let mut found = self
            .out
            .enums
            .iter()
            .enumerate()
            .filter(|(_, e)| e.values.iter().any(|(v, _)| v.eq_ignore_ascii_case(name)));
        match (found.next(), found.next()) {
            (Some((i, _)), None) => Some(Meaning::EnumValue(i)),
            _ => None,
        }
    }

    /// The type of `e`; a refusal is reported once and gives [`Type::Error`].
    pub(super) fn expr(&mut self, e: &Expr, ctx: Ctx) -> Type {
        match e {
            Expr::Int(v, pos) => match Elem::of_literal(*v) {
                Some(t) => Type::Elem(t),
                None => self.error(*pos, format!("{v} fits no integer type")),
            },
            Expr::Real(..) => Type::Elem(Elem::LReal),
            Expr::Bool(..) => BOOL,
            Expr::Time(ns, true, pos) if i64::try_from(*ns).is_err() => {
                self.error(*pos, "an LTIME literal beyond LTIME's 2^63 ns")
            }
            Expr::Time(_, true, _) => Type::Elem(Elem::LTime),
            Expr::Time(ns, false, pos) if i32::try_from(*ns / 1_000_000).is_err() => self.error(
                *pos,
                "a TIME literal beyond TIME's T#24d20h31m23s647ms (an LTIME# holds it)",
            ),
            Expr::Time(..) => Type::Elem(Elem::Time),
            Expr::Str(s, pos) => match u32::try_from(s.chars().count()) {
                Ok(n) if n <= 255 => Type::Str(n.max(1)),
                _ => self.error(*pos, "a string literal of more than 255 characters"),
            },
            Expr::Typed { ty, value } => self.typed_literal(ty, value),
            Expr::Name(n) => self.name_type(n, ctx),
            Expr::Field(base, field) => self.field(base, field, ctx),
            Expr::Index(base, index, pos) => self.index(base, index, *pos, ctx),
            Expr::Deref(base, pos) => match self.expr(base, ctx) {
                Type::Pointer(t) => *t,
                Type::Error => Type::Error,
                _ => self.error(*pos, "`^` follows a POINTER"),
            },
            Expr::Call { callee, args, pos } => self.call_value(callee, args, *pos, ctx),
            Expr::Unary(op, inner, pos) => self.unary(*op, inner, *pos, ctx),
            // A constant expression of untyped integer literals: the type of its value, as
            // a literal's (`200 * 2` is a DINT that an INT takes).
            Expr::Binary(..) if literal(e).is_some() => {
                Type::Elem(literal(e).and_then(Elem::of_literal).unwrap_or(Elem::LInt))
            }
            // A constant `**` of literals: an LREAL, as a real literal is.
            Expr::Binary(BinOp::Pow, ..) if real_literal(e).is_some() => Type::Elem(Elem::LReal),
            Expr::Binary(op, l, r, pos) => self.binary(*op, l, r, *pos, ctx),
        }
    }

    pub(super) fn error(&mut self, pos: Pos, message: impl Into<String>) -> Type {
        self.refuse(pos, message);
        Type::Error
    }

    fn name_type(&mut self, n: &Name, ctx: Ctx) -> Type {
        match self.meaning(&n.text, ctx) {
            Some(Meaning::Local(i)) => self.out.pous[ctx.pou].vars[i].ty.clone(),
            Some(Meaning::Global(i)) => self.out.globals[i].ty.clone(),
            Some(Meaning::Return(t)) => t,
            Some(Meaning::EnumValue(i)) => Type::Enum(i),
            Some(Meaning::Function(_)) => self.error(
                n.pos,
                format!("function `{}` is called: `{}(..)`", n.text, n.text),
            ),
            Some(Meaning::EnumType(_)) => self.error(
                n.pos,
                format!("`{}` is a type: name one of its values", n.text),
            ),
            None => self.error(n.pos, format!("unknown name `{}`", n.text)),
        }
    }

    /// `DINT#-5`, `BOOL#TRUE`, `REAL#1.5`, `E_Mode#Run`.
    fn typed_literal(&mut self, ty: &Name, value: &Expr) -> Type {
        if let Some(e) = Elem::named(&ty.text) {
            return match (e.class(), value) {
                (Class::Float, Expr::Int(..) | Expr::Real(..)) => Type::Elem(e),
                (Class::Bool, Expr::Bool(..)) => Type::Elem(e),
                (Class::Bool, Expr::Int(v, _)) if *v == 0 || *v == 1 => Type::Elem(e),
                (_, Expr::Int(v, pos)) if e.is_integer() => match e.range() {
                    Some((lo, hi)) if (lo..=hi).contains(v) => Type::Elem(e),
                    _ => self.error(*pos, format!("{v} does not fit {}", e.name())),
                },
                _ => self.error(ty.pos, format!("not a literal of {}", e.name())),
            };
        }
        let Some(super::Named::Enum(i)) = self.names.get(&ty.text.to_ascii_uppercase()).cloned()
        else {
            return self.error(
                ty.pos,
                format!("unknown type `{}` of a typed literal", ty.text),
            );
        };
        match value {
            Expr::Name(v) if self.enum_has(i, &v.text) => Type::Enum(i),
            _ => {
                let name = self.out.enums[i].name.clone();
                self.error(ty.pos, format!("not a value of {name}"))
            }
        }
    }

    fn enum_has(&self, i: usize, value: &str) -> bool {
        self.out.enums[i]
            .values
            .iter()
            .any(|(v, _)| v.eq_ignore_ascii_case(value))
    }

    fn field(&mut self, base: &Expr, field: &Name, ctx: Ctx) -> Type {
        if let Expr::Name(n) = base {
            if let Some(Meaning::EnumType(i)) = self.meaning(&n.text, ctx) {
                if self.enum_has(i, &field.text) {
                    return Type::Enum(i);
                }
                let name = self.out.enums[i].name.clone();
                return self.error(field.pos, format!("{name} has no value `{}`", field.text));
            }
        }
        match self.expr(base, ctx) {
            Type::Struct(i) => {
                let found = self.out.structs[i]
                    .fields
                    .iter()
                    .find(|(f, _)| f.eq_ignore_ascii_case(&field.text));
                match found {
                    Some((_, t)) => t.clone(),
                    None => {
                        let name = self.out.structs[i].name.clone();
                        self.error(field.pos, format!("{name} has no field `{}`", field.text))
                    }
                }
            }
            Type::Fb(i) => self.fb_member(i, field),
            Type::StdFb(fb) => match fb.member(&field.text) {
                Some((_, t, _)) => Type::Elem(t),
                None => self.error(field.pos, format!("{fb:?} has no member `{}`", field.text)),
            },
            Type::Elem(e) if e.is_integer() && field.text.parse::<u32>().is_ok() => {
                let bit: u32 = field.text.parse().unwrap_or(u32::MAX);
                if bit < 8 * e.size() as u32 {
                    BOOL
                } else {
                    self.error(field.pos, format!("bit {bit} of a {}", e.name()))
                }
            }
            Type::Pointer(_) => {
                self.error(field.pos, "a POINTER's fields are reached through `^.`")
            }
            Type::Error => Type::Error,
            _ => self.error(
                field.pos,
                format!("`.{}` of a value without fields", field.text),
            ),
        }
    }

    /// An input or output of an instance of function block `i`, read from outside.
    fn fb_member(&mut self, i: usize, field: &Name) -> Type {
        let pou = &self.out.pous[i];
        let var = pou
            .vars
            .iter()
            .find(|v| v.name.eq_ignore_ascii_case(&field.text));
        match var {
            Some(v) if matches!(v.section, Section::Input | Section::Output) => v.ty.clone(),
            Some(_) => {
                let name = pou.name.clone();
                self.error(
                    field.pos,
                    format!(
                        "`{}` is internal to {name}: only its inputs and outputs are reached",
                        field.text
                    ),
                )
            }
            None => {
                let name = pou.name.clone();
                self.error(
                    field.pos,
                    format!("{name} has no input or output `{}`", field.text),
                )
            }
        }
    }

    fn index(&mut self, base: &Expr, index: &[Expr], pos: Pos, ctx: Ctx) -> Type {
        let base = self.expr(base, ctx);
        for i in index {
            match self.expr(i, ctx) {
                // An enumeration's value indexes by its number (an array over its values).
                Type::Elem(e) if e.is_integer() => {}
                Type::Enum(_) | Type::Error => {}
                _ => {
                    self.refuse(i.pos(), "an index is an integer or an enumeration's value");
                }
            }
        }
        match base {
            Type::Array(dims, element) if dims.len() == index.len() => {
                for ((lo, hi), i) in dims.iter().zip(index) {
                    let constant = literal(i).or_else(|| self.enum_literal(i));
                    if let Some(v) = constant.filter(|v| !(*lo as i128..=*hi as i128).contains(v)) {
                        self.refuse(i.pos(), format!("index {v} outside [{lo}..{hi}]"));
                    }
                }
                *element
            }
            Type::Array(dims, _) => self.error(
                pos,
                format!(
                    "{} indices for an array of {} dimensions",
                    index.len(),
                    dims.len()
                ),
            ),
            Type::Error => Type::Error,
            _ => self.error(pos, "`[..]` of a value that is no ARRAY"),
        }
    }

    fn unary(&mut self, op: UnOp, inner: &Expr, pos: Pos, ctx: Ctx) -> Type {
        let t = self.expr(inner, ctx);
        match (op, &t) {
            (_, Type::Error) => Type::Error,
            (UnOp::Neg, Type::Elem(e))
                if matches!(e.class(), Class::Signed | Class::Float | Class::Duration) =>
            {
                t
            }
            (UnOp::Not, Type::Elem(e)) if e.class() == Class::Bool || e.is_integer() => t,
            (UnOp::Neg, _) => self.error(pos, "`-` of a value that has no sign"),
            (UnOp::Not, _) => self.error(pos, "NOT of a value that is neither BOOL nor bits"),
        }
    }

    /// The type both sides of `l op r` go to, literals taking the other side's type.
    pub(super) fn operands(&mut self, l: &Expr, r: &Expr, ctx: Ctx) -> Option<(Elem, Type, Type)> {
        let (lt, rt) = (self.expr(l, ctx), self.expr(r, ctx));
        operands_of(l, r, lt, rt)
    }

    fn binary(&mut self, op: BinOp, l: &Expr, r: &Expr, pos: Pos, ctx: Ctx) -> Type {
        use BinOp::*;
        // Each operand typed once: a chain of operators costs its length, not 2^length.
        let (lt, rt) = (self.expr(l, ctx), self.expr(r, ctx));
        if matches!(op, Eq | Ne) {
            if let (Type::Enum(a), Type::Enum(b)) = (&lt, &rt) {
                return if a == b {
                    BOOL
                } else {
                    self.error(pos, "values of two enumerations")
                };
            }
            // Two pointers to the same type, or a pointer and 0 (NULL: `IF p <> 0 THEN`).
            let null = |e: &Expr| literal(e) == Some(0);
            match (&lt, &rt) {
                (Type::Pointer(a), Type::Pointer(b)) if a == b => return BOOL,
                (Type::Pointer(_), _) if null(r) => return BOOL,
                (_, Type::Pointer(_)) if null(l) => return BOOL,
                _ => {}
            }
        }
        if lt == Type::Error || rt == Type::Error {
            return Type::Error;
        }
        // TwinCAT's pointer arithmetic, in bytes (`p := p + SIZEOF(INT);`): a pointer moved
        // is a pointer to the same type, and two pointers to one type are ordered (`WHILE p
        // < pEnd`); where it points is checked where it is read or written.
        let count = |t: &Type| matches!(t, Type::Elem(e) if matches!(e.class(), Class::Signed | Class::Unsigned));
        match (op, &lt, &rt) {
            (Add | Sub, Type::Pointer(_), n) if count(n) => return lt,
            (Add, n, Type::Pointer(_)) if count(n) => return rt,
            (Lt | Gt | Le | Ge, Type::Pointer(a), Type::Pointer(b)) if a == b => return BOOL,
            _ => {}
        }
        if let Some((d, _, _)) = scaled_duration(op, &lt, &rt) {
            return Type::Elem(d);
        }
        // Two STRINGs are equal or not (their characters before the NUL), or ordered by
        // their bytes.
        if let (Eq | Ne | Lt | Gt | Le | Ge, Type::Str(_), Type::Str(_)) = (op, &lt, &rt) {
            return BOOL;
        }
        let Some((c, _, _)) = operands_of(l, r, lt.clone(), rt.clone()) else {
            let message = format!(
                "{} of {} and {}",
                op_name(op),
                self.type_name(&lt),
                self.type_name(&rt)
            );
            return self.error(pos, message);
        };
        self.binary_result(op, c, pos)
    }

    fn binary_result(&mut self, op: BinOp, c: Elem, pos: Pos) -> Type {
        use BinOp::*;
        let class = c.class();
        let ok = match op {
            Or | Xor | And => class == Class::Bool || c.is_integer(),
            Eq | Ne => true,
            Lt | Gt | Le | Ge => class != Class::Bool,
            Add | Sub => c.is_numeric(),
            Mul | Div => matches!(
                class,
                Class::Signed | Class::Unsigned | Class::Bits | Class::Float
            ),
            Mod => c.is_integer(),
            Pow => class == Class::Float,
            AndThen | OrElse => class == Class::Bool,
        };
        if !ok {
            return self.error(pos, format!("{} of {}", op_name(op), c.name()));
        }
        match op {
            Eq | Ne | Lt | Gt | Le | Ge => BOOL,
            _ => Type::Elem(c),
        }
    }
}

/// A duration scaled by a number, as IEC 61131-3's MUL and DIV of TIME take it: `TIME * n`,
/// `n * TIME`, `TIME / n` of an integer or a real `n` (no bit string): the duration's type,
/// the number's, and whether the duration is the left operand.
pub(super) fn scaled_duration(op: BinOp, lt: &Type, rt: &Type) -> Option<(Elem, Elem, bool)> {
    let (Type::Elem(a), Type::Elem(b)) = (lt, rt) else {
        return None;
    };
    let number = |e: &Elem| matches!(e.class(), Class::Signed | Class::Unsigned | Class::Float);
    let duration = |e: &Elem| e.class() == Class::Duration;
    match op {
        BinOp::Mul | BinOp::Div if duration(a) && number(b) => Some((*a, *b, true)),
        BinOp::Mul if number(a) && duration(b) => Some((*b, *a, false)),
        _ => None,
    }
}

/// The type both sides of `l op r` go to (of types `lt`, `rt`), literals taking the other
/// side's type.
pub(super) fn operands_of(l: &Expr, r: &Expr, lt: Type, rt: Type) -> Option<(Elem, Type, Type)> {
    {
        let common = match (&lt, &rt) {
            (Type::Elem(a), Type::Elem(b)) => {
                if literal_fits(l, *b) {
                    Some(*b)
                } else if literal_fits(r, *a) {
                    Some(*a)
                } else {
                    Elem::common(*a, *b)
                }
            }
            _ => None,
        };
        common.map(|c| (c, lt, rt))
    }
}

impl Checker {
    /// A type as a message writes it.
    pub(super) fn type_name(&self, t: &Type) -> String {
        match t {
            Type::Elem(e) => e.name().into(),
            Type::Str(n) => format!("STRING({n})"),
            Type::Array(dims, e) => {
                let dims: Vec<String> = dims.iter().map(|(a, b)| format!("{a}..{b}")).collect();
                format!("ARRAY[{}] OF {}", dims.join(", "), self.type_name(e))
            }
            Type::Struct(i) => self.out.structs[*i].name.clone(),
            Type::Enum(i) => self.out.enums[*i].name.clone(),
            Type::Pointer(t) => format!("POINTER TO {}", self.type_name(t)),
            Type::Fb(i) => self.out.pous[*i].name.clone(),
            Type::StdFb(fb) => format!("{fb:?}").to_ascii_uppercase(),
            Type::Error => "?".into(),
        }
    }

    /// A call whose value is used: a function, a standard function or a conversion.
    fn call_value(&mut self, callee: &Expr, args: &[Arg], pos: Pos, ctx: Ctx) -> Type {
        // A method (`fb.M(..)`, or `M(..)` inside its POU, made `THIS^.M(..)` by then).
        if let Some((m, _)) = self.method_of(callee, ctx) {
            return self.method_call(m, (args, pos), ctx, true);
        }
        let Expr::Name(n) = callee else {
            let why = self.no_method(callee, ctx);
            return self.error(pos, why);
        };
        let upper = n.text.to_ascii_uppercase();
        if let Some(t) = self.text_call_type(&upper, args, n.pos, ctx) {
            return t;
        }
        if let Some((from, to)) = conversion(&n.text) {
            let [Arg::Positional(a)] = args else {
                return self.error(pos, format!("{} takes one value", n.text));
            };
            return match self.expr(a, ctx) {
                Type::Elem(e)
                    if e == from
                        || e.widens_to(from)
                        || literal(a).is_some()
                        || literal_fits(a, from) =>
                {
                    Type::Elem(to)
                }
                Type::Error => Type::Error,
                t => {
                    let found = self.type_name(&t);
                    self.error(
                        a.pos(),
                        format!("{} takes a {}, not a {found}", n.text, from.name()),
                    )
                }
            };
        }
        if std_lib::FUNCTIONS.contains(&upper.as_str()) {
            return self.std_function(&upper, args, n.pos, ctx);
        }
        match self.meaning(&n.text, ctx) {
            Some(Meaning::Function(i)) => self.function_call(i, args, n.pos, ctx),
            Some(Meaning::Local(_) | Meaning::Global(_)) => {
                self.error(pos, format!("`{}` is a function block instance: call it as a statement and read its outputs", n.text))
            }
            // A `TO_<type>` call left unnamed: refused where it was named (`to_type`).
            _ if super::to_type::target(&upper).is_some() => Type::Error,
            _ => self.error(n.pos, format!("unknown function `{}`", n.text)),
        }
    }
}

fn op_name(op: BinOp) -> &'static str {
    use BinOp::*;
    match op {
        Or => "OR",
        Xor => "XOR",
        And => "AND",
        Eq => "`=`",
        Ne => "`<>`",
        Lt => "`<`",
        Gt => "`>`",
        Le => "`<=`",
        Ge => "`>=`",
        Add => "`+`",
        Sub => "`-`",
        Mul => "`*`",
        Div => "`/`",
        Mod => "MOD",
        Pow => "`**`",
        AndThen => "AND_THEN",
        OrElse => "OR_ELSE",
    }
}
