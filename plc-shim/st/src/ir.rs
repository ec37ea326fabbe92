//! The compiled form of a checked program: statements and expressions with every name
//! resolved to a place in the program's memory and every operation to its type. The runtime
//! ([`crate::vm`]) walks it each cycle without allocating.

use crate::ast::BinOp;
use crate::check::std_lib::StdFb;
use crate::diag::Pos;
use crate::types::Elem;

/// A place in the program's memory.
#[derive(Debug, Clone, PartialEq)]
pub enum Addr {
    /// An absolute offset (globals, programs' and functions' variables).
    Static(u32),
    /// An offset from the running function block instance's base.
    Instance(u32),
    /// A field or member `offset` bytes into a place.
    Offset(Box<Addr>, u32),
    /// Element `index - lo` of `len` elements `stride` bytes apart, from a place.
    Index {
        /// The array.
        base: Box<Addr>,
        /// The index.
        index: Box<Ex>,
        /// The lower bound.
        lo: i64,
        /// How many elements.
        len: u32,
        /// Bytes per element.
        stride: u32,
    },
    /// Where a pointer value points.
    Deref(Box<Ex>),
    /// `plus` bytes past where the pointer variable at `ptr` points (from the running
    /// instance's base with `relative`): `p^.field` of a pointer variable `p`, the manuals'
    /// common access to the HLI, in one step.
    Via {
        /// The pointer variable's offset.
        ptr: u32,
        /// From the instance's base.
        relative: bool,
        /// Bytes past the place pointed at.
        plus: u32,
    },
}

/// An expression: its value is an integer (any integer type, BOOL, TIME, a pointer) or a real.
#[derive(Debug, Clone, PartialEq)]
pub enum Ex {
    /// An integer constant.
    Int(i64),
    /// A real constant.
    Real(f64),
    /// The value of type `Elem` at a place.
    Load(Box<Addr>, Elem),
    /// The value of type `Elem` of a variable: `offset` bytes from the memory's start, or
    /// from the running instance's base with `relative` (the common case, without a place to
    /// walk).
    Var {
        /// Its offset.
        offset: u32,
        /// From the instance's base.
        relative: bool,
        /// Its type.
        ty: Elem,
    },
    /// The pointer at a place.
    LoadPtr(Box<Addr>),
    /// A pointer to a place.
    AddrOf(Box<Addr>),
    /// `-x` of an integer or real type.
    Neg(Box<Ex>, Elem),
    /// NOT of BOOL or bits.
    Not(Box<Ex>, Elem),
    /// `a op b`, both of type `Elem` (a comparison's value is BOOL).
    Bin(BinOp, Elem, Box<Ex>, Box<Ex>),
    /// A conversion between elementary types.
    Conv(Elem, Elem, Box<Ex>),
    /// Whether two STRINGs hold the same characters (before their NUL).
    TextEq(Box<(Text, Text)>),
    /// A value computed from STRINGs: an ordering, a length, a position, a number.
    Text(Box<TextEx>),
    /// A standard function, the type it computes in, its values.
    Std(StdFn, Elem, Vec<Ex>),
    /// A user function's call and the type of its value.
    Call(Box<FnCall>, Elem),
}

/// A user function's call: its body index, its inputs (offsets in its frame), and the place
/// of its value.
#[derive(Debug, Clone, PartialEq)]
pub struct FnCall {
    /// The function's index among the POUs.
    pub pou: usize,
    /// Its elementary inputs (at most [`MAX_CALL_INPUTS`]): offset in its frame, type, value.
    pub inputs: Vec<BlockInput>,
    /// Its STRING inputs (at most [`MAX_TEXT_INPUTS`]): how many of `inputs` come before it
    /// in the call (the values are taken in their order), its offset in the frame, its
    /// size with the NUL, its characters (cut to the size when longer).
    pub texts: Vec<(usize, u32, u32, Text)>,
    /// Its value's place.
    pub value: Addr,
    /// Its VAR_IN_OUTs' leaves copied back after the call: offset in its frame, type, the
    /// caller's place.
    pub back: Vec<(u32, Elem, Addr)>,
    /// Its outputs given in the call (`frac => f`; offsets in its frame), written after it
    /// in their order as a block's are.
    pub outputs: Vec<BlockOutput>,
    /// A method's call: its frame is an instance (its program's memory).
    pub this: Option<ThisCall>,
}

