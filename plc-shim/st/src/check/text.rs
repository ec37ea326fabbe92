//! The string functions of IEC 61131-3 (LEN, LEFT, RIGHT, MID, CONCAT, INSERT, DELETE,
//! REPLACE, FIND), the conversions to and from STRING (`INT_TO_STRING`, `STRING_TO_LREAL`,
//! ...) and the ordering of STRINGs: their types for the checker and their lowering into
//! [`crate::ir::Text`] and [`crate::ir::TextEx`]. The runtime computes them in
//! `vm::text`, without allocating.

use super::expr::{literal, Ctx};
use super::lower::R;
use super::{Checker, Type};
use crate::ast::{Arg, BinOp, Expr};
use crate::diag::Pos;
use crate::ir::{Ex, Text, TextEx, TextFn, MAX_TEXT};
use crate::layout::Layout;
use crate::types::Elem;

/// The string functions by name (reserved as the standard functions are).
pub const TEXT_FUNCTIONS: &[&str] = &[
    "LEN", "LEFT", "RIGHT", "MID", "CONCAT", "INSERT", "DELETE", "REPLACE", "FIND",
];

/// The most values a CONCAT takes.
const MAX_CONCAT: usize = 16;

/// What a value of string function `name` takes: for each value, whether it is a STRING
/// (else an integer); `None` for a name that is no string function.
fn signature(name: &str) -> Option<&'static [bool]> {
    Some(match name {
        "LEN" => &[true],
        "LEFT" | "RIGHT" => &[true, false],
        "MID" | "DELETE" => &[true, false, false],
        "INSERT" => &[true, true, false],
        "REPLACE" => &[true, true, false, false],
        "FIND" => &[true, true],
        _ => return None,
    })
}

/// The conversion of a name to or from STRING: the other type, and whether it goes to STRING.
pub(super) fn text_conversion(upper: &str) -> Option<(Elem, bool)> {
    let (from, to) = upper.split_once("_TO_")?;
    match (from, to) {
        ("STRING", t) => Elem::named(t).map(|e| (e, false)),
        (f, "STRING") => Elem::named(f).map(|e| (e, true)),
        _ => None,
    }
}

/// The most characters a value of `t` takes as text ([`crate::vm`]'s format).
pub(super) fn text_len(t: Elem) -> u32 {
    use Elem::*;
    match t {
        Bool => 5,
        USInt | Byte => 3,
        SInt => 4,
        UInt | Word => 5,
        Int => 6,
        UDInt | DWord => 10,
        DInt => 11,
        LInt | ULInt | LWord => 20,
        Real | LReal => 40,
        Time => 24,
        LTime => 48,
    }
}

/// The length of a STRING of `n` plus `m` characters, as long as a computed STRING may be.
fn joined(n: u32, m: u32) -> u32 {
    (n + m).min(MAX_TEXT as u32)
}

impl Checker {
    /// The type of a call of a string function or a conversion to or from STRING, `None` for
    /// a call that is neither.
    pub(super) fn text_call_type(
        &mut self,
        upper: &str,
        args: &[Arg],
        pos: Pos,
        ctx: Ctx,
    ) -> Option<Type> {
        let values = super::expr::positional(args);
        if let Some((t, to_text)) = text_conversion(upper) {
            return Some(self.text_conversion_type(upper, (t, to_text), args, pos, ctx));
        }
        let concat = upper == "CONCAT";
        let wants = signature(upper);
        if !concat && wants.is_none() {
            return None;
        }
        if values.len() != args.len() {
            return Some(self.error(pos, format!("{upper} takes its values by position")));
        }
        let counted = match wants {
            Some(w) => w.len() == values.len(),
            None => (2..=MAX_CONCAT).contains(&values.len()),
        };
        if !counted {
            let message = match wants {
                Some(w) => format!("{upper} takes {} values", w.len()),
                None => format!("CONCAT takes 2 to {MAX_CONCAT} values"),
            };
            return Some(self.error(pos, message));
        }
        let mut lengths = Vec::new();
        for (k, v) in values.iter().enumerate() {
            let text = wants.is_none_or(|w| w[k]);
            match (text, self.expr(v, ctx)) {
                (_, Type::Error) => return Some(Type::Error),
                (true, Type::Str(n)) => lengths.push(n),
                // Computed in LINT: a 64-bit unsigned value would not fit.
                (false, Type::Elem(e))
                    if e.is_integer() && !matches!(e, Elem::ULInt | Elem::LWord) => {}
                (true, t) => {
                    let found = self.type_name(&t);
                    return Some(self.error(
                        v.pos(),
                        format!("{upper} takes a STRING here, not a {found}"),
                    ));
                }
                (false, t) => {
                    let found = self.type_name(&t);
                    return Some(self.error(
                        v.pos(),
                        format!("{upper} takes an integer of at most 63 bits here, not a {found}"),
                    ));
                }
            }
        }
        Some(match upper {
            "LEN" | "FIND" => Type::Elem(Elem::Int),
            "CONCAT" | "INSERT" | "REPLACE" => {
                Type::Str(lengths.iter().fold(0, |a, n| joined(a, *n)).max(1))
            }
            _ => Type::Str(lengths[0]),
        })
    }

