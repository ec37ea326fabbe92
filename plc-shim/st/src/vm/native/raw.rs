//! The unsafe part of native code: the compiled code's memory and entries, the call into a
//! body's code, and the callback through which that code runs an operation it does not
//! compile. The crate root denies `unsafe_code`; this module alone allows it.
#![allow(unsafe_code)]

use super::super::code::Code;
use super::super::run::Frame;
use super::super::{Exec, Fault, Run};
use super::{Cx, FAULTED, NEXT_END};
use cranelift_jit::JITModule;

/// The compiled code of a program's bodies: its memory, freed when the last program that
/// runs it is dropped.
pub(crate) struct Jit(Option<JITModule>);

// SAFETY: after `finalize_definitions` the module is never used again but to free its
// memory on drop, which takes `&mut self` (no other reference then); the code it holds is
// read-only and executable, so sharing it between threads shares immutable bytes.
unsafe impl Send for Jit {}
// SAFETY: as for `Send`: nothing is reached through `&Jit`.
unsafe impl Sync for Jit {}

impl Jit {
    pub(super) fn new(module: JITModule) -> Jit {
        Jit(Some(module))
    }
}

impl Drop for Jit {
    fn drop(&mut self) {
        if let Some(module) = self.0.take() {
            // SAFETY: the last `Arc<Jit>` is dropped with the `Codes` that hold the entries
            // into this memory (the entries live in the same `Codes`, next to the `Arc`), so
            // no entry is called again.
            unsafe { module.free_memory() };
        }
    }
}

impl core::fmt::Debug for Jit {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("Jit")
    }
}

/// A body's compiled code: `extern "C" fn(*mut Cx) -> u64` (0: the body ended, else a
/// fault's [`Fault::code`]).
#[derive(Clone, Copy)]
pub(crate) struct Entry(unsafe extern "C" fn(*mut Cx) -> u64);

impl core::fmt::Debug for Entry {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("Entry")
    }
}

/// The entry at `f`, a function the module defined with [`super::compile_all`]'s signature.
pub(super) fn entry(f: *const u8) -> Entry {
    // SAFETY: `f` is the finalized address of a function compiled with the signature
    // (pointer) -> i64 in the platform's C calling convention, which is this type's.
    Entry(unsafe { core::mem::transmute::<*const u8, unsafe extern "C" fn(*mut Cx) -> u64>(f) })
}

/// The callback's address, for the module's symbol table.
pub(super) const OP: extern "C" fn(*mut Cx, u32) -> u64 = op;

/// Runs operation `pc` of the body `cx` describes, as the interpreter does, and says where
/// to go on (see [`FAULTED`]).
extern "C" fn op(cx: *mut Cx, pc: u32) -> u64 {
    // SAFETY: native code calls this only with the `Cx` that `run_native` made on its stack
    // for the body running now, and nothing else reaches that `Cx` meanwhile.
    let cx = unsafe { &mut *cx };
    // SAFETY: `cx.exec` and `cx.code` are the `&mut Exec` and `&Code` `run_native` was
    // given; `run_native` does not use them while its native call runs, which is now, and
    // these references end with this function. The lifetime is the runtime's own: nothing
    // taken from it outlives this call.
    let (exec, code) = unsafe {
        (
            &mut *cx.exec.cast::<Exec<'static>>(),
            &*cx.code.cast::<Code>(),
        )
    };
    let at = Frame {
        base: cx.base as u32,
        w: cx.w as usize,
        top: cx.top as usize,
    };
    let r = exec.one(code, pc as usize, at);
    point(cx, exec);
    match r {
        Ok(next) => u64::try_from(next).map_or(NEXT_END, |n| n.min(NEXT_END)),
        Err(f) => FAULTED | f.code(),
    }
}

/// Points `cx` at the state of `exec` (again, after `exec` was used through a reference).
fn point(cx: &mut Cx, exec: &mut Exec<'_>) {
    let st = &mut *exec.st;
    cx.mem = st.memory.as_mut_ptr();
    cx.mem_len = st.memory.len() as u64;
    // A window beyond the registers was refused before the body ran (`run_code`).
    cx.regs = st.regs[cx.w as usize..].as_mut_ptr().cast();
    cx.steps = &mut st.steps;
    cx.site = &mut st.site;
}

impl<'a> Exec<'a> {
    /// Body `code`'s native `entry` on frame `at`.
    pub(in super::super) fn run_native(
        &mut self,
        entry: Entry,
        code: &'a Code,
        at: Frame,
    ) -> Run<()> {
        let mut cx = Cx {
            exec: core::ptr::null_mut(),
            code,
            mem: core::ptr::null_mut(),
            mem_len: 0,
            regs: core::ptr::null_mut(),
            steps: core::ptr::null_mut(),
            budget: self.st.budget,
            site: core::ptr::null_mut(),
            base: u64::from(at.base),
            w: at.w as u64,
            top: at.top as u64,
        };
        point(&mut cx, self);
        cx.exec = (self as *mut Exec<'a>).cast();
        // SAFETY: `entry` is compiled code of this program's `Codes` (kept alive by the
        // `Arc<Jit>` beside it for as long as `self.codes` is borrowed). It reads and
        // writes only through `cx`: the program's memory within `mem_len`, the body's
        // window of registers (`run_code` checked it lies within the file), the steps and
        // the site; and it calls `op` with `cx`. `self` is not used until it returns.
        let r = unsafe { (entry.0)(&mut cx) };
        if r == 0 {
            return Ok(());
        }
        let fault = Fault::of_code(r);
        if fault == Fault::Budget {
            // Native code counts steps without the numbers the fault names.
            self.st.values = [self.st.steps as i64, 0, 0];
        }
        Err(fault)
    }
}
