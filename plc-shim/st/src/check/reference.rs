//! REFERENCE TO (TwinCAT 3, CODESYS 3): a variable that stands for another, bound with
//! `r REF= x;` and read and written without `^` (`r := 5;` writes `x`, `r.field`,
//! `__ISVALIDREF(r)` tells whether it is bound). It is a pointer underneath: before the
//! bodies are checked, every use of a reference becomes `r^`, `REF=` stores `ADR(x)`, and
//! `__ISVALIDREF(r)` compares the pointer with 0; so an unbound reference faults where it is
//! read or written, as a NULL pointer does.
//!
//! A reference is a variable of a POU or a global one; as an input, an output, a
//! VAR_IN_OUT, inside an array or a structure, as a CONSTANT or with an initial value it is
//! refused by name, and so is one bound to a VAR_IN_OUT (a copy of the caller's variable
//! for the call here). `r2 REF= r1` copies the pointer (what r1 stands for, bound or not).

use super::expr::{Ctx, Meaning};
use super::{Checker, Type};
use crate::ast::{Arg, BinOp, Expr, Name, Section, TypeRef, VarDecl};
use crate::diag::Pos;

/// The callee the parser gives `REF=`'s value (a name no program can write).
const BIND: &str = "REF=";

impl Checker {
    /// The type of declaration `d` in section `section`, and whether it declares references.
    pub(super) fn decl_type(
        &mut self,
        d: &VarDecl,
        (section, constant): (Section, bool),
    ) -> (Type, bool) {
        let TypeRef::Reference(inner, pos) = &d.ty else {
            return (self.type_of(&d.ty, 0), false);
        };
        if constant {
            self.refuse(*pos, "a REFERENCE TO is no CONSTANT: REF= binds it");
        }
        if matches!(section, Section::Input | Section::Output | Section::InOut) {
            self.refuse(
                *pos,
                "a REFERENCE TO input, output or VAR_IN_OUT is not supported: a VAR_IN_OUT \
                 of the type itself passes the caller's variable",
            );
            return (Type::Error, false);
        }
        if d.init.is_some() {
            self.refuse(
                *pos,
                "a REFERENCE TO has no initial value: bind it with REF=",
            );
        }
        (Type::Pointer(Box::new(self.type_of(inner, 0))), true)
    }

    /// Whether `name` is a reference where `ctx` reads it.
    fn is_reference(&self, name: &str, ctx: Ctx) -> bool {
        match self.meaning(name, ctx) {
            Some(Meaning::Local(i)) => self.out.pous[ctx.pou].vars[i].reference,
            Some(Meaning::Global(g)) => self.out.globals[g].reference,
            _ => false,
        }
    }

    /// `e` as a reference's use reads it: `r` is `r^`, `__ISVALIDREF(r)` is `r <> 0`.
    /// `true` when `e` was one (and is rewritten).
    pub(super) fn reference_use(&mut self, e: &mut Expr, ctx: Ctx) -> bool {
        match e {
            Expr::Name(n) if self.is_reference(&n.text, ctx) => {
                let pos = n.pos;
                *e = Expr::Deref(Box::new(e.clone()), pos);
                true
            }
            Expr::Call { callee, args, pos } if is_named(callee, "__ISVALIDREF") => {
                let pos = *pos;
                if let [Arg::Positional(a)] = &mut args[..] {
                    if let Some(member) = self.this_member(a, ctx) {
                        *a = Expr::Name(member);
                    }
                }
                let [Arg::Positional(Expr::Name(r))] = &args[..] else {
                    self.refuse(pos, "__ISVALIDREF takes a REFERENCE TO variable");
                    return true;
                };
                if !self.is_reference(&r.text, ctx) {
                    let why = format!("__ISVALIDREF of `{}`, which is no REFERENCE TO", r.text);
                    self.refuse(r.pos, why);
                }
                let zero = Box::new(Expr::Int(0, pos));
                *e = Expr::Binary(BinOp::Ne, Box::new(Expr::Name(r.clone())), zero, pos);
                true
            }
            _ => false,
        }
    }

