//! The compiled tree once more, flattened: each POU body becomes a list of operations on
//! registers ([`Op`]) that the runtime steps through with a program counter ([`super::run`]),
//! instead of walking the tree with a call per node. Every variable, constant and pointer
//! field the manuals' programs use is an operand of the operation that needs it; control
//! flow is jumps ([`super::build`] builds them). What is rare keeps the tree: an operation
//! hands a statement, an expression or a place to the tree walker ([`Op::TreeSt`],
//! [`Op::Tree`], [`Op::Addr`]), so both ways share every rule (the operations call the same
//! `ops`, `read`, `write` and `via`), and a test runs programs both ways and compares their
//! memory. A statement whose own expressions call a user function is the tree's whole: the
//! function may write what an operand reads, and an operation reads its operands when it
//! runs, the tree in its order.
//!
//! A body's registers are a window of the state's register file; a call (a block's body, or
//! the tree from inside a body) runs in the window above its caller's, so nothing a callee
//! does touches a value its caller holds. Recursion is refused by the checker, so the file's
//! size is the deepest chain of calls from any POU (the initial values at load call
//! functions too), known at load.

use super::build::{Builder, Loops};
use super::fast::{Bytes, Input};
use super::library::Library;
use super::V;
use crate::ast::BinOp;
use crate::check::std_lib::StdFb;
use crate::check::Compiled;
use crate::diag::Pos;
use crate::ir::{Addr, BlockInput, Ex, St};
use crate::types::Elem;

/// A register's index in its window.
pub(crate) type R = u16;

/// Where an operation takes a value from.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Src {
    /// A register.
    R(R),
    /// An integer constant that fits 32 bits.
    I(i32),
    /// A constant of the pool ([`Codes::consts`]): a wider integer, or a real.
    K(u32),
    /// A variable: its offset (from the instance's base when relative) and type.
    Var(u32, bool, Elem),
}

/// Where an operation stores a value.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Dst {
    /// The program's memory at an offset (from the instance's base when relative).
    Own(u32, bool),
    /// `plus` bytes past where the pointer variable at the offset points (`p^.field`).
    Via(u32, bool, u32),
    /// Where the tagged pointer in a register points (an [`Op::Addr`] made it).
    At(R),
}

/// One operation. Jumps name an index into the body's operations.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Op {
    /// A statement begins: its place for a fault, and one step of the budget.
    Stmt(u32),
    /// One step of the budget (a REPEAT's round).
    Step,
    /// The place for a fault, without a step.
    At(u32),
    /// `d := a op b` of type `t`.
    Bin(BinOp, Elem, R, Src, Src),
    /// As [`Op::Bin`] for a type that is no real: integer operands, an integer result.
    BinI(BinOp, Elem, R, Src, Src),
    /// `d := -a`.
    Neg(Elem, R, Src),
    /// `d := NOT a`.
    Not(Elem, R, Src),
    /// `d := a` converted from the first type to the second.
    Conv(Elem, Elem, R, Src),
    /// `d := a`.
    Mov(R, Src),
    /// `d :=` the value of the type `plus` bytes past where the pointer variable points.
    LoadVia(R, u32, bool, u32, Elem),
    /// `d :=` the tagged pointer `plus` bytes past where the pointer value points (NULL and
    /// values below it are faults); for an access (true), one past the pointers' range too,
    /// as the access itself would fault there.
    PtrAt(R, Src, u32, bool),
    /// `d :=` the value of the type where the tagged pointer in the register points.
    LoadAt(R, R, Elem),
    /// `d :=` an expression the tree computes (its index among [`Codes::exprs`]).
    Tree(R, u32),
    /// `d :=` the tagged pointer to a place the tree finds (its index among
    /// [`Codes::places`]).
    Addr(R, u32),
    /// Stores a value of the type.
    Store(Dst, Elem, Src),
    /// Stores a pointer.
    StorePtr(Dst, Src),
    /// A statement the tree runs (its index among [`Codes::stmts`]); where its EXIT and
    /// CONTINUE go (`u32::MAX`: end the body, as outside a loop).
    TreeSt(u32, u32, u32),
    /// Goes on at the operation.
    Jump(u32),
    /// Goes on at the operation when the value is not 0 (`IF NOT x`: [`Op::Not`] and
    /// [`Op::JumpIfNot`] in one).
    JumpIf(Src, u32),
    /// Goes on at the operation when the value is 0 (FALSE).
    JumpIfNot(Src, u32),
    /// Goes on at the operation unless the comparison of the two values of the type holds
    /// (an IF's or a loop's `a < b`: [`Op::Bin`] and [`Op::JumpIfNot`] in one).
    JumpCmp(BinOp, Elem, Src, Src, u32),
    /// As [`Op::JumpCmp`] for a type that is no real.
    JumpCmpI(BinOp, Elem, Src, Src, u32),
    /// A CASE of constant labels close together: goes on at the operation the table
    /// ([`Codes::switches`], its index) gives for the value, or at the next one.
    Switch(Src, u32),
    /// Goes on at the operation when the value lies in the range (a CASE arm).
    JumpIn(Src, u32, u32),
    /// A FOR's test: control variable (its offset in own memory, from the instance's base
    /// when relative), its type, the registers of the value,
    /// the last value and the step; past the last, goes on at the operation; else stores the
    /// value and takes a step.
    ForTest((u32, bool), Elem, [R; 3], u32),
    /// A FOR's next value: read back from the variable, plus the step; goes on at the test
    /// (first), or past the loop when the value overflows (second).
    ForNext((u32, bool), Elem, [R; 3], u32, u32),
    /// `d :=` the offset of a block instance in the program's memory (from the instance's
    /// base when relative), with the host's slot of a library block's instance at a fixed
    /// absolute place in the high half ([`slotted`]; 0: none).
    Inst(R, u32, bool, u32),
    /// `d :=` an element of an array at a fixed place, at the index the operand holds: its
    /// tagged pointer, or its instance offset (and host slot) for a block's instance. Its
    /// index among [`Codes::elems`].
    Elem(R, Src, u32),
    /// As [`Op::Inst`] for an instance the tree finds (index among [`Codes::places`]).
    InstTree(R, u32),
    /// Stores an input: the instance's register, the input's offset in it, type, value.
    Input(R, u32, Elem, Src),
    /// Runs POU `pou`'s body on the instance, with call site `k`'s inputs passed.
    Body(u32, R, u32),
    /// Runs a standard block on the instance, with call site `k`'s inputs passed.
    StdBody(StdFb, R, u32),
    /// Reads an output: instance, offset, its type and the type where it goes (converted
    /// when it widens), negated, where it goes.
    Output(R, u32, (Elem, Elem), bool, Dst),
    /// Stores a constant's bytes into the program's memory at an offset (from the
    /// instance's base when relative): [`Op::Store`] of a constant, specialized
    /// ([`super::fast`]).
    SetOwn(u32, bool, Bytes),
    /// `d :=` whether the variable (offset, relative; its type) equals the constant, or
    /// differs from it with `true`: [`Op::BinI`] of `=` or `<>`, specialized.
    EqVarConst(bool, R, (u32, bool), Elem, i32),
    /// `d := a op b` of two BOOLs (AND, OR, XOR): [`Op::BinI`] of BOOLs, specialized.
    Logic(BinOp, R, Src, Src),
    /// A whole block call whose instance has a fixed place and whose inputs are all
    /// operands (the common call: `fbRun(Axis := axConveyor, Velocity := 360.0)`): its
    /// index among [`Codes::call_ops`]. Its outputs follow as [`Op::Output`]s.
    Call(u32),
    /// The body ends.
    Ret,
}

