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
use super::Diagnostic;
use std::sync::Arc;

/// Values of NC variables at decode time.
pub trait Vars {
    /// The value of `name` (upper case, e.g. `V.G.TRACK_CS.X`, `V.P.DEPTH`); `None` if there
    /// is no such variable.
    fn get(&self, name: &str) -> Option<f64>;

    /// The value of P parameter `n`; `None` while it has not been assigned.
    fn param(&self, n: u32) -> Option<f64> {
        let _ = n;
        None
    }

    /// Whether the program's own variables (P, `V.P.`, `V.L.`) are unknown here: a block
    /// checked on its own, outside a run, has no values for them, and that is no error.
    fn program_values_unknown(&self) -> bool {
        false
    }

    /// Whether the `V.G.` values are those of a running machine (a check has placeholders:
    /// where a condition on them leads is not known then).
    fn machine_values_known(&self) -> bool {
        true
    }
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
    fn machine_values_known(&self) -> bool {
        false
    }
}

/// G0, G1, G2 or G3.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MotionMode {
    /// G0: rapid.
    Rapid,
    /// G1: linear at the programmed feed.
    Linear,
    /// G2: clockwise arc at the programmed feed.
    ArcCw,
    /// G3: counter-clockwise arc at the programmed feed.
    ArcCcw,
}

impl MotionMode {
    /// "G0" / "G1" / "G2" / "G3".
    pub fn name(self) -> &'static str {
        match self {
            MotionMode::Rapid => "G0",
            MotionMode::Linear => "G1",
            MotionMode::ArcCw => "G2",
            MotionMode::ArcCcw => "G3",
        }
    }

    /// Whether the motion runs at the programmed feed (not G0).
    pub fn at_feed(self) -> bool {
        self != MotionMode::Rapid
    }
}

/// Millimetres per inch (G70).
pub const MM_PER_INCH: f64 = 25.4;

/// Default tolerance for an arc's end point against its circle (mm).
pub const DEFAULT_ARC_TOLERANCE: f64 = 0.001;

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

/// One-letter words that are never axes: G, M, F, N and the circle, spindle, tool, parameter
/// and call addresses.
pub const RESERVED_ADDRESSES: &[&str] = &[
    "D", "F", "G", "I", "J", "K", "L", "M", "N", "P", "R", "S", "T",
];

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
        if RESERVED_ADDRESSES.contains(&a.as_str()) {
            return Err(format!(
                "axis name \"{a}\" is an address of the language ({})",
                RESERVED_ADDRESSES.join(" ")
            ));
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
    /// G0, G1, G2 or G3.
    pub motion: MotionMode,
    /// Feed (mm/min).
    pub feed: f64,
    /// Target per channel axis, in channel order.
    pub target: AxisValues,
    /// For G2/G3: the circle (the block starts where the one before ended).
    pub arc: Option<super::arc::ArcMove>,
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
    /// FILTER in ticks; `None` when not given (ON then takes [`DEFAULT_FILTER_TICKS`], OFF
    /// the filter it switched on with).
    pub filter_ticks: Option<u32>,
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
    /// `G04` / `#TIME`: wait, nothing moves.
    Dwell {
        /// Source line.
        line: u32,
        /// Seconds.
        seconds: f64,
    },
    /// `#MSG ["text"]`.
    Message {
        /// Source line.
        line: u32,
        /// The text.
        text: Arc<str>,
    },
    /// `S..`: the spindle speed (1/min) M03/M04 turn the spindle at.
    Spindle {
        /// Source line.
        line: u32,
        /// Speed.
        speed: f64,
    },
    /// `T..`: the tool the PLC is to prepare.
    Tool {
        /// Source line.
        line: u32,
        /// Tool number.
        number: u32,
    },
    /// `D..`: the tool data record selected (0: none). Under a transformation the channel
    /// puts it on the flange; without one the decoder offsets the plane's normal by its
    /// length.
    ToolRecord {
        /// Source line.
        line: u32,
        /// D number.
        d: u32,
    },
}

