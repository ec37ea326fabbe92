//! The program tree. Spans locate every node in the source; they do not take part in tree
//! equality, so a re-parsed printout compares equal to the original.

mod expr;
mod names;

pub use expr::{BinOp, Expr, Func};
pub use names::{AxisName, Name};

/// A source range as byte offsets. Lines and columns are counted only when a diagnostic
/// needs them (see [`super::Diagnostic`]): keeping them in every node made the tree half
/// again as large, and the tree's size is what parsing a long program mostly pays for.
#[derive(Debug, Clone, Copy, Default, Eq)]
pub struct Span {
    /// Byte offset of the first character (programs are far below 4 GiB; larger offsets saturate).
    pub start: u32,
    /// Byte offset after the last character.
    pub end: u32,
}

impl PartialEq for Span {
    /// Spans are locations, not content: any two compare equal.
    fn eq(&self, _other: &Self) -> bool {
        true
    }
}

/// One entry of a bracketed list: `KEY`, `KEY=expr`, `KEY3` (number glued to the key, as in
/// `ID3 COUNT1`), or a bare expression (value lists of `#CS`).
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    /// The key, upper case, if the entry has one.
    pub key: Option<Name>,
    /// A number glued to the key (`ID3` -> 3, `G01` -> 1).
    pub glued: Option<f64>,
    /// The value after `=`, or the bare expression.
    pub value: Option<Expr>,
    /// A quoted string value (`LOG_FILE="..."`), shared so decoded blocks can refer to it
    /// without allocating.
    pub text: Option<std::sync::Arc<str>>,
    /// Where the entry stands.
    pub span: Span,
}

/// An NC command (`#...`).
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// `#TRACK CS ON|OFF [options]` (also spelled `#TRACK_CS`).
    TrackCs {
        /// ON or OFF.
        on: bool,
        /// The options in the brackets.
        options: Vec<Entry>,
    },
    /// `#TRACK CS ABS`.
    TrackCsAbs,
    /// `#CHANNEL INTERFACE ON|OFF [DYN_CS|TRACK_CS]`.
    ChannelInterface {
        /// ON or OFF.
        on: bool,
        /// The interface named in the brackets.
        kind: Option<Name>,
    },
    /// `#CS ON [name] [values]`, `#CS ON [values]`, `#CS OFF [name]`.
    Cs {
        /// ON or OFF.
        on: bool,
        /// The coordinate system's name, if given.
        name: Option<Name>,
        /// X Y Z A B C values.
        values: Vec<Expr>,
    },
    /// `#TRAFO ON`, `#TRAFO OFF`, `#TRAFO [id]`, `#TRAFO ON [id]`.
    Trafo {
        /// ON (Some(true)), OFF (Some(false)) or just an id.
        on: Option<bool>,
        /// Kinematic id in brackets.
        id: Option<Expr>,
    },
    /// `#KIN ID [id]`.
    KinId {
        /// The kinematic id.
        id: Expr,
    },
    /// `#SIGNAL SYN [ID.. COUNT..]`.
    SignalSyn {
        /// The options.
        options: Vec<Entry>,
    },
    /// `#WAIT SYN [ID..]`.
    WaitSyn {
        /// The options.
        options: Vec<Entry>,
    },
    /// `#WAIT INDP ALL`.
    WaitIndpAll,
    /// `#FLUSH WAIT` (true) or `#FLUSH CONTINUE` (false).
    Flush {
        /// WAIT.
        wait: bool,
    },
    /// `#PSET axis=value ...` (or axis words).
    Pset {
        /// Axis assignments.
        axes: Vec<AxisWord>,
    },
    /// `#PRESET` (all axes) or `#PRESET axis ...`.
    Preset {
        /// Axes whose preset is removed; empty = all.
        axes: Vec<AxisName>,
    },
    /// `#MSG ["text"]`: a message to the operator.
    Msg {
        /// The text.
        text: std::sync::Arc<str>,
    },
    /// `#TIME t`: dwell t seconds.
    Time {
        /// Seconds.
        seconds: Expr,
    },
    /// `#CONTOUR MODE [DEV PATH_DEV=..]`: how corners of continuous path (G61, G261) are
    /// rounded.
    Contour {
        /// The entries in the brackets.
        options: Vec<Entry>,
    },
    /// `#VAR`: the declarations of `V.P.`/`V.L.` variables follow, up to `#ENDVAR`.
    Var,
    /// `#ENDVAR`.
    EndVar,
}

/// A variable a program may assign: a P parameter or a self-defined `V.P.`/`V.L.` variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// `P12`.
    Param(u32),
    /// `V.P.NAME` (the program's) or `V.L.NAME` (the subroutine level's).
    Var(Name),
}

impl core::fmt::Display for Target {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Target::Param(n) => write!(f, "P{n}"),
            Target::Var(name) => f.write_str(name),
        }
    }
}

