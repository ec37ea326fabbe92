//! Lowering: a checked program into [`crate::ir`], every name a place in memory, every
//! operation typed. It runs after the checker found nothing, so it asks the checker for the
//! types of subexpressions instead of working them out again; what the runtime does not do
//! yet (strings in expressions) is refused here with its place.

use super::expr::{literal, Ctx, Meaning};
use super::place::{deref, plus, strides};
use super::std_value::std_fn;
use super::{Checker, Type};
use crate::ast::{Arg, BinOp, CaseLabel, Expr, Name, Pou, PouKind, Stmt, UnOp};
use crate::diag::{Diagnostic, Pos};
use crate::ir::{Addr, Ex, St, StKind, StdFn, TextEx};
use crate::layout::{std_member, Layout};
use crate::types::{conversion, Class, Elem};
use crate::vm::callees::addr_calls;

pub(super) type R<T> = Result<T, Diagnostic>;

/// A POU's initial values, and where those of its variables holding instances begin.
type Inits = (Vec<St>, usize);

impl Checker {
    pub(super) fn unsupported(&self, pos: Pos, what: &str) -> Diagnostic {
        Diagnostic::new(pos, format!("{what} is not supported by the runtime yet"))
            .in_file(&self.file)
    }

    /// POU `p` (file `file`): its index, the stores of its variables' initial values, its
    /// statements.
    pub(super) fn lower_pou(
        &mut self,
        p: &Pou,
        file: u16,
        layout: &Layout,
    ) -> R<(usize, Inits, Vec<St>)> {
        let Some(super::Named::Pou(pou)) =
            self.names.get(&p.name.text.to_ascii_uppercase()).cloned()
        else {
            return Err(
                Diagnostic::new(p.name.pos, "a POU the checker did not see").in_file(&self.file)
            );
        };
        let ctx = Ctx { pou, loops: 0 };
        let (mut inits, mut late) = (Vec::new(), Vec::new());
        for block in &p.vars {
            for d in &block.vars {
                self.lower_init(d, ctx, file, layout, (&mut inits, &mut late))?;
            }
        }
        let body = self.lower_block(&p.body, ctx, file, layout)?;
        let split = inits.len();
        inits.extend(late);
        Ok((pou, (inits, split), body))
    }

    /// The global variables' initial values, as stores in declaration order (the runtime
    /// runs them once, before the programs' own).
    pub(super) fn lower_global_inits(
        &mut self,
        unit: &crate::ast::Unit,
        file: u16,
        l: &Layout,
    ) -> R<(Vec<St>, Vec<St>)> {
        let (mut out, mut late) = (Vec::new(), Vec::new());
        for item in &unit.items {
            let crate::ast::Item::Globals(block) = item else {
                continue;
            };
            for d in &block.vars {
                self.lower_init(d, super::expr::GLOBAL, file, l, (&mut out, &mut late))?;
            }
        }
        Ok((out, late))
    }

    /// The initial value of declaration `d`, as a store per name: into `early`, or into
    /// `late` for a variable holding function block instances (their initialisers run after
    /// the instances' own initial values, `vm::init`).
    fn lower_init(
        &mut self,
        d: &crate::ast::VarDecl,
        ctx: Ctx,
        file: u16,
        l: &Layout,
        (early, late): (&mut Vec<St>, &mut Vec<St>),
    ) -> R<()> {
        let Some(init) = &d.init else {
            return Ok(());
        };
        for n in &d.names {
            let (addr, ty) = self.place(&Expr::Name(n.clone()), ctx, l)?;
            let mut kinds = Vec::new();
            self.lower_init_value(addr, &ty, init, (ctx, l), &mut kinds)
                .map_err(|e| e.in_file(&self.file))?;
            let out = if self.holds_instances(&ty) {
                &mut *late
            } else {
                &mut *early
            };
            out.extend(kinds.into_iter().map(|kind| St {
                kind,
                at: (file, n.pos),
            }));
        }
        Ok(())
    }

