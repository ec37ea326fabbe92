//! The cam conveyor as a PLC program, step by step as structured text would write it (a
//! CASE over steps, each calling its blocks every cycle and moving on when their outputs
//! say so): the seed's usage of the cam blocks (chapter 5.1) re-expressed for
//! `scenarios/cam-conveyor-program`.
//!
//! ```text
//! Select   MC_CamTableSelect table 1, cyclic, absolute            -> Done
//! Couple   MC_CamIn lifter to conveyor through table 1            -> InSync
//! Run      MC_MoveVelocity conveyor at 360 deg/s; from 1.7 s on      ->
//! Scale    MC_CamScaling: half the stroke at the next cycle, slave auto-offset -> Done
//! Mode     from 2.6 s: MC_SetCamOnlineChangeMode table 1, next cycle          -> Done
//! Change   MC_WriteMotionFunctionPoint: point 4 to 30                          -> Done
//! Out      from 4 s, in the rest phase (350..360 deg): MC_CamOut               -> Done
//! Halt     MC_Halt conveyor                                                    -> Done
//! ```
//!
//! Any Error stops the sequence in `Failed` with the block and its ErrorID. The times count
//! from the program's first cycle on the CNC's clock ([`PlcIo::cnc_clock_us`]), so they keep
//! their meaning at any CNC cycle and PLC task period (at 1 ms, 1.7 s is cycle 1700).

use crate::blocks::cam::{
    McCamIn, McCamOut, McCamScaling, McSetCamOnlineChangeMode, McWriteMotionFunctionPoint,
};
use crate::blocks::cam_data::McCamTableSelect;
use crate::blocks::motion::{McHalt, McMoveVelocity};
use crate::runtime::{PlcIo, PlcProgram};
use hli::calls::cam::McMotionFunctionPoint;

/// The axes of `scenarios/cam-conveyor-program` (`gpAx` indices): conveyor, lifter.
pub const SCENARIO_AXES: [u32; 2] = [0, 1];
const TABLE: u32 = 1;
/// MC_CamActivationMode NextCycle; MC_CamScalingMode AutoOffset and Off.
const NEXT_CYCLE: u32 = 3;
const AUTO_OFFSET: u32 = 1;
const OFF: u32 = 2;

/// The steps of the sequence.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Step {
    /// MC_CamTableSelect.
    #[default]
    Select,
    /// MC_CamIn.
    Couple,
    /// MC_MoveVelocity of the conveyor.
    Run,
    /// MC_CamScaling.
    Scale,
    /// MC_SetCamOnlineChangeMode.
    Mode,
    /// MC_WriteMotionFunctionPoint.
    Change,
    /// MC_CamOut in a rest phase.
    Out,
    /// MC_Halt of the conveyor.
    Halt,
    /// The sequence ran through.
    Finished,
    /// A block reported an error.
    Failed {
        /// The step it failed in.
        at: u8,
        /// The block's ErrorID.
        error_id: u32,
    },
}

/// The program's state: its step, its block instances and what it saw.
#[derive(Debug, Default)]
pub struct CamConveyor {
    /// Where the sequence stands.
    pub step: Step,
    /// PLC cycle each step was entered in.
    pub entered: Vec<(Step, u64)>,
    select: McCamTableSelect,
    cam_in: McCamIn,
    run: McMoveVelocity,
    scale: McCamScaling,
    mode: McSetCamOnlineChangeMode,
    change: McWriteMotionFunctionPoint,
    out: McCamOut,
    halt: McHalt,
    /// The conveyor (master) and the lifter (`gpAx` indices).
    axes: [u32; 2],
    /// The CNC's clock in the first cycle (µs).
    first_clock_us: Option<u64>,
}

impl CamConveyor {
    /// The program before its first cycle, on [`SCENARIO_AXES`].
    pub fn new() -> CamConveyor {
        CamConveyor::on_axes(SCENARIO_AXES)
    }

    /// The program on `[conveyor, lifter]` (`gpAx` indices).
    pub fn on_axes(axes: [u32; 2]) -> CamConveyor {
        let mut p = CamConveyor {
            axes,
            ..CamConveyor::default()
        };
        p.entered.reserve(16);
        p.entered.push((Step::Select, 0));
        p
    }

    fn go(&mut self, step: Step, cycle: u64) {
        self.step = step;
        if self.entered.len() < self.entered.capacity() {
            self.entered.push((step, cycle));
        }
    }

    /// Milliseconds since the first cycle, on the CNC's clock.
    fn elapsed_ms(&mut self, io: &PlcIo<'_>) -> u64 {
        let now = io.cnc_clock_us();
        let first = *self.first_clock_us.get_or_insert(now);
        now.saturating_sub(first) / 1000
    }

    fn fail(&mut self, error_id: u32) {
        let at = self.entered.len() as u8;
        self.step = Step::Failed { at, error_id };
    }
}

