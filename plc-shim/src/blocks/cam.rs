//! The cam blocks of chapter 5.1 for the PLC program that send one call: MC_CamIn,
//! MC_CamInExt, MC_CamOut, MC_CamScaling, MC_WriteMotionFunctionPoint and
//! MC_SetCamOnlineChangeMode. Like the motion blocks, each sends its call on the rising
//! Execute edge without waiting and stays Busy until the CNC answers. MC_CamIn and
//! MC_CamInExt then follow the slave's axis image: InSync once the slave is coupled through a
//! cam and synchronous (`coupling_state_r` 1, `nAxisState` 13), CommandAborted when the
//! coupling goes away, Error with the axis's error when the slave faults. The others are Done
//! when the CNC has taken the command (a scaling with a positional activation mode is then
//! queued in the CNC). The table data and the selection are in [`super::cam_data`], the reads
//! in [`super::cam_read`], the multi-table blocks in [`super::cam_multi`].

use crate::kernel::{done_unless, send, Accept, Kernel, Outputs, Step};
use crate::runtime::PlcIo;
use crate::timeline::registry::{
    input, joined, mode, BlockSpec, InputSpec, Kind, TimelineBlock, Value,
};
use hli::calls::cam::{
    CamActivationMode, CamInCall, CamInterpolation, CamOutCall, CamReadCall, CamReadKind, CamReply,
    CamScalingCall, CamScalingMode, CamStartMode,
};
use hli::calls::AcyclicCall;
use hli::enums::{AxisState, CouplingState};
use hli_transport::rpc::PendingCall;

/// Version of this block library (seed 000 5.3, Get_TcNcCamming_Version): at most the
/// STRING(20) the seed's function returns.
pub fn camming_library_version() -> &'static str {
    concat!("cncplc-cam ", env!("CARGO_PKG_VERSION"))
}

/// The block kernel as the cam blocks use it: a coupling (MC_CamIn) follows the slave's
/// image, remembering whether it has seen the coupling there; the others are Done when the
/// CNC took the call.
pub struct CamCore<C: AcyclicCall> {
    kernel: Kernel<PendingCall<C>, bool>,
}

impl<C: AcyclicCall> Default for CamCore<C> {
    fn default() -> Self {
        Self {
            kernel: Kernel::default(),
        }
    }
}

impl<C: AcyclicCall> core::fmt::Debug for CamCore<C> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        self.kernel.fmt(f)
    }
}

pub(crate) fn failed(code: u32) -> Outputs {
    Outputs::failed(code)
}

/// A cam coupling of `slave` as its image shows it; `seen` once the coupling showed there.
fn follow_coupling(io: &PlcIo<'_>, slave: u32, seen: &mut bool) -> Step<()> {
    let state = io.view.axis_state(slave as usize).ok();
    let cam = state.is_some_and(|s| s.coupling_state_r == CouplingState::Cam.raw());
    let synchronous =
        state.is_some_and(|s| s.axis_state_r == AxisState::SlaveSynchronous.raw() && cam);
    let error = state.map_or(0, |s| s.error_id_r);
    if error != 0 {
        Step::Ended(failed(error))
    } else if cam {
        *seen = true;
        Step::Running(Outputs {
            in_sync: synchronous,
            busy: !synchronous,
            ..Outputs::default()
        })
    } else if *seen {
        Step::Ended(Outputs::aborted())
    } else {
        // Accepted between two ticks: the image shows it from the next tick on.
        Step::Running(Outputs::busy())
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
    ) -> Outputs {
        self.kernel.cycle(
            io,
            execute,
            |io| send(io, target, &call()),
            |reply| match (reply.error_id, couples) {
                (0, Some(_)) => Accept::Follow(false, Outputs::busy()),
                (code, _) => done_unless(code),
            },
            |seen, io, _| match couples {
                Some(slave) => follow_coupling(io, slave, seen),
                None => Step::Ended(Outputs::done(())),
            },
        )
    }

    timeout_input!(kernel);
}

