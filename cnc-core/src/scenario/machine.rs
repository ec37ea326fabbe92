//! The CNC side of a scenario: its channels on one image, ticking; and the in-process run
//! that alternates CNC ticks and PLC timeline cycles on a heap image exactly as lockstep mode
//! alternates the two processes (tests use it; `cnc run --lockstep` gives the same trace).

use super::file::{PlcSetup, Scenario, ScenarioError};
use super::trace::Trace;
use crate::channel::{Channel, Controller, RunState};
use hli::access::Leaf;
use hli::enums::DynCsState;
use hli::views::CncView;
use hli::ImageMemory;
use plc_shim::timeline::Timeline;

/// The channels of a scenario, programs started.
#[derive(Debug)]
pub struct Machine {
    controller: Controller,
    heartbeat: Leaf,
    ticks: u64,
    max_tracking_error: Vec<f64>,
}

impl Machine {
    /// Builds the channels and starts their programs.
    pub fn new(scenario: &Scenario) -> Result<Machine, ScenarioError> {
        let invalid = |message: String| ScenarioError::Invalid {
            file: scenario.name.clone(),
            message,
        };
        let mut channels = Vec::with_capacity(scenario.channels.len());
        for (i, (config, program)) in scenario.channels.iter().zip(&scenario.programs).enumerate() {
            let mut channel = Channel::new(i, config.clone(), scenario.cycle_s)
                .map_err(|e| invalid(e.to_string()))?;
            if let Some(p) = program {
                channel.start(p.clone());
            }
            channels.push(channel);
        }
        let controller =
            Controller::new(channels, scenario.cycle_s).map_err(|e| invalid(e.to_string()))?;
        Ok(Machine {
            controller,
            heartbeat: Leaf::resolve("header.cnc_heartbeat").expect("the header has a heartbeat"),
            ticks: 0,
            max_tracking_error: vec![0.0; scenario.channels.len()],
        })
    }

    /// One tick of every channel, then the heartbeat (the PLC's "a tick is done").
    pub fn tick(&mut self, memory: &ImageMemory) {
        self.controller.tick(&CncView::new(memory));
        memory.place::<u64>(self.heartbeat.offset).increment();
        self.ticks += 1;
        for (c, max) in self
            .controller
            .channels()
            .iter()
            .zip(self.max_tracking_error.iter_mut())
        {
            if c.tracker().state() == DynCsState::Active {
                let e = (c.tool_pose().translation.vector - c.pose_out().translation.vector).norm();
                *max = max.max(e);
            }
        }
    }

    /// Per channel, the largest distance (mm) in ACTIVE between the tool point the joints
    /// realise and the point on the moving workpiece it must be at, in the same tick.
    pub fn max_tracking_error(&self) -> &[f64] {
        &self.max_tracking_error
    }

    /// Ticks done.
    pub fn ticks(&self) -> u64 {
        self.ticks
    }

    /// Axis images the channels use (the image's axis count; at least 1).
    pub fn axis_images(&self) -> usize {
        self.controller.axis_images().max(1)
    }

    /// The channels.
    pub fn controller(&self) -> &Controller {
        &self.controller
    }

    /// Whether no channel runs a program any more.
    pub fn idle(&self) -> bool {
        self.controller
            .channels()
            .iter()
            .all(|c| c.state() != RunState::Running)
    }
}

/// An in-process run: the machine, its image, the PLC timeline and the trace.
#[derive(Debug)]
pub struct InProcess {
    /// The CNC side.
    pub machine: Machine,
    /// The image both sides share.
    pub memory: ImageMemory,
    /// The PLC timeline, if the scenario has one.
    pub timeline: Option<Timeline>,
    /// The trace.
    pub trace: Trace,
}

impl InProcess {
    /// Sets up `scenario` on a heap image with room for `rows` trace rows. A built-in PLC
    /// program is refused: those run only in the PLC process.
    pub fn new(scenario: &Scenario, rows: usize) -> Result<InProcess, ScenarioError> {
        let timeline = match &scenario.plc {
            PlcSetup::None => None,
            PlcSetup::Timeline { timeline, .. } => Some(Timeline::clone(timeline)),
            PlcSetup::Program(p) => {
                return Err(ScenarioError::Invalid {
                    file: scenario.name.clone(),
                    message: format!("built-in PLC program {p:?} runs only in the PLC process"),
                })
            }
        };
        let machine = Machine::new(scenario)?;
        let memory =
            hli::segment::heap_image(scenario.channels.len() as u32, machine.axis_images() as u32);
        Ok(InProcess {
            machine,
            memory,
            timeline,
            trace: Trace::new(&scenario.signals, rows),
        })
    }

    /// One lockstep step: CNC tick, trace sample, PLC cycle. `cycle_s` gives the trace time.
    pub fn step(&mut self, cycle_s: f64) {
        let tick = self.machine.ticks();
        self.machine.tick(&self.memory);
        self.trace.record(&self.memory, tick, tick as f64 * cycle_s);
        if let Some(t) = self.timeline.as_mut() {
            t.cycle(&self.memory);
        }
    }
}
