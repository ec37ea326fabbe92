//! Blocks a host implements (the PLC runtime's block library: MC_Power, MC_CamIn, ...): a
//! FUNCTION_BLOCK the program declares with an empty body and the host names at load
//! ([`Program::load_with`]). A call stores its inputs into the instance as for any block;
//! then, instead of a body, the host runs the block on the instance's members
//! ([`BlockIo`]) and writes its outputs there, and the call's outputs are read as usual.
//!
//! Every instance is found at load (in the globals, the programs and the function blocks
//! inside them), so the host keeps one state per instance, made before the first cycle.
//! A library block in a FUNCTION (whose variables start over each call) is refused.

use super::{read_mem, write_mem, Fault, Program, Run, V};
use crate::ast::PouKind;
use crate::check::{Compiled, Type};
use crate::diag::{Diagnostic, Pos};
use crate::types::Elem;

/// A host's blocks on the program's instances.
pub trait Host {
    /// Runs block `block` (its index among the names given to [`Program::load_with`]) on
    /// instance `io` for one cycle: reads the inputs, writes the outputs.
    fn call(&mut self, block: usize, io: &mut BlockIo<'_>) -> Result<(), Fault>;
}

/// What a program knows of its host's blocks.
#[derive(Debug, Clone, Default)]
pub(super) struct Library {
    /// Per POU: the index of the host's block it is.
    pub(super) of_pou: Vec<Option<usize>>,
    /// Per host block: each variable's place in the instance (offset, type), `None` for one
    /// that is no elementary value (a structure's first leaf stands for it: an AXIS_REF).
    pub(super) members: Vec<Vec<Option<(u32, Elem)>>>,
    /// Per host block: each variable's elementary leaves (offset in the instance, type), in
    /// the order of its declaration (a structure's fields, an array's elements, nested).
    pub(super) leaves: Vec<Vec<Vec<(u32, Elem)>>>,
    /// Every instance: its address and block, in address order.
    pub(super) instances: Vec<(u32, usize)>,
}

/// One instance of a host block during its call: its members by the index of the variable
/// in the block's declaration.
pub struct BlockIo<'a> {
    pub(super) memory: &'a mut [u8],
    pub(super) at: usize,
    pub(super) members: &'a [Option<(u32, Elem)>],
    pub(super) leaves: &'a [Vec<(u32, Elem)>],
    pub(super) slot: usize,
    /// The inputs this call passes (offsets in the instance).
    pub(super) passed: &'a [crate::ir::BlockInput],
}