/// MC_CamScaling's inputs as the coupling blocks keep them before a program sets them: at
/// once (activation mode 0), each side's scaling as given (mode 0), no offsets, scalings 1.
/// MC_CamIn(Ext) and MC_SetCamOnlineChangeMode keep theirs among these.
fn unscaled() -> CamScalingCall {
    CamScalingCall {
        master_scaling: 1.0,
        slave_scaling: 1.0,
        ..CamScalingCall::default()
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
    /// Input: raw `MC_StartMode` (1 absolute .. 4); 0, the default, as MC_CamTableSelect
    /// chose (its MasterAbsolute/SlaveAbsolute; absolute for a table never selected).
    pub start_mode: u32,
    /// Inputs: the activation and each side's scaling mode (Ext), the offsets and the
    /// scalings, as MC_CamScaling takes them (`reserved` is not sent).
    pub scaling: CamScalingCall,
    /// Input: raw `MC_InterpolationType` (tables).
    pub interpolation: u32,
    /// MC_CamInExt rather than MC_CamIn.
    pub extended: bool,
    /// Input: follow the master's actual position (else its set-point).
    pub master_actual: bool,
    /// Outputs of the last call.
    pub out: Outputs,
    core: CamCore<CamInCall>,
}

impl Default for McCamIn {
    fn default() -> Self {
        Self {
            execute: false,
            master: 0,
            table: 0,
            start_mode: hli::calls::cam::CAM_START_AS_SELECTED,
            scaling: unscaled(),
            interpolation: 0,
            extended: false,
            master_actual: false,
            out: Outputs::default(),
            core: CamCore::default(),
        }
    }
}

impl McCamIn {
    timeout_input!(core);

    /// One cycle for slave axis `slave`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, slave: u32) {
        let s = self.scaling;
        let call = CamInCall {
            master: self.master,
            table_id: self.table,
            start_mode: self.start_mode,
            activation_mode: s.activation_mode,
            master_scaling_mode: s.master_scaling_mode,
            slave_scaling_mode: s.slave_scaling_mode,
            interpolation: self.interpolation,
            extended: u32::from(self.extended),
            activation_position: s.activation_position,
            master_offset: s.master_offset,
            slave_offset: s.slave_offset,
            master_scaling: s.master_scaling,
            slave_scaling: s.slave_scaling,
            master_source: u32::from(self.master_actual),
            reserved: 0,
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
    pub out: Outputs,
    core: CamCore<CamOutCall>,
}

impl McCamOut {
    timeout_input!(core);

    /// One cycle for slave axis `slave`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, slave: u32) {
        self.out = self
            .core
            .cycle(io, self.execute, slave, CamOutCall::default, None);
    }
}

/// MC_CamScaling: new offsets and scalings of a coupling, now or at an activation. Done when
/// the scaling has been carried out (seed 000 5.1.6), Busy while it waits for its
/// activation: once the CNC took it, the block asks each cycle whether the coupling still
/// has a scaling queued (a `CamRead` of kind `Queued`).
#[derive(Debug)]
pub struct McCamScaling {
    /// Input: a rising edge sends it.
    pub execute: bool,
    /// Inputs: the activation, each side's scaling mode, the offsets and the scalings
    /// (`reserved` is sent 0).
    pub scaling: CamScalingCall,
    /// Outputs of the last call.
    pub out: Outputs,
    kernel: Kernel<PendingCall<CamScalingCall>, Asked>,
}

impl Default for McCamScaling {
    fn default() -> Self {
        Self {
            execute: false,
            scaling: unscaled(),
            out: Outputs::default(),
            kernel: Kernel::default(),
        }
    }
}

/// A `Queued` read of slave `slave`'s coupling on its way, and the cycle it was sent in.
type Asked = Option<(PendingCall<CamReadCall>, u64)>;

/// Sends the `Queued` read of slave `slave`'s coupling.
fn ask_queued(io: &mut PlcIo<'_>, slave: u32, asked: &mut Asked) -> Step<()> {
    let read = CamReadCall {
        what: CamReadKind::Queued.raw(),
        ..CamReadCall::default()
    };
    match send(io, slave, &read) {
        Ok(p) => {
            *asked = Some((p, io.cycle));
            Step::Running(Outputs::busy())
        }
        Err(code) => Step::Ended(failed(code)),
    }
}

/// Whether slave `slave`'s scaling has been carried out: a `Queued` read each cycle (the next
/// one sent as soon as the last says a scaling still waits), Done once none waits. A read not
/// answered within the block's timeout ends it with [`crate::kernel::ERROR_NO_ANSWER`].
fn scaling_carried_out(
    io: &mut PlcIo<'_>,
    slave: u32,
    asked: &mut Asked,
    timeout: u64,
) -> Step<()> {
    let Some((pending, sent)) = asked.as_ref() else {
        return ask_queued(io, slave, asked);
    };
    match pending.poll() {
        None if io.cycle.saturating_sub(*sent) > timeout => {
            Step::Ended(failed(crate::kernel::ERROR_NO_ANSWER))
        }
        None => Step::Running(Outputs::busy()),
        Some(Ok(reply)) if reply.error_id != 0 => Step::Ended(failed(reply.error_id)),
        Some(Ok(reply)) if reply.values[0] != 0.0 => ask_queued(io, slave, asked),
        Some(Ok(_)) => Step::Ended(Outputs::done(())),
        Some(Err(e)) => Step::Ended(failed(crate::kernel::call_error_code(&e))),
    }
}

/// The seed's `AxisCamDataQueued`: whether cam slave `axis` has data written to its table
/// that is not active yet (an online change waiting for its activation), from the bit in its
/// axis image (`status_r`, `axis_status::CAM_DATA_QUEUED`).
pub fn axis_cam_data_queued(view: &hli::views::PlcView<'_>, axis: usize) -> bool {
    view.axis_state(axis)
        .is_ok_and(|s| s.status_r & hli::enums::axis_status::CAM_DATA_QUEUED != 0)
}

impl McCamScaling {
    /// One cycle for slave axis `slave`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, slave: u32) {
        let call = CamScalingCall {
            reserved: 0,
            ..self.scaling
        };
        // ActivationMode OFF: no scaling is carried out (seed 000 5.1.16.13), so there is
        // nothing to wait for: Done once the CNC took the call, whatever else is queued.
        let off = call.activation_mode == CamActivationMode::Off.raw();
        self.out = self.kernel.cycle(
            io,
            self.execute,
            |io| send(io, slave, &call),
            |reply| match reply.error_id {
                0 if off => Accept::Done(()),
                0 => Accept::Follow(None, Outputs::busy()),
                code => Accept::Failed(code, ()),
            },
            |asked, io, waited| scaling_carried_out(io, slave, asked, waited.timeout),
        );
    }

    timeout_input!(kernel);
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
    pub point: hli::calls::cam::McMotionFunctionPoint,
    /// Outputs of the last call.
    pub out: Outputs,
    core: CamCore<hli::calls::cam::CamPointsWriteCall>,
}

