//! A body's operations as a Cranelift function: block `k` is operation `k`; the operations
//! [`native`] covers are instructions, every other one a call of the runtime's callback
//! followed by a jump to where it says to go on.

use super::super::code::{Code, Codes, Dst, Op, Src, NEXT};
use super::super::fast::Bytes;
use super::super::ops;
use super::super::{Fault, V};
use super::{at, FAULTED, NEXT_END};
use crate::ast::BinOp;
use crate::types::{Class, Elem};
use cranelift_codegen::ir::condcodes::{FloatCC, IntCC};
use cranelift_codegen::ir::{
    types, Block, FuncRef, Function, InstBuilder, InstructionData, MemFlagsData, Opcode, Type,
    Value,
};
use cranelift_codegen::isa::TargetFrontendConfig;
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext, Switch, Variable};

mod arith;
mod call;
mod flow;
mod image;

/// A value an operand gives: an integer, a real, or a register's word and flag (a real
/// when the flag is set, as [`super::super::Exec`]'s `get` reads it).
#[derive(Clone, Copy)]
enum Val {
    Int(Value),
    Real(Value),
    Reg(Value, Value),
}

struct Emit<'f, 'c> {
    b: FunctionBuilder<'f>,
    codes: &'c Codes,
    cx: Value,
    /// The callbacks: one operation ([`raw`](super::raw)'s `op`), a block call's body (`call`).
    op: FuncRef,
    call: FuncRef,
    blocks: Vec<Block>,
    end: Block,
    /// A fault of an instruction (the steps counted here stored first), and one the
    /// callback returned (the steps in memory already).
    fault: Block,
    faulted: Block,
    /// [`FIELDS`] of the `Cx`, read at the start and after each callback.
    fields: [Variable; 7],
    /// The steps of the cycle, stored back before a callback and at the body's end.
    steps: Variable,
    /// The body's registers, and whether an operation names one beyond them (then the body
    /// is not compiled: native code does not check register numbers when it runs).
    regs: u16,
    beyond: bool,
    /// The bytes of the program's memory: an access at a constant offset within them needs
    /// no check when it runs.
    memory: u64,
}

/// The fields of `Cx` native code reads, in [`Emit::fields`]' order.
const FIELDS: [i32; 7] = [
    at::MEM,
    at::MEM_LEN,
    at::REGS,
    at::STEPS,
    at::BUDGET,
    at::SITE,
    at::BASE,
];

/// Loads and stores that cannot trap: every address is checked before (the program's
/// memory is bytes, so no alignment is promised).
const F: MemFlagsData = MemFlagsData::new().with_notrap();

/// Fills `func` with body `code`'s operations; `op` is the callback. False when the body
/// cannot be compiled (an operation names a register beyond its window).
pub(super) fn body(
    func: &mut Function,
    fbc: &mut FunctionBuilderContext,
    (code, codes, memory): (&Code, &Codes, u64),
    (op, call): (FuncRef, FuncRef),
    config: TargetFrontendConfig,
) -> bool {
    let mut b = FunctionBuilder::new(func, fbc);
    let entry = b.create_block();
    b.append_block_params_for_function_params(entry);
    let blocks = (0..code.ops.len()).map(|_| b.create_block()).collect();
    let (end, fault, faulted) = (b.create_block(), b.create_block(), b.create_block());
    b.append_block_param(fault, types::I64);
    b.append_block_param(faulted, types::I64);
    b.switch_to_block(entry);
    let cx = b.block_params(entry)[0];
    let fields = [(); 7].map(|_| b.declare_var(types::I64));
    let steps = b.declare_var(types::I64);
    let mut e = Emit {
        b,
        codes,
        cx,
        op,
        call,
        blocks,
        end,
        fault,
        faulted,
        fields,
        steps,
        regs: code.regs,
        beyond: false,
        memory,
    };
    e.reload();
    let first = e.to(0);
    e.b.ins().jump(first, &[]);
    for (k, op) in code.ops.iter().enumerate() {
        let block = e.blocks[k];
        e.b.switch_to_block(block);
        if !e.native(*op, k) {
            e.callback(*op, k);
        }
    }
    e.b.switch_to_block(end);
    e.spill_steps();
    let zero = e.b.ins().iconst(types::I64, 0);
    e.b.ins().return_(&[zero]);
    e.b.switch_to_block(fault);
    e.spill_steps();
    let code = e.b.block_params(fault)[0];
    e.b.ins().return_(&[code]);
    e.b.switch_to_block(faulted);
    let code = e.b.block_params(faulted)[0];
    e.b.ins().return_(&[code]);
    e.b.seal_all_blocks();
    let beyond = e.beyond;
    e.b.finalize(config);
    !beyond
}

