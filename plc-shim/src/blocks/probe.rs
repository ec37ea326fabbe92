//! The touch-probe blocks: MC_TouchProbe arms a probe of an axis on its Execute edge and
//! reports the recorded position; MC_AbortTrigger disarms it. The arming is followed in the
//! axis image (`gpAx[i]^drive_state.probe_r[k]`) under the arm id the CNC's reply carries, so
//! a later arming (by another block) shows as CommandAborted here. A timeline calls both
//! ([`TIMELINE`]); its report shows the position MC_TouchProbe recorded last.

use super::plain;
use crate::kernel::{no_follow, send, Accept, Kernel, Outputs, Step};
use crate::runtime::PlcIo;
use crate::timeline::registry::{input, BlockSpec, InputSpec, Kind, TimelineBlock, Value};
use hli::calls::probe::{ProbeAbortCall, ProbeArmCall};
use hli::enums::{ProbeEdge, ProbeState};
use hli::layout::{HliAxis, HliAxisDriveState, HliAxisProbe};
use hli::PlaceExt;
use hli_transport::rpc::PendingCall;

fn failed(code: u32) -> Outputs<f64> {
    Outputs::failed(code)
}

/// The probe's block in the image, if the axis exists.
fn probe_image(io: &PlcIo<'_>, axis: u32, probe: u32) -> Option<HliAxisProbe> {
    let state: HliAxisDriveState = io
        .view
        .axis(axis as usize)
        .ok()?
        .field::<HliAxisDriveState>(core::mem::offset_of!(HliAxis, drive_state))
        .read();
    state.probe_r.get(probe.checked_sub(1)? as usize).copied()
}

/// An arming with id `id` as the probe's image shows it; Done carries the recorded position
/// as the outputs' extra.
fn follow_arming(image: Option<HliAxisProbe>, id: u32) -> Step<f64> {
    let out = match image {
        Some(p) if p.arm_id_r != id => Outputs::aborted(),
        Some(p) => match ProbeState::decode(p.state_r) {
            Ok(ProbeState::Armed) => return Step::Running(Outputs::busy()),
            Ok(ProbeState::Recorded) => Outputs::done(p.recorded_position_r),
            Ok(ProbeState::Aborted) if p.error_id_r != 0 => failed(p.error_id_r),
            Ok(ProbeState::Aborted) | Ok(ProbeState::Idle) => Outputs::aborted(),
            Err(_) => failed(hli::calls::ErrorCode::InvalidData.raw()),
        },
        None => failed(hli::calls::ErrorCode::InvalidTarget.raw()),
    };
    Step::Ended(out)
}

/// MC_TouchProbe: on a rising Execute edge arms `probe` (1 or 2) of the axis for `edge`;
/// with `window_only` only an edge between `first_position` and `last_position` records.
/// Outputs hold while Execute stays TRUE and show for one cycle after it fell.
#[derive(Debug)]
pub struct McTouchProbe {
    /// Input: a rising edge arms the probe.
    pub execute: bool,
    /// Input: probe number, 1 or 2.
    pub probe: u32,
    /// Input: the edge that records.
    pub edge: ProbeEdge,
    /// Input: only edges inside the window record.
    pub window_only: bool,
    /// Input: start of the window.
    pub first_position: f64,
    /// Input: end of the window.
    pub last_position: f64,
    /// Outputs of the last call; the extra is the recorded position (axis units).
    pub out: Outputs<f64>,
    kernel: Kernel<PendingCall<ProbeArmCall>, u32, f64>,
}

impl Default for McTouchProbe {
    fn default() -> Self {
        Self {
            execute: false,
            probe: 1,
            edge: ProbeEdge::Positive,
            window_only: false,
            first_position: 0.0,
            last_position: 0.0,
            out: Outputs::default(),
            kernel: Kernel::default(),
        }
    }
}

impl McTouchProbe {
    /// One cycle for `axis`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, axis: u32) {
        let call = ProbeArmCall {
            probe: self.probe,
            edge: self.edge.raw(),
            window_only: u32::from(self.window_only),
            reserved: 0,
            first_position: self.first_position,
            last_position: self.last_position,
        };
        let probe = self.probe;
        self.out = self.kernel.cycle(
            io,
            self.execute,
            |io| send(io, axis, &call),
            |reply| match reply.error_id {
                0 => Accept::Follow(reply.arm_id, Outputs::busy()),
                code => Accept::Failed(code, 0.0),
            },
            |id, io, _| follow_arming(probe_image(io, axis, probe), *id),
        );
    }
}

