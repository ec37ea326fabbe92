//! All axes of the CNC bound to the HLI image: the cyclic tick and the handler of the PLC's
//! axis commands.

use super::axis::{Axis, Coupling};
use super::config::{AxisConfig, ConfigError, DriveLink};
use super::io_map::Block;
use super::sim_drive::{SimScaling, SimulatedDrive};
use crate::setpoint::Kinematic;
use core::mem::offset_of;
use hli::calls::axis::{AxisCommandCall, AxisCommandReply};
use hli::calls::probe::{ProbeAbortCall, ProbeArmCall, ProbeReply};
use hli::calls::{decode_body, reply, ErrorCode, HandlerResult};
use hli::enums::{AxisError, AxisState};
use hli::layout::{
    HliAxis, HliAxisCommandState, HliAxisDriveState, HliAxisLrState, NcDriveIn, NcDriveOut,
    NcEncoderIn, NcEncoderOut, HLI_MAX_AXES,
};
use hli::views::CncView;
use hli::wire::AcyclicRequest;
use hli::PlaceExt;

/// Why a set of axes cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AxisSetError {
    /// More axes than the image holds.
    #[error("{0} axes configured, the image holds at most {HLI_MAX_AXES}")]
    TooMany(usize),
    /// A value out of range.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// Two axes share a name or id.
    #[error("axis {0:?} is configured twice (name or id)")]
    Duplicate(String),
}

/// The right to drive a coupled axis: which axis, and which of its couplings. Coupling an axis
/// ([`AxisSet::couple`]) gives a new lease; driving, changing and releasing the coupling take
/// it and do nothing once it is stale (the axis faulted, or another engine coupled it since).
/// Every engine and the channels hold their axes this way: one ownership rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[must_use = "a coupling is driven and released through its lease"]
pub struct Lease {
    axis: usize,
    epoch: u32,
}

impl Lease {
    /// The axis index.
    pub fn axis(self) -> usize {
        self.axis
    }
}

/// The axes with their simulated drives.
#[derive(Debug)]
pub struct AxisSet {
    axes: Vec<Axis>,
    drives: Vec<Option<SimulatedDrive>>,
    /// What each simulated drive answered last, as written into the image: the axis reads
    /// these, never its own drive's answer back from the segment (where the PLC could have
    /// written over it). Unused for external drives, whose inputs come by the image.
    sim_inputs: Vec<(NcEncoderIn, NcDriveIn)>,
}

impl AxisSet {
    /// Builds the axes (validating every configuration) for a tick of `cycle_s` seconds.
    pub fn new(configs: Vec<AxisConfig>, cycle_s: f64) -> Result<Self, AxisSetError> {
        if configs.len() > HLI_MAX_AXES {
            return Err(AxisSetError::TooMany(configs.len()));
        }
        for (i, c) in configs.iter().enumerate() {
            c.validate()?;
            if configs[..i]
                .iter()
                .any(|o| o.name == c.name || o.id == c.id)
            {
                return Err(AxisSetError::Duplicate(c.name.clone()));
            }
        }
        let drives: Vec<Option<SimulatedDrive>> = configs
            .iter()
            .map(|c| match c.drive {
                DriveLink::Simulated(sim) => Some(SimulatedDrive::new(
                    sim,
                    SimScaling {
                        increments_per_unit: c.increments_per_unit,
                        velocity_increments_per_unit: c.velocity_increments_per_unit,
                        acceleration_increments_per_unit: c.acceleration_increments_per_unit,
                        width: c.encoder_width,
                        mode: c.drive_mode,
                        protocol: c.io.protocol,
                        probe: c.io.probe,
                        torque_increments_per_percent: c.io.torque_increments_per_percent,
                        rated_acceleration: c.dynamics.acceleration,
                    },
                    cycle_s,
                )),
                DriveLink::External => None,
            })
            .collect();
        let axes = configs.into_iter().map(|c| Axis::new(c, cycle_s)).collect();
        let sim_inputs = drives
            .iter()
            .map(|d| {
                let enc_in = d.as_ref().map(SimulatedDrive::encoder_in);
                (
                    enc_in.unwrap_or_else(bytemuck::Zeroable::zeroed),
                    bytemuck::Zeroable::zeroed(),
                )
            })
            .collect();
        Ok(Self {
            axes,
            drives,
            sim_inputs,
        })
    }

