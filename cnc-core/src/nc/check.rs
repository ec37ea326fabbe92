//! The NC check API: a program text checked as `cnc check` checks it (parsed, run through
//! the interpreter with zero variables, decoded), with its diagnostics and the decoded block
//! stream; and a decoded motion block as the JSON line `cnc check --blocks` prints (the golden
//! tests compare these lines with LinuxCNC's).

use super::decode::{check_program, DecoderSetup, ZeroVars};
use super::interp::SearchPath;
use super::json::push_number;
use super::{Decoded, Diagnostic, MotionBlock};
use std::path::Path;

/// Checks one program text (subroutine files next to `dir`); returns its diagnostics (sorted)
/// and the decoded stream of its run.
pub fn check_source_in(
    src: &str,
    axes: &[String],
    dir: Option<&Path>,
    search: &SearchPath,
) -> (Vec<Diagnostic>, Vec<Decoded>) {
    let mut decoded = Vec::new();
    let mut keep = |step: &[Decoded]| decoded.extend_from_slice(step);
    let (_, diags) = check_program(
        "",
        src.to_string(),
        axes,
        &DecoderSetup::default(),
        (dir, search),
        &ZeroVars,
        Some(&mut keep),
    );
    (diags, decoded)
}

/// Checks one program text; returns its diagnostics (sorted) and the decoded stream.
pub fn check_source(src: &str, axes: &[String]) -> (Vec<Diagnostic>, Vec<Decoded>) {
    check_source_in(src, axes, None, &SearchPath::default())
}

/// A decoded motion block as the JSON line `--blocks` prints; `axes` are the channel's names
/// per slot ([`crate::nc::decode::AxisLayout::names`], the same as the configuration's for a
/// channel whose first axes are X Y Z A B C), an empty one left out.
pub fn motion_json(block: &MotionBlock, axes: &[String]) -> String {
    let mut out = String::new();
    push_motion_json(&mut out, block, axes);
    out
}

/// [`motion_json`] appended to `out` (no allocation of its own).
pub fn push_motion_json(out: &mut String, block: &MotionBlock, axes: &[String]) {
    use std::fmt::Write as _;
    let _ = write!(
        out,
        "{{\"line\":{},\"motion\":\"{}\",\"feed\":",
        block.line,
        block.motion.name()
    );
    push_number(out, block.feed);
    out.push_str(",\"target\":{");
    let slots = axes.iter().zip(block.target.iter());
    for (i, (name, v)) in slots.filter(|(name, _)| !name.is_empty()).enumerate() {
        if i > 0 {
            out.push(',');
        }
        out.push('"');
        out.push_str(name);
        out.push_str("\":");
        push_number(out, *v);
    }
    out.push('}');
    if let Some(arc) = &block.arc {
        let [a, b, _] = arc.plane.axes();
        let _ = write!(out, ",\"plane\":\"{}\",\"center\":{{", arc.plane.name());
        for (k, axis) in [a, b].into_iter().enumerate() {
            if k > 0 {
                out.push(',');
            }
            out.push('"');
            out.push_str(axes.get(axis).map_or("?", String::as_str));
            out.push_str("\":");
            push_number(out, arc.center[k]);
        }
        out.push('}');
        if arc.full_turn {
            out.push_str(",\"full_turn\":true");
        }
    }
    out.push('}');
}
