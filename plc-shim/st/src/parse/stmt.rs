//! Statements and expressions. Operator precedence, lowest first: OR and OR_ELSE, XOR, AND
//! (`&`) and AND_THEN,
//! `=` `<>`, `<` `>` `<=` `>=`, `+` `-`, `*` `/` MOD, `**`, unary `-` and NOT, then the
//! postfix forms (`.field`, `[index]`, `^`, `(arguments)`).

use super::Parser;
use crate::ast::{Arg, BinOp, CaseLabel, Expr, Name, Stmt, UnOp};
use crate::diag::Diagnostic;
use crate::lex::Tok;

/// Deepest nesting of expressions and statements: deeper input is refused, not a stack
/// overflow.
pub(super) const MAX_DEPTH: usize = 100;

impl Parser {
    /// Statements until one of the keywords `ends` (not taken).
    pub(super) fn statements(&mut self, ends: &[&str]) -> Result<Vec<Stmt>, Diagnostic> {
        let mut out = Vec::new();
        loop {
            if ends.iter().any(|e| self.is_kw(e)) {
                return Ok(out);
            }
            if self.at_eof() {
                let what = ends.join(" or ");
                return Err(self.error(format!("expected {what}, found the end of the file")));
            }
            if self.eat(&Tok::Semi) {
                continue;
            }
            if self.is_end_word() {
                let what = ends.join(" or ");
                return Err(self.error(format!("expected {what}, found {}", self.found())));
            }
            // A METHOD or ACTION written inside its POU, after the body.
            if self.method_start() {
                return Ok(out);
            }
            self.refuse_object_oriented()?;
            out.push(self.nested(Self::statement)?);
        }
    }

    /// Whether the next word closes something (`END_..`, ELSE, ELSIF, UNTIL): not a statement.
    fn is_end_word(&self) -> bool {
        matches!(self.peek(), Tok::Ident(w) if w.to_ascii_uppercase().starts_with("END_")
            || ["ELSE", "ELSIF", "UNTIL"].iter().any(|k| w.eq_ignore_ascii_case(k)))
    }

    fn statement(&mut self) -> Result<Stmt, Diagnostic> {
        let pos = self.pos();
        if self.eat_kw("IF") {
            return self.if_stmt();
        }
        if self.eat_kw("CASE") {
            return self.case_stmt();
        }
        if self.eat_kw("FOR") {
            return self.for_stmt();
        }
        if self.eat_kw("WHILE") {
            let cond = self.expr()?;
            self.expect_kw("DO")?;
            let body = self.statements(&["END_WHILE"])?;
            self.expect_kw("END_WHILE")?;
            return Ok(Stmt::While { cond, body });
        }
        if self.eat_kw("REPEAT") {
            let body = self.statements(&["UNTIL"])?;
            self.expect_kw("UNTIL")?;
            let until = self.expr()?;
            self.expect_kw("END_REPEAT")?;
            return Ok(Stmt::Repeat { body, until });
        }
        for (kw, make) in [
            ("EXIT", Stmt::Exit as fn(_) -> Stmt),
            ("CONTINUE", Stmt::Continue),
            ("RETURN", Stmt::Return),
        ] {
            if self.eat_kw(kw) {
                self.expect(&Tok::Semi, "`;`")?;
                return Ok(make(pos));
            }
        }
        let target = self.postfix()?;
        if let Some(value) = self.set_or_reset() {
            // `x S= c;` (TwinCAT, CODESYS): x becomes TRUE when c is, else keeps its value.
            let cond = self.expr()?;
            self.expect(&Tok::Semi, "`;`")?;
            let body = vec![Stmt::Assign { target, value }];
            return Ok(Stmt::If {
                branches: vec![(cond, body)],
                otherwise: None,
            });
        }
        if self.eat(&Tok::Assign) {
            let value = self.expr()?;
            self.expect(&Tok::Semi, "`;`")?;
            return Ok(Stmt::Assign { target, value });
        }
        // `r REF= x;`: a REFERENCE TO bound (`check::reference`).
        let bind = matches!(self.peek(), Tok::Ident(w) if w.eq_ignore_ascii_case("REF"))
            && matches!(self.peek_at(1), Tok::Eq);
        if bind {
            let at = self.pos();
            self.bump();
            self.bump();
            let value = crate::check::reference::bind(self.expr()?, at);
            self.expect(&Tok::Semi, "`;`")?;
            return Ok(Stmt::Assign { target, value });
        }
        if matches!(target, Expr::Call { .. }) {
            self.expect(&Tok::Semi, "`;`")?;
            return Ok(Stmt::Call(target));
        }
        Err(self.error(format!(
            "expected `:=` or a call after the expression, found {}",
            self.found()
        )))
    }

