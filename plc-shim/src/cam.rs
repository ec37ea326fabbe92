//! The cam blocks of chapter 5.1 for the PLC program: MC_CamTableSelect, MC_CamIn,
//! MC_CamInExt, MC_CamOut and MC_CamScaling. Like the motion blocks, each sends its call on
//! the rising Execute edge without waiting and stays Busy until the CNC answers. MC_CamIn
//! and MC_CamInExt then follow the slave's axis image: InSync once the slave is coupled
//! through a cam and synchronous (`coupling_state_r` 1, `nAxisState` 13), CommandAborted when
//! the coupling goes away, Error with the axis's error when the slave faults. The others are
//! Done when the CNC has taken the command (a scaling with a positional activation mode is
//! then queued in the CNC).

use crate::runtime::PlcIo;
use hli::calls::{
    AcyclicCall, CallError, CamInCall, CamOutCall, CamReply, CamScalingCall, CamTableSelectCall,
};
use hli::enums::{AxisState, CouplingState};
use hli::rpc::PendingCall;

/// Outputs of a cam block.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CamOutputs {
    /// The CNC took the command (one-shot blocks).
    pub done: bool,
    /// Sent and not finished.
    pub busy: bool,
    /// MC_CamIn(Ext): the slave follows the cam.
    pub in_sync: bool,
    /// MC_CamIn(Ext): the coupling ended without this block (MC_CamOut, a fault, a stop).
    pub command_aborted: bool,
    /// Refused or failed; see `error_id`.
    pub error: bool,
    /// The CNC's error code.
    pub error_id: u32,
}

enum Phase<C: AcyclicCall> {
    Idle,
    Sent(PendingCall<C>),
    /// A coupling accepted; `seen` once the slave showed it.
    Following {
        seen: bool,
    },
}

/// The Execute edge, the pending call and the outputs, shared by the cam blocks.
pub struct CamCore<C: AcyclicCall> {
    execute_before: bool,
    phase: Phase<C>,
    out: CamOutputs,
}

impl<C: AcyclicCall> Default for CamCore<C> {
    fn default() -> Self {
        Self {
            execute_before: false,
            phase: Phase::Idle,
            out: CamOutputs::default(),
        }
    }
}

impl<C: AcyclicCall> core::fmt::Debug for CamCore<C> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("CamCore").field("out", &self.out).finish()
    }
}

fn failed(code: u32) -> CamOutputs {
    CamOutputs {
        error: true,
        error_id: code,
        ..CamOutputs::default()
    }
}

impl<C: AcyclicCall<Reply = CamReply>> CamCore<C> {
    /// One cycle: `call` goes to `target` on a rising edge of `execute`; a coupling block
    /// (`couples`) then follows `slave`'s image.
    pub fn cycle(
        &mut self,
        io: &mut PlcIo<'_>,
        execute: bool,
        target: u32,
        call: impl FnOnce() -> C,
        couples: Option<u32>,
    ) -> CamOutputs {
        let rising = execute && !self.execute_before;
        self.execute_before = execute;
        if rising {
            self.out = CamOutputs::default();
            self.phase = match io.acyclic.start(target, &call()) {
                Ok(pending) => Phase::Sent(pending),
                Err(_) => {
                    self.out = failed(crate::motion::ERROR_NO_ANSWER);
                    Phase::Idle
                }
            };
        }
        if let Phase::Sent(pending) = &self.phase {
            match pending.poll() {
                None => self.out.busy = true,
                Some(Ok(reply)) if reply.error_id != 0 => {
                    self.out = failed(reply.error_id);
                    self.phase = Phase::Idle;
                }
                Some(Ok(_)) => match couples {
                    Some(_) => self.phase = Phase::Following { seen: false },
                    None => {
                        self.out = CamOutputs {
                            done: true,
                            ..CamOutputs::default()
                        };
                        self.phase = Phase::Idle;
                    }
                },
                Some(Err(CallError::Refused { code })) => {
                    self.out = failed(code.raw());
                    self.phase = Phase::Idle;
                }
                Some(Err(_)) => {
                    self.out = failed(crate::motion::ERROR_NO_ANSWER);
                    self.phase = Phase::Idle;
                }
            }
        }
        if let (Phase::Following { seen }, Some(slave)) = (&mut self.phase, couples) {
            let state = io.view.axis_state(slave as usize).ok();
            let cam = state.is_some_and(|s| s.coupling_state_r == CouplingState::Cam.raw());
            let synchronous =
                state.is_some_and(|s| s.axis_state_r == AxisState::SlaveSynchronous.raw() && cam);
            let error = state.map_or(0, |s| s.error_id_r);
            if error != 0 {
                self.out = failed(error);
                self.phase = Phase::Idle;
            } else if cam {
                *seen = true;
                self.out = CamOutputs {
                    in_sync: synchronous,
                    busy: !synchronous,
                    ..CamOutputs::default()
                };
            } else if *seen {
                self.out = CamOutputs {
                    command_aborted: true,
                    ..CamOutputs::default()
                };
                self.phase = Phase::Idle;
            } else {
                // Accepted between two ticks: the image shows it from the next tick on.
                self.out.busy = true;
            }
        }
        if !execute && matches!(self.phase, Phase::Idle) {
            // Execute low and nothing running: the outputs clear (after one cycle shown).
            let shown = self.out;
            self.out = CamOutputs::default();
            return shown;
        }
        self.out
    }
}