    /// The type of a conversion to STRING (`to_text`) or from it.
    fn text_conversion_type(
        &mut self,
        upper: &str,
        (t, to_text): (Elem, bool),
        args: &[Arg],
        pos: Pos,
        ctx: Ctx,
    ) -> Type {
        let values = super::expr::positional(args);
        let [v] = values[..] else {
            return self.error(pos, format!("{upper} takes one value"));
        };
        if args.len() != 1 {
            return self.error(pos, format!("{upper} takes its value by position"));
        }
        match (to_text, self.expr(v, ctx)) {
            (_, Type::Error) => Type::Error,
            (true, _)
                if literal(v)
                    .is_some_and(|x| t.range().is_some_and(|(lo, hi)| !(lo..=hi).contains(&x))) =>
            {
                let x = literal(v).unwrap_or_default();
                self.error(v.pos(), format!("{x} does not fit a {}", t.name()))
            }
            (true, Type::Elem(e)) if e == t || e.widens_to(t) || literal(v).is_some() => {
                Type::Str(text_len(t))
            }
            (false, Type::Str(_)) => Type::Elem(t),
            (_, found) => {
                let want = if to_text { t.name() } else { "STRING" };
                let found = self.type_name(&found);
                self.error(v.pos(), format!("{upper} takes a {want}, not a {found}"))
            }
        }
    }

    /// A STRING operand: a literal's bytes, a variable's place, or a string function's
    /// result.
    pub(super) fn text_ir(&mut self, e: &Expr, ctx: Ctx, l: &Layout) -> R<Text> {
        if let Expr::Str(text, pos) = e {
            let n = text.chars().count().max(1) as u32;
            let bytes = self.literal_bytes(text, n, *pos)?;
            return Ok(Text::Const(bytes.into_boxed_slice()));
        }
        if let Some(f) = self.text_fn_ir(e, ctx, l)? {
            return Ok(Text::Fn(Box::new(f)));
        }
        match self.place(e, ctx, l)? {
            (at, Type::Str(n)) => Ok(Text::At(at, n + 1)),
            _ => Err(self.unsupported(e.pos(), "this value as a STRING")),
        }
    }

    /// Whether `e` is a call of a string function or a conversion to STRING.
    pub(super) fn is_text_fn(e: &Expr) -> bool {
        let Expr::Call { callee, .. } = e else {
            return false;
        };
        let Expr::Name(n) = &**callee else {
            return false;
        };
        let upper = n.text.to_ascii_uppercase();
        TEXT_FUNCTIONS.contains(&upper.as_str())
            || text_conversion(&upper).is_some_and(|(_, to)| to)
    }

    /// Whether `e` is a computed STRING: a call of a string function, of a conversion to
    /// STRING, or of a user function whose value is a STRING.
    pub(super) fn is_text_value(&self, e: &Expr, ctx: Ctx) -> bool {
        let number = matches!(e, Expr::Call { callee, .. }
            if matches!(&**callee, Expr::Name(n)
                if ["LEN", "FIND"].iter().any(|f| n.text.eq_ignore_ascii_case(f))));
        (Self::is_text_fn(e) && !number) || self.text_function(e, ctx).is_some()
    }

