//! The compiled tree once more, flattened: each POU body becomes a list of operations on
//! registers ([`Op`]) that the runtime steps through with a program counter ([`super::run`]),
//! instead of walking the tree with a call per node. Every variable, constant and pointer
//! field the manuals' programs use is an operand of the operation that needs it; control
//! flow is jumps. What is rare keeps the tree: an operation hands a statement, an expression
//! or a place to the tree walker ([`Op::TreeSt`], [`Op::Tree`], [`Op::Addr`]), so both
//! ways share every rule (the operations call the same `ops`, `read`, `write` and `via`),
//! and a test runs programs both ways and compares their memory.
//!
//! A body's registers are a window of the state's register file; a call (a block's body, or
//! the tree from inside a body) runs in the window above its caller's, so nothing a callee
//! does touches a value its caller holds. Recursion is refused by the checker, so the file's
//! size is the deepest chain of calls, known at load.

use super::library::Library;
use crate::ast::{BinOp, PouKind};
use crate::check::std_lib::StdFb;
use crate::check::Compiled;
use crate::diag::Pos;
use crate::ir::{Addr, BlockInput, BlockOutput, Ex, St, StKind};
use crate::types::Elem;

/// A register's index in its window.
pub(crate) type R = u16;

/// Where an operation takes a value from.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Src {
    /// A register.
    R(R),
    /// An integer constant.
    I(i64),
    /// A real constant.
    F(f64),
    /// A variable: its offset (from the instance's base when relative) and type.
    Var(u32, bool, Elem),
}

/// Where an operation stores a value.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Dst {
    /// The program's memory at an offset (from the instance's base when relative).
    Own(u32, bool),
    /// `plus` bytes past where the pointer variable at the offset points (`p^.field`).
    Via(u32, bool, u32),
    /// Where the tagged pointer in a register points (an [`Op::Addr`] made it).
    At(R),
}

/// One operation. Jumps name an index into the body's operations.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Op {
    /// A statement begins: its place for a fault, and one step of the budget.
    Stmt(u32),
    /// One step of the budget (a REPEAT's round).
    Step,
    /// The place for a fault, without a step.
    At(u32),
    /// `d := a op b` of type `t`.
    Bin(BinOp, Elem, R, Src, Src),
    /// `d := -a`.
    Neg(Elem, R, Src),
    /// `d := NOT a`.
    Not(Elem, R, Src),
    /// `d := a` converted from the first type to the second.
    Conv(Elem, Elem, R, Src),
    /// `d := a`.
    Mov(R, Src),
    /// `d :=` the value of the type `plus` bytes past where the pointer variable points.
    LoadVia(R, u32, bool, u32, Elem),
    /// `d :=` the tagged pointer `plus` bytes past where the pointer value points (NULL and
    /// values below it are faults); for an access (true), one past the pointers' range too,
    /// as the access itself would fault there.
    PtrAt(R, Src, u32, bool),
    /// `d :=` the value of the type where the tagged pointer in the register points.
    LoadAt(R, R, Elem),
    /// `d :=` an expression the tree computes (its index among [`Codes::exprs`]).
    Tree(R, u32),
    /// `d :=` the tagged pointer to a place the tree finds (its index among
    /// [`Codes::places`]).
    Addr(R, u32),
    /// Stores a value of the type.
    Store(Dst, Elem, Src),
    /// Stores a pointer.
    StorePtr(Dst, Src),
    /// A statement the tree runs (its index among [`Codes::stmts`]); where its EXIT and
    /// CONTINUE go (`u32::MAX`: end the body, as outside a loop).
    TreeSt(u32, u32, u32),
    /// Goes on at the operation.
    Jump(u32),
    /// Goes on at the operation when the value is 0 (FALSE).
    JumpIfNot(Src, u32),
    /// Goes on at the operation when the value lies in the range (a CASE arm).
    JumpIn(Src, i64, i64, u32),
    /// A FOR's test: control variable (own memory), its type, the registers of the value,
    /// the last value and the step; past the last, goes on at the operation; else stores the
    /// value and takes a step.
    ForTest(Dst, Elem, [R; 3], u32),
    /// A FOR's next value: read back from the variable, plus the step; goes on at the test
    /// (first), or past the loop when the value overflows (second).
    ForNext(Dst, Elem, [R; 3], u32, u32),
    /// `d :=` the offset of a block instance in the program's memory (from the instance's
    /// base when relative).
    Inst(R, u32, bool),
    /// As [`Op::Inst`] for an instance the tree finds (index among [`Codes::places`]).
    InstTree(R, u32),
    /// Stores an input: the instance's register, the input's offset in it, type, value.
    Input(R, u32, Elem, Src),
    /// Runs POU `pou`'s body on the instance, with call site `k`'s inputs passed.
    Body(u32, R, u32),
    /// Runs a standard block on the instance, with call site `k`'s inputs passed.
    StdBody(StdFb, R, u32),
    /// Reads an output: instance, offset, type, negated, where it goes.
    Output(R, u32, Elem, bool, Dst),
    /// A whole block call whose instance has a fixed place and whose inputs are all
    /// operands (the common call: `fbRun(Axis := axConveyor, Velocity := 360.0)`): its
    /// index among [`Codes::call_ops`]. Its outputs follow as [`Op::Output`]s.
    Call(u32),
    /// The body ends.
    Ret,
}

