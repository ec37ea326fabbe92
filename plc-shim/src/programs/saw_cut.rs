//! A flying saw cutting endless material into equal lengths, as the seed's sample program
//! does (seed 001, chapter 12.4) in our own code. Three single axes: the conveyor (master),
//! the saw carriage (slave) and the blade; `gpAx[0..3]` by default ([`SCENARIO_AXES`]),
//! others with [`SawCut::on_axes`].
//!
//! ```text
//! Power     MC_Power the three axes                                     -> Status
//! Conveyor  MC_MoveVelocity of the conveyor                             -> InVelocity
//! Sync      MC_GearInPos: the saw at SAW_SYNC exactly when the conveyor
//!           passes FIRST_CUT + k * length                               -> InSync
//! Down      MC_MoveAbsolute of the blade to its depth (the cut)         -> Done
//! Up        MC_MoveAbsolute of the blade back to 0                      -> Done
//! Out       MC_GearOut: the saw runs on at the conveyor's speed         -> Done
//! Return    MC_MoveAbsolute of the saw home; once it runs back below
//!           SAW_SYNC, the next cut's MC_GearInPos (from the moving saw) -> Sync
//! End       after the last cut: the saw home, the conveyor halted       -> Finished
//! ```
//!
//! Every cut lies on the material at `saw - conveyor` (the set-points): in the synchronous
//! phase that difference is `SAW_SYNC - (FIRST_CUT + k * length)`, so the pieces are the cut
//! length long to the precision of the position sync.

use crate::blocks::motion::{McHalt, McMoveAbsolute, McMoveVelocity, McPower};
use crate::blocks::saw::{McGearInPos, McGearOut};
use crate::runtime::{PlcIo, PlcProgram};

/// The axes of `scenarios/flying-saw` (`gpAx` indices): conveyor, saw carriage, blade.
pub const SCENARIO_AXES: [u32; 3] = [0, 1, 2];
/// Conveyor position of the first cut, mm.
const FIRST_CUT: f64 = 600.0;
/// Saw position where it is synchronous, mm.
const SAW_SYNC: f64 = 300.0;
/// Blade depth, mm.
const DEPTH: f64 = 50.0;
/// Cuts a program records at most.
pub const MAX_CUTS: usize = 64;

/// The steps of the sequence.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Step {
    /// MC_Power.
    #[default]
    Power,
    /// The conveyor speeds up.
    Conveyor,
    /// MC_GearInPos until InSync.
    Sync,
    /// The blade cuts.
    Down,
    /// The blade comes back.
    Up,
    /// MC_GearOut.
    Out,
    /// The saw runs home; the next sync starts on the way.
    Return,
    /// After the last cut: saw home, conveyor halted.
    End,
    /// Done.
    Finished,
    /// A block failed.
    Failed {
        /// The step it failed in.
        at: u8,
        /// The block's ErrorID.
        error_id: u32,
    },
}

/// The program.
#[derive(Debug)]
pub struct SawCut {
    /// Where the sequence stands.
    pub step: Step,
    /// Cuts to make.
    pub cuts: usize,
    /// Cut length, mm.
    pub length: f64,
    /// Conveyor speed, mm/s.
    pub speed: f64,
    /// Cuts made.
    pub made: usize,
    /// Where each cut lies on the material (saw - conveyor set-points at the cut), mm.
    pub cut_at: [f64; MAX_CUTS],
    /// The conveyor, saw carriage and blade (`gpAx` indices).
    axes: [u32; 3],
    power: [McPower; 3],
    conveyor: McMoveVelocity,
    halt: McHalt,
    gear_in: McGearInPos,
    gear_out: McGearOut,
    saw_home: McMoveAbsolute,
    blade: McMoveAbsolute,
    /// Cycles the next rising edge of a block waits for (its Execute low for a cycle).
    rearm: bool,
}