impl PlcProgram for CamConveyor {
    fn cycle(&mut self, io: &mut PlcIo<'_>) {
        let cycle = io.cycle;
        let ms = self.elapsed_ms(io);
        let [conveyor, lifter] = self.axes;
        match self.step {
            Step::Select => {
                self.select.table = TABLE;
                self.select.periodic = true;
                self.select.master_absolute = true;
                self.select.slave_absolute = true;
                self.select.execute = ms >= 4;
                self.select.call(io);
                if self.select.out.error {
                    self.fail(self.select.out.error_id);
                } else if self.select.out.done {
                    self.go(Step::Couple, cycle);
                }
            }
            Step::Couple => {
                self.cam_in.master = conveyor;
                self.cam_in.table = TABLE;
                self.cam_in.start_mode = 1;
                self.cam_in.execute = true;
                self.cam_in.call(io, lifter);
                if self.cam_in.out.error {
                    self.fail(self.cam_in.out.error_id);
                } else if self.cam_in.out.in_sync {
                    self.go(Step::Run, cycle);
                }
            }
            Step::Run | Step::Scale | Step::Mode | Step::Change | Step::Out | Step::Halt => {
                // The coupling and the conveyor's move are called every cycle while they run.
                self.cam_in.call(io, lifter);
                self.run.velocity = 360.0;
                self.run.direction = 1;
                self.run.acceleration = 3600.0;
                self.run.deceleration = 3600.0;
                self.run.jerk = 36000.0;
                self.run.execute = self.step != Step::Halt;
                self.run.call(io, conveyor);
                if self.run.out.error {
                    return self.fail(self.run.out.error_id);
                }
                self.sequence(io, cycle, ms);
            }
            Step::Finished | Step::Failed { .. } => {}
        }
    }

    fn summary(&self) -> String {
        let steps: Vec<String> = self
            .entered
            .iter()
            .map(|(s, c)| format!("{s:?} at cycle {c}"))
            .collect();
        format!("cam-conveyor: {:?}; {}", self.step, steps.join(", "))
    }
}

impl CamConveyor {
    /// The steps after the conveyor runs (`ms` since the first cycle).
    fn sequence(&mut self, io: &mut PlcIo<'_>, cycle: u64, ms: u64) {
        let [conveyor, lifter] = self.axes;
        match self.step {
            Step::Run if ms >= 1700 && self.run.out.in_velocity => {
                self.go(Step::Scale, cycle);
            }
            Step::Scale => {
                self.scale.scaling.activation_mode = NEXT_CYCLE;
                self.scale.scaling.master_scaling_mode = OFF;
                self.scale.scaling.slave_scaling_mode = AUTO_OFFSET;
                self.scale.scaling.slave_scaling = 0.5;
                self.scale.execute = true;
                self.scale.call(io, lifter);
                if self.scale.out.error {
                    self.fail(self.scale.out.error_id);
                } else if self.scale.out.done && ms >= 2600 {
                    self.go(Step::Mode, cycle);
                }
            }
            Step::Mode => {
                self.mode.table = TABLE;
                self.mode.scaling.activation_mode = NEXT_CYCLE;
                self.mode.execute = true;
                self.mode.call(io);
                if self.mode.out.error {
                    self.fail(self.mode.out.error_id);
                } else if self.mode.out.done {
                    self.go(Step::Change, cycle);
                }
            }
            Step::Change => {
                self.change.table = TABLE;
                // Point 4 of the seed's example: POLYNOM5_MM (15) from a velocity point (2).
                self.change.point = McMotionFunctionPoint {
                    point_index: 4,
                    function_type: 15,
                    point_type: 2,
                    rel_index_next_point: 1,
                    master_pos: 240.0,
                    slave_pos: 30.0,
                    ..McMotionFunctionPoint::default()
                };
                self.change.execute = true;
                self.change.call(io);
                if self.change.out.error {
                    self.fail(self.change.out.error_id);
                } else if self.change.out.done {
                    self.go(Step::Out, cycle);
                }
            }
            Step::Out => {
                // In the cam's last rest (350..360 degrees of the conveyor's turn).
                let at_rest = io
                    .view
                    .axis_state(conveyor as usize)
                    .is_ok_and(|s| s.command_position_acs_r > 3_500_000);
                self.out.execute = ms >= 4000 && at_rest || self.out.execute;
                self.out.call(io, lifter);
                if self.out.out.error {
                    self.fail(self.out.out.error_id);
                } else if self.out.out.done {
                    self.go(Step::Halt, cycle);
                }
            }
            Step::Halt => {
                self.halt.deceleration = 3600.0;
                self.halt.jerk = 36000.0;
                self.halt.execute = true;
                self.halt.call(io, conveyor);
                if self.halt.out.error {
                    self.fail(self.halt.out.error_id);
                } else if self.halt.out.done {
                    self.go(Step::Finished, cycle);
                }
            }
            _ => {}
        }
    }
}
