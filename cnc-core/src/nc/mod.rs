//! The NC language front end: [`parse`] (source to tree, never giving up), [`print`] (tree to
//! canonical source) and [`decode`] (tree to the typed block stream a channel executes).

pub mod ast;
pub mod decode;
mod fast_lane;
pub mod lexer;
pub mod parser;
pub mod printer;

pub use decode::{decode_program, Decoded, DecoderState, MotionBlock, MotionMode};
pub use parser::{parse, parse_general};
pub use printer::print;

use ast::Span;

/// A problem found in a program: where, what was expected, and the offending text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagnostic {
    /// Line, 1-based.
    pub line: u32,
    /// Column, 1-based.
    pub col: u32,
    /// What is wrong (and what was expected).
    pub message: String,
    /// The offending source text (may be empty at the end of a block).
    pub found: String,
}

impl Diagnostic {
    /// A diagnostic at `span` of `src`.
    pub fn new(span: Span, message: String, src: &str) -> Self {
        let start = span.start as usize;
        let end = (span.end as usize).max(start).min(src.len());
        let found = src.get(start..end).unwrap_or("").trim().to_string();
        Self {
            line: span.line,
            col: span.col,
            message,
            found,
        }
    }

    /// `FILE:LINE:COL: error: MESSAGE ["found"]`.
    pub fn render(&self, file: &str) -> String {
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