/// The integer type of `n` bytes.
fn int_type(n: usize) -> Type {
    match n {
        1 => types::I8,
        2 => types::I16,
        4 => types::I32,
        _ => types::I64,
    }
}

/// Whether a value of `t` is read with its sign ([`ops::wrap`]'s widths).
fn signed(t: Elem) -> bool {
    matches!(
        t,
        Elem::SInt | Elem::Int | Elem::DInt | Elem::Time | Elem::LInt | Elem::LTime
    )
}

fn is_float(t: Elem) -> bool {
    t.class() == Class::Float
}

/// The integer comparison of `op` (`unsigned`: without a sign).
fn int_cc(op: BinOp, unsigned: bool) -> Option<IntCC> {
    use IntCC::*;
    Some(match (op, unsigned) {
        (BinOp::Eq, _) => Equal,
        (BinOp::Ne, _) => NotEqual,
        (BinOp::Lt, false) => SignedLessThan,
        (BinOp::Lt, true) => UnsignedLessThan,
        (BinOp::Gt, false) => SignedGreaterThan,
        (BinOp::Gt, true) => UnsignedGreaterThan,
        (BinOp::Le, false) => SignedLessThanOrEqual,
        (BinOp::Le, true) => UnsignedLessThanOrEqual,
        (BinOp::Ge, false) => SignedGreaterThanOrEqual,
        (BinOp::Ge, true) => UnsignedGreaterThanOrEqual,
        _ => return None,
    })
}

/// The real comparison of `op`: ordered, but `<>` holds of a NaN ([`ops::compare`]).
fn float_cc(op: BinOp) -> Option<FloatCC> {
    use FloatCC::*;
    Some(match op {
        BinOp::Eq => Equal,
        BinOp::Ne => NotEqual,
        BinOp::Lt => LessThan,
        BinOp::Gt => GreaterThan,
        BinOp::Le => LessThanOrEqual,
        BinOp::Ge => GreaterThanOrEqual,
        _ => return None,
    })
}

/// The operations that may go on elsewhere than at the next one, with where (the callback
/// says which).
fn successors(op: Op, k: usize, codes: &Codes) -> Vec<u64> {
    let next = k as u64 + 1;
    let target = |t: u32| {
        if t == u32::MAX {
            NEXT_END
        } else {
            u64::from(t)
        }
    };
    match op {
        Op::TreeSt(_, exit, cont) => vec![next, target(exit), target(cont), NEXT_END],
        Op::Switch(_, table) => {
            let to = codes
                .switches
                .get(table as usize)
                .map_or(&[][..], |s| &s.to);
            let mut all: Vec<u64> = to
                .iter()
                .map(|&t| if t == NEXT { next } else { u64::from(t) })
                .collect();
            all.push(next);
            all
        }
        Op::Jump(to) => vec![u64::from(to)],
        Op::JumpIf(_, to) | Op::JumpIfNot(_, to) | Op::JumpCmp(.., to) | Op::JumpCmpI(.., to) => {
            vec![u64::from(to), next]
        }
        Op::JumpIn(_, _, to) | Op::ForTest(.., to) => vec![u64::from(to), next],
        Op::ForNext(.., test, end) => vec![u64::from(test), u64::from(end)],
        Op::Ret => vec![NEXT_END],
        _ => vec![next],
    }
}

impl Emit<'_, '_> {
    /// The block of operation `k` (past the last: the body's end).
    fn to(&self, k: u64) -> Block {
        usize::try_from(k)
            .ok()
            .and_then(|k| self.blocks.get(k))
            .copied()
            .unwrap_or(self.end)
    }

    fn goto(&mut self, k: u64) {
        let to = self.to(k);
        self.b.ins().jump(to, &[]);
    }

