//! IEC 61131-3's overloaded conversions `TO_<type>(x)` (TwinCAT 3, CODESYS): each named
//! after the type of its value before the bodies are checked (`TO_LREAL(nCount)` of a DINT is
//! `DINT_TO_LREAL(nCount)`, `TO_STRING(x)` of a REAL `REAL_TO_STRING(x)`, `TO_INT(s)` of a
//! STRING `STRING_TO_INT(s)`), so that every rule of the named conversions holds for them. A
//! value of no elementary type or STRING (an enumeration, a structure), or another count of
//! values, is refused here with its place.

use super::expr::{Ctx, GLOBAL};
use super::{Checker, Named, Type};
use crate::ast::{Arg, Expr, Init, Item, Stmt, Unit};
use crate::types::Elem;

/// The type `TO_<type>` converts to (`STRING` included), `None` for any other name.
pub(super) fn target(upper: &str) -> Option<&str> {
    let to = upper.strip_prefix("TO_")?;
    (to == "STRING" || Elem::named(to).is_some()).then_some(to)
}

impl Checker {
    /// `files` with every `TO_<type>(x)` call named after `x`'s type.
    pub(super) fn name_conversions(&mut self, files: &[(String, Unit)]) -> super::Files {
        let mut out = files.to_vec();
        for (file, unit) in &mut out {
            self.file = file.clone();
            for item in &mut unit.items {
                match item {
                    Item::Pou(p) => {
                        let upper = p.name.text.to_ascii_uppercase();
                        let Some(Named::Pou(pou)) = self.names.get(&upper).cloned() else {
                            continue;
                        };
                        let ctx = Ctx { pou, loops: 0 };
                        self.calls_from = pou;
                        for d in p.vars.iter_mut().flat_map(|b| b.vars.iter_mut()) {
                            if let Some(init) = &mut d.init {
                                self.name_in_init(init, ctx);
                            }
                        }
                        self.name_in_block(&mut p.body, ctx);
                    }
                    Item::Globals(block) => {
                        for d in &mut block.vars {
                            if let Some(init) = &mut d.init {
                                self.name_in_init(init, GLOBAL);
                            }
                        }
                    }
                    Item::Types(_) => {}
                }
            }
        }
        out
    }

    fn name_in_init(&mut self, init: &mut Init, ctx: Ctx) {
        match init {
            Init::Expr(e) => self.name_in(e, ctx),
            Init::Array(values) => {
                for (count, v) in values {
                    if let Some(c) = count {
                        self.name_in(c, ctx);
                    }
                    self.name_in_init(v, ctx);
                }
            }
            Init::Struct(fields) => {
                for (_, v) in fields {
                    self.name_in_init(v, ctx);
                }
            }
        }
    }

    fn name_in_block(&mut self, body: &mut [Stmt], ctx: Ctx) {
        for s in body {
            self.name_in_stmt(s, ctx);
        }
    }

    fn name_in_stmt(&mut self, s: &mut Stmt, ctx: Ctx) {
        match s {
            Stmt::Assign { target, value } => {
                if let Some(member) = self.this_member(target, ctx) {
                    *target = Expr::Name(member);
                }
                match self.bind_reference(target, value, ctx) {
                    Some(false) => {}
                    Some(true) => self.name_in(value, ctx),
                    None => {
                        self.name_in(target, ctx);
                        self.name_in(value, ctx);
                    }
                }
            }
            Stmt::Call(e) => self.name_in(e, ctx),
            Stmt::If {
                branches,
                otherwise,
            } => {
                for (cond, body) in branches {
                    self.name_in(cond, ctx);
                    self.name_in_block(body, ctx);
                }
                self.name_in_block(otherwise.as_deref_mut().unwrap_or_default(), ctx);
            }
            Stmt::Case {
                selector,
                arms,
                otherwise,
            } => {
                self.name_in(selector, ctx);
                for (_, body) in arms {
                    self.name_in_block(body, ctx);
                }
                self.name_in_block(otherwise.as_deref_mut().unwrap_or_default(), ctx);
            }
            Stmt::For {
                from, to, by, body, ..
            } => {
                for e in [Some(from), Some(to), by.as_mut()].into_iter().flatten() {
                    self.name_in(e, ctx);
                }
                self.name_in_block(body, ctx);
            }
            Stmt::While { cond, body } | Stmt::Repeat { body, until: cond } => {
                self.name_in(cond, ctx);
                self.name_in_block(body, ctx);
            }
            Stmt::Exit(_) | Stmt::Continue(_) | Stmt::Return(_) => {}
        }
    }

