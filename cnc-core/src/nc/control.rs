//! Control flow of a program: the `$` statements matched once, level by level (each local
//! subroutine and the main program on their own: no statement and no `$GOTO` crosses a level),
//! into the jump table the interpreter ([`super::interp`]) follows.

use super::ast::{Block, Control, Item, Program, Span};

/// Where control goes from a `$` block (block indices of the program).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Jump {
    /// `$WHILE`: when the condition is false, continue after `end` (its `$ENDWHILE`).
    While {
        /// The matching `$ENDWHILE`.
        end: usize,
    },
    /// `$ENDWHILE`: back to `start` (its `$WHILE`).
    EndWhile {
        /// The matching `$WHILE`.
        start: usize,
    },
    /// `$IF` and `$ELSEIF` when tested: when false, on to `next` (the next `$ELSEIF`, which is
    /// tested in turn, or the `$ELSE` or `$ENDIF`, after which the program continues). An
    /// `$ELSEIF` reached at the end of a true branch continues after `end`.
    If {
        /// The next branch.
        next: usize,
        /// The matching `$ENDIF`.
        end: usize,
    },
    /// `$ELSE` reached from a true branch: continue after `end` (its `$ENDIF`).
    Else {
        /// The matching `$ENDIF`.
        end: usize,
    },
    /// `$FOR`: the counter is set; when it has passed the end, continue after `end`.
    For {
        /// The matching `$ENDFOR`.
        end: usize,
    },
    /// `$ENDFOR`: the counter steps and is tested at `start` (its `$FOR`).
    EndFor {
        /// The matching `$FOR`.
        start: usize,
    },
    /// `$ENDDO`: while the condition holds, again after `start` (its `$DO`).
    EndDo {
        /// The matching `$DO`.
        start: usize,
    },
    /// `$SWITCH`: the value is compared with the `$CASE`s from `first_case` on.
    Switch {
        /// The first `$CASE`, if any.
        first_case: Option<usize>,
        /// The `$DEFAULT`, if any.
        default: Option<usize>,
        /// The matching `$ENDSWITCH`.
        end: usize,
    },
    /// `$CASE`: the next `$CASE` of the same `$SWITCH`. Reached from the branch before, it
    /// falls through (write `$BREAK` to leave).
    Case {
        /// The next `$CASE`, if any.
        next: Option<usize>,
    },
    /// `$BREAK`, `$CONTINUE`, `$GOTO`: continue at `to`.
    Go {
        /// The block to continue at.
        to: usize,
    },
}

/// A `$` statement that does not pair up.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Unmatched {
    /// The block it stands in.
    pub span: Span,
    /// What is missing.
    pub message: String,
}

/// The control statement of a block (a `$` statement stands alone in its block; the decoder
/// refuses a block where it does not).
pub fn control_of(program: &Program, block: usize) -> Option<&Control> {
    let block = program.blocks.get(block)?;
    control_in(program, block)
}

fn control_in<'a>(program: &'a Program, block: &Block) -> Option<&'a Control> {
    program.items_of(block).iter().find_map(|item| match item {
        Item::Control { control, .. } => Some(control.as_ref()),
        _ => None,
    })
}

/// The levels of a program: each local subroutine's blocks, then the main program's.
pub fn levels(program: &Program) -> Vec<core::ops::Range<usize>> {
    let mut levels: Vec<_> = program
        .subs
        .iter()
        .map(|s| s.blocks.start as usize..s.blocks.end as usize)
        .collect();
    levels.push(program.main_start as usize..program.blocks.len());
    levels
}

/// An open statement while matching.
enum Open {
    While(usize),
    If {
        start: usize,
        /// The `$ELSEIF`s and `$ELSE` so far.
        branches: Vec<usize>,
        seen_else: bool,
    },
    For(usize),
    Do(usize),
    Switch {
        start: usize,
        cases: Vec<usize>,
        default: Option<usize>,
    },
}

/// The jumps of a program's `$` blocks, by block (sorted; other blocks have none). Kept
/// sparse: a long program has few `$` blocks, and a slot per block would cost more memory than
/// the rest of its tree's bookkeeping.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct JumpTable(Vec<(usize, Jump)>);

impl JumpTable {
    /// The jump of block `b`.
    pub fn get(&self, b: usize) -> Option<Jump> {
        self.0
            .binary_search_by_key(&b, |e| e.0)
            .ok()
            .map(|i| self.0[i].1)
    }