    /// Callback `f` with `cx` and `k`: its result, once it is no fault (a fault stops the
    /// body as the callback left the steps), the `Cx`'s fields read again.
    fn call_back(&mut self, f: FuncRef, k: u32) -> Value {
        self.spill_steps();
        let k = self.b.ins().iconst(types::I32, i64::from(k));
        let call = self.b.ins().call(f, &[self.cx, k]);
        let r = self.b.inst_results(call)[0];
        let faulted = self
            .b
            .ins()
            .icmp_imm_s(IntCC::UnsignedGreaterThanOrEqual, r, FAULTED as i64);
        let code = self.b.ins().band_imm_s(r, (FAULTED - 1) as i64);
        let go = self.b.create_block();
        self.b
            .ins()
            .brif(faulted, self.faulted, &[code.into()], go, &[]);
        self.b.switch_to_block(go);
        self.reload();
        r
    }

    /// Operation `k` by the callback, then on where it says.
    fn callback(&mut self, op: Op, k: usize) {
        let r = self.call_back(self.op, k as u32);
        let mut to = successors(op, k, self.codes);
        to.sort_unstable();
        to.dedup();
        if let [only] = to[..] {
            self.goto(only);
            return;
        }
        let mut sw = Switch::new();
        for t in to {
            sw.set_entry(u128::from(t), self.to(t));
        }
        let end = self.end;
        sw.emit(&mut self.b, r, end);
    }

    /// Stops the body with fault `f` when `bad` holds, else goes on in a new block.
    fn fault_if(&mut self, bad: Value, f: Fault) {
        let code = self.b.ins().iconst(types::I64, f.code() as i64);
        let go = self.b.create_block();
        self.b.ins().brif(bad, self.fault, &[code.into()], go, &[]);
        self.b.switch_to_block(go);
    }

    /// A field of the `Cx` as last read.
    fn cx_load(&mut self, offset: i32) -> Value {
        let k = FIELDS.iter().position(|f| *f == offset).unwrap_or(0);
        self.b.use_var(self.fields[k])
    }

    /// Reads the `Cx`'s fields and the steps (at the start, and after a callback).
    fn reload(&mut self) {
        for (k, offset) in FIELDS.into_iter().enumerate() {
            let v = self.b.ins().load(types::I64, F, self.cx, offset);
            self.b.def_var(self.fields[k], v);
        }
        let p = self.cx_load(at::STEPS);
        let steps = self.b.ins().load(types::I64, F, p, 0);
        self.b.def_var(self.steps, steps);
    }

    /// Stores the steps counted here.
    fn spill_steps(&mut self) {
        let p = self.cx_load(at::STEPS);
        let steps = self.b.use_var(self.steps);
        self.b.ins().store(F, steps, p, 0);
    }

    /// Register `r`'s address.
    fn reg(&mut self, r: u16) -> Value {
        self.beyond |= r >= self.regs;
        let regs = self.cx_load(at::REGS);
        self.b.ins().iadd_imm_s(regs, i64::from(r) * 16)
    }

    fn put(&mut self, r: u16, v: Val) {
        let p = self.reg(r);
        let (bits, flag) = match v {
            Val::Int(x) => (x, self.b.ins().iconst(types::I8, 0)),
            Val::Real(x) => (self.b.ins().bitcast(types::I64, MemFlagsData::new(), x), {
                self.b.ins().iconst(types::I8, 1)
            }),
            Val::Reg(bits, flag) => (bits, flag),
        };
        self.b.ins().store(F, bits, p, 0);
        self.b.ins().store(F, flag, p, 8);
    }

    /// The offset of a variable (from the instance's base when relative).
    fn own(&mut self, at: u32, relative: bool) -> Value {
        if relative {
            let base = self.cx_load(at::BASE);
            self.b.ins().iadd_imm_s(base, i64::from(at))
        } else {
            self.b.ins().iconst(types::I64, i64::from(at))
        }
    }

    /// The address of `n` bytes at offset `off` of the program's memory; beyond it, the
    /// body stops with [`Fault::BadPointer`] as `read_mem` and `write_mem` do.
    fn mem(&mut self, off: Value, n: usize) -> Value {
        let memory = self.memory;
        let within = |at: i64| {
            at >= 0
                && (at as u64)
                    .checked_add(n as u64)
                    .is_some_and(|e| e <= memory)
        };
        if let Some(at) = self.constant(off).filter(|at| within(*at)) {
            let mem = self.cx_load(at::MEM);
            return self.b.ins().iadd_imm_s(mem, at);
        }
        let len = self.cx_load(at::MEM_LEN);
        let end = self.b.ins().iadd_imm_s(off, n as i64);
        let beyond = self.b.ins().icmp(IntCC::UnsignedGreaterThan, end, len);
        self.fault_if(beyond, Fault::BadPointer);
        let mem = self.cx_load(at::MEM);
        self.b.ins().iadd(mem, off)
    }