    /// `S=` or `R=` next (taken): the value it stores, TRUE or FALSE.
    fn set_or_reset(&mut self) -> Option<Expr> {
        let pos = self.pos();
        let set = match self.peek() {
            Tok::Ident(w) if w.eq_ignore_ascii_case("S") => true,
            Tok::Ident(w) if w.eq_ignore_ascii_case("R") => false,
            _ => return None,
        };
        if !matches!(self.peek_at(1), Tok::Eq) {
            return None;
        }
        self.bump();
        self.bump();
        Some(Expr::Bool(set, pos))
    }

    fn if_stmt(&mut self) -> Result<Stmt, Diagnostic> {
        let mut branches = Vec::new();
        loop {
            let cond = self.expr()?;
            self.expect_kw("THEN")?;
            let body = self.statements(&["ELSIF", "ELSE", "END_IF"])?;
            branches.push((cond, body));
            if !self.eat_kw("ELSIF") {
                break;
            }
        }
        let otherwise = if self.eat_kw("ELSE") {
            Some(self.statements(&["END_IF"])?)
        } else {
            None
        };
        self.expect_kw("END_IF")?;
        Ok(Stmt::If {
            branches,
            otherwise,
        })
    }

    fn case_stmt(&mut self) -> Result<Stmt, Diagnostic> {
        let selector = self.expr()?;
        self.expect_kw("OF")?;
        let mut arms = Vec::new();
        while !self.is_kw("ELSE") && !self.is_kw("END_CASE") {
            if self.at_eof() {
                return Err(self.error("a CASE without its END_CASE"));
            }
            let labels = self.case_labels()?;
            let mut body = Vec::new();
            while !self.is_kw("ELSE") && !self.is_kw("END_CASE") && !self.looks_like_label() {
                if self.at_eof() {
                    return Err(self.error("a CASE without its END_CASE"));
                }
                if self.is_end_word() {
                    return Err(self.error(format!("expected END_CASE, found {}", self.found())));
                }
                if !self.eat(&Tok::Semi) {
                    body.push(self.nested(Self::statement)?);
                }
            }
            arms.push((labels, body));
        }
        let otherwise = if self.eat_kw("ELSE") {
            Some(self.statements(&["END_CASE"])?)
        } else {
            None
        };
        self.expect_kw("END_CASE")?;
        Ok(Stmt::Case {
            selector,
            arms,
            otherwise,
        })
    }

    /// `1, 3..5, E_Mode.Run :`.
    fn case_labels(&mut self) -> Result<Vec<CaseLabel>, Diagnostic> {
        let mut labels = Vec::new();
        loop {
            let value = self.expr()?;
            if self.eat(&Tok::Range) {
                labels.push(CaseLabel::Range(value, self.expr()?));
            } else {
                labels.push(CaseLabel::Value(value));
            }
            if !self.eat(&Tok::Comma) {
                break;
            }
        }
        self.expect(&Tok::Colon, "`:` after the CASE labels")?;
        Ok(labels)
    }

    /// Whether the tokens ahead are CASE labels (a `:`, `,` or `..` before any `;` or `:=`
    /// outside brackets) rather than a statement. A statement that begins with its keyword
    /// (a nested CASE or IF, a loop, EXIT, ...) is never a label, whatever `:` it holds.
    fn looks_like_label(&self) -> bool {
        const STATEMENT_WORDS: [&str; 8] = [
            "CASE", "IF", "FOR", "WHILE", "REPEAT", "EXIT", "CONTINUE", "RETURN",
        ];
        if STATEMENT_WORDS.iter().any(|w| self.is_kw(w)) {
            return false;
        }
        let mut depth = 0i32;
        for k in 0..64 {
            match self.peek_at(k) {
                Tok::LParen | Tok::LBracket => depth += 1,
                Tok::RParen | Tok::RBracket => depth -= 1,
                Tok::Colon | Tok::Comma | Tok::Range if depth == 0 => return true,
                Tok::Semi | Tok::Assign | Tok::OutAssign | Tok::Eof if depth == 0 => return false,
                Tok::Eof => return false,
                _ => {}
            }
        }
        false
    }

    fn for_stmt(&mut self) -> Result<Stmt, Diagnostic> {
        let var = self.name()?;
        self.expect(&Tok::Assign, "`:=` and the first value")?;
        let from = self.expr()?;
        self.expect_kw("TO")?;
        let to = self.expr()?;
        let by = if self.eat_kw("BY") {
            Some(self.expr()?)
        } else {
            None
        };
        self.expect_kw("DO")?;
        let body = self.statements(&["END_FOR"])?;
        self.expect_kw("END_FOR")?;
        Ok(Stmt::For {
            var,
            from,
            to,
            by,
            body,
        })
    }

