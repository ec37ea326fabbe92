//! The test house: the kit every integration test of the workspace shares. Nothing here is
//! used by production code.
//!
//! * [`unique_instance`]: a shared-memory instance name no other test uses;
//! * [`cli`]: every program a test runs (`cnc`, `plc`, `hli-peer`, `kill`, `gcc`, ...) runs
//!   with a watchdog and captured output ([`Cli`]); `cnc run` with an instance and a trace
//!   ([`cli::cnc_run`]); a scratch folder ([`Scratch`]); the repository's scenarios;
//! * [`child`]: a child process that never outlives its test ([`ChildGuard`]), signals;
//! * [`rig`]: axes on a heap image ([`AxisRig`]); [`channel_rig`]: channels and a controller
//!   on a heap image, configurations, a watchdog loop, PLC payloads;
//! * [`lockstep`]: stand-in CNCs in a thread for the PLC-side tests; [`peer`]: payloads with
//!   checksums and the `hli-peer` helper process.
//!
//! The kit depends on the libraries only (never on the application), so `cargo test -p
//! cnc-core` builds no application code; a scenario's in-process machine is the
//! application's own (`cnc_app::scenario::InProcess`, used by its tests).

#![forbid(unsafe_code)]

pub mod channel_rig;
pub mod child;
pub mod cli;
pub mod lockstep;
pub mod noise;
pub mod peer;
pub mod rig;

pub use child::ChildGuard;
pub use cli::{Cli, Scratch};
pub use lockstep::{lockstep_beats, lockstep_script, serve_axes_in_lockstep};
pub use noise::Noise;
pub use peer::{
    checksum, payload, remove_stale_segment, spawn_peer_saying, spawn_ready_peer, verify,
};
pub use rig::AxisRig;

use std::sync::atomic::{AtomicU32, Ordering};

/// A shared-memory instance name no other test (or test run) uses.
pub fn unique_instance(test: &str) -> String {
    static COUNTER: AtomicU32 = AtomicU32::new(0);
    format!(
        "t{}-{}-{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed),
        test
    )
}
