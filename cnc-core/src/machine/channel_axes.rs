//! A channel's axes on the axis layer: each channel axis is an `Axis` coupled to its channel
//! (coupling kind `Channel`), fed the channel's set-point every tick with the path's velocity
//! and acceleration where the channel knows them (no transformation, no dynamic CS on the
//! set-points), else with differences, so it has a drive (ideal or simulated), a following
//! error and an actual position like every other axis.

use crate::axis::config::{AxisConfig, DriveLink, Dynamics};
use crate::axis::sim_drive::DriveModel;
use crate::axis::{motion_phase, AxisSet, Coupling, Lease};
use crate::channel::config::ChannelConfig;
use crate::setpoint::AxisValues;
use crate::setpoint::Kinematic;
use hli::calls::axis::AxisCommandCall;
use hli::enums::{AxisState, CouplingState};

/// The link from one channel to its axes `first..first + count` of the axis set, in the
/// channel's configuration order; the channel's values are per slot of its layout
/// ([`crate::nc::decode::AxisLayout`]).
#[derive(Debug, Clone)]
pub struct ChannelAxes {
    first: usize,
    count: usize,
    /// Per axis: the channel's slot that feeds it.
    slots: Vec<usize>,
    last: AxisValues,
    last_velocity: AxisValues,
    cycle_s: f64,
    /// The channel's couplings of its axes (sized when built).
    leases: Vec<Option<Lease>>,
}

/// The axis configuration of channel axis `i` of `channel`: named `CHANNEL.AXIS`, standing at
/// the channel's start position, no software limits of its own (the channel has them), the
/// channel's dynamics for a stop after decoupling, and the channel's drive (ideal when the
/// configuration names none).
pub fn axis_config(channel: &ChannelConfig, i: usize, id: u32) -> AxisConfig {
    let mut c = AxisConfig::linear(&format!("{}.{}", channel.name, channel.axes[i]), id);
    c.soft_limits = None;
    let l = channel.axis_limits(i);
    let usable = |v: f64| v.is_finite() && v > 0.0;
    if usable(l.velocity) && usable(l.acceleration) && usable(l.jerk) {
        c.dynamics = Dynamics {
            velocity: l.velocity,
            acceleration: l.acceleration,
            deceleration: l.acceleration,
            jerk: l.jerk,
        };
    }
    let start = channel.start.get(i).copied().unwrap_or(0.0);
    let model = channel
        .drive
        .unwrap_or(DriveModel::Ideal { dead_time_ticks: 0 });
    c.drive = match model.simulated(start) {
        Some(sim) => DriveLink::Simulated(sim),
        None => DriveLink::External,
    };
    c
}

impl ChannelAxes {
    /// Axes `first..first + slots.len()`, fed from the channel's `slots`, standing at
    /// `start` (per slot).
    pub fn new(first: usize, slots: &[usize], start: &AxisValues, cycle_s: f64) -> ChannelAxes {
        let count = slots.len();
        let mut last = AxisValues::zeros(count);
        for (l, &slot) in last.iter_mut().zip(slots) {
            *l = start.get(slot).copied().unwrap_or(0.0);
        }
        ChannelAxes {
            first,
            count,
            slots: slots.to_vec(),
            last,
            last_velocity: AxisValues::zeros(count),
            cycle_s,
            leases: vec![None; count],
        }
    }

    /// First axis of the channel in the axis set.
    pub fn first(&self) -> usize {
        self.first
    }

    /// How many axes the channel drives.
    pub fn count(&self) -> usize {
        self.count
    }

    /// Powers the channel's axes and couples them to the channel (before the first tick).
    pub fn couple(&mut self, axes: &mut AxisSet) {
        for (i, lease) in self.leases.iter_mut().enumerate() {
            let axis = self.first + i;
            if let Some(a) = axes.axis_mut(axis) {
                let _ = a.switch_on();
            }
            let coupling = Coupling {
                kind: CouplingState::Channel,
                master: -1,
                phase: AxisState::Standstill,
            };
            *lease = axes.couple(axis, coupling).ok();
        }
    }

    /// Hands the channel's set-points of this tick (per slot) to its axes, with their velocity
    /// and acceleration from `rates` when the channel gives them
    /// ([`crate::channel::Channel::set_point_rates`]), else from differences. Does not
    /// allocate.
    pub fn drive(
        &mut self,
        axes: &mut AxisSet,
        set_points: &AxisValues,
        rates: Option<(&AxisValues, &AxisValues)>,
    ) {
        for (i, &slot) in self.slots.iter().enumerate() {
            let p = set_points[slot];
            let (v, a) = match rates {
                Some((velocity, acceleration)) => (velocity[slot], acceleration[slot]),
                None => {
                    let v = (p - self.last[i]) / self.cycle_s;
                    (v, (v - self.last_velocity[i]) / self.cycle_s)
                }
            };
            let phase = motion_phase(v, a);
            if let Some(lease) = self.leases.get(i).copied().flatten() {
                let set = Kinematic {
                    position: p,
                    velocity: v,
                    acceleration: a,
                    jerk: 0.0,
                };
                axes.drive(lease, set, phase);
            }
            self.last[i] = p;
            self.last_velocity[i] = v;
        }
    }

    /// A channel's RESET on its axes: each axis in error (or not coupled to the channel) is
    /// reset, powered and coupled to the channel again where it stands, and the hand-over
    /// takes its next set-point from rest there. `Ok(mask)`: bit `slot` for each axis reset
    /// (the channel's slot of it); `Err(mask)` when an axis keeps its error or cannot be
    /// coupled.
    pub fn reset(&mut self, axes: &mut AxisSet) -> Result<u32, u32> {
        let (mut reset, mut ok) = (0u32, true);
        for (i, lease) in self.leases.iter_mut().enumerate() {
            let axis = self.first + i;
            let Some(a) = axes.axis_mut(axis) else {
                continue;
            };
            let coupled = a
                .coupling()
                .is_some_and(|c| c.kind == CouplingState::Channel);
            if a.error().is_none() && lease.is_some() && coupled {
                continue;
            }
            reset |= 1 << self.slots[i].min(31);
            let _ = a.command(&AxisCommandCall::reset());
            if a.error().is_some() || a.switch_on().is_err() {
                ok = false;
                continue;
            }
            let actual = a.actual();
            self.last[i] = actual;
            self.last_velocity[i] = 0.0;
            let coupling = Coupling {
                kind: CouplingState::Channel,
                master: -1,
                phase: AxisState::Standstill,
            };
            *lease = axes.couple(axis, coupling).ok();
            ok &= lease.is_some();
        }
        if ok {
            Ok(reset)
        } else {
            Err(reset)
        }
    }

    /// Whether one of the channel's axes is in error (it has dropped its coupling).
    pub fn faulted(&self, axes: &AxisSet) -> bool {
        (self.first..self.first + self.count)
            .any(|i| axes.axis(i).is_some_and(|a| a.error().is_some()))
    }

    /// The actual positions of the channel's axes per slot of its `set_points` (a slot
    /// without an axis keeps its set-point).
    pub fn actual(&self, axes: &AxisSet, set_points: &AxisValues) -> AxisValues {
        let mut out = *set_points;
        for (i, &slot) in self.slots.iter().enumerate() {
            out[slot] = axes.axis(self.first + i).map_or(0.0, |a| a.actual());
        }
        out
    }
}
