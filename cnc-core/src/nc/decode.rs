//! The decoder: program tree to the typed block stream a channel executes, with the semantic
//! checks the grammar cannot make.
//!
//! Coordinates follow this controller, not RS274:
//! * G90/G91 select absolute/incremental axis values (modal, G90 at start);
//! * `G92 X..` sets an additive reference-point offset for the axis (the value is the offset; set
//!   under G90, added under G91; `G92 X0` removes it). It moves nothing and takes effect with
//!   the axis's next absolute position: target = value + G92 offset + PSET offset;
//! * `#PSET X..` declares the current position to be X.. (an offset that makes it so);
//!   `#PRESET` (all axes) or `#PRESET X ..` removes it;
//! * G0/G1 are modal (G0 at start), F is modal (0 at start; G1 needs a positive feed).
//!
//! Variables (`V.G.TRACK_CS.X`...) are read from a [`Vars`] source when the block is decoded;
//! the channel decodes a block after the values it depends on are known.

use super::ast::*;
use super::control::{match_control, Jump};
use super::Diagnostic;
use std::sync::Arc;

/// Values of NC variables at decode time.
pub trait Vars {
    /// The value of `name` (upper case, e.g. `V.G.TRACK_CS.X`); `None` if there is no such
    /// variable.
    fn get(&self, name: &str) -> Option<f64>;
}

/// The channel variables known to the decoder, all 0: what `cnc check` uses.
#[derive(Debug, Clone, Copy, Default)]
pub struct ZeroVars;

/// The variables the language defines.
pub const KNOWN_VARIABLES: &[&str] = &[
    "V.G.TRACK_CS.X",
    "V.G.TRACK_CS.Y",
    "V.G.TRACK_CS.Z",
    "V.G.TRACK_CS.A",
    "V.G.TRACK_CS.B",
    "V.G.TRACK_CS.C",
];

impl Vars for ZeroVars {
    fn get(&self, name: &str) -> Option<f64> {
        KNOWN_VARIABLES.contains(&name).then_some(0.0)
    }
}

/// G0 or G1.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MotionMode {
    /// G0: rapid.
    Rapid,
    /// G1: linear at the programmed feed.
    Linear,
}

impl MotionMode {
    /// "G0" / "G1".
    pub fn name(self) -> &'static str {
        match self {
            MotionMode::Rapid => "G0",
            MotionMode::Linear => "G1",
        }
    }
}

/// Most axes one channel can have.
pub const MAX_CHANNEL_AXES: usize = 16;

/// One value per channel axis, in channel order, stored inline: a decoded block needs no heap
/// allocation, and the channel's tick can copy targets freely.
#[derive(Clone, Copy, PartialEq)]
pub struct AxisValues {
    len: u8,
    /// Slots beyond `len` stay 0, so the derived equality compares only the used ones.
    values: [f64; MAX_CHANNEL_AXES],
}

impl AxisValues {
    /// `n` zeros; `n` is cut to [`MAX_CHANNEL_AXES`] ([`check_channel_axes`] refuses more).
    pub fn zeros(n: usize) -> Self {
        Self {
            len: n.min(MAX_CHANNEL_AXES) as u8,
            values: [0.0; MAX_CHANNEL_AXES],
        }
    }

    /// The values of `slice` (cut to [`MAX_CHANNEL_AXES`]).
    pub fn from_slice(slice: &[f64]) -> Self {
        let mut v = Self::zeros(slice.len());
        let n = v.len();
        v.values[..n].copy_from_slice(&slice[..n]);
        v
    }
}

impl core::ops::Deref for AxisValues {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        &self.values[..self.len as usize]
    }
}

impl core::ops::DerefMut for AxisValues {
    fn deref_mut(&mut self) -> &mut [f64] {
        &mut self.values[..self.len as usize]
    }
}

