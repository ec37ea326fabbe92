//! Builds one body's operations ([`super::code`]): statements into operations and jumps,
//! expressions into operands and the operations that fill registers, places into operands
//! or the pointer operations, and what the operations do not cover into the tree's.

use super::code::{Code, Codes, Dst, Op, Src, Switch, NEXT, R};
use super::library::Library;
use super::V;
use crate::ast::BinOp;
use crate::ir::{Addr, Ex, St, StKind};
use crate::types::Elem;

mod calls;

use calls::index_place;

/// Where EXIT and CONTINUE go inside the loop being compiled: the operations to patch.
#[derive(Clone, Copy)]
pub(super) enum Loops {
    /// Outside a loop: both end the body.
    None,
    /// Inside the loop whose exits and continues are collected at these indices of the
    /// builder's lists.
    In(usize),
}

/// Builds one body's operations.
pub(super) struct Builder<'c> {
    codes: &'c mut Codes,
    library: &'c Library,
    ops: Vec<Op>,
    /// The next free register, and the most used.
    next: u16,
    most: u16,
    /// More registers than a window holds: the body stays on the tree.
    overflow: bool,
    /// Per loop being compiled: the jumps EXIT and CONTINUE left to patch.
    loops: Vec<(Vec<usize>, Vec<usize>)>,
}

/// A jump's target not known yet.
const LATER: u32 = u32::MAX;

