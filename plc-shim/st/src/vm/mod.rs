//! The runtime of a compiled program: one memory sized at load, every PROGRAM's statements run
//! once per cycle, nothing allocated in a cycle: each body as a list of operations on
//! registers ([`code`], [`run`]), what is rare in it by walking the compiled tree. A cycle is
//! bounded by a budget of steps (statements and loop rounds), so an endless loop ends it; a
//! division by zero, an index outside its array, a pointer outside the memory, a conversion
//! of a value its type cannot hold, or the budget spent is a [`Fault`] with the statement's
//! file, line and column, and the program stops.

use crate::ast::{BinOp, PouKind};
use crate::check::{compile, Compiled, Type};
use crate::diag::{Diagnostic, Pos};
use crate::ir::{Addr, BlockInput, BlockOutput, Ex, St, StKind};
use crate::types::Elem;
use hli::ImageMemory;
use library::Library;
pub use library::{BlockIo, Host};
pub use symbols::{Symbol, MAX_LISTED_ELEMENTS};

mod build;
pub(crate) mod callees;
mod code;
mod fast;
mod fault;
mod image;
mod init;
mod library;
mod mem;
mod native;
pub(crate) mod ops;
mod run;
mod std_fb;
mod symbols;
mod text;

pub use fault::{Fault, FaultAt};
pub use image::IMAGE_TAG;
pub(crate) use mem::{arr, pointed, read_mem, tagged, write_mem, Loc};

/// A STRING's characters before its NUL: a literal's, or the `n` bytes of memory at `at`.
fn chars<'m>(
    memory: &'m [u8],
    t: &'m crate::ir::Text,
    at: Option<(usize, usize)>,
) -> Run<&'m [u8]> {
    let bytes: &[u8] = match (t, at) {
        (_, Some((from, n))) => memory.get(from..from + n).ok_or(Fault::BadPointer)?,
        (crate::ir::Text::Const(lit), None) => lit,
        (crate::ir::Text::At(..) | crate::ir::Text::Fn(_), None) => &[],
    };
    Ok(text::before_nul(bytes))
}

/// How a statement list ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Flow {
    Next,
    Exit,
    Continue,
    Return,
}

/// A value while it is computed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum V {
    I(i64),
    F(f64),
}

impl V {
    #[inline]
    fn int(self) -> i64 {
        match self {
            V::I(v) => v,
            V::F(v) => v as i64,
        }
    }
    #[inline]
    fn float(self) -> f64 {
        match self {
            V::I(v) => v as f64,
            V::F(v) => v,
        }
    }
}

/// The default budget of steps per cycle.
pub const DEFAULT_BUDGET: u64 = 1_000_000;

/// A loaded program: its code and its state.
#[derive(Debug, Clone)]
pub struct Program {
    code: Compiled,
    /// The bodies as operations.
    codes: code::Codes,
    state: State,
    library: Library,
    /// The PROGRAMs, in the order the files declare them.
    programs: Vec<usize>,
}

/// What a program changes as it runs.
#[derive(Debug, Clone)]
struct State {
    memory: Vec<u8>,
    budget: u64,
    steps: u64,
    now_ns: i64,
    /// The statement being run (for a fault's place): its index among the operations'
    /// [`code::Codes::sites`], or [`fault::TREE_SITE`] when the tree walker set `at`.
    site: u32,
    /// The statement the tree walker runs (when `site` is [`fault::TREE_SITE`]).
    at: (u16, Pos),
    /// The numbers of the last fault that has some ([`FaultAt::values`]).
    values: [i64; 3],
    /// The bodies' registers (windows of it, one per call in a chain of calls).
    regs: Vec<Reg>,
}

/// A register: a word, and whether it holds a real (read and written field by field,
/// never copied as a whole value: the copy's wide load would wait for the two narrow
/// stores).
#[derive(Debug, Clone, Copy, Default)]
#[repr(C)]
struct Reg {
    bits: u64,
    real: bool,
}

