//! Arithmetic of expressions: the operators and built-in functions, with the dialect's rules
//! (angles in degrees, a condition holds when its value is at least 0.5 in size). A result that
//! is not a number a program can use is an error naming why, never a NaN passed on.

use super::ast::{BinOp, Func};

/// Whether a condition value counts as true: |v| >= 0.5, as the dialect tests conditions.
pub fn truth(v: f64) -> bool {
    v.abs() >= 0.5
}

fn flag(c: bool) -> f64 {
    if c {
        1.0
    } else {
        0.0
    }
}

/// Why an operator or function has no value a program can use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EvalError {
    /// `a / 0`.
    DivisionByZero,
    /// `a MOD 0`.
    ModByZero,
    /// A negative number to a fractional power.
    NegativeToFraction,
    /// 0 to a negative power.
    ZeroToNegative,
    /// `SQRT` of a negative value.
    SqrtNegative,
    /// `LN` of 0 or less.
    LnNotPositive,
    /// `TAN` at an odd multiple of 90 degrees.
    TanPole,
    /// `ASIN`/`ACOS` outside -1..1.
    AsinAcosRange,
}

impl core::fmt::Display for EvalError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            EvalError::DivisionByZero => "division by zero",
            EvalError::ModByZero => "MOD by zero",
            EvalError::NegativeToFraction => {
                "a negative number to a fractional power (**) has no real value"
            }
            EvalError::ZeroToNegative => "0 to a negative power (**) is a division by zero",
            EvalError::SqrtNegative => "SQRT of a negative value",
            EvalError::LnNotPositive => "LN of a value that is not positive",
            EvalError::TanPole => "TAN of an odd multiple of 90 degrees",
            EvalError::AsinAcosRange => "ASIN/ACOS of a value outside -1..1",
        })
    }
}

/// `a op b`.
pub fn binary(op: BinOp, a: f64, b: f64) -> Result<f64, EvalError> {
    Ok(match op {
        BinOp::Add => a + b,
        BinOp::Sub => a - b,
        BinOp::Mul => a * b,
        BinOp::Div => {
            if b == 0.0 {
                return Err(EvalError::DivisionByZero);
            }
            a / b
        }
        BinOp::Mod => {
            if b == 0.0 {
                return Err(EvalError::ModByZero);
            }
            a % b
        }
        BinOp::Pow => {
            if a < 0.0 && b.fract() != 0.0 {
                return Err(EvalError::NegativeToFraction);
            }
            if a == 0.0 && b < 0.0 {
                return Err(EvalError::ZeroToNegative);
            }
            a.powf(b)
        }
        BinOp::Eq => flag(a == b),
        BinOp::Ne => flag(a != b),
        BinOp::Lt => flag(a < b),
        BinOp::Le => flag(a <= b),
        BinOp::Gt => flag(a > b),
        BinOp::Ge => flag(a >= b),
        BinOp::And => flag(truth(a) && truth(b)),
        BinOp::Or => flag(truth(a) || truth(b)),
        BinOp::Xor => flag(truth(a) != truth(b)),
    })
}

/// `func[a]` or `func[a, b]` (ATAN2 takes y, then x).
pub fn function(func: Func, a: f64, b: Option<f64>) -> Result<f64, EvalError> {
    Ok(match func {
        Func::Abs => a.abs(),
        Func::Sqr => a * a,
        Func::Sqrt => {
            if a < 0.0 {
                return Err(EvalError::SqrtNegative);
            }
            a.sqrt()
        }
        Func::Exp => a.exp(),
        Func::Ln => {
            if a <= 0.0 {
                return Err(EvalError::LnNotPositive);
            }
            a.ln()
        }
        Func::Sin => sin_deg(a),
        Func::Cos => sin_deg(a + 90.0),
        Func::Tan => {
            let c = sin_deg(a + 90.0);
            if c == 0.0 {
                return Err(EvalError::TanPole);
            }
            sin_deg(a) / c
        }
        Func::Asin | Func::Acos => {
            if !(-1.0..=1.0).contains(&a) {
                return Err(EvalError::AsinAcosRange);
            }
            if func == Func::Asin {
                a.asin().to_degrees()
            } else {
                a.acos().to_degrees()
            }
        }
        Func::Atan => a.atan().to_degrees(),
        Func::Atan2 => a.atan2(b.unwrap_or(1.0)).to_degrees(),
        Func::Int => a.trunc(),
        Func::Fract => a.fract(),
        Func::Round => a.round(),
        Func::Not => flag(!truth(a)),
    })
}

/// The sine of `deg` degrees, exact at multiples of 30 and 90 degrees (so that `COS[90]` is 0
/// and `SIN[30]` is 0.5, as a programmer writing them means).
fn sin_deg(deg: f64) -> f64 {
    let r = deg.rem_euclid(360.0);
    let exact = [
        (0.0, 0.0),
        (30.0, 0.5),
        (90.0, 1.0),
        (150.0, 0.5),
        (180.0, 0.0),
        (210.0, -0.5),
        (270.0, -1.0),
        (330.0, -0.5),
    ];
    exact
        .iter()
        .find(|(at, _)| *at == r)
        .map_or_else(|| r.to_radians().sin(), |(_, v)| *v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn functions_work_in_degrees_and_refuse_what_has_no_value() {
        assert_eq!(function(Func::Sin, 30.0, None), Ok(0.5));
        assert_eq!(function(Func::Cos, 90.0, None), Ok(0.0));
        assert!((function(Func::Cos, 60.0, None).unwrap() - 0.5).abs() < 1e-15);
        assert!((function(Func::Atan2, 1.0, Some(1.0)).unwrap() - 45.0).abs() < 1e-12);
        assert_eq!(
            function(Func::Sqrt, -1.0, None),
            Err(EvalError::SqrtNegative)
        );
        assert_eq!(
            EvalError::SqrtNegative.to_string(),
            "SQRT of a negative value"
        );
        assert!(function(Func::Ln, 0.0, None).is_err());
        assert!(function(Func::Tan, 90.0, None).is_err());
        assert_eq!(function(Func::Fract, -2.25, None), Ok(-0.25));
        assert_eq!(function(Func::Int, -2.75, None), Ok(-2.0));
        assert_eq!(function(Func::Not, 0.3, None), Ok(1.0));
        assert_eq!(binary(BinOp::Pow, 2.0, 10.0), Ok(1024.0));
        assert_eq!(binary(BinOp::Mod, 7.0, 3.0), Ok(1.0));
        assert!(binary(BinOp::Div, 1.0, 0.0).is_err());
        assert_eq!(binary(BinOp::And, 0.6, 0.4), Ok(0.0));
        assert_eq!(binary(BinOp::Xor, 1.0, 0.0), Ok(1.0));
    }
}