    /// The place a variable, field, element or dereference names, and its type.
    pub(super) fn place(&mut self, e: &Expr, ctx: Ctx, l: &Layout) -> R<(Addr, Type)> {
        match e {
            Expr::Name(n) => self.name_place(n, ctx, l),
            Expr::Field(base, field) => {
                let (addr, ty) = self.place(base, ctx, l)?;
                let (offset, member) = self.member(&ty, field, l)?;
                Ok((plus(addr, offset), member))
            }
            Expr::Index(base, index, _) => {
                let (mut addr, ty) = self.place(base, ctx, l)?;
                let Type::Array(dims, element) = ty else {
                    return Err(self.unsupported(e.pos(), "an index of this value"));
                };
                let (size, align) = l.size_align(&self.out, &element);
                let element_stride = u64::from(size).div_ceil(u64::from(align)) * u64::from(align);
                let lens: Vec<u64> = dims.iter().map(|(lo, hi)| hi.abs_diff(*lo) + 1).collect();
                let Some(strides) = strides(element_stride, &lens) else {
                    return Err(self.unsupported(e.pos(), "an array larger than 4 GiB"));
                };
                for (k, i) in index.iter().enumerate() {
                    let index = self.int_value(i, ctx, l)?;
                    let (lo, len) = (dims[k].0, lens[k]);
                    if let Ex::Int(i) = index {
                        // A constant index within the bounds is an offset, found now.
                        let step = i.checked_sub(lo).and_then(|d| u64::try_from(d).ok());
                        if let Some(step) = step.filter(|s| *s < len) {
                            addr = plus(addr, step as u32 * strides[k]);
                            continue;
                        }
                    }
                    addr = Addr::Index {
                        base: Box::new(addr),
                        index: Box::new(index),
                        lo: dims[k].0,
                        len: lens[k] as u32,
                        stride: strides[k],
                    };
                }
                Ok((addr, *element))
            }
            Expr::Deref(p, _) => match self.expr(p, ctx) {
                Type::Pointer(t) => Ok((deref(self.value(p, ctx, l)?), *t)),
                _ => Err(self.unsupported(e.pos(), "`^` of this value")),
            },
            _ => Err(self.unsupported(e.pos(), "a place of this kind")),
        }
    }

    fn name_place(&mut self, n: &Name, ctx: Ctx, l: &Layout) -> R<(Addr, Type)> {
        // Only a name in a POU (not a global's initial value) is a local or a return value.
        // A method's variables are its function block instance's (its program's).
        let owner = self.family(ctx.pou).unwrap_or(ctx.pou);
        let local = |offset: u32| match self.out.pous[owner].kind {
            PouKind::FunctionBlock => Addr::Instance(offset),
            _ => Addr::Static(l.statics[owner] + offset),
        };
        match self.meaning(&n.text, ctx) {
            Some(Meaning::Local(i)) => Ok((
                local(l.pous[ctx.pou].2[i]),
                self.out.pous[ctx.pou].vars[i].ty.clone(),
            )),
            Some(Meaning::Return(t)) => {
                let offset = *l.pous[ctx.pou].2.last().unwrap_or(&0);
                Ok((local(offset), t))
            }
            Some(Meaning::Global(i)) => {
                Ok((Addr::Static(l.globals[i]), self.out.globals[i].ty.clone()))
            }
            _ => Err(self.unsupported(n.pos, "a place of this name")),
        }
    }