impl BlockIo<'_> {
    /// The instance's index among [`Program::library_instances`].
    #[inline]
    pub fn slot(&self) -> usize {
        self.slot
    }

    #[inline]
    fn place(&self, k: usize) -> Option<(usize, Elem)> {
        let (offset, t) = (*self.members.get(k)?)?;
        Some((self.at + offset as usize, t))
    }

    /// The call site (the same number for every call from one place of the program: each
    /// gives the same inputs).
    #[inline]
    pub fn site(&self) -> usize {
        self.passed.as_ptr() as usize
    }

    /// Whether this call gives variable `k` (an input named in the call).
    pub fn given(&self, k: usize) -> bool {
        let offset = self.members.get(k).copied().flatten().map(|(o, _)| o);
        offset.is_some_and(|o| self.passed.iter().any(|(at, _, _)| *at == o))
    }

    /// Variable `k` as an integer (BOOL 0 or 1), `None` if it is a real or has no place.
    #[inline]
    pub fn int(&self, k: usize) -> Option<i64> {
        let (at, t) = self.place(k)?;
        match read_mem(self.memory, at, t).ok()? {
            V::I(i) => Some(i),
            V::F(_) => None,
        }
    }

    /// The integer of type `t` `offset` bytes into variable `k` (a structure's field: an
    /// `MC_CAM_REF`'s), `None` outside the instance's memory.
    pub fn field(&self, k: usize, offset: u32, t: Elem) -> Option<i64> {
        let (at, _) = self.place(k)?;
        match read_mem(self.memory, at.checked_add(offset as usize)?, t).ok()? {
            V::I(i) => Some(i),
            V::F(_) => None,
        }
    }

    /// The characters of STRING variable `k` (`size` bytes with its NUL) before its NUL.
    pub fn text(&self, k: usize, size: usize) -> Option<&[u8]> {
        let (at, _) = self.place(k)?;
        let bytes = self.memory.get(at..at.checked_add(size)?)?;
        let end = bytes.iter().position(|b| *b == 0).unwrap_or(bytes.len());
        Some(&bytes[..end])
    }

    /// The `n` bytes of the program's memory pointer `p` points at: `None` for NULL, a
    /// pointer into the image, or bytes beyond the memory.
    pub fn memory_at(&self, p: i64, n: usize) -> Option<&[u8]> {
        self.memory.get(own_range(p, n)?)
    }

    /// As [`BlockIo::memory_at`], to write (a read's answer into the program's array).
    pub fn memory_at_mut(&mut self, p: i64, n: usize) -> Option<&mut [u8]> {
        self.memory.get_mut(own_range(p, n)?)
    }

    /// Variable `k` as a number.
    #[inline]
    pub fn real(&self, k: usize) -> Option<f64> {
        let (at, t) = self.place(k)?;
        read_mem(self.memory, at, t).ok().map(V::float)
    }

    /// `out` filled with `n` LREALs from where pointer variable `k` points (the program's own
    /// memory only); `false` for a NULL pointer, one into the image, or `n` values beyond the
    /// memory. `out` is cleared first and not grown beyond `n` (give it the room).
    pub fn lreals(&self, k: usize, n: usize, out: &mut Vec<f64>) -> bool {
        out.clear();
        let bytes = n
            .checked_mul(8)
            .and_then(|b| self.memory_at(self.int(k)?, b));
        let Some(bytes) = bytes else {
            return false;
        };
        out.extend(
            bytes
                .chunks_exact(8)
                .map(|c| f64::from_le_bytes(super::arr(c))),
        );
        true
    }

    /// Sets the elementary leaves of variable `k` (a structure's fields in order, an
    /// elementary output itself) from `values`, each converted to its type: how many values
    /// it took.
    pub fn set_leaves(&mut self, k: usize, values: &[f64]) -> usize {
        let Some(leaves) = self.leaves.get(k) else {
            return 0;
        };
        for (&(offset, t), v) in leaves.iter().zip(values) {
            let _ = write_mem(self.memory, self.at + offset as usize, t, of_type(*v, t));
        }
        leaves.len().min(values.len())
    }

    /// Sets variable `k` (an output) to `v`, converted to its type; nothing if it has no place.
    pub fn set(&mut self, k: usize, v: f64) {
        if let Some((at, t)) = self.place(k) {
            let _ = write_mem(self.memory, at, t, of_type(v, t));
        }
    }
}

/// Where the `n` bytes pointer `p` points at lie in the program's memory: `None` for NULL,
/// a pointer into the image, or a range that overflows.
fn own_range(p: i64, n: usize) -> Option<core::ops::Range<usize>> {
    match super::pointed(p).ok()? {
        super::Loc::Own(at) => Some(at..at.checked_add(n)?),
        super::Loc::Image(_) => None,
    }
}

/// Number `v` as a value of type `t` (a BOOL is TRUE for anything but 0).
fn of_type(v: f64, t: Elem) -> V {
    match t {
        Elem::Real | Elem::LReal => V::F(v),
        Elem::Bool => V::I(i64::from(v != 0.0)),
        _ => V::I(v as i64),
    }
}

impl Library {
    /// The host's slot of the instance at `at`, if one is there.
    pub(super) fn slot_at(&self, at: u32) -> Option<u32> {
        let k = self.instances.binary_search_by_key(&at, |(a, _)| *a).ok()?;
        u32::try_from(k).ok()
    }

