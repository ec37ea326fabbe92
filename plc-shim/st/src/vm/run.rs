//! Runs a body's operations ([`super::code`]): a program counter over the list, each
//! operation reading its operands (registers of the body's window, constants, variables),
//! the rules of values, places and faults those of the tree walker.

use super::code::{slotted, CallOp, Code, Dst, ElemOp, Op, Src, NEXT};
use super::fast::{self, Input};
use super::{ops, pointed, tagged, Exec, Fault, Flow, Loc, Run, IMAGE_TAG, V};
use crate::types::Elem;

/// As [`tagged`] for a place about to be read or written: one whose tag would not come back
/// as the same place (beyond the pointers' range, where the access faults anyway) is the
/// access's fault now.
fn access_tag(at: Loc) -> Run<V> {
    let (Loc::Own(n) | Loc::Image(n)) = at;
    if n as u64 >= (IMAGE_TAG as u64) - 1 {
        return Err(Fault::BadPointer);
    }
    Ok(V::I(tagged(at)))
}

/// [`Exec::one`]'s next operation when the body ends.
pub(super) const END: usize = usize::MAX;

/// Where a body runs: its instance's base, its registers' window, and where its callees'
/// windows start.
#[derive(Debug, Clone, Copy)]
pub(super) struct Frame {
    pub(super) base: u32,
    pub(super) w: usize,
    pub(super) top: usize,
}

impl<'a> Exec<'a> {
    /// Body `code` on the instance at `base`, its registers from the window's start on:
    /// in native code when the body was compiled to it ([`super::native`]), else operation
    /// by operation.
    pub(super) fn run_code(&mut self, code: &'a Code, base: u32) -> Run<()> {
        let w = self.window;
        // Where what this body calls keeps its registers.
        let top = w + usize::from(code.regs);
        if top > self.st.regs.len() {
            return Err(Fault::BadPointer);
        }
        self.run_native(code, Frame { base, w, top })
    }

    /// Body `code` operation by operation.
    pub(super) fn run_ops(&mut self, code: &'a Code, at: Frame) -> Run<()> {
        let mut pc = 0;
        while pc < code.ops.len() {
            pc = self.one(code, pc, at)?;
        }
        Ok(())
    }

