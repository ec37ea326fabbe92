//! Values at decode time: the [`Vars`] a block reads, and the context that evaluates its
//! expressions and collects its diagnostics.

use super::DecodeError;
use crate::nc::ast::*;

/// Values of NC variables at decode time.
pub trait Vars {
    /// The value of `name` (upper case, e.g. `V.G.TRACK_CS.X`, `V.P.DEPTH`); `None` if there
    /// is no such variable.
    fn get(&self, name: &str) -> Option<f64>;

    /// The value of P parameter `n`; `None` while it has not been assigned.
    fn param(&self, n: u32) -> Option<f64> {
        let _ = n;
        None
    }

    /// Whether the program's own variables (P, `V.P.`, `V.L.`) are unknown here: a block
    /// checked on its own, outside a run, has no values for them, and that is no error.
    fn program_values_unknown(&self) -> bool {
        false
    }

    /// Whether the `V.G.` values are those of a running machine (a check has placeholders:
    /// where a condition on them leads is not known then).
    fn machine_values_known(&self) -> bool {
        true
    }
}

/// The channel variables known to the decoder, all 0: what `cnc check` uses.
#[derive(Debug, Clone, Copy, Default)]
pub struct ZeroVars;

/// The variables the language defines.
pub const KNOWN_VARIABLES: &[&str] = &[
    "V.G.TRACK_CS.X",
    "V.G.TRACK_CS.Y",
    "V.G.TRACK_CS.Z",
    "V.G.TRACK_CS.A",
    "V.G.TRACK_CS.B",
    "V.G.TRACK_CS.C",
];

impl Vars for ZeroVars {
    fn get(&self, name: &str) -> Option<f64> {
        KNOWN_VARIABLES.contains(&name).then_some(0.0)
    }
    fn machine_values_known(&self) -> bool {
        false
    }
}

/// One decoding (a block, or an expression): the variables it reads and the errors it finds.
pub(super) struct Ctx<'a> {
    pub(super) vars: &'a dyn Vars,
    /// The first error and where it stands: what a run stops at.
    pub(super) first: Option<(Span, DecodeError)>,
    /// The errors after the first, for a check that reports them all (`None` in a run: the
    /// tick allocates nothing for a failing block).
    pub(super) more: Option<Vec<(Span, DecodeError)>>,
}

impl<'a> Ctx<'a> {
    /// A decoding that keeps its first error only (a run).
    pub(super) fn first_only(vars: &'a dyn Vars) -> Self {
        Self {
            vars,
            first: None,
            more: None,
        }
    }

    /// A decoding that keeps every error (a check).
    pub(super) fn all(vars: &'a dyn Vars) -> Self {
        Self {
            vars,
            first: None,
            more: Some(Vec::new()),
        }
    }

    pub(super) fn error(&mut self, span: Span, error: impl Into<DecodeError>) {
        let error = (span, error.into());
        if self.first.is_none() {
            self.first = Some(error);
        } else if let Some(more) = self.more.as_mut() {
            more.push(error);
        }
    }

    /// Every error found, in order.
    pub(super) fn into_errors(self) -> impl Iterator<Item = (Span, DecodeError)> {
        self.first
            .into_iter()
            .chain(self.more.into_iter().flatten())
    }

    /// The value of `e`: a literal at once (nearly every word of a program), anything else
    /// through [`Ctx::eval_expr`].
    #[inline(always)]
    pub(super) fn eval(&mut self, e: &Expr, span: Span) -> Option<f64> {
        match e {
            Expr::Num(v) => Some(*v),
            _ => self.eval_expr(e, span),
        }
    }

    fn eval_expr(&mut self, e: &Expr, span: Span) -> Option<f64> {
        let value = match e {
            Expr::Num(v) => Some(*v),
            Expr::Var(name) => self.variable(name, span),
            Expr::Param(n) => match self.vars.param(*n) {
                Some(v) => Some(v),
                None if self.vars.program_values_unknown() => None,
                None => {
                    self.error(span, DecodeError::UnassignedParam { number: *n });
                    None
                }
            },
            Expr::Neg(inner) => self.eval(inner, span).map(|v| -v),
            Expr::Call(call) => {
                let (func, args) = &**call;
                let a = self.eval(args.first()?, span)?;
                let b = match args.get(1) {
                    Some(b) => Some(self.eval(b, span)?),
                    None => None,
                };
                match crate::nc::eval::function(*func, a, b) {
                    Ok(v) => Some(v),
                    Err(e) => {
                        self.error(span, e);
                        None
                    }
                }
            }
            Expr::Bin(bin) => {
                let (op, a, b) = &**bin;
                let (a, b) = (self.eval(a, span)?, self.eval(b, span)?);
                match crate::nc::eval::binary(*op, a, b) {
                    Ok(v) => Some(v),
                    Err(e) => {
                        self.error(span, e);
                        None
                    }
                }
            }
        }?;
        if !value.is_finite() {
            self.error(span, DecodeError::NotFinite { value });
            return None;
        }
        Some(value)
    }

    fn variable(&mut self, name: &Name, span: Span) -> Option<f64> {
        if let Some(v) = self.vars.get(name) {
            return Some(v);
        }
        let own = name.starts_with("V.P.") || name.starts_with("V.L.");
        if own && self.vars.program_values_unknown() {
            return None;
        }
        let name = *name;
        if own {
            self.error(span, DecodeError::UnassignedVariable { name });
        } else if name.starts_with("V.G.WZ_AKT.") {
            self.error(span, DecodeError::ToolVariable { name });
        } else {
            self.error(span, DecodeError::UnknownVariable { name });
        }
        None
    }

    /// A whole number within `range`, else an error naming `what`.
    pub(super) fn whole(
        &mut self,
        e: &Expr,
        span: Span,
        what: &str,
        min: f64,
        max: f64,
    ) -> Option<u32> {
        let v = self.eval(e, span)?;
        if v.fract() != 0.0 || v < min || v > max {
            let what = Name::from(what);
            self.error(
                span,
                DecodeError::NotWhole {
                    what,
                    min,
                    max,
                    value: v,
                },
            );
            return None;
        }
        Some(v as u32)
    }
}

/// Evaluates `expr` with the variables of `vars`; the error says what went wrong (an unknown
/// variable, a division by zero, a value that is not finite...). Allocates nothing.
pub fn evaluate(expr: &Expr, vars: &dyn Vars) -> Result<f64, DecodeError> {
    let mut ctx = Ctx::first_only(vars);
    match (ctx.eval(expr, Span::default()), ctx.first) {
        (Some(v), None) => Ok(v),
        (_, Some((_, e))) => Err(e),
        (None, None) => Err(DecodeError::NoValue),
    }
}