impl McWriteMotionFunctionPoint {
    timeout_input!(core);

    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let mut points = [hli::calls::cam::McMotionFunctionPoint::default(); 4];
        points[0] = self.point;
        let call = hli::calls::cam::CamPointsWriteCall {
            first: self.point.point_index,
            count: 1,
            flags: hli::calls::cam::CAM_CHUNK_FIRST | hli::calls::cam::CAM_CHUNK_LAST,
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
    /// Inputs: the activation and each side's scaling mode, as MC_CamScaling takes them (its
    /// offsets and scalings are not used).
    pub scaling: CamScalingCall,
    /// Outputs of the last call.
    pub out: Outputs,
    core: CamCore<hli::calls::cam::CamOnlineModeCall>,
}

impl McSetCamOnlineChangeMode {
    timeout_input!(core);

    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let s = self.scaling;
        let call = hli::calls::cam::CamOnlineModeCall {
            activation_mode: s.activation_mode,
            master_scaling_mode: s.master_scaling_mode,
            slave_scaling_mode: s.slave_scaling_mode,
            reserved: 0,
            activation_position: s.activation_position,
        };
        self.out = self.core.cycle(io, self.execute, self.table, || call, None);
    }
}

/// What a timeline records of a cam block's outputs: Done, Busy, CommandAborted, Error (no
/// Active, InVelocity, InSync or StartSync).
pub(crate) fn recorded(out: Outputs) -> (Outputs, bool) {
    let out = Outputs {
        active: false,
        in_velocity: false,
        in_sync: false,
        start_sync: false,
        ..out
    };
    (out, false)
}

impl TimelineBlock for McCamIn {
    timeline_timeout!();
    fn set_master(&mut self, index: u32) -> bool {
        self.master = index;
        true
    }
    fn set(&mut self, key: &str, value: &Value) {
        match (key, value.uint()) {
            ("master_source", Some(v)) => self.master_actual = v != 0,
            ("master", Some(v)) => self.master = v,
            ("table", Some(v)) => self.table = v,
            ("start_mode", Some(v)) => self.start_mode = v,
            ("interpolation", Some(v)) => self.interpolation = v,
            _ => set_scaling(&mut self.scaling, key, value),
        }
    }
    fn execute(&mut self) -> Option<&mut bool> {
        Some(&mut self.execute)
    }
    fn cycle(&mut self, io: &mut PlcIo<'_>, axis: u32) -> (Outputs, bool) {
        self.call(io, axis);
        let (out, status) = recorded(self.out);
        // InSync, the one output a coupling adds.
        let in_sync = self.out.in_sync;
        (Outputs { in_sync, ..out }, status)
    }
}

impl TimelineBlock for McCamOut {
    timeline_timeout!();
    fn set(&mut self, _: &str, _: &Value) {}
    execute_cycle!(with_axis, recorded);
}

impl TimelineBlock for McCamScaling {
    timeline_timeout!();
    fn set(&mut self, key: &str, value: &Value) {
        set_scaling(&mut self.scaling, key, value);
    }
    execute_cycle!(with_axis, recorded);
}

impl TimelineBlock for McWriteMotionFunctionPoint {
    timeline_timeout!();
    fn set(&mut self, key: &str, value: &Value) {
        set_point(self, key, value);
    }
    execute_cycle!(no_axis, recorded);
}

