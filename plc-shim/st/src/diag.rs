//! Where something is in a source file, and what is wrong there.

/// A line and column, both from 1 (columns count characters).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub struct Pos {
    /// The line.
    pub line: u32,
    /// The column.
    pub col: u32,
}

/// A refusal at a place of a file: rendered `FILE:LINE:COL: error: MESSAGE`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}:{}:{}: error: {message}", self.file, self.pos.line, self.pos.col)]
pub struct Diagnostic {
    /// The file (set by whoever reads it; empty until then).
    pub file: String,
    /// Where.
    pub pos: Pos,
    /// What.
    pub message: String,
}

impl Diagnostic {
    /// A refusal at `pos` of a file named later ([`Diagnostic::in_file`]).
    pub fn new(pos: Pos, message: impl Into<String>) -> Diagnostic {
        Diagnostic {
            file: String::new(),
            pos,
            message: message.into(),
        }
    }

    /// The same refusal, in `file`.
    pub fn in_file(mut self, file: &str) -> Diagnostic {
        self.file = file.to_string();
        self
    }
}
