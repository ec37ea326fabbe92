//! The operating-system calls the CNC and PLC processes make that have nothing to do with the
//! interface between them: a sleep to an absolute CLOCK_MONOTONIC deadline ([`monotonic`]),
//! transparent-huge-page advice for large buffers ([`advise_huge_pages`]), a child process's
//! peak memory ([`wait_with_peak_memory`]), the real-time settings of a thread
//! ([`realtime`]: SCHED_FIFO, CPU pinning, locked memory, timer slack, stack pre-faulting) and
//! a futex word shared between processes ([`futex`]), and log lines that never panic on a
//! closed pipe ([`stdio`]).
//!
//! Each is a thin, safe wrapper around one or two system calls. The crate is, beside
//! `hli::raw` (the image memory) and `hli_transport::raw` (a mapped object taken over as an
//! image), the only place of the workspace where `unsafe` code may live: the root denies it and each module that makes a system call allows it for itself,
//! with a `// SAFETY:` comment on every block. Everything else in the workspace forbids it.

#![deny(unsafe_code)]

#[cfg(target_os = "linux")]
#[allow(unsafe_code)]
pub mod futex;
#[allow(unsafe_code)]
mod memory;
#[allow(unsafe_code)]
pub mod monotonic;
#[cfg(target_os = "linux")]
#[allow(unsafe_code)]
mod process;
#[cfg(target_os = "linux")]
#[allow(unsafe_code)]
pub mod realtime;
pub mod stdio;

pub use memory::advise_huge_pages;
#[cfg(target_os = "linux")]
pub use process::{terminate, wait_with_peak_memory};