/// The machine data a decoder needs: zero offsets, tool table, arc tolerance.
#[derive(Debug, Clone, PartialEq)]
pub struct DecoderSetup {
    /// G54..G59, per channel axis.
    pub zero_offsets: [Vec<f64>; 6],
    /// Tool length per D number.
    pub tools: Vec<(u32, f64)>,
    /// No tool table is at hand (`cnc check` without `--tool`): every D selects length 0
    /// instead of being refused as unknown.
    pub tools_unknown: bool,
    /// How far an arc's end point may lie off its circle (mm).
    pub arc_tolerance: f64,
}

impl Default for DecoderSetup {
    fn default() -> Self {
        Self {
            zero_offsets: Default::default(),
            tools: Vec::new(),
            tools_unknown: false,
            arc_tolerance: DEFAULT_ARC_TOLERANCE,
        }
    }
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
    /// G17/G18/G19.
    plane: super::arc::Plane,
    /// G70 (inch) rather than G71.
    inch: bool,
    /// G161: I, J, K are absolute (else, G162, relative to the start point).
    center_absolute: bool,
    /// The selected zero offset: 0 for G53 (none), 1..=6 for G54..G59.
    zero: usize,
    /// The offsets of G54..G59 per axis (machine configuration).
    zero_offsets: [AxisValues; 6],
    /// Tool length per D number (machine configuration).
    tools: Vec<(u32, f64)>,
    /// See [`DecoderSetup::tools_unknown`].
    tools_unknown: bool,
    /// The length of the selected D (0 for D0).
    tool_length: f64,
    /// A transformation is on (`#TRAFO`): the tool length is the channel's, not an offset.
    trafo: bool,
    /// The end point's tolerance against an arc's circle (mm).
    arc_tolerance: f64,
    /// Whether the position is where the program put it (false for a block checked on its own:
    /// an arc's start is not known then).
    start_known: bool,
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
        let value = match e {
            Expr::Num(v) => Some(*v),
            Expr::Var(name) => self.variable(name, span),
            Expr::Param(n) => match self.vars.param(*n) {
                Some(v) => Some(v),
                None if self.vars.program_values_unknown() => None,
                None => {
                    self.error(span, format!("P{n} is read before it is assigned"));
                    None
                }
            },
            Expr::Neg(inner) => self.eval(inner, span).map(|v| -v),
            Expr::Call(call) => {
                let (func, args) = &**call;
                let a = self.eval(args.first()?, span)?;
                let b = match args.get(1) {
                    Some(b) => Some(self.eval(b, span)?),
                    None => None,
                };
                match super::eval::function(*func, a, b) {
                    Ok(v) => Some(v),
                    Err(message) => {
                        self.error(span, message);
                        None
                    }
                }
            }
            Expr::Bin(bin) => {
                let (op, a, b) = &**bin;
                let (a, b) = (self.eval(a, span)?, self.eval(b, span)?);
                match super::eval::binary(*op, a, b) {
                    Ok(v) => Some(v),
                    Err(message) => {
                        self.error(span, message);
                        None
                    }
                }
            }
        }?;
        if !value.is_finite() {
            self.error(
                span,
                format!("the value is not a finite number ({value}): it overflowed"),
            );
            return None;
        }
        Some(value)
    }

    fn variable(&mut self, name: &Name, span: Span) -> Option<f64> {
        if let Some(v) = self.vars.get(name) {
            return Some(v);
        }
        let own = name.starts_with("V.P.") || name.starts_with("V.L.");
        if own && self.vars.program_values_unknown() {
            return None;
        }
        if own {
            self.error(
                span,
                format!("variable \"{name}\" is read before it is assigned"),
            );
        } else {
            self.error(
                span,
                format!(
                    "unknown variable \"{name}\" (known: V.P.* and V.L.* once assigned, {})",
                    KNOWN_VARIABLES.join(", ")
                ),
            );
        }
        None
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

/// What the items of the block being decoded ask for besides modal settings, gathered before
/// anything moves (the axis values themselves are in `DecoderState::words`).
#[derive(Default)]
struct BlockInput {
    /// G92: the axis words set offsets.
    g92: bool,
    /// G04.
    dwell_code: bool,
    /// G0..G3 and where it stands.
    motion_code: Option<(u32, Span)>,
    /// One bit per axis with a word in this block (axis indices are below 16).
    programmed: u32,
    /// I, J, K in this block (inch converted by [`DecoderState::inches_and_feed`]).
    center: [Option<f64>; 3],
    /// R in this block (converted like the centre).
    radius: Option<f64>,
    /// The bare dwell time (`G04 2.5`).
    dwell: Option<(f64, Span)>,
    /// F in this block.
    feed: Option<f64>,
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
            plane: super::arc::Plane::Xy,
            inch: false,
            center_absolute: false,
            zero: 0,
            zero_offsets: [AxisValues::zeros(n); 6],
            tools: Vec::new(),
            tools_unknown: false,
            tool_length: 0.0,
            trafo: false,
            arc_tolerance: DEFAULT_ARC_TOLERANCE,
            start_known: true,
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
        let mut diags = self.decode_block_unlocated(program, index, src, vars, out);
        super::locate(&mut diags, src);
        diags
    }

    /// [`DecoderState::decode_block`] with the diagnostics' lines and columns left to count
    /// ([`super::locate`]): a check counts them once for all.
    pub fn decode_block_unlocated(
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

    /// Takes the machine data of `setup`.
    pub fn configure(&mut self, setup: &DecoderSetup) {
        // G54..G59 per channel axis (values beyond the channel's axes are refused at load).
        for (slot, values) in self.zero_offsets.iter_mut().zip(&setup.zero_offsets) {
            for (i, v) in values.iter().enumerate().take(slot.len()) {
                slot[i] = *v;
            }
        }
        self.tools = setup.tools.clone();
        self.tools_unknown = setup.tools_unknown;
        self.arc_tolerance = setup.arc_tolerance;
    }

    /// For blocks checked out of their program's order: a feed is taken as programmed, and
    /// where the block starts is not known (the checks that depend on it are left out).
    pub fn checked_out_of_run(&mut self) {
        if self.feed <= 0.0 {
            self.feed = 1.0;
        }
        self.start_known = false;
    }

    /// Millimetres per programmed length unit (25.4 under G70).
    fn length_unit(&self) -> f64 {
        if self.inch {
            MM_PER_INCH
        } else {
            1.0
        }
    }

    /// The offset an absolute value of `axis` gets besides G92 and #PSET: the zero offset and,
    /// on the plane's normal, the tool length.
    fn offset(&self, axis: usize) -> f64 {
        let zero = match self.zero {
            0 => 0.0,
            z => self.zero_offsets[z - 1].get(axis).copied().unwrap_or(0.0),
        };
        let tool = if axis == self.plane.axes()[2] && !self.trafo {
            self.tool_length
        } else {
            0.0
        };
        zero + tool
    }

    fn unknown_axis(&self, ctx: &mut Ctx<'_>, span: Span, name: &str) {
        // `XP1`, `XV.P.A`: an axis with a value glued on, which this dialect writes X=P1.
        let glued_value = name.len() > 1
            && matches!(name.as_bytes()[name.len().min(2) - 1], b'P' | b'V')
            && self.axis_index(&name[..1]).is_some();
        let hint = if glued_value {
            format!(
                " (a value from a variable is written {}=..., e.g. {}=P1)",
                &name[..1],
                &name[..1]
            )
        } else {
            String::new()
        };
        ctx.error(
            span,
            format!(
                "unknown axis \"{name}\" for this channel (axes: {}){hint}",
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

    /// Decodes one block; `out` receives its elements. Assignments, calls and `$` statements
    /// are the interpreter's ([`super::interp`]): here they are only checked to stand where
    /// they may.
    fn block(&mut self, block: &Block, items: &[Item], ctx: &mut Ctx<'_>, out: &mut Vec<Decoded>) {
        // Elements that follow the block's motion, in a buffer kept across blocks.
        let mut tail = core::mem::take(&mut self.tail);
        tail.clear();
        let mut input = self.read_items(block, items, ctx, &mut tail);
        self.inches_and_feed(&mut input);
        if input.dwell_code || input.dwell.is_some() {
            self.dwell(block, &input, ctx, &mut tail);
            input.programmed = 0;
        }
        if let Some((code, _)) = input.motion_code {
            self.motion = match code {
                0 => MotionMode::Rapid,
                1 => MotionMode::Linear,
                2 => MotionMode::ArcCw,
                _ => MotionMode::ArcCcw,
            };
        }
        self.path_motion(block, &input, ctx, out);
        if !tail.is_empty() {
            out.append(&mut tail);
        }
        self.tail = tail;
    }

    /// Reads the items of `block` in order: modal G codes take effect at once, what moves is
    /// gathered into the returned [`BlockInput`] (axis values into `self.words`), and the
    /// elements that follow the motion go to `tail`.
    fn read_items(
        &mut self,
        block: &Block,
        items: &[Item],
        ctx: &mut Ctx<'_>,
        tail: &mut Vec<Decoded>,
    ) -> BlockInput {
        let line = block.line;
        let mut input = BlockInput::default();
        for item in items {
            match item {
                Item::G { code, span } => self.g_code(*code, *span, &mut input, ctx),
                Item::Feed { value, span } => {
                    if let Some(f) = ctx.eval(value, *span) {
                        if f > 0.0 && f.is_finite() {
                            input.feed = Some(f);
                        } else {
                            ctx.error(*span, format!("feed must be positive, found {f}"));
                        }
                    }
                }
                Item::M { code, .. } => tail.push(Decoded::MFunction { line, code: *code }),
                Item::Axis(word) if word.name.as_bytes().is_empty() => {
                    if let Some(v) = ctx.eval(&word.value, word.span) {
                        input.dwell = Some((v, word.span));
                    }
                }
                Item::Axis(word) if Addr::of_name(&word.name).is_some() => {
                    self.address_word(line, word, &mut input, ctx, tail)
                }
                Item::Axis(word) => self.axis_word(word, &mut input, ctx),
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
                Item::Assign { .. } => {}
                Item::Call { span, .. } => {
                    if items
                        .iter()
                        .any(|i| !matches!(i, Item::Call { .. } | Item::Assign { .. }))
                    {
                        ctx.error(
                            *span,
                            "a subroutine call stands in its block with P assignments only",
                        );
                    }
                }
                Item::Control { .. } => {
                    if items.len() > 1 {
                        ctx.error(block.span, "a $ statement stands alone in its block");
                    }
                }
            }
        }
        input
    }

    /// `G<code>` at `span`: a motion or a dwell of the block, G92, or a modal setting taken at
    /// once.
    fn g_code(&mut self, code: u32, span: Span, input: &mut BlockInput, ctx: &mut Ctx<'_>) {
        match code {
            0..=3 => {
                if let Some((other, _)) = input.motion_code.filter(|(c, _)| *c != code) {
                    ctx.error(
                        span,
                        format!("G{code} and G{other} in one block: choose one motion"),
                    );
                }
                input.motion_code = Some((code, span));
            }
            4 => input.dwell_code = true,
            // Blocks always end at exact stop here (no blending): G60 and G09 ask for
            // nothing more, G359/G360 switch what is always on.
            9 | 60 | 359 | 360 => {}
            17 => self.plane = super::arc::Plane::Xy,
            18 => self.plane = super::arc::Plane::Zx,
            19 => self.plane = super::arc::Plane::Yz,
            53..=59 => self.zero = (code - 53) as usize,
            70 => self.inch = true,
            71 => self.inch = false,
            90 => self.absolute = true,
            91 => self.absolute = false,
            92 => input.g92 = true,
            161 => self.center_absolute = true,
            162 => self.center_absolute = false,
            other => ctx.error(
                span,
                format!("unknown G code G{other} (known: G0-G4, G9, G17-G19, G53-G60, G70, G71, G90-G92, G161, G162, G359, G360)"),
            ),
        }
    }

    /// A word of an address that is no axis (see [`Addr`]): the circle's I, J, K, R for the
    /// block, S, T and D as elements in `tail`.
    fn address_word(
        &mut self,
        line: u32,
        word: &AxisWord,
        input: &mut BlockInput,
        ctx: &mut Ctx<'_>,
        tail: &mut Vec<Decoded>,
    ) {
        let addr = Addr::of_name(&word.name).unwrap_or(Addr::R);
        let Some(v) = ctx.eval(&word.value, word.span) else {
            return;
        };
        match addr {
            Addr::I => input.center[0] = Some(v),
            Addr::J => input.center[1] = Some(v),
            Addr::K => input.center[2] = Some(v),
            Addr::R => input.radius = Some(v),
            Addr::S if v >= 0.0 => tail.push(Decoded::Spindle { line, speed: v }),
            Addr::T | Addr::D if v.fract() == 0.0 && (0.0..=1e6).contains(&v) => {
                let n = v as u32;
                if addr == Addr::T {
                    tail.push(Decoded::Tool { line, number: n });
                } else {
                    self.tool_record(line, n, word.span, ctx, tail);
                }
            }
            Addr::S => ctx.error(
                word.span,
                format!("spindle speed S must not be negative, found {v}"),
            ),
            _ => ctx.error(
                word.span,
                format!(
                    "{} must be a whole number 0..=1000000, found {v}",
                    addr.letter()
                ),
            ),
        }
    }

    /// `D<n>` at `span`: selects tool data record `n` and its length (D0: none).
    fn tool_record(
        &mut self,
        line: u32,
        n: u32,
        span: Span,
        ctx: &mut Ctx<'_>,
        tail: &mut Vec<Decoded>,
    ) {
        if n == 0 {
            tail.push(Decoded::ToolRecord { line, d: 0 });
            self.tool_length = 0.0;
        } else if let Some(&(_, length)) = self.tools.iter().find(|(d, _)| *d == n) {
            self.tool_length = length;
            tail.push(Decoded::ToolRecord { line, d: n });
        } else if self.tools_unknown {
            self.tool_length = 0.0;
        } else {
            ctx.error(
                span,
                format!("D{n}: no such tool data record in the tool table (D0 removes the offset)"),
            );
        }
    }

    /// An axis word: its value into `self.words`, its axis marked programmed (once per
    /// block).
    fn axis_word(&mut self, word: &AxisWord, input: &mut BlockInput, ctx: &mut Ctx<'_>) {
        let Some(i) = self.axis_of(&word.name) else {
            self.unknown_axis(ctx, word.span, word.name.as_str());
            return;
        };
        if input.programmed & (1 << i) != 0 {
            ctx.error(
                word.span,
                format!("axis {} programmed twice in one block", word.name),
            );
            return;
        }
        if let Some(v) = ctx.eval(&word.value, word.span) {
            self.words[i] = v;
            input.programmed |= 1 << i;
        }
    }

    /// Takes the block's feed. G70 anywhere in the block applies to its values: lengths of
    /// the main axes, the circle and the feed are inches then.
    fn inches_and_feed(&mut self, input: &mut BlockInput) {
        if self.inch {
            for i in BitIndices(input.programmed & 0b111) {
                self.words[i] *= MM_PER_INCH;
            }
            for c in input
                .center
                .iter_mut()
                .chain(core::iter::once(&mut input.radius))
                .flatten()
            {
                *c *= MM_PER_INCH;
            }
        }
        if let Some(f) = input.feed {
            self.feed = if self.inch { f * MM_PER_INCH } else { f };
        }
    }

    /// What the block's axis words and circle do: set G92 offsets (with G92), or move, one
    /// motion element into `out`.
    fn path_motion(
        &mut self,
        block: &Block,
        input: &BlockInput,
        ctx: &mut Ctx<'_>,
        out: &mut Vec<Decoded>,
    ) {
        let (center, radius) = (input.center, input.radius);
        let arc_words = center.iter().any(Option::is_some) || radius.is_some();
        let is_arc = matches!(self.motion, MotionMode::ArcCw | MotionMode::ArcCcw);
        if arc_words && !is_arc {
            ctx.error(block.span, "I, J, K and R belong to G2/G3 blocks");
        }
        let axes = BitIndices(input.programmed);
        if input.g92 {
            for i in axes {
                let v = self.words[i];
                self.g92[i] = if self.absolute { v } else { self.g92[i] + v };
            }
        } else if input.programmed != 0 || (is_arc && arc_words) {
            if self.motion.at_feed() && self.feed <= 0.0 {
                ctx.error(
                    block.span,
                    format!(
                        "{} motion without a feed: program F.. first",
                        self.motion.name()
                    ),
                );
            }
            let start = self.position;
            for i in axes {
                let v = self.words[i];
                self.position[i] = if self.absolute {
                    v + self.g92[i] + self.pset[i] + self.offset(i)
                } else {
                    self.position[i] + v
                };
            }
            let arc = if is_arc {
                self.arc(&start, center, radius, block.span, ctx)
            } else {
                None
            };
            out.push(Decoded::Motion(MotionBlock {
                line: block.line,
                number: block.number,
                motion: self.motion,
                feed: self.feed,
                target: self.position,
                arc,
            }));
        }
    }

    /// `G04 t`, `G04 X t` (the first main axis names the time): alone in its block.
    fn dwell(
        &mut self,
        block: &Block,
        input: &BlockInput,
        ctx: &mut Ctx<'_>,
        tail: &mut Vec<Decoded>,
    ) {
        let (line, bare, programmed) = (block.line, input.dwell, input.programmed);
        let motion = input.motion_code.is_some();
        let by_axis =
            (programmed == 1).then(|| self.words[0] / if self.inch { MM_PER_INCH } else { 1.0 });
        let seconds = match (bare, by_axis) {
            _ if motion || (programmed != 0 && programmed != 1) => {
                ctx.error(block.span, "G04 stands alone in its block: its time is G04 <seconds> or G04 <first axis><seconds>");
                return;
            }
            (Some(_), Some(_)) => {
                ctx.error(
                    block.span,
                    "G04: give the time once (bare or with the first axis)",
                );
                return;
            }
            (Some((t, _)), None) | (None, Some(t)) => t,
            (None, None) => {
                ctx.error(block.span, "G04 needs a time in seconds: G04 2.5");
                return;
            }
        };
        if seconds.is_nan() || seconds < 0.0 {
            ctx.error(
                block.span,
                format!("dwell time must not be negative, found {seconds}"),
            );
            return;
        }
        tail.insert(0, Decoded::Dwell { line, seconds });
    }

    /// The circle of a G2/G3 block from `start` to the (already set) position.
    fn arc(
        &self,
        start: &AxisValues,
        center: [Option<f64>; 3],
        radius: Option<f64>,
        span: Span,
        ctx: &mut Ctx<'_>,
    ) -> Option<super::arc::ArcMove> {
        use super::arc::{center_from_radius, check_on_circle, ArcError, ArcMove};
        let [a, b, _] = self.plane.axes();
        if self.position.len() <= a.max(b) {
            ctx.error(
                span,
                "G2/G3 needs the channel's first three axes (the main axes)",
            );
            return None;
        }
        let p0 = [start[a], start[b]];
        let p1 = [self.position[a], self.position[b]];
        let ccw = self.motion == MotionMode::ArcCcw;
        let given = [center[a], center[b]];
        let has_center = given.iter().any(Option::is_some);
        let result = match (has_center, radius) {
            (true, Some(_)) => Err(ArcError::CenterAndRadius),
            (false, None) => Err(ArcError::NoCenter),
            // Checked on its own, the block's start is not known: nothing more to check.
            _ if !self.start_known => return None,
            (false, Some(r)) => center_from_radius(p0, p1, r, ccw),
            (true, None) => {
                let c = if self.center_absolute {
                    [
                        given[0].map_or(p0[0], |v| v + self.g92[a] + self.pset[a] + self.offset(a)),
                        given[1].map_or(p0[1], |v| v + self.g92[b] + self.pset[b] + self.offset(b)),
                    ]
                } else {
                    [
                        p0[0] + given[0].unwrap_or(0.0),
                        p0[1] + given[1].unwrap_or(0.0),
                    ]
                };
                check_on_circle(p0, p1, c, self.arc_tolerance).map(|()| c)
            }
        };
        match result {
            Ok(center) => {
                let full_turn = (p1[0] - p0[0]).hypot(p1[1] - p0[1]) < 1e-9;
                Some(ArcMove {
                    plane: self.plane,
                    center,
                    ccw,
                    full_turn,
                })
            }
            Err(e) => {
                ctx.error(span, e.to_string());
                None
            }
        }
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
                (Some("F"), Some(f), None) => feed = f * self.length_unit(),
                (Some("F"), None, Some(v)) => feed = ctx.eval(v, e.span)? * self.length_unit(),
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
        let pos = if axis < 3 {
            pos * self.length_unit()
        } else {
            pos
        };
        let target = if absolute {
            pos + self.g92[axis] + self.pset[axis] + self.offset(axis)
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

    /// The `#` command `command` at `span` of the block on `line`: its element, if it has one
    /// (`#PSET` and `#PRESET` change the decoder's offsets only).
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
            Command::Cs { on, name, values } => cs(line, *on, *name, values, span, ctx),
            Command::Trafo { on, id } => self.trafo(line, *on, id.as_ref(), span, ctx),
            Command::KinId { id } => {
                let id = ctx.whole(id, span, "kinematic id", 0.0, 65535.0)?;
                Some(Decoded::Trafo {
                    line,
                    on: None,
                    id: Some(id),
                })
            }
            Command::SignalSyn { options } => signal_syn(line, options, span, ctx),
            Command::WaitSyn { options } => wait_syn(line, options, span, ctx),
            Command::WaitIndpAll => Some(Decoded::WaitIndependent { line }),
            Command::Flush { wait } => Some(Decoded::Flush { line, wait: *wait }),
            Command::Pset { axes } => {
                self.pset(axes, ctx);
                None
            }
            Command::Msg { text } => Some(Decoded::Message {
                line,
                text: text.clone(),
            }),
            Command::Time { seconds } => time(line, seconds, span, ctx),
            Command::Var | Command::EndVar => None,
            Command::Preset { axes } => {
                self.preset(axes, span, ctx);
                None
            }
        }
    }

    /// `#TRAFO ON|OFF [id]`: switches the transformation (which takes the tool length off the
    /// decoder's offsets).
    fn trafo(
        &mut self,
        line: u32,
        on: Option<bool>,
        id: Option<&Expr>,
        span: Span,
        ctx: &mut Ctx<'_>,
    ) -> Option<Decoded> {
        let id = match id {
            Some(e) => Some(ctx.whole(e, span, "kinematic id", 0.0, 65535.0)?),
            None => None,
        };
        // `#TRAFO [45]` switches on with that id (as the seed's programs use it).
        let on = on.or(id.map(|_| true));
        if let Some(on) = on {
            self.trafo = on;
        }
        Some(Decoded::Trafo { line, on, id })
    }

    /// `#PSET X..`: each axis's preset offset, so that its position reads as given.
    fn pset(&mut self, axes: &[AxisWord], ctx: &mut Ctx<'_>) {
        for word in axes {
            let Some(i) = self.axis_of(&word.name) else {
                self.unknown_axis(ctx, word.span, word.name.as_str());
                continue;
            };
            if let Some(v) = ctx.eval(&word.value, word.span) {
                let v = if self.inch && i < 3 {
                    v * MM_PER_INCH
                } else {
                    v
                };
                // The position holds the zero offset and tool length: they are not the
                // preset's.
                self.pset[i] = self.position[i] - v - self.g92[i] - self.offset(i);
            }
        }
    }

    /// `#PRESET` (every axis) or `#PRESET X ..`: removes the preset offsets.
    fn preset(&mut self, axes: &[AxisName], span: Span, ctx: &mut Ctx<'_>) {
        if axes.is_empty() {
            self.pset.iter_mut().for_each(|p| *p = 0.0);
        }
        for name in axes {
            match self.axis_index(name.as_str()) {
                Some(i) => self.pset[i] = 0.0,
                None => self.unknown_axis(ctx, span, name.as_str()),
            }
        }
    }
}

/// `#CS ON|OFF [name] [values]` at `span`: the frame, missing values 0.
fn cs(
    line: u32,
    on: bool,
    name: Option<Name>,
    values: &[Expr],
    span: Span,
    ctx: &mut Ctx<'_>,
) -> Option<Decoded> {
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
        on,
        name,
        frame,
    })
}

/// `#SIGNAL SYN [ID.. COUNT..]` at `span`.
fn signal_syn(line: u32, options: &[Entry], span: Span, ctx: &mut Ctx<'_>) -> Option<Decoded> {
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

/// `#WAIT SYN [ID..]` at `span`: at most [`SyncIds::CAPACITY`] ids.
fn wait_syn(line: u32, options: &[Entry], span: Span, ctx: &mut Ctx<'_>) -> Option<Decoded> {
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

/// `#TIME t` at `span`: a dwell of `t` seconds.
fn time(line: u32, seconds: &Expr, span: Span, ctx: &mut Ctx<'_>) -> Option<Decoded> {
    let seconds = ctx.eval(seconds, span)?;
    if seconds < 0.0 {
        ctx.error(span, format!("#TIME must not be negative, found {seconds}"));
        return None;
    }
    Some(Decoded::Dwell { line, seconds })
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
        filter_ticks: None,
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
            "FILTER" => {
                t.filter_ticks = Some(whole_entry(e, ctx, "FILTER", 0.0, f64::from(u32::MAX))?)
            }
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
    if given("SET_ZERO") && given("ABSOLUTE") {
        ctx.error(
            span,
            "#TRACK CS: SET_ZERO and ABSOLUTE are the same option; give one",
        );
        ok = false;
    }
    (ok && (t.source.is_some() || !on)).then_some(t)
}

/// Evaluates `expr` at `span` of `src` with the variables of `vars`; the diagnostic says what
/// went wrong (an unknown variable, a division by zero, a value that is not finite...).
pub fn evaluate_at(expr: &Expr, span: Span, src: &str, vars: &dyn Vars) -> Result<f64, Diagnostic> {
    let mut ctx = Ctx {
        src,
        vars,
        diags: Vec::new(),
    };
    match ctx.eval(expr, span) {
        Some(v) if ctx.diags.is_empty() => Ok(v),
        _ => {
            // Unlocated: whoever reports it counts lines once for all its diagnostics.
            Err(ctx.diags.into_iter().next().unwrap_or_else(|| {
                Diagnostic::new(span, "the value cannot be computed".to_string(), src)
            }))
        }
    }
}

/// How many steps a check runs a program before it stops following it (a loop waiting for a
/// value only a running machine changes): generous for any program that ends by itself.
pub fn check_budget(blocks: usize) -> u64 {
    (blocks as u64)
        .saturating_mul(100)
        .saturating_add(1_000_000)
}

/// Checks a whole program for a channel with `axes`, reading the channel's variables from
/// `vars`: parses it with every subroutine file it calls (from `dir`, then `search`), runs it
/// once (see [`super::interp::check_set`]) and checks every block the run did not reach. `keep`
/// receives the decoded stream of the run (what `cnc check --blocks` prints), also when there
/// are diagnostics. The set is
/// only runnable when the diagnostics are empty.
pub fn check_program(
    name: &str,
    src: String,
    axes: &[String],
    setup: &DecoderSetup,
    paths: (Option<&std::path::Path>, &super::interp::SearchPath),
    vars: &dyn Vars,
    keep: Option<super::interp::BlockSink<'_>>,
) -> (super::interp::ProgramSet, Vec<Diagnostic>) {
    let (set, mut diags) = super::interp::ProgramSet::load(name, src, paths.0, paths.1);
    if let Err(message) = check_channel_axes(axes) {
        diags.push(Diagnostic::whole_program(message));
        return (set, diags);
    }
    {
        // Also with syntax errors: the tree holds what was understood, and its semantic
        // errors are reported with them.
        let mut decoder = DecoderState::new(axes);
        decoder.configure(setup);
        let budget = check_budget(set.block_count());
        let (run, _) = super::interp::check_set(&set, &mut decoder, vars, budget, keep);
        diags.extend(run);
        diags.sort_by(|a, b| {
            (a.file.as_deref(), a.line, a.col).cmp(&(b.file.as_deref(), b.line, b.col))
        });
        // The first diagnostic per position: a call that could not be resolved at load is
        // not reported again by the run.
        diags.dedup_by(|b, a| (&a.file, a.line, a.col) == (&b.file, b.line, b.col));
    }
    (set, diags)
}
