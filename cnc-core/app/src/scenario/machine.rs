//! The CNC side of a scenario: its channels on one image, ticking; and the in-process run
//! that alternates CNC ticks and PLC timeline cycles on a heap image exactly as lockstep mode
//! alternates the two processes (tests use it; `cnc run --lockstep` gives the same trace).
//! A timeline that calls function blocks gets the same acyclic service as the PLC process,
//! opened in this process under a name of its own, and the machine answers it between the
//! tick and the PLC cycle, as `cnc run` does.

use super::file::{PlcSetup, Scenario, ScenarioError};
use super::trace::Trace;
use cnc_core::channel::config::ProgramStart;
use cnc_core::channel::Channel;
use cnc_core::machine::engines::{self, EngineSetup};
pub use cnc_core::machine::Machine;
use cnc_core::machine::MachineSetup;
use hli::views::{CncView, PlcView};
use hli::ImageMemory;
use hli_transport::rpc::{AcyclicClient, AcyclicServer};
use plc_shim::runtime::{PlcIo, PlcProgram};
use plc_shim::timeline::Timeline;
use std::sync::atomic::{AtomicU32, Ordering};

/// Builds the machine of a scenario: its channels with their programs started, channel axes
/// on ideal drives.
pub fn build(scenario: &Scenario) -> Result<Machine, ScenarioError> {
    let invalid = |message: String| ScenarioError::Invalid {
        file: scenario.name.clone(),
        message,
    };
    let mut channels = Vec::with_capacity(scenario.channels.len());
    for (i, (config, program)) in scenario.channels.iter().zip(&scenario.programs).enumerate() {
        let mut channel = Channel::new(i, config.clone(), scenario.cycle_s)
            .map_err(|e| invalid(e.to_string()))?;
        match program {
            Some(p) if config.program_start == ProgramStart::Plc => channel.select(p.clone()),
            Some(p) => channel
                .start(p.clone())
                .expect("a channel that has not run starts"),
            None => {}
        }
        if let Some(Some(folder)) = scenario.folders.get(i) {
            channel.set_program_folder(folder.clone());
        }
        channels.push(channel);
    }
    let channel_axes = super::axes::axis_names(&scenario.channels, &[]).len();
    let setup = EngineSetup {
        channel_axes,
        single_axes: scenario.axes.len(),
        cycle_s: scenario.cycle_s,
    };
    let engines =
        engines::standard(&setup, &scenario.engines).map_err(|e| invalid(e.to_string()))?;
    let mut machine = Machine::new(MachineSetup {
        channels,
        axes: scenario.axes.iter().map(|a| a.config.clone()).collect(),
        engines,
        cycle_s: scenario.cycle_s,
    })
    .map_err(|e| invalid(e.to_string()))?;
    for (i, a) in scenario.axes.iter().enumerate() {
        if a.power {
            if let Some(axis) = machine.axes_mut().axis_mut(channel_axes + i) {
                axis.switch_on()
                    .map_err(|e| invalid(format!("[[axis]] {:?}: power: {e:?}", a.config.name)))?;
            }
        }
    }
    Ok(machine)
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
    /// The scenario's built-in PLC program (`[plc] program`), run in this process: the
    /// in-process twin of the PLC process.
    pub program: Option<BuiltIn>,
    /// The trace.
    pub trace: Trace,
    /// The acyclic service of a timeline that calls blocks or of a built-in program: the CNC's
    /// and the PLC's end.
    acyclic: Option<(AcyclicServer, AcyclicClient)>,
    plc_cycles: u64,
    /// The PLC task runs after every `plc_period`-th tick (the first one first).
    plc_period: u64,
    answered: u64,
}

/// A built-in PLC program run in the CNC's process.
pub struct BuiltIn(pub Box<dyn PlcProgram>);

impl core::fmt::Debug for BuiltIn {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("BuiltIn(PLC program)")
    }
}

/// Numbers the acyclic services of in-process runs (several may run in one process).
static IN_PROCESS_SERVICES: AtomicU32 = AtomicU32::new(0);

impl InProcess {
    /// A built-in program's cycle: the calls answered, then the program.
    fn program_cycle(&mut self) {
        self.answer_calls();
        self.run_program();
    }

    /// Answers the acyclic calls the PLC side sent (between a tick and the PLC's cycle).
    pub fn answer_calls(&mut self) {
        let Some((server, _)) = self.acyclic.as_mut() else {
            return;
        };
        let view = CncView::new(&self.memory);
        let machine = &mut self.machine;
        let calls = server.poll(|kind, request| machine.dispatch(&view, kind, request));
        let rows = server.poll_rows(|_, header, values| machine.dispatch_bulk(header, values));
        self.answered += (calls.unwrap_or(0) + rows.unwrap_or(0)) as u64;
    }

    /// One cycle of the built-in PLC program alone (the calls are answered before, by
    /// [`InProcess::answer_calls`]); nothing without one.
    pub fn run_program(&mut self) {
        let (Some(program), Some((_, client))) = (self.program.as_mut(), self.acyclic.as_mut())
        else {
            return;
        };
        program.0.cycle(&mut PlcIo {
            view: PlcView::new(&self.memory),
            memory: &self.memory,
            acyclic: client,
            cycle: self.plc_cycles,
            link: plc_shim::runtime::Link::Operational,
        });
        self.plc_cycles += 1;
    }