    /// The offset and type of member `field` of a value of `ty`.
    pub(super) fn member(&self, ty: &Type, field: &Name, l: &Layout) -> R<(u32, Type)> {
        let same = |a: &str| a.eq_ignore_ascii_case(&field.text);
        match ty {
            Type::Struct(i) => {
                let k = self.out.structs[*i]
                    .fields
                    .iter()
                    .position(|(f, _)| same(f));
                k.map(|k| (l.structs[*i].2[k], self.out.structs[*i].fields[k].1.clone()))
            }
            Type::Fb(i) => {
                let k = self.out.pous[*i].vars.iter().position(|v| same(&v.name));
                k.map(|k| (l.pous[*i].2[k], self.out.pous[*i].vars[k].ty.clone()))
            }
            Type::StdFb(fb) => {
                let member = fb.member(&field.text);
                member
                    .and_then(|(_, t, _)| std_member(*fb, &field.text).map(|o| (o, Type::Elem(t))))
            }
            _ => None,
        }
        .ok_or_else(|| self.unsupported(field.pos, "this member"))
    }

    /// The value of an integer expression (an index, a CASE selector), as an integer.
    fn int_value(&mut self, e: &Expr, ctx: Ctx, l: &Layout) -> R<Ex> {
        self.value(e, ctx, l)
    }

    /// The value of `e` as type `to`: converted if it is of another elementary type.
    pub(super) fn value_as(&mut self, e: &Expr, to: Elem, ctx: Ctx, l: &Layout) -> R<Ex> {
        if let Some(v) = super::expr::literal_value(e, to) {
            return Ok(v);
        }
        if let Some((f, at, values)) = super::expr::literal_call(e) {
            if super::expr::literal_fits(e, to) {
                return self.literal_call_value((&f, at), &values, to, ctx, l);
            }
        }
        let from = match self.expr(e, ctx) {
            Type::Elem(f) => f,
            Type::Enum(i) => self.out.enums[i].base,
            _ => to,
        };
        let v = self.value(e, ctx, l)?;
        Ok(if from == to {
            v
        } else {
            Ex::Conv(from, to, Box::new(v))
        })
    }

    /// The value of an expression of an elementary, enumeration or pointer type.
    pub(super) fn value(&mut self, e: &Expr, ctx: Ctx, l: &Layout) -> R<Ex> {
        match e {
            Expr::Int(v, _) => Ok(Ex::Int(*v as i64)),
            Expr::Real(v, _) => Ok(Ex::Real(*v)),
            Expr::Bool(b, _) => Ok(Ex::Int(i64::from(*b))),
            // TIME counts milliseconds.
            Expr::Time(ns, true, _) => Ok(Ex::Int(*ns as i64)),
            Expr::Time(ns, false, _) => Ok(Ex::Int((*ns / 1_000_000) as i64)),
            Expr::Str(_, pos) => Err(self.unsupported(*pos, "a string in an expression")),
            Expr::Typed { ty, value } => self.typed_value(ty, value),
            Expr::Name(n) => match self.meaning(&n.text, ctx) {
                Some(Meaning::EnumValue(i)) => Ok(Ex::Int(self.enum_value(i, &n.text))),
                _ => self.load(e, ctx, l),
            },
            Expr::Field(base, field) => self.field_value(e, base, field, ctx, l),
            Expr::Index(..) | Expr::Deref(..) => self.load(e, ctx, l),
            Expr::Unary(op, inner, _) => {
                let Type::Elem(t) = self.expr(e, ctx) else {
                    return Err(self.unsupported(e.pos(), "this operand"));
                };
                let v = Box::new(self.value_as(inner, t, ctx, l)?);
                Ok(match op {
                    UnOp::Neg => Ex::Neg(v, t),
                    UnOp::Not => Ex::Not(v, t),
                })
            }
            // A constant expression of untyped literals: its value, folded at load.
            Expr::Binary(..) if super::expr::literal(e).is_some() => {
                Ok(Ex::Int(super::expr::literal(e).unwrap_or_default() as i64))
            }
            Expr::Binary(..) if super::expr::real_literal(e).is_some() => {
                Ok(Ex::Real(super::expr::real_literal(e).unwrap_or_default()))
            }
            Expr::Binary(op, a, b, _) => self.binary_value(*op, a, b, ctx, l),
            Expr::Call { callee, args, .. } => self.call_value_ir(callee, args, ctx, l),
        }
    }