    fn set(&mut self, b: usize, jump: Jump) {
        match self.0.binary_search_by_key(&b, |e| e.0) {
            Ok(i) => self.0[i].1 = jump,
            Err(i) => self.0.insert(i, (b, jump)),
        }
    }

    fn has(&self, b: usize) -> bool {
        self.get(b).is_some()
    }
}

/// Matches the `$` statements of `program`: per `$` block its jump, and every statement left
/// without a partner. The table is only complete when nothing is unmatched.
pub fn match_control(program: &Program) -> (JumpTable, Vec<Unmatched>) {
    let mut jumps = JumpTable::default();
    let mut unmatched = Vec::new();
    for level in levels(program) {
        match_level(program, level, &mut jumps, &mut unmatched);
    }
    (jumps, unmatched)
}

fn match_level(
    program: &Program,
    level: core::ops::Range<usize>,
    jumps: &mut JumpTable,
    unmatched: &mut Vec<Unmatched>,
) {
    let mut matching = LevelMatch {
        program,
        jumps,
        unmatched,
        open: Vec::new(),
        gotos: Vec::new(),
    };
    for b in level.clone() {
        let Some(control) = control_in(program, &program.blocks[b]) else {
            continue;
        };
        matching.statement(b, control);
    }
    matching.report_open();
    matching.resolve_gotos(level.clone());
    matching.report_stray_exits(level);
}

/// The matching of one level, statement by statement: what is still open, the `$GOTO`s (whose
/// targets are looked up once the level is read), and where jumps and problems go.
struct LevelMatch<'a> {
    program: &'a Program,
    jumps: &'a mut JumpTable,
    unmatched: &'a mut Vec<Unmatched>,
    open: Vec<Open>,
    gotos: Vec<(usize, u32)>,
}