/// A block call in one operation ([`Op::Call`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct CallOp {
    /// The statement's place.
    pub(crate) site: u32,
    /// The instance's offset, from the instance's base when relative.
    pub(crate) at: u32,
    pub(crate) relative: bool,
    /// Its inputs: this range of [`Codes::inputs`].
    pub(crate) inputs: (u32, u32),
    /// The POU whose body runs, or the standard block.
    pub(crate) body: Result<u32, StdFb>,
    /// Its index among [`Codes::calls`] (the inputs the host is told were passed).
    pub(crate) call: u32,
    /// The host's slot of a library block's instance at a fixed absolute place (found once
    /// here instead of at every call).
    pub(crate) slot: Option<u32>,
}

/// A POU body's operations and how many registers they use.
#[derive(Debug, Clone, Default)]
pub(crate) struct Code {
    pub(crate) ops: Vec<Op>,
    pub(crate) regs: u16,
}

/// Every POU's body compiled, and what the operations refer to.
#[derive(Debug, Clone, Default)]
pub(crate) struct Codes {
    /// Per POU: its body's code (`None`: a library block's, or not compiled).
    pub(crate) bodies: Vec<Option<Code>>,
    /// The statements' places (file, position).
    pub(crate) sites: Vec<(u16, Pos)>,
    /// Statements the tree runs.
    pub(crate) stmts: Vec<St>,
    /// Expressions the tree computes.
    pub(crate) exprs: Vec<Ex>,
    /// Places the tree finds.
    pub(crate) places: Vec<Addr>,
    /// Each block call's inputs (what the block's host is told was passed).
    pub(crate) calls: Vec<Vec<BlockInput>>,
    /// The block calls in one operation.
    pub(crate) call_ops: Vec<CallOp>,
    /// Their inputs: offset in the instance, type, value.
    pub(crate) inputs: Vec<(u32, Elem, Src)>,
    /// Registers of the deepest chain of calls.
    pub(crate) registers: usize,
}

/// The most registers the file may hold (the deepest chain of calls).
const MAX_REGISTERS: usize = 1 << 16;

impl Codes {
    /// Compiles every body of `c` but those of `library` POUs; nothing (every body on the
    /// tree) when the registers would exceed [`MAX_REGISTERS`].
    pub(crate) fn of(c: &Compiled, library: &Library) -> Codes {
        let mut codes = Codes::default();
        for (pou, (_, body)) in c.bodies.iter().enumerate() {
            let host = library.of_pou.get(pou).copied().flatten().is_some();
            let code = (!host).then(|| {
                let mut b = Builder::new(&mut codes, library);
                b.block(body, Loops::None);
                b.finish()
            });
            codes.bodies.push(code);
        }
        let mut need = vec![None; c.bodies.len()];
        let deepest = (0..c.bodies.len())
            .filter(|&p| c.checked.pous[p].kind == PouKind::Program)
            .map(|p| codes.need(c, p, &mut need, 0))
            .collect::<Option<Vec<usize>>>()
            .map(|n| n.into_iter().max().unwrap_or(0));
        match deepest {
            Some(n) if n <= MAX_REGISTERS => codes.registers = n,
            _ => return Codes::default(),
        }
        codes
    }

    /// Registers POU `pou`'s body and everything it calls need (`None`: deeper than the
    /// POUs, which only a cycle of calls would be).
    fn need(
        &self,
        c: &Compiled,
        pou: usize,
        memo: &mut Vec<Option<usize>>,
        depth: usize,
    ) -> Option<usize> {
        if let Some(n) = memo[pou] {
            return Some(n);
        }
        if depth > c.bodies.len() {
            return None;
        }
        let own = self.bodies[pou].as_ref().map_or(0, |b| usize::from(b.regs));
        let mut callees = Vec::new();
        let (inits, body) = &c.bodies[pou];
        for s in inits.iter().chain(body) {
            super::callees::of_st(s, &mut callees);
        }
        let mut deepest = 0;
        for callee in callees {
            deepest = deepest.max(self.need(c, callee, memo, depth + 1)?);
        }
        memo[pou] = Some(own + deepest);
        memo[pou]
    }
}

