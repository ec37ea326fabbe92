//! The high-level interface (HLI) between the CNC and the PLC process.
//!
//! * [`layout`]: `#[repr(C)]` control units and state images, sizes and offsets asserted at
//!   compile time;
//! * [`symbols`]: every node and leaf by its ST path; [`access`]: one leaf read or written by
//!   its path; [`c_header`]: the same layout for C;
//! * [`segment`]: the shared-memory object (create, attach, validate, heartbeats);
//! * [`handshake`]: the semaphore protocols as typed handles; [`views`]: the CNC's and the
//!   PLC's side of an image;
//! * [`events`]: iceoryx2 wake-ups; acyclic calls: [`wire`] (frames), [`calls`] (what
//!   every call has in common, the kinds, the refusal codes; one module per family of
//!   calls: [`calls::cam`], [`calls::fifo`] ...), [`rpc`] (the transport: a mailbox of call
//!   and bulk slots in shared memory);
//! * [`units`], [`enums`]: HLI units and validated enumerations.
//!
//! All `unsafe` code of the crate is in [`raw`] (the image memory and the `ZeroCopySend`
//! impls): the root denies `unsafe_code` and only `raw` allows it. The crate has no motion
//! logic; system calls that are not about the interface (the tick's sleep, memory advice,
//! real-time settings) are in the `cnc-os` crate.

#![deny(unsafe_code)]

pub mod access;
pub mod c_header;
pub mod calls;
pub mod command_book;
pub mod desc;
pub mod enums;
pub mod events;
pub mod handshake;
pub mod layout;
pub mod protocol;
#[allow(unsafe_code)]
pub mod raw;
pub mod rpc;
pub mod segment;
pub mod signals;
pub mod symbols;
pub mod units;
pub mod views;
pub mod wire;

pub use desc::{Bool, HliType, PlaceExt, SymbolWriter};
pub use raw::{ImageMemory, Place};

/// Quiets iceoryx2's own logging to errors unless `IOX2_LOG_LEVEL` says otherwise (it warns
/// about running without a config file, which is our normal case). Call once at start-up.
pub fn init_logging() {
    iceoryx2::prelude::set_log_level_from_env_or(iceoryx2::prelude::LogLevel::Error);
}
