//! Following the `$` statements through a unit's jump table, and telling which of them a
//! check cannot follow without a running machine.

use super::{Env, Interpreter, ProgramFault, Unit, CASE_TOLERANCE};
use crate::nc::ast::{Block, Control, Expr, Span, Target};
use crate::nc::control::{control_of, Jump};
use crate::nc::decode::{evaluate, Vars};
use crate::nc::eval::truth;

/// A fault and the span of the block it stands at.
type Failed = (Span, ProgramFault);

impl Interpreter {
    /// Follows the `$` statement of block `b`; returns the next block.
    pub(super) fn jump(
        &mut self,
        unit: &Unit,
        b: usize,
        jump: Jump,
        block: &Block,
        system: &dyn Vars,
    ) -> Result<usize, Failed> {
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
    fn if_chain(&mut self, here: &Here<'_>) -> Result<usize, Failed> {
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
    ) -> Result<usize, Failed> {
        let [start, last, step] = bounds;
        let first = here.eval(self, start)?;
        self.assign(var, first).map_err(|m| here.error(m))?;
        let (last, step) = (here.eval(self, last)?, here.eval(self, step)?);
        Ok(if self.for_continues(here.block, first, last, step)? {
            here.b + 1
        } else {
            end + 1
        })
    }

    /// `$ENDFOR` of the `$FOR` at `start`: steps the counter; back into the loop while it has
    /// not passed the end, else on after the `$ENDFOR`.
    fn end_for(&mut self, here: &Here<'_>, start: usize) -> Result<usize, Failed> {
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
        Ok(if self.for_continues(for_block, value, last, step)? {
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
    ) -> Result<usize, Failed> {
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
        block: &Block,
        value: f64,
        last: f64,
        step: f64,
    ) -> Result<bool, Failed> {
        if step == 0.0 {
            return Err((block.span, ProgramFault::ForStepZero));
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
    fn eval_in(&self, interp: &Interpreter, at: usize, e: &Expr) -> Result<f64, Failed> {
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
        evaluate(e, &env).map_err(|error| (span, error.into()))
    }

    /// The value of `e`, an expression of the block itself.
    fn eval(&self, interp: &Interpreter, e: &Expr) -> Result<f64, Failed> {
        self.eval_in(interp, self.b, e)
    }

    /// `fault` at the block.
    fn error(&self, fault: ProgramFault) -> Failed {
        (self.block.span, fault)
    }
}

/// Whether where `$` block `b` (with `jump`) leads depends on a `V.G.` value: its own
/// condition, and for an `$IF` chain every `$ELSEIF`, for a `$SWITCH` every `$CASE`, for an
/// `$ENDFOR` its `$FOR`'s bounds.
pub(super) fn decided_by_machine(unit: &Unit, b: usize, jump: Jump) -> bool {
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
    fn reads(e: &Expr) -> bool {
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
