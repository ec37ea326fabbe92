//! Calls of METHODs and ACTIONs (`check::methods` makes each a POU of its own): which
//! method a call names, its typing and its lowering as a function call whose frame is the
//! instance, `THIS^`.

use super::expr::{Ctx, Meaning};
use super::lower::R;
use super::methods::{Found, MethodOf, THIS};
use super::Type;
use crate::ast::{Arg, Expr, Name, PouKind, Unit};
use crate::diag::Pos;
use crate::ir::{Addr, Ex, ThisCall};
use crate::layout::Layout;

impl super::Checker {
    /// Each method found bound to its POU; a method's variables of types its POU's room
    /// for them does not have (a bound naming the method's own constant), or a method named
    /// as a variable of its POU, refused.
    pub(super) fn bind_methods(&mut self, found: &[Found], files: &[(String, Unit)]) {
        use super::Named;
        for f in found {
            let (Some(Named::Pou(i)), Some(Named::Pou(parent))) = (
                self.names.get(&f.key).cloned(),
                self.names.get(&f.parent).cloned(),
            ) else {
                continue;
            };
            self.file = files
                .get(self.out.pous[i].file)
                .map_or_else(String::new, |(n, _)| n.clone());
            let own_from = self.out.pous[i].vars.len().saturating_sub(f.own);
            self.out.pous[i].method = Some(MethodOf {
                parent,
                own_from,
                name: f.name.text.clone(),
                private: f.private,
                action: f.action,
            });
            let pou = &self.out.pous[i];
            let mine: Vec<&super::Type> =
                pou.vars.iter().map(|v| &v.ty).chain(&pou.returns).collect();
            let theirs: Vec<&super::Type> =
                self.out.pous[parent].vars.iter().map(|v| &v.ty).collect();
            let refused = mine.iter().chain(&theirs).any(|t| **t == Type::Error);
            if !refused && theirs.get(..mine.len()) != Some(&mine[..]) {
                self.refuse(
                    f.name.pos,
                    "a method's variable whose type names the method's own constant is not \
                     supported: declare the constant in its POU",
                );
            }
            let upper = f.name.text.to_ascii_uppercase();
            let operator = super::std_lib::FUNCTIONS.contains(&upper.as_str())
                || crate::types::conversion(&upper).is_some()
                || super::to_type::target(&upper).is_some();
            if operator {
                let why = format!(
                    "`{}` is an operator of the language: a method takes another name",
                    f.name.text
                );
                self.refuse(f.name.pos, why);
            }
            let taken = (self.out.pous[parent].vars.iter())
                .any(|v| v.name.eq_ignore_ascii_case(&f.name.text));
            if taken {
                let why = format!("`{}` names a variable and a method", f.name.text);
                self.refuse(f.name.pos, why);
            }
        }
    }

    /// The POU (a function block or a program) whose body or method `pou` is.
    pub(super) fn family(&self, pou: usize) -> Option<usize> {
        let p = self.out.pous.get(pou)?;
        match (&p.method, p.kind) {
            (Some(m), _) => Some(m.parent),
            (None, PouKind::FunctionBlock | PouKind::Program) => Some(pou),
            _ => None,
        }
    }

    /// `M` of a call `M(..)` in its POU's body or methods, made `THIS^.M(..)` (the base a
    /// name no program writes, [`THIS`]) before the bodies are checked: inside its POU a
    /// method's name wins over a global function and a text function of that name (as in
    /// TwinCAT; an operator's name is no method's, `bind_methods`), and nothing that reads
    /// calls by name takes it for one of those; a variable of the caller's hides it.
    pub(super) fn own_method_callee(&mut self, callee: &mut Expr, ctx: Ctx) {
        let Expr::Name(n) = callee else {
            return;
        };
        let Some(owner) = self.family(ctx.pou) else {
            return;
        };
        if matches!(self.meaning(&n.text, ctx), Some(Meaning::Local(_))) {
            return;
        }
        if self.method_named(owner, &n.text).is_some() {
            let (name, pos) = (n.clone(), n.pos);
            let this = Expr::Name(Name {
                text: THIS.into(),
                pos,
            });
            *callee = Expr::Field(Box::new(this), name);
        }
    }

    /// The method `callee` calls, if it names one: `THIS^.M(..)` ([`Checker::own_method_callee`])
    /// in its POU's body or methods, `fb.M(..)` of an instance of its function block. Its
    /// POU index and whether it is called on the current instance.
    pub(super) fn method_of(&mut self, callee: &Expr, ctx: Ctx) -> Option<(usize, bool)> {
        let (owner, name, this) = match callee {
            Expr::Field(base, n) if matches!(&**base, Expr::Name(t) if t.text == THIS) => {
                (self.family(ctx.pou)?, n, true)
            }
            Expr::Field(base, n) => {
                let errors = self.errors.len();
                let ty = self.expr(base, ctx);
                self.errors.truncate(errors);
                match ty {
                    Type::Fb(f) => (f, n, false),
                    _ => return None,
                }
            }
            _ => return None,
        };
        self.method_named(owner, &name.text).map(|m| (m, this))
    }

    /// Method `name` of POU `owner` (its POU index, `check::methods`' `P.M`).
    fn method_named(&self, owner: usize, name: &str) -> Option<usize> {
        let key = format!("{}.{}", self.out.pous[owner].name, name).to_ascii_uppercase();
        match self.names.get(&key) {
            Some(super::Named::Pou(m)) if self.out.pous[*m].method.is_some() => Some(*m),
            _ => None,
        }
    }