impl core::fmt::Debug for AxisValues {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

/// Checks a channel's axis names: 1 to [`MAX_CHANNEL_AXES`] of them, each a letter followed by
/// letters or digits (`X`, `AB`, `X1`), none twice.
pub fn check_channel_axes(axes: &[String]) -> Result<(), String> {
    if axes.is_empty() || axes.len() > MAX_CHANNEL_AXES {
        return Err(format!(
            "a channel has 1 to {MAX_CHANNEL_AXES} axes, found {}",
            axes.len()
        ));
    }
    for (i, a) in axes.iter().enumerate() {
        let mut chars = a.chars();
        let well_formed = chars.next().is_some_and(|c| c.is_ascii_uppercase())
            && chars.all(|c| c.is_ascii_uppercase() || c.is_ascii_digit())
            && a.len() <= AxisName::CAPACITY;
        if !well_formed {
            return Err(format!(
                "axis name \"{a}\" must be upper-case letters then digits (e.g. X, AB, X1)"
            ));
        }
        if axes[..i].contains(a) {
            return Err(format!("axis name \"{a}\" is given twice"));
        }
    }
    Ok(())
}

/// A path motion with absolute targets for every axis of the channel.
#[derive(Debug, Clone, PartialEq)]
pub struct MotionBlock {
    /// Source line.
    pub line: u32,
    /// Block number.
    pub number: Option<u32>,
    /// G0 or G1.
    pub motion: MotionMode,
    /// Feed (mm/min).
    pub feed: f64,
    /// Target per channel axis, in channel order.
    pub target: AxisValues,
}

/// Where a tracking channel takes its dynamic coordinate system from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrackSource {
    /// `CH=n`: channel n's interface.
    Channel(u8),
    /// `ID=0`: the PLC; `ID=n`: master channel n.
    Id(u8),
}

/// `#TRACK CS ON|OFF [...]`, checked.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackCommand {
    /// ON or OFF.
    pub on: bool,
    /// Source (required for ON; optional for OFF).
    pub source: Option<TrackSource>,
    /// SET_ZERO / ABSOLUTE.
    pub set_zero: bool,
    /// OPTION (0 translation and rotation, 1 translation only).
    pub option: u32,
    /// KIN_BASE.
    pub kin_base: bool,
    /// FILTER in ticks (200 when not given).
    pub filter_ticks: u32,
    /// WAIT.
    pub wait: bool,
    /// ROT_TRANS.
    pub rot_trans: bool,
    /// RELATIVE.
    pub relative: bool,
    /// X Y Z A B C offset.
    pub offset: [f64; 6],
    /// SIMU.
    pub simu: bool,
    /// LOG_FILE: the file the diagnosis is written to (shared with the tree, so decoding the
    /// block in the tick does not allocate).
    pub log_file: Option<Arc<str>>,
}

/// The signal ids of one `#WAIT SYN`, inline (decoding allocates nothing).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SyncIds {
    ids: [u32; SyncIds::CAPACITY],
    len: u8,
}

impl SyncIds {
    /// Most ids one `#WAIT SYN` names.
    pub const CAPACITY: usize = 8;

    /// Adds `id`; false when full.
    pub fn push(&mut self, id: u32) -> bool {
        let Some(slot) = self.ids.get_mut(usize::from(self.len)) else {
            return false;
        };
        *slot = id;
        self.len += 1;
        true
    }

    /// The ids in the order given.
    pub fn as_slice(&self) -> &[u32] {
        &self.ids[..usize::from(self.len)]
    }
}

/// Default tracking filter, ticks.
pub const DEFAULT_FILTER_TICKS: u32 = 200;

/// One decoded block element.
#[derive(Debug, Clone, PartialEq)]
pub enum Decoded {
    /// Path motion.
    Motion(MotionBlock),
    /// An independent axis move `X1[INDP_ASYN POS=..]`.
    IndependentMove {
        /// Source line.
        line: u32,
        /// Channel axis index.
        axis: usize,
        /// Absolute target.
        target: f64,
        /// Feed.
        feed: f64,
        /// G0 or G1.
        motion: MotionMode,
        /// INDP_ASYN (true) or INDP_SYN.
        asynchronous: bool,
    },
    /// `#WAIT INDP ALL`.
    WaitIndependent {
        /// Source line.
        line: u32,
    },
    /// An M function.
    MFunction {
        /// Source line.
        line: u32,
        /// Code.
        code: u32,
    },
    /// `#TRACK CS ON|OFF`.
    Track {
        /// Source line.
        line: u32,
        /// The command.
        command: TrackCommand,
    },
    /// `#TRACK CS ABS`.
    TrackAbs {
        /// Source line.
        line: u32,
    },
    /// `#CHANNEL INTERFACE ON|OFF`.
    ChannelInterface {
        /// Source line.
        line: u32,
        /// ON or OFF.
        on: bool,
    },
    /// `#CS ON|OFF`.
    Cs {
        /// Source line.
        line: u32,
        /// ON or OFF.
        on: bool,
        /// Name, if given.
        name: Option<Name>,
        /// X Y Z A B C (missing values 0).
        frame: [f64; 6],
    },
    /// `#TRAFO` / `#KIN ID`.
    Trafo {
        /// Source line.
        line: u32,
        /// Transformation on (Some), off, or only the id selected (None).
        on: Option<bool>,
        /// Kinematic id.
        id: Option<u32>,
    },
    /// `#SIGNAL SYN`.
    SignalSyn {
        /// Source line.
        line: u32,
        /// Signal id.
        id: u32,
        /// How many channels it counts for.
        count: u32,
    },
    /// `#WAIT SYN`.
    WaitSyn {
        /// Source line.
        line: u32,
        /// Signal ids waited for.
        ids: SyncIds,
    },
    /// `#FLUSH WAIT|CONTINUE`.
    Flush {
        /// Source line.
        line: u32,
        /// WAIT.
        wait: bool,
    },
    /// A control statement (its jump is in the program's jump table).
    Control {
        /// Source line.
        line: u32,
        /// The statement.
        op: ControlOp,
    },
}

