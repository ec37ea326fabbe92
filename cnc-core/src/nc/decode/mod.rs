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
//!
//! This module holds the decoder's state and its entry points; `block` decodes a block's
//! items, dwell and motion, `commands` its `#` commands, `values` evaluates expressions with
//! the [`Vars`], `axes` checks axis names and keeps values per axis, `output` defines the
//! [`Decoded`] elements and `error` the [`DecodeError`] a block fails with (a value; its text
//! is made where a diagnostic or a channel's error is written).

mod axes;
mod block;
mod commands;
mod error;
mod output;
mod values;

use crate::setpoint::{AxisValues, MAX_CHANNEL_AXES};
pub use axes::{check_channel_axes, AxisLayout, POSE_AXES, RESERVED_ADDRESSES};
pub use error::{DecodeError, Form};
pub use output::{Decoded, MotionBlock, SyncIds, TrackCommand, TrackSource, DEFAULT_FILTER_TICKS};
pub use values::{evaluate, Vars, ZeroVars, KNOWN_VARIABLES};

use super::ast::*;
use super::Diagnostic;
use values::Ctx;

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

/// Default corner deviation of continuous path (mm), until `#CONTOUR MODE` sets one.
pub const DEFAULT_PATH_DEV: f64 = 0.05;

/// Default tolerance for an arc's end point against its circle (mm).
pub const DEFAULT_ARC_TOLERANCE: f64 = 0.001;

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
    /// The corner deviation of continuous path until the program sets one (mm).
    pub path_dev: f64,
}

impl Default for DecoderSetup {
    fn default() -> Self {
        Self {
            zero_offsets: Default::default(),
            tools: Vec::new(),
            tools_unknown: false,
            arc_tolerance: DEFAULT_ARC_TOLERANCE,
            path_dev: DEFAULT_PATH_DEV,
        }
    }
}

/// The decoder's modal state.
#[derive(Debug, Clone)]
pub struct DecoderState {
    /// The channel's axes by slot (pose slots X..C first; the values below are per slot).
    layout: AxisLayout,
    /// The slots' names for fast comparison with names from the tree.
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
    /// G261: continuous path at every block's end (G260 ends it).
    contour: bool,
    /// G360: exact stop at every block's end (G359 ends it); wins over G261.
    exact_stop: bool,
    /// `#CONTOUR MODE [PATH_DEV=..]`: the corner deviation (mm).
    path_dev: f64,
    /// Whether the position is where the program put it (false for a block checked on its own:
    /// an arc's start is not known then).
    start_known: bool,
    /// Per block: the values of its axis words by axis (valid where [`DecoderState::block`]
    /// marks the axis as programmed).
    words: [f64; MAX_CHANNEL_AXES],
    /// Non-motion elements of the block being decoded (kept to reuse its capacity).
    tail: Vec<Decoded>,
}

impl DecoderState {
    /// A channel with these axis names (upper case), at position 0, G0 G90, feed 0. Its values
    /// are kept per slot of the names' [`AxisLayout`].
    pub fn new(axes: &[String]) -> Self {
        let layout = AxisLayout::new(axes);
        let n = layout.len();
        Self {
            axis_names: layout
                .names()
                .iter()
                .map(|a| AxisName::from(a.as_str()))
                .collect(),
            layout,
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
            contour: false,
            exact_stop: false,
            path_dev: DEFAULT_PATH_DEV,
            start_known: true,
            words: [0.0; MAX_CHANNEL_AXES],
            tail: Vec::with_capacity(4),
        }
    }

    /// Decodes block `index` of `program` (parsed from `src`) with the variable values of
    /// `vars` now, appending its elements to `out`: how a channel consumes its program, one
    /// block when it reaches it. Returns the block's diagnostics (empty when it decoded
    /// cleanly; nothing is allocated then), their lines and columns left to count
    /// ([`super::locate`]): a check counts them once for all. Where a control statement goes
    /// is in the program's jump table ([`super::control::match_control`]).
    pub fn decode_block_unlocated(
        &mut self,
        program: &Program,
        index: usize,
        src: &str,
        vars: &dyn Vars,
        out: &mut Vec<Decoded>,
    ) -> Vec<Diagnostic> {
        let mut ctx = Ctx::all(vars);
        if let Some(block) = program.blocks.get(index) {
            self.block(block, program.items_of(block), &mut ctx, out);
        }
        ctx.into_errors()
            .map(|(span, e)| self.diagnostic(span, &e, src))
            .collect()
    }

    /// Decodes block `index` of `program` as a running channel does: the first error, as a
    /// value, and nothing allocated (neither for the elements, within the capacity of `out`,
    /// nor for an error).
    pub fn decode_block_in_run(
        &mut self,
        program: &Program,
        index: usize,
        vars: &dyn Vars,
        out: &mut Vec<Decoded>,
    ) -> Result<(), (Span, DecodeError)> {
        let mut ctx = Ctx::first_only(vars);
        if let Some(block) = program.blocks.get(index) {
            self.block(block, program.items_of(block), &mut ctx, out);
        }
        ctx.first.map_or(Ok(()), Err)
    }

    /// The diagnostic of `error` at `span` of `src`, with this channel's axis names where
    /// the text lists them (lines and columns not counted yet).
    pub fn diagnostic(&self, span: Span, error: &DecodeError, src: &str) -> Diagnostic {
        Diagnostic::new(span, error.with_axes(self.layout.names()).to_string(), src)
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

    /// The channel's axis names per slot (empty for a pose slot the channel lacks).
    pub fn axes(&self) -> &[String] {
        self.layout.names()
    }

    /// Where the channel's axes are kept.
    pub fn layout(&self) -> &AxisLayout {
        &self.layout
    }

    /// Takes the machine data of `setup`.
    pub fn configure(&mut self, setup: &DecoderSetup) {
        // G54..G59 per channel axis (values beyond the channel's axes are refused at load).
        for (offsets, values) in self.zero_offsets.iter_mut().zip(&setup.zero_offsets) {
            self.layout.place(values, offsets);
        }
        self.tools = setup.tools.clone();
        self.tools_unknown = setup.tools_unknown;
        self.arc_tolerance = setup.arc_tolerance;
        self.path_dev = setup.path_dev;
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
        let glued = name.len() > 1
            && matches!(name.as_bytes()[name.len().min(2) - 1], b'P' | b'V')
            && self.axis_index(&name[..1]).is_some();
        let name = Name::from(name);
        ctx.error(span, DecodeError::UnknownAxis { name, glued });
    }

    fn axis_index(&self, name: &str) -> Option<usize> {
        let slot = self.layout.names().iter().position(|a| a == name)?;
        self.layout.has(slot).then_some(slot)
    }

    /// Axis lookup for names straight from the tree (byte comparison, no UTF-8 check).
    fn axis_of(&self, name: &AxisName) -> Option<usize> {
        // An empty name (a pose slot the channel lacks) packs to 0, which no word's does.
        let packed = name.packed();
        (packed != 0)
            .then(|| self.axis_names.iter().position(|a| a.packed() == packed))
            .flatten()
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