    fn enum_value(&self, i: usize, name: &str) -> i64 {
        self.enum_number(i, name).map_or(0, |n| n as i64)
    }

    fn typed_value(&mut self, ty: &Name, value: &Expr) -> R<Ex> {
        match (Elem::named(&ty.text), value) {
            (Some(e), Expr::Int(v, _)) if e.class() == Class::Float => Ok(Ex::Real(*v as f64)),
            (Some(_), Expr::Int(v, _)) => Ok(Ex::Int(*v as i64)),
            (Some(_), Expr::Real(v, _)) => Ok(Ex::Real(*v)),
            (Some(_), Expr::Bool(b, _)) => Ok(Ex::Int(i64::from(*b))),
            (None, Expr::Name(v)) => match self.names.get(&ty.text.to_ascii_uppercase()) {
                Some(super::Named::Enum(i)) => Ok(Ex::Int(self.enum_value(*i, &v.text))),
                _ => Err(self.unsupported(ty.pos, "this typed literal")),
            },
            _ => Err(self.unsupported(ty.pos, "this typed literal")),
        }
    }

    fn field_value(&mut self, e: &Expr, base: &Expr, field: &Name, ctx: Ctx, l: &Layout) -> R<Ex> {
        if let Expr::Name(n) = base {
            if let Some(Meaning::EnumType(i)) = self.meaning(&n.text, ctx) {
                return Ok(Ex::Int(self.enum_value(i, &field.text)));
            }
        }
        if let Ok(bit) = field.text.parse::<u32>() {
            let Type::Elem(t) = self.expr(base, ctx) else {
                return Err(self.unsupported(field.pos, "this bit"));
            };
            let word = self.value(base, ctx, l)?;
            let shifted = Ex::Std(StdFn::Shr, t, vec![word, Ex::Int(i64::from(bit))]);
            return Ok(Ex::Bin(
                BinOp::And,
                t,
                Box::new(shifted),
                Box::new(Ex::Int(1)),
            ));
        }
        self.load(e, ctx, l)
    }

    fn load(&mut self, e: &Expr, ctx: Ctx, l: &Layout) -> R<Ex> {
        let (addr, ty) = self.place(e, ctx, l)?;
        match (ty, addr) {
            (Type::Elem(ty), Addr::Static(offset)) => Ok(Ex::Var {
                offset,
                relative: false,
                ty,
            }),
            (Type::Elem(ty), Addr::Instance(offset)) => Ok(Ex::Var {
                offset,
                relative: true,
                ty,
            }),
            (ty, addr) => self.load_at(e, ty, addr),
        }
    }

    fn load_at(&self, e: &Expr, ty: Type, addr: Addr) -> R<Ex> {
        match ty {
            Type::Elem(t) => Ok(Ex::Load(Box::new(addr), t)),
            Type::Enum(i) => Ok(Ex::Load(Box::new(addr), self.out.enums[i].base)),
            Type::Pointer(_) => Ok(Ex::LoadPtr(Box::new(addr))),
            _ => Err(self.unsupported(e.pos(), "a value of this type in an expression")),
        }
    }