impl SawCut {
    /// `cuts` pieces of `length` mm from a conveyor at `speed` mm/s.
    pub fn new(cuts: usize, length: f64, speed: f64) -> SawCut {
        let limits = |b: &mut McMoveAbsolute, v: f64| {
            b.velocity = v;
            b.acceleration = 5000.0;
            b.deceleration = 5000.0;
            b.jerk = 1e5;
        };
        let mut saw_home = McMoveAbsolute::default();
        limits(&mut saw_home, 1000.0);
        let mut blade = McMoveAbsolute::default();
        limits(&mut blade, 500.0);
        let mut gear_in = McGearInPos::default();
        let [conveyor_axis, saw_axis, _] = SCENARIO_AXES;
        gear_in.master = conveyor_axis;
        gear_in.slave = saw_axis;
        gear_in.slave_sync_position = SAW_SYNC;
        gear_in.inputs.acceleration = 4000.0;
        gear_in.inputs.deceleration = 4000.0;
        gear_in.inputs.jerk = 1e5;
        let mut conveyor = McMoveVelocity::default();
        conveyor.direction = 1;
        conveyor.velocity = speed;
        conveyor.acceleration = 2000.0;
        conveyor.deceleration = 2000.0;
        conveyor.jerk = 1e5;
        let mut halt = McHalt::default();
        halt.deceleration = 2000.0;
        halt.jerk = 1e5;
        let mut gear_out = McGearOut::default();
        gear_out.slave = saw_axis;
        SawCut {
            step: Step::Power,
            cuts: cuts.min(MAX_CUTS),
            length,
            speed,
            made: 0,
            cut_at: [0.0; MAX_CUTS],
            axes: SCENARIO_AXES,
            power: Default::default(),
            conveyor,
            halt,
            gear_in,
            gear_out,
            saw_home,
            blade,
            rearm: false,
        }
    }

    /// The same program on other axes: `[conveyor, saw carriage, blade]` (`gpAx` indices).
    pub fn on_axes(mut self, axes: [u32; 3]) -> SawCut {
        self.axes = axes;
        self.gear_in.master = axes[0];
        self.gear_in.slave = axes[1];
        self.gear_out.slave = axes[1];
        self
    }

    fn fail(&mut self, error_id: u32) {
        let at = match self.step {
            Step::Power => 0,
            Step::Conveyor => 1,
            Step::Sync => 2,
            Step::Down => 3,
            Step::Up => 4,
            Step::Out => 5,
            Step::Return => 6,
            Step::End => 7,
            _ => 9,
        };
        self.step = Step::Failed { at, error_id };
    }

    /// The next step; every block's Execute goes low for one cycle so that the next command
    /// of the same block gets its rising edge.
    fn go(&mut self, step: Step) {
        self.step = step;
        self.rearm = true;
    }

    /// Calls every block once, each with Execute TRUE in its steps, unless the blocks are
    /// re-armed this cycle (every Execute low); returns whether they were.
    fn call_blocks(&mut self, io: &mut PlcIo<'_>) -> bool {
        // Power and the conveyor stay called every cycle (MC_Power is level-driven).
        let [conveyor, saw, blade] = self.axes;
        for (&axis, p) in self.axes.iter().zip(self.power.iter_mut()) {
            p.enable = true;
            p.call(io, axis);
        }
        let rearm = core::mem::take(&mut self.rearm);
        let on = |step: Step, here: Step| !rearm && step == here;
        let step = self.step;
        self.conveyor.execute = !matches!(step, Step::Power);
        self.conveyor.call(io, conveyor);
        self.halt.execute = on(step, Step::End);
        self.halt.call(io, conveyor);
        self.gear_in.execute = on(step, Step::Sync);
        let next_cut = FIRST_CUT + self.made as f64 * self.length;
        self.gear_in.master_sync_position = next_cut;
        self.gear_in.call(io);
        self.gear_out.execute = on(step, Step::Out);
        self.gear_out.call(io);
        self.saw_home.position = 0.0;
        self.saw_home.execute = on(step, Step::Return) || on(step, Step::End);
        self.saw_home.call(io, saw);
        self.blade.position = if step == Step::Down { DEPTH } else { 0.0 };
        self.blade.execute = on(step, Step::Down) || on(step, Step::Up);
        self.blade.call(io, blade);
        rearm
    }

