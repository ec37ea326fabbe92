//! Array and structure initialisers (`[1, 2, 3(0)]`, `(x := 1.5, y := 2.0)`), nested as the
//! types are: checked against the variable's type (every value assignable, the fields named,
//! no more values than elements), and lowered to one store per value, run once at load. A
//! repetition count is a constant; an initialiser gives at most [`MAX_INIT_VALUES`] values.
//! A function block instance takes the same form for its inputs (`fbDelay : TON := (PT :=
//! T#2S);`, as TwinCAT and CODESYS write it): they are stored after the block's own initial
//! values (`vm::init`), so the instance's win. A library block's instance is refused one
//! (`vm::library`): its host takes its inputs from its calls.

use super::expr::Ctx;
use super::lower::R;
use super::{Checker, Type};
use crate::ast::Init;
use crate::diag::{Diagnostic, Pos};
use crate::ir::{Addr, StKind};
use crate::layout::Layout;

/// The most values one initialiser gives (repetitions counted).
pub const MAX_INIT_VALUES: u64 = 1 << 16;

impl Checker {
    /// `init` against a variable of type `ty` declared at `pos`.
    pub(super) fn check_init(&mut self, init: &Init, ty: &Type, pos: Pos, ctx: Ctx) {
        let values = self.check_init_in(init, ty, pos, ctx);
        if values > MAX_INIT_VALUES {
            let most = MAX_INIT_VALUES;
            self.refuse(pos, format!("an initialiser of more than {most} values"));
        }
    }

    /// `init` checked; how many values it gives (repetitions and nesting multiplied,
    /// saturating).
    fn check_init_in(&mut self, init: &Init, ty: &Type, pos: Pos, ctx: Ctx) -> u64 {
        match (init, ty) {
            (Init::Expr(e), _) => {
                self.assignable(e, ty, ctx);
                1
            }
            (Init::Array(items), Type::Array(dims, element)) => {
                let total = dims
                    .iter()
                    .fold(1u64, |n, (lo, hi)| n.saturating_mul(hi.abs_diff(*lo) + 1));
                let (mut given, mut values) = (0u64, 0u64);
                for (count, item) in items {
                    let times = match count {
                        None => Some(1),
                        Some(c) => self.const_int(c).and_then(|n| u64::try_from(n).ok()),
                    };
                    let Some(times) = times else {
                        let at = count.as_ref().map_or(pos, |c| c.pos());
                        self.refuse(at, "a repetition count is a constant of 0 or more");
                        return 0;
                    };
                    given = given.saturating_add(times);
                    let each = self.check_init_in(item, element, pos, ctx);
                    values = values.saturating_add(times.saturating_mul(each));
                }
                if given > total {
                    self.refuse(pos, format!("{given} initial values for {total} elements"));
                }
                values
            }
            (Init::Struct(fields), Type::Struct(i)) => {
                let mut values = 0u64;
                for (name, item) in fields {
                    let found = self.out.structs[*i]
                        .fields
                        .iter()
                        .find(|(f, _)| f.eq_ignore_ascii_case(&name.text))
                        .map(|(_, t)| t.clone());
                    match found {
                        Some(t) => {
                            let each = self.check_init_in(item, &t, name.pos, ctx);
                            values = values.saturating_add(each);
                        }
                        None => {
                            let s = self.out.structs[*i].name.clone();
                            self.refuse(name.pos, format!("{s} has no field `{}`", name.text));
                        }
                    }
                }
                values
            }
            (Init::Struct(fields), Type::Fb(_) | Type::StdFb(_)) => {
                let mut values = 0u64;
                for (name, item) in fields {
                    if let Some(t) = self.fb_input(ty, name) {
                        let each = self.check_init_in(item, &t, name.pos, ctx);
                        values = values.saturating_add(each);
                    }
                }
                if let Type::Fb(i) = ty {
                    self.fb_inits.push((*i, self.file.clone(), pos));
                }
                values
            }
            (_, Type::Error) => 0,
            (Init::Array(_), _) => {
                let t = self.type_name(ty);
                self.refuse(pos, format!("an array initialiser for a {t}"));
                0
            }
            (Init::Struct(_), _) => {
                let t = self.type_name(ty);
                self.refuse(pos, format!("a structure initialiser for a {t}"));
                0
            }
        }
    }

    /// The stores of `init` into `addr`, a place of type `ty` (checked already).
    pub(super) fn lower_init_value(
        &mut self,
        addr: Addr,
        ty: &Type,
        init: &Init,
        (ctx, l): (Ctx, &Layout),
        out: &mut Vec<StKind>,
    ) -> R<()> {
        match (init, ty) {
            (Init::Expr(e), _) => out.push(self.lower_store(addr, ty.clone(), e, ctx, l)?),
            (Init::Array(items), Type::Array(_, element)) => {
                let (size, align) = l.size_align(&self.out, element);
                let stride = size.div_ceil(align) * align;
                let mut k = 0u32;
                for (count, item) in items {
                    let times = count.as_ref().and_then(|c| self.const_int(c)).unwrap_or(1);
                    for _ in 0..times {
                        let at = super::place::plus(addr.clone(), k * stride);
                        self.lower_init_value(at, element, item, (ctx, l), out)?;
                        k += 1;
                    }
                }
            }
            (Init::Struct(fields), Type::Fb(_) | Type::StdFb(_)) => {
                for (name, item) in fields {
                    let (offset, t) = self.member(ty, name, l)?;
                    let at = super::place::plus(addr.clone(), offset);
                    self.lower_init_value(at, &t, item, (ctx, l), out)?;
                }
            }
            (Init::Struct(fields), Type::Struct(i)) => {
                for (name, item) in fields {
                    let def = &self.out.structs[*i];
                    let k = def
                        .fields
                        .iter()
                        .position(|(f, _)| f.eq_ignore_ascii_case(&name.text))
                        .ok_or_else(|| Diagnostic::new(name.pos, "no such field"))?;
                    let t = def.fields[k].1.clone();
                    let at = super::place::plus(addr.clone(), l.structs[*i].2[k]);
                    self.lower_init_value(at, &t, item, (ctx, l), out)?;
                }
            }
            _ => {
                return Err(Diagnostic::new(
                    Pos::default(),
                    "an initialiser of this type",
                ))
            }
        }
        Ok(())
    }

    /// The type of input `name` of a function block instance of type `ty`, or a refusal
    /// naming what it is instead.
    fn fb_input(&mut self, ty: &Type, name: &crate::ast::Name) -> Option<Type> {
        let block = self.type_name(ty);
        let found = match ty {
            Type::StdFb(fb) => fb
                .member(&name.text)
                .map(|(_, t, input)| (Type::Elem(t), input)),
            Type::Fb(i) => (self.out.pous[*i].vars.iter())
                .find(|v| v.name.eq_ignore_ascii_case(&name.text))
                .map(|v| (v.ty.clone(), v.section == super::Section::Input)),
            _ => None,
        };
        match found {
            Some((t, true)) => Some(t),
            Some(_) => {
                let why = format!(
                    "`{}` is no input of {block}: an instance's declaration gives initial values to its inputs",
                    name.text
                );
                self.refuse(name.pos, why);
                None
            }
            None => {
                self.refuse(name.pos, format!("{block} has no input `{}`", name.text));
                None
            }
        }
    }
}
