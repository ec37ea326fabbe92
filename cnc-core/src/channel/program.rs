//! A channel program ready to run: parsed, checked as a whole (a program with any diagnostic
//! is refused, never executed), with its control flow resolved to block positions.

use crate::nc::ast::{Control, Item, Program};
use crate::nc::decode::{check_channel_axes, ZeroVars};
use crate::nc::{decode_program, parse, Diagnostic};

/// Where control goes from a `$` block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Jump {
    /// `$WHILE`: when the condition is false, continue after this block (its `$ENDWHILE`).
    While {
        /// The matching `$ENDWHILE`.
        end: usize,
    },
    /// `$ENDWHILE`: back to this `$WHILE`.
    EndWhile {
        /// The matching `$WHILE`.
        start: usize,
    },
    /// `$IF`: when false, continue after this block (`$ELSE`) or at it (`$ENDIF`).
    If {
        /// The matching `$ELSE` or `$ENDIF`.
        next: usize,
    },
    /// `$ELSE` reached from the true branch: continue after this block (`$ENDIF`).
    Else {
        /// The matching `$ENDIF`.
        end: usize,
    },
}

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
        let (_, semantic) = decode_program(&tree, src, axes, &ZeroVars);
        diagnostics.extend(semantic);
        if !diagnostics.is_empty() {
            diagnostics.sort_by_key(|d| (d.line, d.col));
            diagnostics.dedup();
            return Err(refuse(diagnostics));
        }
        let jumps = resolve_jumps(&tree);
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

/// Matches `$` statements by block (the whole-program check has verified they pair up).
fn resolve_jumps(tree: &Program) -> Vec<Option<Jump>> {
    let mut jumps = vec![None; tree.blocks.len()];
    // Open statements: (block, is_while, else block).
    let mut open: Vec<(usize, bool, Option<usize>)> = Vec::new();
    for (b, block) in tree.blocks.iter().enumerate() {
        for item in tree.items_of(block) {
            let Item::Control { control, .. } = item else {
                continue;
            };
            match control.as_ref() {
                Control::While(_) => open.push((b, true, None)),
                Control::If(_) => open.push((b, false, None)),
                Control::Else => {
                    if let Some((_, false, else_at)) = open.last_mut() {
                        *else_at = Some(b);
                    }
                }
                Control::EndWhile => {
                    if let Some((start, true, _)) = open.pop() {
                        jumps[start] = Some(Jump::While { end: b });
                        jumps[b] = Some(Jump::EndWhile { start });
                    }
                }
                Control::EndIf => {
                    if let Some((start, false, else_at)) = open.pop() {
                        jumps[start] = Some(Jump::If {
                            next: else_at.unwrap_or(b),
                        });
                        if let Some(e) = else_at {
                            jumps[e] = Some(Jump::Else { end: b });
                        }
                    }
                }
            }
        }
    }
    jumps
}