    fn binary_value(&mut self, op: BinOp, a: &Expr, b: &Expr, ctx: Ctx, l: &Layout) -> R<Ex> {
        let (ta, tb) = (self.expr(a, ctx), self.expr(b, ctx));
        if let (Type::Str(_), Type::Str(_)) = (&ta, &tb) {
            if !matches!(op, BinOp::Eq | BinOp::Ne) {
                return self.text_order_ir(op, (a, b), ctx, l);
            }
            let (x, y) = (self.text_ir(a, ctx, l)?, self.text_ir(b, ctx, l)?);
            let equal = Ex::TextEq(Box::new((x, y)));
            return Ok(match op {
                BinOp::Ne => Ex::Not(Box::new(equal), Elem::Bool),
                _ => equal,
            });
        }
        if let Some((d, f, left)) = super::expr::scaled_duration(op, &ta, &tb) {
            return self.scaled_duration_value(op, (a, b), (d, f, left), ctx, l);
        }
        let t = match (&ta, &tb) {
            (Type::Enum(i), _) | (_, Type::Enum(i)) => self.out.enums[*i].base,
            (Type::Pointer(_), _) | (_, Type::Pointer(_)) => Elem::ULInt,
            _ => match self.operands(a, b, ctx) {
                Some((c, _, _)) => c,
                None => return Err(self.unsupported(a.pos(), "these operands")),
            },
        };
        let (x, y) = (self.value_as(a, t, ctx, l)?, self.value_as(b, t, ctx, l)?);
        Ok(Ex::Bin(op, t, Box::new(x), Box::new(y)))
    }

    /// `TIME * n`, `n * TIME`, `TIME / n`: by an integer, in the duration's own integer
    /// arithmetic (wrapping to its width as the PLC's integers do; a division by zero
    /// faults); by a real, in LREAL and rounded back as LREAL_TO_TIME does. The operands in
    /// their written order.
    fn scaled_duration_value(
        &mut self,
        op: BinOp,
        (a, b): (&Expr, &Expr),
        (d, f, left): (Elem, Elem, bool),
        ctx: Ctx,
        l: &Layout,
    ) -> R<Ex> {
        // Both to LREAL by a real; an integer to the duration's type.
        let real = f.class() == Class::Float;
        let t = if real { Elem::LReal } else { d };
        // An integer literal as the duration's integer arithmetic holds it (wrapped to its
        // width, as a variable's value converted to it is).
        let held = |v: Ex, factor: bool| match v {
            Ex::Int(i) if factor && !real => Ex::Int(crate::vm::ops::wrap(i, d)),
            v => v,
        };
        let x = held(self.value_as(a, t, ctx, l)?, !left);
        let y = held(self.value_as(b, t, ctx, l)?, left);
        Ok(if real {
            let product = Ex::Bin(op, Elem::LReal, Box::new(x), Box::new(y));
            Ex::Conv(Elem::LReal, d, Box::new(product))
        } else {
            Ex::Bin(op, d, Box::new(x), Box::new(y))
        })
    }

    fn call_value_ir(&mut self, callee: &Expr, args: &[Arg], ctx: Ctx, l: &Layout) -> R<Ex> {
        if let Some((m, this)) = self.method_of(callee, ctx) {
            return self.method_value(m, (callee, this), args, ctx, l);
        }
        let Expr::Name(n) = callee else {
            return Err(self.unsupported(callee.pos(), "this call"));
        };
        let positional = super::expr::positional(args);
        let upper = n.text.to_ascii_uppercase();
        if let Some(v) = self.text_value_ir(&upper, &positional, ctx, l)? {
            return Ok(v);
        }
        if let Some((from, to)) = conversion(&n.text) {
            let v = self.value_as(positional[0], from, ctx, l)?;
            return Ok(Ex::Conv(from, to, Box::new(v)));
        }
        if upper == "ADR" {
            let (addr, _) = self.place(positional[0], ctx, l)?;
            return Ok(Ex::AddrOf(Box::new(addr)));
        }
        if upper == "SIZEOF" {
            let t = self.sizeof_type(positional[0], ctx);
            return Ok(Ex::Int(i64::from(l.size_align(&self.out, &t).0)));
        }
        if let Some(f) = std_fn(&upper) {
            return self.std_value(f, n, &positional, ctx, l);
        }
        match self.meaning(&n.text, ctx) {
            Some(Meaning::Function(i)) => self.function_value(i, args, n.pos, ctx, l),
            _ => Err(self.unsupported(n.pos, "this call")),
        }
    }

