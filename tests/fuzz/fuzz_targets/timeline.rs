//! cargo-fuzz target `timeline`: the decoder of `tests/support/decoders.rs`.
#![no_main]

#[allow(dead_code)]
#[path = "../../support/decoders.rs"]
mod decoders;

/// The shipped scenarios, for the call target's machines.
static SCENARIOS: std::sync::LazyLock<std::path::PathBuf> = std::sync::LazyLock::new(|| {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios")
});

libfuzzer_sys::fuzz_target!(|data: &[u8]| decoders::timeline(data));
