//! Statements, assignments and calls: targets that can be written, conditions that are BOOL,
//! loops and their EXIT, CASE labels against the selector, the arguments of functions and
//! function blocks (the standard functions' in `std_type`), and recursion refused.

use super::expr::{literal, literal_fits, Ctx, Meaning};
use super::{Checker, Type};
use crate::ast::{Arg, CaseLabel, Expr, Name, Pou, Section, Stmt};
use crate::diag::Pos;
use crate::types::Elem;

const BOOL: Type = Type::Elem(Elem::Bool);

impl Checker {
    pub(super) fn check_pou(&mut self, p: &Pou) {
        let Some(super::Named::Pou(pou)) =
            self.names.get(&p.name.text.to_ascii_uppercase()).cloned()
        else {
            return;
        };
        let ctx = Ctx { pou, loops: 0 };
        self.calls_from = pou;
        // Its own constants first (an initialiser's repetition count).
        self.consts.scope = Some(p.name.text.to_ascii_uppercase());
        self.initial_values(p, ctx);
        self.consts.scope = None;
        self.statements(&p.body, ctx);
    }

    /// The initial values of the POU's variables against their types (expressions, array
    /// and structure initialisers).
    fn initial_values(&mut self, p: &Pou, ctx: Ctx) {
        for block in &p.vars {
            for d in &block.vars {
                let (Some(init), Some(first)) = (&d.init, d.names.first()) else {
                    continue;
                };
                let ty = self.out.pous[ctx.pou]
                    .vars
                    .iter()
                    .find(|v| v.name == first.text)
                    .map(|v| v.ty.clone());
                if let Some(ty) = ty {
                    self.check_init(init, &ty, first.pos, ctx);
                }
            }
        }
    }

    fn statements(&mut self, body: &[Stmt], ctx: Ctx) {
        for s in body {
            self.statement(s, ctx);
        }
    }

    fn statement(&mut self, s: &Stmt, ctx: Ctx) {
        let in_loop = Ctx {
            loops: ctx.loops + 1,
            ..ctx
        };
        match s {
            Stmt::Assign { target, value } => self.assign(target, value, ctx),
            Stmt::Call(call) => self.call_statement(call, ctx),
            Stmt::If {
                branches,
                otherwise,
            } => {
                for (cond, body) in branches {
                    self.condition(cond, ctx);
                    self.statements(body, ctx);
                }
                self.statements(otherwise.as_deref().unwrap_or(&[]), ctx);
            }
            Stmt::Case {
                selector,
                arms,
                otherwise,
            } => self.case(selector, arms, otherwise.as_deref(), ctx),
            Stmt::For {
                var,
                from,
                to,
                by,
                body,
            } => {
                let target = Expr::Name(var.clone());
                match self.writable(&target, ctx) {
                    Some(Type::Elem(e)) if e.is_integer() => {
                        for bound in [Some(from), Some(to), by.as_ref()].into_iter().flatten() {
                            self.assignable(bound, &Type::Elem(e), ctx);
                        }
                    }
                    Some(Type::Error) | None => {}
                    Some(_) => self.refuse(var.pos, "a FOR variable is an integer"),
                }
                self.statements(body, in_loop);
            }
            Stmt::While { cond, body } => {
                self.condition(cond, ctx);
                self.statements(body, in_loop);
            }
            Stmt::Repeat { body, until } => {
                self.statements(body, in_loop);
                self.condition(until, ctx);
            }
            Stmt::Exit(pos) | Stmt::Continue(pos) if ctx.loops == 0 => {
                self.refuse(*pos, "EXIT and CONTINUE belong in a loop");
            }
            Stmt::Exit(_) | Stmt::Continue(_) | Stmt::Return(_) => {}
        }
    }

    fn condition(&mut self, cond: &Expr, ctx: Ctx) {
        match self.expr(cond, ctx) {
            BOOL | Type::Error => {}
            t => {
                let found = self.type_name(&t);
                self.refuse(cond.pos(), format!("a condition is BOOL, not {found}"));
            }
        }
    }

