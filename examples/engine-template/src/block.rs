//! The phase gear's PLC blocks on the block kernel (its Execute, Busy, timeout and output
//! rules): each sends its call to the slave's axis index on a rising Execute and is Done once
//! the CNC took it, or Error with the engine's code ([`crate::calls::PhaseGearError`]).
//!
//! ```toml
//! [[step]]
//! call = { block = "PhaseGearIn", instance = "gear", axis = 1, master = 0, ratio = 0.5,
//!          phase = 2.0 }
//! [[step]]
//! wait = "gear.Done"
//! ```

use crate::calls::{PhaseGearInCall, PhaseGearOutCall};
use hli::calls::AcyclicCall;
use hli_transport::rpc::PendingCall;
use plc_shim::kernel::{done_unless, no_follow, send, Kernel, Outputs};
use plc_shim::timeline::registry::{
    input, required, BlockSpec, InputField, InputSpec, Kind, TimelineBlock, Value,
};
use plc_shim::PlcIo;

/// A block that sends one call of kind `C` and is Done when the CNC took it.
#[derive(Debug, Default)]
pub struct OneCall<C: AcyclicCall> {
    /// Input: a rising edge sends the call.
    pub execute: bool,
    /// Inputs: the call's body.
    pub inputs: C,
    /// Outputs of the last cycle.
    pub out: Outputs,
    kernel: Kernel<PendingCall<C>>,
}

impl<C> OneCall<C>
where
    C: AcyclicCall<Reply = crate::calls::PhaseGearReply> + Copy,
{
    /// One cycle for slave axis `slave`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, slave: u32) {
        let body = self.inputs;
        self.out = self.kernel.cycle(
            io,
            self.execute,
            |io| send(io, slave, &body),
            |reply| done_unless(reply.error_id),
            no_follow,
        );
    }
}

/// PhaseGearIn: couple (or shift the phase of) the instance's axis.
pub type PhaseGearIn = OneCall<PhaseGearInCall>;
/// PhaseGearOut: let the instance's axis go.
pub type PhaseGearOut = OneCall<PhaseGearOutCall>;

/// PhaseGearIn's inputs (the slave is the instance's axis).
const GEAR_IN: &[InputSpec] = &[
    required("master", Kind::Count),
    input("ratio", Kind::Real),
    input("phase", Kind::Real),
];

/// A call body whose fields a timeline sets by input key.
pub trait Inputs {
    /// Sets input `key` (one of the block's declared inputs) to `value`.
    fn set(&mut self, key: &str, value: &Value);
}

impl Inputs for PhaseGearInCall {
    fn set(&mut self, key: &str, value: &Value) {
        match key {
            "master" => self.master.take(value),
            "ratio" => self.ratio.take(value),
            "phase" => self.phase.take(value),
            _ => {}
        }
    }
}

impl Inputs for PhaseGearOutCall {
    fn set(&mut self, _: &str, _: &Value) {}
}

impl<C> TimelineBlock for OneCall<C>
where
    C: AcyclicCall<Reply = crate::calls::PhaseGearReply> + Copy + Inputs + core::fmt::Debug,
{
    fn set(&mut self, key: &str, value: &Value) {
        self.inputs.set(key, value);
    }
    fn execute(&mut self) -> Option<&mut bool> {
        Some(&mut self.execute)
    }
    fn cycle(&mut self, io: &mut PlcIo<'_>, axis: u32) -> (Outputs, bool) {
        self.call(io, axis);
        (self.out, false)
    }
    fn timeout_cycles(&mut self, cycles: u64) -> bool {
        self.kernel.set_timeout_cycles(cycles);
        true
    }
}

/// The phase gear's blocks as a timeline calls them (registered by [`crate::register`]).
pub const TIMELINE: &[BlockSpec] = &[
    BlockSpec::on_axis("PhaseGearIn", GEAR_IN, |_| Box::<PhaseGearIn>::default()),
    BlockSpec::on_axis("PhaseGearOut", &[], |_| Box::<PhaseGearOut>::default()),
];