    /// A call of method `m` (`method_of`), typed as a function's; as a statement (its
    /// value dropped) or as a value (a method without one refused). A PRIVATE or PROTECTED
    /// method is called from its POU's body and methods only.
    pub(super) fn method_call(
        &mut self,
        m: usize,
        call: (&[Arg], Pos),
        ctx: Ctx,
        value: bool,
    ) -> Type {
        let (args, pos) = call;
        let Some(of) = self.out.pous[m].method.clone() else {
            return Type::Error;
        };
        if of.private && self.family(ctx.pou) != Some(of.parent) {
            let owner = self.out.pous[of.parent].name.clone();
            return self.error(pos, format!("`{}` is PRIVATE to {owner}", of.name));
        }
        let t = self.function_call(m, args, pos, ctx);
        match (&self.out.pous[m].returns, value) {
            (None, true) => {
                let what = if of.action {
                    "an ACTION"
                } else {
                    "a method without a value"
                };
                self.error(
                    pos,
                    format!("`{}` is {what}: call it as a statement", of.name),
                )
            }
            (None, false) => Type::Elem(crate::types::Elem::Bool),
            _ => t,
        }
    }

    /// A call of method `m` as a value (as a statement, a method without one reads its
    /// slot, which nobody uses): `callee` names the instance, or the current one (`this`).
    pub(super) fn method_value(
        &mut self,
        m: usize,
        (callee, this): (&Expr, bool),
        args: &[Arg],
        ctx: Ctx,
        l: &Layout,
    ) -> R<Ex> {
        let (Some(of), pos) = (self.out.pous[m].method.clone(), callee.pos()) else {
            return Err(self.unsupported(callee.pos(), "this call"));
        };
        let instance = match callee {
            Expr::Field(base, _) if !this => self.place(base, ctx, l)?.0,
            _ if self.out.pous[of.parent].kind == PouKind::FunctionBlock => Addr::Instance(0),
            _ => Addr::Static(l.statics[of.parent]),
        };
        if crate::vm::callees::addr_calls(&instance) {
            let what = "a method of an instance at an index a function computes";
            return Err(self.unsupported(pos, what));
        }
        let (offsets, types) = (&l.pous[m].2, &self.out.pous[m]);
        let start = offsets.get(of.own_from).copied();
        // The end of its last slot (its value's): not the POU's size, whose padding may
        // hold a later method's first variable.
        let last = types
            .returns
            .clone()
            .or_else(|| types.vars.last().map(|v| v.ty.clone()));
        let at = offsets.last().copied().unwrap_or(0);
        let end = at + last.map_or(0, |t| l.size_align(&self.out, &t).0);
        let value_ty = match &self.out.pous[m].returns {
            Some(Type::Elem(t)) => *t,
            None => crate::types::Elem::Bool,
            Some(_) => {
                return Err(self.unsupported(pos, "a method whose value is no elementary value"))
            }
        };
        let mut call = self.function_call_ir(m, args, pos, ctx, l)?;
        call.value = Addr::Offset(Box::new(instance.clone()), at);
        call.this = Some(ThisCall {
            instance,
            own: (start.unwrap_or(end), end),
            value: at,
        });
        Ok(Ex::Call(Box::new(call), value_ty))
    }

    /// `x` of `THIS^.x` where the POU `ctx` is in has an instance (no variable is called
    /// THIS there); an `x` that is neither a variable nor a method of the instance is
    /// refused (it would be read as a global or a method's own variable).
    pub(super) fn this_member(&mut self, e: &Expr, ctx: Ctx) -> Option<Name> {
        let Expr::Field(base, member) = e else {
            return None;
        };
        let Expr::Deref(this, _) = &**base else {
            return None;
        };
        let Expr::Name(n) = &**this else {
            return None;
        };
        let family = self
            .family(ctx.pou)
            .filter(|_| n.text.eq_ignore_ascii_case("THIS"));
        let family = family.filter(|_| self.meaning(&n.text, ctx).is_none())?;
        let owner = &self.out.pous[family];
        let var = (owner.vars.iter())
            .any(|v| !v.name.contains('.') && v.name.eq_ignore_ascii_case(&member.text));
        if !var && self.method_named(family, &member.text).is_none() {
            let owner = &self.out.pous[family];
            let why = format!("`{}` is no member of {} (THIS^)", member.text, owner.name);
            self.refuse(member.pos, why);
        }
        Some(member.clone())
    }

    /// Why `callee` (no name) is no call to make: SUPER^, a program's method from outside,
    /// a method its block does not have.
    pub(super) fn no_method(&mut self, callee: &Expr, ctx: Ctx) -> String {
        let Expr::Field(base, m) = callee else {
            return "only functions and methods are called in an expression".into();
        };
        if let Expr::Deref(b, _) = &**base {
            if matches!(&**b, Expr::Name(n) if n.text.eq_ignore_ascii_case("SUPER")) {
                return "`SUPER^` is not supported: a function block has no EXTENDS here".into();
            }
        }
        if let Expr::Name(n) = &**base {
            let program = match self.names.get(&n.text.to_ascii_uppercase()) {
                Some(super::Named::Pou(i)) => self.out.pous[*i].kind == PouKind::Program,
                _ => false,
            };
            if program && self.meaning(&n.text, ctx).is_none() {
                return format!(
                    "`{}.{}`: a PROGRAM's methods and actions are called inside it only",
                    n.text, m.text
                );
            }
        }
        let errors = self.errors.len();
        let ty = self.expr(base, ctx);
        self.errors.truncate(errors);
        match ty {
            Type::Fb(f) => format!("{} has no method `{}`", self.out.pous[f].name, m.text),
            _ => "only functions and methods are called in an expression".into(),
        }
    }
}