impl LevelMatch<'_> {
    fn report(&mut self, b: usize, message: &str) {
        self.unmatched.push(Unmatched {
            span: self.program.blocks[b].span,
            message: message.to_string(),
        })
    }

    /// The `$` statement `control` of block `b`: opens, continues or closes a statement.
    fn statement(&mut self, b: usize, control: &Control) {
        match control {
            Control::While(_) => self.open.push(Open::While(b)),
            Control::If(_) => self.open.push(Open::If {
                start: b,
                branches: Vec::new(),
                seen_else: false,
            }),
            Control::For { .. } => self.open.push(Open::For(b)),
            Control::Do => self.open.push(Open::Do(b)),
            Control::Switch(_) => self.open.push(Open::Switch {
                start: b,
                cases: Vec::new(),
                default: None,
            }),
            Control::ElseIf(_) | Control::Else => self.branch(b, control),
            Control::Case(_) | Control::Default => self.case(b, control),
            Control::EndWhile => match self.open.last() {
                Some(&Open::While(start)) => self.close_loop(
                    start,
                    b,
                    Some(Jump::While { end: b }),
                    Jump::EndWhile { start },
                ),
                _ => self.report(b, "$ENDWHILE without a matching $WHILE"),
            },
            Control::EndFor => match self.open.last() {
                Some(&Open::For(start)) => {
                    self.close_loop(start, b, Some(Jump::For { end: b }), Jump::EndFor { start })
                }
                _ => self.report(b, "$ENDFOR without a matching $FOR"),
            },
            Control::EndDo(_) => match self.open.last() {
                Some(&Open::Do(start)) => self.close_loop(start, b, None, Jump::EndDo { start }),
                _ => self.report(b, "$ENDDO without a matching $DO"),
            },
            Control::EndIf => self.close_if(b),
            Control::EndSwitch => self.close_switch(b),
            // Given their jumps when their loop or `$SWITCH` closes; reported below if not.
            Control::Break | Control::Continue => {}
            Control::Goto(n) => self.gotos.push((b, *n)),
        }
    }

    /// `$ELSEIF` or `$ELSE` at block `b`: a branch of the open `$IF`.
    fn branch(&mut self, b: usize, control: &Control) {
        match self.open.last_mut() {
            Some(Open::If {
                branches,
                seen_else,
                ..
            }) if !*seen_else => {
                branches.push(b);
                *seen_else = matches!(control, Control::Else);
            }
            _ => self.report(b, &format!("${} without a matching $IF", control.keyword())),
        }
    }

    /// `$CASE` or `$DEFAULT` at block `b`: a case of the open `$SWITCH`.
    fn case(&mut self, b: usize, control: &Control) {
        // `$DEFAULT` may stand anywhere among the cases (reached sequentially it runs on
        // into the case after it, like any branch); once per `$SWITCH`.
        match self.open.last_mut() {
            Some(Open::Switch {
                default: Some(_), ..
            }) if matches!(control, Control::Default) => {
                self.report(b, "a second $DEFAULT in one $SWITCH")
            }
            Some(Open::Switch { cases, default, .. }) => {
                if matches!(control, Control::Default) {
                    *default = Some(b);
                } else {
                    cases.push(b);
                }
            }
            _ => self.report(
                b,
                &format!("${} without a matching $SWITCH", control.keyword()),
            ),
        }
    }

    /// Closes the innermost open statement, the loop from `start` to `end`: the jump of its
    /// first block (`$DO` has none), of its last, and of its `$BREAK`s and `$CONTINUE`s.
    fn close_loop(&mut self, start: usize, end: usize, first: Option<Jump>, last: Jump) {
        self.open.pop();
        if let Some(jump) = first {
            self.jumps.set(start, jump);
        }
        self.jumps.set(end, last);
        resolve_exits(self.program, start, end, end, self.jumps);
    }

    /// `$ENDIF` at block `b`: closes the open `$IF`, chaining its branches.
    fn close_if(&mut self, b: usize) {
        let Some(Open::If { .. }) = self.open.last() else {
            self.report(b, "$ENDIF without a matching $IF");
            return;
        };
        let Some(Open::If {
            start, branches, ..
        }) = self.open.pop()
        else {
            unreachable!("matched just above")
        };
        let mut at = start;
        for &branch in &branches {
            self.jumps.set(
                at,
                Jump::If {
                    next: branch,
                    end: b,
                },
            );
            at = branch;
        }
        if matches!(control_of(self.program, at), Some(Control::Else)) {
            self.jumps.set(at, Jump::Else { end: b });
        } else {
            self.jumps.set(at, Jump::If { next: b, end: b });
        }
    }

    /// `$ENDSWITCH` at block `b`: closes the open `$SWITCH`, chaining its cases.
    fn close_switch(&mut self, b: usize) {
        let Some(Open::Switch { .. }) = self.open.last() else {
            self.report(b, "$ENDSWITCH without a matching $SWITCH");
            return;
        };
        let Some(Open::Switch {
            start,
            cases,
            default,
        }) = self.open.pop()
        else {
            unreachable!("matched just above")
        };
        self.jumps.set(
            start,
            Jump::Switch {
                first_case: cases.first().copied(),
                default,
                end: b,
            },
        );
        for (i, &case) in cases.iter().enumerate() {
            self.jumps.set(
                case,
                Jump::Case {
                    next: cases.get(i + 1).copied(),
                },
            );
        }
        // `$BREAK` inside the switch (not inside a loop nested in it) leaves it.
        resolve_breaks(self.program, start, b, self.jumps);
    }

    /// Reports the statements left open at the end of the level.
    fn report_open(&mut self) {
        for o in core::mem::take(&mut self.open) {
            let (b, message) = match o {
                Open::While(b) => (b, "$WHILE without $ENDWHILE"),
                Open::If { start, .. } => (start, "$IF without $ENDIF"),
                Open::For(b) => (b, "$FOR without $ENDFOR"),
                Open::Do(b) => (b, "$DO without $ENDDO"),
                Open::Switch { start, .. } => (start, "$SWITCH without $ENDSWITCH"),
            };
            self.report(b, message);
        }
    }

    /// Gives each `$GOTO` its jump to the one block of `level` with its number.
    fn resolve_gotos(&mut self, level: core::ops::Range<usize>) {
        for (b, n) in core::mem::take(&mut self.gotos) {
            let targets: Vec<usize> = level
                .clone()
                .filter(|&t| self.program.blocks[t].number == Some(n))
                .collect();
            match targets.as_slice() {
                [to] => self.jumps.set(b, Jump::Go { to: *to }),
                [] => self.report(
                    b,
                    &format!("$GOTO N{n}: no block N{n} in this program level"),
                ),
                _ => self.report(
                    b,
                    &format!("$GOTO N{n}: block number N{n} stands more than once"),
                ),
            }
        }
    }

    /// Reports the `$BREAK`s and `$CONTINUE`s of `level` left without a jump: they have
    /// nothing to leave.
    fn report_stray_exits(&mut self, level: core::ops::Range<usize>) {
        for b in level {
            if !self.jumps.has(b) {
                match control_of(self.program, b) {
                    Some(Control::Break) => self.report(b, "$BREAK outside a loop or $SWITCH"),
                    Some(Control::Continue) => self.report(b, "$CONTINUE outside a loop"),
                    _ => {}
                }
            }
        }
    }
}

