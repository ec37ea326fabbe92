//! IEC 61131-3 Structured Text in the TwinCAT flavour the manuals' PLC programs are written
//! in: [`lex`] (tokens with line and column: typed literals such as `DINT#-13059200`, based
//! integers `16#FF`, durations `T#1s500ms`, nested comments, pragmas skipped), [`parse`]
//! (programs, function blocks, functions, TYPE blocks, global variable lists, every
//! statement and expression of the language, `POINTER TO` with `^`), [`ast`] (the tree) and
//! [`diag`] (refusals as `FILE:LINE:COL: error: ..`).
//!
//! This is the language's front end; the checker, the compiler and the PLC runtime's binding
//! to the HLI and the block library build on it.

// Unsafe code lives in `vm::native`'s `raw` alone (the call into compiled code), which
// allows it; everywhere else it is refused.
#![deny(unsafe_code)]

pub mod ast;
pub mod check;
pub mod diag;
pub mod ir;
pub mod layout;
pub mod lex;
pub mod parse;
pub mod types;
pub mod vm;

pub use diag::{Diagnostic, Pos};
pub use parse::parse;

/// Parses `text` of file `file`: its tree, or the first refusal named with the file.
pub fn parse_file(file: &str, text: &str) -> Result<ast::Unit, Diagnostic> {
    parse(text).map_err(|d| d.in_file(file))
}