/// A program running: its code, its state, and the image its pointers may reach.
struct Exec<'a> {
    code: &'a Compiled,
    st: &'a mut State,
    /// The image and its map (which leaf starts where, which the PLC may write).
    image: Option<(&'a ImageMemory, &'static image::ImageMap)>,
    library: &'a Library,
    host: Option<&'a mut dyn Host>,
    /// The inputs the block call being run passes (a host block sees which were given).
    passing: &'a [BlockInput],
    /// The bodies as operations.
    codes: &'a code::Codes,
    /// Where the running body's registers start.
    window: usize,
}

type Run<T> = Result<T, Fault>;

impl Program {
    /// Parses, checks and compiles `files` (name and text), and sets every variable to its
    /// initial value.
    pub fn load(files: &[(&str, &str)]) -> Result<Program, Vec<Diagnostic>> {
        Program::load_with(files, &[])
    }

    /// As [`Program::load`], with the FUNCTION_BLOCKs named `library` run by a [`Host`]
    /// (each declared in `files` with an empty body).
    pub fn load_with(files: &[(&str, &str)], library: &[&str]) -> Result<Program, Vec<Diagnostic>> {
        let mut units = Vec::with_capacity(files.len());
        for (name, text) in files {
            units.push((
                name.to_string(),
                crate::parse_file(name, text).map_err(|d| vec![d])?,
            ));
        }
        let code = compile(&units)?;
        let library = Library::of(&code, library)?;
        let codes = code::Codes::of(&code, &library);
        let programs = (code.checked.pous.iter().enumerate())
            .filter(|(_, p)| p.kind == PouKind::Program)
            .map(|(i, _)| i)
            .collect();
        let mut p = Program {
            programs,
            library,
            state: State {
                regs: vec![Reg::default(); codes.registers],
                memory: vec![0; code.layout.size as usize],
                budget: DEFAULT_BUDGET,
                steps: 0,
                now_ns: 0,
                site: fault::TREE_SITE,
                at: (0, Pos::default()),
                values: [0; 3],
            },
            code,
            codes,
        };
        let mut exec = Exec {
            code: &p.code,
            st: &mut p.state,
            image: None,
            library: &p.library,
            host: None,
            passing: &[],
            codes: &p.codes,
            window: 0,
        };
        if let Err(f) = exec.initialise() {
            let file = p
                .code
                .files
                .get(f.file as usize)
                .cloned()
                .unwrap_or_default();
            let message = format!("an initial value: {f}");
            return Err(vec![Diagnostic::new(f.pos, message).in_file(&file)]);
        }
        Ok(p)
    }

    /// Sets the steps a cycle may run (statements and loop rounds).
    pub fn set_budget(&mut self, steps: u64) {
        self.state.budget = steps.max(1);
    }

    /// Runs every body by walking the compiled tree from now on, as the operations did (the
    /// tests compare the two ways).
    pub fn interpret_only(&mut self) {
        self.codes = code::Codes::default();
    }

    /// The compiled program.
    pub fn code(&self) -> &Compiled {
        &self.code
    }

    /// One cycle at time `now_ns` (the PLC's clock, for the timers) without an image: every
    /// PROGRAM's statements in the order the files declare them.
    pub fn cycle(&mut self, now_ns: i64) -> Result<(), FaultAt> {
        self.cycle_on(now_ns, None)
    }

    /// One cycle with `image` the program's pointers into the HLI reach (`gpCh`, `gpAx`,
    /// `gpFifo`; [`Program::bind_image`] set them).
    pub fn cycle_on(&mut self, now_ns: i64, image: Option<&ImageMemory>) -> Result<(), FaultAt> {
        self.cycle_with(now_ns, image, None)
    }

    /// One cycle with `image`, and `host` running the library's blocks.
    pub fn cycle_with(
        &mut self,
        now_ns: i64,
        image: Option<&ImageMemory>,
        host: Option<&mut dyn Host>,
    ) -> Result<(), FaultAt> {
        self.state.now_ns = now_ns;
        self.state.steps = 0;
        let mut exec = Exec {
            code: &self.code,
            st: &mut self.state,
            image: image.map(|m| (m, image::map())),
            library: &self.library,
            // The host's own lifetime shortened to the cycle's.
            host: host.map(|h| h as &mut dyn Host),
            passing: &[],
            codes: &self.codes,
            window: 0,
        };
        for &pou in &self.programs {
            let base = exec.code.layout.statics[pou];
            exec.run_body(pou, base).map_err(|f| exec.fault_at(f))?;
        }
        Ok(())
    }

