//! A block call's operations: in one operation ([`Op::Call`]) when its instance has a fixed
//! place and its inputs are operands or values that can be computed before it, else its
//! inputs stored one by one and its body run ([`Op::Body`]); the host's slot of a library
//! block's instance found at load wherever its place is fixed (or an array's element at a
//! computed index of consecutive slots).

use super::{operand, own, Builder};
use crate::ast::BinOp;
use crate::check::std_lib::StdFb;
use crate::ir::{Addr, BlockInput, BlockOutput, Ex, St};
use crate::types::Class;
use crate::vm::code::{CallOp, Dst, ElemOp, Op, Src, R};
use crate::vm::fast;

impl Builder<'_> {
    /// The bytes of an instance of the POU or standard block.
    fn size(&self, body: Result<u32, StdFb>) -> u32 {
        match body {
            Ok(pou) => self
                .codes
                .sizes
                .get(pou as usize)
                .copied()
                .unwrap_or(u32::MAX),
            Err(fb) => crate::layout::std_fb(fb).1,
        }
    }

    pub(super) fn call(
        &mut self,
        s: &St,
        instance: &Addr,
        inputs: &[BlockInput],
        outputs: &[BlockOutput],
        body: Result<u32, StdFb>,
    ) {
        let site = self.site(s);
        if let Some(Dst::Own(at, relative)) = own(instance) {
            let place = (at, relative, self.size(body));
            if inputs.iter().all(|(_, _, e)| hoistable(e, place)) {
                // Computed before the call: none faults or reads the instance, so it is as
                // if each were computed just before its input is stored.
                let mark = self.next;
                let values = inputs.iter().map(|(_, _, e)| self.expr(e)).collect();
                self.whole_call(site, (at, relative), inputs, values, body, outputs);
                self.next = mark;
                return;
            }
        }
        self.ops.push(Op::Stmt(site));
        let inst = self.reg();
        let fixed = match own(instance) {
            Some(Dst::Own(at, relative)) => Some((at, relative)),
            _ => None,
        };
        match fixed {
            Some((at, relative)) => {
                let slot1 = self.host_slot(body, at, relative).map_or(0, |s| s + 1);
                self.ops.push(Op::Inst(inst, at, relative, slot1));
            }
            _ => match index_place(instance) {
                Some((mut e, index)) if e.plus == 0 => {
                    let host = self.host_slot(body, e.at, e.relative).is_some();
                    e.instance = Some(if host { self.slots(&e).unwrap_or(0) } else { 0 });
                    self.element(inst, e, index);
                }
                _ => {
                    let k = self.place(instance);
                    self.ops.push(Op::InstTree(inst, k));
                }
            },
        }
        for (offset, t, e) in inputs {
            let mark = self.next;
            let v = self.expr(e);
            // An instance at a fixed place: its input is a variable there.
            let input = fixed.and_then(|(at, r)| Some((at.checked_add(*offset)?, r)));
            self.ops.push(match input {
                Some((at, relative)) => Op::Store(Dst::Own(at, relative), *t, v),
                None => Op::Input(inst, *offset, *t, v),
            });
            self.next = mark;
        }
        self.codes.calls.push(inputs.to_vec());
        let call = (self.codes.calls.len() - 1) as u32;
        self.ops.push(match body {
            Ok(pou) => Op::Body(pou, inst, call),
            Err(fb) => Op::StdBody(fb, inst, call),
        });
        self.ops.push(Op::At(site));
        for (offset, t, target, negated, there) in outputs {
            let mark = self.next;
            let to = self.dst(target);
            self.ops
                .push(Op::Output(inst, *offset, (*t, *there), *negated, to));
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
            let input = fast::input(*t, v, &self.codes.consts);
            self.codes.inputs.push((*offset, input));
        }
        self.codes.calls.push(inputs.to_vec());
        let slot = self.host_slot(body, at, relative);
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
        self.ops.push(Op::Inst(inst, at, relative, 0));
        for (offset, t, target, negated, there) in outputs {
            let mark = self.next;
            let to = self.dst(target);
            self.ops
                .push(Op::Output(inst, *offset, (*t, *there), *negated, to));
            self.next = mark;
        }
    }

    /// The host's slot of the library block instance `body` at absolute place `at`; `None`
    /// for another block, a place from an instance's base, or no instance there.
    fn host_slot(&self, body: Result<u32, StdFb>, at: u32, relative: bool) -> Option<u32> {
        let pou = body.ok()? as usize;
        self.library.of_pou.get(pou).copied().flatten()?;
        (!relative).then(|| self.library.slot_at(at)).flatten()
    }

    /// The host slot plus one of the first of an array's elements when they are a
    /// library block's instances in consecutive slots (absolute places only).
    fn slots(&self, e: &ElemOp) -> Option<u32> {
        if e.relative {
            return None;
        }
        let first = self.library.slot_at(e.at)?;
        let consecutive = (0..e.len).all(|j| {
            let at = j.checked_mul(e.stride).and_then(|o| o.checked_add(e.at));
            at.and_then(|at| self.library.slot_at(at)) == first.checked_add(j)
        });
        consecutive.then(|| first.checked_add(1)).flatten()
    }

    /// `d :=` element `e` at the index `index` gives ([`Op::Elem`]).
    pub(super) fn element(&mut self, d: R, e: ElemOp, index: &Ex) {
        let mark = self.next;
        let i = self.expr(index);
        self.next = mark;
        self.codes.elems.push(e);
        let k = (self.codes.elems.len() - 1) as u32;
        self.ops.push(Op::Elem(d, i, k));
    }
}