/// The one-letter addresses that carry a value but are not axes. The tree keeps them as
/// [`AxisWord`]s (the decoder tells them apart, and a channel may not name an axis so), which
/// keeps every item at 32 bytes. The bare dwell time after `G04` is an axis word without a
/// name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Addr {
    /// `I`: circle centre along the plane's first axis.
    I,
    /// `J`: circle centre along the plane's second axis.
    J,
    /// `K`: circle centre along the plane's third axis (G18/G19).
    K,
    /// `R`: circle radius (negative: the arc is longer than half a turn).
    R,
    /// `S`: spindle speed (1/min).
    S,
    /// `T`: tool number.
    T,
    /// `D`: tool data record (length offset); `D0` removes the offset.
    D,
}

impl Addr {
    /// The address a word's name spells, if it is one of these.
    pub fn of_name(name: &AxisName) -> Option<Addr> {
        let [letter] = name.as_bytes() else {
            return None;
        };
        Some(match letter {
            b'I' => Addr::I,
            b'J' => Addr::J,
            b'K' => Addr::K,
            b'R' => Addr::R,
            b'S' => Addr::S,
            b'T' => Addr::T,
            b'D' => Addr::D,
            _ => return None,
        })
    }

    /// Source spelling.
    pub fn letter(self) -> &'static str {
        match self {
            Addr::I => "I",
            Addr::J => "J",
            Addr::K => "K",
            Addr::R => "R",
            Addr::S => "S",
            Addr::T => "T",
            Addr::D => "D",
        }
    }
}

/// `P1 = expr`, `V.P.X = expr`.
#[derive(Debug, Clone, PartialEq)]
pub struct Assign {
    /// What is assigned.
    pub target: Target,
    /// The value.
    pub value: Expr,
}

/// A subroutine call: `L name` (a file) or `LL name` (a `%L` subroutine of the same file).
/// Data goes in and out through P parameters and `V.P.` variables, as the dialect has it.
#[derive(Debug, Clone, PartialEq)]
pub struct SubCall {
    /// `LL`: a local subroutine.
    pub local: bool,
    /// The name as written (file names keep their case).
    pub name: String,
}

/// An axis with its value: `X10`, `AB=90`, `X=V.G.TRACK_CS.X`.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisWord {
    /// Axis name, upper case.
    pub name: AxisName,
    /// The value. (Whether it was written `X10` or `X=10` is not kept: the printer chooses
    /// the form, and leaving the flag out keeps items at 32 bytes.)
    pub value: Expr,
    /// Where it stands.
    pub span: Span,
}

/// The contents of an independent axis command `X1[INDP_ASYN POS=-90 G01 F500 G90]`.
#[derive(Debug, Clone, PartialEq)]
pub struct IndependentAxis {
    /// Axis name.
    pub name: AxisName,
    /// The entries in the brackets.
    pub options: Vec<Entry>,
}

/// One item of a block.
#[derive(Debug, Clone, PartialEq)]
pub enum Item {
    /// `G<n>`.
    G {
        /// The code (leading zeros dropped).
        code: u32,
        /// Where it stands.
        span: Span,
    },
    /// `F<value>` / `F=expr`.
    Feed {
        /// The value.
        value: Expr,
        /// Where it stands.
        span: Span,
    },
    /// `M<n>`.
    M {
        /// The M code.
        code: u32,
        /// Where it stands.
        span: Span,
    },
    /// An axis word.
    Axis(AxisWord),
    /// An independent axis command `X1[INDP_ASYN POS=-90 G01 F500 G90]`.
    IndependentAxis {
        /// The axis and its entries (boxed, so that this rare item does not make every item
        /// larger).
        axis: Box<IndependentAxis>,
        /// Where it stands.
        span: Span,
    },
    /// A `#` command (boxed, so the common items stay small).
    Command {
        /// The command.
        command: Box<Command>,
        /// Where it stands.
        span: Span,
    },
    /// `P1 = expr`, `V.L.X = expr` (boxed: rare next to axis words).
    Assign {
        /// The assignment.
        assign: Box<Assign>,
        /// Where it stands.
        span: Span,
    },
    /// `L name`, `LL name` (boxed).
    Call {
        /// The call.
        call: Box<SubCall>,
        /// Where it stands.
        span: Span,
    },
    /// A `$` statement (boxed).
    Control {
        /// The control statement (boxed, so the common items stay small).
        control: Box<Control>,
        /// Where it stands.
        span: Span,
    },
}