    /// `value` where a `want` is wanted: the same type, one that widens to it, or a literal
    /// that fits.
    pub(super) fn assignable(&mut self, value: &Expr, want: &Type, ctx: Ctx) {
        let got = self.expr(value, ctx);
        if got == Type::Error || *want == Type::Error || got == *want {
            return;
        }
        let fits = match (&got, want) {
            (Type::Elem(g), Type::Elem(w)) => g.widens_to(*w) || literal_fits(value, *w),
            (Type::Str(_), Type::Str(_)) => true,
            // ADR of an array goes to a pointer to its elements, as in TwinCAT (`ADR(aRows)`
            // to a POINTER TO LREAL: the first element's address).
            // Any pointer goes to a POINTER TO BYTE (PVOID: an untyped address, as an
            // MC_CAM_REF's pArray takes `ADR(aTable)`).
            (Type::Pointer(a), Type::Pointer(b)) => {
                a == b || (is_adr(value) && element(a) == &**b) || **b == Type::Elem(Elem::Byte)
            }
            _ => false,
        };
        if !fits {
            let (g, w) = (self.type_name(&got), self.type_name(want));
            let message = match (literal(value), want) {
                (Some(v), Type::Elem(e)) if e.is_integer() => format!("{v} does not fit {w}"),
                _ => format!("{g} where {w} is wanted"),
            };
            self.refuse(value.pos(), message);
        }
    }

    /// The type of a place that may be written, or a refusal.
    fn writable(&mut self, target: &Expr, ctx: Ctx) -> Option<Type> {
        match target {
            Expr::Name(n) => match self.meaning(&n.text, ctx) {
                Some(Meaning::Local(i)) => {
                    let v = &self.out.pous[ctx.pou].vars[i];
                    let (constant, ty) = (v.constant, v.ty.clone());
                    if constant {
                        self.refuse(n.pos, format!("`{}` is a CONSTANT", n.text));
                    }
                    Some(ty)
                }
                Some(Meaning::Global(i)) => {
                    let v = &self.out.globals[i];
                    let (constant, ty) = (v.constant, v.ty.clone());
                    if constant {
                        self.refuse(n.pos, format!("`{}` is a CONSTANT", n.text));
                    }
                    Some(ty)
                }
                Some(Meaning::Return(t)) => Some(t),
                _ => Some(self.expr(target, ctx)),
            },
            Expr::Field(base, _) if self.reads_an_instance(base, ctx) => {
                self.refuse(
                    target.pos(),
                    "an instance's inputs are set in its call, its outputs only read",
                );
                None
            }
            Expr::Field(..) if self.cnc_owned(target, ctx).is_some() => {
                let field = self.cnc_owned(target, ctx).unwrap_or_default();
                let message = format!("`{field}` of the image is written by the CNC (or the drives): the PLC only reads it");
                self.refuse(target.pos(), message);
                None
            }
            Expr::Field(..) | Expr::Index(..) | Expr::Deref(..) => Some(self.expr(target, ctx)),
            _ => {
                self.refuse(
                    target.pos(),
                    "only a variable, a field, an element or `p^` is written",
                );
                None
            }
        }
    }

    /// The name of the first field along `target` that the CNC or the drives write in the
    /// image (the HLI's units keep their writers: `hli::st_prelude::field_writers`).
    fn cnc_owned(&mut self, target: &Expr, ctx: Ctx) -> Option<String> {
        match target {
            Expr::Field(base, field) => {
                let errors = self.errors.len();
                let base_type = self.expr(base, ctx);
                self.errors.truncate(errors);
                if let Type::Struct(i) = base_type {
                    if image_writer_is_cnc(&self.out.structs[i].name, &field.text) {
                        return Some(field.text.clone());
                    }
                }
                self.cnc_owned(base, ctx)
            }
            Expr::Index(base, _, _) => self.cnc_owned(base, ctx),
            _ => None,
        }
    }

    fn reads_an_instance(&mut self, base: &Expr, ctx: Ctx) -> bool {
        let errors = self.errors.len();
        let t = self.expr(base, ctx);
        self.errors.truncate(errors);
        matches!(t, Type::Fb(_) | Type::StdFb(_))
    }

    /// Whether `ty` holds a function block instance (itself, in an array or a structure).
    pub(super) fn holds_instance(&self, ty: &Type, depth: usize) -> bool {
        match ty {
            Type::Fb(_) | Type::StdFb(_) => true,
            Type::Array(_, element) if depth < 16 => self.holds_instance(element, depth + 1),
            Type::Struct(i) if depth < 16 => self.out.structs[*i]
                .fields
                .iter()
                .any(|(_, t)| self.holds_instance(t, depth + 1)),
            _ => false,
        }
    }