/// A control statement. Where it goes is not here: the program's jump table
/// ([`super::control::match_control`]) holds that, matched once per program.
#[derive(Debug, Clone, PartialEq)]
pub enum ControlOp {
    /// `$WHILE`: evaluate the condition.
    While {
        /// Condition.
        cond: Expr,
    },
    /// `$ENDWHILE`.
    EndWhile,
    /// `$IF`: evaluate the condition.
    If {
        /// Condition.
        cond: Expr,
    },
    /// `$ELSE`.
    Else,
    /// `$ENDIF`.
    EndIf,
}

/// The decoder's modal state.
#[derive(Debug, Clone)]
pub struct DecoderState {
    axes: Vec<String>,
    /// The same names for fast comparison with names from the tree.
    axis_names: Vec<AxisName>,
    position: AxisValues,
    g92: AxisValues,
    pset: AxisValues,
    absolute: bool,
    motion: MotionMode,
    feed: f64,
    /// Per block: the values of its axis words by axis (valid where [`DecoderState::block`]
    /// marks the axis as programmed).
    words: [f64; MAX_CHANNEL_AXES],
    /// Non-motion elements of the block being decoded (kept to reuse its capacity).
    tail: Vec<Decoded>,
}

struct Ctx<'a> {
    src: &'a str,
    vars: &'a dyn Vars,
    diags: Vec<Diagnostic>,
}

impl Ctx<'_> {
    fn error(&mut self, span: Span, message: impl Into<String>) {
        self.diags
            .push(Diagnostic::new(span, message.into(), self.src));
    }

    /// The value of `e`: a literal at once (nearly every word of a program), anything else
    /// through [`Ctx::eval_expr`].
    #[inline(always)]
    fn eval(&mut self, e: &Expr, span: Span) -> Option<f64> {
        match e {
            Expr::Num(v) => Some(*v),
            _ => self.eval_expr(e, span),
        }
    }

    fn eval_expr(&mut self, e: &Expr, span: Span) -> Option<f64> {
        match e {
            Expr::Num(v) => Some(*v),
            Expr::Var(name) => match self.vars.get(name) {
                Some(v) => Some(v),
                None => {
                    self.error(
                        span,
                        format!(
                            "unknown variable \"{name}\" (known: {})",
                            KNOWN_VARIABLES.join(", ")
                        ),
                    );
                    None
                }
            },
            Expr::Neg(inner) => self.eval(inner, span).map(|v| -v),
            Expr::Bin(bin) => {
                let (op, a, b) = &**bin;
                let (a, b) = (self.eval(a, span)?, self.eval(b, span)?);
                let bool_val = |c: bool| if c { 1.0 } else { 0.0 };
                Some(match op {
                    BinOp::Add => a + b,
                    BinOp::Sub => a - b,
                    BinOp::Mul => a * b,
                    BinOp::Div => {
                        if b == 0.0 {
                            self.error(span, "division by zero");
                            return None;
                        }
                        a / b
                    }
                    BinOp::Eq => bool_val(a == b),
                    BinOp::Ne => bool_val(a != b),
                    BinOp::Lt => bool_val(a < b),
                    BinOp::Le => bool_val(a <= b),
                    BinOp::Gt => bool_val(a > b),
                    BinOp::Ge => bool_val(a >= b),
                })
            }
        }
    }

    /// A whole number within `range`, else an error naming `what`.
    fn whole(&mut self, e: &Expr, span: Span, what: &str, min: f64, max: f64) -> Option<u32> {
        let v = self.eval(e, span)?;
        if v.fract() != 0.0 || v < min || v > max {
            self.error(
                span,
                format!("{what} must be a whole number in {min}..={max}, found {v}"),
            );
            return None;
        }
        Some(v as u32)
    }
}

