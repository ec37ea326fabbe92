//! PLC programs in Structured Text (`plc-st`, docs/plc-st.md) on the PLC runtime: the files
//! are loaded with the HLI's declarations (`hli::st_prelude`), so `gpCh`, `gpAx` and `gpFifo`
//! point into the image; every PROGRAM runs each cycle on the PLC's clock (the PLC cycles
//! times the task's period, so a lockstep run is the same every time). A fault stops the
//! program: the runtime then ends without another heartbeat and the CNC stops as for a lost
//! PLC; the summary names the fault with its FILE:LINE:COL.

pub mod host;
pub mod library;
pub mod vars;

use crate::runtime::{PlcIo, PlcProgram};
use hli::layout::HliSegmentHeader;
use host::Blocks;
use library::{Library, LIBRARY};
use plc_st::vm::{FaultAt, Program};
use std::path::PathBuf;

/// The name the HLI's declarations are loaded under (diagnostics in them name it).
pub const PRELUDE: &str = "<hli>";

/// A Structured Text program on the runtime.
#[derive(Debug)]
pub struct StProgram {
    program: Program,
    blocks: Blocks,
    /// The variables published for the tools, once [`StProgram::publish_on`] made them.
    publisher: Option<vars::Publisher>,
    period_ticks: u64,
    cycles: u64,
    fault: Option<FaultAt>,
}

impl StProgram {
    /// Loads `files` (with the HLI's declarations), run every `period_ticks` CNC ticks; `Err`
    /// is every diagnostic, one per line, `FILE:LINE:COL: error: ..`.
    pub fn load(files: &[PathBuf], period_ticks: u64) -> Result<StProgram, String> {
        let mut texts = Vec::with_capacity(files.len());
        for f in files {
            let text = std::fs::read_to_string(f).map_err(|e| format!("{}: {e}\n", f.display()))?;
            texts.push((f.display().to_string(), text));
        }
        StProgram::from_texts(&texts, period_ticks)
    }

    /// As [`StProgram::load`], from the files' names and texts.
    pub fn from_texts(files: &[(String, String)], period_ticks: u64) -> Result<StProgram, String> {
        let prelude = hli::st_prelude::generate();
        let library = Library::new();
        let mut refs: Vec<(&str, &str)> =
            vec![(PRELUDE, prelude.as_str()), (LIBRARY, library.text())];
        refs.extend(files.iter().map(|(n, t)| (n.as_str(), t.as_str())));
        let mut program = Program::load_with(&refs, &library.names())
            .map_err(|errors| errors.iter().map(|d| format!("{d}\n")).collect::<String>())?;
        program.bind_image();
        let blocks = Blocks::new(library.clone(), program.library_instances());
        Ok(StProgram {
            program,
            blocks,
            publisher: None,
            period_ticks: period_ticks.max(1),
            cycles: 0,
            fault: None,
        })
    }

    /// How many POUs the program's own files declare (not the HLI's or the library's), and
    /// how many methods and actions of them.
    pub fn pous(&self) -> (usize, usize) {
        let files = &self.program.code().files;
        let own = |p: &&plc_st::check::PouDef| {
            files
                .get(p.file)
                .is_some_and(|f| f != PRELUDE && f != LIBRARY)
        };
        let pous = self.program.code().checked.pous.iter().filter(own);
        let methods = pous.clone().filter(|p| p.method.is_some()).count();
        (pous.count() - methods, methods)
    }

    /// Publishes the program's variables for `plc get|set|watch` on instance `instance`
    /// ([`vars`]), from the next cycle on.
    pub fn publish_on(&mut self, instance: &str) -> Result<(), String> {
        self.publisher = Some(vars::Publisher::create(instance, &self.program)?);
        Ok(())
    }

    /// The program.
    pub fn program(&self) -> &Program {
        &self.program
    }

    /// The fault that stopped it, if one did.
    pub fn fault(&self) -> Option<FaultAt> {
        self.fault
    }
}

impl PlcProgram for StProgram {
    fn cycle(&mut self, io: &mut PlcIo<'_>) {
        if self.fault.is_some() {
            if let Some(p) = &mut self.publisher {
                p.serve(&self.program);
            }
            return;
        }
        let at = core::mem::offset_of!(HliSegmentHeader, cnc_cycle_ns);
        let tick_ns = u64::from(io.memory.place::<u32>(at).load());
        let now = self
            .cycles
            .saturating_mul(self.period_ticks)
            .saturating_mul(tick_ns);
        self.cycles += 1;
        if self
            .publisher
            .as_ref()
            .is_some_and(|p| p.take_write(&mut self.program))
        {
            self.blocks.forget_outputs();
        }
        let memory = io.memory;
        let mut host = self
            .blocks
            .host(io, self.period_ticks.saturating_mul(tick_ns));
        if let Err(fault) = self
            .program
            .cycle_with(now as i64, Some(memory), Some(&mut host))
        {
            self.fault = Some(fault);
        }
        if let Some(p) = &mut self.publisher {
            p.publish(&self.program);
        }
    }

    fn halted(&self) -> bool {
        self.fault.is_some()
    }

    fn summary(&self) -> String {
        match &self.fault {
            Some(f) => format!(
                "st: stopped after {} cycles: {}",
                self.cycles,
                self.program.fault_text(f)
            ),
            None => format!("st: {} cycles", self.cycles),
        }
    }
}