impl<'c> Builder<'c> {
    pub(super) fn new(codes: &'c mut Codes, library: &'c Library) -> Builder<'c> {
        Builder {
            codes,
            library,
            ops: Vec::new(),
            next: 0,
            most: 0,
            overflow: false,
            loops: Vec::new(),
        }
    }

    /// The body's code; `None` (the tree runs it) when it needs more registers than a
    /// window holds.
    pub(super) fn finish(mut self) -> Option<Code> {
        self.ops.push(Op::Ret);
        (!self.overflow).then_some(Code {
            ops: (self.ops.into_iter())
                .map(|op| super::fast::specialize(op, &self.codes.consts))
                .collect(),
            regs: self.most,
            native: None,
        })
    }

    fn here(&self) -> u32 {
        self.ops.len() as u32
    }

    fn reg(&mut self) -> R {
        let r = self.next;
        match self.next.checked_add(1) {
            Some(n) => self.next = n,
            None => self.overflow = true,
        }
        self.most = self.most.max(self.next);
        r
    }

    fn site(&mut self, s: &St) -> u32 {
        self.codes.sites.push(s.at);
        (self.codes.sites.len() - 1) as u32
    }

    /// Points the jump at `at` to `to`.
    fn patch(&mut self, at: usize, to: u32) {
        match &mut self.ops[at] {
            Op::Jump(t)
            | Op::JumpIfNot(_, t)
            | Op::JumpIf(_, t)
            | Op::JumpCmp(.., t)
            | Op::JumpCmpI(.., t)
            | Op::JumpIn(_, _, t)
            | Op::ForTest(.., t) => *t = to,
            Op::ForNext(.., t) => *t = to,
            _ => {}
        }
    }

    pub(super) fn block(&mut self, body: &[St], loops: Loops) {
        for s in body {
            let mark = self.next;
            self.statement(s, loops);
            self.next = mark;
        }
    }

    fn statement(&mut self, s: &St, loops: Loops) {
        // A function called in the statement's own expressions may write what an operand
        // of it reads; operands are read when their operation runs, the tree's in its order:
        // such a statement is the tree's.
        if super::callees::calls_in(s) {
            return self.tree_statement(s, loops);
        }
        match &s.kind {
            StKind::Store(a, t, e) => {
                let site = self.site(s);
                self.ops.push(Op::Stmt(site));
                let v = self.expr(e);
                let to = self.dst(a);
                self.ops.push(Op::Store(to, *t, v));
            }
            StKind::StorePtr(a, e) => {
                let site = self.site(s);
                self.ops.push(Op::Stmt(site));
                let v = self.expr(e);
                let to = self.dst(a);
                self.ops.push(Op::StorePtr(to, v));
            }
            StKind::If(arms, otherwise) => {
                let site = self.site(s);
                self.ops.push(Op::Stmt(site));
                let mut ends = Vec::new();
                for (cond, body) in arms {
                    let mark = self.next;
                    let c = self.expr(cond);
                    let skip = self.jump_unless(c, LATER);
                    // The condition is taken: its registers are free for the arm.
                    self.next = mark;
                    self.block(body, loops);
                    ends.push(self.ops.len());
                    self.ops.push(Op::Jump(LATER));
                    let next = self.here();
                    self.patch(skip, next);
                }
                self.block(otherwise, loops);
                let end = self.here();
                ends.into_iter().for_each(|j| self.patch(j, end));
            }
            StKind::Case(sel, arms, otherwise) => self.case(s, sel, arms, otherwise, loops),
            StKind::For {
                var,
                ty,
                from,
                to,
                by,
                body,
            } => match own(var) {
                Some(Dst::Own(at, relative)) => {
                    self.for_loop(s, (at, relative), *ty, [from, to, by], body)
                }
                _ => self.tree_statement(s, loops),
            },
            StKind::While(cond, body) => {
                let site = self.site(s);
                self.ops.push(Op::Stmt(site));
                let top = self.here();
                self.ops.push(Op::Stmt(site));
                let c = self.expr(cond);
                let test = self.jump_unless(c, LATER);
                let continues = self.looped(body);
                self.ops.push(Op::Jump(top));
                let end = self.here();
                self.close_loop(continues, top, end);
                self.patch(test, end);
            }
            StKind::Repeat(body, until) => {
                let site = self.site(s);
                self.ops.push(Op::Stmt(site));
                let top = self.here();
                self.ops.push(Op::Step);
                let continues = self.looped(body);
                let check = self.here();
                self.ops.push(Op::At(site));
                let u = self.expr(until);
                self.jump_unless(u, top);
                let end = self.here();
                self.close_loop(continues, check, end);
            }
            StKind::Exit | StKind::Continue | StKind::Return => {
                let site = self.site(s);
                self.ops.push(Op::Stmt(site));
                match (&s.kind, loops) {
                    (StKind::Exit, Loops::In(k)) => {
                        self.loops[k].0.push(self.ops.len());
                        self.ops.push(Op::Jump(LATER));
                    }
                    (StKind::Continue, Loops::In(k)) => {
                        self.loops[k].1.push(self.ops.len());
                        self.ops.push(Op::Jump(LATER));
                    }
                    _ => self.ops.push(Op::Ret),
                }
            }
            StKind::CallFb {
                pou,
                instance,
                inputs,
                outputs,
            } => self.call(s, instance, inputs, outputs, Ok(*pou as u32)),
            StKind::CallStdFb {
                fb,
                instance,
                inputs,
                outputs,
            } => self.call(s, instance, inputs, outputs, Err(*fb)),
            StKind::Eval(e) => {
                let site = self.site(s);
                self.ops.push(Op::Stmt(site));
                // The value is dropped (a constant or a variable has nothing to compute).
                let _ = self.expr(e);
            }
            StKind::Copy(..) | StKind::Bytes(..) | StKind::Text(..) => {
                self.tree_statement(s, loops)
            }
        }
    }

    /// A statement the tree runs, EXIT and CONTINUE going where this loop's go.
    fn tree_statement(&mut self, s: &St, loops: Loops) {
        self.codes.stmts.push(s.clone());
        let k = (self.codes.stmts.len() - 1) as u32;
        let at = self.ops.len();
        self.ops.push(Op::TreeSt(k, u32::MAX, u32::MAX));
        if let Loops::In(l) = loops {
            // Patched when the loop closes: EXIT to its end, CONTINUE to its next round.
            self.loops[l].0.push(at);
            self.loops[l].1.push(at);
        }
    }

    /// A loop's body; the list of its CONTINUE jumps to patch (its EXITs stay on the loop).
    fn looped(&mut self, body: &[St]) -> usize {
        self.loops.push((Vec::new(), Vec::new()));
        let k = self.loops.len() - 1;
        self.block(body, Loops::In(k));
        k
    }

    /// Points the loop's EXITs at `end` and its CONTINUEs at `next`.
    fn close_loop(&mut self, k: usize, next: u32, end: u32) {
        let (exits, continues) = self.loops.pop().unwrap_or_default();
        debug_assert_eq!(k, self.loops.len());
        for at in exits {
            match &mut self.ops[at] {
                Op::TreeSt(_, exit, _) => *exit = end,
                _ => self.patch(at, end),
            }
        }
        for at in continues {
            match &mut self.ops[at] {
                Op::TreeSt(_, _, cont) => *cont = next,
                _ => self.patch(at, next),
            }
        }
    }

    /// Goes on at `to` unless `c` holds: a comparison just computed into `c`'s register is
    /// taken into the jump. The jump's index (to patch).
    fn jump_unless(&mut self, c: Src, to: u32) -> usize {
        if let (Src::R(r), Some(&Op::Not(Elem::Bool, d, a))) = (c, self.ops.last()) {
            if d == r {
                *self.ops.last_mut().expect("the negation") = Op::JumpIf(a, to);
                return self.ops.len() - 1;
            }
        }
        let last = match self.ops.last() {
            Some(&Op::Bin(op, t, d, a, b)) => Some((op, t, d, a, b, false)),
            Some(&Op::BinI(op, t, d, a, b)) => Some((op, t, d, a, b, true)),
            _ => None,
        };
        if let (Src::R(r), Some((op, t, d, a, b, int))) = (c, last) {
            let compares = matches!(
                op,
                BinOp::Eq | BinOp::Ne | BinOp::Lt | BinOp::Gt | BinOp::Le | BinOp::Ge
            );
            // The register is the condition's alone (read by nothing after the jump).
            if compares && d == r {
                *self.ops.last_mut().expect("the comparison") = if int {
                    Op::JumpCmpI(op, t, a, b, to)
                } else {
                    Op::JumpCmp(op, t, a, b, to)
                };
                return self.ops.len() - 1;
            }
        }
        self.ops.push(Op::JumpIfNot(c, to));
        self.ops.len() - 1
    }

    /// A CASE's tests as one jump table when its labels lie close together (a state
    /// machine's steps): its index among the switches, the table's entries the arms'
    /// numbers until they are known.
    fn switch(&mut self, v: Src, arms: &[crate::ir::CaseArm]) -> Option<u32> {
        // A range written high to low holds no value (the tests in order would take none).
        let ranges = || {
            arms.iter()
                .enumerate()
                .flat_map(|(k, (r, _))| r.iter().map(move |x| (k, x)))
                .filter(|(_, (a, b))| a <= b)
        };
        let lo = ranges().map(|(_, (lo, _))| *lo).min()?;
        let hi = ranges().map(|(_, (_, hi))| *hi).max()?;
        let span = hi.checked_sub(lo).filter(|s| (0..256).contains(s))?;
        if ranges().count() < 3 {
            return None;
        }
        let mut to = vec![NEXT; span as usize + 1];
        // The first arm that holds a value takes it, as the tests in order would.
        for (k, (a, b)) in ranges() {
            for e in &mut to[(a - lo) as usize..=(b - lo) as usize] {
                if *e == NEXT {
                    *e = k as u32;
                }
            }
        }
        self.codes.switches.push(Switch { lo, to });
        let k = (self.codes.switches.len() - 1) as u32;
        self.ops.push(Op::Switch(v, k));
        Some(k)
    }

    fn case(
        &mut self,
        s: &St,
        sel: &Ex,
        arms: &[crate::ir::CaseArm],
        otherwise: &[St],
        loops: Loops,
    ) {
        let site = self.site(s);
        self.ops.push(Op::Stmt(site));
        // Computed once, as the tree reads it once: an operand is a register, a variable
        // (nothing runs between the tests that could change it) or a constant.
        let v = self.expr(sel);
        let mut tests = Vec::new();
        let table = self.switch(v, arms);
        if table.is_none() {
            for (k, (ranges, _)) in arms.iter().enumerate() {
                for (lo, hi) in ranges {
                    tests.push((self.ops.len(), k));
                    self.codes.ranges.push((*lo, *hi));
                    let range = (self.codes.ranges.len() - 1) as u32;
                    self.ops.push(Op::JumpIn(v, range, LATER));
                }
            }
        }
        self.block(otherwise, loops);
        let mut ends = vec![self.ops.len()];
        self.ops.push(Op::Jump(LATER));
        let mut starts = Vec::new();
        for (_, body) in arms {
            starts.push(self.here());
            self.block(body, loops);
            ends.push(self.ops.len());
            self.ops.push(Op::Jump(LATER));
        }
        for (at, k) in tests {
            self.patch(at, starts[k]);
        }
        if let Some(t) = table {
            for e in &mut self.codes.switches[t as usize].to {
                if *e != NEXT {
                    *e = starts[*e as usize];
                }
            }
        }
        let end = self.here();
        ends.into_iter().for_each(|j| self.patch(j, end));
    }

    fn for_loop(
        &mut self,
        s: &St,
        var: (u32, bool),
        ty: Elem,
        [from, to, by]: [&Ex; 3],
        body: &[St],
    ) {
        let site = self.site(s);
        self.ops.push(Op::Stmt(site));
        let regs = [self.reg(), self.reg(), self.reg()];
        for (r, e) in regs.into_iter().zip([from, to, by]) {
            let v = self.expr(e);
            self.ops.push(Op::Mov(r, v));
        }
        let top = self.here();
        let test = self.ops.len();
        self.ops.push(Op::ForTest(var, ty, regs, LATER));
        let k = self.looped(body);
        let next = self.here();
        self.ops.push(Op::ForNext(var, ty, regs, top, LATER));
        let end = self.here();
        self.close_loop(k, next, end);
        self.patch(test, end);
        if let Op::ForNext(.., exit) = &mut self.ops[next as usize] {
            *exit = end;
        }
    }

    /// The tagged pointer to an element of an array at a fixed place at an index known at
    /// run time (`a[i]`, `a[i].field`), into a register; `None` for any other place.
    fn element_place(&mut self, a: &Addr) -> Option<R> {
        let (e, index) = index_place(a)?;
        let r = self.reg();
        self.element(r, e, index);
        Some(r)
    }

    fn place(&mut self, a: &Addr) -> u32 {
        self.codes.places.push(a.clone());
        (self.codes.places.len() - 1) as u32
    }

    /// Where a store goes; a place the tree must find is found into a register now.
    fn dst(&mut self, a: &Addr) -> Dst {
        if let Some(d) = own(a) {
            return d;
        }
        if let Addr::Via {
            ptr,
            relative,
            plus,
        } = *a
        {
            return Dst::Via(ptr, relative, plus);
        }
        if let Some(r) = self.pointer_place(a, true) {
            return Dst::At(r);
        }
        if let Some(r) = self.element_place(a) {
            return Dst::At(r);
        }
        let r = self.reg();
        let k = self.place(a);
        self.ops.push(Op::Addr(r, k));
        Dst::At(r)
    }

    /// The tagged pointer to a place behind a pointer (`gpCh[0]^.unit.field`,
    /// `p^.array[2]`), into a register; `None` when the tree must find it.
    fn pointer_place(&mut self, a: &Addr, access: bool) -> Option<R> {
        let (e, plus) = behind_pointer(a)?;
        let mark = self.next;
        let p = self.expr(e);
        self.next = mark;
        let r = self.reg();
        self.ops.push(Op::PtrAt(r, p, plus, access));
        Some(r)
    }

    /// `e`'s value read where the tagged pointer to `a` points, or the tree's.
    fn load_behind(&mut self, e: &Ex, a: &Addr, t: Elem) -> Src {
        let place = match self.pointer_place(a, true) {
            Some(p) => Some(p),
            None => self.element_place(a),
        };
        match place {
            Some(p) => {
                self.next = p;
                let r = self.reg();
                self.ops.push(Op::LoadAt(r, p, t));
                Src::R(r)
            }
            None => self.tree(e),
        }
    }

    /// An expression's value: an operand, or a register the operations pushed fill.
    fn expr(&mut self, e: &Ex) -> Src {
        match e {
            Ex::Int(v) => self.codes.constant(V::I(*v)),
            Ex::Real(v) => self.codes.constant(V::F(*v)),
            Ex::Var {
                offset,
                relative,
                ty,
            } => Src::Var(*offset, *relative, *ty),
            Ex::Load(a, t) => match **a {
                _ if own(a).is_some() => match own(a) {
                    Some(Dst::Own(at, relative)) => Src::Var(at, relative, *t),
                    _ => self.tree(e),
                },
                Addr::Via {
                    ptr,
                    relative,
                    plus,
                } => {
                    let r = self.reg();
                    self.ops.push(Op::LoadVia(r, ptr, relative, plus, *t));
                    Src::R(r)
                }
                _ => self.load_behind(e, a, *t),
            },
            Ex::LoadPtr(a) => match own(a) {
                Some(Dst::Own(at, relative)) => Src::Var(at, relative, Elem::ULInt),
                _ => self.load_behind(e, a, Elem::ULInt),
            },
            Ex::AddrOf(a) => match (own(a), &**a) {
                (Some(Dst::Own(at, false)), _) => self.codes.constant(V::I(i64::from(at) + 1)),
                // `ADR(gpCh[0]^.unit)`: past where the pointer variable points.
                (
                    _,
                    Addr::Via {
                        ptr,
                        relative,
                        plus,
                    },
                ) => {
                    let r = self.reg();
                    let p = Src::Var(*ptr, *relative, Elem::ULInt);
                    self.ops.push(Op::PtrAt(r, p, *plus, false));
                    Src::R(r)
                }
                _ => match self.pointer_place(a, false) {
                    Some(r) => Src::R(r),
                    None => self.tree(e),
                },
            },
            Ex::Neg(x, t) => self.unary(x, |r, v| Op::Neg(*t, r, v)),
            Ex::Not(x, t) => self.unary(x, |r, v| Op::Not(*t, r, v)),
            Ex::Conv(from, to, x) => self.unary(x, |r, v| Op::Conv(*from, *to, r, v)),
            Ex::Bin(BinOp::AndThen | BinOp::OrElse, ..) => self.tree(e),
            Ex::Bin(op, t, a, b) => {
                let mark = self.next;
                let (x, y) = (self.expr(a), self.expr(b));
                self.next = mark;
                let r = self.reg();
                self.ops.push(if t.class() == crate::types::Class::Float {
                    Op::Bin(*op, *t, r, x, y)
                } else {
                    Op::BinI(*op, *t, r, x, y)
                });
                Src::R(r)
            }
            _ => self.tree(e),
        }
    }

    fn unary(&mut self, x: &Ex, op: impl Fn(R, Src) -> Op) -> Src {
        let mark = self.next;
        let v = self.expr(x);
        self.next = mark;
        let r = self.reg();
        self.ops.push(op(r, v));
        Src::R(r)
    }

    fn tree(&mut self, e: &Ex) -> Src {
        self.codes.exprs.push(e.clone());
        let k = (self.codes.exprs.len() - 1) as u32;
        let r = self.reg();
        self.ops.push(Op::Tree(r, k));
        Src::R(r)
    }
}

