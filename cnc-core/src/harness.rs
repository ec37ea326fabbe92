//! A machine for tests, in the library: single axes and the engines a test names, on a heap
//! image, ticked in lockstep; calls go straight to the machine (no PLC, no process, no
//! configuration file). Engine tests run next to their engine on it, and an engine in a
//! user's own crate can be tested the same way.
//!
//! ```ignore
//! let saw = SawEngine::new(2, 0.001);
//! let mut run = Harness::new(0.001, vec![master, slave], vec![Box::new(saw)]).unwrap();
//! run.power_all();
//! let reply = run.call(1, &SawGearInCall { .. }).unwrap();
//! let ticks = run.until(5000, |r| r.axis(1).state() == AxisState::SlaveSynchronous);
//! ```

use crate::axis::config::AxisConfig;
use crate::axis::Axis;
use crate::machine::{Engine, Machine, MachineError, MachineSetup};
use crate::setpoint::Kinematic;
use hli::calls::{AcyclicCall, ErrorCode};
use hli::views::{CncView, PlcView};
use hli::ImageMemory;

/// A machine of single axes and engines on a heap image.
#[derive(Debug)]
pub struct Harness {
    /// The machine.
    pub machine: Machine,
    /// Its image, as the PLC would see it.
    pub memory: ImageMemory,
    cycle_s: f64,
}

impl Harness {
    /// A machine with tick `cycle_s`, these single axes (numbered from 0, unpowered) and these
    /// engines, ticked in this order.
    pub fn new(
        cycle_s: f64,
        axes: Vec<AxisConfig>,
        engines: Vec<Box<dyn Engine>>,
    ) -> Result<Harness, MachineError> {
        let machine = Machine::new(MachineSetup {
            channels: Vec::new(),
            axes,
            engines,
            cycle_s,
        })?;
        let memory = hli::image::heap_image(0, machine.axis_images() as u32);
        Ok(Harness {
            machine,
            memory,
            cycle_s,
        })
    }

    /// A machine with tick `cycle_s` and these single axes, with the engines every machine
    /// of single axes gets without engine configuration, in their tick order (the engine
    /// set's: the cams and the flying saw), as `cnc run` makes them.
    pub fn standard(cycle_s: f64, axes: Vec<AxisConfig>) -> Result<Harness, String> {
        use crate::machine::engines::{configure, standard, ConfigInput, EngineSetup};
        let names: Vec<String> = axes.iter().map(|a| a.name.clone()).collect();
        let no_files = |name: &str| Err(format!("{name}: a harness reads no files"));
        let configs = configure(&ConfigInput {
            sections: &toml::Table::new(),
            axis_names: &names,
            channel_axes: 0,
            open: &no_files,
        })
        .map_err(|e| e.to_string())?;
        let setup = EngineSetup {
            channel_axes: 0,
            single_axes: axes.len(),
            cycle_s,
        };
        let engines = standard(&setup, &configs).map_err(|e| e.to_string())?;
        Harness::new(cycle_s, axes, engines).map_err(|e| e.to_string())
    }

    /// Every axis enabled (as MC_Power would), before the first tick.
    pub fn power_all(&mut self) {
        let axes = self.machine.axes_mut();
        for i in 0..axes.len() {
            if let Some(axis) = axes.axis_mut(i) {
                // An axis that cannot switch on stays off; the test sees it in its state.
                let _ = axis.switch_on();
            }
        }
    }

    /// The tick, s.
    pub fn cycle_s(&self) -> f64 {
        self.cycle_s
    }

    /// One tick, and what the CNC does between ticks.
    pub fn step(&mut self) {
        self.machine.tick(&self.memory);
        self.machine.serve_channels();
    }

    /// `n` ticks.
    pub fn steps(&mut self, n: usize) {
        for _ in 0..n {
            self.step();
        }
    }

    /// Ticks until `done` holds, and how many that took; a watchdog of `max` ticks rather
    /// than a time limit.
    ///
    /// # Panics
    /// When `done` does not hold within `max` ticks.
    pub fn until(&mut self, max: usize, done: impl Fn(&Harness) -> bool) -> usize {
        for k in 0..max {
            if done(self) {
                return k;
            }
            self.step();
        }
        panic!("watchdog: not reached within {max} ticks");
    }

    /// An acyclic call to `target` (an axis, a group, a table), answered at once as between
    /// two ticks.
    pub fn call<C: AcyclicCall>(&mut self, target: u32, body: &C) -> Result<C::Reply, ErrorCode> {
        let view = CncView::new(&self.memory);
        self.machine.call(&view, target, body)
    }

    /// Axis `i`.
    ///
    /// # Panics
    /// When the machine has no axis `i`.
    pub fn axis(&self, i: usize) -> &Axis {
        self.machine.axes().axis(i).expect("an axis of the machine")
    }

    /// Axis `i`'s set-point.
    pub fn setpoint(&self, i: usize) -> Kinematic {
        self.axis(i).setpoint()
    }

    /// The image as the PLC reads it.
    pub fn plc_view(&self) -> PlcView<'_> {
        PlcView::new(&self.memory)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hli::calls::axis::AxisCommandCall;

    #[test]
    fn a_powered_axis_moves_by_a_call_and_arrives() {
        let axes = vec![AxisConfig::linear("X", 1)];
        let mut run = Harness::new(0.001, axes, Vec::new()).unwrap();
        run.power_all();
        run.step();
        let limits = [100.0, 1000.0, 1000.0, 1e5];
        let reply = run
            .call(0, &AxisCommandCall::move_absolute(10.0, limits))
            .unwrap();
        assert_eq!(reply.error_id, 0);
        let ticks = run.until(5000, |r| r.setpoint(0).position == 10.0);
        assert!(
            ticks > 100,
            "a move of 10 mm at 100 mm/s takes 0.1 s: {ticks}"
        );
    }
}