/// The indices of the set bits of a mask, lowest first.
#[derive(Clone, Copy)]
struct BitIndices(u32);

impl Iterator for BitIndices {
    type Item = usize;
    fn next(&mut self) -> Option<usize> {
        if self.0 == 0 {
            return None;
        }
        let i = self.0.trailing_zeros();
        self.0 &= self.0 - 1;
        Some(i as usize)
    }
}

impl DecoderState {
    /// A channel with these axis names (upper case), at position 0, G0 G90, feed 0.
    pub fn new(axes: &[String]) -> Self {
        let n = axes.len();
        Self {
            axes: axes.to_vec(),
            axis_names: axes.iter().map(|a| AxisName::from(a.as_str())).collect(),
            position: AxisValues::zeros(n),
            g92: AxisValues::zeros(n),
            pset: AxisValues::zeros(n),
            absolute: true,
            motion: MotionMode::Rapid,
            feed: 0.0,
            words: [0.0; MAX_CHANNEL_AXES],
            tail: Vec::with_capacity(4),
        }
    }

    /// Decodes block `index` of `program` (parsed from `src`) with the variable values of
    /// `vars` now, appending its elements to `out`: how a channel consumes its program, one
    /// block when it reaches it. Returns the block's diagnostics (empty when it decoded
    /// cleanly; nothing is allocated then). Where a control statement goes is in the
    /// program's jump table ([`super::control::match_control`]).
    pub fn decode_block(
        &mut self,
        program: &Program,
        index: usize,
        src: &str,
        vars: &dyn Vars,
        out: &mut Vec<Decoded>,
    ) -> Vec<Diagnostic> {
        let mut ctx = Ctx {
            src,
            vars,
            diags: Vec::new(),
        };
        if let Some(block) = program.blocks.get(index) {
            self.block(block, program.items_of(block), &mut ctx, out);
        }
        super::locate(&mut ctx.diags, src);
        ctx.diags
    }

    /// The programmed position per axis (after offsets), as the next incremental block sees it.
    pub fn position(&self) -> &AxisValues {
        &self.position
    }

    /// Sets the programmed position of `axis` (the channel re-expresses its position when a
    /// transformation or coordinate system is switched).
    pub fn set_position(&mut self, axis: usize, value: f64) {
        if let Some(p) = self.position.get_mut(axis) {
            *p = value;
        }
    }

    /// Sets the additive G92 offset of `axis` (`#TRACK CS ABS` uses it like `G92 X=...`).
    pub fn set_g92(&mut self, axis: usize, value: f64) {
        if let Some(p) = self.g92.get_mut(axis) {
            *p = value;
        }
    }

    /// The channel's axis names.
    pub fn axes(&self) -> &[String] {
        &self.axes
    }

    fn unknown_axis(&self, ctx: &mut Ctx<'_>, span: Span, name: &str) {
        ctx.error(
            span,
            format!(
                "unknown axis \"{name}\" for this channel (axes: {})",
                self.axes.join(" ")
            ),
        );
    }

    fn axis_index(&self, name: &str) -> Option<usize> {
        self.axes.iter().position(|a| a == name)
    }

    /// Axis lookup for names straight from the tree (byte comparison, no UTF-8 check).
    fn axis_of(&self, name: &AxisName) -> Option<usize> {
        let packed = name.packed();
        self.axis_names.iter().position(|a| a.packed() == packed)
    }

