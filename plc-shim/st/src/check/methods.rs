//! METHODs and ACTIONs (TwinCAT 3's, CODESYS 3's) as POUs of their own, run on their
//! function block's instance (their PROGRAM's memory).
//!
//! Before the checker reads the files, each method of a POU `P` becomes a POU `P.M` placed
//! after `P`: `P`'s own variables (the same types in the same order, so at the same
//! offsets; their initial values left to `P`, a CONSTANT's kept), then room for the methods
//! declared before `M`, then `M`'s own variables and its value. `P` itself gets room for
//! every method's variables and value after its own, under names no program can write
//! (`M.x`). So a method's body reads and writes the instance as `P`'s body does, its own
//! variables live in the instance without meeting another method's (a method may call
//! another of the same instance), and a call of `M` is a function call whose frame is the
//! instance: its own variables start from zero and their initial values at every call, as
//! a function's, while `P`'s keep theirs ([`MethodOf`]).
//!
//! An ACTION is a method without variables of its own and without a value.

use super::expr::{Ctx, Meaning};
use super::lower::R;
use super::Type;
use crate::ast::{
    Arg, Expr, Init, Item, Method, Name, Pou, PouKind, Section, TypeRef, Unit, VarBlock, VarDecl,
};
use crate::diag::Pos;
use crate::ir::{Addr, Ex, ThisCall};
use crate::layout::Layout;

/// What makes a POU a method: found by the checker from its name (upper case, `P.M`).
#[derive(Debug, Clone, PartialEq)]
pub struct MethodOf {
    /// The POU it belongs to (index into [`super::Checked::pous`]).
    pub parent: usize,
    /// Its index among the POU's variables where its own begin (the POU's before).
    pub own_from: usize,
    /// Its name as written (`M_Reset`).
    pub name: String,
    /// PRIVATE or PROTECTED: called only from its POU's body and methods.
    pub private: bool,
    /// An ACTION.
    pub action: bool,
}

/// A method as the desugaring found it: its POU's name, its parent's, and what the checker
/// needs beside the variables.
#[derive(Debug, Clone)]
pub(super) struct Found {
    /// The method's POU name in upper case (`FB_AXIS.M_RESET`).
    pub key: String,
    /// Its parent's name in upper case.
    pub parent: String,
    /// Its name as written.
    pub name: Name,
    /// PRIVATE or PROTECTED.
    pub private: bool,
    /// An ACTION.
    pub action: bool,
    /// How many variables of its own it has (its value's slot of a method without a value
    /// counted).
    pub own: usize,
}

/// The name of a method's value slot when it has no value (no name a program can write).
pub(super) const NO_VALUE: &str = "()";

/// The base of a call of a method on the current instance (no name a program can write).
pub(super) const THIS: &str = "THIS^";

/// The files with every method as a POU of its own, and the methods found.
pub(super) fn desugar(files: &[(String, Unit)]) -> (Vec<(String, Unit)>, Vec<Found>) {
    let mut found = Vec::new();
    let out = files
        .iter()
        .map(|(file, unit)| {
            let mut items = Vec::with_capacity(unit.items.len());
            for item in &unit.items {
                match item {
                    Item::Pou(p) if !p.methods.is_empty() => {
                        let (parent, methods) = split(p, &mut found);
                        items.push(Item::Pou(parent));
                        items.extend(methods.into_iter().map(Item::Pou));
                    }
                    other => items.push(other.clone()),
                }
            }
            (file.clone(), Unit { items })
        })
        .collect();
    (out, found)
}

/// POU `p` with room for its methods' variables, and each method as a POU.
fn split(p: &Pou, found: &mut Vec<Found>) -> (Pou, Vec<Pou>) {
    // P's own variables as each method sees them: the initial values are P's to set, once.
    let inherited: Vec<VarBlock> = p.vars.iter().map(without_inits).collect();
    let mut room: Vec<VarBlock> = Vec::new();
    let mut methods = Vec::new();
    for m in &p.methods {
        let own = own_vars(m);
        found.push(Found {
            key: format!("{}.{}", p.name.text, m.name.text).to_ascii_uppercase(),
            parent: p.name.text.to_ascii_uppercase(),
            name: m.name.clone(),
            private: m.private,
            action: m.action,
            own: own
                .iter()
                .map(|b| b.vars.iter().map(|d| d.names.len()).sum::<usize>())
                .sum(),
        });
        let mut vars = inherited.clone();
        vars.extend(room.iter().cloned());
        vars.extend(own.iter().cloned());
        methods.push(Pou {
            kind: PouKind::Method,
            name: Name {
                text: format!("{}.{}", p.name.text, m.name.text),
                pos: m.name.pos,
            },
            returns: m.returns.clone(),
            vars,
            body: m.body.clone(),
            methods: Vec::new(),
        });
        room.extend(hidden(m, &own));
    }
    let mut parent = p.clone();
    parent.methods.clear();
    parent.vars.extend(room);
    (parent, methods)
}

