//! The interpreter: runs a program block by block the way a channel consumes it, following
//! `$` statements, assignments and subroutine calls, and hands each block with its variable
//! values to the decoder.
//!
//! * A [`ProgramSet`] is the main program with every file its `L name` calls reach, loaded
//!   and checked once: calls, jump tables and `%L` subroutines are resolved there, so running
//!   allocates nothing (the call stack and the variable stores have fixed capacities).
//! * P parameters and `V.P.` variables belong to the whole run: a subroutine sees and changes
//!   its caller's (that is how the dialect hands data to subroutines). `V.L.` variables belong
//!   to the level that assigns them and the subroutines it calls; they end with that level.
//! * A condition holds when its value is at least 0.5 in size; `$CASE` values match within
//!   0.001; a `$CASE` branch runs on into the next one unless it ends with `$BREAK`.
//!
//! This module runs the blocks ([`Interpreter`]); `load` builds the [`ProgramSet`], `jump`
//! follows the `$` statements, `check` runs a set once to check it ([`check_set`]), and
//! `error` holds [`StepError`], why a step failed as a value (a check makes a diagnostic of
//! it, a channel keeps it).

mod check;
mod error;
mod jump;
mod load;

pub(crate) use check::Unknown;
pub use check::{check_set, BlockSink};
pub use error::{ProgramFault, StepError};
pub use load::{ProgramSet, SearchPath, Unit};

use super::ast::{Command, Item, Name, Program, Span, Target};
use super::control::control_of;
use super::decode::{evaluate, Decoded, DecoderState, Vars};
use super::parser::MAX_PARAM;
use super::Diagnostic;
use jump::decided_by_machine;

/// Deepest nesting of subroutine calls (the main program is level 0).
pub const MAX_CALL_DEPTH: usize = 16;
/// Most `V.P.` variables, and most live `V.L.` variables, of a run.
pub const MAX_VARIABLES: usize = 256;
/// Values of `$CASE` and `$SWITCH` closer than this are equal.
pub const CASE_TOLERANCE: f64 = 0.001;

/// One level of the call stack: the unit, the next block and the end of the level's blocks.
#[derive(Debug, Clone, Copy)]
struct Frame {
    unit: u32,
    next: u32,
    end: u32,
    /// How many `V.L.` variables lived when the level was entered.
    locals_mark: u32,
    /// Whether the caller was inside `#VAR` ... `#ENDVAR` (restored on return).
    caller_declaring: bool,
}

/// How a block ends besides its motion.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct BlockEnd {
    /// A subroutine call at this span.
    pub call: Option<Span>,
    /// M17/M29: a subroutine returns.
    pub leave: bool,
    /// M2/M30: the program ends.
    pub end: bool,
}

/// What one step did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// A block was decoded into the output (possibly into nothing, like an assignment).
    Block {
        /// The unit and block index.
        unit: u32,
        /// Block index in the unit.
        block: u32,
    },
    /// A `$` statement was followed.
    Control,
    /// The program has ended (M2/M30, or past its last block).
    End,
    /// A condition reads a machine value that only a running machine has (a check runs
    /// without one): where the program goes from here is not known.
    Undecided,
}

/// The run-time state of a program: call stack and variables. Fixed capacities, allocated
/// once: stepping allocates nothing, also when it fails (its error is a value).
#[derive(Debug, Clone)]
pub struct Interpreter {
    frames: Vec<Frame>,
    params: Vec<Option<f64>>,
    globals: Vec<(Name, f64)>,
    locals: Vec<(Name, f64)>,
    /// Inside `#VAR` ... `#ENDVAR`: assignments declare (a `V.L.` shadows an outer one).
    declaring: bool,
    ended: bool,
}

impl Default for Interpreter {
    fn default() -> Self {
        Self::new()
    }
}

/// The variables a block sees: the program's own, then the channel's.
struct Env<'a> {
    interp: &'a Interpreter,
    system: &'a dyn Vars,
}

impl Vars for Env<'_> {
    fn get(&self, name: &str) -> Option<f64> {
        if name.starts_with("V.P.") {
            self.interp
                .globals
                .iter()
                .find(|(n, _)| *n == name)
                .map(|v| v.1)
        } else if name.starts_with("V.L.") {
            self.interp
                .locals
                .iter()
                .rev()
                .find(|(n, _)| *n == name)
                .map(|v| v.1)
        } else {
            self.system.get(name)
        }
    }

    fn param(&self, n: u32) -> Option<f64> {
        self.interp.params.get(n as usize).copied().flatten()
    }

    fn machine_values_known(&self) -> bool {
        self.system.machine_values_known()
    }
}

