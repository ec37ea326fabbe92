//! The integration tests of hli in one binary, one module per topic: one linked test binary
//! instead of one per file keeps the build short on a small CI machine.

#[path = "../../../tests/support/counting_alloc.rs"]
mod counting_alloc;
mod golden;
mod handshake_model;
mod no_alloc;