/// MC_AbortTrigger: on a rising Execute edge disarms `probe` of the axis.
#[derive(Debug)]
pub struct McAbortTrigger {
    /// Input: a rising edge disarms.
    pub execute: bool,
    /// Input: probe number, 1 or 2.
    pub probe: u32,
    /// Outputs of the last call.
    pub out: Outputs<f64>,
    kernel: Kernel<PendingCall<ProbeAbortCall>, (), f64>,
}

impl Default for McAbortTrigger {
    fn default() -> Self {
        Self {
            execute: false,
            probe: 1,
            out: Outputs::default(),
            kernel: Kernel::default(),
        }
    }
}

impl McAbortTrigger {
    /// One cycle for `axis`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, axis: u32) {
        let call = ProbeAbortCall {
            probe: self.probe,
            reserved: 0,
        };
        self.out = self.kernel.cycle(
            io,
            self.execute,
            |io| send(io, axis, &call),
            |reply| match reply.error_id {
                0 => Accept::Done(0.0),
                code => Accept::Failed(code, 0.0),
            },
            no_follow,
        );
    }
}

/// MC_TouchProbe in a timeline: the position it recorded last, for the report.
#[derive(Debug, Default)]
struct TouchProbeInstance {
    block: McTouchProbe,
    recorded: Option<f64>,
}

impl TimelineBlock for TouchProbeInstance {
    fn set(&mut self, key: &str, value: &Value) {
        let b = &mut self.block;
        match (key, value) {
            ("probe", Value::Int(v)) => b.probe = *v as u32,
            ("edge", Value::Int(v)) => b.edge = ProbeEdge::decode(*v as u32).unwrap_or(b.edge),
            ("window_only", Value::Bool(v)) => b.window_only = *v,
            ("first_position", Value::Real(v)) => b.first_position = *v,
            ("last_position", Value::Real(v)) => b.last_position = *v,
            _ => {}
        }
    }
    fn execute(&mut self) -> Option<&mut bool> {
        Some(&mut self.block.execute)
    }
    fn cycle(&mut self, io: &mut PlcIo<'_>, axis: u32) -> (Outputs, bool) {
        self.block.call(io, axis);
        if self.block.out.done {
            self.recorded = Some(self.block.out.extra);
        }
        plain(self.block.out)
    }
    fn read(&self) -> Option<Vec<f64>> {
        self.recorded.map(|p| vec![p])
    }
    /// `RecordedPosition` in Structured Text (PLCopen's MC_TouchProbe).
    fn results(&self) -> Option<&'static crate::timeline::registry::Results> {
        Some(&RECORDED)
    }
    fn result_values(&self, out: &mut [f64]) -> usize {
        match (self.recorded, out.first_mut()) {
            (Some(p), Some(slot)) => {
                *slot = p;
                1
            }
            _ => 0,
        }
    }
}

/// MC_TouchProbe's `RecordedPosition`.
const RECORDED: crate::timeline::registry::Results = crate::timeline::registry::Results {
    outputs: &[("RecordedPosition", "LREAL")],
    declaration: "",
    type_name: "",
};

impl TimelineBlock for McAbortTrigger {
    fn set(&mut self, key: &str, value: &Value) {
        if let ("probe", Value::Int(v)) = (key, value) {
            self.probe = *v as u32;
        }
    }
    execute_cycle!(with_axis, plain);
}

/// Probe 1 or 2 of the axis.
const PROBE: InputSpec = input("probe", Kind::Range(1, 2));

/// The touch-probe blocks a timeline calls.
pub const TIMELINE: &[BlockSpec] = &[
    BlockSpec::on_axis(
        "MC_TouchProbe",
        &[
            PROBE,
            input(
                "edge",
                Kind::OneOf(&[("\"positive\"", 1), ("\"negative\"", 2)]),
            ),
            input("window_only", Kind::Bool),
            input("first_position", Kind::Real),
            input("last_position", Kind::Real),
        ],
        |_| Box::<TouchProbeInstance>::default(),
    ),
    BlockSpec::on_axis("MC_AbortTrigger", &[PROBE], |_| {
        Box::<McAbortTrigger>::default()
    }),
];
