//! A synthetic load for the tick benchmark and the no-allocation test: `n` six-axis robots
//! (kinematic 45), all with tracking active. Robot 1 follows the PLC's dynamic CS and
//! publishes its own tool frame; robots 2..n follow robot 1 (the seed's example 3 pattern).
//! Every robot moves in an endless loop, so the load never ends.

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
    }
    Scenario::parse("fleet", &toml, |file| {
        let text = if file == "lead.nc" { LEAD } else { FOLLOWER };
        Ok((PathBuf::from(file), text.to_string()))
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
    let s = tracking_robots_on(n, drive).map_err(|e| e.to_string())?;
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
