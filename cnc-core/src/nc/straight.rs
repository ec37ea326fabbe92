//! Checking a straight program as it is read: a program without `$` statements, calls and
//! local subroutines runs from its first block to its last, so it can be parsed, run and
//! checked one window of blocks at a time. `cnc check` keeps a window of the tree in memory
//! instead of the whole tree (which takes several times the source's size), and reads the
//! source once. A program that turns out not to be straight is left to the whole-program check
//! ([`super::check_program`]).

use super::ast::{Item, Program};
use super::decode::{DecoderSetup, DecoderState, Vars};
use super::interp::{BlockSink, Interpreter, Unknown};
use super::parser::Windows;
use super::Diagnostic;

/// Blocks per window: small enough to stay in the caches, large enough that refilling costs
/// nothing.
const WINDOW: usize = 4096;

/// Whether `window` holds anything that makes a program other than straight.
fn bends(window: &Program) -> bool {
    !window.subs.is_empty()
        || window
            .items
            .iter()
            .any(|i| matches!(i, Item::Control { .. } | Item::Call { .. }))
}

/// Checks `src` for a channel with `axes` window by window, the way
/// [`super::check_program`] checks a whole program, handing each step's decoded elements to
/// `sink`. `None` when the program is not straight.
pub fn check_straight(
    src: &str,
    axes: &[String],
    setup: &DecoderSetup,
    vars: &dyn Vars,
    mut sink: Option<BlockSink<'_>>,
) -> Option<Vec<Diagnostic>> {
    let mut windows = Windows::new(src);
    let mut window = Program::default();
    window.blocks.reserve(WINDOW);
    window.items.reserve(WINDOW * 8);
    let mut interp = Interpreter::new();
    interp.reset_variables();
    let mut decoder = DecoderState::new(axes);
    decoder.configure(setup);
    // Blocks after M2/M30 are checked on their own, as the whole-program check does.
    let mut after_end: Option<DecoderState> = None;
    let mut out = Vec::with_capacity(8);
    let mut diags = Vec::new();
    while windows.next(&mut window, WINDOW) {
        if bends(&window) {
            return None;
        }
        for b in 0..window.blocks.len() {
            out.clear();
            if let Some(state) = after_end.as_mut() {
                let unknown = Unknown { system: vars };
                diags.extend(state.decode_block_unlocated(&window, b, src, &unknown, &mut out));
                continue;
            }
            match interp.run_block(&window, b, src, &mut decoder, vars, &mut out) {
                Ok(ending) => {
                    if let Some(k) = sink.as_deref_mut() {
                        if !out.is_empty() {
                            k(&out);
                        }
                    }
                    if ending.end {
                        let mut state = DecoderState::new(axes);
                        state.configure(setup);
                        state.checked_out_of_run();
                        after_end = Some(state);
                    }
                }
                Err(d) => diags.push(d),
            }
        }
    }
    // Syntax first, as the whole-program check orders them: the first per position is kept.
    let mut all = windows.finish();
    super::locate(&mut diags, src);
    all.append(&mut diags);
    let mut diags = all;
    diags.sort_by_key(|d| (d.line, d.col));
    diags.dedup_by(|b, a| (a.line, a.col) == (b.line, b.col));
    Some(diags)
}
