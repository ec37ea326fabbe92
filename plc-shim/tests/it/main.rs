//! The PLC runtime's integration tests, one binary (each file a module): a test binary
//! links the ST runtime's code generator, so one link instead of one per file.

// The counting allocator of the no-allocation tests (one per binary).
#[path = "../../../tests/support/counting_alloc.rs"]
mod counting_alloc;
#[path = "support/stand_in.rs"]
mod stand_in;

mod fifo_blocks;
mod st_blocks;
mod st_cam_ref;
mod st_saw_sync;
mod st_text;
mod st_vars;
