//! Places the lowering computes: an address moved on by a fixed offset, the strides of an
//! array, the leaves of a structure input, a single bit written.

use super::expr::Ctx;
use super::lower::R;
use super::{Checker, Type};
use crate::ast::{BinOp, Expr};
use crate::ir::{Addr, Ex, StKind, StdFn};
use crate::layout::Layout;
use crate::types::Elem;

/// `addr` moved on by `offset` bytes, folded into a fixed place or an offset it already has.
pub(super) fn plus(addr: Addr, offset: u32) -> Addr {
    match addr {
        Addr::Static(at) if at.checked_add(offset).is_some() => Addr::Static(at + offset),
        Addr::Instance(at) if at.checked_add(offset).is_some() => Addr::Instance(at + offset),
        Addr::Offset(inner, at) if at.checked_add(offset).is_some() => {
            Addr::Offset(inner, at + offset)
        }
        Addr::Via {
            ptr,
            relative,
            plus,
        } if plus.checked_add(offset).is_some() => Addr::Via {
            ptr,
            relative,
            plus: plus + offset,
        },
        other => Addr::Offset(Box::new(other), offset),
    }
}

/// Where pointer value `p` points: a pointer variable's (`p^`) in one step.
pub(super) fn deref(p: Ex) -> Addr {
    match p {
        Ex::LoadPtr(a) => match *a {
            Addr::Static(ptr) => Addr::Via {
                ptr,
                relative: false,
                plus: 0,
            },
            Addr::Instance(ptr) => Addr::Via {
                ptr,
                relative: true,
                plus: 0,
            },
            other => Addr::Deref(Box::new(Ex::LoadPtr(Box::new(other)))),
        },
        other => Addr::Deref(Box::new(other)),
    }
}

/// The byte stride of each dimension of an array (last dimension fastest), `None` where the
/// whole array would not fit in 32 bits of address.
pub(super) fn strides(element: u64, lens: &[u64]) -> Option<Vec<u32>> {
    let mut strides = vec![0u32; lens.len()];
    let mut stride = element;
    for k in (0..lens.len()).rev() {
        strides[k] = u32::try_from(stride).ok()?;
        u32::try_from(lens[k]).ok()?;
        stride = stride.checked_mul(lens[k])?;
    }
    u32::try_from(stride).ok().map(|_| strides)
}

impl Checker {
    /// `word.bit := value`: the word with that bit cleared, then set from the value.
    pub(super) fn lower_bit_write(
        &mut self,
        word: &Expr,
        bit: u32,
        value: &Expr,
        ctx: Ctx,
        l: &Layout,
    ) -> R<StKind> {
        let (addr, ty) = self.place(word, ctx, l)?;
        let Type::Elem(t) = ty else {
            return Err(self.unsupported(word.pos(), "a bit of this value"));
        };
        let old = Ex::Load(Box::new(addr.clone()), t);
        let cleared = Ex::Bin(
            BinOp::And,
            t,
            Box::new(old),
            Box::new(Ex::Int(!(1i64 << bit))),
        );
        let flag = self.value_as(value, Elem::Bool, ctx, l)?;
        let moved = Ex::Std(
            StdFn::Shl,
            t,
            vec![
                Ex::Conv(Elem::Bool, t, Box::new(flag)),
                Ex::Int(i64::from(bit)),
            ],
        );
        let word = Ex::Bin(BinOp::Or, t, Box::new(cleared), Box::new(moved));
        Ok(StKind::Store(addr, t, word))
    }

    /// The elementary leaves of a structure (offset, type), `None` beyond 64 of them or for
    /// anything but elementary, pointer and enumeration fields and structures of them.
    pub(super) fn leaves(&self, ty: &Type, l: &Layout) -> Option<Vec<(u32, Elem)>> {
        let mut out = Vec::new();
        self.leaves_into(ty, 0, l, &mut out)?;
        Some(out)
    }

    fn leaves_into(
        &self,
        ty: &Type,
        at: u32,
        l: &Layout,
        out: &mut Vec<(u32, Elem)>,
    ) -> Option<()> {
        match ty {
            Type::Elem(e) if out.len() < 64 => out.push((at, *e)),
            // A pointer is copied as its 8 bytes (an MC_CAM_REF's pArray), an enumeration as
            // its base type.
            Type::Pointer(_) if out.len() < 64 => out.push((at, Elem::ULInt)),
            Type::Enum(i) if out.len() < 64 => out.push((at, self.out.enums[*i].base)),
            Type::Struct(i) => {
                for (k, (_, field)) in self.out.structs[*i].fields.iter().enumerate() {
                    self.leaves_into(field, at + l.structs[*i].2[k], l, out)?;
                }
            }
            _ => return None,
        }
        Some(())
    }
}
