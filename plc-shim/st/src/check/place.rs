//! Places the lowering computes: an address moved on by a fixed offset, the strides of an
//! array, the leaves of a structure input, a single bit written.

use super::expr::Ctx;
use super::lower::R;
use super::{Checker, Type};
use crate::ast::{BinOp, Expr};
use crate::diag::{Diagnostic, Pos};
use crate::ir::{Addr, Ex, St, StKind, StdFn, Text};
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

    /// The elementary leaves of a structure or an array (offset, type), `None` beyond 64 of
    /// them or for anything but elementary, pointer, enumeration and STRING values and
    /// structures and arrays of them. A STRING's bytes (its NUL's room included) are its
    /// [`string_chunks`], copied as they are.
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
            Type::Str(n) => {
                for (k, e) in string_chunks(*n) {
                    if out.len() >= 64 {
                        return None;
                    }
                    out.push((at + k, e));
                }
            }
            Type::Struct(i) => {
                for (k, (_, field)) in self.out.structs[*i].fields.iter().enumerate() {
                    self.leaves_into(field, at + l.structs[*i].2[k], l, out)?;
                }
            }
            Type::Array(dims, element) => {
                let (size, align) = l.size_align(&self.out, element);
                let stride = size.div_ceil(align.max(1)) * align.max(1);
                let count: i64 = dims.iter().map(|(lo, hi)| hi - lo + 1).product();
                if count > 64 {
                    return None;
                }
                for k in 0..count as u32 {
                    self.leaves_into(element, at + k * stride, l, out)?;
                }
            }
            _ => return None,
        }
        Some(())
    }
}

/// Whether a place is fixed: no index computed, no pointer followed.
fn fixed(a: &Addr) -> bool {
    match a {
        Addr::Static(_) | Addr::Instance(_) => true,
        Addr::Offset(inner, _) => fixed(inner),
        _ => false,
    }
}

/// The parts of the STRING(n) at `place`, read.
fn loads(place: &Addr, n: u32) -> Vec<(u32, Elem, Ex)> {
    string_chunks(n)
        .into_iter()
        .map(|(at, t)| (at, t, Ex::Load(Box::new(plus(place.clone(), at)), t)))
        .collect()
}

/// The parts a STRING(n)'s n + 1 bytes are passed in: 8-byte words, then single bytes.
fn string_chunks(n: u32) -> Vec<(u32, Elem)> {
    let size = n + 1;
    let words = (0..size / 8).map(|k| (8 * k, Elem::LWord));
    words
        .chain((size / 8 * 8..size).map(|at| (at, Elem::Byte)))
        .collect()
}

impl Checker {
    /// A string literal's bytes for a STRING(n): ASCII, at most n characters, NUL-padded to
    /// n + 1 bytes.
    pub(super) fn literal_bytes(&mut self, text: &str, n: u32, pos: Pos) -> R<Vec<u8>> {
        if !text.is_ascii() {
            return Err(self.unsupported(pos, "a STRING of other than ASCII characters"));
        }
        if text.len() > n as usize {
            let message = format!(
                "'{text}' has {} characters: a STRING({n}) holds {n}",
                text.len()
            );
            return Err(Diagnostic::new(pos, message).in_file(&self.file));
        }
        let mut bytes = text.as_bytes().to_vec();
        bytes.resize(n as usize + 1, 0);
        Ok(bytes)
    }

    /// A value for a STRING(n): a literal no longer than n, a STRING variable no longer than
    /// n (refused otherwise: it may not fit), or a computed STRING (cut to n when longer, as
    /// TwinCAT's string functions are).
    pub(super) fn text_for(&mut self, n: u32, value: &Expr, ctx: Ctx, l: &Layout) -> R<Text> {
        if let Expr::Str(text, pos) = value {
            let bytes = self.literal_bytes(text, n, *pos)?;
            return Ok(Text::Const(bytes.into_boxed_slice()));
        }
        match self.text_ir(value, ctx, l)? {
            Text::At(_, size) if size > n + 1 => {
                let message = format!("a STRING({}) into a STRING({n}): it may not fit", size - 1);
                Err(Diagnostic::new(value.pos(), message).in_file(&self.file))
            }
            text => Ok(text),
        }
    }

    /// `value` stored into the STRING(n) at `addr` ([`Checker::text_for`]).
    pub(super) fn lower_string(
        &mut self,
        addr: Addr,
        n: u32,
        value: &Expr,
        ctx: Ctx,
        l: &Layout,
    ) -> R<StKind> {
        Ok(match self.text_for(n, value, ctx, l)? {
            Text::Const(bytes) => StKind::Bytes(addr, bytes),
            Text::At(from, size) => StKind::Copy(addr, from, size),
            text => StKind::Text(addr, n + 1, text),
        })
    }

