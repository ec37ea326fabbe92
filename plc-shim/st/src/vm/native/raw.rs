//! The unsafe part of native code: the compiled code's memory and entries, the call into a
//! body's code, and the callback through which that code runs an operation it does not
//! compile. The crate root denies `unsafe_code`; this module alone allows it.
#![allow(unsafe_code)]

use super::super::code::Code;
use super::super::run::Frame;
use super::super::{Exec, Fault, Run};
use super::{Cx, FAULTED, NEXT_END};
use cranelift_jit::JITModule;
use cranelift_module::FuncId;

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

    /// The module, while code is compiled into it.
    pub(super) fn module(&mut self) -> Option<&mut JITModule> {
        self.0.as_mut()
    }
}

impl Drop for Jit {
    fn drop(&mut self) {
        if let Some(module) = self.0.take() {
            // SAFETY: the last `Arc<Jit>` is dropped with the `Codes` that hold the entries
            // into this memory (the entries live in the same `Codes`, next to the `Arc`), or
            // before any entry was handed out (a compilation that failed), so no entry is
            // called again.
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

/// Finishes the functions `jit`'s module defined, `ids` (per body, with
/// [`super::compile_all`]'s signature): their entries, for the `Codes` that keeps `jit`.
pub(super) fn finish(
    jit: &mut Jit,
    ids: &[Option<FuncId>],
) -> Result<Vec<Option<Entry>>, super::NoNative> {
    let module = jit.module().ok_or(super::NoNative)?;
    module.finalize_definitions()?;
    let entry = |id: FuncId| {
        let f = module.get_finalized_function(id);
        // SAFETY: `f` is the finalized address of a function this module defined with the
        // signature (pointer) -> i64 in the platform's C calling convention, which is this
        // type's; it stays mapped while `jit` lives, and `jit` is kept beside the entries.
        Entry(unsafe { core::mem::transmute::<*const u8, unsafe extern "C" fn(*mut Cx) -> u64>(f) })
    };
    Ok(ids.iter().map(|id| id.map(entry)).collect())
}

/// The callback's address, for the module's symbol table.
pub(super) const OP: extern "C" fn(*mut Cx, u32) -> u64 = op;

/// Runs operation `pc` of the body `cx` describes, as the interpreter does, and says where
/// to go on (see [`FAULTED`]).
extern "C" fn op(cx: *mut Cx, pc: u32) -> u64 {
    enter(cx, |exec, code, at| {
        let next = exec.one(code, pc as usize, at)?;
        Ok(u64::try_from(next).map_or(NEXT_END, |n| n.min(NEXT_END)))
    })
}

/// The callback's address for [`super::super::code::Op::Call`] `k`'s body.
pub(super) const CALL: extern "C" fn(*mut Cx, u32) -> u64 = call;

/// Runs the body of block call `k` ([`super::super::code::Op::Call`]) whose inputs native
/// code has stored: 0, or [`FAULTED`] with the fault's code.
extern "C" fn call(cx: *mut Cx, k: u32) -> u64 {
    enter(cx, |exec, _, at| {
        let codes = exec.codes;
        let c = codes.call_ops.get(k as usize).ok_or(Fault::BadPointer)?;
        let instance = if c.relative { at.base + c.at } else { c.at };
        exec.call_body(c, at.top, instance).map(|()| 0)
    })
}

/// `f` on the runtime and the body `cx` describes: its result, or [`FAULTED`] with a fault's
/// code. A panic is kept in `cx` with a fault's code: it does not unwind through native
/// code, which has no unwind tables; `run_native` raises it again once that has returned.
fn enter(cx: *mut Cx, f: impl FnOnce(&mut Exec<'static>, &'static Code, Frame) -> Run<u64>) -> u64 {
    // SAFETY: native code calls the callbacks only with the `Cx` that `run_native` made on
    // its stack for the body running now, and nothing else reaches that `Cx` meanwhile.
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
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| f(exec, code, at)));
    point(cx, exec);
    match r {
        Ok(Ok(v)) => v,
        Ok(Err(fault)) => FAULTED | fault.code(),
        Err(panic) => {
            cx.panic = Some(panic);
            // Any fault's code: the native code stops, and `run_native` raises the panic.
            FAULTED | Fault::BadPointer.code()
        }
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
    /// Body `code`'s native code (none: its operations) on frame `at`.
    pub(in super::super) fn run_native(&mut self, code: &'a Code, at: Frame) -> Run<()> {
        let Some(entry) = code.native else {
            return self.run_ops(code, at);
        };
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
            image: core::ptr::null_mut(),
            image_len: 0,
            leaf: core::ptr::null(),
            leaves: 0,
            writable: core::ptr::null(),
            panic: None,
        };
        if let Some((image, map)) = self.image {
            cx.image = image.base_ptr();
            cx.image_len = image.len() as u64;
            (cx.leaf, cx.leaves) = (map.leaf.as_ptr(), map.leaf.len() as u64);
            // One flag per byte of the same image as the sizes.
            cx.writable = map.writable.as_ptr();
        }
        point(&mut cx, self);
        cx.exec = (self as *mut Exec<'a>).cast();
        // SAFETY: `entry` is compiled code of this program's `Codes` (kept alive by the
        // `Arc<Jit>` beside it for as long as `self.codes` is borrowed). It reads and
        // writes only through `cx`: the program's memory within `mem_len`, the body's
        // window of registers (`run_code` checked it lies within the file), the steps and
        // the site; the image's map below `leaves` (the sizes and the flags have one entry
        // per byte of the image each), and the image's leaves within `image_len`, each with
        // one aligned load or store of its own size (a relaxed atomic's instruction), as
        // `ImageMemory`'s contract asks; and it calls `op` with `cx`. `self` is not used
        // until it returns.
        let r = unsafe { (entry.0)(&mut cx) };
        if let Some(panic) = cx.panic.take() {
            std::panic::resume_unwind(panic);
        }
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
