//! Expressions: [`Expr`] with its operators ([`BinOp`]) and functions ([`Func`]).

use super::Name;

/// Binary operators of expressions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinOp {
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/`
    Div,
    /// `==`
    Eq,
    /// `!=`
    Ne,
    /// `<`
    Lt,
    /// `<=`
    Le,
    /// `>`
    Gt,
    /// `>=`
    Ge,
    /// `MOD` (remainder, with the sign of the dividend)
    Mod,
    /// `**` (power)
    Pow,
    /// `AND` (both non-zero)
    And,
    /// `OR` (either non-zero)
    Or,
    /// `XOR` (exactly one non-zero)
    Xor,
}

impl BinOp {
    /// Source spelling.
    pub fn symbol(self) -> &'static str {
        match self {
            BinOp::Add => "+",
            BinOp::Sub => "-",
            BinOp::Mul => "*",
            BinOp::Div => "/",
            BinOp::Eq => "==",
            BinOp::Ne => "!=",
            BinOp::Lt => "<",
            BinOp::Le => "<=",
            BinOp::Gt => ">",
            BinOp::Ge => ">=",
            BinOp::Mod => "MOD",
            BinOp::Pow => "**",
            BinOp::And => "AND",
            BinOp::Or => "OR",
            BinOp::Xor => "XOR",
        }
    }

    /// Binding strength (higher binds tighter): OR and XOR, then AND, then the comparisons,
    /// then sums, products and MOD, and the power tightest.
    pub fn precedence(self) -> u8 {
        match self {
            BinOp::Or | BinOp::Xor => 1,
            BinOp::And => 2,
            BinOp::Eq | BinOp::Ne | BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge => 3,
            BinOp::Add | BinOp::Sub => 4,
            BinOp::Mul | BinOp::Div | BinOp::Mod => 5,
            BinOp::Pow => 6,
        }
    }
}

/// The built-in functions of expressions, written `NAME[args]`. Angles are in degrees.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Func {
    /// `ABS[x]`
    Abs,
    /// `SQR[x]`: x squared.
    Sqr,
    /// `SQRT[x]`
    Sqrt,
    /// `EXP[x]`
    Exp,
    /// `LN[x]`
    Ln,
    /// `SIN[deg]`
    Sin,
    /// `COS[deg]`
    Cos,
    /// `TAN[deg]`
    Tan,
    /// `ASIN[x]` in degrees.
    Asin,
    /// `ACOS[x]` in degrees.
    Acos,
    /// `ATAN[x]` in degrees.
    Atan,
    /// `ATAN2[y, x]` in degrees.
    Atan2,
    /// `INT[x]`: the whole part (toward zero).
    Int,
    /// `FRACT[x]`: the fractional part (x - INT[x]).
    Fract,
    /// `ROUND[x]`: the nearest whole number (halves away from zero).
    Round,
    /// `NOT[x]`: 1 when x is 0, else 0.
    Not,
}

impl Func {
    /// Every function with its spelling and number of arguments.
    pub const ALL: [(Func, &'static str, usize); 16] = [
        (Func::Abs, "ABS", 1),
        (Func::Sqr, "SQR", 1),
        (Func::Sqrt, "SQRT", 1),
        (Func::Exp, "EXP", 1),
        (Func::Ln, "LN", 1),
        (Func::Sin, "SIN", 1),
        (Func::Cos, "COS", 1),
        (Func::Tan, "TAN", 1),
        (Func::Asin, "ASIN", 1),
        (Func::Acos, "ACOS", 1),
        (Func::Atan, "ATAN", 1),
        (Func::Atan2, "ATAN2", 2),
        (Func::Int, "INT", 1),
        (Func::Fract, "FRACT", 1),
        (Func::Round, "ROUND", 1),
        (Func::Not, "NOT", 1),
    ];

    /// The function spelled `name` (upper case).
    pub fn named(name: &str) -> Option<Func> {
        Self::ALL.iter().find(|f| f.1 == name).map(|f| f.0)
    }

    /// Source spelling.
    pub fn name(self) -> &'static str {
        Self::ALL.iter().find(|f| f.0 == self).map_or("?", |f| f.1)
    }

    /// Number of arguments.
    pub fn arity(self) -> usize {
        Self::ALL.iter().find(|f| f.0 == self).map_or(1, |f| f.2)
    }
}

/// An arithmetic expression.
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    /// A literal number.
    Num(f64),
    /// A variable such as `V.G.TRACK_CS.X` (boxed: variables are rare next to numbers, and
    /// an inline name would double the size of every expression and item).
    Var(Box<Name>),
    /// Unary minus.
    Neg(Box<Expr>),
    /// A binary operation on two operands (one box for both keeps [`Expr`] at 16 bytes).
    Bin(Box<(BinOp, Expr, Expr)>),
    /// A P parameter `P12`.
    Param(u32),
    /// A function `SIN[...]`, `ATAN2[y, x]` with its arguments.
    Call(Box<(Func, Vec<Expr>)>),
}