/// A method's call ([`FnCall::this`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ThisCall {
    /// The instance (found after the values, as the function's frame is then taken).
    pub instance: Addr,
    /// Its own variables, from this offset in the instance to the next: only they start
    /// from zero and their initial values at each call.
    pub own: (u32, u32),
    /// Its value's offset in the instance (read there after the call, from the frame the
    /// call ran on, not from the instance's place found again).
    pub value: u32,
}

/// A STRING's characters: a literal's (NUL-padded), a variable's `size` bytes at a place, or
/// a string function's result.
#[derive(Debug, Clone, PartialEq)]
pub enum Text {
    /// A literal.
    Const(Box<[u8]>),
    /// A variable: its place and size (with the NUL).
    At(Addr, u32),
    /// A string function's result (at most [`MAX_TEXT`] characters).
    Fn(Box<TextFn>),
}

/// The most characters a computed STRING holds (STRING(255), as TwinCAT's string functions).
pub const MAX_TEXT: usize = 255;

/// A string function whose value is a STRING (positions count from 1, as IEC 61131-3's).
#[derive(Debug, Clone, PartialEq)]
pub enum TextFn {
    /// CONCAT of its values.
    Concat(Vec<Text>),
    /// LEFT(s, n).
    Left(Text, Ex),
    /// RIGHT(s, n).
    Right(Text, Ex),
    /// MID(s, n, p).
    Mid(Text, Ex, Ex),
    /// INSERT(s, t, p): `t` after the first `p` characters of `s`.
    Insert(Text, Text, Ex),
    /// DELETE(s, n, p).
    Delete(Text, Ex, Ex),
    /// REPLACE(s, t, n, p): `n` characters from `p` on replaced by `t`.
    Replace(Text, Text, Ex, Ex),
    /// A value of the type as text (`INT_TO_STRING`, ...).
    Of(Elem, Ex),
    /// A user function's STRING value: the call, and the size of its value (with the NUL).
    Call(FnCall, u32),
}

/// A value computed from STRINGs.
#[derive(Debug, Clone, PartialEq)]
pub enum TextEx {
    /// An ordering of two STRINGs (`<`, `>`, `<=`, `>=`: by their bytes).
    Cmp(BinOp, Text, Text),
    /// LEN.
    Len(Text),
    /// FIND(s, t): where `t` first starts in `s`, 0 if nowhere.
    Find(Text, Text),
    /// A STRING read as a value of the type (`STRING_TO_INT`, ...).
    To(Elem, Text),
}

/// The most inputs a call of a user function passes (their values are held on the stack while
/// the function's frame is made ready).
pub const MAX_CALL_INPUTS: usize = 32;

/// The most STRING inputs a call of a user function passes (their characters are held on
/// the stack while the function's frame is made ready).
pub const MAX_TEXT_INPUTS: usize = 4;

/// The most values a standard function (MIN, MAX, MUX, ...) takes (held on the stack).
pub const MAX_STD_VALUES: usize = 16;

/// An input of a block's call: its offset in the instance, its type, its value.
pub type BlockInput = (u32, Elem, Ex);

/// An output of a block's call: its offset in the instance, its type, where it goes, whether
/// negated, and the type there (the output's, or one it widens to: converted).
pub type BlockOutput = (u32, Elem, Addr, bool, Elem);

/// A CASE arm: the ranges of values it takes (a single value is a range of one) and its
/// statements.
pub type CaseArm = (Vec<(i64, i64)>, Vec<St>);