    /// Points the controller's pointer arrays the program declares (`gpCh`, `gpAx`,
    /// `gpFifo`, as `hli::st_prelude` declares them) at the image's units: element `k` of
    /// `gpCh` at `gpCh[k]^`.
    pub fn bind_image(&mut self) {
        image::warm();
        for (g, var) in self.code.checked.globals.iter().enumerate() {
            let Type::Array(dims, element) = &var.ty else {
                continue;
            };
            if !matches!(**element, Type::Pointer(_)) || dims.len() != 1 {
                continue;
            }
            let (lo, hi) = dims[0];
            for k in lo..=hi {
                let Some(p) = image::pointer_to(&format!("{}[{k}]^", var.name)) else {
                    break;
                };
                let at = self.code.layout.globals[g] as usize + (k - lo) as usize * 8;
                if let Some(slot) = self.state.memory.get_mut(at..at + 8) {
                    slot.copy_from_slice(&p.to_le_bytes());
                }
            }
        }
    }

    /// A fault as `FILE:LINE:COL: fault: what`.
    pub fn fault_text(&self, f: &FaultAt) -> String {
        let file = self
            .code
            .files
            .get(f.file as usize)
            .map_or("?", String::as_str);
        format!("{file}:{}:{}: fault: {f}", f.pos.line, f.pos.col)
    }

    /// The value of a variable of a PROGRAM, by `PROGRAM.variable` (ASCII case ignored), as
    /// a number: for tests and the tools.
    pub fn read_var(&self, path: &str) -> Option<f64> {
        let (program, var) = path.split_once('.')?;
        let c = &self.code.checked;
        let pou = c
            .pous
            .iter()
            .position(|p| p.name.eq_ignore_ascii_case(program))?;
        let k = c.pous[pou]
            .vars
            .iter()
            .position(|v| v.name.eq_ignore_ascii_case(var))?;
        let at = (self.code.layout.statics[pou] + self.code.layout.pous[pou].2[k]) as usize;
        let t = match &c.pous[pou].vars[k].ty {
            Type::Elem(t) => *t,
            Type::Enum(i) => c.enums[*i].base,
            _ => return None,
        };
        read_mem(&self.state.memory, at, t).ok().map(V::float)
    }
}

impl<'a> Exec<'a> {
    /// A fault with numbers: they are kept for [`FaultAt::values`].
    #[cold]
    fn fault_with(&mut self, fault: Fault, values: [i64; 3]) -> Fault {
        self.st.values = values;
        fault
    }

    /// POU `pou`'s statements on the instance at `base`.
    fn run_body(&mut self, pou: usize, base: u32) -> Run<()> {
        if let Some(block) = self.library.of_pou[pou] {
            return self.call_host(block, base);
        }
        if let Some(Some(body)) = self.codes.bodies.get(pou) {
            return self.run_code(body, base);
        }
        let code = self.code;
        self.block(&code.bodies[pou].1, base).map(|_| ())
    }

    #[inline]
    fn step(&mut self) -> Run<()> {
        self.st.steps += 1;
        if self.st.steps > self.st.budget {
            return Err(self.fault_with(Fault::Budget, [self.st.steps as i64, 0, 0]));
        }
        Ok(())
    }

    fn block(&mut self, body: &'a [St], base: u32) -> Run<Flow> {
        for s in body {
            let flow = self.statement(s, base)?;
            if flow != Flow::Next {
                return Ok(flow);
            }
        }
        Ok(Flow::Next)
    }