impl Interpreter {
    /// A fresh interpreter (no program started).
    pub fn new() -> Self {
        Self {
            frames: Vec::with_capacity(MAX_CALL_DEPTH + 1),
            params: vec![None; MAX_PARAM as usize + 1],
            globals: Vec::with_capacity(MAX_VARIABLES),
            locals: Vec::with_capacity(MAX_VARIABLES),
            declaring: false,
            ended: true,
        }
    }

    /// Starts the main program of `set`: variables cleared, at its first main block.
    pub fn start(&mut self, set: &ProgramSet) {
        self.reset_variables();
        let main = &set.main().tree;
        self.frames.push(Frame {
            unit: 0,
            next: main.main_start,
            end: main.blocks.len() as u32,
            locals_mark: 0,
            caller_declaring: false,
        });
        self.ended = false;
    }

    /// The call depth (0 in the main program).
    pub fn depth(&self) -> usize {
        self.frames.len().saturating_sub(1)
    }

    /// P parameter `n`, if assigned.
    pub fn param(&self, n: u32) -> Option<f64> {
        self.params.get(n as usize).copied().flatten()
    }

    /// The unit and block index the next step starts at (possibly one past the level's end).
    pub fn position(&self) -> Option<(u32, u32)> {
        self.frames.last().map(|f| (f.unit, f.next))
    }

    /// The unit and block index of the block the next step runs, if it runs one of the level.
    pub fn current_block(&self) -> Option<(u32, u32)> {
        self.frames
            .last()
            .filter(|f| f.next < f.end)
            .map(|f| (f.unit, f.next))
    }

    /// Runs one step: a `$` statement, or one block decoded into `out` with `decoder`.
    pub fn step(
        &mut self,
        set: &ProgramSet,
        decoder: &mut DecoderState,
        system: &dyn Vars,
        out: &mut Vec<Decoded>,
    ) -> Result<Step, StepError> {
        let Some(&frame) = self.frames.last() else {
            self.ended = true;
            return Ok(Step::End);
        };
        if self.ended {
            return Ok(Step::End);
        }
        if frame.next >= frame.end {
            // Past the level's last block: a subroutine returns, the main program ends.
            if self.frames.len() > 1 {
                self.leave();
                return Ok(Step::Control);
            }
            self.ended = true;
            return Ok(Step::End);
        }
        let unit = &set.units[frame.unit as usize];
        let b = frame.next as usize;
        let block = &unit.tree.blocks[b];
        if let Some(jump) = unit.jumps.get(b) {
            if !system.machine_values_known() && decided_by_machine(unit, b, jump) {
                return Ok(Step::Undecided);
            }
            let next = self
                .jump(unit, b, jump, block, system)
                .map_err(|(span, fault)| StepError {
                    unit: frame.unit,
                    span,
                    fault,
                })?;
            self.top().next = next as u32;
            return Ok(Step::Control);
        }
        if control_of(&unit.tree, b).is_some() {
            // `$ENDIF`, `$DO`, `$DEFAULT`, `$ENDSWITCH`: nothing to do.
            self.top().next += 1;
            return Ok(Step::Control);
        }
        self.top().next += 1;
        let failed = |(span, fault)| StepError {
            unit: frame.unit,
            span,
            fault,
        };
        let BlockEnd { call, leave, end } = self
            .run_block_in_run(&unit.tree, b, decoder, system, out)
            .map_err(failed)?;
        if let Some(span) = call {
            let callee = unit
                .calls
                .binary_search_by_key(&(b as u32), |c| c.0)
                .ok()
                .map(|i| unit.calls[i].1);
            let Some(callee) = callee else {
                return Err(failed((span, ProgramFault::CallNotLoaded)));
            };
            if self.frames.len() > MAX_CALL_DEPTH {
                return Err(failed((span, ProgramFault::CallDepth)));
            }
            self.frames.push(Frame {
                unit: callee.unit,
                next: callee.start,
                end: callee.end,
                locals_mark: self.locals.len() as u32,
                caller_declaring: self.declaring,
            });
            self.declaring = false;
        } else if end {
            self.ended = true;
        } else if leave && self.frames.len() > 1 {
            self.leave();
        }
        Ok(Step::Block {
            unit: frame.unit,
            block: b as u32,
        })
    }

    /// Runs block `b` of `tree` (parsed from `src`) that is no `$` statement: its assignments
    /// in order, then the block decoded with the variables as they are then. Says how the
    /// block ends (a call, M17/M29, M2/M30); following that is the caller's. For a checker:
    /// the error is a diagnostic (see [`Interpreter::run_block_in_run`]).
    pub fn run_block(
        &mut self,
        tree: &Program,
        b: usize,
        src: &str,
        decoder: &mut DecoderState,
        system: &dyn Vars,
        out: &mut Vec<Decoded>,
    ) -> Result<BlockEnd, Diagnostic> {
        self.run_block_in_run(tree, b, decoder, system, out)
            .map_err(|(span, fault)| {
                Diagnostic::new(span, fault.with_axes(decoder.axes()).to_string(), src)
            })
    }