    /// Whether `e` is a place in or holding a function block instance (ADR of it refused).
    pub(super) fn instance_place(&mut self, e: &Expr, ctx: Ctx) -> bool {
        let errors = self.errors.len();
        let t = self.expr(e, ctx);
        // A field or element anywhere below an instance (`fb.Point.MasterPos`).
        let (mut inside, mut place) = (false, e);
        while let Expr::Field(base, _) | Expr::Index(base, ..) = place {
            inside |= self.reads_an_instance(base, ctx);
            place = base;
        }
        self.errors.truncate(errors);
        inside || self.holds_instance(&t, 0)
    }

    fn assign(&mut self, target: &Expr, value: &Expr, ctx: Ctx) {
        // `r REF= x` (`check::reference`).
        if self.check_binding(target, value, ctx) {
            return;
        }
        if let Some(want) = self.writable(target, ctx) {
            match want {
                Type::Fb(_) | Type::StdFb(_) => {
                    self.refuse(target.pos(), "a function block instance is not assigned")
                }
                Type::Array(..) | Type::Struct(_) if self.holds_instance(&want, 0) => {
                    // An instance's state is its block's (a library block's outputs are
                    // written by the block alone).
                    self.refuse(target.pos(), "function block instances are not copied")
                }
                Type::Array(..) | Type::Struct(_) => {
                    // Whole arrays and structures of the same type copy.
                    let got = self.expr(value, ctx);
                    if got != want && got != Type::Error {
                        let (g, w) = (self.type_name(&got), self.type_name(&want));
                        self.refuse(value.pos(), format!("{g} where {w} is wanted"));
                    }
                }
                _ => self.assignable(value, &want, ctx),
            }
        }
    }

    fn case(
        &mut self,
        selector: &Expr,
        arms: &[(Vec<CaseLabel>, Vec<Stmt>)],
        otherwise: Option<&[Stmt]>,
        ctx: Ctx,
    ) {
        let t = self.expr(selector, ctx);
        let ok = matches!(&t, Type::Elem(e) if e.is_integer())
            || matches!(t, Type::Enum(_) | Type::Error);
        if !ok {
            let found = self.type_name(&t);
            self.refuse(
                selector.pos(),
                format!("a CASE selector is an integer or an enumeration, not {found}"),
            );
        }
        for (labels, body) in arms {
            for label in labels {
                let values = match label {
                    CaseLabel::Value(v) => vec![v],
                    CaseLabel::Range(a, b) => vec![a, b],
                };
                for v in values {
                    if !self.is_label(v, ctx) {
                        self.refuse(
                            v.pos(),
                            "a CASE label is a literal or an enumeration's value",
                        );
                    } else if ok {
                        self.assignable(v, &t, ctx);
                    }
                }
            }
            self.statements(body, ctx);
        }
        self.statements(otherwise.unwrap_or(&[]), ctx);
    }

    /// Whether `v` may label a CASE arm: a literal (typed or not) or an enumeration's value.
    fn is_label(&self, v: &Expr, ctx: Ctx) -> bool {
        match v {
            Expr::Typed { .. } => true,
            Expr::Name(n) => matches!(self.meaning(&n.text, ctx), Some(Meaning::EnumValue(_))),
            Expr::Field(base, _) => matches!(&**base, Expr::Name(n)
                if matches!(self.meaning(&n.text, ctx), Some(Meaning::EnumType(_)))),
            _ => literal(v).is_some(),
        }
    }

    /// A call as a statement: a function block instance, or a function whose value is
    /// dropped.
    fn call_statement(&mut self, call: &Expr, ctx: Ctx) {
        let Expr::Call { callee, args, pos } = call else {
            return;
        };
        let errors = self.errors.len();
        let instance = self.expr(callee, ctx);
        match instance {
            Type::Fb(i) => {
                self.errors.truncate(errors);
                self.record_call(i, *pos);
                let params: Vec<(String, Type, Section)> = self.out.pous[i]
                    .vars
                    .iter()
                    .filter(|v| {
                        matches!(v.section, Section::Input | Section::Output | Section::InOut)
                    })
                    .map(|v| (v.name.clone(), v.ty.clone(), v.section))
                    .collect();
                self.named_args(args, &params, *pos, ctx);
            }
            Type::StdFb(fb) => {
                self.errors.truncate(errors);
                let params: Vec<(String, Type, Section)> = fb
                    .members()
                    .iter()
                    .map(|(n, t, input)| {
                        let section = if *input {
                            Section::Input
                        } else {
                            Section::Output
                        };
                        (n.to_string(), Type::Elem(*t), section)
                    })
                    .collect();
                self.named_args(args, &params, *pos, ctx);
            }
            _ => {
                self.errors.truncate(errors);
                match self.method_of(callee, ctx) {
                    Some((m, _)) => {
                        self.method_call(m, (args, *pos), ctx, false);
                    }
                    None => {
                        self.expr(call, ctx);
                    }
                }
            }
        }
    }