    /// `target := value` as a store or a copy.
    pub(super) fn lower_assign(
        &mut self,
        target: &Expr,
        value: &Expr,
        ctx: Ctx,
        l: &Layout,
    ) -> R<StKind> {
        if let Expr::Field(word, f) = target {
            if let Ok(bit) = f.text.parse::<u32>() {
                return self.lower_bit_write(word, bit, value, ctx, l);
            }
        }
        let (addr, ty) = self.place(target, ctx, l)?;
        self.lower_store(addr, ty, value, ctx, l)
    }

    /// `value` stored into `addr`, a place of type `ty`.
    pub(super) fn lower_store(
        &mut self,
        addr: Addr,
        ty: Type,
        value: &Expr,
        ctx: Ctx,
        l: &Layout,
    ) -> R<StKind> {
        Ok(match ty {
            Type::Elem(t) => StKind::Store(addr, t, self.value_as(value, t, ctx, l)?),
            Type::Enum(i) => {
                let base = self.out.enums[i].base;
                StKind::Store(addr, base, self.value_as(value, base, ctx, l)?)
            }
            Type::Pointer(_) => StKind::StorePtr(addr, self.value(value, ctx, l)?),
            Type::Array(..) | Type::Struct(_) => {
                let (from, _) = self.place(value, ctx, l)?;
                let size = l.size_align(&self.out, &ty).0;
                StKind::Copy(addr, from, size)
            }
            Type::Str(n) => self.lower_string(addr, n, value, ctx, l)?,
            _ => return Err(self.unsupported(value.pos(), "an assignment of this type")),
        })
    }

    fn lower_stmt(&mut self, s: &Stmt, ctx: Ctx, file: u16, l: &Layout) -> R<St> {
        let at = (file, stmt_pos(s));
        let kind = match s {
            Stmt::Assign { target, value } => self.lower_assign(target, value, ctx, l)?,
            Stmt::Call(call) => self.lower_call(call, ctx, at, l)?,
            Stmt::If {
                branches,
                otherwise,
            } => {
                let mut arms = Vec::with_capacity(branches.len());
                for (cond, body) in branches {
                    let c = self.value(cond, ctx, l)?;
                    arms.push((c, self.lower_block(body, ctx, file, l)?));
                }
                let other = self.lower_block(otherwise.as_deref().unwrap_or(&[]), ctx, file, l)?;
                StKind::If(arms, other)
            }
            Stmt::Case {
                selector,
                arms,
                otherwise,
            } => {
                let sel = self.value(selector, ctx, l)?;
                let mut out = Vec::with_capacity(arms.len());
                for (labels, body) in arms {
                    let mut ranges = Vec::with_capacity(labels.len());
                    for label in labels {
                        let (a, b) = match label {
                            CaseLabel::Value(v) => (v, v),
                            CaseLabel::Range(a, b) => (a, b),
                        };
                        let (lo, hi) = (self.constant(a, ctx)?, self.constant(b, ctx)?);
                        if lo > hi {
                            let why = format!(
                                "CASE range {lo}..{hi} holds no value: its upper bound lies \
                                 below the lower"
                            );
                            return Err(Diagnostic::new(a.pos(), why).in_file(&self.file));
                        }
                        ranges.push((lo, hi));
                    }
                    out.push((ranges, self.lower_block(body, ctx, file, l)?));
                }
                let other = self.lower_block(otherwise.as_deref().unwrap_or(&[]), ctx, file, l)?;
                StKind::Case(sel, out, other)
            }
            Stmt::For {
                var,
                from,
                to,
                by,
                body,
            } => {
                let (addr, ty) = self.place(&Expr::Name(var.clone()), ctx, l)?;
                let Type::Elem(t) = ty else {
                    return Err(self.unsupported(var.pos, "this FOR variable"));
                };
                let by = match by {
                    Some(b) => self.value_as(b, t, ctx, l)?,
                    None => Ex::Int(1),
                };
                StKind::For {
                    var: addr,
                    ty: t,
                    from: self.value_as(from, t, ctx, l)?,
                    to: self.value_as(to, t, ctx, l)?,
                    by,
                    body: self.lower_block(
                        body,
                        Ctx {
                            loops: ctx.loops + 1,
                            ..ctx
                        },
                        file,
                        l,
                    )?,
                }
            }
            Stmt::While { cond, body } => StKind::While(
                self.value(cond, ctx, l)?,
                self.lower_block(body, ctx, file, l)?,
            ),
            Stmt::Repeat { body, until } => StKind::Repeat(
                self.lower_block(body, ctx, file, l)?,
                self.value(until, ctx, l)?,
            ),
            Stmt::Exit(_) => StKind::Exit,
            Stmt::Continue(_) => StKind::Continue,
            Stmt::Return(_) => StKind::Return,
        };
        Ok(St { kind, at })
    }