/// Whether an expression is an operand (a constant or a variable): nothing to compute.
fn operand(e: &Ex) -> bool {
    match e {
        Ex::Int(_) | Ex::Real(_) | Ex::Var { .. } => true,
        Ex::Load(a, _) => matches!(own(a), Some(Dst::Own(..))),
        _ => false,
    }
}

/// A place of the program's own memory at a fixed offset (absolute, or from the instance's
/// base), if `a` is one (fields, and elements at constant indices within their bounds).
fn own(a: &Addr) -> Option<Dst> {
    match a {
        Addr::Static(o) => Some(Dst::Own(*o, false)),
        Addr::Instance(o) => Some(Dst::Own(*o, true)),
        _ => {
            let (inner, plus) = inside(a)?;
            match own(inner)? {
                Dst::Own(o, relative) => Some(Dst::Own(o.checked_add(plus)?, relative)),
                _ => None,
            }
        }
    }
}

/// `a` as a pointer's value and the bytes past where it points, when every step from the
/// pointer is a field or an element at a constant index within its bounds.
fn behind_pointer(a: &Addr) -> Option<(&Ex, u32)> {
    match a {
        Addr::Deref(e) => Some((e, 0)),
        _ => {
            let (inner, plus) = inside(a)?;
            let (e, p) = behind_pointer(inner)?;
            Some((e, p.checked_add(plus)?))
        }
    }
}