    /// Decodes one block; `out` receives its elements (a control statement as its kind and
    /// condition; the jump table says where it goes).
    fn block(&mut self, block: &Block, items: &[Item], ctx: &mut Ctx<'_>, out: &mut Vec<Decoded>) {
        let line = block.line;
        let mut g92 = false;
        let mut motion_code: Option<(u32, Span)> = None;
        // One bit per axis with a word in this block (axis indices are below 16).
        let mut programmed: u32 = 0;
        // Elements that follow the block's motion, in a buffer kept across blocks.
        let mut tail = core::mem::take(&mut self.tail);
        tail.clear();
        for item in items {
            match item {
                Item::G { code, span } => match code {
                    0 | 1 => {
                        if let Some((other, _)) = motion_code.filter(|(c, _)| c != code) {
                            ctx.error(
                                *span,
                                format!("G{code} and G{other} in one block: choose one motion"),
                            );
                        }
                        motion_code = Some((*code, *span));
                    }
                    90 => self.absolute = true,
                    91 => self.absolute = false,
                    92 => g92 = true,
                    other => ctx.error(
                        *span,
                        format!("unknown G code G{other} (known: G0, G1, G90, G91, G92)"),
                    ),
                },
                Item::Feed { value, span } => {
                    if let Some(f) = ctx.eval(value, *span) {
                        if f > 0.0 && f.is_finite() {
                            self.feed = f;
                        } else {
                            ctx.error(*span, format!("feed must be positive, found {f}"));
                        }
                    }
                }
                Item::M { code, .. } => tail.push(Decoded::MFunction { line, code: *code }),
                Item::Axis(word) => {
                    let Some(i) = self.axis_of(&word.name) else {
                        self.unknown_axis(ctx, word.span, word.name.as_str());
                        continue;
                    };
                    if programmed & (1 << i) != 0 {
                        ctx.error(
                            word.span,
                            format!("axis {} programmed twice in one block", word.name),
                        );
                        continue;
                    }
                    if let Some(v) = ctx.eval(&word.value, word.span) {
                        self.words[i] = v;
                        programmed |= 1 << i;
                    }
                }
                Item::IndependentAxis { axis, span } => {
                    let (name, options) = (axis.name.as_str(), &axis.options);
                    if let Some(d) = self.independent(line, name, options, *span, ctx) {
                        tail.push(d);
                    }
                }
                Item::Command { command, span } => {
                    if let Some(d) = self.command(line, command, *span, ctx) {
                        tail.push(d);
                    }
                }
                Item::Control { control, span: _ } => {
                    let op = match control.as_ref() {
                        Control::While(c) => ControlOp::While { cond: c.clone() },
                        Control::EndWhile => ControlOp::EndWhile,
                        Control::If(c) => ControlOp::If { cond: c.clone() },
                        Control::Else => ControlOp::Else,
                        Control::EndIf => ControlOp::EndIf,
                    };
                    if items.len() > 1 {
                        ctx.error(block.span, "a $ statement stands alone in its block");
                    }
                    tail.push(Decoded::Control { line, op });
                }
            }
        }
        if let Some((code, _)) = motion_code {
            self.motion = if code == 0 {
                MotionMode::Rapid
            } else {
                MotionMode::Linear
            };
        }
        let axes = BitIndices(programmed);
        if g92 {
            for i in axes {
                let v = self.words[i];
                self.g92[i] = if self.absolute { v } else { self.g92[i] + v };
            }
        } else if programmed != 0 {
            if self.motion == MotionMode::Linear && self.feed <= 0.0 {
                ctx.error(block.span, "G1 motion without a feed: program F.. first");
            }
            for i in axes {
                let v = self.words[i];
                self.position[i] = if self.absolute {
                    v + self.g92[i] + self.pset[i]
                } else {
                    self.position[i] + v
                };
            }
            out.push(Decoded::Motion(MotionBlock {
                line,
                number: block.number,
                motion: self.motion,
                feed: self.feed,
                target: self.position,
            }));
        }
        if !tail.is_empty() {
            out.append(&mut tail);
        }
        self.tail = tail;
    }

