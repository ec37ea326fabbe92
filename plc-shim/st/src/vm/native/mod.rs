//! The bodies' operations ([`super::code`]) compiled to native code at load, with
//! Cranelift: a body becomes one function whose blocks are its operations. The operations
//! the machine programs run most are native instructions on the registers, the program's
//! memory and the image: a statement's mark and step, jumps, comparisons, CASE tables and
//! ranges, FOR loops, moves, stores and constants, integer arithmetic with division, BOOL
//! logic, real arithmetic, conversions from integers, a block's instance, inputs and
//! outputs, and reads and writes through a pointer variable (`p^.field`, into the program's
//! memory or the image's leaves by the image's rules), an element at a computed index within
//! its bounds, a block call's inputs. A block call's body calls back into the runtime
//! ([`super::Exec::call_body`]: the host's blocks, a POU's body), and so does every other
//! operation (the tree's statements, standard functions, an index beyond its bounds, ...):
//! the runtime runs that one operation as the interpreter does ([`super::Exec::one`]) and
//! says where to go on. So the interpreter's loop, its dispatch and its decoding of operands
//! leave the cycle.
//!
//! Both ways share every rule that the native instructions do not restate: those that do
//! (the widths and signs of loads and stores, wrapping to a type, the order of faults) are
//! held to the interpreter's by `tests/it/two_ways.rs`, which runs random programs natively,
//! as operations and as the tree, and compares memory, faults, places and numbers.
//!
//! The unsafe part (calling the code, and the callback's view of the runtime) is
//! [`raw`]'s alone.

mod emit;
mod raw;

use super::code::Codes;
use cranelift_codegen::ir::{types, AbiParam};
use cranelift_codegen::settings::{self, Configurable};
use cranelift_jit::{JITBuilder, JITModule};
use cranelift_module::{default_libcall_names, Linkage, Module};
use std::sync::Arc;

pub(crate) use raw::{Entry, Jit};

/// What native code sees of the runtime while a body runs (its first argument): pointers
/// into the state, and the body's frame. The callback sets the pointers again after every
/// operation it runs, and native code reads them from here each time it uses them.
#[repr(C)]
pub(super) struct Cx {
    /// The runtime ([`super::Exec`]), for the callback.
    exec: *mut core::ffi::c_void,
    /// The body's operations, for the callback.
    code: *const super::code::Code,
    /// The program's memory and its length.
    mem: *mut u8,
    mem_len: u64,
    /// The first register of the body's window.
    regs: *mut u8,
    /// The steps the cycle has taken, and its budget.
    steps: *mut u64,
    budget: u64,
    /// The statement a fault names ([`super::State::site`]).
    site: *mut u32,
    /// The body's frame ([`super::run::Frame`]).
    base: u64,
    w: u64,
    top: u64,
    /// The HLI image (null: none) and its length; per byte of it, the size of the leaf that
    /// starts there (`leaves` of them) and whether the PLC may write it
    /// ([`super::image::ImageMap`]).
    image: *mut u8,
    image_len: u64,
    leaf: *const u8,
    leaves: u64,
    writable: *const bool,
    /// A panic of the callback, raised again once the native code has returned.
    panic: Option<Box<dyn core::any::Any + Send>>,
}

/// Byte offsets of [`Cx`]'s fields, as native code reads them.
mod at {
    use super::Cx;
    use core::mem::offset_of;
    pub(super) const MEM: i32 = offset_of!(Cx, mem) as i32;
    pub(super) const MEM_LEN: i32 = offset_of!(Cx, mem_len) as i32;
    pub(super) const REGS: i32 = offset_of!(Cx, regs) as i32;
    pub(super) const STEPS: i32 = offset_of!(Cx, steps) as i32;
    pub(super) const BUDGET: i32 = offset_of!(Cx, budget) as i32;
    pub(super) const SITE: i32 = offset_of!(Cx, site) as i32;
    pub(super) const BASE: i32 = offset_of!(Cx, base) as i32;
    pub(super) const IMAGE: i32 = offset_of!(Cx, image) as i32;
    pub(super) const IMAGE_LEN: i32 = offset_of!(Cx, image_len) as i32;
    pub(super) const LEAF: i32 = offset_of!(Cx, leaf) as i32;
    pub(super) const LEAVES: i32 = offset_of!(Cx, leaves) as i32;
    pub(super) const WRITABLE: i32 = offset_of!(Cx, writable) as i32;
}

