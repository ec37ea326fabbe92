//! The former way channel axes reached the axis images, kept only as the baseline of the
//! `channels` benchmark while the machine tick replaces it (remove with that baseline): each
//! channel axis's `gpAx[k]^lr_state` written straight from the channel's set-point, no axis
//! layer, no drive. The machine (`crate::machine`) now runs channel axes as `Axis` objects.

use super::plc_io::hli_value;
use crate::setpoint::AxisValues;
use hli::enums::CouplingState;
use hli::layout::{HliAxis, HliAxisLrState};
use hli::views::CncView;
use hli::PlaceExt;

/// Writes one channel's axes into consecutive axis images.
#[derive(Debug, Clone)]
pub struct AxisPublisher {
    first: usize,
    last: AxisValues,
    last_velocity: AxisValues,
    cycle_s: f64,
}

impl AxisPublisher {
    /// Axes `first..first + start.len()` of the image, standing at `start` (the channel's
    /// set-points at start-up), ticking every `cycle_s`.
    pub fn new(first: usize, start: &AxisValues, cycle_s: f64) -> Self {
        Self {
            first,
            last: *start,
            last_velocity: AxisValues::zeros(start.len()),
            cycle_s,
        }
    }

    /// First axis image used.
    pub fn first(&self) -> usize {
        self.first
    }

    /// Publishes `set_points` (channel order). Does not allocate.
    pub fn publish(&mut self, view: &CncView<'_>, set_points: &AxisValues) {
        for (i, &p) in set_points.iter().enumerate() {
            let Ok(axis) = view.axis(self.first + i) else {
                break;
            };
            let v = (p - self.last[i]) / self.cycle_s;
            let a = (v - self.last_velocity[i]) / self.cycle_s;
            let state = crate::axis::motion_phase(v, a);
            // Linear units (0.1 um) and angle units (0.0001 degree) scale alike.
            let raw = |x: f64| hli_value(x, false);
            let position = raw(p);
            axis.field::<HliAxisLrState>(core::mem::offset_of!(HliAxis, lr_state))
                .write(&HliAxisLrState {
                    current_position_acs_r: position,
                    command_position_acs_r: position,
                    current_velocity_r: raw(v),
                    command_velocity_r: raw(v),
                    command_acceleration_r: raw(a),
                    following_error_r: 0,
                    axis_state_r: state.raw(),
                    coupling_state_r: CouplingState::Channel.raw(),
                    master_axis_r: -1,
                    error_id_r: 0,
                    status_r: 0,
                    fill_up_1: 0,
                });
            self.last[i] = p;
            self.last_velocity[i] = v;
        }
    }
}