    /// The value of `v` when an integer constant defines it.
    fn constant(&self, v: Value) -> Option<i64> {
        let inst = self.b.func.dfg.value_def(v).inst()?;
        match self.b.func.dfg.insts[inst] {
            InstructionData::UnaryImm {
                opcode: Opcode::Iconst,
                imm,
            } => Some(imm.bits()),
            _ => None,
        }
    }

    /// The value of type `t` at offset `off`.
    fn read(&mut self, off: Value, t: Elem) -> Val {
        let p = self.mem(off, t.size());
        match t {
            Elem::Real => {
                let f = self.b.ins().load(types::F32, F, p, 0);
                Val::Real(self.b.ins().fpromote(types::F64, f))
            }
            Elem::LReal => Val::Real(self.b.ins().load(types::F64, F, p, 0)),
            _ => Val::Int(self.load_int(p, t)),
        }
    }

    /// The integer of type `t` at address `p` (`read_mem`'s widths and signs).
    fn load_int(&mut self, p: Value, t: Elem) -> Value {
        let i = self.b.ins();
        match t.size() {
            1 if signed(t) => i.sload8(types::I64, F, p, 0),
            1 => i.uload8(types::I64, F, p, 0),
            2 if signed(t) => i.sload16(types::I64, F, p, 0),
            2 => i.uload16(types::I64, F, p, 0),
            4 if signed(t) => i.sload32(F, p, 0),
            4 => i.uload32(F, p, 0),
            _ => i.load(types::I64, F, p, 0),
        }
    }

    /// Stores `v` as a value of type `t` at offset `off` (`write_mem`).
    fn write(&mut self, off: Value, t: Elem, v: Val) {
        let x = match t {
            Elem::Real => {
                let f = self.float(v);
                self.b.ins().fdemote(types::F32, f)
            }
            Elem::LReal => self.float(v),
            _ => {
                let i = self.int(v);
                match t.size() {
                    n @ (1 | 2 | 4) => self.b.ins().ireduce(int_type(n), i),
                    _ => i,
                }
            }
        };
        let p = self.mem(off, t.size());
        self.b.ins().store(F, x, p, 0);
    }

    /// An operand's value.
    fn src(&mut self, s: Src) -> Val {
        match s {
            Src::R(r) => {
                let p = self.reg(r);
                let bits = self.b.ins().load(types::I64, F, p, 0);
                let flag = self.b.ins().load(types::I8, F, p, 8);
                Val::Reg(bits, flag)
            }
            Src::I(v) => Val::Int(self.b.ins().iconst(types::I64, i64::from(v))),
            Src::K(k) => match self.codes.consts.get(k as usize).copied() {
                Some(V::F(f)) => Val::Real(self.b.ins().f64const(f)),
                Some(v) => Val::Int(self.b.ins().iconst(types::I64, v.int())),
                None => Val::Int(self.b.ins().iconst(types::I64, 0)),
            },
            Src::Var(at, relative, t) => {
                let off = self.own(at, relative);
                self.read(off, t)
            }
        }
    }

    /// `v` where an integer is wanted (`V::int`: a real cut toward zero).
    fn int(&mut self, v: Val) -> Value {
        match v {
            Val::Int(x) | Val::Reg(x, _) => x,
            Val::Real(f) => self.b.ins().fcvt_to_sint_sat(types::I64, f),
        }
    }

    fn src_int(&mut self, s: Src) -> Value {
        let v = self.src(s);
        self.int(v)
    }

    /// `v` where a real is wanted (`V::float`).
    fn float(&mut self, v: Val) -> Value {
        match v {
            Val::Real(f) => f,
            Val::Int(x) => self.b.ins().fcvt_from_sint(types::F64, x),
            Val::Reg(bits, flag) => {
                let real = self.b.ins().bitcast(types::F64, MemFlagsData::new(), bits);
                let int = self.b.ins().fcvt_from_sint(types::F64, bits);
                self.b.ins().select(flag, real, int)
            }
        }
    }