    /// An expression.
    pub(super) fn expr(&mut self) -> Result<Expr, Diagnostic> {
        self.nested(|p| p.binary(0))
    }

    /// `parse` one level deeper: nesting beyond [`MAX_DEPTH`] is refused.
    pub(super) fn nested<T>(
        &mut self,
        parse: impl FnOnce(&mut Self) -> Result<T, Diagnostic>,
    ) -> Result<T, Diagnostic> {
        if self.depth >= MAX_DEPTH {
            return Err(self.error(format!(
                "expressions or statements nested deeper than {MAX_DEPTH}"
            )));
        }
        self.depth += 1;
        let result = parse(self);
        self.depth -= 1;
        result
    }

    /// Operators of `level` and above, left-associative.
    fn binary(&mut self, level: usize) -> Result<Expr, Diagnostic> {
        const LEVELS: usize = 8;
        if level == LEVELS {
            return self.unary();
        }
        let mut lhs = self.binary(level + 1)?;
        let depth = self.depth;
        while let Some(op) = self.operator(level) {
            let pos = self.pos();
            self.bump();
            // Each operator in a chain is a level of the tree: counted like a nesting.
            self.deeper()?;
            let rhs = self.binary(level + 1)?;
            lhs = Expr::Binary(op, Box::new(lhs), Box::new(rhs), pos);
        }
        self.depth = depth;
        Ok(lhs)
    }

    /// The binary operator of precedence `level` next, if any.
    fn operator(&self, level: usize) -> Option<BinOp> {
        let word = |w: &str| self.is_kw(w);
        match (level, self.peek()) {
            (0, _) if word("OR") => Some(BinOp::Or),
            (0, _) if word("OR_ELSE") => Some(BinOp::OrElse),
            (1, _) if word("XOR") => Some(BinOp::Xor),
            (2, Tok::Amp) => Some(BinOp::And),
            (2, _) if word("AND") => Some(BinOp::And),
            (2, _) if word("AND_THEN") => Some(BinOp::AndThen),
            (3, Tok::Eq) => Some(BinOp::Eq),
            (3, Tok::Ne) => Some(BinOp::Ne),
            (4, Tok::Lt) => Some(BinOp::Lt),
            (4, Tok::Gt) => Some(BinOp::Gt),
            (4, Tok::Le) => Some(BinOp::Le),
            (4, Tok::Ge) => Some(BinOp::Ge),
            (5, Tok::Plus) => Some(BinOp::Add),
            (5, Tok::Minus) => Some(BinOp::Sub),
            (6, Tok::Star) => Some(BinOp::Mul),
            (6, Tok::Slash) => Some(BinOp::Div),
            (6, _) if word("MOD") => Some(BinOp::Mod),
            (7, Tok::Power) => Some(BinOp::Pow),
            _ => None,
        }
    }

    fn unary(&mut self) -> Result<Expr, Diagnostic> {
        let pos = self.pos();
        if self.eat(&Tok::Minus) {
            let operand = self.nested(Self::unary)?;
            return Ok(Expr::Unary(UnOp::Neg, Box::new(operand), pos));
        }
        if self.eat(&Tok::Plus) {
            return self.nested(Self::unary);
        }
        if self.eat_kw("NOT") {
            let operand = self.nested(Self::unary)?;
            return Ok(Expr::Unary(UnOp::Not, Box::new(operand), pos));
        }
        self.postfix()
    }