/// An element of an array at a fixed place at an index that is no constant within its
/// bounds (`a[i]`, `a[i].field`): the element's description (a pointer's) and the index.
pub(super) fn index_place(a: &Addr) -> Option<(ElemOp, &Ex)> {
    match a {
        Addr::Offset(inner, plus) => {
            let (mut e, index) = index_place(inner)?;
            e.plus = e.plus.checked_add(*plus)?;
            Some((e, index))
        }
        Addr::Index {
            base,
            index,
            lo,
            len,
            stride,
        } => match own(base)? {
            Dst::Own(at, relative) => Some((
                ElemOp {
                    at,
                    relative,
                    lo: *lo,
                    len: *len,
                    stride: *stride,
                    plus: 0,
                    instance: None,
                },
                index,
            )),
            _ => None,
        },
        _ => None,
    }
}

/// Whether input value `e` may be computed before the call of the instance at `place`
/// (offset, relative, size) instead of just before its input is stored: an operand, or a
/// computation that cannot fault and reads no byte of the instance (comparisons, integer
/// arithmetic and logic, NOT, negation, integers to reals, of constants and variables at
/// fixed places outside it).
fn hoistable(e: &Ex, place: (u32, bool, u32)) -> bool {
    let outside = |at: u32, relative: bool, width: usize| {
        let (start, same, size) = place;
        let end = u64::from(at) + width as u64;
        relative == same
            && (end <= u64::from(start) || u64::from(at) >= u64::from(start) + u64::from(size))
    };
    match e {
        Ex::Int(_) | Ex::Real(_) => true,
        Ex::Var {
            offset,
            relative,
            ty,
        } => outside(*offset, *relative, ty.size()),
        Ex::Load(a, t) => matches!(own(a), Some(Dst::Own(at, r)) if outside(at, r, t.size())),
        Ex::Not(x, _) | Ex::Neg(x, _) => hoistable(x, place),
        Ex::Conv(from, to, x) => {
            from.class() != Class::Float && to.class() == Class::Float && hoistable(x, place)
        }
        Ex::Bin(op, t, a, b) => {
            let compares = matches!(
                op,
                BinOp::Eq | BinOp::Ne | BinOp::Lt | BinOp::Gt | BinOp::Le | BinOp::Ge
            );
            let wraps = t.class() != Class::Float
                && matches!(
                    op,
                    BinOp::Add | BinOp::Sub | BinOp::Mul | BinOp::And | BinOp::Or | BinOp::Xor
                );
            (compares || wraps) && hoistable(a, place) && hoistable(b, place)
        }
        _ => operand(e),
    }
}