    /// Sets up `scenario` on a heap image with room for `rows` trace rows. A built-in PLC
    /// program runs in this process, with the acyclic service it would have in its own.
    pub fn new(scenario: &Scenario, rows: usize) -> Result<InProcess, ScenarioError> {
        let invalid = |message: String| ScenarioError::Invalid {
            file: scenario.name.clone(),
            message,
        };
        let (timeline, program) = match &scenario.plc {
            PlcSetup::None => (None, None),
            PlcSetup::Timeline { timeline, .. } => {
                let mut timeline = Timeline::clone(timeline);
                timeline.count_ticks_of((scenario.file_cycle_s * 1e9).round() as u64);
                (Some(timeline), None)
            }
            PlcSetup::Program(p, args) => {
                let mut args = args.clone();
                let period = scenario.plc_period_ticks();
                if period > 1 {
                    args.extend(["--period-ticks".to_string(), period.to_string()]);
                }
                let program = plc_shim::cli::built_in_from(p, &args)
                    .map_err(|e| invalid(format!("[plc] program {p:?}: {e}")))?;
                (None, Some(BuiltIn(program)))
            }
        };
        let acyclic = match &timeline {
            _ if program.is_some() || timeline.as_ref().is_some_and(Timeline::calls_blocks) => {
                let instance = format!(
                    "inproc-{}-{}",
                    std::process::id(),
                    IN_PROCESS_SERVICES.fetch_add(1, Ordering::Relaxed)
                );
                let refused = |e: hli::calls::CallError| invalid(format!("acyclic service: {e}"));
                let server = AcyclicServer::open(&instance).map_err(refused)?;
                let client = AcyclicClient::open(&instance).map_err(refused)?;
                Some((server, client))
            }
            _ => None,
        };
        let machine = build(scenario)?;
        let memory =
            hli::image::heap_image(scenario.channels.len() as u32, machine.axis_images() as u32);
        // The header announces the run's cycle, as the CNC process's does.
        let at = core::mem::offset_of!(hli::layout::HliSegmentHeader, cnc_cycle_ns);
        memory
            .place::<u32>(at)
            .store((scenario.cycle_s * 1e9).round() as u32);
        Ok(InProcess {
            machine,
            memory,
            timeline,
            program,
            trace: Trace::new(&scenario.signals, rows),
            acyclic,
            plc_cycles: 0,
            plc_period: scenario.plc_period_ticks(),
            answered: 0,
        })
    }

    /// The whole scenario in-process: its `ticks` steps with a trace row each (the run
    /// `cnc run --lockstep` makes with a PLC process). A scenario without `ticks` runs none.
    pub fn run_through(scenario: &Scenario) -> Result<InProcess, ScenarioError> {
        let ticks = scenario.ticks.unwrap_or(0) as usize;
        let mut run = InProcess::new(scenario, ticks)?;
        for _ in 0..ticks {
            run.step(scenario.cycle_s);
        }
        Ok(run)
    }

    /// The trace as `cnc run --trace` writes it.
    pub fn trace_csv(&self) -> Vec<u8> {
        let mut csv = Vec::new();
        // Writing into a Vec cannot fail.
        let _ = self.trace.write_csv(&mut csv);
        csv
    }

    /// Calls the timeline sent and calls the CNC answered so far (a call sent in the last
    /// cycle is answered in the next step).
    pub fn calls(&self) -> (u64, u64) {
        let sent = self.acyclic.as_ref().map_or(0, |(_, client)| client.sent());
        (sent, self.answered)
    }

    /// One lockstep step: CNC tick, trace sample, acyclic calls answered, PLC cycle (the
    /// order of `cnc run --lockstep`). `cycle_s` gives the trace time.
    pub fn step(&mut self, cycle_s: f64) {
        let tick = self.machine.ticks();
        self.machine.tick(&self.memory);
        self.trace.record(&self.memory, tick, tick as f64 * cycle_s);
        self.plc_cycle();
        // Between this tick and the next, as `cnc run` does after "tick done".
        self.machine.serve_channels();
    }

    /// The PLC's cycle after a tick, with the acyclic calls answered first (after the ticks
    /// its task is due at).
    fn plc_cycle(&mut self) {
        let tick = self.machine.ticks().saturating_sub(1);
        if !tick.is_multiple_of(self.plc_period.max(1)) {
            // Not due: the CNC still answers the calls after every tick, as `cnc run` does.
            self.answer_calls();
            return;
        }
        if self.program.is_some() {
            return self.program_cycle();
        }
        let Some(timeline) = self.timeline.as_mut() else {
            return;
        };
        match self.acyclic.as_mut() {
            Some((server, client)) => {
                let view = CncView::new(&self.memory);
                let machine = &mut self.machine;
                let calls = server.poll(|kind, request| machine.dispatch(&view, kind, request));
                let rows =
                    server.poll_rows(|_, header, values| machine.dispatch_bulk(header, values));
                self.answered += (calls.unwrap_or(0) + rows.unwrap_or(0)) as u64;
                timeline.cycle_io(&mut PlcIo {
                    view: PlcView::new(&self.memory),
                    memory: &self.memory,
                    acyclic: client,
                    cycle: self.plc_cycles,
                    link: plc_shim::runtime::Link::Operational,
                });
            }
            None => {
                timeline.cycle(&self.memory);
            }
        }
        self.plc_cycles += 1;
    }
}