    /// Operation `pc` of `code`: the index of the operation that follows ([`END`]: the
    /// body ends).
    #[inline(always)]
    pub(super) fn one(&mut self, code: &'a Code, pc: usize, at: Frame) -> Run<usize> {
        let Frame { base, w, top } = at;
        let codes = self.codes;
        let Some(op) = code.ops.get(pc) else {
            return Ok(END);
        };
        let mut pc = pc + 1;
        match *op {
            Op::Stmt(k) => {
                self.st.site = k;
                self.step()?;
            }
            Op::Step => self.step()?,
            Op::At(k) => self.st.site = k,
            Op::Bin(op, t, d, a, b) => {
                let (x, y) = (self.src(a, base, w)?, self.src(b, base, w)?);
                let v = ops::binary(op, t, x, y)?;
                self.put(w, d, v);
            }
            Op::BinI(op, t, d, a, b) => {
                let (x, y) = (self.src_int(a, base, w)?, self.src_int(b, base, w)?);
                let v = ops::binary_int(op, t, x, y)?;
                self.put(w, d, V::I(v));
            }
            Op::Neg(t, d, a) => {
                let v = ops::neg(self.src(a, base, w)?, t);
                self.put(w, d, v);
            }
            Op::Not(t, d, a) => {
                let v = ops::not(V::I(self.src_int(a, base, w)?), t);
                self.put(w, d, v);
            }
            Op::Conv(from, to, d, a) => {
                let v = ops::convert(self.src(a, base, w)?, from, to)?;
                self.put(w, d, v);
            }
            Op::Mov(d, a) => {
                let v = self.src(a, base, w)?;
                self.put(w, d, v);
            }
            Op::LoadVia(d, ptr, relative, plus, t) => {
                let at = self.via(ptr, relative, plus, base)?;
                let v = self.read(at, t)?;
                self.put(w, d, v);
            }
            Op::PtrAt(d, p, plus, access) => {
                let at = pointed(self.src_int(p, base, w)?)?.plus(plus as usize);
                let v = if access {
                    access_tag(at)?
                } else {
                    V::I(tagged(at))
                };
                self.put(w, d, v);
            }
            Op::LoadAt(d, r, t) => {
                let at = pointed(self.get_int(w, r))?;
                let v = self.read(at, t)?;
                self.put(w, d, v);
            }
            Op::Tree(d, k) => {
                let e = &codes.exprs[k as usize];
                let v = self.nested(top, |x| x.eval(e, base))?;
                self.put(w, d, v);
            }
            Op::Addr(d, k) => {
                let a = &codes.places[k as usize];
                let at = self.nested(top, |x| x.addr(a, base))?;
                self.put(w, d, access_tag(at)?);
            }
            Op::Store(to, t, s) => {
                let v = self.src(s, base, w)?;
                self.store(to, t, v, base, w)?;
            }
            Op::StorePtr(to, s) => {
                let v = self.src(s, base, w)?;
                self.store(to, Elem::ULInt, v, base, w)?;
            }
            Op::TreeSt(k, exit, next) => {
                let s = &codes.stmts[k as usize];
                let to = match self.nested(top, |x| x.statement(s, base))? {
                    Flow::Next => return Ok(pc),
                    Flow::Exit => exit,
                    Flow::Continue => next,
                    Flow::Return => u32::MAX,
                };
                if to == u32::MAX {
                    return Ok(END);
                }
                pc = to as usize;
            }
            Op::Jump(to) => pc = to as usize,
            Op::JumpIf(c, to) => {
                if self.src_int(c, base, w)? != 0 {
                    pc = to as usize;
                }
            }
            Op::JumpIfNot(c, to) => {
                if self.src_int(c, base, w)? == 0 {
                    pc = to as usize;
                }
            }
            Op::JumpCmp(op, t, a, b, to) => {
                let (x, y) = (self.src(a, base, w)?, self.src(b, base, w)?);
                if !ops::compare(op, t, x, y) {
                    pc = to as usize;
                }
            }
            Op::JumpCmpI(op, t, a, b, to) => {
                let (x, y) = (self.src_int(a, base, w)?, self.src_int(b, base, w)?);
                if !ops::compare_int(op, t, x, y) {
                    pc = to as usize;
                }
            }
            Op::Switch(s, k) => {
                let table = &codes.switches[k as usize];
                let i = self.src_int(s, base, w)?.checked_sub(table.lo);
                let i = i.and_then(|i| usize::try_from(i).ok());
                let to = i.and_then(|i| table.to.get(i));
                if let Some(&to) = to.filter(|t| **t != NEXT) {
                    pc = to as usize;
                }
            }
            Op::JumpIn(s, k, to) => {
                let (lo, hi) = codes.ranges[k as usize];
                if (lo..=hi).contains(&self.src_int(s, base, w)?) {
                    pc = to as usize;
                }
            }
            Op::ForTest((at, relative), ty, [i, last, step], end) => {
                let reg = |r: u16| self.get_int(w, r);
                let (i, last, step) = (reg(i), reg(last), reg(step));
                if (step >= 0 && i > last) || (step < 0 && i < last) {
                    pc = end as usize;
                } else {
                    self.store(Dst::Own(at, relative), ty, V::I(i), base, w)?;
                    self.step()?;
                }
            }
            Op::ForNext((at, relative), ty, [i, _, step], test, end) => {
                let now = self.src(Src::Var(at, relative, ty), base, w)?.int();
                let step = self.get_int(w, step);
                match now.checked_add(step) {
                    Some(next) => {
                        self.put(w, i, V::I(next));
                        pc = test as usize;
                    }
                    None => pc = end as usize,
                }
            }
            Op::Inst(d, at, relative, slot1) => {
                let at = if relative { base + at } else { at };
                self.put(w, d, V::I(slotted(at, slot1)));
            }
            Op::Elem(d, i, k) => {
                let i = self.src_int(i, base, w)?;
                let v = self.element(&codes.elems[k as usize], i, base)?;
                self.put(w, d, v);
            }
            Op::InstTree(d, k) => {
                let a = &codes.places[k as usize];
                let at = self.nested(top, |x| x.own(a, base))?;
                self.put(w, d, V::I(at as i64));
            }
            Op::Input(inst, offset, t, s) => {
                let v = self.src(s, base, w)?;
                let at = self.instance(inst, w) + offset;
                self.write_own(at as usize, t, v)?;
            }
            Op::Body(pou, inst, call) => {
                self.passing = &codes.calls[call as usize];
                // The instance's offset, and its host slot plus one when found at load.
                let v = self.get_int(w, inst);
                let (at, slot1) = (v as u32, (v >> 32) as u32);
                match self.library.of_pou[pou as usize] {
                    Some(block) if slot1 > 0 => self.call_host_at(block, at, slot1 as usize - 1)?,
                    _ => self.nested(top, |x| x.run_body(pou as usize, at))?,
                }
            }
            Op::StdBody(fb, inst, call) => {
                self.passing = &codes.calls[call as usize];
                let at = self.instance(inst, w);
                self.run_std_fb(fb, at as usize)?;
            }
            Op::Output(inst, offset, (t, there), negated, to) => {
                let at = self.instance(inst, w) + offset;
                let v = self.read_own(at as usize, t)?;
                let v = ops::output(v, negated, t, there)?;
                self.store(to, there, v, base, w)?;
            }
            Op::SetOwn(at, relative, bytes) => {
                let at = if relative { base + at } else { at };
                fast::set(&mut self.st.memory, at as usize, bytes)?;
            }
            Op::EqVarConst(ne, d, (at, relative), t, c) => {
                let at = if relative { base + at } else { at };
                let x = self.read_own(at as usize, t)?.int();
                self.put(w, d, V::I(i64::from((x == i64::from(c)) != ne)));
            }
            Op::Logic(op, d, a, b) => {
                let (x, y) = (self.src_int(a, base, w)?, self.src_int(b, base, w)?);
                self.put(w, d, V::I(fast::logic(op, x, y)));
            }
            Op::Call(k) => self.call(&codes.call_ops[k as usize], base, w, top)?,
            Op::Ret => return Ok(END),
        }
        Ok(pc)
    }