    fn independent(
        &mut self,
        line: u32,
        name: &str,
        options: &[Entry],
        span: Span,
        ctx: &mut Ctx<'_>,
    ) -> Option<Decoded> {
        let Some(axis) = self.axis_index(name) else {
            self.unknown_axis(ctx, span, name);
            return None;
        };
        let (mut asynchronous, mut pos, mut feed, mut motion, mut absolute) =
            (None, None, self.feed, MotionMode::Linear, true);
        for e in options {
            match (e.key.as_deref(), e.glued, &e.value) {
                (Some("INDP_ASYN"), None, None) => asynchronous = Some(true),
                (Some("INDP_SYN"), None, None) => asynchronous = Some(false),
                (Some("POS"), None, Some(v)) => pos = ctx.eval(v, e.span),
                (Some("F"), Some(f), None) => feed = f,
                (Some("F"), None, Some(v)) => feed = ctx.eval(v, e.span)?,
                (Some("G"), Some(0.0), None) => motion = MotionMode::Rapid,
                (Some("G"), Some(1.0), None) => motion = MotionMode::Linear,
                (Some("G"), Some(90.0), None) => absolute = true,
                (Some("G"), Some(91.0), None) => absolute = false,
                _ => ctx.error(e.span, "independent axis: expected INDP_ASYN, INDP_SYN, POS=.., G0, G1, G90, G91 or F.."),
            }
        }
        let Some(asynchronous) = asynchronous else {
            ctx.error(span, "independent axis: expected INDP_ASYN or INDP_SYN");
            return None;
        };
        let Some(pos) = pos else {
            ctx.error(span, "independent axis: expected POS=..");
            return None;
        };
        if motion == MotionMode::Linear && feed <= 0.0 {
            ctx.error(span, "independent axis: G1 needs a positive feed F..");
            return None;
        }
        let target = if absolute {
            pos + self.g92[axis] + self.pset[axis]
        } else {
            self.position[axis] + pos
        };
        self.position[axis] = target;
        Some(Decoded::IndependentMove {
            line,
            axis,
            target,
            feed,
            motion,
            asynchronous,
        })
    }

    fn command(
        &mut self,
        line: u32,
        command: &Command,
        span: Span,
        ctx: &mut Ctx<'_>,
    ) -> Option<Decoded> {
        match command {
            Command::TrackCs { on, options } => {
                track(*on, options, span, ctx).map(|command| Decoded::Track { line, command })
            }
            Command::TrackCsAbs => Some(Decoded::TrackAbs { line }),
            Command::ChannelInterface { on, .. } => {
                Some(Decoded::ChannelInterface { line, on: *on })
            }
            Command::Cs { on, name, values } => {
                if values.len() > 6 {
                    ctx.error(
                        span,
                        format!(
                            "#CS takes at most 6 values (X Y Z A B C), found {}",
                            values.len()
                        ),
                    );
                    return None;
                }
                if !on && !values.is_empty() {
                    ctx.error(span, "#CS OFF takes no values");
                    return None;
                }
                let mut frame = [0.0; 6];
                for (i, v) in values.iter().enumerate() {
                    frame[i] = ctx.eval(v, span)?;
                }
                Some(Decoded::Cs {
                    line,
                    on: *on,
                    name: *name,
                    frame,
                })
            }
            Command::Trafo { on, id } => {
                let id = match id {
                    Some(e) => Some(ctx.whole(e, span, "kinematic id", 0.0, 65535.0)?),
                    None => None,
                };
                // `#TRAFO [45]` switches on with that id (as the seed's programs use it).
                let on = on.or(id.map(|_| true));
                Some(Decoded::Trafo { line, on, id })
            }
            Command::KinId { id } => {
                let id = ctx.whole(id, span, "kinematic id", 0.0, 65535.0)?;
                Some(Decoded::Trafo {
                    line,
                    on: None,
                    id: Some(id),
                })
            }
            Command::SignalSyn { options } => {
                let mut id = None;
                let mut count = None;
                for e in options {
                    let v = entry_number(e, ctx)?;
                    let whole = ctx.whole(
                        &Expr::Num(v),
                        e.span,
                        e.key.as_deref().unwrap_or("value"),
                        1.0,
                        65535.0,
                    )?;
                    match e.key.as_deref() {
                        Some("ID") => id = Some(whole),
                        _ => count = Some(whole),
                    }
                }
                match (id, count) {
                    (Some(id), Some(count)) => Some(Decoded::SignalSyn { line, id, count }),
                    _ => {
                        ctx.error(span, "#SIGNAL SYN needs ID.. and COUNT..");
                        None
                    }
                }
            }
            Command::WaitSyn { options } => {
                let mut ids = SyncIds::default();
                for e in options {
                    let v = entry_number(e, ctx)?;
                    let id = ctx.whole(&Expr::Num(v), e.span, "ID", 1.0, 65535.0)?;
                    if !ids.push(id) {
                        ctx.error(
                            e.span,
                            format!("#WAIT SYN waits for at most {} ids", SyncIds::CAPACITY),
                        );
                        return None;
                    }
                }
                if ids.as_slice().is_empty() {
                    ctx.error(span, "#WAIT SYN needs at least one ID..");
                    return None;
                }
                Some(Decoded::WaitSyn { line, ids })
            }
            Command::WaitIndpAll => Some(Decoded::WaitIndependent { line }),
            Command::Flush { wait } => Some(Decoded::Flush { line, wait: *wait }),
            Command::Pset { axes } => {
                for word in axes {
                    let Some(i) = self.axis_of(&word.name) else {
                        self.unknown_axis(ctx, word.span, word.name.as_str());
                        continue;
                    };
                    if let Some(v) = ctx.eval(&word.value, word.span) {
                        self.pset[i] = self.position[i] - v - self.g92[i];
                    }
                }
                None
            }
            Command::Preset { axes } => {
                if axes.is_empty() {
                    self.pset.iter_mut().for_each(|p| *p = 0.0);
                }
                for name in axes {
                    match self.axis_index(name.as_str()) {
                        Some(i) => self.pset[i] = 0.0,
                        None => self.unknown_axis(ctx, span, name.as_str()),
                    }
                }
                None
            }
        }
    }
}

