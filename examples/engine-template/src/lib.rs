//! A motion engine in a user's own crate, added by the recipe of ARCHITECTURE.md ("Adding an
//! engine"): an electronic gear with a ratio and a phase. The slave follows
//! `slave0 + ratio x (master - master0) + phase`, where a new phase is reached by a
//! jerk-limited shift within the `[phase_gear]` limits, while the coupling runs.
//!
//! Its home is this crate, one file per part of the recipe:
//!
//! * [`calls`]: the wire vocabulary (request and reply bodies, the kinds, the error codes),
//!   which both processes speak;
//! * [`engine`]: the engine on the machine seam, its `[phase_gear]` configuration and its
//!   `EngineDef`;
//! * [`block`]: the PLC blocks `PhaseGearIn` and `PhaseGearOut` on the block kernel, with
//!   their inputs declared as `InputSpec`s (what a timeline checks a call against).
//!
//! A program that runs it registers it once, before it reads a configuration: the one line
//! [`register`] (the standard `cnc` and `plc` binaries do not know it).

#![forbid(unsafe_code)]

pub mod block;
pub mod calls;
pub mod engine;

/// The call families, engines and block families this crate adds.
static CALLS: &[&[hli::calls::CallSpec]] = &[calls::CALLS];
static ENGINES: &[cnc_core::machine::engines::EngineDef] = &[engine::ENGINE];
static BLOCKS: &[&[plc_shim::timeline::registry::BlockSpec]] = &[block::TIMELINE];

/// Registers the phase gear with the HLI's calls, the machine's engines and the timeline's
/// blocks; again is allowed. `Err` says what clashes (a call number or block name taken,
/// other extensions registered before).
pub fn register() -> Result<(), String> {
    hli::calls::register_extension(CALLS).map_err(|e| e.to_string())?;
    cnc_core::machine::engines::register_extension(ENGINES).map_err(|e| e.to_string())?;
    plc_shim::timeline::registry::register_extension(BLOCKS)
}
