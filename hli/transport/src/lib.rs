//! The transport of the high-level interface: how the image and the calls travel between the
//! CNC and the PLC process. The types, layouts and symbol table are the `hli` crate.
//!
//! * [`segment`]: the shared-memory object (create, attach, validate, heartbeats);
//! * [`events`]: iceoryx2 wake-ups;
//! * [`rpc`]: the acyclic calls' transport, a mailbox of call and bulk slots in shared memory;
//! * [`signals`]: termination signals as a flag the loops poll.
//!
//! The crate's one `unsafe` step is [`raw`] (a mapped object taken over as an image).

#![deny(unsafe_code)]

pub mod events;
#[allow(unsafe_code)]
pub mod raw;
pub mod rpc;
pub mod segment;
pub mod signals;

/// Quiets iceoryx2's own logging to errors unless `IOX2_LOG_LEVEL` says otherwise (it warns
/// about running without a config file, which is our normal case). Call once at start-up.
pub fn init_logging() {
    iceoryx2::prelude::set_log_level_from_env_or(iceoryx2::prelude::LogLevel::Error);
}