    fn statement(&mut self, s: &'a St, base: u32) -> Run<Flow> {
        self.tree_at(s.at);
        self.step()?;
        match &s.kind {
            StKind::Store(a, t, e) => {
                let v = self.operand(e, base)?;
                match a {
                    Addr::Static(o) => self.write_own(*o as usize, *t, v)?,
                    Addr::Instance(o) => self.write_own((base + o) as usize, *t, v)?,
                    Addr::Via {
                        ptr,
                        relative,
                        plus,
                    } => {
                        let at = self.via(*ptr, *relative, *plus, base)?;
                        self.write(at, *t, v)?;
                    }
                    _ => {
                        let at = self.addr(a, base)?;
                        self.write(at, *t, v)?;
                    }
                }
            }
            StKind::StorePtr(a, e) => {
                let v = self.eval(e, base)?;
                let at = self.addr(a, base)?;
                self.write(at, Elem::ULInt, v)?;
            }
            StKind::Copy(to, from, size) => {
                let (to, from) = (self.own(to, base)?, self.own(from, base)?);
                let n = *size as usize;
                self.check(to, n)?;
                self.check(from, n)?;
                self.st.memory.copy_within(from..from + n, to);
            }
            StKind::Text(to, size, t) => self.store_text(to, *size, t, base)?,
            StKind::Bytes(to, bytes) => {
                let to = self.own(to, base)?;
                self.check(to, bytes.len())?;
                self.st.memory[to..to + bytes.len()].copy_from_slice(bytes);
            }
            StKind::If(arms, otherwise) => {
                for (cond, body) in arms {
                    if self.operand(cond, base)?.int() != 0 {
                        return self.block(body, base);
                    }
                }
                return self.block(otherwise, base);
            }
            StKind::Case(sel, arms, otherwise) => {
                let v = self.operand(sel, base)?.int();
                for (ranges, body) in arms {
                    if ranges.iter().any(|(lo, hi)| (*lo..=*hi).contains(&v)) {
                        return self.block(body, base);
                    }
                }
                return self.block(otherwise, base);
            }
            StKind::For {
                var,
                ty,
                from,
                to,
                by,
                body,
            } => return self.for_loop(var, *ty, (from, to, by), body, base),
            StKind::While(cond, body) => loop {
                self.tree_at(s.at);
                self.step()?;
                if self.eval(cond, base)?.int() == 0 {
                    break;
                }
                match self.block(body, base)? {
                    Flow::Exit => break,
                    Flow::Return => return Ok(Flow::Return),
                    _ => {}
                }
            },
            StKind::Repeat(body, until) => loop {
                self.step()?;
                match self.block(body, base)? {
                    Flow::Exit => break,
                    Flow::Return => return Ok(Flow::Return),
                    _ => {}
                }
                self.tree_at(s.at);
                if self.eval(until, base)?.int() != 0 {
                    break;
                }
            },
            StKind::Exit => return Ok(Flow::Exit),
            StKind::Continue => return Ok(Flow::Continue),
            StKind::Return => return Ok(Flow::Return),
            StKind::CallFb {
                pou,
                instance,
                inputs,
                outputs,
            } => self.call_block(s, base, (instance, inputs, outputs), Some(*pou), None)?,
            StKind::CallStdFb {
                fb,
                instance,
                inputs,
                outputs,
            } => self.call_block(s, base, (instance, inputs, outputs), None, Some(*fb))?,
            StKind::Eval(e) => {
                self.eval(e, base)?;
            }
        }
        Ok(Flow::Next)
    }

    fn for_loop(
        &mut self,
        var: &Addr,
        ty: Elem,
        (from, to, by): (&Ex, &Ex, &Ex),
        body: &'a [St],
        base: u32,
    ) -> Run<Flow> {
        let at = self.addr(var, base)?;
        let (first, last, step) = (
            self.eval(from, base)?.int(),
            self.eval(to, base)?.int(),
            self.eval(by, base)?.int(),
        );
        let mut i = first;
        loop {
            if (step >= 0 && i > last) || (step < 0 && i < last) {
                break;
            }
            self.write(at, ty, V::I(i))?;
            self.step()?;
            match self.block(body, base)? {
                Flow::Exit => break,
                Flow::Return => return Ok(Flow::Return),
                _ => {}
            }
            // The body may have changed the variable; a step of 0 ends on the budget.
            i = self.read(at, ty)?.int();
            match i.checked_add(step) {
                Some(next) => i = next,
                None => break,
            }
        }
        Ok(Flow::Next)
    }