    /// Number of axes.
    pub fn len(&self) -> usize {
        self.axes.len()
    }
    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.axes.is_empty()
    }
    /// Axis `i`.
    pub fn axis(&self, i: usize) -> Option<&Axis> {
        self.axes.get(i)
    }
    /// What a slave follows of master axis `i`: its set-point, or with `actual` its encoder
    /// ([`Axis::actual_kinematic`]: an actual-value master, such as an encoder wheel).
    pub fn master(&self, i: usize, actual: bool) -> Option<Kinematic> {
        let a = self.axes.get(i)?;
        Some(match actual {
            true => a.actual_kinematic(),
            false => a.setpoint(),
        })
    }
    /// Axis `i`, mutable (for couplings and tests).
    pub fn axis_mut(&mut self, i: usize) -> Option<&mut Axis> {
        self.axes.get_mut(i)
    }
    /// Couples axis `i` to an engine (or a channel) that hands in its set-points with
    /// [`AxisSet::drive`]; refused when the axis may not move (see [`Axis::couple`]).
    pub fn couple(&mut self, i: usize, coupling: Coupling) -> Result<Lease, AxisError> {
        let axis = self.axes.get_mut(i).ok_or(AxisError::InvalidParameter)?;
        axis.couple(coupling)?;
        Ok(Lease {
            axis: i,
            epoch: axis.coupling_epoch(),
        })
    }

    /// The axis of `lease` while the lease holds.
    fn leased(&mut self, lease: Lease) -> Option<&mut Axis> {
        self.axes
            .get_mut(lease.axis)
            .filter(|a| a.coupling().is_some() && a.coupling_epoch() == lease.epoch)
    }

    /// Whether `lease` still holds its axis.
    pub fn holds(&self, lease: Lease) -> bool {
        self.axes
            .get(lease.axis)
            .is_some_and(|a| a.coupling().is_some() && a.coupling_epoch() == lease.epoch)
    }

    /// This tick's set-point of a leased axis; `false` (nothing done) once the lease is stale.
    pub fn drive(&mut self, lease: Lease, setpoint: Kinematic, phase: AxisState) -> bool {
        self.leased(lease)
            .map(|a| a.drive_coupled(setpoint, phase))
            .is_some()
    }

    /// Changes what a leased axis is coupled to, in place (see [`Axis::recouple`]).
    pub fn recouple(&mut self, lease: Lease, coupling: Coupling) -> bool {
        self.leased(lease).is_some_and(|a| a.recouple(coupling))
    }

    /// A coupling command of the leased axis's engine in its command book (see
    /// `AxisCommandKind::GearIn`): the id a PLC block follows; `None` once the lease is stale.
    pub fn begin_coupled(
        &mut self,
        lease: Lease,
        kind: hli::enums::AxisCommandKind,
    ) -> Option<u32> {
        self.leased(lease).map(|a| a.begin_coupled(kind))
    }

    /// Status bits the engine holding `lease` reports for its axis (shown in `status_r`
    /// while it holds it); `false` once the lease is stale.
    pub fn set_coupled_status(&mut self, lease: Lease, bits: u32) -> bool {
        self.leased(lease)
            .map(|a| a.set_coupled_status(bits))
            .is_some()
    }

    /// Ends the coupling of `lease` (see [`Axis::decouple`]); `false` when the lease was
    /// already stale (the axis is someone else's, or free).
    pub fn release(&mut self, lease: Lease) -> bool {
        self.leased(lease).map(Axis::decouple).is_some()
    }

    /// The simulated drive of axis `i`, if it has one.
    pub fn drive_mut(&mut self, i: usize) -> Option<&mut SimulatedDrive> {
        self.drives.get_mut(i).and_then(Option::as_mut)
    }
    /// Index of the axis named `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.axes.iter().position(|a| a.config().name == name)
    }

    /// Writes the simulated encoders' first readings into the image (before the first tick),
    /// and every axis's NC axis ID, so a PLC finds an axis by ID from its first cycle.
    pub fn prime(&self, view: &CncView<'_>) {
        for (i, axis) in self.axes.iter().enumerate() {
            if let Ok(place) = view.axis(i) {
                place
                    .field::<HliAxisLrState>(offset_of!(HliAxis, lr_state))
                    .write(&HliAxisLrState {
                        nc_axis_id_r: axis.config().id,
                        ..bytemuck::Zeroable::zeroed()
                    });
            }
        }
        for (i, drive) in self.drives.iter().enumerate() {
            if let (Some(drive), Ok(place)) = (drive, view.axis(i)) {
                place
                    .field::<NcEncoderIn>(offset_of!(HliAxis, enc_in))
                    .write(&drive.encoder_in());
                place
                    .field::<NcDriveIn>(offset_of!(HliAxis, drive_in))
                    .write(&bytemuck::Zeroable::zeroed());
            }
        }
    }

    /// One tick of every axis: [`AxisSet::sense`] then [`AxisSet::act`].
    pub fn tick(&mut self, view: &CncView<'_>) {
        self.sense(view);
        self.act(view);
    }

    /// First half of the axis stage: every axis reads its inputs (an external drive's from
    /// the image, a simulated drive's as it answered) and free axes run their generators, so
    /// engines see this tick's set-points of their masters. A slave whose master axis is in
    /// error is let go and brakes ([`AxisSet::release_orphans`]).
    pub fn sense(&mut self, view: &CncView<'_>) {
        for (i, axis) in self.axes.iter_mut().enumerate() {
            let Ok(place) = view.axis(i) else { continue };
            let (enc_in, drive_in) = match self.drives[i] {
                Some(_) => self.sim_inputs[i],
                None => {
                    let mut enc_in = place
                        .field::<NcEncoderIn>(offset_of!(HliAxis, enc_in))
                        .read();
                    let mut drive_in = place
                        .field::<NcDriveIn>(offset_of!(HliAxis, drive_in))
                        .read();
                    let map = &axis.config().io.map;
                    map.decode(Block::EncIn, &mut enc_in);
                    map.decode(Block::DriveIn, &mut drive_in);
                    (enc_in, drive_in)
                }
            };
            axis.sense(&enc_in, &drive_in);
        }
        self.release_orphans();
    }

    /// A slave coupled to a master axis that is in error (its set-point stands at once)
    /// would stop with it, without braking: it is let go with the motion it had and brakes
    /// with its own deceleration and jerk (MC_Halt: not locked, so once the master is
    /// repaired the PLC can couple or move it again). The engine that held it sees its lease
    /// gone.
    fn release_orphans(&mut self) {
        for i in 0..self.axes.len() {
            let Some(master) = self.axes[i]
                .coupling()
                .and_then(|c| usize::try_from(c.master).ok())
            else {
                continue;
            };
            if master == i || self.axes.get(master).is_none_or(|m| m.error().is_none()) {
                continue;
            }
            let axis = &mut self.axes[i];
            axis.decouple();
            let d = axis.config().dynamics;
            // Refused only by an axis that may not move: it stands already.
            let _ = axis.command(&hli::calls::axis::AxisCommandCall::halt(
                d.deceleration,
                d.jerk,
            ));
        }
    }

    /// Second half: every axis monitors, controls and writes its block; simulated drives
    /// take the outputs and answer with the next inputs.
    pub fn act(&mut self, view: &CncView<'_>) {
        for (i, (axis, drive)) in self.axes.iter_mut().zip(self.drives.iter_mut()).enumerate() {
            let Ok(place) = view.axis(i) else { continue };
            let out = axis.act();
            place
                .field::<HliAxisLrState>(offset_of!(HliAxis, lr_state))
                .write(&out.lr_state);
            // An external drive's mapped blocks go out in the hardware's bytes.
            let (mut drive_out, mut enc_out) = (out.drive_out, out.enc_out);
            let map = &axis.config().io.map;
            map.encode(Block::DriveOut, &mut drive_out);
            map.encode(Block::EncOut, &mut enc_out);
            place
                .field::<NcDriveOut>(offset_of!(HliAxis, drive_out))
                .write(&drive_out);
            place
                .field::<NcEncoderOut>(offset_of!(HliAxis, enc_out))
                .write(&enc_out);
            place
                .field::<HliAxisCommandState>(offset_of!(HliAxis, command_state))
                .write(&out.command_state);
            place
                .field::<HliAxisDriveState>(offset_of!(HliAxis, drive_state))
                .write(&out.drive_state);
            if let Some(drive) = drive {
                let drive_in = drive.step(&out.drive_out, &out.enc_out);
                let enc_in = drive.encoder_in();
                self.sim_inputs[i] = (enc_in, drive_in);
                place
                    .field::<NcDriveIn>(offset_of!(HliAxis, drive_in))
                    .write(&drive_in);
                place
                    .field::<NcEncoderIn>(offset_of!(HliAxis, enc_in))
                    .write(&enc_in);
            }
        }
    }

    /// Answers an [`AxisCommandCall`] addressed to axis `request.target`.
    pub fn handle_command(&mut self, request: &AcyclicRequest) -> HandlerResult {
        let call: AxisCommandCall = decode_body(request)?;
        let axis = self
            .axes
            .get_mut(request.target as usize)
            .ok_or(ErrorCode::InvalidTarget)?;
        let answer = match axis.command(&call) {
            Ok(command_id) => AxisCommandReply {
                command_id,
                error_id: 0,
            },
            Err(e) => AxisCommandReply {
                command_id: 0,
                error_id: e.raw(),
            },
        };
        reply(&answer)
    }

    /// Answers a [`ProbeArmCall`] (`arm`) or a [`ProbeAbortCall`] addressed to axis
    /// `request.target`. Any axis may probe, a channel's too: probing moves nothing.
    pub fn handle_probe(&mut self, request: &AcyclicRequest, arm: bool) -> HandlerResult {
        let axis = self
            .axes
            .get_mut(request.target as usize)
            .ok_or(ErrorCode::InvalidTarget)?;
        let outcome = if arm {
            axis.arm_probe(&decode_body::<ProbeArmCall>(request)?)
        } else {
            axis.abort_probe(&decode_body::<ProbeAbortCall>(request)?)
        };
        reply(&match outcome {
            Ok(arm_id) => ProbeReply {
                arm_id,
                error_id: 0,
            },
            Err(e) => ProbeReply {
                arm_id: 0,
                error_id: e.raw(),
            },
        })
    }
}
