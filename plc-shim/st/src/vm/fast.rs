//! Operations specialized to their operands' kinds: once a body's operations are built,
//! the most frequent shapes of the machine programs are rewritten into operations that
//! decide nothing at run time that was known at load (which kind of operand, which
//! operation, how a constant is stored). Each does what the general operation it replaces
//! does, the same faults at the same places; `tests/it/two_ways.rs` runs both against the
//! tree walker.
//!
//! * a constant stored into the program's own memory ([`Op::SetOwn`]): its bytes computed
//!   here, by the same [`write_mem`] the store would run (`eStep := SawSync;`,
//!   `axConveyor.AxisIndex := 27;`, `fBladeTarget := 0.0;`);
//! * a variable compared with a constant for equality ([`Op::EqVarConst`]): the state
//!   machines' `eStep = SawDown` (equality does not depend on the type's sign: both values
//!   are read as the type gives them);
//! * a block call's constant input ([`Input::Const`]): its bytes, as for [`Op::SetOwn`]
//!   (`Velocity := 360.0`);
//! * AND, OR and XOR of BOOLs ([`Op::Logic`]): both operands 0 or 1, so the result needs no
//!   wrapping to the type.

use super::code::{Dst, Op, Src};
use super::mem::write_mem;
use super::V;
use crate::ast::BinOp;
use crate::types::Elem;

/// The bytes a constant is stored as, little-endian as the program's memory holds it.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Bytes {
    B1([u8; 1]),
    B2([u8; 2]),
    B4([u8; 4]),
    B8([u8; 8]),
}

impl Bytes {
    /// The bytes `v` is stored as in type `t` (`None`: a width no elementary type has).
    fn of(t: Elem, v: V) -> Option<Bytes> {
        let mut buf = [0u8; 8];
        write_mem(&mut buf, 0, t, v).ok()?;
        let part = |n: usize| buf.get(..n);
        Some(match t.size() {
            1 => Bytes::B1(part(1)?.try_into().ok()?),
            2 => Bytes::B2(part(2)?.try_into().ok()?),
            4 => Bytes::B4(part(4)?.try_into().ok()?),
            8 => Bytes::B8(buf),
            _ => return None,
        })
    }
}

/// A whole block call's input ([`super::code::Codes::inputs`]).
#[derive(Debug, Clone, Copy)]
pub(crate) enum Input {
    /// A constant's bytes.
    Const(Bytes),
    /// A value of the type from an operand.
    Value(Elem, Src),
}

/// The value of operand `s` when it is a constant (`consts`: the pool).
fn constant(s: Src, consts: &[V]) -> Option<V> {
    match s {
        Src::I(x) => Some(V::I(i64::from(x))),
        Src::K(k) => consts.get(k as usize).copied(),
        _ => None,
    }
}

/// An input of type `t` given by operand `v`.
pub(super) fn input(t: Elem, v: Src, consts: &[V]) -> Input {
    let constant = constant(v, consts).and_then(|c| Bytes::of(t, c));
    constant.map_or(Input::Value(t, v), Input::Const)
}

/// The operation `op` specialized to its operands, or `op` itself.
pub(super) fn specialize(op: Op, consts: &[V]) -> Op {
    match op {
        Op::Store(Dst::Own(at, relative), t, s) => {
            match constant(s, consts).and_then(|v| Bytes::of(t, v)) {
                Some(bytes) => Op::SetOwn(at, relative, bytes),
                None => op,
            }
        }
        Op::BinI(o @ (BinOp::Eq | BinOp::Ne), _, d, Src::Var(at, relative, t), Src::I(c)) => {
            Op::EqVarConst(o == BinOp::Ne, d, (at, relative), t, c)
        }
        Op::BinI(o @ (BinOp::And | BinOp::Or | BinOp::Xor), Elem::Bool, d, a, b) => {
            Op::Logic(o, d, a, b)
        }
        _ => op,
    }
}

/// `a op b` of two BOOLs (0 or 1) as [`Op::Logic`] computes it.
#[inline(always)]
pub(super) fn logic(op: BinOp, a: i64, b: i64) -> i64 {
    match op {
        BinOp::And => a & b,
        BinOp::Or => a | b,
        _ => a ^ b,
    }
}

/// Stores `bytes` at `at` of the program's memory (a place beyond it is the store's fault).
#[inline(always)]
pub(super) fn set(m: &mut [u8], at: usize, bytes: Bytes) -> super::Run<()> {
    fn put<const N: usize>(m: &mut [u8], at: usize, b: [u8; N]) -> super::Run<()> {
        let slot = m.get_mut(at..at + N).ok_or(super::Fault::BadPointer)?;
        slot.copy_from_slice(&b);
        Ok(())
    }
    match bytes {
        Bytes::B1(b) => put(m, at, b),
        Bytes::B2(b) => put(m, at, b),
        Bytes::B4(b) => put(m, at, b),
        Bytes::B8(b) => put(m, at, b),
    }
}
