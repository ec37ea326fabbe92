//! Checking a loaded set: one run from the start, then every block the run did not reach.

use super::{with_file, Interpreter, ProgramSet, Step};
use crate::nc::decode::{Decoded, DecoderState, Vars};
use crate::nc::Diagnostic;

/// Receives the decoded elements of each step of a run.
pub type BlockSink<'a> = &'a mut dyn FnMut(&[Decoded]);

/// Checks a loaded set for a channel: runs it once from the start with `vars` (at most
/// `budget` steps: a loop waiting for a value that only a running machine changes is no
/// error), then checks every block the run did not reach on its own. `keep` receives the
/// decoded stream of the run, step by step (`cnc check --blocks`). Returns the diagnostics, the first
/// per block, sorted by file and position.
pub fn check_set(
    set: &ProgramSet,
    decoder: &mut DecoderState,
    vars: &dyn Vars,
    budget: u64,
    mut keep: Option<BlockSink<'_>>,
) -> (Vec<Diagnostic>, bool) {
    let mut visited: Vec<Vec<bool>> = set
        .units
        .iter()
        .map(|u| vec![false; u.tree.blocks.len()])
        .collect();
    // Per unit: its diagnostics, located once at the end (locating one at a time would scan
    // the source once per diagnostic), and which blocks failed in the run.
    let mut found: Vec<Vec<Diagnostic>> = set.units.iter().map(|_| Vec::new()).collect();
    let mut failed: Vec<Vec<bool>> = visited.clone();
    let mut interp = Interpreter::new();
    interp.start(set);
    let mut scratch = Vec::with_capacity(8);
    let mut steps = 0u64;
    let mut finished = false;
    let fresh = decoder.clone();
    while steps < budget {
        steps += 1;
        scratch.clear();
        let at = interp.position();
        let current = interp.current_block();
        let step = interp.step(set, decoder, vars, &mut scratch);
        // The block the step ran (or failed in) has been checked by the run.
        if let (Some((u, b)), Ok(Step::Block { .. } | Step::Control) | Err(_)) = (current, &step) {
            if let Some(v) = visited[u as usize].get_mut(b as usize) {
                *v = true;
            }
        }
        // A block that failed hands on nothing.
        if let (Some(k), Ok(_)) = (keep.as_deref_mut(), &step) {
            if !scratch.is_empty() {
                k(&scratch);
            }
        }
        match step {
            Ok(Step::End) => {
                finished = true;
                break;
            }
            Ok(Step::Undecided) => break,
            Ok(_) => {}
            Err(d) => {
                let (u, b) = current.or(at).unwrap_or((0, 0));
                let again = failed[u as usize].get(b as usize).copied().unwrap_or(true);
                if again {
                    // A block failing a second time (in a loop): its error is known, and the
                    // run cannot be trusted past it.
                    break;
                }
                failed[u as usize][b as usize] = true;
                found[u as usize].push(d.diagnostic(set, decoder.axes()));
                interp.skip_failed(at);
            }
        }
    }
    // The blocks the run did not reach, each on its own: values of the program's own variables
    // are unknown there, and so is the modal state (a feed is assumed, the start is unknown).
    let unknown = Unknown { system: vars };
    for (u, unit) in set.units.iter().enumerate() {
        let mut state = fresh.clone();
        state.checked_out_of_run();
        for (b, seen) in visited[u].iter().enumerate() {
            if *seen {
                continue;
            }
            scratch.clear();
            let more =
                state.decode_block_unlocated(&unit.tree, b, &unit.src, &unknown, &mut scratch);
            found[u].extend(more.into_iter().map(|d| with_file(d, unit)));
        }
    }
    let mut diags = Vec::new();
    for (u, mut list) in found.into_iter().enumerate() {
        crate::nc::locate(&mut list, &set.units[u].src);
        diags.append(&mut list);
    }
    diags.sort_by(|a, b| {
        (a.file.as_deref(), a.line, a.col).cmp(&(b.file.as_deref(), b.line, b.col))
    });
    diags.dedup();
    (diags, finished)
}

/// Variables of a block checked on its own: the channel's as given, the program's unknown.
pub(crate) struct Unknown<'a> {
    pub(crate) system: &'a dyn Vars,
}

impl Vars for Unknown<'_> {
    fn get(&self, name: &str) -> Option<f64> {
        self.system.get(name)
    }
    fn program_values_unknown(&self) -> bool {
        true
    }
}
