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
    let mut open: Vec<Open> = Vec::new();
    let span_of = |b: usize| program.blocks[b].span;
    let mut report = |b: usize, message: &str| {
        unmatched.push(Unmatched {
            span: span_of(b),
            message: message.to_string(),
        })
    };
    let mut gotos: Vec<(usize, u32)> = Vec::new();
    for b in level.clone() {
        let Some(control) = control_in(program, &program.blocks[b]) else {
            continue;
        };
        match control {
            Control::While(_) => open.push(Open::While(b)),
            Control::If(_) => open.push(Open::If {
                start: b,
                branches: Vec::new(),
                seen_else: false,
            }),
            Control::For { .. } => open.push(Open::For(b)),
            Control::Do => open.push(Open::Do(b)),
            Control::Switch(_) => open.push(Open::Switch {
                start: b,
                cases: Vec::new(),
                default: None,
            }),
            Control::ElseIf(_) | Control::Else => match open.last_mut() {
                Some(Open::If {
                    branches,
                    seen_else,
                    ..
                }) if !*seen_else => {
                    branches.push(b);
                    *seen_else = matches!(control, Control::Else);
                }
                _ => report(b, &format!("${} without a matching $IF", control.keyword())),
            },
            // `$DEFAULT` may stand anywhere among the cases (reached sequentially it runs on
            // into the case after it, like any branch); once per `$SWITCH`.
            Control::Case(_) | Control::Default => match open.last_mut() {
                Some(Open::Switch {
                    default: Some(_), ..
                }) if matches!(control, Control::Default) => {
                    report(b, "a second $DEFAULT in one $SWITCH")
                }
                Some(Open::Switch { cases, default, .. }) => {
                    if matches!(control, Control::Default) {
                        *default = Some(b);
                    } else {
                        cases.push(b);
                    }
                }
                _ => report(
                    b,
                    &format!("${} without a matching $SWITCH", control.keyword()),
                ),
            },
            Control::EndWhile => match open.last() {
                Some(&Open::While(start)) => {
                    open.pop();
                    jumps.set(start, Jump::While { end: b });
                    jumps.set(b, Jump::EndWhile { start });
                    resolve_exits(program, start, b, b, jumps);
                }
                _ => report(b, "$ENDWHILE without a matching $WHILE"),
            },
            Control::EndFor => match open.last() {
                Some(&Open::For(start)) => {
                    open.pop();
                    jumps.set(start, Jump::For { end: b });
                    jumps.set(b, Jump::EndFor { start });
                    resolve_exits(program, start, b, b, jumps);
                }
                _ => report(b, "$ENDFOR without a matching $FOR"),
            },
            Control::EndDo(_) => match open.last() {
                Some(&Open::Do(start)) => {
                    open.pop();
                    jumps.set(b, Jump::EndDo { start });
                    resolve_exits(program, start, b, b, jumps);
                }
                _ => report(b, "$ENDDO without a matching $DO"),
            },
            Control::EndIf => match open.last() {
                Some(Open::If { .. }) => {
                    let Some(Open::If {
                        start, branches, ..
                    }) = open.pop()
                    else {
                        unreachable!("matched just above")
                    };
                    let mut at = start;
                    for &branch in &branches {
                        jumps.set(
                            at,
                            Jump::If {
                                next: branch,
                                end: b,
                            },
                        );
                        at = branch;
                    }
                    if matches!(control_of(program, at), Some(Control::Else)) {
                        jumps.set(at, Jump::Else { end: b });
                    } else {
                        jumps.set(at, Jump::If { next: b, end: b });
                    }
                }
                _ => report(b, "$ENDIF without a matching $IF"),
            },
            Control::EndSwitch => match open.last() {
                Some(Open::Switch { .. }) => {
                    let Some(Open::Switch {
                        start,
                        cases,
                        default,
                    }) = open.pop()
                    else {
                        unreachable!("matched just above")
                    };
                    jumps.set(
                        start,
                        Jump::Switch {
                            first_case: cases.first().copied(),
                            default,
                            end: b,
                        },
                    );
                    for (i, &case) in cases.iter().enumerate() {
                        jumps.set(
                            case,
                            Jump::Case {
                                next: cases.get(i + 1).copied(),
                            },
                        );
                    }
                    // `$BREAK` inside the switch (not inside a loop nested in it) leaves it.
                    resolve_breaks(program, start, b, jumps);
                }
                _ => report(b, "$ENDSWITCH without a matching $SWITCH"),
            },
            // Given their jumps when their loop or `$SWITCH` closes; reported below if not.
            Control::Break | Control::Continue => {}
            Control::Goto(n) => gotos.push((b, *n)),
        }
    }
    for o in open {
        let (b, message) = match o {
            Open::While(b) => (b, "$WHILE without $ENDWHILE"),
            Open::If { start, .. } => (start, "$IF without $ENDIF"),
            Open::For(b) => (b, "$FOR without $ENDFOR"),
            Open::Do(b) => (b, "$DO without $ENDDO"),
            Open::Switch { start, .. } => (start, "$SWITCH without $ENDSWITCH"),
        };
        report(b, message);
    }
    for (b, n) in gotos {
        let targets: Vec<usize> = level
            .clone()
            .filter(|&t| program.blocks[t].number == Some(n))
            .collect();
        match targets.as_slice() {
            [to] => jumps.set(b, Jump::Go { to: *to }),
            [] => report(
                b,
                &format!("$GOTO N{n}: no block N{n} in this program level"),
            ),
            _ => report(
                b,
                &format!("$GOTO N{n}: block number N{n} stands more than once"),
            ),
        }
    }
    // A `$BREAK` or `$CONTINUE` left without a jump has nothing to leave.
    for b in level {
        if !jumps.has(b) {
            match control_of(program, b) {
                Some(Control::Break) => report(b, "$BREAK outside a loop or $SWITCH"),
                Some(Control::Continue) => report(b, "$CONTINUE outside a loop"),
                _ => {}
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