    /// The user function `e` calls and the length of its STRING value, `None` if `e` is no
    /// call of a function whose value is a STRING.
    fn text_function(&self, e: &Expr, ctx: Ctx) -> Option<(usize, u32)> {
        let Expr::Call { callee, .. } = e else {
            return None;
        };
        let Expr::Name(n) = &**callee else {
            return None;
        };
        if Self::is_text_fn(e) {
            return None;
        }
        match self.meaning(&n.text, ctx) {
            Some(super::expr::Meaning::Function(i)) => match self.out.pous[i].returns {
                Some(Type::Str(len)) => Some((i, len)),
                _ => None,
            },
            _ => None,
        }
    }

    /// A string function whose value is a STRING, `None` if `e` is no such call.
    fn text_fn_ir(&mut self, e: &Expr, ctx: Ctx, l: &Layout) -> R<Option<TextFn>> {
        let Expr::Call { callee, args, pos } = e else {
            return Ok(None);
        };
        if let Some((i, len)) = self.text_function(e, ctx) {
            let call = self.function_call_ir(i, args, *pos, ctx, l)?;
            return Ok(Some(TextFn::Call(call, len + 1)));
        }
        if !Self::is_text_fn(e) {
            return Ok(None);
        }
        let Expr::Name(n) = &**callee else {
            return Ok(None);
        };
        let upper = n.text.to_ascii_uppercase();
        let v = super::expr::positional(args);
        if let Some((t, true)) = text_conversion(&upper) {
            return Ok(Some(TextFn::Of(t, self.value_as(v[0], t, ctx, l)?)));
        }
        let int = |c: &mut Self, k: usize| c.value_as(v[k], Elem::LInt, ctx, l);
        Ok(Some(match upper.as_str() {
            "CONCAT" => TextFn::Concat(
                v.iter()
                    .map(|x| self.text_ir(x, ctx, l))
                    .collect::<R<Vec<_>>>()?,
            ),
            "LEFT" => TextFn::Left(self.text_ir(v[0], ctx, l)?, int(self, 1)?),
            "RIGHT" => TextFn::Right(self.text_ir(v[0], ctx, l)?, int(self, 1)?),
            "MID" => TextFn::Mid(self.text_ir(v[0], ctx, l)?, int(self, 1)?, int(self, 2)?),
            "DELETE" => TextFn::Delete(self.text_ir(v[0], ctx, l)?, int(self, 1)?, int(self, 2)?),
            "INSERT" => {
                let (a, b) = (self.text_ir(v[0], ctx, l)?, self.text_ir(v[1], ctx, l)?);
                TextFn::Insert(a, b, int(self, 2)?)
            }
            "REPLACE" => {
                let (a, b) = (self.text_ir(v[0], ctx, l)?, self.text_ir(v[1], ctx, l)?);
                TextFn::Replace(a, b, int(self, 2)?, int(self, 3)?)
            }
            // LEN and FIND are numbers: `text_value_ir`.
            _ => return Ok(None),
        }))
    }

    /// LEN, FIND or a conversion from STRING as a value, `None` if `upper` is none of them.
    pub(super) fn text_value_ir(
        &mut self,
        upper: &str,
        args: &[&Expr],
        ctx: Ctx,
        l: &Layout,
    ) -> R<Option<Ex>> {
        let e = match (upper, text_conversion(upper)) {
            (_, Some((t, false))) => TextEx::To(t, self.text_ir(args[0], ctx, l)?),
            ("LEN", _) => TextEx::Len(self.text_ir(args[0], ctx, l)?),
            ("FIND", _) => TextEx::Find(
                self.text_ir(args[0], ctx, l)?,
                self.text_ir(args[1], ctx, l)?,
            ),
            _ => return Ok(None),
        };
        Ok(Some(Ex::Text(Box::new(e))))
    }

    /// An ordering of two STRINGs (`<`, `>`, `<=`, `>=`).
    pub(super) fn text_order_ir(
        &mut self,
        op: BinOp,
        (a, b): (&Expr, &Expr),
        ctx: Ctx,
        l: &Layout,
    ) -> R<Ex> {
        let (x, y) = (self.text_ir(a, ctx, l)?, self.text_ir(b, ctx, l)?);
        Ok(Ex::Text(Box::new(TextEx::Cmp(op, x, y))))
    }
}
