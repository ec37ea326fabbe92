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

use super::ast::{Block, Command, Control, Expr, Item, Name, Program, Span, Target};
use super::control::{control_of, match_control, Jump, JumpTable};
use super::decode::{evaluate_at, Decoded, DecoderState, Vars};
use super::eval::truth;
use super::parser::MAX_PARAM;
use super::{parse, Diagnostic};
use std::path::{Path, PathBuf};

/// Deepest nesting of subroutine calls (the main program is level 0).
pub const MAX_CALL_DEPTH: usize = 16;
/// Most `V.P.` variables, and most live `V.L.` variables, of a run.
pub const MAX_VARIABLES: usize = 256;
/// Values of `$CASE` and `$SWITCH` closer than this are equal.
pub const CASE_TOLERANCE: f64 = 0.001;

/// One program file with its tree, jump table and resolved calls.
#[derive(Debug, Clone)]
pub struct Unit {
    /// The file name as given (for messages).
    pub name: String,
    /// The source text.
    pub src: String,
    /// The tree.
    pub tree: Program,
    /// The jumps of its `$` blocks.
    pub jumps: JumpTable,
    /// Per block with a call: where it goes (sorted by block).
    calls: Vec<(u32, Callee)>,
    /// A subroutine file (its diagnostics name it; the main file's are named by the caller).
    called: bool,
}

/// Where a call goes: blocks `blocks` of unit `unit`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Callee {
    unit: u32,
    start: u32,
    end: u32,
}

/// A main program and every subroutine file it reaches.
#[derive(Debug, Clone)]
pub struct ProgramSet {
    /// `units[0]` is the main program.
    pub units: Vec<Unit>,
}

/// Where `L name` looks for files: the calling file's folder, then these folders.
#[derive(Debug, Clone, Default)]
pub struct SearchPath(pub Vec<PathBuf>);

impl ProgramSet {
    /// Parses `src` (named `name`, in folder `dir` when it is a file) and every file its calls
    /// reach, resolving calls and matching control flow. Every problem is a diagnostic with its
    /// file; the set is only runnable when there are none.
    pub fn load(
        name: &str,
        src: String,
        dir: Option<&Path>,
        search: &SearchPath,
    ) -> (Self, Vec<Diagnostic>) {
        let mut set = ProgramSet { units: Vec::new() };
        let mut diags = Vec::new();
        let mut dirs: Vec<Option<PathBuf>> = Vec::new();
        let mut paths: Vec<Option<PathBuf>> = Vec::new();
        set.add_unit(name.to_string(), src, &mut diags);
        dirs.push(dir.map(Path::to_path_buf));
        paths.push(None);
        let mut u = 0;
        while u < set.units.len() {
            let calls: Vec<(u32, Span, bool, String)> = {
                let unit = &set.units[u];
                unit.tree
                    .blocks
                    .iter()
                    .enumerate()
                    .flat_map(|(b, block)| {
                        unit.tree
                            .items_of(block)
                            .iter()
                            .filter_map(move |i| match i {
                                Item::Call { call, span } => {
                                    Some((b as u32, *span, call.local, call.name.clone()))
                                }
                                _ => None,
                            })
                    })
                    .collect()
            };
            for (b, span, local, callee) in calls {
                let target = if local {
                    set.local_callee(u, b, &callee, span, &mut diags)
                } else {
                    set.global_callee(u, &callee, span, &dirs, &mut paths, search, &mut diags)
                        .map(|unit| {
                            if dirs.len() < set.units.len() {
                                let dir = paths[unit as usize]
                                    .as_deref()
                                    .and_then(Path::parent)
                                    .map(Path::to_path_buf);
                                dirs.push(dir);
                            }
                            let main = &set.units[unit as usize].tree;
                            Callee {
                                unit,
                                start: main.main_start,
                                end: main.blocks.len() as u32,
                            }
                        })
                };
                if let Some(t) = target {
                    set.units[u].calls.push((b, t));
                }
            }
            u += 1;
        }
        (set, diags)
    }