    /// The library of `code` for the host's block `names`: each a FUNCTION_BLOCK of the
    /// program with an empty body, or a refusal naming it.
    pub(super) fn of(code: &Compiled, names: &[&str]) -> Result<Library, Vec<Diagnostic>> {
        let c = &code.checked;
        let mut lib = Library {
            of_pou: vec![None; c.pous.len()],
            ..Library::default()
        };
        let mut errors = Vec::new();
        for (k, name) in names.iter().enumerate() {
            let found = c
                .pous
                .iter()
                .position(|p| p.name.eq_ignore_ascii_case(name));
            let refuse = |what: &str| {
                let file = found.and_then(|i| code.files.get(c.pous[i].file));
                Diagnostic::new(
                    Pos { line: 1, col: 1 },
                    format!("library block {name}: {what}"),
                )
                .in_file(file.map_or("", String::as_str))
            };
            let initialised = found.and_then(|i| code.fb_inits.iter().find(|f| f.0 == i));
            match found {
                Some(_) if initialised.is_some() => {
                    let (_, file, pos) = initialised.cloned().unwrap_or_default();
                    errors.push(
                        Diagnostic::new(
                            pos,
                            format!(
                                "an initial value for an input of library block {name}: its \
                                 inputs are given in its calls"
                            ),
                        )
                        .in_file(&file),
                    )
                }
                Some(i) if c.pous[i].kind != PouKind::FunctionBlock => {
                    errors.push(refuse("is not a FUNCTION_BLOCK"))
                }
                Some(i) if !code.bodies[i].1.is_empty() => {
                    errors.push(refuse("has statements: the host runs it"))
                }
                Some(i) => lib.of_pou[i] = Some(k),
                None => errors.push(refuse("is not declared")),
            }
            lib.members
                .push(found.map_or_else(Vec::new, |i| members(code, i)));
            lib.leaves.push(found.map_or_else(Vec::new, |i| {
                let (c, l) = (&code.checked, &code.layout);
                let vars = c.pous[i].vars.iter().enumerate();
                vars.map(|(k, v)| leaves_of(code, &v.ty, l.pous[i].2[k]))
                    .collect()
            }));
        }
        for (i, pou) in c.pous.iter().enumerate() {
            // A function's variables, and a method's own, live for one call.
            let from = pou.method.as_ref().map_or(0, |m| m.own_from);
            let own = pou.vars.get(from..).unwrap_or_default();
            let holds = own.iter().any(|v| lib.holds_block(code, &v.ty, 0));
            let kind = match pou.kind {
                PouKind::Function => "FUNCTION",
                _ => "METHOD",
            };
            if matches!(pou.kind, PouKind::Function | PouKind::Method) && holds {
                let file = code.files.get(pou.file).map_or("", String::as_str);
                let pos = pou.vars.first().map_or(Pos { line: 1, col: 1 }, |v| v.pos);
                errors.push(
                    Diagnostic::new(
                        pos,
                        format!(
                            "{kind} {}: a library block keeps its state from cycle to \
                             cycle: declare it in a PROGRAM or FUNCTION_BLOCK",
                            c.pous[i].name
                        ),
                    )
                    .in_file(file),
                );
            }
        }
        if errors.is_empty() {
            lib.find_instances(code);
            Ok(lib)
        } else {
            Err(errors)
        }
    }

    /// Whether a value of `ty` is or contains an instance of a host block.
    fn holds_block(&self, code: &Compiled, ty: &Type, depth: usize) -> bool {
        let c = &code.checked;
        depth < 64
            && match ty {
                Type::Fb(i) => {
                    self.of_pou[*i].is_some()
                        || c.pous[*i]
                            .vars
                            .iter()
                            .any(|v| self.holds_block(code, &v.ty, depth + 1))
                }
                Type::Struct(i) => c.structs[*i]
                    .fields
                    .iter()
                    .any(|(_, t)| self.holds_block(code, t, depth + 1)),
                Type::Array(_, e) => self.holds_block(code, e, depth + 1),
                _ => false,
            }
    }

    /// Every instance of a host block in a value of `ty` at `at`, into `self.instances`.
    fn walk(&mut self, code: &Compiled, ty: &Type, at: u32) {
        let (c, l) = (&code.checked, &code.layout);
        if !self.holds_block(code, ty, 0) {
            return;
        }
        match ty {
            Type::Fb(i) => match self.of_pou[*i] {
                Some(k) => self.instances.push((at, k)),
                None => {
                    for (k, v) in c.pous[*i].vars.iter().enumerate() {
                        self.walk(code, &v.ty, at + l.pous[*i].2[k]);
                    }
                }
            },
            Type::Struct(i) => {
                for (k, (_, t)) in c.structs[*i].fields.iter().enumerate() {
                    self.walk(code, t, at + l.structs[*i].2[k]);
                }
            }
            Type::Array(dims, element) => {
                let (size, align) = l.size_align(c, element);
                let stride = size.div_ceil(align) * align;
                let count: u64 = dims.iter().map(|(lo, hi)| hi.abs_diff(*lo) + 1).product();
                for k in 0..count as u32 {
                    self.walk(code, element, at + k * stride);
                }
            }
            _ => {}
        }
    }