    /// [`Interpreter::run_block`] as a running channel needs it: the error is a value, the
    /// fault and where it stands, and nothing is allocated.
    pub fn run_block_in_run(
        &mut self,
        tree: &Program,
        b: usize,
        decoder: &mut DecoderState,
        system: &dyn Vars,
        out: &mut Vec<Decoded>,
    ) -> Result<BlockEnd, (Span, ProgramFault)> {
        let mut ending = BlockEnd::default();
        let Some(block) = tree.blocks.get(b) else {
            return Ok(ending);
        };
        for item in tree.items_of(block) {
            match item {
                Item::Assign { assign, span } => {
                    let env = Env {
                        interp: self,
                        system,
                    };
                    let value = evaluate(&assign.value, &env).map_err(|e| (*span, e.into()))?;
                    self.assign(assign.target, value)
                        .map_err(|fault| (*span, fault))?;
                }
                Item::Call { span, .. } => ending.call = Some(*span),
                Item::M { code: 17 | 29, .. } => ending.leave = true,
                Item::M { code: 2 | 30, .. } => ending.end = true,
                Item::Command { command, .. } => match command.as_ref() {
                    Command::Var => self.declaring = true,
                    Command::EndVar => self.declaring = false,
                    _ => {}
                },
                _ => {}
            }
        }
        let env = Env {
            interp: self,
            system,
        };
        decoder
            .decode_block_in_run(tree, b, &env, out)
            .map_err(|(span, e)| (span, e.into()))?;
        Ok(ending)
    }

    /// Clears the variables for a new run without a program set (a checker running a straight
    /// program window by window with [`Interpreter::run_block`]).
    pub fn reset_variables(&mut self) {
        self.frames.clear();
        self.params.iter_mut().for_each(|p| *p = None);
        self.globals.clear();
        self.locals.clear();
        self.declaring = false;
    }

    /// Goes on after the block that failed (a check reports every error, not the first).
    pub fn skip_failed(&mut self, at: Option<(u32, u32)>) {
        if self.position() == at {
            if let Some(f) = self.frames.last_mut() {
                f.next += 1;
            }
        }
    }

    fn top(&mut self) -> &mut Frame {
        let last = self.frames.len() - 1;
        &mut self.frames[last]
    }

    /// Returns from a subroutine: its `V.L.` variables end.
    fn leave(&mut self) {
        if let Some(f) = self.frames.pop() {
            self.locals.truncate(f.locals_mark as usize);
            self.declaring = f.caller_declaring;
        }
    }

    fn assign(&mut self, target: Target, value: f64) -> Result<(), ProgramFault> {
        match target {
            Target::Param(n) => {
                let slot = self
                    .params
                    .get_mut(n as usize)
                    .ok_or(ProgramFault::NoSuchParam { number: n })?;
                *slot = Some(value);
            }
            Target::Var(name) if name.starts_with("V.P.") => {
                if let Some(v) = self.globals.iter_mut().find(|(n, _)| *n == name) {
                    v.1 = value;
                } else if self.globals.len() < MAX_VARIABLES {
                    self.globals.push((name, value));
                } else {
                    return Err(ProgramFault::TooManyGlobals);
                }
            }
            Target::Var(name) if name.starts_with("V.L.") => {
                let mark = self.frames.last().map_or(0, |f| f.locals_mark as usize);
                let existing = if self.declaring {
                    // A declaration makes the level its own variable (shadowing an outer one).
                    self.locals[mark..]
                        .iter_mut()
                        .rev()
                        .find(|(n, _)| *n == name)
                } else {
                    self.locals.iter_mut().rev().find(|(n, _)| *n == name)
                };
                if let Some(v) = existing {
                    v.1 = value;
                } else if self.locals.len() < MAX_VARIABLES {
                    self.locals.push((name, value));
                } else {
                    return Err(ProgramFault::TooManyLocals);
                }
            }
            Target::Var(name) => return Err(ProgramFault::NotAssignable { name }),
        }
        Ok(())
    }
}

/// `d` with the file of `unit` when that is a called file (the caller names the main file).
fn with_file(mut d: Diagnostic, unit: &Unit) -> Diagnostic {
    if d.file.is_none() && unit.called {
        d.file = Some(unit.name.as_str().into());
    }
    d
}