// An operation is read from memory for every step of a cycle: kept at three words (a
// cycle's operations are lines of the data cache a cold cycle misses).
const _: () = assert!(core::mem::size_of::<Op>() <= 24);
const _: () = assert!(core::mem::size_of::<Src>() == 8);

/// A block call in one operation ([`Op::Call`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct CallOp {
    /// The statement's place.
    pub(crate) site: u32,
    /// The instance's offset, from the instance's base when relative.
    pub(crate) at: u32,
    pub(crate) relative: bool,
    /// Its inputs: this range of [`Codes::inputs`].
    pub(crate) inputs: (u32, u32),
    /// The POU whose body runs, or the standard block.
    pub(crate) body: Result<u32, StdFb>,
    /// Its index among [`Codes::calls`] (the inputs the host is told were passed).
    pub(crate) call: u32,
    /// The host's slot of a library block's instance at a fixed absolute place (found once
    /// here instead of at every call).
    pub(crate) slot: Option<u32>,
}

/// A CASE's jump table ([`Op::Switch`]): for values from `lo` on, where each goes
/// ([`NEXT`]: the operation after the switch, the ELSE's).
#[derive(Debug, Clone, Default)]
pub(crate) struct Switch {
    pub(crate) lo: i64,
    pub(crate) to: Vec<u32>,
}

/// A [`Switch`] entry: the operation after the switch.
pub(crate) const NEXT: u32 = u32::MAX;

/// An element of an array at a fixed place, at an index known at run time ([`Op::Elem`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct ElemOp {
    /// The array's offset (from the instance's base when relative).
    pub(crate) at: u32,
    pub(crate) relative: bool,
    /// The lower bound, how many elements, and the bytes per element.
    pub(crate) lo: i64,
    pub(crate) len: u32,
    pub(crate) stride: u32,
    /// Bytes past the element's start (a field of it).
    pub(crate) plus: u32,
    /// The element is a block instance the call runs: its offset, not a pointer, and
    /// the host slot of the array's first element plus one when the elements are a
    /// library block's instances in consecutive slots (0: none).
    pub(crate) instance: Option<u32>,
}