    /// Every instance of a host block in the globals and the programs, in address order.
    fn find_instances(&mut self, code: &Compiled) {
        let (c, l) = (&code.checked, &code.layout);
        for (g, var) in c.globals.iter().enumerate() {
            self.walk(code, &var.ty, l.globals[g]);
        }
        for (i, pou) in c.pous.iter().enumerate() {
            if pou.kind == PouKind::Program {
                for (k, v) in pou.vars.iter().enumerate() {
                    self.walk(code, &v.ty, l.statics[i] + l.pous[i].2[k]);
                }
            }
        }
        self.instances.sort_unstable();
    }
}

/// The elementary leaves of a value of `ty` at `at` (at most 4,096 of them).
fn leaves_of(code: &Compiled, ty: &Type, at: u32) -> Vec<(u32, Elem)> {
    fn walk(code: &Compiled, ty: &Type, at: u32, out: &mut Vec<(u32, Elem)>) {
        let (c, l) = (&code.checked, &code.layout);
        if out.len() >= 4096 {
            return;
        }
        match ty {
            Type::Elem(e) => out.push((at, *e)),
            Type::Enum(e) => out.push((at, c.enums[*e].base)),
            Type::Struct(s) => {
                for (k, (_, field)) in c.structs[*s].fields.iter().enumerate() {
                    walk(code, field, at + l.structs[*s].2[k], out);
                }
            }
            Type::Array(dims, element) => {
                let (size, align) = l.size_align(c, element);
                let stride = size.div_ceil(align) * align;
                let count: i64 = dims.iter().map(|(lo, hi)| hi - lo + 1).product();
                for k in 0..count.clamp(0, 4096) as u32 {
                    walk(code, element, at + k * stride, out);
                }
            }
            _ => {}
        }
    }
    let mut out = Vec::new();
    walk(code, ty, at, &mut out);
    out
}

/// Each variable's place in an instance of POU `pou`.
fn members(code: &Compiled, pou: usize) -> Vec<Option<(u32, Elem)>> {
    let (c, l) = (&code.checked, &code.layout);
    c.pous[pou]
        .vars
        .iter()
        .enumerate()
        .map(|(k, v)| {
            let offset = l.pous[pou].2[k];
            match &v.ty {
                Type::Elem(e) => Some((offset, *e)),
                Type::Pointer(_) => Some((offset, Elem::LInt)),
                Type::Str(_) => Some((offset, Elem::Byte)),
                Type::Struct(s) => match c.structs[*s].fields.first() {
                    Some((_, Type::Elem(e))) => Some((offset + l.structs[*s].2[0], *e)),
                    Some((_, Type::Pointer(_))) => Some((offset + l.structs[*s].2[0], Elem::LInt)),
                    Some((_, Type::Enum(e))) => {
                        Some((offset + l.structs[*s].2[0], c.enums[*e].base))
                    }
                    _ => None,
                },
                _ => None,
            }
        })
        .collect()
}

impl Program {
    /// Every instance of a host block: its address and its block's index among the names
    /// given at load, in address order (a host keeps its state per instance in this order).
    pub fn library_instances(&self) -> &[(u32, usize)] {
        &self.library.instances
    }
}

impl super::Exec<'_> {
    /// Host block `block` on the instance at `base`.
    pub(super) fn call_host(&mut self, block: usize, base: u32) -> Run<()> {
        let slot = self.library.slot_at(base).ok_or(Fault::BadPointer)?;
        self.call_host_at(block, base, slot as usize)
    }

    /// As [`Exec::call_host`] for the instance in host slot `slot`.
    pub(super) fn call_host_at(&mut self, block: usize, base: u32, slot: usize) -> Run<()> {
        let lib = self.library;
        let host = self.host.as_deref_mut().ok_or(Fault::NoHost)?;
        let mut io = BlockIo {
            memory: &mut self.st.memory,
            at: base as usize,
            members: &lib.members[block],
            leaves: &lib.leaves[block],
            slot,
            passed: self.passing,
        };
        host.call(block, &mut io)
    }
}
