//! A channel program ready to run: parsed and checked as a whole in one pass (a program with
//! any diagnostic is refused, never executed), keeping its tree and its jump table. Blocks are
//! decoded only when the channel reaches them.

use crate::nc::ast::Program;
pub use crate::nc::control::Jump;
use crate::nc::decode::{check_channel_axes, ZeroVars};
use crate::nc::{check_program, parse, Diagnostic};

/// A checked program.
#[derive(Debug, Clone)]
pub struct LoadedProgram {
    /// Name for messages (file name or scenario key).
    pub name: String,
    /// The source text.
    pub src: String,
    /// The tree.
    pub tree: Program,
    /// Per block: its jump, if it is a `$` statement.
    pub jumps: Vec<Option<Jump>>,
}

/// A program refused at load.
#[derive(Debug, Clone, thiserror::Error)]
#[error("{}", render(.name, .diagnostics))]
pub struct ProgramError {
    /// Program name.
    pub name: String,
    /// Everything wrong with it.
    pub diagnostics: Vec<Diagnostic>,
}

fn render(name: &str, diagnostics: &[Diagnostic]) -> String {
    diagnostics
        .iter()
        .map(|d| d.render(name))
        .collect::<Vec<_>>()
        .join("\n")
}

impl LoadedProgram {
    /// Parses and checks `src` for a channel with `axes`.
    pub fn load(name: &str, src: &str, axes: &[String]) -> Result<Self, ProgramError> {
        let refuse = |diagnostics| ProgramError {
            name: name.to_string(),
            diagnostics,
        };
        if let Err(message) = check_channel_axes(axes) {
            return Err(refuse(vec![Diagnostic {
                line: 1,
                col: 1,
                message,
                found: String::new(),
                offset: 0,
            }]));
        }
        let (tree, mut diagnostics) = parse(src);
        let (jumps, semantic) = check_program(&tree, src, axes, &ZeroVars);
        diagnostics.extend(semantic);
        if !diagnostics.is_empty() {
            diagnostics.sort_by_key(|d| (d.line, d.col));
            diagnostics.dedup();
            return Err(refuse(diagnostics));
        }
        Ok(Self {
            name: name.to_string(),
            src: src.to_string(),
            tree,
            jumps,
        })
    }

    /// Number of blocks.
    pub fn len(&self) -> usize {
        self.tree.blocks.len()
    }

    /// Whether the program has no blocks.
    pub fn is_empty(&self) -> bool {
        self.tree.blocks.is_empty()
    }
}
