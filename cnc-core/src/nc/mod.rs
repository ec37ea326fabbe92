//! The NC language front end: [`parse`] (source to tree, never giving up), [`print`] (tree to
//! canonical source) and [`decode`] (tree to the typed block stream a channel executes).

pub mod arc;
pub mod ast;
pub mod check;
pub mod control;
pub mod decode;
pub mod eval;
mod fast_lane;
pub mod interp;
pub mod json;
pub mod lexer;
pub mod parser;
pub mod printer;
pub mod straight;

pub use decode::{check_program, Decoded, DecoderState, MotionBlock, MotionMode};
pub use parser::{parse, parse_general, set_buffer_advice};
pub use printer::print;

use ast::Span;

/// A problem found in a program: where, what was expected, and the offending text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagnostic {
    /// Line, 1-based.
    pub line: u32,
    /// Column, 1-based, in characters.
    pub col: u32,
    /// What is wrong (and what was expected).
    pub message: String,
    /// The offending source text (may be empty at the end of a block).
    pub found: String,
    /// Byte offset in the source, from which [`locate`] counts line and column.
    pub(crate) offset: u32,
    /// The file it is in, when a program spans several (subroutine files); else the one the
    /// caller names.
    pub file: Option<std::sync::Arc<str>>,
}

impl Diagnostic {
    /// A diagnostic at `span` of `src`. Its line and column are 0 until [`locate`] counts
    /// them: the tree keeps byte offsets only, and counting lines once for all diagnostics
    /// costs nothing when a program is clean.
    pub fn new(span: Span, message: String, src: &str) -> Self {
        let start = span.start as usize;
        let end = (span.end as usize).max(start).min(src.len());
        let found = src.get(start..end).unwrap_or("").trim().to_string();
        Self {
            line: 0,
            col: 0,
            message,
            found,
            offset: span.start,
            file: None,
        }
    }

    /// A diagnostic about the program as a whole (line 1, column 1), such as the channel's axis
    /// names.
    pub fn whole_program(message: String) -> Self {
        Self {
            line: 1,
            col: 1,
            message,
            found: String::new(),
            offset: 0,
            file: None,
        }
    }

    /// A diagnostic at `span` of `src` with its line and column counted.
    pub fn located(span: Span, message: String, src: &str) -> Self {
        let mut one = [Self::new(span, message, src)];
        locate(&mut one, src);
        let [d] = one;
        d
    }

    /// `FILE:LINE:COL: error: MESSAGE ["found"]` (its own file, if it has one).
    pub fn render(&self, file: &str) -> String {
        let file = self.file.as_deref().unwrap_or(file);
        if self.found.is_empty() || self.message.contains(&format!("\"{}\"", self.found)) {
            format!("{file}:{}:{}: error: {}", self.line, self.col, self.message)
        } else {
            format!(
                "{file}:{}:{}: error: {} (at \"{}\")",
                self.line, self.col, self.message, self.found
            )
        }
    }
}

/// Gives each diagnostic of `src` without a line yet its line and column (in characters),
/// counting through the source once, then orders them by position.
pub(crate) fn locate(diags: &mut [Diagnostic], src: &str) {
    if diags.is_empty() {
        return;
    }
    let mut order: Vec<usize> = (0..diags.len()).filter(|&i| diags[i].line == 0).collect();
    order.sort_by_key(|&i| diags[i].offset);
    let bytes = src.as_bytes();
    let (mut line, mut line_start, mut pos) = (1u32, 0usize, 0usize);
    for i in order {
        let target = (diags[i].offset as usize).min(bytes.len());
        while pos < target {
            if bytes[pos] == b'\n' {
                line += 1;
                line_start = pos + 1;
            }
            pos += 1;
        }
        let before = &bytes[line_start..target];
        // Columns count characters: continuation bytes of UTF-8 start with 0b10.
        let chars = before.iter().filter(|&&b| b & 0xC0 != 0x80).count();
        diags[i].line = line;
        diags[i].col = u32::try_from(chars + 1).unwrap_or(u32::MAX);
    }
    diags.sort_by_key(|d| (d.line, d.col));
}
