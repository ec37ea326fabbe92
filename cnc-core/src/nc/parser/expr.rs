//! Expressions, by precedence climbing: numbers, variables, P parameters, operators and
//! function calls.

use super::{Parser, MAX_PARAM};
use crate::nc::ast::*;
use crate::nc::lexer::Tok;

impl Parser<'_> {
    /// Expression with precedence climbing; unary minus binds tightest.
    pub(super) fn expr(&mut self) -> Option<Expr> {
        self.binary(1)
    }

    fn binary(&mut self, min_prec: u8) -> Option<Expr> {
        let mut lhs = self.unary()?;
        // `X=1 -2` reads as one expression: whitespace does not separate list entries from a
        // following operator.
        while let Some(op) = self
            .binary_operator()
            .filter(|op| op.precedence() >= min_prec)
        {
            self.bump();
            // The power is right-associative: 2**3**2 is 2**9.
            let next = if op == BinOp::Pow {
                op.precedence()
            } else {
                op.precedence() + 1
            };
            let rhs = self.binary(next)?;
            lhs = Expr::Bin(Box::new((op, lhs, rhs)));
        }
        Some(lhs)
    }

    fn binary_operator(&self) -> Option<BinOp> {
        let p = match self.peek() {
            Tok::Punct(p) => *p,
            Tok::Word(w) => {
                return match w.as_str() {
                    "MOD" => Some(BinOp::Mod),
                    "AND" => Some(BinOp::And),
                    "OR" => Some(BinOp::Or),
                    "XOR" => Some(BinOp::Xor),
                    _ => None,
                }
            }
            _ => return None,
        };
        Some(match p {
            "**" => BinOp::Pow,
            "+" => BinOp::Add,
            "-" => BinOp::Sub,
            "*" => BinOp::Mul,
            "/" => BinOp::Div,
            "==" => BinOp::Eq,
            "!=" => BinOp::Ne,
            "<" => BinOp::Lt,
            "<=" => BinOp::Le,
            ">" => BinOp::Gt,
            ">=" => BinOp::Ge,
            _ => return None,
        })
    }

    /// The `]` that closes the bracket opened at `open`, consumed.
    fn close_bracket(&mut self, open: Span) -> Option<()> {
        if self.is_punct("]") {
            self.bump();
            Some(())
        } else {
            let found = self.describe();
            self.error(
                open,
                format!("\"[\" is not closed by \"]\" (found {found})"),
            );
            None
        }
    }

    fn unary(&mut self) -> Option<Expr> {
        match self.peek().clone() {
            Tok::Punct("-") => {
                self.bump();
                Some(Expr::Neg(Box::new(self.unary()?)))
            }
            Tok::Punct("+") => {
                self.bump();
                self.unary()
            }
            Tok::Num(n) => {
                self.bump();
                Some(Expr::Num(n))
            }
            Tok::Var(v) => {
                self.bump();
                Some(Expr::Var(Box::new(v)))
            }
            Tok::Addr(w, n) if w == "P" => {
                let span = self.span();
                self.bump();
                match Self::param_number(w, Some(n)) {
                    Some(n) => Some(Expr::Param(n)),
                    None => {
                        self.error(
                            span,
                            format!("a P parameter is P and a whole number 1..={MAX_PARAM}"),
                        );
                        None
                    }
                }
            }
            Tok::Punct("[") => {
                let open = self.span();
                self.bump();
                let inner = self.expr()?;
                self.close_bracket(open)?;
                Some(inner)
            }
            // `ATAN2` arrives as the word ATAN with a glued 2.
            Tok::Addr(w, n)
                if w == "ATAN" && n == 2.0 && matches!(self.peek_at(1), Tok::Punct("[")) =>
            {
                self.call(Func::Atan2)
            }
            Tok::Word(w)
                if Func::named(&w).is_some() && matches!(self.peek_at(1), Tok::Punct("[")) =>
            {
                self.call(Func::named(&w)?)
            }
            Tok::Word(w) => {
                let (span, found) = (self.span(), self.describe());
                let hint = if Func::named(&w).is_some() {
                    format!("{w} is a function: write {w}[...]")
                } else if matches!(self.peek_at(1), Tok::Punct("[")) {
                    let known: Vec<&str> = Func::ALL.iter().map(|f| f.1).collect();
                    format!("unknown function {w} (known: {})", known.join(", "))
                } else {
                    format!(
                        "expected a number, a variable, P.., a function or \"[\", found {found}"
                    )
                };
                self.error(span, hint);
                None
            }
            _ => {
                let (span, found) = (self.span(), self.describe());
                self.error(
                    span,
                    format!(
                        "expected a number, a variable, P.., a function or \"[\", found {found}"
                    ),
                );
                None
            }
        }
    }

    /// `FUNC[args]`, the cursor on the function's name.
    fn call(&mut self, func: Func) -> Option<Expr> {
        let span = self.span();
        self.bump();
        let open = self.span();
        self.bump();
        let mut args = vec![self.expr()?];
        while self.is_punct(",") {
            self.bump();
            args.push(self.expr()?);
        }
        self.close_bracket(open)?;
        if args.len() != func.arity() {
            self.error(
                span,
                format!(
                    "{}[...] takes {} argument(s), found {}",
                    func.name(),
                    func.arity(),
                    args.len()
                ),
            );
            return None;
        }
        Some(Expr::Call(Box::new((func, args))))
    }
}