/// A method's own variable sections, with the slot of its value when it has none (where a
/// method with a value keeps it: after its own variables).
fn own_vars(m: &Method) -> Vec<VarBlock> {
    let mut own = m.vars.clone();
    if m.returns.is_none() {
        own.push(slot(
            m.name.pos,
            NO_VALUE.to_string(),
            bool_type(m.name.pos),
        ));
    }
    own
}

/// The room method `m` takes in its POU: its own variables (`own`) under names no program
/// writes, plain VAR without initial values, and its value's slot.
fn hidden(m: &Method, own: &[VarBlock]) -> Vec<VarBlock> {
    let rename = |n: &Name| Name {
        text: format!("{}.{}", m.name.text, n.text),
        pos: n.pos,
    };
    let mut room: Vec<VarBlock> = own
        .iter()
        .map(|b| VarBlock {
            section: Section::Var,
            constant: false,
            retain: false,
            vars: (b.vars.iter())
                .map(|d| VarDecl {
                    names: d.names.iter().map(rename).collect(),
                    ty: d.ty.clone(),
                    init: None,
                })
                .collect(),
            pos: b.pos,
        })
        .collect();
    if let Some(ty) = &m.returns {
        room.push(slot(
            m.name.pos,
            format!("{}.{NO_VALUE}", m.name.text),
            ty.clone(),
        ));
    }
    room
}

fn slot(pos: Pos, text: String, ty: TypeRef) -> VarBlock {
    VarBlock {
        section: Section::Var,
        constant: false,
        retain: false,
        vars: vec![VarDecl {
            names: vec![Name { text, pos }],
            ty,
            init: None,
        }],
        pos,
    }
}

fn bool_type(pos: Pos) -> TypeRef {
    TypeRef::Named(Name {
        text: "BOOL".into(),
        pos,
    })
}

/// A section of the POU's as a method sees it: a CONSTANT keeps its values (the method
/// reads them), the others are the POU's to set.
fn without_inits(b: &VarBlock) -> VarBlock {
    let mut b = b.clone();
    if !b.constant {
        for d in &mut b.vars {
            d.init = None::<Init>;
        }
    }
    b
}

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
    /// method's name wins over a global, a function and a standard or text function of that
    /// name (as in TwinCAT), and nothing that reads calls by name takes it for one of those;
    /// a variable of the caller's hides it.
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
        let key = format!("{}.{}", self.out.pous[owner].name, n.text).to_ascii_uppercase();
        if let Some(super::Named::Pou(m)) = self.names.get(&key) {
            if self.out.pous[*m].method.is_some() {
                let (name, pos) = (n.clone(), n.pos);
                *callee = Expr::Field(
                    Box::new(Expr::Name(Name {
                        text: THIS.into(),
                        pos,
                    })),
                    name,
                );
            }
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
        let key = format!("{}.{}", self.out.pous[owner].name, name.text).to_ascii_uppercase();
        match self.names.get(&key) {
            Some(super::Named::Pou(m)) if self.out.pous[*m].method.is_some() => Some((*m, this)),
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
}

impl super::Checker {
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
}

impl super::Checker {
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
        let key = format!("{}.{}", owner.name, member.text).to_ascii_uppercase();
        let method = matches!(self.names.get(&key), Some(super::Named::Pou(_)));
        if !var && !method {
            let why = format!("`{}` is no member of {} (THIS^)", member.text, owner.name);
            self.refuse(member.pos, why);
        }
        Some(member.clone())
    }
}

impl super::Checker {
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

impl super::Checker {
    /// Every VAR_EXTERNAL names a global of its type (the POU's variable of that name
    /// stands for the global: `Checker::meaning`).
    pub(super) fn check_externals(&mut self, files: &[(String, Unit)]) {
        for p in 0..self.out.pous.len() {
            // A method's are its POU's, checked there.
            if self.out.pous[p].method.is_some() {
                continue;
            }
            for k in 0..self.out.pous[p].vars.len() {
                let v = &self.out.pous[p].vars[k];
                if v.section != Section::External {
                    continue;
                }
                let global = self.globals.get(&v.name.to_ascii_uppercase()).copied();
                let why = match global.map(|g| &self.out.globals[g]) {
                    None => format!("VAR_EXTERNAL `{}`: no global variable of that name", v.name),
                    Some(g) if g.ty != v.ty || g.reference != v.reference => {
                        let (want, got) = (self.type_name(&g.ty), self.type_name(&v.ty));
                        format!("VAR_EXTERNAL `{}` is {got}: the global is {want}", v.name)
                    }
                    Some(_) => continue,
                };
                let pos = v.pos;
                self.file = files
                    .get(self.out.pous[p].file)
                    .map_or_else(String::new, |(n, _)| n.clone());
                self.refuse(pos, why);
            }
        }
    }
}