    /// The saw and conveyor set-points in mm.
    fn set_points(&self, io: &PlcIo<'_>) -> Option<(f64, f64)> {
        let c = io.view.axis_state(self.axes[0] as usize).ok()?;
        let s = io.view.axis_state(self.axes[1] as usize).ok()?;
        Some((
            s.command_position_acs_r as f64 * 1e-4,
            c.command_position_acs_r as f64 * 1e-4,
        ))
    }
}

impl PlcProgram for SawCut {
    fn cycle(&mut self, io: &mut PlcIo<'_>) {
        let step = self.step;
        if self.call_blocks(io) {
            return;
        }
        match step {
            Step::Power => {
                if self.power.iter().all(|p| p.status) {
                    self.go(Step::Conveyor);
                } else if let Some(p) = self.power.iter().find(|p| p.error) {
                    self.fail(p.error_id);
                }
            }
            Step::Conveyor => {
                if self.conveyor.out.in_velocity {
                    self.go(Step::Sync);
                } else if self.conveyor.out.error {
                    self.fail(self.conveyor.out.error_id);
                }
            }
            Step::Sync => {
                if self.gear_in.out.in_sync {
                    self.go(Step::Down);
                } else if self.gear_in.out.error || self.gear_in.out.command_aborted {
                    self.fail(self.gear_in.out.error_id);
                }
            }
            Step::Down => {
                if self.blade.out.done {
                    if let (Some((s, c)), Some(slot)) =
                        (self.set_points(io), self.cut_at.get_mut(self.made))
                    {
                        *slot = s - c;
                    }
                    self.made += 1;
                    self.go(Step::Up);
                } else if self.blade.out.error {
                    self.fail(self.blade.out.error_id);
                }
            }
            Step::Up => {
                if self.blade.out.done {
                    self.go(Step::Out);
                } else if self.blade.out.error {
                    self.fail(self.blade.out.error_id);
                }
            }
            Step::Out => {
                if self.gear_out.out.done {
                    self.go(if self.made >= self.cuts {
                        Step::End
                    } else {
                        Step::Return
                    });
                } else if self.gear_out.out.error {
                    self.fail(self.gear_out.out.error_id);
                }
            }
            Step::Return => {
                // On the way home, once back behind the sync position: the next sync starts
                // from the moving saw (the universal saw takes any start state).
                let back = self
                    .set_points(io)
                    .is_some_and(|(s, _)| s < SAW_SYNC - 50.0);
                if self.saw_home.out.error {
                    self.fail(self.saw_home.out.error_id);
                } else if back || self.saw_home.out.done {
                    self.go(Step::Sync);
                }
            }
            Step::End => {
                if self.saw_home.out.done && self.halt.out.done {
                    self.step = Step::Finished;
                } else if self.saw_home.out.error || self.halt.out.error {
                    self.fail(self.saw_home.out.error_id.max(self.halt.out.error_id));
                }
            }
            Step::Finished | Step::Failed { .. } => {}
        }
    }

    fn summary(&self) -> String {
        let cuts = &self.cut_at[..self.made.min(MAX_CUTS)];
        let lengths = cuts.windows(2).map(|w| w[0] - w[1]);
        let (lo, hi) = lengths.fold((f64::MAX, f64::MIN), |(lo, hi), l| (lo.min(l), hi.max(l)));
        format!(
            "saw-cut: {:?}, {} cuts, piece length min {lo:.4} max {hi:.4} mm",
            self.step, self.made
        )
    }
}