/// A place as the place it lies in and the bytes from that one's start: a field, or an
/// element at a constant index within its bounds.
fn inside(a: &Addr) -> Option<(&Addr, u32)> {
    match a {
        Addr::Offset(inner, plus) => Some((inner, *plus)),
        Addr::Index {
            base,
            index,
            lo,
            len,
            stride,
        } => Some((
            base,
            constant_index(index, *lo, *len)?.checked_mul(*stride)?,
        )),
        _ => None,
    }
}

/// A constant index's element (from 0) when it lies within the bounds (else the tree
/// evaluates it and faults as it must).
fn constant_index(index: &Ex, lo: i64, len: u32) -> Option<u32> {
    let Ex::Int(i) = index else {
        return None;
    };
    let k = i.checked_sub(lo)?;
    (0..i64::from(len)).contains(&k).then_some(k as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A body that would need more registers than a window numbers stays on the tree
    /// (instead of wrapping round onto registers in use).
    #[test]
    fn a_body_beyond_the_registers_is_left_to_the_tree() {
        let (mut codes, library) = (Codes::default(), Library::default());
        let mut b = Builder::new(&mut codes, &library);
        b.next = u16::MAX - 1;
        assert_eq!(b.reg(), u16::MAX - 1);
        assert!(!b.overflow);
        b.reg();
        assert!(b.overflow, "no register after the last");
        assert!(b.finish().is_none());
        let b = Builder::new(&mut codes, &library);
        assert!(b.finish().is_some());
    }
}