    fn add_unit(&mut self, name: String, src: String, diags: &mut Vec<Diagnostic>) -> u32 {
        let (tree, parse_diags) = parse(&src);
        let (jumps, unmatched) = match_control(&tree);
        let mut unit_diags = parse_diags;
        for u in unmatched {
            unit_diags.push(Diagnostic::new(u.span, u.message, &src));
        }
        super::locate(&mut unit_diags, &src);
        let called = !self.units.is_empty();
        let file: std::sync::Arc<str> = name.as_str().into();
        diags.extend(unit_diags.into_iter().map(|mut d| {
            if called {
                d.file = Some(file.clone());
            }
            d
        }));
        self.units.push(Unit {
            name,
            src,
            tree,
            jumps,
            calls: Vec::new(),
            called,
        });
        (self.units.len() - 1) as u32
    }

    fn error(&self, unit: usize, span: Span, message: String, diags: &mut Vec<Diagnostic>) {
        let u = &self.units[unit];
        let mut d = Diagnostic::new(span, message, &u.src);
        let mut one = [d];
        super::locate(&mut one, &u.src);
        [d] = one;
        diags.push(with_file(d, u));
    }

    fn local_callee(
        &self,
        unit: usize,
        block: u32,
        name: &str,
        span: Span,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<Callee> {
        let tree = &self.units[unit].tree;
        if block < tree.main_start {
            self.error(
                unit,
                span,
                format!("LL {name}: local subroutines are called from the main program only"),
                diags,
            );
            return None;
        }
        let upper = name.to_ascii_uppercase();
        match tree.subs.iter().find(|s| s.name == upper) {
            Some(sub) => Some(Callee {
                unit: unit as u32,
                start: sub.blocks.start,
                end: sub.blocks.end,
            }),
            None => {
                let known: Vec<&str> = tree.subs.iter().map(|s| s.name.as_str()).collect();
                self.error(
                    unit,
                    span,
                    format!(
                        "LL {name}: no local subroutine \"%L {upper}\" in this file (defined: {})",
                        if known.is_empty() {
                            "none".to_string()
                        } else {
                            known.join(", ")
                        }
                    ),
                    diags,
                );
                None
            }
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn global_callee(
        &mut self,
        unit: usize,
        name: &str,
        span: Span,
        dirs: &[Option<PathBuf>],
        paths: &mut Vec<Option<PathBuf>>,
        search: &SearchPath,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<u32> {
        let relative = Path::new(name);
        let candidates: Vec<PathBuf> = if relative.is_absolute() {
            vec![relative.to_path_buf()]
        } else {
            dirs[unit]
                .iter()
                .chain(search.0.iter())
                .map(|d| d.join(relative))
                .chain(dirs[unit].is_none().then(|| relative.to_path_buf()))
                .collect()
        };
        let Some(found) = candidates.iter().find(|p| p.is_file()) else {
            let looked: Vec<String> = candidates.iter().map(|p| p.display().to_string()).collect();
            self.error(
                unit,
                span,
                format!(
                    "L {name}: subroutine file not found (looked at: {})",
                    looked.join(", ")
                ),
                diags,
            );
            return None;
        };
        let canonical = found.canonicalize().unwrap_or_else(|_| found.clone());
        if let Some(u) = paths.iter().position(|p| p.as_ref() == Some(&canonical)) {
            return Some(u as u32);
        }
        let src = match std::fs::read(found) {
            Ok(bytes) => String::from_utf8_lossy(&bytes).into_owned(),
            Err(e) => {
                self.error(
                    unit,
                    span,
                    format!("L {name}: cannot read {}: {e}", found.display()),
                    diags,
                );
                return None;
            }
        };
        let u = self.add_unit(found.display().to_string(), src, diags);
        paths.push(Some(canonical));
        Some(u)
    }

    /// The unit of the main program.
    pub fn main(&self) -> &Unit {
        &self.units[0]
    }

    /// Number of blocks of all units.
    pub fn block_count(&self) -> usize {
        self.units.iter().map(|u| u.tree.blocks.len()).sum()
    }
}

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
/// once: stepping allocates nothing (except for a diagnostic).
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
    ) -> Result<Step, Diagnostic> {
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
            let next = self.jump(unit, b, jump, block, system)?;
            self.top().next = next as u32;
            return Ok(Step::Control);
        }
        if control_of(&unit.tree, b).is_some() {
            // `$ENDIF`, `$DO`, `$DEFAULT`, `$ENDSWITCH`: nothing to do.
            self.top().next += 1;
            return Ok(Step::Control);
        }
        self.top().next += 1;
        let BlockEnd { call, leave, end } = self
            .run_block(&unit.tree, b, &unit.src, decoder, system, out)
            .map_err(|d| with_file(d, unit))?;
        if let Some(span) = call {
            let callee = unit
                .calls
                .binary_search_by_key(&(b as u32), |c| c.0)
                .ok()
                .map(|i| unit.calls[i].1);
            let Some(callee) = callee else {
                return Err(with_file(
                    Diagnostic::new(
                        span,
                        "the subroutine of this call was not loaded".into(),
                        &unit.src,
                    ),
                    unit,
                ));
            };
            if self.frames.len() > MAX_CALL_DEPTH {
                return Err(with_file(
                    Diagnostic::new(
                        span,
                        format!("subroutine calls nest deeper than {MAX_CALL_DEPTH} levels (a recursion without end?)"),
                        &unit.src,
                    ),
                    unit,
                ));
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
    /// block ends (a call, M17/M29, M2/M30); following that is the caller's.
    pub fn run_block(
        &mut self,
        tree: &Program,
        b: usize,
        src: &str,
        decoder: &mut DecoderState,
        system: &dyn Vars,
        out: &mut Vec<Decoded>,
    ) -> Result<BlockEnd, Diagnostic> {
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
                    let value = evaluate_at(&assign.value, *span, src, &env)?;
                    self.assign(assign.target, value)
                        .map_err(|m| Diagnostic::new(*span, m, src))?;
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
        let diags = decoder.decode_block_unlocated(tree, b, src, &env, out);
        match diags.into_iter().next() {
            Some(d) => Err(d),
            None => Ok(ending),
        }
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

    fn assign(&mut self, target: Target, value: f64) -> Result<(), String> {
        match target {
            Target::Param(n) => {
                let slot = self.params.get_mut(n as usize).ok_or_else(|| format!("P{n} does not exist"))?;
                *slot = Some(value);
            }
            Target::Var(name) if name.starts_with("V.P.") => {
                if let Some(v) = self.globals.iter_mut().find(|(n, _)| *n == name) {
                    v.1 = value;
                } else if self.globals.len() < MAX_VARIABLES {
                    self.globals.push((name, value));
                } else {
                    return Err(format!("more than {MAX_VARIABLES} V.P. variables"));
                }
            }
            Target::Var(name) if name.starts_with("V.L.") => {
                let mark = self.frames.last().map_or(0, |f| f.locals_mark as usize);
                let existing = if self.declaring {
                    // A declaration makes the level its own variable (shadowing an outer one).
                    self.locals[mark..].iter_mut().rev().find(|(n, _)| *n == name)
                } else {
                    self.locals.iter_mut().rev().find(|(n, _)| *n == name)
                };
                if let Some(v) = existing {
                    v.1 = value;
                } else if self.locals.len() < MAX_VARIABLES {
                    self.locals.push((name, value));
                } else {
                    return Err(format!("more than {MAX_VARIABLES} live V.L. variables"));
                }
            }
            Target::Var(name) => {
                return Err(format!(
                    "\"{name}\" cannot be assigned: a program assigns P parameters, V.P. and V.L. variables"
                ))
            }
        }
        Ok(())
    }

    /// Follows the `$` statement of block `b`; returns the next block.
    fn jump(
        &mut self,
        unit: &Unit,
        b: usize,
        jump: Jump,
        block: &Block,
        system: &dyn Vars,
    ) -> Result<usize, Diagnostic> {
        let here = Here {
            unit,
            b,
            block,
            system,
        };
        Ok(match (jump, control_of(&unit.tree, b)) {
            (Jump::While { end }, Some(Control::While(c))) => {
                if truth(here.eval(self, c)?) {
                    b + 1
                } else {
                    end + 1
                }
            }
            (Jump::EndWhile { start }, _) => start,
            (Jump::If { end, .. }, Some(Control::ElseIf(_))) => end + 1,
            (Jump::If { .. }, Some(Control::If(_))) => self.if_chain(&here)?,
            (Jump::Else { end }, _) => end + 1,
            (
                Jump::For { end },
                Some(Control::For {
                    var,
                    start,
                    end: last,
                    step,
                }),
            ) => self.for_start(&here, *var, [start, last, step], end)?,
            (Jump::EndFor { start }, _) => self.end_for(&here, start)?,
            (Jump::EndDo { start }, Some(Control::EndDo(c))) => {
                if truth(here.eval(self, c)?) {
                    start + 1
                } else {
                    b + 1
                }
            }
            (
                Jump::Switch {
                    first_case,
                    default,
                    end,
                },
                Some(Control::Switch(v)),
            ) => {
                let target = default.map_or(end + 1, |d| d + 1);
                self.switch(&here, v, first_case, target)?
            }
            (Jump::Case { .. }, _) => b + 1,
            (Jump::Go { to }, _) => to,
            _ => b + 1,
        })
    }

    /// `$IF` and its `$ELSEIF`s, tested in turn: the first block of the branch that runs, or
    /// after the chain's `$ELSE` or `$ENDIF`.
    fn if_chain(&mut self, here: &Here<'_>) -> Result<usize, Diagnostic> {
        let unit = here.unit;
        let mut at = here.b;
        Ok(loop {
            let (Some(Jump::If { next, .. }), Some(Control::If(c) | Control::ElseIf(c))) =
                (unit.jumps.get(at), control_of(&unit.tree, at))
            else {
                break at + 1;
            };
            if truth(here.eval_in(self, at, c)?) {
                break at + 1;
            }
            match control_of(&unit.tree, next) {
                Some(Control::ElseIf(_)) => at = next,
                _ => break next + 1,
            }
        })
    }

    /// `$FOR var = start, last, step` (`bounds`): sets the counter; the loop's first block,
    /// or after its `$ENDFOR` at `end` when the counter is past `last` already.
    fn for_start(
        &mut self,
        here: &Here<'_>,
        var: Target,
        bounds: [&Expr; 3],
        end: usize,
    ) -> Result<usize, Diagnostic> {
        let [start, last, step] = bounds;
        let first = here.eval(self, start)?;
        self.assign(var, first).map_err(|m| here.error(m))?;
        let (last, step) = (here.eval(self, last)?, here.eval(self, step)?);
        Ok(
            if self.for_continues(here.unit, here.block, first, last, step)? {
                here.b + 1
            } else {
                end + 1
            },
        )
    }

    /// `$ENDFOR` of the `$FOR` at `start`: steps the counter; back into the loop while it has
    /// not passed the end, else on after the `$ENDFOR`.
    fn end_for(&mut self, here: &Here<'_>, start: usize) -> Result<usize, Diagnostic> {
        let (unit, b) = (here.unit, here.b);
        let Some(Control::For {
            var,
            end: last,
            step,
            ..
        }) = control_of(&unit.tree, start)
        else {
            return Ok(b + 1);
        };
        let (last, step) = (
            here.eval_in(self, start, last)?,
            here.eval_in(self, start, step)?,
        );
        let env = Env {
            interp: self,
            system: here.system,
        };
        let current = match var {
            Target::Param(n) => env.param(*n),
            Target::Var(name) => env.get(name),
        }
        .unwrap_or(0.0);
        let value = current + step;
        self.assign(*var, value).map_err(|m| here.error(m))?;
        let for_block = &unit.tree.blocks[start];
        Ok(if self.for_continues(unit, for_block, value, last, step)? {
            start + 1
        } else {
            b + 1
        })
    }

    /// `$SWITCH v`: the first block of the `$CASE` from `first_case` on whose value matches,
    /// else `otherwise` (after the `$DEFAULT`, or after the `$ENDSWITCH`).
    fn switch(
        &mut self,
        here: &Here<'_>,
        v: &Expr,
        first_case: Option<usize>,
        otherwise: usize,
    ) -> Result<usize, Diagnostic> {
        let unit = here.unit;
        let value = here.eval(self, v)?;
        let mut case = first_case;
        let mut target = otherwise;
        while let Some(c) = case {
            if let Some(Control::Case(e)) = control_of(&unit.tree, c) {
                if (here.eval_in(self, c, e)? - value).abs() < CASE_TOLERANCE {
                    target = c + 1;
                    break;
                }
            }
            case = match unit.jumps.get(c) {
                Some(Jump::Case { next }) => next,
                _ => None,
            };
        }
        Ok(target)
    }

    fn for_continues(
        &self,
        unit: &Unit,
        block: &Block,
        value: f64,
        last: f64,
        step: f64,
    ) -> Result<bool, Diagnostic> {
        if step == 0.0 {
            return Err(with_file(
                Diagnostic::new(block.span, "$FOR with step 0 never ends".into(), &unit.src),
                unit,
            ));
        }
        Ok(if step > 0.0 {
            value <= last
        } else {
            value >= last
        })
    }
}

/// The `$` block being followed: block `b` of `unit`, and the channel's variables.
struct Here<'a> {
    unit: &'a Unit,
    b: usize,
    block: &'a Block,
    system: &'a dyn Vars,
}

impl Here<'_> {
    /// The value of `e`, an expression of block `at` (whose span its messages name).
    fn eval_in(&self, interp: &Interpreter, at: usize, e: &Expr) -> Result<f64, Diagnostic> {
        let span = self
            .unit
            .tree
            .blocks
            .get(at)
            .map_or(self.block.span, |bl| bl.span);
        let env = Env {
            interp,
            system: self.system,
        };
        evaluate_at(e, span, &self.unit.src, &env).map_err(|d| with_file(d, self.unit))
    }

    /// The value of `e`, an expression of the block itself.
    fn eval(&self, interp: &Interpreter, e: &Expr) -> Result<f64, Diagnostic> {
        self.eval_in(interp, self.b, e)
    }

    /// A diagnostic with `message` at the block.
    fn error(&self, message: String) -> Diagnostic {
        with_file(
            Diagnostic::new(self.block.span, message, &self.unit.src),
            self.unit,
        )
    }
}

/// Whether where `$` block `b` (with `jump`) leads depends on a `V.G.` value: its own
/// condition, and for an `$IF` chain every `$ELSEIF`, for a `$SWITCH` every `$CASE`, for an
/// `$ENDFOR` its `$FOR`'s bounds.
fn decided_by_machine(unit: &Unit, b: usize, jump: Jump) -> bool {
    let reads = |at: usize| control_of(&unit.tree, at).is_some_and(reads_machine_values);
    match jump {
        Jump::If { .. } if matches!(control_of(&unit.tree, b), Some(Control::If(_))) => {
            let mut at = b;
            loop {
                if reads(at) {
                    return true;
                }
                match unit.jumps.get(at) {
                    Some(Jump::If { next, .. })
                        if matches!(control_of(&unit.tree, next), Some(Control::ElseIf(_))) =>
                    {
                        at = next
                    }
                    _ => return false,
                }
            }
        }
        Jump::Switch { first_case, .. } => {
            let mut case = first_case;
            while let Some(c) = case {
                if reads(c) {
                    return true;
                }
                case = match unit.jumps.get(c) {
                    Some(Jump::Case { next }) => next,
                    _ => None,
                };
            }
            reads(b)
        }
        Jump::EndFor { start } => reads(start),
        _ => reads(b),
    }
}

/// Whether the condition of `control` reads a `V.G.` value.
fn reads_machine_values(control: &Control) -> bool {
    fn reads(e: &super::ast::Expr) -> bool {
        use super::ast::Expr;
        match e {
            Expr::Var(name) => name.starts_with("V.G."),
            Expr::Neg(inner) => reads(inner),
            Expr::Bin(bin) => reads(&bin.1) || reads(&bin.2),
            Expr::Call(call) => call.1.iter().any(reads),
            Expr::Num(_) | Expr::Param(_) => false,
        }
    }
    match control {
        Control::While(c)
        | Control::If(c)
        | Control::ElseIf(c)
        | Control::EndDo(c)
        | Control::Switch(c)
        | Control::Case(c) => reads(c),
        Control::For {
            start, end, step, ..
        } => reads(start) || reads(end) || reads(step),
        _ => false,
    }
}

fn with_file(mut d: Diagnostic, unit: &Unit) -> Diagnostic {
    if d.file.is_none() && unit.called {
        d.file = Some(unit.name.as_str().into());
    }
    d
}

/// Receives the decoded elements of each step of a run.
pub type BlockSink<'a> = &'a mut dyn FnMut(&[Decoded]);

/// Checks a loaded set for a channel: runs it once from the start with `vars` (at most
/// `budget` steps: a loop waiting for a value that only a running machine changes is no
/// error), then checks every block the run did not reach on its own. `keep` receives the
/// decoded stream of the run, step by step (`cnc check --blocks`). Returns the diagnostics, the first
/// per block, sorted by file and position.
pub fn check_set(
    set: &ProgramSet,
    decoder: &mut DecoderState,
    vars: &dyn Vars,
    budget: u64,
    mut keep: Option<BlockSink<'_>>,
) -> (Vec<Diagnostic>, bool) {
    let mut visited: Vec<Vec<bool>> = set
        .units
        .iter()
        .map(|u| vec![false; u.tree.blocks.len()])
        .collect();
    // Per unit: its diagnostics, located once at the end (locating one at a time would scan
    // the source once per diagnostic), and which blocks failed in the run.
    let mut found: Vec<Vec<Diagnostic>> = set.units.iter().map(|_| Vec::new()).collect();
    let mut failed: Vec<Vec<bool>> = visited.clone();
    let mut interp = Interpreter::new();
    interp.start(set);
    let mut scratch = Vec::with_capacity(8);
    let mut steps = 0u64;
    let mut finished = false;
    let fresh = decoder.clone();
    while steps < budget {
        steps += 1;
        scratch.clear();
        let at = interp.position();
        let current = interp.current_block();
        let step = interp.step(set, decoder, vars, &mut scratch);
        // The block the step ran (or failed in) has been checked by the run.
        if let (Some((u, b)), Ok(Step::Block { .. } | Step::Control) | Err(_)) = (current, &step) {
            if let Some(v) = visited[u as usize].get_mut(b as usize) {
                *v = true;
            }
        }
        // A block that failed hands on nothing.
        if let (Some(k), Ok(_)) = (keep.as_deref_mut(), &step) {
            if !scratch.is_empty() {
                k(&scratch);
            }
        }
        match step {
            Ok(Step::End) => {
                finished = true;
                break;
            }
            Ok(Step::Undecided) => break,
            Ok(_) => {}
            Err(d) => {
                let (u, b) = current.or(at).unwrap_or((0, 0));
                let again = failed[u as usize].get(b as usize).copied().unwrap_or(true);
                if again {
                    // A block failing a second time (in a loop): its error is known, and the
                    // run cannot be trusted past it.
                    break;
                }
                failed[u as usize][b as usize] = true;
                found[u as usize].push(d);
                interp.skip_failed(at);
            }
        }
    }
    // The blocks the run did not reach, each on its own: values of the program's own variables
    // are unknown there, and so is the modal state (a feed is assumed, the start is unknown).
    let unknown = Unknown { system: vars };
    for (u, unit) in set.units.iter().enumerate() {
        let mut state = fresh.clone();
        state.checked_out_of_run();
        for (b, seen) in visited[u].iter().enumerate() {
            if *seen {
                continue;
            }
            scratch.clear();
            let more =
                state.decode_block_unlocated(&unit.tree, b, &unit.src, &unknown, &mut scratch);
            found[u].extend(more.into_iter().map(|d| with_file(d, unit)));
        }
    }
    let mut diags = Vec::new();
    for (u, mut list) in found.into_iter().enumerate() {
        super::locate(&mut list, &set.units[u].src);
        diags.append(&mut list);
    }
    diags.sort_by(|a, b| {
        (a.file.as_deref(), a.line, a.col).cmp(&(b.file.as_deref(), b.line, b.col))
    });
    diags.dedup();
    (diags, finished)
}

/// Variables of a block checked on its own: the channel's as given, the program's unknown.
pub(crate) struct Unknown<'a> {
    pub(crate) system: &'a dyn Vars,
}

impl Vars for Unknown<'_> {
    fn get(&self, name: &str) -> Option<f64> {
        self.system.get(name)
    }
    fn program_values_unknown(&self) -> bool {
        true
    }
}
