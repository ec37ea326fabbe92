//! The standard functions' values as the lowering computes them: the type their values
//! are computed in, and a call of literals in the type it meets.

use super::expr::Ctx;
use super::lower::R;
use super::{Checker, Type};
use crate::ast::{Arg, Expr, Name};
use crate::diag::Pos;
use crate::ir::{Ex, StdFn};
use crate::layout::Layout;
use crate::types::Elem;

impl Checker {
    pub(super) fn std_value(
        &mut self,
        f: StdFn,
        n: &Name,
        args: &[&Expr],
        ctx: Ctx,
        l: &Layout,
    ) -> R<Ex> {
        if matches!(f, StdFn::MemCpy | StdFn::MemSet) {
            let what = format!("{}'s value (call it as a statement)", n.text);
            return Err(self.unsupported(n.pos, &what));
        }
        self.std_ex(f, n, args, ctx, l)
    }

    /// A function called as a statement, its value dropped (MEMCPY, MEMMOVE and MEMSET are
    /// called only so).
    pub(super) fn statement_value(&mut self, call: &Expr, ctx: Ctx, l: &Layout) -> R<Ex> {
        if let Expr::Call { callee, args, .. } = call {
            if let Expr::Name(n) = &**callee {
                let f = std_fn(&n.text.to_ascii_uppercase());
                if let Some(f @ (StdFn::MemCpy | StdFn::MemSet)) = f {
                    return self.std_ex(f, n, &super::expr::positional(args), ctx, l);
                }
            }
        }
        self.value(call, ctx, l)
    }

    fn std_ex(&mut self, f: StdFn, n: &Name, args: &[&Expr], ctx: Ctx, l: &Layout) -> R<Ex> {
        let Type::Elem(result) = self.expr(
            &Expr::Call {
                callee: Box::new(Expr::Name(n.clone())),
                args: args.iter().map(|a| Arg::Positional((*a).clone())).collect(),
                pos: n.pos,
            },
            ctx,
        ) else {
            return Err(self.unsupported(n.pos, "this standard function's values"));
        };
        if args.len() > crate::ir::MAX_STD_VALUES {
            return Err(self.unsupported(n.pos, "a standard function of more than 16 values"));
        }
        // The type the values are computed in.
        let within = match f {
            StdFn::Trunc => Elem::LReal,
            _ => result,
        };
        let mut values = Vec::with_capacity(args.len());
        for (k, a) in args.iter().enumerate() {
            let selector = matches!(f, StdFn::Sel | StdFn::Mux) && k == 0;
            let shift = matches!(f, StdFn::Shl | StdFn::Shr | StdFn::Rol | StdFn::Ror) && k == 1;
            let exponent = f == StdFn::Expt && k == 1;
            values.push(match (selector, shift) {
                (true, _) | (_, true) => self.value_as(a, Elem::LInt, ctx, l)?,
                // An integer exponent: its own value, as a real.
                _ if exponent => match self.expr(a, ctx) {
                    Type::Elem(e) if e != within => {
                        let v = self.value_as(a, e, ctx, l)?;
                        Ex::Conv(e, within, Box::new(v))
                    }
                    _ => self.value_as(a, within, ctx, l)?,
                },
                _ => self.value_as(a, within, ctx, l)?,
            });
        }
        let v = Ex::Std(f, within, values);
        Ok(if within == result {
            v
        } else {
            Ex::Conv(within, result, Box::new(v))
        })
    }

    /// A [`super::expr::literal_call`] computed in the type `to` its literals fit: the
    /// selector as any other's, the literals as `to`'s.
    pub(super) fn literal_call_value(
        &mut self,
        (f, at): (&str, Pos),
        values: &[&Expr],
        to: Elem,
        ctx: Ctx,
        l: &Layout,
    ) -> R<Ex> {
        let f = std_fn(f).ok_or_else(|| self.unsupported(at, "this call"))?;
        if values.len() > crate::ir::MAX_STD_VALUES {
            return Err(self.unsupported(at, "a standard function of more than 16 values"));
        }
        let mut out = Vec::with_capacity(values.len());
        for (k, v) in values.iter().enumerate() {
            let selector = matches!(f, StdFn::Sel | StdFn::Mux) && k == 0;
            out.push(if selector {
                self.value_as(v, Elem::LInt, ctx, l)?
            } else {
                self.value_as(v, to, ctx, l)?
            });
        }
        Ok(Ex::Std(f, to, out))
    }
}

/// The standard function of an upper-case name.
pub(super) fn std_fn(upper: &str) -> Option<StdFn> {
    Some(match upper {
        "ABS" => StdFn::Abs,
        "SQRT" => StdFn::Sqrt,
        "LN" => StdFn::Ln,
        "LOG" => StdFn::Log,
        "EXP" => StdFn::Exp,
        "SIN" => StdFn::Sin,
        "COS" => StdFn::Cos,
        "TAN" => StdFn::Tan,
        "ASIN" => StdFn::Asin,
        "ACOS" => StdFn::Acos,
        "ATAN" => StdFn::Atan,
        "MIN" => StdFn::Min,
        "MAX" => StdFn::Max,
        "LIMIT" => StdFn::Limit,
        "SEL" => StdFn::Sel,
        "MUX" => StdFn::Mux,
        "TRUNC" | "TRUNC_INT" => StdFn::Trunc,
        "SHL" => StdFn::Shl,
        "SHR" => StdFn::Shr,
        "ROL" => StdFn::Rol,
        "ROR" => StdFn::Ror,
        "EXPT" => StdFn::Expt,
        "MOVE" => StdFn::Move,
        "TIME" | "LTIME" => StdFn::Now,
        "MEMCPY" | "MEMMOVE" => StdFn::MemCpy,
        "MEMSET" => StdFn::MemSet,
        "MEMCMP" => StdFn::MemCmp,
        _ => return None,
    })
}