impl TimelineBlock for McSetCamOnlineChangeMode {
    timeline_timeout!();
    fn set(&mut self, key: &str, value: &Value) {
        match (key, value.uint()) {
            ("table", Some(v)) => self.table = v,
            _ => set_scaling(&mut self.scaling, key, value),
        }
    }
    execute_cycle!(no_axis, recorded);
}

inputs! {
    /// MC_CamScaling's inputs, in its order. MC_CamInExt takes them all, MC_CamIn the offsets
    /// and scalings ([`SCALES`]), MC_SetCamOnlineChangeMode the activation and the scaling
    /// modes ([`ACTIVATION`]).
    SCALING, set_scaling: CamScalingCall {
        "activation_mode": mode::<CamActivationMode>() => activation_mode,
        "activation_position": Kind::Real => activation_position,
        "master_scaling_mode": mode::<CamScalingMode>() => master_scaling_mode,
        "slave_scaling_mode": mode::<CamScalingMode>() => slave_scaling_mode,
        "master_offset": Kind::Real => master_offset,
        "slave_offset": Kind::Real => slave_offset,
        "master_scaling": Kind::Real => master_scaling,
        "slave_scaling": Kind::Real => slave_scaling,
    }
}

/// The activation and each side's scaling mode, of [`SCALING`].
const ACTIVATION: &[InputSpec] = SCALING.split_at(4).0;
/// The offsets and the scalings, of [`SCALING`].
const SCALES: &[InputSpec] = SCALING.split_at(4).1;

inputs! {
    /// MC_WriteMotionFunctionPoint's inputs: the table and the point.
    POINT, set_point: McWriteMotionFunctionPoint {
        "table": Kind::Count => table,
        "point_index": Kind::Count => point.point_index,
        "function_type": Kind::Count => point.function_type,
        "point_type": Kind::Count => point.point_type,
        "rel_index_next": Kind::Count => point.rel_index_next_point,
        "master_pos": Kind::Real => point.master_pos,
        "slave_pos": Kind::Real => point.slave_pos,
        "slave_velo": Kind::Real => point.slave_velo,
        "slave_acc": Kind::Real => point.slave_acc,
        "slave_jerk": Kind::Real => point.slave_jerk,
    }
}

/// The master's set-point (the default) or its actual position.
pub(crate) const MASTER_SOURCE: InputSpec = input(
    "master_source",
    Kind::OneOf(&[("\"set_point\"", 0), ("\"actual\"", 1)]),
);
const TABLE: InputSpec = input("table", Kind::Count);
/// What MC_CamIn and MC_CamInExt take before the scaling's inputs; the interpolation comes
/// after them.
const CAM_IN_FIRST: [InputSpec; 4] = [
    MASTER_SOURCE,
    input("master", Kind::Count),
    TABLE,
    input("start_mode", mode::<CamStartMode>()),
];
const INTERPOLATION: InputSpec = input("interpolation", mode::<CamInterpolation>());

const CAM_IN: [InputSpec; 9] = joined(&[&CAM_IN_FIRST, SCALES, &[INTERPOLATION]]);
const CAM_IN_EXT: [InputSpec; 13] = joined(&[&CAM_IN_FIRST, &SCALING, &[INTERPOLATION]]);
const ONLINE_CHANGE_MODE: [InputSpec; 5] = joined(&[&[TABLE], ACTIVATION]);

/// The one-call cam blocks a timeline calls; the slave is the instance's axis.
pub const TIMELINE: &[BlockSpec] = &[
    BlockSpec::on_axis("MC_CamIn", &CAM_IN, |_| Box::<McCamIn>::default()),
    BlockSpec::on_axis("MC_CamInExt", &CAM_IN_EXT, |_| {
        Box::new(McCamIn {
            extended: true,
            ..McCamIn::default()
        })
    }),
    BlockSpec::on_axis("MC_CamOut", &[], |_| Box::<McCamOut>::default()),
    BlockSpec::on_axis("MC_CamScaling", &SCALING, |_| {
        Box::<McCamScaling>::default()
    }),
    BlockSpec::on_axis("MC_WriteMotionFunctionPoint", &POINT, |_| {
        Box::<McWriteMotionFunctionPoint>::default()
    }),
    BlockSpec::on_axis("MC_SetCamOnlineChangeMode", &ONLINE_CHANGE_MODE, |_| {
        Box::<McSetCamOnlineChangeMode>::default()
    }),
];

#[cfg(test)]
mod tests {
    #[test]
    fn the_library_names_its_version_within_the_seeds_string_20() {
        let v = super::camming_library_version();
        assert_eq!(v, concat!("cncplc-cam ", env!("CARGO_PKG_VERSION")));
        assert!(v.len() <= 20, "{v}");
        assert!(crate::blocks::fifo::fifo_library_version().len() <= 20);
    }
}