    /// Names the calls in `e`, the innermost first (their types are the outer ones' values').
    fn name_in(&mut self, e: &mut Expr, ctx: Ctx) {
        let mut itself = None;
        // `THIS^.x` in a function block's (a program's) body or methods: its own `x` (a
        // method's variables may not take its POU's names, so nothing hides it).
        if let Some(member) = self.this_member(e, ctx) {
            *e = Expr::Name(member);
        }
        // A REFERENCE TO's use: `r` is `r^` (`check::reference`).
        if self.reference_use(e, ctx) {
            return;
        }
        match e {
            // A typed literal's value is a literal or an enumeration's value, no variable.
            Expr::Typed { .. } => {}
            Expr::Field(base, _) | Expr::Deref(base, _) | Expr::Unary(_, base, _) => {
                self.name_in(base, ctx)
            }
            Expr::Index(base, indices, _) => {
                self.name_in(base, ctx);
                indices.iter_mut().for_each(|i| self.name_in(i, ctx));
            }
            Expr::Binary(_, a, b, _) => {
                self.name_in(a, ctx);
                self.name_in(b, ctx);
            }
            Expr::Call { callee, args, .. } => {
                // An instance's place may hold calls too (`fbs[TO_INT(r)](..)`).
                self.name_in(callee, ctx);
                self.own_method_callee(callee, ctx);
                for arg in args.iter_mut() {
                    match arg {
                        Arg::Positional(v) | Arg::Input(_, v) => self.name_in(v, ctx),
                        Arg::Output { target, .. } => self.name_in(target, ctx),
                    }
                }
                // UPPER_BOUND / LOWER_BOUND of an array: the constant bound itself.
                if let Some(bound) = self.array_bound(callee, args, ctx) {
                    itself = Some(Expr::Int(i128::from(bound), callee.pos()));
                }
                // TO_STRING of a STRING: the STRING itself.
                if self.name_call(callee, args, ctx) {
                    if let [Arg::Positional(v)] = &args[..] {
                        itself = Some(v.clone());
                    }
                }
            }
            Expr::Int(..)
            | Expr::Real(..)
            | Expr::Bool(..)
            | Expr::Str(..)
            | Expr::Time(..)
            | Expr::Name(_) => {}
        }
        if let Some(v) = itself {
            *e = v;
        }
    }

    /// `TO_<type>(x)` named `<x's type>_TO_<type>`; another count of values refused. `true`
    /// for a call that is its value itself (TO_STRING of a STRING).
    fn name_call(&mut self, callee: &mut Expr, args: &[Arg], ctx: Ctx) -> bool {
        let Expr::Name(n) = callee else {
            return false;
        };
        let upper = n.text.to_ascii_uppercase();
        // A variable of that name (an instance called) is not the conversion.
        let Some(to) = target(&upper).filter(|_| self.meaning(&n.text, ctx).is_none()) else {
            return false;
        };
        let [Arg::Positional(value)] = args else {
            let message = format!("{} takes one value, by position", n.text);
            self.refuse(n.pos, message);
            return false;
        };
        // The value's type: its errors are the checks' to report when the call is named
        // (they check it again), here when it is not (the call is refused as it stands).
        let errors = self.errors.len();
        let ty = self.expr(value, ctx);
        if !matches!(ty, Type::Error) {
            self.errors.truncate(errors);
        }
        let from = match ty {
            Type::Elem(e) => e.name(),
            Type::Str(_) if to == "STRING" => return true,
            Type::Str(_) => "STRING",
            Type::Error => return false,
            other => {
                let found = self.type_name(&other);
                let message = format!(
                    "{} of a {found}: it converts a value of an elementary type or a STRING",
                    n.text
                );
                self.refuse(value.pos(), message);
                return false;
            }
        };
        n.text = format!("{from}_TO_{to}");
        false
    }
}
