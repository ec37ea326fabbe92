//! A synthetic load for the tick benchmark and the no-allocation test: `n` six-axis robots
//! (kinematic 45), all with tracking active. Robot 1 follows the PLC's dynamic CS and
//! publishes its own tool frame; robots 2..n follow robot 1 (the seed's example 3 pattern).
//! Every robot moves in an endless loop, so the load never ends. The robots whose axes the
//! image cannot hold (6 onwards) drive no axis images (`axis_images = false`).

use super::file::{Scenario, ScenarioError};
use super::machine::InProcess;
use hli::enums::DynCsState;
use hli::layout::HliCoordinateSystemInt;
use hli::views::PlcView;
use std::path::PathBuf;

const LEAD: &str = "%lead
#TRAFO [45]
#CHANNEL INTERFACE ON [DYN_CS]
#TRACK CS ON [ID=0 FILTER=100]
$WHILE 1
G1 X660 Y30 Z540 F3000
G1 X610 Y-30 Z520 F3000
$ENDWHILE
";

const FOLLOWER: &str = "%follower
#TRAFO [45]
#TRACK CS ON [CH=1 SET_ZERO X=400 Y=700 C=-90 FILTER=0]
$WHILE 1
G1 X640 Y10 Z530 F1200
G1 X630 Y-10 Z530 F1200
$ENDWHILE
";

/// The scenario of `n` robots (1..=12) on ideal drives.
pub fn tracking_robots(n: usize) -> Result<Scenario, ScenarioError> {
    tracking_robots_on(n, None)
}

/// The scenario of `n` robots whose axes have `drive` (a TOML drive model, e.g.
/// `{ model = "pt2", frequency_hz = 80.0, damping = 0.9 }`).
pub fn tracking_robots_on(n: usize, drive: Option<&str>) -> Result<Scenario, ScenarioError> {
    tracking_robots_with(n, drive, Moves::BackAndForth)
}

/// The robots' loops.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Moves {
    /// Back and forth between two points (every block ends at rest: the turn is a reversal).
    BackAndForth,
    /// Round a triangle, each block ending at exact stop.
    Triangle,
    /// Round the same triangle in continuous path (`G261`, corner deviation 1 mm).
    TriangleContour,
}

/// The loop of `text` replaced by a triangle through its two points and a third.
fn triangle(text: &str, contour: bool) -> String {
    let (head, rest) = text.split_once("$WHILE 1\n").expect("a loop");
    let (first, rest) = rest.split_once('\n').expect("a first move");
    let (second, _) = rest.split_once('\n').expect("a second move");
    let third = "G1 X650 Y-20 Z560";
    let mode = if contour {
        "#CONTOUR MODE [DEV PATH_DEV=1]\nG261\n"
    } else {
        ""
    };
    format!("{head}{mode}$WHILE 1\n{first}\n{second}\n{third}\n$ENDWHILE\n")
}

/// [`tracking_robots_on`] with the robots' loops of `moves`.
pub fn tracking_robots_with(
    n: usize,
    drive: Option<&str>,
    moves: Moves,
) -> Result<Scenario, ScenarioError> {
    let mut toml = String::from("cycle_ms = 1.0\n");
    for i in 0..n {
        toml.push_str(&format!(
            "[[channel]]\nname = \"robot{}\"\naxes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\n\
             kinematics = {{ id = 45, preset = \"kr6r900sixx\" }}\n\
             start = [0.0, -60.0, 90.0, 0.0, 60.0, 0.0]\nkin_trafo_display = 1\n\
             program = \"{}\"\n",
            i + 1,
            if i == 0 { "lead.nc" } else { "follower.nc" }
        ));
        if let Some(d) = drive {
            toml.push_str(&format!("drive = {d}\n"));
        }
        if (i + 1) * 6 > hli::layout::HLI_MAX_AXES {
            // Beyond the image's 32 axes: simulated channels.
            toml.push_str("axis_images = false\n");
        }
    }
    Scenario::parse("fleet", &toml, |file| {
        let text = if file == "lead.nc" { LEAD } else { FOLLOWER };
        let text = match moves {
            Moves::BackAndForth => text.to_string(),
            Moves::Triangle => triangle(text, false),
            Moves::TriangleContour => triangle(text, true),
        };
        Ok((PathBuf::from(file), text))
    })
}

/// What the PLC does for the fleet: enables robot 1's unit and commands a 1 mm shift once
/// (robot 1 couples it in over 100 ticks, within its joints' limits).
pub fn plc_setup(view: &PlcView<'_>) {
    let _ = view.set_dyn_cs_enabled(0, true);
    if let Ok(writer) = view.dyn_cs_command(0) {
        let _ = writer.try_send(&HliCoordinateSystemInt {
            translation: [10_000, 0, 0],
            fill_up_2: 0,
            rotation: [0; 3],
            fill_up_1: 0,
        });
    }
}

/// The fleet of `n` robots on a heap image, ticked `warm_up` times so the programs run and
/// every channel tracks; an error names the first channel that does not.
pub fn running(n: usize, warm_up: usize) -> Result<InProcess, String> {
    running_on(n, None, warm_up)
}

/// [`running`] with the robots' axes on `drive` (see [`tracking_robots_on`]).
pub fn running_on(n: usize, drive: Option<&str>, warm_up: usize) -> Result<InProcess, String> {
    running_with(n, drive, Moves::BackAndForth, warm_up)
}

/// [`running_on`] with the robots' loops of `moves`.
pub fn running_with(
    n: usize,
    drive: Option<&str>,
    moves: Moves,
    warm_up: usize,
) -> Result<InProcess, String> {
    let s = tracking_robots_with(n, drive, moves).map_err(|e| e.to_string())?;
    let mut run = InProcess::new(&s, 0).map_err(|e| e.to_string())?;
    plc_setup(&PlcView::new(&run.memory));
    for _ in 0..warm_up {
        run.machine.tick(&run.memory);
    }
    for c in run.machine.controller().channels() {
        if c.tracker().state() != DynCsState::Active || c.error().is_some() {
            return Err(format!(
                "{} not tracking after {warm_up} ticks: {:?} {:?}",
                c.config().name,
                c.tracker().state(),
                c.error()
            ));
        }
    }
    Ok(run)
}