    /// `v` cut to the width of `t` ([`ops::wrap`]).
    fn wrap(&mut self, v: Value, t: Elem) -> Value {
        let n = t.size();
        if n >= 8 || is_float(t) {
            return v;
        }
        let cut = self.b.ins().ireduce(int_type(n), v);
        if signed(t) {
            self.b.ins().sextend(types::I64, cut)
        } else {
            self.b.ins().uextend(types::I64, cut)
        }
    }

    fn bool_int(&mut self, c: Value) -> Val {
        Val::Int(self.b.ins().uextend(types::I64, c))
    }

    /// A real result, the body stopped with [`Fault::OutOfRange`] when it is not finite.
    fn finite(&mut self, f: Value) -> Val {
        let abs = self.b.ins().fabs(f);
        let inf = self.b.ins().f64const(f64::INFINITY);
        let bad = self
            .b
            .ins()
            .fcmp(FloatCC::UnorderedOrGreaterThanOrEqual, abs, inf);
        self.fault_if(bad, Fault::OutOfRange);
        Val::Real(f)
    }

    /// Whether `a op b` holds of two values of type `t` (`None`: no comparison).
    fn compare(&mut self, op: BinOp, t: Elem, a: Src, b: Src) -> Option<Value> {
        if is_float(t) {
            let cc = float_cc(op)?;
            let (x, y) = (self.src(a), self.src(b));
            let (x, y) = (self.float(x), self.float(y));
            Some(self.b.ins().fcmp(cc, x, y))
        } else {
            let cc = int_cc(op, ops::unsigned(t))?;
            let (x, y) = (self.src_int(a), self.src_int(b));
            Some(self.b.ins().icmp(cc, x, y))
        }
    }

    /// Stores a constant's bytes at offset `off`.
    fn set(&mut self, off: Value, bytes: Bytes) {
        let (n, v) = match bytes {
            Bytes::B1(b) => (1, i64::from(b[0])),
            Bytes::B2(b) => (2, i64::from(u16::from_le_bytes(b))),
            Bytes::B4(b) => (4, i64::from(u32::from_le_bytes(b))),
            Bytes::B8(b) => (8, i64::from_le_bytes(b)),
        };
        let p = self.mem(off, n);
        let x = self.b.ins().iconst(int_type(n), v);
        self.b.ins().store(F, x, p, 0);
    }

    /// A statement's step of the budget ([`super::super::Exec::step`]).
    fn step(&mut self) {
        let steps = self.b.use_var(self.steps);
        let steps = self.b.ins().iadd_imm_s(steps, 1);
        self.b.def_var(self.steps, steps);
        let budget = self.cx_load(at::BUDGET);
        let spent = self.b.ins().icmp(IntCC::UnsignedGreaterThan, steps, budget);
        self.fault_if(spent, Fault::Budget);
    }

    fn set_site(&mut self, k: u32) {
        let p = self.cx_load(at::SITE);
        let k = self.b.ins().iconst(types::I32, i64::from(k));
        self.b.ins().store(F, k, p, 0);
    }

    /// The offset register `r` holds of an instance, plus `offset`.
    fn in_instance(&mut self, r: u16, offset: u32) -> Value {
        let p = self.reg(r);
        let v = self.b.ins().uload32(F, p, 0);
        self.b.ins().iadd_imm_s(v, i64::from(offset))
    }

