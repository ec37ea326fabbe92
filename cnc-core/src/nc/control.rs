//! Control flow of a program: `$WHILE`/`$ENDWHILE` and `$IF`/`$ELSE`/`$ENDIF` matched once, by
//! block, into the jump table a channel follows (`channel::program` keeps it; the decoder
//! reports the statements that do not pair up).

use super::ast::{Control, Item, Program, Span};

/// Where control goes from a `$` block (block indices).
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
    /// `$IF`: when false, continue after `next` (its `$ELSE`) or at it (its `$ENDIF`).
    If {
        /// The matching `$ELSE` or `$ENDIF`.
        next: usize,
    },
    /// `$ELSE` reached from the true branch: continue after `end` (its `$ENDIF`).
    Else {
        /// The matching `$ENDIF`.
        end: usize,
    },
}

/// A `$` statement that does not pair up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Unmatched {
    /// The block it stands in.
    pub span: Span,
    /// What is missing.
    pub message: &'static str,
}

/// The control statement of a block (a `$` statement stands alone in its block; the decoder
/// refuses a block where it does not).
pub fn control_of(program: &Program, block: usize) -> Option<&Control> {
    let block = program.blocks.get(block)?;
    program.items_of(block).iter().find_map(|item| match item {
        Item::Control { control, .. } => Some(control.as_ref()),
        _ => None,
    })
}

/// Matches the `$` statements of `program`: per block its jump (`None` for other blocks), and
/// every statement left without a partner. The table is only complete when nothing is
/// unmatched.
pub fn match_control(program: &Program) -> (Vec<Option<Jump>>, Vec<Unmatched>) {
    let mut jumps = vec![None; program.blocks.len()];
    let mut unmatched = Vec::new();
    // Open statements: (block, is_while, its $ELSE).
    let mut open: Vec<(usize, bool, Option<usize>)> = Vec::new();
    let span_of = |b: usize| program.blocks[b].span;
    for b in 0..program.blocks.len() {
        let Some(control) = control_of(program, b) else {
            continue;
        };
        match control {
            Control::While(_) => open.push((b, true, None)),
            Control::If(_) => open.push((b, false, None)),
            Control::Else => match open.last_mut() {
                Some((_, false, else_at @ None)) => *else_at = Some(b),
                _ => unmatched.push(Unmatched {
                    span: span_of(b),
                    message: "$ELSE without a matching $IF",
                }),
            },
            Control::EndWhile => match open.last() {
                Some(&(start, true, _)) => {
                    open.pop();
                    jumps[start] = Some(Jump::While { end: b });
                    jumps[b] = Some(Jump::EndWhile { start });
                }
                _ => unmatched.push(Unmatched {
                    span: span_of(b),
                    message: "$ENDWHILE without a matching $WHILE",
                }),
            },
            Control::EndIf => match open.last() {
                Some(&(start, false, else_at)) => {
                    open.pop();
                    jumps[start] = Some(Jump::If {
                        next: else_at.unwrap_or(b),
                    });
                    if let Some(e) = else_at {
                        jumps[e] = Some(Jump::Else { end: b });
                    }
                }
                _ => unmatched.push(Unmatched {
                    span: span_of(b),
                    message: "$ENDIF without a matching $IF",
                }),
            },
        }
    }
    for (b, is_while, _) in open {
        unmatched.push(Unmatched {
            span: span_of(b),
            message: if is_while {
                "$WHILE without $ENDWHILE"
            } else {
                "$IF without $ENDIF"
            },
        });
    }
    (jumps, unmatched)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nc::parse;

    fn jumps(src: &str) -> (Vec<Option<Jump>>, Vec<&'static str>) {
        let (tree, diags) = parse(src);
        assert!(diags.is_empty(), "{diags:?}");
        let (j, u) = match_control(&tree);
        (j, u.into_iter().map(|u| u.message).collect())
    }

    #[test]
    fn nested_loops_and_branches_pair_up() {
        let src = "$WHILE 1\n$IF 0\nX1\n$ELSE\nX2\n$ENDIF\n$ENDWHILE\nM30\n";
        let (j, u) = jumps(src);
        assert!(u.is_empty());
        assert_eq!(j[0], Some(Jump::While { end: 6 }));
        assert_eq!(j[1], Some(Jump::If { next: 3 }));
        assert_eq!(j[3], Some(Jump::Else { end: 5 }));
        assert_eq!(j[5], None, "$ENDIF falls through");
        assert_eq!(j[6], Some(Jump::EndWhile { start: 0 }));
        assert_eq!(j[2], None);
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