    /// `target REF= x;` (the parser's `target := REF=(x)`): `target := ADR(x)` of a
    /// reference `target` (which is not read through); `target := r` of a reference `r`
    /// (what it stands for, unbound or not: the pointer copied). `None` when the statement
    /// is none; `Some(true)` when its value is still to be named as any value is.
    pub(super) fn bind_reference(
        &mut self,
        target: &Expr,
        value: &mut Expr,
        ctx: Ctx,
    ) -> Option<bool> {
        let Expr::Call { callee, args, .. } = value else {
            return None;
        };
        if !is_named(callee, BIND) {
            return None;
        }
        let bound = matches!(target, Expr::Name(n) if self.is_reference(&n.text, ctx));
        if !bound {
            self.refuse(target.pos(), "REF= binds a REFERENCE TO variable");
        }
        if let [Arg::Positional(Expr::Name(r))] = &args[..] {
            if bound && self.is_reference(&r.text, ctx) {
                *value = Expr::Name(r.clone());
                return Some(false);
            }
        }
        let Expr::Call { callee, pos, .. } = value else {
            return None;
        };
        // `x` is named as any value is, after this.
        **callee = Expr::Name(Name {
            text: "ADR".into(),
            pos: *pos,
        });
        Some(true)
    }
}

impl Checker {
    /// `r := ADR(x)` as `r REF= x` leaves it (the only way a reference's own name is
    /// assigned): `x` must be a variable of the type `r` stands for, refused in a
    /// reference's words. `false` when `target` is no reference's own name.
    pub(super) fn check_binding(&mut self, target: &Expr, value: &Expr, ctx: Ctx) -> bool {
        let Expr::Name(r) = target else {
            return false;
        };
        if !self.is_reference(&r.text, ctx) {
            return false;
        }
        let Type::Pointer(want) = self.expr(target, ctx) else {
            return true;
        };
        let x = match value {
            Expr::Call { args, .. } => match &args[..] {
                [Arg::Positional(x)] => x,
                _ => return true,
            },
            // `r2 REF= r1`: the pointer copied.
            Expr::Name(_) => {
                let got = self.expr(value, ctx);
                if got != Type::Pointer(want.clone()) && got != Type::Error {
                    let (w, g) = (self.type_name(&want), self.type_name(&got));
                    let why = format!("REF= binds a REFERENCE TO {w}, not a {g}");
                    self.refuse(value.pos(), why.replace("POINTER TO", "REFERENCE TO"));
                }
                return true;
            }
            _ => return true,
        };
        if self.in_out_root(x, ctx) {
            let why = "REF= of a VAR_IN_OUT: here it is a copy of the caller's variable for the \
                       call, so a reference to it would outlive it; bind the caller's variable";
            self.refuse(x.pos(), why);
            return true;
        }
        let place = matches!(
            x,
            Expr::Name(_) | Expr::Field(..) | Expr::Index(..) | Expr::Deref(..)
        );
        let errors = self.errors.len();
        let got = self.expr(x, ctx);
        if !place {
            self.errors.truncate(errors);
            let w = self.type_name(&want);
            let why = format!("REF= binds a REFERENCE TO {w} to a variable, not a value");
            self.refuse(x.pos(), why);
        } else if got != *want && got != Type::Error {
            let (w, g) = (self.type_name(&want), self.type_name(&got));
            let why =
                format!("REF= binds a REFERENCE TO {w} to a variable of that type, not a {g}");
            self.refuse(x.pos(), why);
        } else {
            // ADR's own checks (no instance, a variable).
            self.expr(value, ctx);
        }
        true
    }
}

impl Checker {
    /// Whether place `e` lies in a VAR_IN_OUT of the POU `ctx` is in (copied in and back
    /// around each call here, so its address is the copy's).
    pub(super) fn in_out_root(&self, e: &Expr, ctx: Ctx) -> bool {
        let mut e = e;
        loop {
            match e {
                Expr::Field(base, _) | Expr::Index(base, ..) => e = base,
                Expr::Name(n) => {
                    return match self.meaning(&n.text, ctx) {
                        Some(Meaning::Local(i)) => {
                            self.out.pous[ctx.pou].vars[i].section == Section::InOut
                        }
                        _ => false,
                    };
                }
                _ => return false,
            }
        }
    }
}

fn is_named(callee: &Expr, name: &str) -> bool {
    matches!(callee, Expr::Name(n) if n.text.eq_ignore_ascii_case(name))
}

/// `REF=`'s value as the parser gives it: a call no program can write.
pub(crate) fn bind(value: Expr, pos: Pos) -> Expr {
    Expr::Call {
        callee: Box::new(Expr::Name(Name {
            text: BIND.into(),
            pos,
        })),
        args: vec![Arg::Positional(value)],
        pos,
    }
}