/// Gives the `$BREAK`s directly inside the loop `start..=end` (not inside a loop or `$SWITCH`
/// nested in it) their jump after the loop, and its `$CONTINUE`s (also those inside a nested
/// `$SWITCH`, which has no next round) their jump to `again`.
fn resolve_exits(program: &Program, start: usize, end: usize, again: usize, jumps: &mut JumpTable) {
    let (mut loops, mut switches) = (0usize, 0usize);
    for b in start + 1..end {
        match control_of(program, b) {
            Some(Control::While(_) | Control::For { .. } | Control::Do) => loops += 1,
            Some(Control::EndWhile | Control::EndFor | Control::EndDo(_)) => {
                loops = loops.saturating_sub(1)
            }
            Some(Control::Switch(_)) => switches += 1,
            Some(Control::EndSwitch) => switches = switches.saturating_sub(1),
            Some(Control::Break) if loops == 0 && switches == 0 => {
                jumps.set(b, Jump::Go { to: end + 1 })
            }
            Some(Control::Continue) if loops == 0 => jumps.set(b, Jump::Go { to: again }),
            _ => {}
        }
    }
}

/// Gives the `$BREAK`s directly inside the `$SWITCH` `start..=end` their jump after it.
fn resolve_breaks(program: &Program, start: usize, end: usize, jumps: &mut JumpTable) {
    let mut depth = 0usize;
    for b in start + 1..end {
        match control_of(program, b) {
            Some(Control::While(_) | Control::For { .. } | Control::Do | Control::Switch(_)) => {
                depth += 1
            }
            Some(Control::EndWhile | Control::EndFor | Control::EndDo(_) | Control::EndSwitch) => {
                depth = depth.saturating_sub(1)
            }
            Some(Control::Break) if depth == 0 => jumps.set(b, Jump::Go { to: end + 1 }),
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nc::parse;

    fn leak(s: String) -> &'static str {
        Box::leak(s.into_boxed_str())
    }

    fn jumps(src: &str) -> (JumpTable, Vec<&'static str>) {
        let (tree, diags) = parse(src);
        assert!(diags.is_empty(), "{diags:?}");
        let (j, u) = match_control(&tree);
        (j, u.into_iter().map(|u| leak(u.message)).collect())
    }

    #[test]
    fn nested_loops_and_branches_pair_up() {
        let src = "$WHILE 1\n$IF 0\nX1\n$ELSE\nX2\n$ENDIF\n$ENDWHILE\nM30\n";
        let (j, u) = jumps(src);
        assert!(u.is_empty());
        assert_eq!(j.get(0), Some(Jump::While { end: 6 }));
        assert_eq!(j.get(1), Some(Jump::If { next: 3, end: 5 }));
        assert_eq!(j.get(3), Some(Jump::Else { end: 5 }));
        assert_eq!(j.get(5), None, "$ENDIF falls through");
        assert_eq!(j.get(6), Some(Jump::EndWhile { start: 0 }));
        assert_eq!(j.get(2), None);
    }

    #[test]
    fn crossed_and_open_statements_are_reported() {
        let (_, u) = jumps("$WHILE 1\n$ENDIF\n");
        assert_eq!(
            u,
            ["$ENDIF without a matching $IF", "$WHILE without $ENDWHILE"]
        );
        let (_, u) = jumps("$ELSE\n$ENDWHILE\n");
        assert_eq!(
            u,
            [
                "$ELSE without a matching $IF",
                "$ENDWHILE without a matching $WHILE"
            ]
        );
        let (_, u) = jumps("$IF 1\n$ELSE\n$ELSE\n$ENDIF\n");
        assert_eq!(u, ["$ELSE without a matching $IF"]);
    }
}
