//! One block decoded: its items read, then its dwell, motion or offsets.

use super::values::Ctx;
use super::{DecodeError, Form};
use super::{Decoded, DecoderState, MotionBlock, MotionMode, MM_PER_INCH};
use crate::nc::ast::*;
use crate::setpoint::AxisValues;

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
    /// G61: this block's end is blended; G60/G09: it stops exactly.
    contour_here: bool,
    exact_here: bool,
}

impl DecoderState {
    /// Decodes one block; `out` receives its elements. Assignments, calls and `$` statements
    /// are the interpreter's ([`crate::nc::interp`]): here they are only checked to stand where
    /// they may.
    pub(super) fn block(
        &mut self,
        block: &Block,
        items: &[Item],
        ctx: &mut Ctx<'_>,
        out: &mut Vec<Decoded>,
    ) {
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
                            ctx.error(*span, DecodeError::FeedNotPositive { value: f });
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
                        ctx.error(*span, Form::CallNotAlone);
                    }
                }
                Item::Control { .. } => {
                    if items.len() > 1 {
                        ctx.error(block.span, Form::ControlNotAlone);
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
                    ctx.error(span, DecodeError::MotionTwice { code, other });
                }
                input.motion_code = Some((code, span));
            }
            4 => input.dwell_code = true,
            // Exact stop at this block's end (G60, G09) or at every one (G360 .. G359);
            // continuous path at this block's end (G61) or at every one (G261 .. G260).
            9 | 60 => input.exact_here = true,
            359 => self.exact_stop = false,
            360 => self.exact_stop = true,
            61 => input.contour_here = true,
            260 => self.contour = false,
            261 => self.contour = true,
            17 => self.plane = crate::nc::arc::Plane::Xy,
            18 => self.plane = crate::nc::arc::Plane::Zx,
            19 => self.plane = crate::nc::arc::Plane::Yz,
            53..=59 => self.zero = (code - 53) as usize,
            70 => self.inch = true,
            71 => self.inch = false,
            90 => self.absolute = true,
            91 => self.absolute = false,
            92 => input.g92 = true,
            161 => self.center_absolute = true,
            162 => self.center_absolute = false,
            other => ctx.error(span, DecodeError::UnknownGCode { code: other }),
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
            Addr::S => ctx.error(word.span, DecodeError::SpindleNegative { value: v }),
            _ => ctx.error(
                word.span,
                DecodeError::NotWholeAddress {
                    letter: addr.letter(),
                    value: v,
                },
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
            // Without a transformation the length goes on the plane's normal axis.
            if length != 0.0 && !self.trafo && !self.layout.has(self.plane.axes()[2]) {
                ctx.error(span, Form::ToolLengthNeedsAxis);
                return;
            }
            self.tool_length = length;
            tail.push(Decoded::ToolRecord { line, d: n });
        } else if self.tools_unknown {
            self.tool_length = 0.0;
        } else {
            ctx.error(span, DecodeError::NoToolRecord { d: n });
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
            let name = Name::from(word.name.as_str());
            ctx.error(word.span, DecodeError::AxisTwice { name });
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
            ctx.error(block.span, Form::ArcWordsWithoutArc);
        }
        let axes = BitIndices(input.programmed);
        if input.g92 {
            for i in axes {
                let v = self.words[i];
                self.g92[i] = if self.absolute { v } else { self.g92[i] + v };
            }
        } else if input.programmed != 0 || (is_arc && arc_words) {
            if self.motion.at_feed() && self.feed <= 0.0 {
                let motion = self.motion.name();
                ctx.error(block.span, DecodeError::NoFeed { motion });
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
                blend: self.blend(input),
                arc,
            }));
        }
    }

    /// Whether this block's end may be blended, and within what: continuous path (G61 here or
    /// G261 on), no exact stop (G60/G09 here or G360 on). Arcs too: the contour takes them
    /// as their chords.
    fn blend(&self, input: &BlockInput) -> Option<f64> {
        let continuous = input.contour_here || self.contour;
        let exact = input.exact_here || self.exact_stop;
        (continuous && !exact).then_some(self.path_dev)
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
                ctx.error(block.span, Form::DwellNotAlone);
                return;
            }
            (Some(_), Some(_)) => {
                ctx.error(block.span, Form::DwellTimeTwice);
                return;
            }
            (Some((t, _)), None) | (None, Some(t)) => t,
            (None, None) => {
                ctx.error(block.span, Form::DwellNoTime);
                return;
            }
        };
        if seconds.is_nan() || seconds < 0.0 {
            ctx.error(block.span, DecodeError::DwellNegative { seconds });
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
    ) -> Option<crate::nc::arc::ArcMove> {
        use crate::nc::arc::{center_from_radius, check_on_circle, ArcError, ArcMove};
        let [a, b, _] = self.plane.axes();
        if !(self.layout.has(a) && self.layout.has(b)) {
            ctx.error(span, Form::ArcNeedsMainAxes);
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
                ctx.error(span, DecodeError::Arc(e));
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
                _ => ctx.error(e.span, Form::IndependentOption),
            }
        }
        let Some(asynchronous) = asynchronous else {
            ctx.error(span, Form::IndependentMode);
            return None;
        };
        let Some(pos) = pos else {
            ctx.error(span, Form::IndependentPos);
            return None;
        };
        if motion == MotionMode::Linear && feed <= 0.0 {
            ctx.error(span, DecodeError::IndependentNoFeed);
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
}