/// Where EXIT and CONTINUE go inside the loop being compiled: the operations to patch.
#[derive(Clone, Copy)]
enum Loops {
    /// Outside a loop: both end the body.
    None,
    /// Inside the loop whose exits and continues are collected at these indices of the
    /// builder's lists.
    In(usize),
}

/// Builds one body's operations.
struct Builder<'c> {
    codes: &'c mut Codes,
    library: &'c Library,
    ops: Vec<Op>,
    /// The next free register, and the most used.
    next: u16,
    most: u16,
    /// Per loop being compiled: the jumps EXIT and CONTINUE left to patch.
    loops: Vec<(Vec<usize>, Vec<usize>)>,
}

/// A jump's target not known yet.
const LATER: u32 = u32::MAX;

impl<'c> Builder<'c> {
    fn new(codes: &'c mut Codes, library: &'c Library) -> Builder<'c> {
        Builder {
            codes,
            library,
            ops: Vec::new(),
            next: 0,
            most: 0,
            loops: Vec::new(),
        }
    }

    fn finish(mut self) -> Code {
        self.ops.push(Op::Ret);
        Code {
            ops: self.ops,
            regs: self.most,
        }
    }

    fn here(&self) -> u32 {
        self.ops.len() as u32
    }

    fn reg(&mut self) -> R {
        let r = self.next;
        self.next += 1;
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
            Op::Jump(t) | Op::JumpIfNot(_, t) | Op::JumpIn(_, _, _, t) | Op::ForTest(.., t) => {
                *t = to
            }
            Op::ForNext(.., t) => *t = to,
            _ => {}
        }
    }

    fn block(&mut self, body: &[St], loops: Loops) {
        for s in body {
            let mark = self.next;
            self.statement(s, loops);
            self.next = mark;
        }
    }

    fn statement(&mut self, s: &St, loops: Loops) {
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
                    let c = self.expr(cond);
                    let skip = self.ops.len();
                    self.ops.push(Op::JumpIfNot(c, LATER));
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
                Some(v) => self.for_loop(s, v, *ty, [from, to, by], body),
                None => self.tree_statement(s, loops),
            },
            StKind::While(cond, body) => {
                let site = self.site(s);
                self.ops.push(Op::Stmt(site));
                let top = self.here();
                self.ops.push(Op::Stmt(site));
                let c = self.expr(cond);
                let test = self.ops.len();
                self.ops.push(Op::JumpIfNot(c, LATER));
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
                self.ops.push(Op::JumpIfNot(u, top));
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
            StKind::Copy(..) | StKind::Bytes(..) => self.tree_statement(s, loops),
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
        let v = self.expr(sel);
        // Computed once (the tree reads it once).
        let v = match v {
            Src::Var(..) | Src::R(_) | Src::I(_) => v,
            other => {
                let r = self.reg();
                self.ops.push(Op::Mov(r, other));
                Src::R(r)
            }
        };
        let mut tests = Vec::new();
        for (k, (ranges, _)) in arms.iter().enumerate() {
            for (lo, hi) in ranges {
                tests.push((self.ops.len(), k));
                self.ops.push(Op::JumpIn(v, *lo, *hi, LATER));
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
        let end = self.here();
        ends.into_iter().for_each(|j| self.patch(j, end));
    }

    fn for_loop(&mut self, s: &St, var: Dst, ty: Elem, [from, to, by]: [&Ex; 3], body: &[St]) {
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

    fn call(
        &mut self,
        s: &St,
        instance: &Addr,
        inputs: &[BlockInput],
        outputs: &[BlockOutput],
        body: Result<u32, StdFb>,
    ) {
        let site = self.site(s);
        let operands: Option<Vec<Src>> = inputs.iter().map(|(_, _, e)| operand(e)).collect();
        if let (Some(Dst::Own(at, relative)), Some(values)) = (own(instance), operands) {
            return self.whole_call(site, (at, relative), inputs, values, body, outputs);
        }
        self.ops.push(Op::Stmt(site));
        let inst = self.reg();
        match own(instance) {
            Some(Dst::Own(at, relative)) => self.ops.push(Op::Inst(inst, at, relative)),
            _ => {
                let k = self.place(instance);
                self.ops.push(Op::InstTree(inst, k));
            }
        }
        for (offset, t, e) in inputs {
            let mark = self.next;
            let v = self.expr(e);
            self.ops.push(Op::Input(inst, *offset, *t, v));
            self.next = mark;
        }
        self.codes.calls.push(inputs.to_vec());
        let call = (self.codes.calls.len() - 1) as u32;
        self.ops.push(match body {
            Ok(pou) => Op::Body(pou, inst, call),
            Err(fb) => Op::StdBody(fb, inst, call),
        });
        self.ops.push(Op::At(site));
        for (offset, t, target, negated) in outputs {
            let mark = self.next;
            let to = self.dst(target);
            self.ops.push(Op::Output(inst, *offset, *t, *negated, to));
            self.next = mark;
        }
    }

    /// A call in one operation ([`Op::Call`]), its outputs after it.
    fn whole_call(
        &mut self,
        site: u32,
        (at, relative): (u32, bool),
        inputs: &[BlockInput],
        values: Vec<Src>,
        body: Result<u32, StdFb>,
        outputs: &[BlockOutput],
    ) {
        let first = self.codes.inputs.len() as u32;
        for ((offset, t, _), v) in inputs.iter().zip(values) {
            self.codes.inputs.push((*offset, *t, v));
        }
        self.codes.calls.push(inputs.to_vec());
        let host = body
            .ok()
            .and_then(|p| self.library.of_pou.get(p as usize).copied().flatten());
        let slot = match (host, relative) {
            (Some(_), false) => self.library.slot_at(at),
            _ => None,
        };
        self.codes.call_ops.push(CallOp {
            site,
            at,
            relative,
            inputs: (first, self.codes.inputs.len() as u32),
            body,
            call: (self.codes.calls.len() - 1) as u32,
            slot,
        });
        let k = (self.codes.call_ops.len() - 1) as u32;
        self.ops.push(Op::Call(k));
        if outputs.is_empty() {
            return;
        }
        let inst = self.reg();
        self.ops.push(Op::Inst(inst, at, relative));
        for (offset, t, target, negated) in outputs {
            let mark = self.next;
            let to = self.dst(target);
            self.ops.push(Op::Output(inst, *offset, *t, *negated, to));
            self.next = mark;
        }
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
        match self.pointer_place(a, true) {
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
            Ex::Int(v) => Src::I(*v),
            Ex::Real(v) => Src::F(*v),
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
                (Some(Dst::Own(at, false)), _) => Src::I(i64::from(at) + 1),
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
            Ex::Bin(op, t, a, b) => {
                let mark = self.next;
                let (x, y) = (self.expr(a), self.expr(b));
                self.next = mark;
                let r = self.reg();
                self.ops.push(Op::Bin(*op, *t, r, x, y));
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

/// An expression that is an operand (a constant or a variable): nothing to compute.
fn operand(e: &Ex) -> Option<Src> {
    match e {
        Ex::Int(v) => Some(Src::I(*v)),
        Ex::Real(v) => Some(Src::F(*v)),
        Ex::Var {
            offset,
            relative,
            ty,
        } => Some(Src::Var(*offset, *relative, *ty)),
        Ex::Load(a, t) => match own(a)? {
            Dst::Own(at, relative) => Some(Src::Var(at, relative, *t)),
            _ => None,
        },
        _ => None,
    }
}

/// A place of the program's own memory at a fixed offset (absolute, or from the instance's
/// base), if `a` is one (fields, and elements at constant indices within their bounds).
fn own(a: &Addr) -> Option<Dst> {
    match a {
        Addr::Static(o) => Some(Dst::Own(*o, false)),
        Addr::Instance(o) => Some(Dst::Own(*o, true)),
        Addr::Offset(inner, plus) => match own(inner)? {
            Dst::Own(o, relative) => Some(Dst::Own(o.checked_add(*plus)?, relative)),
            _ => None,
        },
        Addr::Index {
            base,
            index,
            lo,
            len,
            stride,
        } => {
            let step = constant_index(index, *lo, *len)?.checked_mul(*stride)?;
            match own(base)? {
                Dst::Own(o, relative) => Some(Dst::Own(o.checked_add(step)?, relative)),
                _ => None,
            }
        }
        _ => None,
    }
}

/// `a` as a pointer's value and the bytes past where it points, when every step from the
/// pointer is a field or an element at a constant index within its bounds.
fn behind_pointer(a: &Addr) -> Option<(&Ex, u32)> {
    match a {
        Addr::Deref(e) => Some((e, 0)),
        Addr::Offset(inner, plus) => {
            let (e, p) = behind_pointer(inner)?;
            Some((e, p.checked_add(*plus)?))
        }
        Addr::Index {
            base,
            index,
            lo,
            len,
            stride,
        } => {
            let step = constant_index(index, *lo, *len)?.checked_mul(*stride)?;
            let (e, p) = behind_pointer(base)?;
            Some((e, p.checked_add(step)?))
        }
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
