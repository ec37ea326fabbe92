//! Example PLC programs: the rotary table as dynamic-CS master (here), the cam conveyor
//! ([`cam_conveyor`]), a position file streamed through a FIFO group ([`fifo_stream`]) and a
//! flying saw cutting equal lengths ([`saw_cut`]).

pub mod cam_conveyor;
pub mod fifo_stream;
pub mod saw_cut;
pub mod turntable;

use crate::motion::{McMoveVelocity, McPower};
use crate::runtime::{PlcIo, PlcProgram};
use hli::enums::{DynCsCommand, DynCsState};
use hli::layout::{HliCoordinateSystemInt, HliDynCsTransition, HliMFunctionAck};
use hli::rpc::{PendingCall, ReadAxisState};
use hli::Bool;

/// The table axis (index in `gpAx`).
const TABLE_AXIS: u32 = 0;
/// PLC cycle the table speed is given for.
const NOMINAL_CYCLE_S: f64 = 0.001;

/// The PLC as master of a dynamic coordinate system: a rotary table turning at a constant
/// speed (the seed's example 4, PLC-only variant). It powers the table axis and turns it with
/// MC_MoveVelocity; every cycle it commands the table frame (rotation = the axis's actual
/// position)
/// through `MC_CONTROL_DYN_CS_UNIT.command_w`, switches tracking on through `transition_w`,
/// reads back `request_r`, acknowledges M functions and reads the table axis acyclically.
#[derive(Debug, Default)]
pub struct RotaryTableMaster {
    /// Channel whose unit the PLC drives.
    pub channel: usize,
    /// Table speed, degree per PLC cycle.
    pub deg_per_cycle: f64,
    /// Filter ticks sent with the activation.
    pub filter_ticks: u32,
    /// Commands the CNC consumed (sent while free).
    pub commands_sent: u64,
    /// Commands refused because the previous one was pending.
    pub commands_busy: u64,
    /// Requests read back.
    pub requests_read: u64,
    /// Transitions sent.
    pub transitions_sent: u64,
    /// M functions acknowledged.
    pub m_functions_acked: u64,
    /// Acyclic axis reads answered.
    pub acyclic_replies: u64,
    /// Acyclic calls that failed.
    pub acyclic_errors: u64,
    /// Protocol or decoding problems seen.
    pub errors: u64,
    /// Last tracking state seen.
    pub last_state: Option<DynCsState>,
    /// The table axis reached its velocity.
    pub table_in_velocity: bool,
    /// Last table position read from the image, 0.0001 degree.
    pub table_position: i32,
    pending_ack: Option<HliMFunctionAck>,
    power: McPower,
    turn: McMoveVelocity,
    axis_failing: bool,
    read: Option<PendingCall<ReadAxisState>>,
}

impl RotaryTableMaster {
    /// A table on `channel` turning `deg_per_cycle` per cycle.
    pub fn new(channel: usize, deg_per_cycle: f64, filter_ticks: u32) -> Self {
        Self {
            channel,
            deg_per_cycle,
            filter_ticks,
            ..Self::default()
        }
    }
}

impl PlcProgram for RotaryTableMaster {
    fn cycle(&mut self, io: &mut PlcIo<'_>) {
        let view = io.view;
        let ch = self.channel;
        if io.cycle == 0 && view.set_dyn_cs_enabled(ch, true).is_err() {
            self.errors += 1;
            return;
        }
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
        if failing && !self.axis_failing {
            self.errors += 1; // once per refusal, not per cycle it stays shown
        }
        self.axis_failing = failing;
        // The table frame: rotation about Z by the table's actual position (wrapped to a turn).
        if let Ok(axis) = view.axis_state(TABLE_AXIS as usize) {
            self.table_position = axis.current_position_acs_r;
        }
        let frame = HliCoordinateSystemInt {
            translation: [0; 3],
            fill_up_2: 0,
            rotation: [0, 0, self.table_position],
            fill_up_1: 0,
        };
        match view.dyn_cs_command(ch).map(|tx| tx.try_send(&frame)) {
            Ok(Ok(())) => self.commands_sent += 1,
            Ok(Err(hli::handshake::SendError::Busy)) => self.commands_busy += 1,
            _ => self.errors += 1,
        }
        if io.cycle == 1 {
            let params = HliDynCsTransition {
                command: 0,
                filter_max_ticks: self.filter_ticks,
                option: 0,
                f_wait: Bool::FALSE,
                f_set_zero: Bool::FALSE,
                f_kin_base: Bool::FALSE,
                f_rot_trans: Bool::FALSE,
                kinematic_base_cs: bytemuck::Zeroable::zeroed(),
            };
            match view
                .dyn_cs_transition(ch)
                .map(|tx| tx.try_send(DynCsCommand::Activate, &params))
            {
                Ok(Ok(())) => self.transitions_sent += 1,
                _ => self.errors += 1,
            }
        }
        if let Ok(mut rx) = view.dyn_cs_request(ch) {
            match rx.try_take() {
                Ok(Some(_)) => self.requests_read += 1,
                Ok(None) => {}
                Err(_) => self.errors += 1,
            }
        }
        match view.dyn_cs_state(ch) {
            Ok(Ok(state)) => self.last_state = Some(state),
            _ => self.errors += 1,
        }
        // M functions: read the announcement, acknowledge it (possibly a later cycle).
        if let Ok(mut rx) = view.m_function_request(ch) {
            match rx.try_take() {
                Ok(Some(request)) => {
                    self.pending_ack = Some(HliMFunctionAck {
                        m_code: request.m_code,
                        request_id: request.request_id,
                    })
                }
                Ok(None) => {}
                Err(_) => self.errors += 1,
            }
        }
        if let Some(ack) = self.pending_ack {
            if let Ok(Ok(())) = view.m_function_ack(ch).map(|tx| tx.try_send(&ack)) {
                self.pending_ack = None;
                self.m_functions_acked += 1;
            }
        }
        // Acyclic read of the table axis now and then, without blocking the cycle.
        if io.cycle % 500 == 250 && view.axis_count() > 0 && self.read.is_none() {
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
            "plc: commands {} (busy {}), requests read {}, transitions {}, M acks {}, acyclic replies {} (errors {}), protocol errors {}, last state {:?}, table in velocity {}",
            self.commands_sent,
            self.commands_busy,
            self.requests_read,
            self.transitions_sent,
            self.m_functions_acked,
            self.acyclic_replies,
            self.acyclic_errors,
            self.errors,
            self.last_state,
            self.table_in_velocity
        )
    }
}