/// MC_CamTableSelect: how couplings through table `table` run (cyclic or linear).
#[derive(Debug, Default)]
pub struct McCamTableSelect {
    /// Input: a rising edge sends the selection.
    pub execute: bool,
    /// Input: the table ID.
    pub table: u32,
    /// Input: continued period by period.
    pub periodic: bool,
    /// Input: master coordinates absolute.
    pub master_absolute: bool,
    /// Input: slave coordinates absolute.
    pub slave_absolute: bool,
    /// Outputs of the last call.
    pub out: CamOutputs,
    core: CamCore<CamTableSelectCall>,
}

impl McCamTableSelect {
    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let call = CamTableSelectCall {
            periodic: u32::from(self.periodic),
            master_absolute: u32::from(self.master_absolute),
            slave_absolute: u32::from(self.slave_absolute),
            reserved: 0,
        };
        self.out = self.core.cycle(io, self.execute, self.table, || call, None);
    }
}

/// MC_CamIn and MC_CamInExt (`extended`): couples `slave` to `master` through a cam.
#[derive(Debug)]
pub struct McCamIn {
    /// Input: a rising edge sends the coupling.
    pub execute: bool,
    /// Input: the master axis.
    pub master: u32,
    /// Input: the cam table ID.
    pub table: u32,
    /// Input: raw `MC_StartMode` (1 absolute .. 4).
    pub start_mode: u32,
    /// Input (Ext): raw `MC_CamActivationMode`.
    pub activation_mode: u32,
    /// Input (Ext): the activation position.
    pub activation_position: f64,
    /// Input (Ext): raw `MC_CamScalingMode` of the master.
    pub master_scaling_mode: u32,
    /// Input (Ext): raw `MC_CamScalingMode` of the slave.
    pub slave_scaling_mode: u32,
    /// Input: master offset.
    pub master_offset: f64,
    /// Input: slave offset.
    pub slave_offset: f64,
    /// Input: master scaling.
    pub master_scaling: f64,
    /// Input: slave scaling.
    pub slave_scaling: f64,
    /// Input: raw `MC_InterpolationType` (tables).
    pub interpolation: u32,
    /// MC_CamInExt rather than MC_CamIn.
    pub extended: bool,
    /// Outputs of the last call.
    pub out: CamOutputs,
    core: CamCore<CamInCall>,
}

impl Default for McCamIn {
    fn default() -> Self {
        Self {
            execute: false,
            master: 0,
            table: 0,
            start_mode: 1,
            activation_mode: 0,
            activation_position: 0.0,
            master_scaling_mode: 0,
            slave_scaling_mode: 0,
            master_offset: 0.0,
            slave_offset: 0.0,
            master_scaling: 1.0,
            slave_scaling: 1.0,
            interpolation: 0,
            extended: false,
            out: CamOutputs::default(),
            core: CamCore::default(),
        }
    }
}

impl McCamIn {
    /// One cycle for slave axis `slave`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, slave: u32) {
        let call = CamInCall {
            master: self.master,
            table_id: self.table,
            start_mode: self.start_mode,
            activation_mode: self.activation_mode,
            master_scaling_mode: self.master_scaling_mode,
            slave_scaling_mode: self.slave_scaling_mode,
            interpolation: self.interpolation,
            extended: u32::from(self.extended),
            activation_position: self.activation_position,
            master_offset: self.master_offset,
            slave_offset: self.slave_offset,
            master_scaling: self.master_scaling,
            slave_scaling: self.slave_scaling,
        };
        self.out = self
            .core
            .cycle(io, self.execute, slave, || call, Some(slave));
    }
}

/// MC_CamOut: the slave leaves its cam and goes on at its velocity as a free axis.
#[derive(Debug, Default)]
pub struct McCamOut {
    /// Input: a rising edge sends it.
    pub execute: bool,
    /// Outputs of the last call.
    pub out: CamOutputs,
    core: CamCore<CamOutCall>,
}