/// Control flow.
#[derive(Debug, Clone, PartialEq)]
pub enum Control {
    /// `$WHILE cond`.
    While(Expr),
    /// `$ENDWHILE`.
    EndWhile,
    /// `$IF cond`.
    If(Expr),
    /// `$ELSEIF cond`.
    ElseIf(Expr),
    /// `$ELSE`.
    Else,
    /// `$ENDIF`.
    EndIf,
    /// `$FOR P1 = start, end, step`: counts up (or down, with a negative step) while the
    /// variable has not passed `end`.
    For {
        /// The counter.
        var: Target,
        /// First value.
        start: Expr,
        /// Last value.
        end: Expr,
        /// Step (not 0).
        step: Expr,
    },
    /// `$ENDFOR`.
    EndFor,
    /// `$DO`: the body runs once, then again while the `$ENDDO` condition holds.
    Do,
    /// `$ENDDO cond`.
    EndDo(Expr),
    /// `$SWITCH expr`.
    Switch(Expr),
    /// `$CASE value`.
    Case(Expr),
    /// `$DEFAULT`.
    Default,
    /// `$ENDSWITCH`.
    EndSwitch,
    /// `$BREAK`: leaves the innermost loop or `$SWITCH`.
    Break,
    /// `$CONTINUE`: the innermost loop's next round.
    Continue,
    /// `$GOTO N100`: continues at the block numbered 100 of the same program level.
    Goto(u32),
}

impl Control {
    /// The statement's keyword, without `$`.
    pub fn keyword(&self) -> &'static str {
        match self {
            Control::While(_) => "WHILE",
            Control::EndWhile => "ENDWHILE",
            Control::If(_) => "IF",
            Control::ElseIf(_) => "ELSEIF",
            Control::Else => "ELSE",
            Control::EndIf => "ENDIF",
            Control::For { .. } => "FOR",
            Control::EndFor => "ENDFOR",
            Control::Do => "DO",
            Control::EndDo(_) => "ENDDO",
            Control::Switch(_) => "SWITCH",
            Control::Case(_) => "CASE",
            Control::Default => "DEFAULT",
            Control::EndSwitch => "ENDSWITCH",
            Control::Break => "BREAK",
            Control::Continue => "CONTINUE",
            Control::Goto(_) => "GOTO",
        }
    }
}

/// A local subroutine `%L name` ... `M17` of a program file: a range of its blocks.
#[derive(Debug, Clone, PartialEq)]
pub struct LocalSub {
    /// The name, upper case.
    pub name: String,
    /// Its blocks: this range of [`Program::blocks`].
    pub blocks: core::ops::Range<u32>,
    /// Where `%L name` stands.
    pub span: Span,
}

/// One block (a logical line, continuation lines joined). Its items live in the program's
/// item arena ([`Program::items_of`]): one allocation for the whole program instead of one
/// per block, which was a fifth of the parse time.
#[derive(Debug, Clone)]
pub struct Block {
    /// Block number `N..`.
    pub number: Option<u32>,
    /// The block's items: this range of [`Program::items`], in source order.
    pub items: core::ops::Range<u32>,
    /// Where the block stands.
    pub span: Span,
    /// The line the block starts on, 1-based.
    pub line: u32,
}

impl PartialEq for Block {
    /// Like spans, the line is a location, not content: it takes no part in equality.
    fn eq(&self, other: &Self) -> bool {
        self.number == other.number && self.items == other.items
    }
}

/// A parsed program.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Program {
    /// `%name`.
    pub name: Option<String>,
    /// The local subroutines (`%L name`), which stand before the main program.
    pub subs: Vec<LocalSub>,
    /// The main program's first block (after the local subroutines).
    pub main_start: u32,
    /// Blocks that hold anything (empty and comment-only lines are not kept).
    pub blocks: Vec<Block>,
    /// The items of all blocks, block after block.
    pub items: Vec<Item>,
}

impl Program {
    /// The items of `block` (a block of this program).
    pub fn items_of(&self, block: &Block) -> &[Item] {
        self.items
            .get(block.items.start as usize..block.items.end as usize)
            .unwrap_or(&[])
    }

    /// Appends a block with `items`.
    pub fn push_block(&mut self, number: Option<u32>, items: Vec<Item>, span: Span, line: u32) {
        let start = arena_index(self.items.len());
        self.items.extend(items);
        let end = arena_index(self.items.len());
        self.blocks.push(Block {
            number,
            items: start..end,
            span,
            line,
        });
    }
}

/// An index into the item arena. Programs hold far fewer than 4 billion items (each takes a
/// source byte at least, and sources are read into memory), so this saturates only in theory.
pub(crate) fn arena_index(len: usize) -> u32 {
    u32::try_from(len).unwrap_or(u32::MAX)
}

// The tree's size is what parsing a long program mostly pays for (memory to fault in and
// fill): keep the common nodes small.
const _: () = assert!(core::mem::size_of::<Span>() == 8);
const _: () = assert!(core::mem::size_of::<Expr>() == 16);
const _: () = assert!(core::mem::size_of::<Item>() == 32);
const _: () = assert!(core::mem::size_of::<Block>() == 28);
