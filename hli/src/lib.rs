//! The high-level interface (HLI) between the CNC and the PLC process: what it is, apart
//! from how it travels. No process, no system call, no shared memory: the transport (the
//! shared segment, the call mailbox, the wake-up events) is the `hli-transport` crate
//! beside this one.
//!
//! * [`layout`]: `#[repr(C)]` control units and state images, sizes and offsets asserted at
//!   compile time; [`image`]: the image's identity and header, a heap-backed image;
//! * [`symbols`]: every node and leaf by its ST path; [`access`]: one leaf read or written by
//!   its path; [`c_header`]: the same layout for C;
//! * [`handshake`]: the semaphore protocols as typed handles; [`views`]: the CNC's and the
//!   PLC's side of an image; [`protocol`]: the rules for outside writes;
//! * acyclic calls: [`wire`] (frames), [`calls`] (what every call has in common, the kinds,
//!   the refusal codes; one module per family of calls: [`calls::cam`], [`calls::fifo`] ...);
//! * [`units`], [`enums`]: HLI units and validated enumerations.
//!
//! All `unsafe` code of the crate is in [`raw`] (the image memory and the `ZeroCopySend`
//! impls that let the transport move frames): the root denies `unsafe_code` and only `raw`
//! allows it. The crate's one dependency beyond plain data is iceoryx2's trait crate
//! (`iceoryx2-bb-elementary-traits`, no code of its own) for those impls.

#![deny(unsafe_code)]

pub mod access;
pub mod c_header;
pub mod calls;
pub mod command_book;
pub mod desc;
pub mod enums;
pub mod handshake;
pub mod image;
pub mod layout;
pub mod protocol;
#[allow(unsafe_code)]
pub mod raw;
pub mod st_prelude;
pub mod symbols;
pub mod units;
pub mod views;
pub mod wire;

pub use desc::{Bool, HliType, PlaceExt, SymbolWriter};
pub use raw::{ImageMemory, Place};
