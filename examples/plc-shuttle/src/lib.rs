//! A PLC program written in a user's crate, the way a machine builder writes one: a shuttle
//! carries parts between two stations on one axis. The program powers the axis, then moves it
//! with MC_MoveAbsolute to the far station and back, `strokes` times, as a step sequence (the
//! CASE statement a structured-text program would use). The PLC's task runtime, the axis
//! blocks and the HLI come from `plc-shim`; `main.rs` only parses the arguments and hands the
//! program to [`plc_shim::cli::host`].

#![forbid(unsafe_code)]

use plc_shim::blocks::motion::{McMoveAbsolute, McPower};
use plc_shim::runtime::{PlcIo, PlcProgram};

/// Where the sequence is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// Waiting for the axis to report ENABLED.
    PowerOn,
    /// Moving to the far station.
    Outward,
    /// Moving back to the home station.
    Return,
    /// All strokes made.
    Done,
    /// A block reported an error (its ErrorID).
    Failed(u32),
}

/// The shuttle program.
#[derive(Debug)]
pub struct Shuttle {
    /// The shuttle's axis (index in `gpAx`).
    pub axis: u32,
    /// Home station, mm.
    pub home: f64,
    /// Far station, mm.
    pub far: f64,
    /// Round trips to make.
    pub strokes: u32,
    /// Velocity, mm/s.
    pub velocity: f64,
    /// Round trips made.
    pub made: u32,
    /// The sequence's step.
    pub step: Step,
    power: McPower,
    outward: McMoveAbsolute,
    back: McMoveAbsolute,
}

impl Shuttle {
    /// A shuttle on `axis` between `home` and `far`.
    pub fn new(axis: u32, home: f64, far: f64, strokes: u32, velocity: f64) -> Shuttle {
        let profile = |position| {
            let mut block = McMoveAbsolute::default();
            block.position = position;
            block.velocity = velocity;
            block.acceleration = 4.0 * velocity;
            block.deceleration = 4.0 * velocity;
            block.jerk = 40.0 * velocity;
            block
        };
        Shuttle {
            axis,
            home,
            far,
            strokes,
            velocity,
            made: 0,
            step: if strokes == 0 {
                Step::Done
            } else {
                Step::PowerOn
            },
            power: McPower::default(),
            outward: profile(far),
            back: profile(home),
        }
    }

    /// Whether the sequence has ended (done or failed).
    pub fn finished(&self) -> bool {
        matches!(self.step, Step::Done | Step::Failed(_))
    }
}

impl PlcProgram for Shuttle {
    fn cycle(&mut self, io: &mut PlcIo<'_>) {
        // Every block instance is called every cycle, as in a PLC; the steps only set inputs.
        self.power.enable = !self.finished();
        self.power.call(io, self.axis);
        self.outward.execute = self.step == Step::Outward;
        self.outward.call(io, self.axis);
        self.back.execute = self.step == Step::Return;
        self.back.call(io, self.axis);
        self.step = match self.step {
            Step::PowerOn if self.power.error => Step::Failed(self.power.error_id),
            Step::PowerOn if self.power.status => Step::Outward,
            Step::Outward if self.outward.out.error => Step::Failed(self.outward.out.error_id),
            Step::Outward if self.outward.out.done => Step::Return,
            Step::Return if self.back.out.error => Step::Failed(self.back.out.error_id),
            Step::Return if self.back.out.done => {
                self.made += 1;
                if self.made == self.strokes {
                    Step::Done
                } else {
                    Step::Outward
                }
            }
            other => other,
        };
    }

    fn summary(&self) -> String {
        format!(
            "shuttle: {} of {} round trips between {} and {} mm, {:?}",
            self.made, self.strokes, self.home, self.far, self.step
        )
    }
}