fn entry_number(e: &Entry, ctx: &mut Ctx<'_>) -> Option<f64> {
    match (e.glued, &e.value) {
        (Some(v), None) => Some(v),
        (None, Some(v)) => ctx.eval(v, e.span),
        _ => {
            ctx.error(e.span, "expected a value");
            None
        }
    }
}

fn whole_entry(e: &Entry, ctx: &mut Ctx<'_>, what: &str, min: f64, max: f64) -> Option<u32> {
    let v = entry_number(e, ctx)?;
    ctx.whole(&Expr::Num(v), e.span, what, min, max)
}

const OFF_OPTIONS: &[&str] = &["WAIT", "FILTER", "ID", "CH"];

/// Every `#TRACK CS` option, one bit each for the "given twice" check (SET_ZERO and ABSOLUTE
/// have a bit each, so that giving both is reported as such; unknown keys have none).
const TRACK_OPTIONS: &[&str] = &[
    "CH",
    "ID",
    "SET_ZERO",
    "ABSOLUTE",
    "OPTION",
    "KIN_BASE",
    "FILTER",
    "WAIT",
    "ROT_TRANS",
    "RELATIVE",
    "X",
    "Y",
    "Z",
    "A",
    "B",
    "C",
    "SIMU",
    "LOG_FILE",
];

fn option_bit(key: &str) -> u32 {
    TRACK_OPTIONS
        .iter()
        .position(|o| *o == key)
        .map_or(0, |i| 1 << i)
}

fn track(on: bool, options: &[Entry], span: Span, ctx: &mut Ctx<'_>) -> Option<TrackCommand> {
    let mut t = TrackCommand {
        on,
        source: None,
        set_zero: false,
        option: 0,
        kin_base: false,
        filter_ticks: DEFAULT_FILTER_TICKS,
        wait: false,
        rot_trans: false,
        relative: false,
        offset: [0.0; 6],
        simu: false,
        log_file: None,
    };
    // Options seen so far, one bit per entry of TRACK_OPTIONS (no allocation in the tick).
    let mut seen = 0u32;
    let mut ok = true;
    for e in options {
        let key = e.key.as_deref().unwrap_or("");
        let bit = option_bit(key);
        if seen & bit != 0 {
            ctx.error(e.span, format!("#TRACK CS: option {key} given twice"));
            ok = false;
            continue;
        }
        seen |= bit;
        if !on && !OFF_OPTIONS.contains(&key) {
            ctx.error(e.span, format!("#TRACK CS OFF: option {key} is only allowed with ON (OFF takes WAIT, FILTER, ID, CH)"));
            ok = false;
            continue;
        }
        let value = |ctx: &mut Ctx<'_>| entry_number(e, ctx);
        match key {
            "CH" => {
                t.source =
                    whole_entry(e, ctx, "CH", 1.0, 12.0).map(|v| TrackSource::Channel(v as u8))
            }
            "ID" => {
                t.source = whole_entry(e, ctx, "ID", 0.0, 12.0).map(|v| TrackSource::Id(v as u8))
            }
            "OPTION" => t.option = whole_entry(e, ctx, "OPTION", 0.0, 1.0)?,
            "FILTER" => t.filter_ticks = whole_entry(e, ctx, "FILTER", 0.0, f64::from(u32::MAX))?,
            "SET_ZERO" | "ABSOLUTE" => t.set_zero = true,
            "KIN_BASE" => t.kin_base = true,
            "WAIT" => t.wait = true,
            "ROT_TRANS" => t.rot_trans = true,
            "RELATIVE" => t.relative = true,
            "SIMU" => t.simu = true,
            "LOG_FILE" => match &e.text {
                Some(name) if !name.trim().is_empty() => t.log_file = Some(Arc::clone(name)),
                _ => {
                    ctx.error(e.span, "#TRACK CS: LOG_FILE needs a file name in quotes, e.g. LOG_FILE=\"dyncs.log\"");
                    ok = false;
                }
            },
            "X" | "Y" | "Z" | "A" | "B" | "C" => {
                let i = ["X", "Y", "Z", "A", "B", "C"]
                    .iter()
                    .position(|k| *k == key)
                    .unwrap_or(0);
                t.offset[i] = value(ctx)?;
            }
            // The parser has reported unknown options already.
            _ => ok = false,
        }
    }
    let given = |key: &str| seen & option_bit(key) != 0;
    if given("CH") && given("ID") {
        ctx.error(
            span,
            "#TRACK CS: give the source as CH=.. or ID=.., not both",
        );
        ok = false;
    }
    if on && !given("CH") && !given("ID") {
        ctx.error(span, "#TRACK CS ON: expected a source, CH=.. or ID=..");
        ok = false;
    }
    if t.kin_base && t.rot_trans {
        ctx.error(span, "#TRACK CS: ROT_TRANS applies to the master-slave offset and cannot be combined with KIN_BASE");
        ok = false;
    }
    if given("SET_ZERO") && given("ABSOLUTE") {
        ctx.error(
            span,
            "#TRACK CS: SET_ZERO and ABSOLUTE are the same option; give one",
        );
        ok = false;
    }
    (ok && (t.source.is_some() || !on)).then_some(t)
}

