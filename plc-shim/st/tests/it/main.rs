//! The Structured Text runtime's integration tests, one binary (each file a module): a
//! test binary links the code generator, so one link instead of one per file.

// The counting allocator of the no-allocation tests (one per binary).
#[path = "../../../../tests/support/counting_alloc.rs"]
mod counting_alloc;
mod support;

mod bytes;
mod calls;
mod check;
mod consts;
mod host;
mod image;
mod init_blocks;
mod literals;
mod methods;
mod native;
mod parse;
mod pointers;
mod references;
mod run;
mod standard;
mod text;
mod time;
mod two_ways;
mod unions;