    /// `Input := value` and `Output => target` against a block's parameters.
    fn named_args(&mut self, args: &[Arg], params: &[(String, Type, Section)], pos: Pos, ctx: Ctx) {
        let find = |name: &str| params.iter().find(|(n, _, _)| n.eq_ignore_ascii_case(name));
        for arg in args {
            match arg {
                Arg::Input(name, value) => match find(&name.text) {
                    Some((_, t, Section::Input)) => self.assignable(value, t, ctx),
                    // Copied in before the call and back after it: a place that may be written.
                    Some((_, t, Section::InOut)) => {
                        if let Some(place) = self.writable(value, ctx) {
                            if place != *t {
                                let (g, w) = (self.type_name(&place), self.type_name(t));
                                self.refuse(value.pos(), format!("a {g} for a VAR_IN_OUT of {w}"));
                            }
                        }
                    }
                    Some(_) => self.refuse(
                        name.pos,
                        format!("`{}` is an output: `{} =>`", name.text, name.text),
                    ),
                    None => self.refuse(name.pos, format!("no input `{}`", name.text)),
                },
                Arg::Output {
                    name,
                    target,
                    negated,
                } => match find(&name.text) {
                    Some((_, t, Section::Output)) => {
                        let t = t.clone();
                        self.output_binding(&t, (name, target, *negated), ctx);
                    }
                    Some(_) => self.refuse(
                        name.pos,
                        format!("`{}` is an input: `{} :=`", name.text, name.text),
                    ),
                    None => self.refuse(name.pos, format!("no output `{}`", name.text)),
                },
                Arg::Positional(v) => {
                    self.refuse(
                        v.pos(),
                        "a function block's inputs are named: `Name := value`",
                    );
                }
            }
        }
        let _ = pos;
    }

    /// A user function's call: its inputs by position or name, its value.
    pub(super) fn function_call(&mut self, i: usize, args: &[Arg], pos: Pos, ctx: Ctx) -> Type {
        self.record_call(i, pos);
        // Its parameters in their order: inputs, and VAR_IN_OUTs (a variable of their type).
        let params = self.parameters(i);
        let inputs: Vec<(String, Type, Section)> = params
            .iter()
            .map(|k| &self.out.pous[i].vars[*k])
            .map(|v| (v.name.clone(), v.ty.clone(), v.section))
            .collect();
        let name = self.out.pous[i].name.clone();
        let positional = args
            .iter()
            .filter(|a| matches!(a, Arg::Positional(_)))
            .count();
        if positional > inputs.len() {
            self.refuse(
                pos,
                format!("{name} takes {} inputs, not {positional}", inputs.len()),
            );
        }
        let mut given = vec![false; inputs.len()];
        for (k, arg) in args.iter().enumerate() {
            let found = self.parameter_of(i, &params, arg, k);
            let (v, at) = match arg {
                Arg::Positional(v)
                    if args[..k].iter().any(|a| !matches!(a, Arg::Positional(_))) =>
                {
                    self.refuse(v.pos(), "a value by position after a named one: name it");
                    continue;
                }
                Arg::Positional(v) => (v, v.pos()),
                Arg::Input(n, v) => {
                    if found.is_none() {
                        self.refuse(n.pos, format!("{name} has no input `{}`", n.text));
                    }
                    (v, n.pos)
                }
                Arg::Output {
                    name: n,
                    target,
                    negated,
                } => {
                    let var = self.output_var(i, &n.text);
                    match var.map(|k| self.out.pous[i].vars[k].ty.clone()) {
                        Some(t @ Type::Elem(_)) => {
                            self.output_binding(&t, (n, target, *negated), ctx)
                        }
                        Some(_) => self.refuse(
                            n.pos,
                            format!(
                                "{name}: an output that is no elementary value (`{}`)",
                                n.text
                            ),
                        ),
                        _ => self.refuse(n.pos, format!("{name} has no output `{}`", n.text)),
                    }
                    continue;
                }
            };
            if let Some(p) = found {
                let (param_name, t, section) = inputs[p].clone();
                if std::mem::replace(&mut given[p], true) {
                    self.refuse(at, format!("{name}: `{param_name}` is given twice"));
                }
                self.parameter(v, &t, section, ctx);
            }
        }
        // A VAR_IN_OUT has no value of its own: every call names the variable.
        for ((param, _, section), given) in inputs.iter().zip(given) {
            if *section == Section::InOut && !given {
                self.refuse(
                    pos,
                    format!("{name}: its VAR_IN_OUT `{param}` must be given"),
                );
            }
        }
        self.out.pous[i].returns.clone().unwrap_or(Type::Error)
    }