    fn lower_block(&mut self, body: &[Stmt], ctx: Ctx, file: u16, l: &Layout) -> R<Vec<St>> {
        body.iter()
            .map(|s| self.lower_stmt(s, ctx, file, l))
            .collect()
    }

    /// The number a CASE label stands for.
    fn constant(&mut self, e: &Expr, ctx: Ctx) -> R<i64> {
        if let Some(v) = literal(e) {
            return Ok(v as i64);
        }
        let scratch = Layout {
            statics: vec![0; self.out.pous.len()],
            ..Layout::default()
        };
        match self.value(e, ctx, &scratch)? {
            Ex::Int(v) => Ok(v),
            _ => Err(self.unsupported(e.pos(), "a CASE label that is no constant")),
        }
    }

    /// A call statement: a function block instance's or a function's.
    fn lower_call(&mut self, call: &Expr, ctx: Ctx, at: (u16, Pos), l: &Layout) -> R<StKind> {
        let Expr::Call { callee, args, .. } = call else {
            return Err(self.unsupported(call.pos(), "this call"));
        };
        // A method first, as the checker resolves it.
        if self.method_of(callee, ctx).is_some() {
            return Ok(StKind::Eval(self.statement_value(call, ctx, l)?));
        }
        let errors = self.errors.len();
        let ty = self.expr(callee, ctx);
        self.errors.truncate(errors);
        let (pou, fb) = match ty {
            Type::Fb(i) => (Some(i), None),
            Type::StdFb(fb) => (None, Some(fb)),
            // A STRING's call for what it does: its characters computed and left.
            _ if self.is_text_value(call, ctx) => {
                let text = self.text_ir(call, ctx, l)?;
                return Ok(StKind::Eval(Ex::Text(Box::new(TextEx::Len(text)))));
            }
            _ => return Ok(StKind::Eval(self.statement_value(call, ctx, l)?)),
        };
        let (instance, _) = self.place(callee, ctx, l)?;
        let (mut inputs, mut outputs, mut texts) = (Vec::new(), Vec::new(), Vec::new());
        for arg in args {
            let (name, is_input) = match arg {
                Arg::Input(n, _) => (n, true),
                Arg::Output { name, .. } => (name, false),
                Arg::Positional(v) => return Err(self.unsupported(v.pos(), "a positional input")),
            };
            let inst_ty = match (pou, fb) {
                (Some(i), _) => Type::Fb(i),
                (_, Some(f)) => Type::StdFb(f),
                _ => Type::Error,
            };
            let (offset, member) = self.member(&inst_ty, name, l)?;
            let in_out = pou.is_some_and(|i| {
                self.out.pous[i].vars.iter().any(|v| {
                    v.section == crate::ast::Section::InOut
                        && v.name.eq_ignore_ascii_case(&name.text)
                })
            });
            if let (true, Arg::Input(_, v)) = (in_out, arg) {
                // VAR_IN_OUT: copied in before the call and back after it, leaf by leaf.
                for (at, t, leaf) in self.in_out_leaves(v, &member, ctx, l)? {
                    inputs.push((offset + at, t, Ex::Load(Box::new(leaf.clone()), t)));
                    outputs.push((offset + at, t, leaf, false, t));
                }
                continue;
            }
            if let (Type::Struct(_) | Type::Array(..), Arg::Input(_, v)) = (&member, arg) {
                // A structure (an AXIS_REF) or array input is passed leaf by leaf.
                let (from, _) = self.place(v, ctx, l)?;
                for (at, t) in self.leaves(&member, l).ok_or_else(|| {
                    self.unsupported(
                        name.pos,
                        "a structure or array input of more than 64 values",
                    )
                })? {
                    let leaf = Addr::Offset(Box::new(from.clone()), at);
                    inputs.push((offset + at, t, Ex::Load(Box::new(leaf), t)));
                }
                continue;
            }
            if let (Type::Str(n), Arg::Input(_, v)) = (&member, arg) {
                // A STRING input is passed in 8-byte parts (its literal's as constants).
                let input = (&instance, offset, at, inputs.len());
                for (k, t, part) in self.string_input(*n, v, input, &mut texts, ctx, l)? {
                    inputs.push((offset + k, t, part));
                }
                continue;
            }
            if let (Type::Str(m), Arg::Output { target, .. }) = (&member, arg) {
                outputs.extend(self.string_output(*m, (offset, target), ctx, l)?);
                continue;
            }
            if let (Type::Struct(_) | Type::Array(..), Arg::Output { target, .. }) = (&member, arg)
            {
                // A structure's or an array's output goes to the caller's variable leaf by
                // leaf after the call.
                let (to, _) = self.place(target, ctx, l)?;
                let leaves = self.leaves(&member, l).filter(|_| !addr_calls(&to));
                let leaves = leaves.ok_or_else(|| {
                    self.unsupported(
                        name.pos,
                        "an output of more than 64 values, of this type, or to a variable at \
                         an index a function computes",
                    )
                })?;
                for (at, t) in leaves {
                    outputs.push((offset + at, t, plus(to.clone(), at), false, t));
                }
                continue;
            }
            let t = match member {
                Type::Elem(t) => t,
                // A pointer input (FiFoWrite's AdrDataArray) is its address, 8 bytes.
                Type::Pointer(_) if matches!(arg, Arg::Input(..)) => Elem::LInt,
                _ => {
                    return Err(self
                        .unsupported(name.pos, "an input or output that is no elementary value"))
                }
            };
            match arg {
                Arg::Input(_, v) => inputs.push((offset, t, self.value_as(v, t, ctx, l)?)),
                Arg::Output {
                    target, negated, ..
                } => {
                    let (to, there) = self.place(target, ctx, l)?;
                    let there = if let Type::Elem(e) = there { e } else { t };
                    outputs.push((offset, t, to, *negated, there));
                }
                Arg::Positional(_) => {}
            }
            let _ = is_input;
        }
        let kind = match (pou, fb) {
            (Some(pou), _) => StKind::CallFb {
                pou,
                instance,
                inputs,
                outputs,
            },
            (_, Some(fb)) => StKind::CallStdFb {
                fb,
                instance,
                inputs,
                outputs,
            },
            _ => StKind::Eval(Ex::Int(0)),
        };
        self.texts_first(texts, St { kind, at }, call.pos())
    }
}

/// Where a statement starts.
fn stmt_pos(s: &Stmt) -> Pos {
    match s {
        Stmt::Assign { target, .. } => target.pos(),
        Stmt::Call(c) => c.pos(),
        Stmt::If { branches, .. } => branches.first().map_or(Pos::default(), |b| b.0.pos()),
        Stmt::Case { selector, .. } => selector.pos(),
        Stmt::For { var, .. } => var.pos,
        Stmt::While { cond, .. } => cond.pos(),
        Stmt::Repeat { until, .. } => until.pos(),
        Stmt::Exit(p) | Stmt::Continue(p) | Stmt::Return(p) => *p,
    }
}
