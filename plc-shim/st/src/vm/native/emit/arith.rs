//! Arithmetic as instructions: [`super::Op::BinI`] (comparisons, the four operations,
//! logic, division), [`super::Op::Bin`] of reals and [`super::Op::Conv`] from integers, with
//! the rules of [`super::ops`].

use super::super::super::code::Src;
use super::super::super::Fault;
use super::{float_cc, int_cc, is_float, ops, Emit, Val};
use crate::ast::BinOp;
use crate::types::Elem;
use cranelift_codegen::ir::condcodes::{FloatCC, IntCC};
use cranelift_codegen::ir::{types, InstBuilder, Value};

impl Emit<'_, '_> {
    /// [`Op::BinI`]: comparisons, arithmetic, logic and division natively, the rest (none
    /// the checker makes) by the callback.
    pub(super) fn bin_int(&mut self, o: BinOp, t: Elem, d: u16, a: Src, b: Src, next: u64) -> bool {
        if let Some(cc) = int_cc(o, ops::unsigned(t)) {
            let (x, y) = (self.src_int(a), self.src_int(b));
            let c = self.b.ins().icmp(cc, x, y);
            let v = self.bool_int(c);
            self.put(d, v);
            self.goto(next);
            return true;
        }
        if matches!(o, BinOp::Div | BinOp::Mod) {
            let (x, y) = (self.src_int(a), self.src_int(b));
            let v = self.divide(o == BinOp::Div, ops::unsigned(t), x, y);
            let v = self.wrap(v, t);
            self.put(d, Val::Int(v));
            self.goto(next);
            return true;
        }
        if !matches!(
            o,
            BinOp::Add | BinOp::Sub | BinOp::Mul | BinOp::And | BinOp::Or | BinOp::Xor
        ) {
            return false;
        }
        let (x, y) = (self.src_int(a), self.src_int(b));
        let i = self.b.ins();
        let v = match o {
            BinOp::Add => i.iadd(x, y),
            BinOp::Sub => i.isub(x, y),
            BinOp::Mul => i.imul(x, y),
            BinOp::And => i.band(x, y),
            BinOp::Or => i.bor(x, y),
            _ => i.bxor(x, y),
        };
        let v = self.wrap(v, t);
        self.put(d, Val::Int(v));
        self.goto(next);
        true
    }

    /// `x / y` (`div`) or `x MOD y` of 64-bit integers as [`ops::binary_int`] computes them:
    /// a division by zero stops the body; with a sign, a divisor of -1 negates (wrapping, where
    /// the machine's division of the lowest value would trap) and leaves no remainder.
    fn divide(&mut self, div: bool, unsigned: bool, x: Value, y: Value) -> Value {
        let zero = self.b.ins().icmp_imm_s(IntCC::Equal, y, 0);
        self.fault_if(zero, Fault::DivisionByZero);
        let i = self.b.ins();
        if unsigned {
            return if div { i.udiv(x, y) } else { i.urem(x, y) };
        }
        let minus_one = self.b.ins().icmp_imm_s(IntCC::Equal, y, -1);
        let one = self.b.ins().iconst(types::I64, 1);
        let by = self.b.ins().select(minus_one, one, y);
        let (v, then) = if div {
            (self.b.ins().sdiv(x, by), self.b.ins().ineg(x))
        } else {
            (self.b.ins().srem(x, by), self.b.ins().iconst(types::I64, 0))
        };
        self.b.ins().select(minus_one, then, v)
    }

    /// [`Op::Bin`] of reals ([`ops::binary`]'s real half).
    pub(super) fn bin_real(
        &mut self,
        o: BinOp,
        t: Elem,
        d: u16,
        a: Src,
        b: Src,
        next: u64,
    ) -> bool {
        if float_cc(o).is_some() {
            let Some(c) = self.compare(o, t, a, b) else {
                return false;
            };
            let v = self.bool_int(c);
            self.put(d, v);
            self.goto(next);
            return true;
        }
        if !matches!(o, BinOp::Add | BinOp::Sub | BinOp::Mul | BinOp::Div) {
            return false;
        }
        let (x, y) = (self.src(a), self.src(b));
        let (x, y) = (self.float(x), self.float(y));
        let v = match o {
            BinOp::Add => self.b.ins().fadd(x, y),
            BinOp::Sub => self.b.ins().fsub(x, y),
            BinOp::Mul => self.b.ins().fmul(x, y),
            _ => {
                let zero = self.b.ins().f64const(0.0);
                let by_zero = self.b.ins().fcmp(FloatCC::Equal, y, zero);
                self.fault_if(by_zero, Fault::DivisionByZero);
                self.b.ins().fdiv(x, y)
            }
        };
        let v = self.finite(v);
        self.put(d, v);
        self.goto(next);
        true
    }

    /// [`Op::Conv`] between integers and from an integer to a real ([`ops::convert`]).
    pub(super) fn conv(&mut self, from: Elem, to: Elem, d: u16, a: Src, next: u64) -> bool {
        let durations = matches!(
            (from, to),
            (Elem::Time, Elem::LTime) | (Elem::LTime, Elem::Time)
        );
        if is_float(from) || durations {
            return false;
        }
        let x = self.src_int(a);
        let v = if is_float(to) {
            let f = if ops::unsigned(from) {
                self.b.ins().fcvt_from_uint(types::F64, x)
            } else {
                self.b.ins().fcvt_from_sint(types::F64, x)
            };
            Val::Real(f)
        } else if to == Elem::Bool {
            let c = self.b.ins().icmp_imm_s(IntCC::NotEqual, x, 0);
            self.bool_int(c)
        } else {
            Val::Int(self.wrap(x, to))
        };
        self.put(d, v);
        self.goto(next);
        true
    }
}
