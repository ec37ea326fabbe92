//! Address words: `G01`, `F500`, `X10`, `AB=90`, `X1[...]`, `P1=2`, the subroutine calls
//! `L name` and `LL name`, and the axis names and numbers glued to words.

use super::{Parser, MAX_PARAM};
use crate::nc::ast::*;
use crate::nc::lexer::Tok;

impl Parser<'_> {
    /// The word at the cursor with the number glued to it, if any (`G01` arrives as one
    /// address token from the lexer, `G 01` never glues); consumed. `None` if no word is there.
    pub(super) fn take_word(&mut self) -> Option<(Name, Option<f64>)> {
        match *self.peek() {
            Tok::Word(w) => {
                self.bump();
                Some((w, self.glued_number()))
            }
            Tok::Addr(w, n) => {
                self.bump();
                Some((w, Some(n)))
            }
            _ => None,
        }
    }

    /// A number written directly after a word (`G01`, `ID3`), consumed.
    fn glued_number(&mut self) -> Option<f64> {
        match self.peek() {
            Tok::Num(n) if !self.token().spaced => {
                let n = *n;
                self.bump();
                Some(n)
            }
            _ => None,
        }
    }

    /// The axis name of a word with an optional glued whole number (`X`, `X1`); a sign or a
    /// decimal point is reported and the block skipped, a name longer than
    /// [`AxisName::CAPACITY`] is reported.
    pub(super) fn axis_name(
        &mut self,
        word: Name,
        glued: Option<f64>,
        span: Span,
    ) -> Option<AxisName> {
        let with_number;
        let name = match glued {
            None => word.as_str(),
            Some(n) if n.fract() == 0.0 && n >= 0.0 => {
                with_number = format!("{word}{}", n as u64);
                &with_number
            }
            Some(_) => {
                self.error(
                    span,
                    "an axis name is letters and digits only (no sign, no decimal point)",
                );
                self.recover();
                return None;
            }
        };
        let axis = AxisName::parse(name);
        if axis.is_none() {
            self.error(
                span,
                format!(
                    "axis name \"{name}\" is longer than {} characters",
                    AxisName::CAPACITY
                ),
            );
        }
        axis
    }

    /// Whether the token at the cursor can start an expression.
    pub(super) fn starts_expression(&self) -> bool {
        match self.peek() {
            Tok::Num(_) | Tok::Var(_) | Tok::Punct("[" | "-" | "+") => true,
            Tok::Addr(w, n) => {
                *w == "P"
                    || (*w == "ATAN" && *n == 2.0 && matches!(self.peek_at(1), Tok::Punct("[")))
            }
            Tok::Word(w) => Func::named(w).is_some() && matches!(self.peek_at(1), Tok::Punct("[")),
            _ => false,
        }
    }

    /// `= expr` after an assignment's target (consumed already).
    pub(super) fn assignment(&mut self, target: Target, span: Span) -> Option<Item> {
        if !self.is_punct("=") {
            let found = self.describe();
            self.error(
                span,
                format!("expected \"=\" after \"{target}\" (an assignment), found {found}"),
            );
            self.recover();
            return None;
        }
        self.bump();
        let value = self.expr()?;
        Some(Item::Assign {
            assign: Box::new(Assign { target, value }),
            span: self.extend(span),
        })
    }

    /// The P parameter number glued to `P` (`P12`), if the word is one.
    pub(super) fn param_number(word: Name, glued: Option<f64>) -> Option<u32> {
        let n = glued?;
        (word == "P" && n.fract() == 0.0 && (1.0..=f64::from(MAX_PARAM)).contains(&n))
            .then_some(n as u32)
    }

    /// `L name [P1=..]`, `LL name [P1=..]`: the name runs to the next blank.
    fn sub_call(&mut self, local: bool, span: Span) -> Option<Item> {
        let keyword = if local { "LL" } else { "L" };
        if self.at_end_of_block() || !self.token().spaced {
            let found = self.describe();
            self.error(
                span,
                format!("{keyword}: expected a blank and a subroutine name, found {found}"),
            );
            self.recover();
            return None;
        }
        let name = self.raw_name();
        if !self.at_end_of_block() {
            let (at, found) = (self.span(), self.describe());
            self.error(
                at,
                format!("{keyword} {name} takes no arguments (set P parameters before the call), found {found}"),
            );
            self.recover();
        }
        Some(Item::Call {
            call: Box::new(SubCall { local, name }),
            span: self.extend(span),
        })
    }

    /// `G01`, `F500`, `M30`, `X10`, `AB=90`, `X1=5`, `X1[...]`, `I5`, `P1=2`, `L sub.nc`.
    pub(super) fn word_item(&mut self, span: Span) -> Option<Item> {
        let (word, glued) = self.take_word()?;
        if glued.is_none() && (word == "L" || word == "LL") {
            return self.sub_call(word == "LL", span);
        }
        if word == "P" || word == "PP" || word == "PPP" {
            return self.param_assignment(word, glued, span);
        }
        if self.is_punct("=") {
            return self.assigned_word(word, glued, span);
        }
        // `X[P1 * 2]`: an expression in brackets right after the address.
        let independent = matches!(self.peek_at(1), Tok::Word(w) if w.starts_with("INDP"));
        // `G4 [..]`: a code word ends at its number; the bracket is the next item.
        let code = glued.is_some() && matches!(word.as_str(), "G" | "M" | "N");
        let bracket = self.is_punct("[") && !code;
        if bracket && !self.token().spaced && !independent {
            return self.bracketed_word(word, glued, span);
        }
        if bracket {
            return self.independent_axis(word, glued, span);
        }
        self.numbered_word(word, glued, span)
    }

    /// `P12 = expr` after `P12` (`word` and `glued`); indirect (`PP1`) and indexed (`P[..]`)
    /// parameters are reported and the block skipped.
    fn param_assignment(&mut self, word: Name, glued: Option<f64>, span: Span) -> Option<Item> {
        if word == "PP" || word == "PPP" {
            self.error(span, "indirect P parameters (PP1) are not supported");
            self.recover();
            return None;
        }
        if glued.is_none() && self.is_punct("[") {
            self.error(
                span,
                "indexed P parameters (P[..]) and P arrays are not supported",
            );
            self.recover();
            return None;
        }
        let Some(n) = Self::param_number(word, glued) else {
            self.error(
                span,
                format!("a P parameter is P and a whole number 1..={MAX_PARAM}, such as P12"),
            );
            self.recover();
            return None;
        };
        self.assignment(Target::Param(n), span)
    }

    /// `X=expr`, `F=expr`, the cursor on the `=`; `G=`, `M=` and `N=` are reported.
    fn assigned_word(&mut self, word: Name, glued: Option<f64>, span: Span) -> Option<Item> {
        // A name that is too long is reported; its value is still read, so that the
        // rest of the block is checked as usual.
        let name = self.axis_name(word, glued, span);
        if name.is_none() && self.at_end_of_block() {
            return None;
        }
        self.bump();
        let value = self.expr();
        let (name, value) = (name?, value?);
        Some(match name.as_str() {
            "F" => Item::Feed {
                value,
                span: self.extend(span),
            },
            "G" | "M" | "N" => {
                self.error(
                    span,
                    format!("{name}=... is not allowed: write {name}<number>"),
                );
                return None;
            }
            _ => Item::Axis(AxisWord {
                name,
                value,
                span: self.extend(span),
            }),
        })
    }

    /// `X[P1 * 2]`, `F[..]`: the value in brackets right after the address.
    fn bracketed_word(&mut self, word: Name, glued: Option<f64>, span: Span) -> Option<Item> {
        let name = self.axis_name(word, glued, span)?;
        let value = self.expr()?;
        Some(if name.as_str() == "F" {
            Item::Feed {
                value,
                span: self.extend(span),
            }
        } else {
            Item::Axis(AxisWord {
                name,
                value,
                span: self.extend(span),
            })
        })
    }

    /// `X1[INDP_ASYN ...]`: an independent axis command, the cursor on the `[`.
    fn independent_axis(&mut self, word: Name, glued: Option<f64>, span: Span) -> Option<Item> {
        let name = self.axis_name(word, glued, span);
        if name.is_none() && self.at_end_of_block() {
            return None;
        }
        let options = self.bracket_list();
        let (name, options) = (name?, options?);
        Some(Item::IndependentAxis {
            axis: Box::new(IndependentAxis { name, options }),
            span: self.extend(span),
        })
    }

    /// A word with its number: `G01`, `M30`, `F500`, `X10`, also signed (`X-60`).
    fn numbered_word(&mut self, word: Name, glued: Option<f64>, span: Span) -> Option<Item> {
        // `X-60`: a signed number glued to the address.
        let glued = glued.or_else(|| self.signed_glued_number());
        let Some(value) = glued else {
            let found = self.describe();
            self.error(
                span,
                format!(
                    "address \"{word}\" needs a value: expected a number or \"=\", found {found}"
                ),
            );
            return None;
        };
        match word.as_bytes() {
            b"G" | b"M" => {
                if value.fract() != 0.0 || value < 0.0 {
                    self.error(
                        span,
                        format!("{word} code must be a whole number, found {value}"),
                    );
                    return None;
                }
                let code = value as u32;
                let span = self.extend(span);
                Some(if word.as_bytes() == b"G" {
                    Item::G { code, span }
                } else {
                    Item::M { code, span }
                })
            }
            b"F" => Some(Item::Feed {
                value: Expr::Num(value),
                span: self.extend(span),
            }),
            b"N" => {
                self.error(span, "a block number N must come first in its block");
                None
            }
            _ => Some(Item::Axis(AxisWord {
                name: self.axis_name(word, None, span)?,
                value: Expr::Num(value),
                span: self.extend(span),
            })),
        }
    }

    /// A sign and a number glued to the word before (`X-60`), consumed.
    fn signed_glued_number(&mut self) -> Option<f64> {
        let sign = match self.peek() {
            Tok::Punct("-") => -1.0,
            Tok::Punct("+") => 1.0,
            _ => return None,
        };
        match self.peek_at(1) {
            Tok::Num(n) if !self.token().spaced && !self.tokens[self.pos + 1].spaced => {
                let n = *n;
                self.bump();
                self.bump();
                Some(sign * n)
            }
            _ => None,
        }
    }
}