    /// A block's STRING(n) input (`input`: the instance, the input's offset in it, the
    /// call's place, how many inputs come before it), passed in 8-byte parts: a literal's
    /// as constants, a variable's (no longer than n) read; for a computed STRING, a
    /// statement into `texts` that computes it into the input (cut to n), and the parts read
    /// back from there (so that the call gives the input): see [`Checker::texts_first`].
    pub(super) fn string_input(
        &mut self,
        n: u32,
        value: &Expr,
        (instance, offset, at, before): (&Addr, u32, (u16, Pos), usize),
        texts: &mut Vec<(usize, St)>,
        ctx: Ctx,
        l: &Layout,
    ) -> R<Vec<(u32, Elem, Ex)>> {
        let text = match self.text_for(n, value, ctx, l)? {
            // A literal in constants, a variable read.
            Text::Const(bytes) => {
                return Ok(string_chunks(n)
                    .into_iter()
                    .map(|(at, t)| {
                        let mut word = [0u8; 8];
                        let b = &bytes[at as usize..at as usize + t.size()];
                        word[..b.len()].copy_from_slice(b);
                        (at, t, Ex::Int(i64::from_le_bytes(word)))
                    })
                    .collect())
            }
            Text::At(from, size) => return Ok(loads(&from, size - 1)),
            computed => computed,
        };
        let place = plus(instance.clone(), offset);
        texts.push((
            before,
            St {
                kind: StKind::Text(place.clone(), n + 1, text),
                at,
            },
        ));
        Ok(loads(&place, n))
    }

    /// A block call with computed STRING inputs (`texts`, each after the inputs it
    /// follows): every input stored into the instance in the order written, the STRINGs
    /// computed into theirs in their turn, then the call, which reads them back: one
    /// statement, as the call stores its inputs one after the other. Refused when the
    /// instance's place is not fixed (an array's element, a pointer's) and an input calls a
    /// function, which could move the place between the stores.
    pub(super) fn texts_first(
        &mut self,
        texts: Vec<(usize, St)>,
        mut call: St,
        pos: Pos,
    ) -> R<StKind> {
        let (StKind::CallFb {
            instance, inputs, ..
        }
        | StKind::CallStdFb {
            instance, inputs, ..
        }) = &mut call.kind
        else {
            return Ok(call.kind);
        };
        if texts.is_empty() {
            return Ok(call.kind);
        }
        let mut body = Vec::new();
        let mut texts = texts.into_iter().peekable();
        for k in 0..=inputs.len() {
            while let Some((_, st)) = texts.next_if(|(before, _)| *before <= k) {
                body.push(st);
            }
            let Some((offset, t, value)) = inputs.get_mut(k) else {
                break;
            };
            let place = plus(instance.clone(), *offset);
            let back = Ex::Load(Box::new(place.clone()), *t);
            if *value != back {
                let value = std::mem::replace(value, back);
                let kind = StKind::Store(place, *t, value);
                body.push(St { kind, at: call.at });
            }
        }
        if !fixed(instance) && body.iter().any(crate::vm::callees::calls_in) {
            let what = "a computed STRING input of an instance at a computed place beside \
                        inputs that call a function";
            return Err(self.unsupported(pos, what));
        }
        body.push(call);
        Ok(StKind::If(vec![(Ex::Int(1), body)], Vec::new()))
    }

    /// A block's STRING(m) output given to `target` in the call: its parts, copied after
    /// the call into a STRING at least as long (refused otherwise, or when the target's
    /// place is at an index a function computes).
    pub(super) fn string_output(
        &mut self,
        m: u32,
        (offset, target): (u32, &Expr),
        ctx: Ctx,
        l: &Layout,
    ) -> R<Vec<crate::ir::BlockOutput>> {
        let (to, ty) = self.place(target, ctx, l)?;
        match ty {
            Type::Str(k) if k < m => {
                let message = format!("a STRING({m}) into a STRING({k}): it may not fit");
                return Err(Diagnostic::new(target.pos(), message).in_file(&self.file));
            }
            Type::Str(_) if !crate::vm::callees::addr_calls(&to) => {}
            _ => return Err(self.unsupported(target.pos(), "this STRING output's target")),
        }
        Ok(string_chunks(m)
            .into_iter()
            .map(|(at, t)| (offset + at, t, plus(to.clone(), at), false, t))
            .collect())
    }
}