    /// `name => target` of an output of type `t`: a place its value widens to (NOT of a BOOL
    /// output only).
    fn output_binding(
        &mut self,
        t: &Type,
        (name, target, negated): (&Name, &Expr, bool),
        ctx: Ctx,
    ) {
        if negated && *t != BOOL {
            self.refuse(name.pos, "NOT of an output that is not BOOL");
        }
        if let Some(want) = self.writable(target, ctx) {
            let widens = match (t, &want) {
                (Type::Elem(a), Type::Elem(b)) => a.widens_to(*b),
                (Type::Str(m), Type::Str(k)) => k >= m,
                _ => false,
            };
            if want != *t && !widens {
                let (g, w) = (self.type_name(t), self.type_name(&want));
                self.refuse(target.pos(), format!("a {g} output into a {w}"));
            }
        }
    }

    /// A function's parameter of type `t`: a value for an input, a variable of its own type
    /// for a VAR_IN_OUT (copied in before the call and back after it).
    fn parameter(&mut self, v: &Expr, t: &Type, section: Section, ctx: Ctx) {
        if section != Section::InOut {
            return self.assignable(v, t, ctx);
        }
        if let Some(place) = self.writable(v, ctx) {
            if place != *t {
                let (g, w) = (self.type_name(&place), self.type_name(t));
                self.refuse(v.pos(), format!("a {g} for a VAR_IN_OUT of {w}"));
            }
        }
    }

    /// Notes that the POU being checked calls POU `callee` (for the recursion check).
    fn record_call(&mut self, callee: usize, pos: Pos) {
        let caller = self.calls_from;
        if caller == callee || self.reaches(callee, caller) {
            let name = self.out.pous[callee].name.clone();
            self.refuse(
                pos,
                format!(
                    "{name} calls itself (directly or through others): recursion is not allowed"
                ),
            );
            return;
        }
        self.call_graph.push((caller, callee));
    }

    /// Whether `from` calls `to` through the calls seen so far.
    fn reaches(&self, from: usize, to: usize) -> bool {
        let mut stack = vec![from];
        let mut seen = vec![false; self.out.pous.len()];
        while let Some(p) = stack.pop() {
            if p == to {
                return true;
            }
            if std::mem::replace(&mut seen[p], true) {
                continue;
            }
            stack.extend(
                self.call_graph
                    .iter()
                    .filter(|(a, _)| *a == p)
                    .map(|(_, b)| *b),
            );
        }
        false
    }
}

/// Whether field `field` of the image's structure `name` is written by the CNC or the drives.
fn image_writer_is_cnc(name: &str, field: &str) -> bool {
    use hli::desc::SymbolWriter;
    use std::collections::HashSet;
    static CNC: std::sync::OnceLock<HashSet<(String, String)>> = std::sync::OnceLock::new();
    let owned = CNC.get_or_init(|| {
        hli::st_prelude::field_writers()
            .into_iter()
            .filter(|(_, _, w)| matches!(w, SymbolWriter::Cnc | SymbolWriter::Io))
            .map(|(s, f, _)| (s.to_ascii_uppercase(), f.to_ascii_uppercase()))
            .collect()
    });
    owned.contains(&(name.to_ascii_uppercase(), field.to_ascii_uppercase()))
}

/// Whether `e` is a call of ADR.
fn is_adr(e: &Expr) -> bool {
    matches!(e, Expr::Call { callee, .. }
        if matches!(&**callee, Expr::Name(n) if n.text.eq_ignore_ascii_case("ADR")))
}

/// The innermost element type of an array (`t` itself for anything else).
fn element(t: &Type) -> &Type {
    match t {
        Type::Array(_, e) => element(e),
        other => other,
    }
}