// A register as native code reads and writes it: its word, then its flag (a real).
const _: () = assert!(core::mem::size_of::<super::Reg>() == 16);
const _: () = assert!(core::mem::offset_of!(super::Reg, bits) == 0);
const _: () = assert!(core::mem::offset_of!(super::Reg, real) == 8);
const _: () = assert!(core::mem::size_of::<*mut u8>() == 8);
const _: () = assert!(core::mem::size_of::<bool>() == 1);

/// What the callback returns: the next operation's index ([`NEXT_END`]: the body ends), or
/// [`FAULTED`] with the fault's code ([`super::Fault::code`]).
const FAULTED: u64 = 1 << 32;
/// The callback's next operation when the body ends.
const NEXT_END: u64 = u32::MAX as u64;

/// The most operations a body compiled to native code has: the code generator's time grows
/// faster than a body's length (a body of 40,000 operations took 30 s), so a longer body
/// runs as operations.
const MAX_OPS: usize = 16_384;

/// Compiles every body of `codes` to native code. Where the code generator cannot (an
/// architecture it does not know, a body it refuses), every body keeps its operations: the
/// interpreter runs the same rules. `memory`: the bytes of the program's memory (its size
/// for the program's life).
pub(crate) fn compile(codes: &mut Codes, memory: u64) {
    if let Ok((jit, entries)) = compile_all(codes, memory) {
        for (code, entry) in codes.bodies.iter_mut().zip(entries) {
            if let Some(code) = code {
                code.native = entry;
            }
        }
        codes.native = Some(Arc::new(jit));
    }
}

/// A failure of the code generator (its message is not kept: the interpreter runs).
struct NoNative;

impl<E: core::fmt::Display> From<E> for NoNative {
    fn from(_: E) -> NoNative {
        NoNative
    }
}

fn compile_all(codes: &Codes, memory: u64) -> Result<(Jit, Vec<Option<Entry>>), NoNative> {
    let mut flags = settings::builder();
    flags.set("opt_level", "speed")?;
    flags.set("is_pic", "false")?;
    flags.set("use_colocated_libcalls", "false")?;
    let isa = cranelift_native::builder()?.finish(settings::Flags::new(flags))?;
    let mut jb = JITBuilder::with_isa(isa, default_libcall_names());
    jb.symbol("plc_st_op", raw::OP as *const u8);
    jb.symbol("plc_st_call", raw::CALL as *const u8);
    // Held by `Jit` from here on: its memory is freed also when a step below fails.
    let mut jit = Jit::new(JITModule::new(jb));
    let module = jit.module().ok_or(NoNative)?;
    let ptr = module.target_config().pointer_type();
    let mut op_sig = module.make_signature();
    op_sig.params.push(AbiParam::new(ptr));
    op_sig.params.push(AbiParam::new(types::I32));
    op_sig.returns.push(AbiParam::new(types::I64));
    let op = module.declare_function("plc_st_op", Linkage::Import, &op_sig)?;
    let call = module.declare_function("plc_st_call", Linkage::Import, &op_sig)?;
    let mut sig = module.make_signature();
    sig.params.push(AbiParam::new(ptr));
    sig.returns.push(AbiParam::new(types::I64));
    let mut ids = Vec::with_capacity(codes.bodies.len());
    let mut ctx = module.make_context();
    let mut fbc = cranelift_frontend::FunctionBuilderContext::new();
    for code in &codes.bodies {
        let Some(code) = code.as_ref().filter(|c| c.ops.len() <= MAX_OPS) else {
            ids.push(None);
            continue;
        };
        ctx.func.signature = sig.clone();
        let callbacks = (
            module.declare_func_in_func(op, &mut ctx.func),
            module.declare_func_in_func(call, &mut ctx.func),
        );
        let config = module.target_config();
        let id = if emit::body(
            &mut ctx.func,
            &mut fbc,
            (code, codes, memory),
            callbacks,
            config,
        ) {
            let id = module.declare_anonymous_function(&sig)?;
            module.define_function(id, &mut ctx)?;
            Some(id)
        } else {
            None
        };
        module.clear_context(&mut ctx);
        ids.push(id);
    }
    let entries = raw::finish(&mut jit, &ids)?;
    Ok((jit, entries))
}

impl super::Program {
    /// Runs every body operation by operation from now on, as its native code did (the
    /// tests compare the ways).
    pub fn operations_only(&mut self) {
        for code in self.codes.bodies.iter_mut().flatten() {
            code.native = None;
        }
        self.codes.native = None;
    }

    /// Whether the bodies run as native code (false where the code generator knows no
    /// instructions for the machine, or after [`super::Program::operations_only`]; a body
    /// of more than 16,384 operations keeps its operations even so).
    pub fn is_native(&self) -> bool {
        self.codes.native.is_some()
    }
}