    /// A function block instance's call: its inputs, its body (a POU's, or a standard
    /// block's), its outputs.
    fn call_block(
        &mut self,
        s: &St,
        base: u32,
        (instance, inputs, outputs): (&Addr, &'a [BlockInput], &[BlockOutput]),
        pou: Option<usize>,
        fb: Option<crate::check::std_lib::StdFb>,
    ) -> Run<()> {
        let at = self.own(instance, base)? as u32;
        self.store_all(inputs, at, base)?;
        self.passing = inputs;
        match (pou, fb) {
            (Some(pou), _) => self.run_body(pou, at)?,
            (_, Some(fb)) => self.run_std_fb(fb, at as usize)?,
            _ => {}
        }
        self.tree_at(s.at);
        self.read_outputs(outputs, at, base)
    }

    fn store_all(&mut self, inputs: &[BlockInput], at: u32, base: u32) -> Run<()> {
        for (offset, t, e) in inputs {
            // Most inputs are constants or variables (Velocity := 360.0).
            let v = self.operand(e, base)?;
            self.write_own((at + offset) as usize, *t, v)?;
        }
        Ok(())
    }

    fn read_outputs(&mut self, outputs: &[BlockOutput], at: u32, base: u32) -> Run<()> {
        for (offset, t, target, negated, there) in outputs {
            let v = self.read_own((at + offset) as usize, *t)?;
            let v = ops::output(v, *negated, *t, *there)?;
            let to = self.addr(target, base)?;
            self.write(to, *there, v)?;
        }
        Ok(())
    }

    /// Where a place is.
    fn addr(&mut self, a: &Addr, base: u32) -> Run<Loc> {
        Ok(match a {
            Addr::Static(o) => Loc::Own(*o as usize),
            Addr::Instance(o) => Loc::Own((base + o) as usize),
            Addr::Offset(inner, o) => self.addr(inner, base)?.plus(*o as usize),
            Addr::Index {
                base: array,
                index,
                lo,
                len,
                stride,
            } => {
                let i = self.eval(index, base)?.int();
                let hi = lo + i64::from(*len) - 1;
                if i < *lo || i > hi {
                    return Err(self.fault_with(Fault::IndexOutOfRange, [i, *lo, hi]));
                }
                let step = (i - lo) as usize * *stride as usize;
                self.addr(array, base)?.plus(step)
            }
            Addr::Deref(p) => {
                let p = self.eval(p, base)?.int();
                pointed(p)?
            }
            Addr::Via {
                ptr,
                relative,
                plus,
            } => self.via(*ptr, *relative, *plus, base)?,
        })
    }

    /// Where `p^` plus `plus` bytes is, for the pointer variable `p` at `ptr`.
    #[inline(always)]
    fn via(&self, ptr: u32, relative: bool, plus: u32, base: u32) -> Run<Loc> {
        let at = if relative { base + ptr } else { ptr };
        let p = read_mem(&self.st.memory, at as usize, Elem::ULInt)?.int();
        Ok(pointed(p)?.plus(plus as usize))
    }

    fn own(&mut self, a: &Addr, base: u32) -> Run<usize> {
        match self.addr(a, base)? {
            Loc::Own(at) => Ok(at),
            Loc::Image(_) => Err(Fault::ImageCopy),
        }
    }

    fn check(&self, at: usize, n: usize) -> Run<()> {
        match at.checked_add(n) {
            Some(end) if end <= self.st.memory.len() => Ok(()),
            _ => Err(Fault::BadPointer),
        }
    }

    #[inline]
    pub(crate) fn read(&self, at: Loc, t: Elem) -> Run<V> {
        match at {
            Loc::Own(at) => self.read_own(at, t),
            Loc::Image(at) => self.image_read(at, t),
        }
    }

    #[inline]
    pub(crate) fn write(&mut self, at: Loc, t: Elem, v: V) -> Run<()> {
        match at {
            Loc::Own(at) => self.write_own(at, t, v),
            Loc::Image(at) => self.image_write(at, t, v),
        }
    }

    #[inline]
    pub(crate) fn read_own(&self, at: usize, t: Elem) -> Run<V> {
        read_mem(&self.st.memory, at, t)
    }

    #[inline]
    pub(crate) fn write_own(&mut self, at: usize, t: Elem, v: V) -> Run<()> {
        write_mem(&mut self.st.memory, at, t, v)
    }

    /// `e`'s value, a constant's or a variable's without a call (the leaves of most
    /// expressions).
    #[inline(always)]
    fn operand(&mut self, e: &Ex, base: u32) -> Run<V> {
        match e {
            Ex::Int(v) => Ok(V::I(*v)),
            Ex::Real(v) => Ok(V::F(*v)),
            Ex::Var {
                offset,
                relative,
                ty,
            } => {
                let at = if *relative { base + offset } else { *offset };
                self.read_own(at as usize, *ty)
            }
            _ => self.eval(e, base),
        }
    }

    fn eval(&mut self, e: &Ex, base: u32) -> Run<V> {
        Ok(match e {
            Ex::Int(_) | Ex::Real(_) | Ex::Var { .. } => self.operand(e, base)?,
            Ex::Load(a, t) => {
                let at = match **a {
                    // The manuals' `p^.field`, without a call.
                    Addr::Via {
                        ptr,
                        relative,
                        plus,
                    } => self.via(ptr, relative, plus, base)?,
                    _ => self.addr(a, base)?,
                };
                self.read(at, *t)?
            }
            Ex::LoadPtr(a) => {
                let at = self.addr(a, base)?;
                self.read(at, Elem::ULInt)?
            }
            Ex::AddrOf(a) => V::I(tagged(self.addr(a, base)?)),
            Ex::Neg(x, t) => ops::neg(self.operand(x, base)?, *t),
            Ex::Not(x, t) => ops::not(self.operand(x, base)?, *t),
            Ex::Bin(op @ (BinOp::AndThen | BinOp::OrElse), _, a, b) => {
                let x = self.operand(a, base)?.int() != 0;
                let y = if x == (*op == BinOp::AndThen) {
                    self.operand(b, base)?.int() != 0
                } else {
                    x
                };
                V::I(i64::from(y))
            }
            Ex::Bin(op, t, a, b) => {
                let (x, y) = (self.operand(a, base)?, self.operand(b, base)?);
                ops::binary(*op, *t, x, y)?
            }
            Ex::Conv(from, to, x) => ops::convert(self.operand(x, base)?, *from, *to)?,
            Ex::Std(f, t, args) => self.std_fn(*f, *t, args, base)?,
            Ex::TextEq(pair) => V::I(i64::from(self.text_eq(&pair.0, &pair.1, base)?)),
            Ex::Text(e) => self.text_value(e, base)?,
            Ex::Call(c, ty) => {
                let frame = self.call_function(c, base)?;
                let at = match &c.this {
                    Some(this) => Loc::Own(frame as usize + this.value as usize),
                    None => self.addr(&c.value, base)?,
                };
                self.read(at, *ty)?
            }
        })
    }

    /// A user function's call (out of `eval`: its values' array would make every `eval`'s
    /// frame large); its value is left in its frame, whose offset it returns.
    #[inline(never)]
    pub(super) fn call_function(&mut self, c: &crate::ir::FnCall, base: u32) -> Run<u32> {
        if c.texts.is_empty() {
            return self.call_with(c, base, &mut []);
        }
        self.call_with_texts(c, base)
    }

    /// As [`Exec::call_function`] for a call with STRING inputs: their characters held
    /// on the stack meanwhile.
    #[inline(never)]
    fn call_with_texts(&mut self, c: &crate::ir::FnCall, base: u32) -> Run<u32> {
        let mut bufs: [text::Buf; crate::ir::MAX_TEXT_INPUTS] =
            core::array::from_fn(|_| text::Buf::new());
        let n = c.texts.len().min(bufs.len());
        self.call_with(c, base, &mut bufs[..n])
    }

    fn call_with(&mut self, c: &crate::ir::FnCall, base: u32, bufs: &mut [text::Buf]) -> Run<u32> {
        let (pou, inputs, back) = (c.pou, &c.inputs, &c.back);
        // The values first, in their order (one may call this function too), then the frame.
        // A VAR_IN_OUT's leaf is read where its place is found, and goes back there: its
        // place bound when its turn comes, before the body or a later value moves an index.
        let mut values = [V::I(0); crate::ir::MAX_CALL_INPUTS];
        let mut places = [Loc::Own(0); crate::ir::MAX_CALL_INPUTS];
        let mut texts = c.texts.iter().zip(bufs.iter_mut()).peekable();
        for k in 0..=inputs.len() {
            while let Some(((_, _, _, t), buf)) = texts.next_if(|((before, ..), _)| *before <= k) {
                self.text_into(t, base, buf)?;
            }
            let (Some(v), Some((offset, t, e))) = (values.get_mut(k), inputs.get(k)) else {
                break;
            };
            *v = match back.iter().position(|(o, _, _)| o == offset) {
                Some(j) => {
                    places[j] = self.addr(&back[j].2, base)?;
                    self.read(places[j], *t)?
                }
                None => self.eval(e, base)?,
            };
        }
        let statement = self.place();
        // A function's variables start from zero and their initial values each call; a
        // method's frame is its instance, whose own variables (only) do so.
        let (frame, (from, to)) = match &c.this {
            Some(this) => {
                let at = u32::try_from(self.own(&this.instance, base)?);
                (at.map_err(|_| Fault::BadPointer)?, this.own)
            }
            None => (
                self.code.layout.statics[pou],
                (0, self.code.layout.pous[pou].0),
            ),
        };
        let own = frame as usize + from as usize..frame as usize + to as usize;
        self.st
            .memory
            .get_mut(own)
            .ok_or(Fault::BadPointer)?
            .fill(0);
        // Its own initial values, its block instances' (declared and given), as a POU's.
        self.init_pou(pou, frame)?;
        for (v, (offset, t, _)) in values.iter().zip(inputs.iter()) {
            self.write_own((frame + offset) as usize, *t, *v)?;
        }
        for ((_, offset, size, _), buf) in c.texts.iter().zip(bufs.iter()) {
            self.put_text((frame + offset) as usize, *size as usize, buf.chars())?;
        }
        self.run_body(pou, frame)?;
        self.set_place(statement);
        // The VAR_IN_OUTs back into the caller's variables, leaf by leaf, then the outputs.
        for (&at, (offset, t, _)) in places.iter().zip(back.iter()) {
            let v = self.read_own((frame + offset) as usize, *t)?;
            self.write(at, *t, v)?;
        }
        self.read_outputs(&c.outputs, frame, base)?;
        Ok(frame)
    }

    /// Whether two STRINGs hold the same characters before their NUL (or their end).
    #[inline(never)]
    fn text_eq(&mut self, a: &crate::ir::Text, b: &crate::ir::Text, base: u32) -> Run<bool> {
        if matches!(a, crate::ir::Text::Fn(_)) || matches!(b, crate::ir::Text::Fn(_)) {
            return Ok(self.text_cmp(a, b, base)?.is_eq());
        }
        let (x, y) = (self.text_at(a, base)?, self.text_at(b, base)?);
        let memory = &self.st.memory;
        Ok(chars(memory, a, x)? == chars(memory, b, y)?)
    }

    /// Where a STRING operand's bytes are in the program's memory (`None`: a literal's).
    fn text_at(&mut self, t: &crate::ir::Text, base: u32) -> Run<Option<(usize, usize)>> {
        match t {
            crate::ir::Text::Const(_) | crate::ir::Text::Fn(_) => Ok(None),
            crate::ir::Text::At(addr, n) => Ok(Some((self.own(addr, base)?, *n as usize))),
        }
    }
}
