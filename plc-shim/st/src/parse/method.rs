//! METHOD and ACTION declarations (TwinCAT 3's and CODESYS 3's): inside their FUNCTION_BLOCK
//! or PROGRAM after its body, or right after its `END_..`.
//!
//! ```text
//! METHOD [PUBLIC|PRIVATE|PROTECTED|INTERNAL|FINAL] M_Name [: TYPE]
//! VAR_INPUT .. END_VAR  VAR_OUTPUT .. END_VAR  VAR_IN_OUT .. END_VAR  VAR .. END_VAR
//! <statements>
//! END_METHOD
//!
//! ACTION A_Name:
//! <statements>
//! END_ACTION
//! ```

use super::Parser;
use crate::ast::{Method, Section};
use crate::diag::Diagnostic;
use crate::lex::Tok;

/// Access words a method may carry before its name.
const OPEN: [&str; 3] = ["PUBLIC", "INTERNAL", "FINAL"];
const CLOSED: [&str; 2] = ["PRIVATE", "PROTECTED"];

impl Parser {
    /// Whether a METHOD or an ACTION declaration begins here (the word followed by a name,
    /// so that a variable called `action` is still one: `action S= b;`).
    pub(super) fn method_start(&self) -> bool {
        let word = |w: &str| matches!(self.peek(), Tok::Ident(x) if x.eq_ignore_ascii_case(w));
        if !(word("METHOD") || word("ACTION")) {
            return false;
        }
        let set = matches!(self.peek_at(1), Tok::Ident(w)
            if w.eq_ignore_ascii_case("S") || w.eq_ignore_ascii_case("R"))
            && matches!(self.peek_at(2), Tok::Eq);
        matches!(self.peek_at(1), Tok::Ident(_)) && !set
    }

    fn section_word(&self, w: &str) -> bool {
        super::SECTIONS.iter().any(|s| s.eq_ignore_ascii_case(w))
            || w.eq_ignore_ascii_case("VAR_INST")
    }

    /// A METHOD or an ACTION, from its word to its END_.. .
    pub(super) fn method(&mut self) -> Result<Method, Diagnostic> {
        let action = self.eat_kw("ACTION");
        if !action {
            self.expect_kw("METHOD")?;
        }
        let mut private = false;
        while let Tok::Ident(w) = self.peek().clone() {
            // An access word before a name (a method may be called `Private`, and its body
            // may begin with a name: `METHOD Private  n := 1;`).
            let named = matches!(self.peek_at(1), Tok::Ident(n) if !super::reserved(n) && !self.section_word(n));
            let statement = matches!(
                self.peek_at(2),
                Tok::Assign | Tok::LParen | Tok::Dot | Tok::LBracket | Tok::Caret | Tok::Eq
            ) || (matches!(self.peek_at(2), Tok::Ident(_))
                && matches!(self.peek_at(3), Tok::Eq));
            if !named || statement {
                break;
            }
            if ["ABSTRACT", "OVERRIDE"]
                .iter()
                .any(|k| w.eq_ignore_ascii_case(k))
            {
                return Err(self.error(format!(
                    "`{w}` is not supported: methods without EXTENDS neither are abstract nor \
                     override"
                )));
            }
            if CLOSED.iter().any(|k| w.eq_ignore_ascii_case(k)) {
                private = true;
            } else if !OPEN.iter().any(|k| w.eq_ignore_ascii_case(k)) {
                break;
            }
            self.bump();
        }
        let name = self.name()?;
        // Methods the runtime of TwinCAT would call by itself: here none would call them.
        let implicit = ["FB_INIT", "FB_REINIT", "FB_EXIT"];
        if implicit.iter().any(|m| name.text.eq_ignore_ascii_case(m)) {
            return Err(Diagnostic::new(
                name.pos,
                format!(
                    "`{}` is not supported: nothing calls it here; give the block's variables \
                     their initial values in their declarations",
                    name.text
                ),
            ));
        }
        let returns = match (action, self.eat(&Tok::Colon)) {
            (false, true) => Some(self.type_ref()?),
            _ => None,
        };
        let mut vars = Vec::new();
        while self.is_var_section() || self.is_kw("VAR_INST") {
            if self.is_kw("VAR_INST") {
                return Err(self.error(
                    "`VAR_INST` is not supported: declare the variable in the function block",
                ));
            }
            let block = self.var_block()?;
            if action {
                return Err(Diagnostic::new(
                    block.pos,
                    "an ACTION has no variables of its own: declare them in its POU",
                ));
            }
            if matches!(block.section, Section::Global | Section::External) {
                return Err(Diagnostic::new(
                    block.pos,
                    "a METHOD declares VAR_INPUT, VAR_OUTPUT, VAR_IN_OUT, VAR and VAR_TEMP",
                ));
            }
            vars.push(block);
        }
        let end = if action { "END_ACTION" } else { "END_METHOD" };
        let body = self.statements(&[end])?;
        self.expect_kw(end)?;
        Ok(Method {
            name,
            action,
            private,
            returns,
            vars,
            body,
        })
    }
}