    /// Operation `op` (the `k`th) as instructions: false when it is the callback's.
    fn native(&mut self, op: Op, k: usize) -> bool {
        let next = k as u64 + 1;
        match op {
            Op::Stmt(site) => {
                self.set_site(site);
                self.step();
            }
            Op::Step => self.step(),
            Op::At(site) => self.set_site(site),
            Op::Jump(to) => {
                self.goto(u64::from(to));
                return true;
            }
            Op::JumpIf(c, to) | Op::JumpIfNot(c, to) => {
                let v = self.src_int(c);
                let (yes, no) = (self.to(u64::from(to)), self.to(next));
                let (yes, no) = if matches!(op, Op::JumpIf(..)) {
                    (yes, no)
                } else {
                    (no, yes)
                };
                self.b.ins().brif(v, yes, &[], no, &[]);
                return true;
            }
            Op::JumpCmp(cmp, t, a, b, to) | Op::JumpCmpI(cmp, t, a, b, to) => {
                let Some(holds) = self.compare(cmp, t, a, b) else {
                    return false;
                };
                let (on, away) = (self.to(next), self.to(u64::from(to)));
                self.b.ins().brif(holds, on, &[], away, &[]);
                return true;
            }
            Op::Ret => {
                self.goto(NEXT_END);
                return true;
            }
            Op::Mov(d, s) => {
                let v = self.src(s);
                self.put(d, v);
            }
            Op::Store(Dst::Own(at, relative), t, s) => {
                let v = self.src(s);
                let off = self.own(at, relative);
                self.write(off, t, v);
            }
            Op::SetOwn(at, relative, bytes) => {
                let off = self.own(at, relative);
                self.set(off, bytes);
            }
            Op::EqVarConst(ne, d, (at, relative), t, c) if !is_float(t) => {
                let off = self.own(at, relative);
                let x = self.read(off, t);
                let x = self.int(x);
                let cc = if ne { IntCC::NotEqual } else { IntCC::Equal };
                let c = self.b.ins().icmp_imm_s(cc, x, i64::from(c));
                let v = self.bool_int(c);
                self.put(d, v);
            }
            Op::Logic(o, d, a, b) => {
                let (x, y) = (self.src_int(a), self.src_int(b));
                let v = match o {
                    BinOp::And => self.b.ins().band(x, y),
                    BinOp::Or => self.b.ins().bor(x, y),
                    _ => self.b.ins().bxor(x, y),
                };
                self.put(d, Val::Int(v));
            }
            Op::BinI(o, t, d, a, b) => return self.bin_int(o, t, d, a, b, next),
            Op::Bin(o, t, d, a, b) if is_float(t) => return self.bin_real(o, t, d, a, b, next),
            Op::Neg(t, d, a) => {
                let v = self.src(a);
                let v = if is_float(t) {
                    let f = self.float(v);
                    Val::Real(self.b.ins().fneg(f))
                } else {
                    let x = self.int(v);
                    let x = self.b.ins().ineg(x);
                    Val::Int(self.wrap(x, t))
                };
                self.put(d, v);
            }
            Op::Not(t, d, a) => {
                let x = self.src_int(a);
                let v = if t == Elem::Bool {
                    let c = self.b.ins().icmp_imm_s(IntCC::Equal, x, 0);
                    self.bool_int(c)
                } else {
                    let x = self.b.ins().bnot(x);
                    Val::Int(self.wrap(x, t))
                };
                self.put(d, v);
            }
            Op::Conv(from, to, d, a) => return self.conv(from, to, d, a, next),
            Op::Inst(d, at, relative, slot1) => {
                let off = self.own(at, relative);
                let v = self.b.ins().bor_imm_s(off, i64::from(slot1) << 32);
                self.put(d, Val::Int(v));
            }
            Op::Input(inst, offset, t, s) => {
                let v = self.src(s);
                let off = self.in_instance(inst, offset);
                self.write(off, t, v);
            }
            Op::LoadVia(d, ptr, relative, plus, t) => {
                self.load_via(d, (ptr, relative, plus), t, next);
                return true;
            }
            Op::Store(Dst::Via(ptr, relative, plus), t, s) => {
                let v = self.src(s);
                self.store_via((ptr, relative, plus), t, v, next);
                return true;
            }
            Op::Switch(s, table) => return self.switch(s, table, next),
            Op::Call(c) => return self.block_call(c, next),
            Op::Elem(d, i, e) => return self.element(op, k, (d, i, e)),
            Op::JumpIn(s, range, to) => return self.jump_in(s, range, to, next),
            Op::ForTest(var, ty, regs, end) => return self.for_test(var, ty, regs, end, next),
            Op::ForNext(var, ty, regs, test, end) => {
                return self.for_next(var, ty, regs, (test, end))
            }
            Op::Output(inst, offset, (t, there), negated, Dst::Own(at, relative)) if t == there => {
                let off = self.in_instance(inst, offset);
                let mut v = self.read(off, t);
                if negated {
                    let x = self.int(v);
                    let c = self.b.ins().icmp_imm_s(IntCC::Equal, x, 0);
                    v = self.bool_int(c);
                }
                let off = self.own(at, relative);
                self.write(off, there, v);
            }
            _ => return false,
        }
        self.goto(next);
        true
    }
}
