//! Lines for a process's log and report that never panic: `println!` and `eprintln!` panic
//! when the reader of the pipe is gone (a parent that was killed, a log reader that ended),
//! which would end the process, or the task that logs, without saying why it stopped. A line
//! that cannot be written is dropped.

use std::io::Write;

/// Writes `line` and a newline to stdout; a closed stdout is ignored.
pub fn line_out(line: &str) {
    let _ = writeln!(std::io::stdout().lock(), "{line}");
}

/// Writes `line` and a newline to stderr; a closed stderr is ignored.
pub fn line_err(line: &str) {
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}
