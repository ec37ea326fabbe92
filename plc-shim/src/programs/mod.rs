//! Example PLC programs: the rotary table as dynamic-CS master (here), the turntable of
//! application example 4 ([`turntable`]), the cam conveyor ([`cam_conveyor`]), a position file
//! streamed through a FIFO group ([`fifo_stream`]), a flying saw cutting equal lengths
//! ([`saw_cut`]), and the program of `cnc demo`'s machine built from three of them
//! ([`demo_machine`]).

pub mod cam_conveyor;
pub mod demo_machine;
pub mod fifo_stream;
pub mod saw_cut;
pub mod turntable;

use crate::blocks::dyn_cs::{DynCsMaster, MFunctionHandshake, McDynCsTransition};
use crate::blocks::motion::{McMoveVelocity, McPower};
use crate::runtime::{PlcIo, PlcProgram};
use hli::calls::axis::ReadAxisState;
use hli_transport::rpc::PendingCall;

/// The table axis (index in `gpAx`).
const TABLE_AXIS: u32 = 0;
/// PLC cycle the table speed is given for.
const NOMINAL_CYCLE_S: f64 = 0.001;

/// The PLC as master of a dynamic coordinate system: a rotary table turning at a constant
/// speed. It powers the table axis and turns it with MC_MoveVelocity; every cycle it commands
/// the table frame (rotation = the axis's actual position) through [`DynCsMaster`], switches
/// tracking on in its second cycle through [`McDynCsTransition`], acknowledges M functions and
/// reads the table axis acyclically now and then.
#[derive(Debug)]
pub struct RotaryTableMaster {
    /// Channel whose unit the PLC drives.
    pub channel: usize,
    /// Table speed, degree per PLC cycle.
    pub deg_per_cycle: f64,
    /// Acyclic axis reads answered.
    pub acyclic_replies: u64,
    /// Acyclic calls that failed.
    pub acyclic_errors: u64,
    /// Axis blocks that reported an error (counted once per error shown).
    pub axis_errors: u64,
    /// The table axis reached its velocity.
    pub table_in_velocity: bool,
    master: DynCsMaster,
    switch: McDynCsTransition,
    m: MFunctionHandshake,
    power: McPower,
    turn: McMoveVelocity,
    axis_failing: bool,
    read: Option<PendingCall<ReadAxisState>>,
}

impl RotaryTableMaster {
    /// A table on `channel` turning `deg_per_cycle` per cycle, tracking switched on with a
    /// filter of `filter_ticks`.
    pub fn new(channel: usize, deg_per_cycle: f64, filter_ticks: u32) -> Self {
        let mut switch = McDynCsTransition::default();
        switch.filter_max_ticks = filter_ticks;
        Self {
            channel,
            deg_per_cycle,
            acyclic_replies: 0,
            acyclic_errors: 0,
            axis_errors: 0,
            table_in_velocity: false,
            master: DynCsMaster::default(),
            switch,
            m: MFunctionHandshake::default(),
            power: McPower::default(),
            turn: McMoveVelocity::default(),
            axis_failing: false,
            read: None,
        }
    }
}

impl PlcProgram for RotaryTableMaster {
    fn cycle(&mut self, io: &mut PlcIo<'_>) {
        let ch = self.channel;
        // The table axis: powered, then turning at the configured speed.
        self.power.enable = true;
        self.power.call(io, TABLE_AXIS);
        if self.power.status && !self.turn.execute {
            self.turn.direction = 1;
            self.turn.velocity = self.deg_per_cycle / NOMINAL_CYCLE_S;
            self.turn.acceleration = 10.0 * self.turn.velocity;
            self.turn.deceleration = self.turn.acceleration;
            self.turn.jerk = 100.0 * self.turn.velocity;
            self.turn.execute = true;
        }
        self.turn.call(io, TABLE_AXIS);
        self.table_in_velocity |= self.turn.out.in_velocity;
        let failing = self.turn.out.error || self.power.error;
        self.axis_errors += u64::from(failing && !self.axis_failing);
        self.axis_failing = failing;
        // The table frame: rotation about Z by the table's actual position, every cycle.
        self.master.enable = true;
        self.master.send = true;
        self.master.frame.rotation[2] = io
            .gp_ax(TABLE_AXIS as usize)
            .map_or(0, |axis| axis.lr_state().current_position_acs_r);
        self.master.call(io, ch);
        // Tracking on in the second cycle (a one-cycle Execute pulse).
        self.switch.execute = io.cycle == 1;
        self.switch.call(io, ch);
        // M functions: acknowledged as they come.
        self.m.call(io, ch);
        self.m.acknowledge(io, ch);
        // Acyclic read of the table axis now and then, without blocking the cycle.
        if io.cycle % 500 == 250 && io.view.axis_count() > 0 && self.read.is_none() {
            match io.acyclic.start(TABLE_AXIS, &ReadAxisState::default()) {
                Ok(pending) => self.read = Some(pending),
                Err(_) => self.acyclic_errors += 1,
            }
        }
        if let Some(result) = self.read.as_ref().and_then(PendingCall::poll) {
            match result {
                Ok(_) => self.acyclic_replies += 1,
                Err(_) => self.acyclic_errors += 1,
            }
            self.read = None;
        }
    }

    fn summary(&self) -> String {
        format!(
            "plc: commands {} (busy {}), requests read {}, transitions {}, M acks {}, acyclic replies {} (errors {}), axis errors {}, block error {:#x}, last state {:?}, table in velocity {}",
            self.master.frames_sent,
            self.master.frames_waiting,
            self.master.requests_read,
            self.switch.sent,
            self.m.acknowledged,
            self.acyclic_replies,
            self.acyclic_errors,
            self.axis_errors,
            self.master.error_id.max(self.switch.out.error_id).max(self.m.error_id),
            self.master.state,
            self.table_in_velocity
        )
    }
}
