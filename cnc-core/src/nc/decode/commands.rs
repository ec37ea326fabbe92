//! The `#` commands of a block, checked and decoded.

use super::values::Ctx;
use super::{
    DecodeError, Decoded, DecoderState, Form, SyncIds, TrackCommand, TrackSource, MM_PER_INCH,
};
use crate::nc::ast::*;
use std::sync::Arc;

impl DecoderState {
    /// The `#` command `command` at `span` of the block on `line`: its element, if it has one
    /// (`#PSET` and `#PRESET` change the decoder's offsets only).
    pub(super) fn command(
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
            Command::Contour { options } => {
                self.contour(options, ctx);
                None
            }
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
        if on == Some(true) && !self.layout.has_pose() {
            ctx.error(span, Form::TrafoNeedsPoseAxes);
            return None;
        }
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
        let found = values.len();
        ctx.error(span, DecodeError::CsValues { found });
        return None;
    }
    if !on && !values.is_empty() {
        ctx.error(span, Form::CsOffValues);
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
            ctx.error(span, Form::SignalSynOptions);
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
            ctx.error(e.span, DecodeError::WaitSynIds);
            return None;
        }
    }
    if ids.as_slice().is_empty() {
        ctx.error(span, Form::WaitSynNoId);
        return None;
    }
    Some(Decoded::WaitSyn { line, ids })
}

/// `#TIME t` at `span`: a dwell of `t` seconds.
impl DecoderState {
    /// `#CONTOUR MODE [DEV PATH_DEV=..]`: the corner deviation of continuous path from here on.
    fn contour(&mut self, options: &[Entry], ctx: &mut Ctx<'_>) {
        for e in options
            .iter()
            .filter(|e| e.key.as_deref() == Some("PATH_DEV"))
        {
            let Some(value) = entry_number(e, ctx) else {
                continue;
            };
            if !(value.is_finite() && value >= 0.0) {
                ctx.error(e.span, DecodeError::PathDeviation { value });
                continue;
            }
            let mm = if self.inch {
                value * MM_PER_INCH
            } else {
                value
            };
            self.path_dev = mm;
        }
    }
}

fn time(line: u32, seconds: &Expr, span: Span, ctx: &mut Ctx<'_>) -> Option<Decoded> {
    let seconds = ctx.eval(seconds, span)?;
    if seconds < 0.0 {
        ctx.error(span, DecodeError::TimeNegative { seconds });
        return None;
    }
    Some(Decoded::Dwell { line, seconds })
}

fn entry_number(e: &Entry, ctx: &mut Ctx<'_>) -> Option<f64> {
    match (e.glued, &e.value) {
        (Some(v), None) => Some(v),
        (None, Some(v)) => ctx.eval(v, e.span),
        _ => {
            ctx.error(e.span, Form::ExpectedValue);
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
            ctx.error(
                e.span,
                DecodeError::TrackOptionTwice {
                    key: Name::from(key),
                },
            );
            ok = false;
            continue;
        }
        seen |= bit;
        if !on && !OFF_OPTIONS.contains(&key) {
            ctx.error(
                e.span,
                DecodeError::TrackOffOption {
                    key: Name::from(key),
                },
            );
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
                    ctx.error(e.span, Form::LogFileName);
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
        ctx.error(span, Form::TrackSourceTwice);
        ok = false;
    }
    if on && !given("CH") && !given("ID") {
        ctx.error(span, Form::TrackNoSource);
        ok = false;
    }
    if given("SET_ZERO") && given("ABSOLUTE") {
        ctx.error(span, Form::TrackSetZeroTwice);
        ok = false;
    }
    (ok && (t.source.is_some() || !on)).then_some(t)
}
