//! Termination requests (SIGINT, SIGTERM) for the processes' main loops.
//!
//! iceoryx2 captures these signals in every process that opens a node (its signal handler
//! records the last one), so a process that never asks simply keeps running. `capture`
//! installs that handler at start-up; `take` asks for (and consumes) a pending request. It
//! takes a lock inside iceoryx2: call it from the main loop between ticks, not in the tick.

use iceoryx2_bb_posix::signal::{NonFatalFetchableSignal, SignalHandler};

/// A termination request.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Termination {
    /// SIGINT (Ctrl-C).
    Interrupt,
    /// SIGTERM.
    Terminate,
}

impl Termination {
    /// The exit code of a process that stopped on this signal: 128 + signal number.
    pub fn exit_code(self) -> u8 {
        match self {
            Termination::Interrupt => 130,
            Termination::Terminate => 143,
        }
    }

    /// The signal's name.
    pub fn name(self) -> &'static str {
        match self {
            Termination::Interrupt => "SIGINT",
            Termination::Terminate => "SIGTERM",
        }
    }
}

/// Installs the capturing handler (idempotent). Before it, SIGINT and SIGTERM end the process
/// at once.
pub fn capture() {
    let _ = SignalHandler::last_signal();
}

/// A termination request received since the last call, if any.
pub fn take() -> Option<Termination> {
    match SignalHandler::last_signal() {
        Some(NonFatalFetchableSignal::Interrupt) => Some(Termination::Interrupt),
        Some(NonFatalFetchableSignal::Terminate) => Some(Termination::Terminate),
        _ => None,
    }
}