    /// Register `r` of the window at `w` (a register is a word and a flag for a real, never
    /// copied as a whole value: the copy's wide load would wait for the two narrow stores).
    #[inline(always)]
    fn get(&self, w: usize, r: u16) -> V {
        let reg = &self.st.regs[w + usize::from(r)];
        if reg.real {
            V::F(f64::from_bits(reg.bits))
        } else {
            V::I(reg.bits as i64)
        }
    }

    /// Register `r` of the window at `w` where an integer is wanted (a condition, a
    /// selector, a pointer, an instance, an integer operation's operand): the type
    /// checker never gives a real there.
    #[inline(always)]
    fn get_int(&self, w: usize, r: u16) -> i64 {
        let reg = &self.st.regs[w + usize::from(r)];
        debug_assert!(!reg.real, "a real where an integer is wanted");
        reg.bits as i64
    }

    #[inline(always)]
    fn put(&mut self, w: usize, r: u16, v: V) {
        let (bits, real) = match v {
            V::I(x) => (x as u64, false),
            V::F(x) => (x.to_bits(), true),
        };
        let reg = &mut self.st.regs[w + usize::from(r)];
        reg.bits = bits;
        reg.real = real;
    }

    /// A whole block call ([`Op::Call`]): as the tree's, its inputs stored one after the
    /// other, the body run, the statement's place set again for its outputs.
    fn call(&mut self, c: &'a CallOp, base: u32, w: usize, top: usize) -> Run<()> {
        let codes = self.codes;
        self.st.site = c.site;
        self.step()?;
        let at = if c.relative { base + c.at } else { c.at };
        let (first, end) = (c.inputs.0 as usize, c.inputs.1 as usize);
        for &(offset, input) in &codes.inputs[first..end] {
            let to = (at + offset) as usize;
            match input {
                Input::Const(bytes) => fast::set(&mut self.st.memory, to, bytes)?,
                Input::Value(t, s) => {
                    let v = self.src(s, base, w)?;
                    self.write_own(to, t, v)?;
                }
            }
        }
        self.call_body(c, top, at)
    }

