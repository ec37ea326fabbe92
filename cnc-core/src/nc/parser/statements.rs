//! The `$` statements: `$IF`, `$WHILE`, `$FOR`, `$GOTO`...

use super::Parser;
use crate::nc::ast::*;
use crate::nc::lexer::Tok;

impl Parser<'_> {
    pub(super) fn control(&mut self, span: Span) -> Option<Control> {
        let word = match self.peek().clone() {
            Tok::Word(w) => {
                self.bump();
                w
            }
            _ => {
                let found = self.describe();
                self.error(
                    span,
                    format!(
                        "expected WHILE, ENDWHILE, IF, ELSE or ENDIF after \"$\", found {found}"
                    ),
                );
                self.recover();
                return None;
            }
        };
        let control = match word.as_str() {
            "WHILE" => Control::While(self.expr()?),
            "ENDWHILE" => Control::EndWhile,
            "IF" => Control::If(self.expr()?),
            "ELSEIF" => Control::ElseIf(self.expr()?),
            "ELSE" => Control::Else,
            "ENDIF" => Control::EndIf,
            "FOR" => self.for_statement(span)?,
            "ENDFOR" => Control::EndFor,
            "DO" => Control::Do,
            "ENDDO" => Control::EndDo(self.expr()?),
            "SWITCH" => Control::Switch(self.expr()?),
            "CASE" => Control::Case(self.expr()?),
            "DEFAULT" => Control::Default,
            "ENDSWITCH" => Control::EndSwitch,
            "BREAK" => Control::Break,
            "CONTINUE" => Control::Continue,
            "GOTO" => {
                let target = match *self.peek() {
                    Tok::Addr(w, n) if w == "N" && n.fract() == 0.0 && n >= 0.0 => {
                        self.bump();
                        Some(n as u32)
                    }
                    _ => None,
                };
                let Some(target) = target else {
                    let found = self.describe();
                    self.error(
                        span,
                        format!("$GOTO: expected a block number such as N100, found {found}"),
                    );
                    self.recover();
                    return None;
                };
                Control::Goto(target)
            }
            other => {
                self.error(span, format!("unknown statement \"${other}\" (known: $IF, $ELSEIF, $ELSE, $ENDIF, $WHILE, $ENDWHILE, $DO, $ENDDO, $FOR, $ENDFOR, $SWITCH, $CASE, $DEFAULT, $ENDSWITCH, $BREAK, $CONTINUE, $GOTO)"));
                self.recover();
                return None;
            }
        };
        if !self.at_end_of_block() {
            let (s, found) = (self.span(), self.describe());
            self.error(
                s,
                format!("expected end of block after ${word}, found {found}"),
            );
            self.recover();
        }
        Some(control)
    }

    /// `$FOR P1 = start, end, step` (the step may be left out: 1).
    fn for_statement(&mut self, span: Span) -> Option<Control> {
        let var = match *self.peek() {
            Tok::Addr(w, n) => Self::param_number(w, Some(n)).map(Target::Param),
            Tok::Var(v) => Some(Target::Var(v)),
            _ => None,
        };
        let Some(var) = var else {
            let found = self.describe();
            self.error(
                span,
                format!("$FOR: expected a counter such as P1, found {found}"),
            );
            self.recover();
            return None;
        };
        self.bump();
        if !self.is_punct("=") {
            let found = self.describe();
            self.error(span, format!("$FOR {var}: expected \"=\", found {found}"));
            self.recover();
            return None;
        }
        self.bump();
        let start = self.expr()?;
        let mut bounds = Vec::with_capacity(2);
        while self.is_punct(",") && bounds.len() < 2 {
            self.bump();
            bounds.push(self.expr()?);
        }
        let mut bounds = bounds.into_iter();
        let Some(end) = bounds.next() else {
            self.error(span, format!("$FOR {var}: expected \"start, end[, step]\""));
            self.recover();
            return None;
        };
        let step = bounds.next().unwrap_or(Expr::Num(1.0));
        Some(Control::For {
            var,
            start,
            end,
            step,
        })
    }
}