/// A standard function the runtime computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StdFn {
    /// ABS.
    Abs,
    /// SQRT.
    Sqrt,
    /// LN.
    Ln,
    /// LOG (base 10).
    Log,
    /// EXP.
    Exp,
    /// SIN.
    Sin,
    /// COS.
    Cos,
    /// TAN.
    Tan,
    /// ASIN.
    Asin,
    /// ACOS.
    Acos,
    /// ATAN.
    Atan,
    /// MIN of its values.
    Min,
    /// MAX of its values.
    Max,
    /// LIMIT(min, in, max).
    Limit,
    /// SEL(g, in0, in1).
    Sel,
    /// MUX(k, in0, ..).
    Mux,
    /// TRUNC.
    Trunc,
    /// SHL.
    Shl,
    /// SHR.
    Shr,
    /// ROL.
    Rol,
    /// ROR.
    Ror,
    /// EXPT: the first value to the power of the second.
    Expt,
    /// MOVE: the value itself.
    Move,
    /// `TIME()` and `LTIME()`: the PLC's clock (the cycle's time since the start).
    Now,
    /// MEMCPY and MEMMOVE (TwinCAT's Tc2_System): `n` bytes from the second pointer to the
    /// first, within the program's own memory (a statement).
    MemCpy,
    /// MEMSET: `n` bytes from the pointer on set to a byte's value (a statement).
    MemSet,
    /// MEMCMP: `n` bytes at two pointers compared: 0 when equal, else -1 or 1 as the first
    /// differing byte of the first is smaller or greater.
    MemCmp,
}

/// A statement, with where it stands for a fault's report.
#[derive(Debug, Clone, PartialEq)]
pub struct St {
    /// What it does.
    pub kind: StKind,
    /// Its file (index into the program's files) and place.
    pub at: (u16, Pos),
}

/// What a statement does.
#[derive(Debug, Clone, PartialEq)]
pub enum StKind {
    /// Stores a value of an elementary type.
    Store(Addr, Elem, Ex),
    /// Stores a pointer.
    StorePtr(Addr, Ex),
    /// Copies `size` bytes (a structure, an array, a string).
    Copy(Addr, Addr, u32),
    /// Writes constant bytes (a string literal, NUL-padded to its STRING's size).
    Bytes(Addr, Box<[u8]>),
    /// Writes a string function's result into a STRING of `size` bytes (with its NUL),
    /// cut to fit.
    Text(Addr, u32, Text),
    /// IF/ELSIF/ELSE.
    If(Vec<(Ex, Vec<St>)>, Vec<St>),
    /// CASE: each arm's ranges of values and statements, then ELSE.
    Case(Ex, Vec<CaseArm>, Vec<St>),
    /// FOR.
    For {
        /// The control variable.
        var: Addr,
        /// Its type.
        ty: Elem,
        /// First value.
        from: Ex,
        /// Last value.
        to: Ex,
        /// Step.
        by: Ex,
        /// The statements.
        body: Vec<St>,
    },
    /// WHILE.
    While(Ex, Vec<St>),
    /// REPEAT .. UNTIL.
    Repeat(Vec<St>, Ex),
    /// EXIT.
    Exit,
    /// CONTINUE.
    Continue,
    /// RETURN.
    Return,
    /// A function block instance's call: its inputs stored, its body run on its base, its
    /// outputs read.
    CallFb {
        /// The function block's index among the POUs.
        pou: usize,
        /// The instance.
        instance: Addr,
        /// Inputs (stores relative to the instance) before the body.
        inputs: Vec<BlockInput>,
        /// Outputs after it.
        outputs: Vec<BlockOutput>,
    },
    /// A standard function block's call.
    CallStdFb {
        /// Which one.
        fb: StdFb,
        /// The instance.
        instance: Addr,
        /// Inputs.
        inputs: Vec<BlockInput>,
        /// Outputs.
        outputs: Vec<BlockOutput>,
    },
    /// An expression whose value is dropped (a function called as a statement).
    Eval(Ex),
}