    /// The body of [`Op::Call`] `c` on its instance at `at` (its inputs stored): the call's
    /// inputs passed, the block or POU run, the statement's place set again for its outputs.
    pub(super) fn call_body(&mut self, c: &'a CallOp, top: usize, at: u32) -> Run<()> {
        let codes = self.codes;
        self.passing = &codes.calls[c.call as usize];
        match c.body {
            Ok(pou) => match (c.slot, self.library.of_pou[pou as usize]) {
                (Some(slot), Some(block)) => self.call_host_at(block, at, slot as usize)?,
                _ => self.nested(top, |x| x.run_body(pou as usize, at))?,
            },
            Err(fb) => self.run_std_fb(fb, at as usize)?,
        }
        self.st.site = c.site;
        Ok(())
    }

    /// Element `e` at index `i`: its tagged pointer, or its instance's offset (and host
    /// slot); an index beyond the bounds is the tree's fault, with the same numbers.
    fn element(&mut self, e: &ElemOp, i: i64, base: u32) -> Run<V> {
        let hi = e.lo + i64::from(e.len) - 1;
        if i < e.lo || i > hi {
            return Err(self.fault_with(Fault::IndexOutOfRange, [i, e.lo, hi]));
        }
        let k = (i - e.lo) as usize;
        let start = if e.relative { base + e.at } else { e.at } as usize;
        let at = start + k * e.stride as usize + e.plus as usize;
        match e.instance {
            None => access_tag(Loc::Own(at)),
            Some(0) => Ok(V::I(at as i64)),
            Some(first) => Ok(V::I(slotted(at as u32, first + k as u32))),
        }
    }

    /// `f` with the register window above this body's (from `top` on).
    #[inline]
    fn nested<T>(&mut self, top: usize, f: impl FnOnce(&mut Self) -> Run<T>) -> Run<T> {
        let saved = std::mem::replace(&mut self.window, top);
        let r = f(self);
        self.window = saved;
        r
    }

    /// The instance offset register `r` holds.
    #[inline]
    fn instance(&self, r: u16, w: usize) -> u32 {
        self.get_int(w, r) as u32
    }

    /// Operand `s` where an integer is wanted ([`Exec::get_int`]).
    #[inline(always)]
    fn src_int(&self, s: Src, base: u32, w: usize) -> Run<i64> {
        match s {
            Src::R(r) => Ok(self.get_int(w, r)),
            Src::I(v) => Ok(i64::from(v)),
            Src::K(k) => Ok(self.codes.consts[k as usize].int()),
            Src::Var(at, relative, t) => {
                let at = if relative { base + at } else { at };
                self.read_own(at as usize, t).map(V::int)
            }
        }
    }

    #[inline(always)]
    fn src(&self, s: Src, base: u32, w: usize) -> Run<V> {
        match s {
            Src::R(r) => Ok(self.get(w, r)),
            Src::I(v) => Ok(V::I(i64::from(v))),
            Src::K(k) => Ok(self.codes.consts[k as usize]),
            Src::Var(at, relative, t) => {
                let at = if relative { base + at } else { at };
                self.read_own(at as usize, t)
            }
        }
    }

    #[inline]
    fn store(&mut self, to: Dst, t: Elem, v: V, base: u32, w: usize) -> Run<()> {
        match to {
            Dst::Own(at, relative) => {
                let at = if relative { base + at } else { at };
                self.write_own(at as usize, t, v)
            }
            Dst::Via(ptr, relative, plus) => {
                let at = self.via(ptr, relative, plus, base)?;
                self.write(at, t, v)
            }
            Dst::At(r) => {
                let at = pointed(self.get(w, r).int())?;
                self.write(at, t, v)
            }
        }
    }
}