/// Evaluates `expr` with the variables of `vars` (a `$WHILE`/`$IF` condition at run time);
/// `None` for an unknown variable or a division by zero.
pub fn evaluate(expr: &Expr, vars: &dyn Vars) -> Option<f64> {
    let mut ctx = Ctx {
        src: "",
        vars,
        diags: Vec::new(),
    };
    ctx.eval(expr, Span::default())
}

/// Decodes a whole program for a channel with `axes`, reading variables from `vars`: the block
/// stream `cnc check --blocks` prints. The stream is only meaningful when the diagnostics are
/// empty: a program with errors must not be executed.
pub fn decode_program(
    program: &Program,
    src: &str,
    axes: &[String],
    vars: &dyn Vars,
) -> (Vec<Decoded>, Vec<Diagnostic>) {
    let mut out = Vec::with_capacity(program.blocks.len());
    let (_, diagnostics) = walk(program, src, axes, vars, Some(&mut out));
    (out, diagnostics)
}

/// Checks a whole program for a channel with `axes` as it is loaded: every block's semantics
/// (with `vars`), and its control flow, matched once into the jump table the channel follows.
/// Nothing decoded is kept: the channel decodes each block when it reaches it, with the
/// variables and positions of that moment. The table is only complete when the diagnostics
/// are empty.
pub fn check_program(
    program: &Program,
    src: &str,
    axes: &[String],
    vars: &dyn Vars,
) -> (Vec<Option<Jump>>, Vec<Diagnostic>) {
    walk(program, src, axes, vars, None)
}

/// One pass over `program`: each block decoded (into `keep`, or into one scratch buffer reused
/// block by block), then the control statements matched.
fn walk(
    program: &Program,
    src: &str,
    axes: &[String],
    vars: &dyn Vars,
    keep: Option<&mut Vec<Decoded>>,
) -> (Vec<Option<Jump>>, Vec<Diagnostic>) {
    let mut ctx = Ctx {
        src,
        vars,
        diags: Vec::new(),
    };
    if let Err(message) = check_channel_axes(axes) {
        ctx.error(Span::default(), message);
        super::locate(&mut ctx.diags, src);
        return (vec![None; program.blocks.len()], ctx.diags);
    }
    let mut state = DecoderState::new(axes);
    let mut scratch = Vec::new();
    let keeping = keep.is_some();
    let out = keep.unwrap_or(&mut scratch);
    for block in &program.blocks {
        state.block(block, program.items_of(block), &mut ctx, out);
        if !keeping {
            out.clear();
        }
    }
    let (jumps, unmatched) = match_control(program);
    for u in unmatched {
        ctx.error(u.span, u.message);
    }
    super::locate(&mut ctx.diags, src);
    (jumps, ctx.diags)
}
