//! The control flow the callback ran before: a CASE's table and ranges, a FOR's test and
//! next value ([`super::super::super::run`]'s rules for them).

use super::super::super::code::{Op, Src, NEXT};
use super::{Emit, Val};
use crate::types::Elem;
use cranelift_codegen::ir::condcodes::IntCC;
use cranelift_codegen::ir::{types, InstBuilder, Value};
use cranelift_frontend::Switch;

impl Emit<'_, '_> {
    /// Register `r`'s word where an integer is wanted.
    fn reg_int(&mut self, r: u16) -> Value {
        let p = self.reg(r);
        self.b.ins().load(types::I64, super::F, p, 0)
    }

    /// Whether `lo <= v <= hi` (with their signs).
    fn within(&mut self, v: Value, lo: i64, hi: i64) -> Value {
        let above = self
            .b
            .ins()
            .icmp_imm_s(IntCC::SignedGreaterThanOrEqual, v, lo);
        let below = self.b.ins().icmp_imm_s(IntCC::SignedLessThanOrEqual, v, hi);
        self.b.ins().band(above, below)
    }

    /// [`super::Op::Switch`]: the table's operation for the value, else the next one.
    pub(super) fn switch(&mut self, s: Src, table: u32, next: u64) -> bool {
        let Some(t) = self.codes.switches.get(table as usize) else {
            return false;
        };
        let (lo, to) = (t.lo, t.to.clone());
        let Some(hi) = i64::try_from(to.len())
            .ok()
            .and_then(|n| lo.checked_add(n - 1))
        else {
            return false;
        };
        let v = self.src_int(s);
        let inside = self.within(v, lo, hi);
        let (table_block, after) = (self.b.create_block(), self.to(next));
        self.b.ins().brif(inside, table_block, &[], after, &[]);
        self.b.switch_to_block(table_block);
        let k = self.b.ins().iadd_imm_s(v, lo.wrapping_neg());
        let mut sw = Switch::new();
        for (i, &t) in to.iter().enumerate() {
            if t != NEXT {
                sw.set_entry(i as u128, self.to(u64::from(t)));
            }
        }
        sw.emit(&mut self.b, k, after);
        true
    }

    /// [`super::Op::JumpIn`]: on at `to` when the value lies in the range.
    pub(super) fn jump_in(&mut self, s: Src, range: u32, to: u32, next: u64) -> bool {
        let Some(&(lo, hi)) = self.codes.ranges.get(range as usize) else {
            return false;
        };
        let v = self.src_int(s);
        let inside = self.within(v, lo, hi);
        let (yes, no) = (self.to(u64::from(to)), self.to(next));
        self.b.ins().brif(inside, yes, &[], no, &[]);
        true
    }

    /// [`super::Op::ForTest`]: past the last value on at `end`, else the value stored and a
    /// step taken.
    pub(super) fn for_test(
        &mut self,
        (at, relative): (u32, bool),
        ty: Elem,
        [i, last, step]: [u16; 3],
        end: u32,
        next: u64,
    ) -> bool {
        let (i, last, step) = (self.reg_int(i), self.reg_int(last), self.reg_int(step));
        let up = self
            .b
            .ins()
            .icmp_imm_s(IntCC::SignedGreaterThanOrEqual, step, 0);
        let above = self.b.ins().icmp(IntCC::SignedGreaterThan, i, last);
        let below = self.b.ins().icmp(IntCC::SignedLessThan, i, last);
        let past = self.b.ins().select(up, above, below);
        let (go, past_end) = (self.b.create_block(), self.to(u64::from(end)));
        self.b.ins().brif(past, past_end, &[], go, &[]);
        self.b.switch_to_block(go);
        let off = self.own(at, relative);
        self.write(off, ty, Val::Int(i));
        self.step();
        self.goto(next);
        true
    }

    /// [`super::Op::ForNext`]: the variable read back plus the step, on at `test`; at `end`
    /// when the sum overflows.
    pub(super) fn for_next(
        &mut self,
        (at, relative): (u32, bool),
        ty: Elem,
        [i, _, step]: [u16; 3],
        (test, end): (u32, u32),
    ) -> bool {
        let now = self.src_int(Src::Var(at, relative, ty));
        let step = self.reg_int(step);
        let sum = self.b.ins().iadd(now, step);
        // Overflow: both operands' signs differ from the sum's.
        let a = self.b.ins().bxor(now, sum);
        let b = self.b.ins().bxor(step, sum);
        let both = self.b.ins().band(a, b);
        let over = self.b.ins().icmp_imm_s(IntCC::SignedLessThan, both, 0);
        let (go, past) = (self.b.create_block(), self.to(u64::from(end)));
        self.b.ins().brif(over, past, &[], go, &[]);
        self.b.switch_to_block(go);
        self.put(i, Val::Int(sum));
        self.goto(u64::from(test));
        true
    }

    /// [`super::Op::Elem`] `op` (the `k`th): an index within the bounds natively, one
    /// beyond them by the callback (its fault names the index and the bounds).
    pub(super) fn element(&mut self, op: Op, k: usize, (d, i, e): (u16, Src, u32)) -> bool {
        let Some(e) = self.codes.elems.get(e as usize).copied() else {
            return false;
        };
        let Some(hi) = e.lo.checked_add(i64::from(e.len) - 1) else {
            return false;
        };
        let v = self.src_int(i);
        let inside = self.within(v, e.lo, hi);
        let (fast, slow) = (self.b.create_block(), self.b.create_block());
        self.b.ins().brif(inside, fast, &[], slow, &[]);
        self.b.switch_to_block(slow);
        self.callback(op, k);
        self.b.switch_to_block(fast);
        let index = self.b.ins().iadd_imm_s(v, e.lo.wrapping_neg());
        let start = self.own(e.at, e.relative);
        let step = self.b.ins().imul_imm_s(index, i64::from(e.stride));
        let at = self.b.ins().iadd(start, step);
        let at = self.b.ins().iadd_imm_s(at, i64::from(e.plus));
        let v = match e.instance {
            // A tagged pointer into the program's memory (`tagged`).
            None => self.b.ins().iadd_imm_s(at, 1),
            Some(0) => at,
            // The instance's offset and its host slot plus one (`slotted`).
            Some(first) => {
                let at = self.b.ins().band_imm_s(at, i64::from(u32::MAX));
                let slot = self.b.ins().iadd_imm_s(index, i64::from(first));
                let slot = self.b.ins().band_imm_s(slot, i64::from(u32::MAX));
                let slot = self.b.ins().ishl_imm_s(slot, 32);
                self.b.ins().bor(at, slot)
            }
        };
        self.put(d, Val::Int(v));
        self.goto(k as u64 + 1);
        true
    }
}