    /// One more level of the tree being read, refused beyond [`MAX_DEPTH`].
    fn deeper(&mut self) -> Result<(), Diagnostic> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(self.error(format!(
                "expressions or statements nested deeper than {MAX_DEPTH}"
            )));
        }
        Ok(())
    }

    /// A primary and its `.field`, `[index]`, `^` and `(arguments)`.
    pub(super) fn postfix(&mut self) -> Result<Expr, Diagnostic> {
        let mut e = self.primary()?;
        let depth = self.depth;
        let result = self.suffixes(&mut e);
        self.depth = depth;
        result.map(|()| e)
    }

    /// The `.field`, `[index]`, `^` and `(arguments)` after a primary, each a level.
    fn suffixes(&mut self, e: &mut Expr) -> Result<(), Diagnostic> {
        loop {
            let pos = self.pos();
            if matches!(
                self.peek(),
                Tok::Dot | Tok::LBracket | Tok::Caret | Tok::LParen
            ) {
                self.deeper()?;
            }
            if self.eat(&Tok::Dot) {
                let field = match self.peek().clone() {
                    // Bit access: `word.3`.
                    Tok::Int(bit) => {
                        self.bump();
                        Name {
                            text: bit.to_string(),
                            pos,
                        }
                    }
                    _ => self.field_name()?,
                };
                *e = Expr::Field(Box::new(std::mem::replace(e, Expr::Int(0, pos))), field);
            } else if self.eat(&Tok::LBracket) {
                let mut index = vec![self.expr()?];
                while self.eat(&Tok::Comma) {
                    index.push(self.expr()?);
                }
                self.expect(&Tok::RBracket, "`]`")?;
                *e = Expr::Index(
                    Box::new(std::mem::replace(e, Expr::Int(0, pos))),
                    index,
                    pos,
                );
            } else if self.eat(&Tok::Caret) {
                *e = Expr::Deref(Box::new(std::mem::replace(e, Expr::Int(0, pos))), pos);
                // `p^field`, as the manuals write it, is `p^.field`.
                let field_pos = self.pos();
                if let Tok::Ident(word) = self.peek().clone() {
                    if !super::reserved(&word) {
                        self.bump();
                        let field = Name {
                            text: word,
                            pos: field_pos,
                        };
                        *e = Expr::Field(Box::new(std::mem::replace(e, Expr::Int(0, pos))), field);
                    }
                }
            } else if self.eat(&Tok::LParen) {
                let args = self.arguments()?;
                *e = Expr::Call {
                    callee: Box::new(std::mem::replace(e, Expr::Int(0, pos))),
                    args,
                    pos,
                };
            } else {
                return Ok(());
            }
        }
    }

    /// Arguments after `(`, through the `)`.
    fn arguments(&mut self) -> Result<Vec<Arg>, Diagnostic> {
        let mut args = Vec::new();
        if self.eat(&Tok::RParen) {
            return Ok(args);
        }
        loop {
            let named = matches!(self.peek(), Tok::Ident(_));
            let negated = self.is_kw("NOT") && *self.peek_at(2) == Tok::OutAssign;
            if negated {
                self.bump();
            }
            if (named || negated) && *self.peek_at(1) == Tok::Assign {
                let name = self.name()?;
                self.bump();
                args.push(Arg::Input(name, self.expr()?));
            } else if (named || negated) && *self.peek_at(1) == Tok::OutAssign {
                let name = self.name()?;
                self.bump();
                let target = self.postfix()?;
                args.push(Arg::Output {
                    name,
                    target,
                    negated,
                });
            } else {
                args.push(Arg::Positional(self.expr()?));
            }
            if !self.eat(&Tok::Comma) {
                break;
            }
        }
        self.expect(&Tok::RParen, "`)` after the arguments")?;
        Ok(args)
    }

    fn primary(&mut self) -> Result<Expr, Diagnostic> {
        let pos = self.pos();
        match self.peek().clone() {
            Tok::LParen => {
                self.bump();
                let e = self.expr()?;
                self.expect(&Tok::RParen, "`)`")?;
                Ok(e)
            }
            Tok::TypePrefix(ty) => {
                self.bump();
                let ty = Name { text: ty, pos };
                let value = match self.peek().clone() {
                    Tok::Ident(_) if self.is_kw("TRUE") || self.is_kw("FALSE") => {
                        self.expr_primary_literal()?
                    }
                    Tok::Ident(_) => Expr::Name(self.name()?),
                    _ => self.expr_primary_literal()?,
                };
                Ok(Expr::Typed {
                    ty,
                    value: Box::new(value),
                })
            }
            Tok::Ident(_) if self.is_kw("TRUE") || self.is_kw("FALSE") => {
                self.expr_primary_literal()
            }
            Tok::Ident(_) => Ok(Expr::Name(self.name()?)),
            _ => self.expr_primary_literal(),
        }
    }

    /// A literal: a number, a duration, a string, TRUE or FALSE.
    pub(super) fn expr_primary_literal(&mut self) -> Result<Expr, Diagnostic> {
        let pos = self.pos();
        let e = match self.peek().clone() {
            Tok::Int(v) => Expr::Int(v, pos),
            Tok::Real(v) => Expr::Real(v, pos),
            Tok::Time(v, long) => Expr::Time(v, long, pos),
            Tok::Str(s) => Expr::Str(s, pos),
            Tok::Ident(_) if self.is_kw("TRUE") => Expr::Bool(true, pos),
            Tok::Ident(_) if self.is_kw("FALSE") => Expr::Bool(false, pos),
            _ => return Err(self.error(format!("expected a value, found {}", self.found()))),
        };
        self.bump();
        Ok(e)
    }
}