impl McCamOut {
    /// One cycle for slave axis `slave`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, slave: u32) {
        self.out = self
            .core
            .cycle(io, self.execute, slave, CamOutCall::default, None);
    }
}

/// MC_CamScaling: new offsets and scalings of a coupling, now or at an activation.
#[derive(Debug)]
pub struct McCamScaling {
    /// Input: a rising edge sends it.
    pub execute: bool,
    /// Input: raw `MC_CamActivationMode`.
    pub activation_mode: u32,
    /// Input: the activation position.
    pub activation_position: f64,
    /// Input: raw `MC_CamScalingMode` of the master.
    pub master_scaling_mode: u32,
    /// Input: raw `MC_CamScalingMode` of the slave.
    pub slave_scaling_mode: u32,
    /// Input: master offset.
    pub master_offset: f64,
    /// Input: slave offset.
    pub slave_offset: f64,
    /// Input: master scaling.
    pub master_scaling: f64,
    /// Input: slave scaling.
    pub slave_scaling: f64,
    /// Outputs of the last call.
    pub out: CamOutputs,
    core: CamCore<CamScalingCall>,
}

impl Default for McCamScaling {
    fn default() -> Self {
        Self {
            execute: false,
            activation_mode: 0,
            activation_position: 0.0,
            master_scaling_mode: 0,
            slave_scaling_mode: 0,
            master_offset: 0.0,
            slave_offset: 0.0,
            master_scaling: 1.0,
            slave_scaling: 1.0,
            out: CamOutputs::default(),
            core: CamCore::default(),
        }
    }
}

impl McCamScaling {
    /// One cycle for slave axis `slave`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, slave: u32) {
        let call = CamScalingCall {
            activation_mode: self.activation_mode,
            master_scaling_mode: self.master_scaling_mode,
            slave_scaling_mode: self.slave_scaling_mode,
            reserved: 0,
            activation_position: self.activation_position,
            master_offset: self.master_offset,
            slave_offset: self.slave_offset,
            master_scaling: self.master_scaling,
            slave_scaling: self.slave_scaling,
        };
        self.out = self.core.cycle(io, self.execute, slave, || call, None);
    }
}

/// MC_WriteMotionFunctionPoint: one point of the motion function `table` changed, under the
/// table's online-change mode (MC_SetCamOnlineChangeMode). Done when the CNC took it (checked
/// whole with the function it changes; queued when its activation is still to come).
#[derive(Debug, Default)]
pub struct McWriteMotionFunctionPoint {
    /// Input: a rising edge sends it.
    pub execute: bool,
    /// Input: the table ID.
    pub table: u32,
    /// Input: the point.
    pub point: hli::calls::McMotionFunctionPoint,
    /// Outputs of the last call.
    pub out: CamOutputs,
    core: CamCore<hli::calls::CamPointsWriteCall>,
}

impl McWriteMotionFunctionPoint {
    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let mut points = [hli::calls::McMotionFunctionPoint::default(); 4];
        points[0] = self.point;
        let call = hli::calls::CamPointsWriteCall {
            first: self.point.point_index,
            count: 1,
            flags: hli::calls::CAM_CHUNK_LAST,
            total: 1,
            points,
        };
        self.out = self.core.cycle(io, self.execute, self.table, || call, None);
    }
}

/// MC_SetCamOnlineChangeMode: when point changes of `table` apply, and whether the master
/// and slave offsets follow so that nothing jumps.
#[derive(Debug, Default)]
pub struct McSetCamOnlineChangeMode {
    /// Input: a rising edge sends it.
    pub execute: bool,
    /// Input: the table ID.
    pub table: u32,
    /// Input: raw `MC_CamActivationMode`.
    pub activation_mode: u32,
    /// Input: the activation position.
    pub activation_position: f64,
    /// Input: raw `MC_CamScalingMode` of the master.
    pub master_scaling_mode: u32,
    /// Input: raw `MC_CamScalingMode` of the slave.
    pub slave_scaling_mode: u32,
    /// Outputs of the last call.
    pub out: CamOutputs,
    core: CamCore<hli::calls::CamOnlineModeCall>,
}

impl McSetCamOnlineChangeMode {
    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let call = hli::calls::CamOnlineModeCall {
            activation_mode: self.activation_mode,
            master_scaling_mode: self.master_scaling_mode,
            slave_scaling_mode: self.slave_scaling_mode,
            reserved: 0,
            activation_position: self.activation_position,
        };
        self.out = self.core.cycle(io, self.execute, self.table, || call, None);
    }
}