/// An instance's offset with its host slot plus one (0: none) in the high half: what an
/// instance register holds (its offset is the low half, as `as u32` reads it).
pub(crate) fn slotted(at: u32, slot1: u32) -> i64 {
    i64::from(at) | (i64::from(slot1) << 32)
}

/// A POU body's operations and how many registers they use.
#[derive(Debug, Clone, Default)]
pub(crate) struct Code {
    pub(crate) ops: Vec<Op>,
    pub(crate) regs: u16,
    /// The operations compiled to native code ([`super::native`]; `None`: run one by one).
    pub(crate) native: Option<super::native::Entry>,
}

/// Every POU's body compiled, and what the operations refer to.
#[derive(Debug, Clone, Default)]
pub(crate) struct Codes {
    /// Per POU: its body's code (`None`: a library block's, or not compiled).
    pub(crate) bodies: Vec<Option<Code>>,
    /// The statements' places (file, position).
    pub(crate) sites: Vec<(u16, Pos)>,
    /// Statements the tree runs.
    pub(crate) stmts: Vec<St>,
    /// Expressions the tree computes.
    pub(crate) exprs: Vec<Ex>,
    /// Places the tree finds.
    pub(crate) places: Vec<Addr>,
    /// Each block call's inputs (what the block's host is told was passed).
    pub(crate) calls: Vec<Vec<BlockInput>>,
    /// The block calls in one operation.
    pub(crate) call_ops: Vec<CallOp>,
    /// Their inputs: offset in the instance, and what is stored there.
    pub(crate) inputs: Vec<(u32, Input)>,
    /// Elements at indices known at run time.
    pub(crate) elems: Vec<ElemOp>,
    /// CASE jump tables.
    pub(crate) switches: Vec<Switch>,
    /// The ranges of CASE labels ([`Op::JumpIn`]): lowest and highest value.
    pub(crate) ranges: Vec<(i64, i64)>,
    /// Constants that do not fit an operand ([`Src::K`]).
    pub(crate) consts: Vec<V>,
    /// Per POU: the bytes of an instance (a function block's).
    pub(crate) sizes: Vec<u32>,
    /// Registers of the deepest chain of calls.
    pub(crate) registers: usize,
    /// The native code of the bodies' [`Code::native`] entries (kept as long as they are).
    pub(crate) native: Option<std::sync::Arc<super::native::Jit>>,
}

/// The most registers the file may hold (the deepest chain of calls).
const MAX_REGISTERS: usize = 1 << 16;

impl Codes {
    /// The operand of constant `v`: in the operand when it fits, else in the pool.
    pub(crate) fn constant(&mut self, v: V) -> Src {
        if let V::I(x) = v {
            if let Ok(x) = i32::try_from(x) {
                return Src::I(x);
            }
        }
        self.consts.push(v);
        Src::K((self.consts.len() - 1) as u32)
    }

    /// Compiles every body of `c` but those of `library` POUs, to operations and on to
    /// native code; nothing (every body on the tree) when the registers would exceed
    /// [`MAX_REGISTERS`].
    pub(crate) fn of(c: &Compiled, library: &Library) -> Codes {
        let mut codes = Codes {
            sizes: c.layout.pous.iter().map(|p| p.0).collect(),
            ..Codes::default()
        };
        for (pou, (_, body)) in c.bodies.iter().enumerate() {
            let host = library.of_pou.get(pou).copied().flatten().is_some();
            let code = (!host)
                .then(|| {
                    let mut b = Builder::new(&mut codes, library);
                    b.block(body, Loops::None);
                    b.finish()
                })
                .flatten();
            codes.bodies.push(code);
        }
        // Every POU, not only the programs: the initial values at load may call functions.
        let mut need = vec![None; c.bodies.len()];
        let deepest = (0..c.bodies.len())
            .map(|p| codes.need(c, p, &mut need, 0))
            .collect::<Option<Vec<usize>>>()
            .map(|n| n.into_iter().max().unwrap_or(0));
        match deepest {
            Some(n) if n <= MAX_REGISTERS => codes.registers = n,
            _ => return Codes::default(),
        }
        super::native::compile(&mut codes, u64::from(c.layout.size));
        codes
    }

    /// Registers POU `pou`'s body and everything it calls need (`None`: deeper than the
    /// POUs, which only a cycle of calls would be).
    fn need(
        &self,
        c: &Compiled,
        pou: usize,
        memo: &mut Vec<Option<usize>>,
        depth: usize,
    ) -> Option<usize> {
        if let Some(n) = memo[pou] {
            return Some(n);
        }
        if depth > c.bodies.len() {
            return None;
        }
        let own = self.bodies[pou].as_ref().map_or(0, |b| usize::from(b.regs));
        let mut callees = Vec::new();
        let (inits, body) = &c.bodies[pou];
        for s in inits.iter().chain(body) {
            super::callees::of_st(s, &mut callees);
        }
        let mut deepest = 0;
        for callee in callees {
            deepest = deepest.max(self.need(c, callee, memo, depth + 1)?);
        }
        memo[pou] = Some(own + deepest);
        memo[pou]
    }
}
