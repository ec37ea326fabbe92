//! The operations on values: integers wrap to their type's width as the PLC's do, unsigned
//! types compare and divide without a sign, reals stay reals; a division by zero and a
//! conversion of a value its type cannot hold are faults.

use super::{Fault, V};
use crate::ast::BinOp;
use crate::ir::StdFn;
use crate::types::{Class, Elem};

type Run<T> = Result<T, Fault>;

/// `v` cut to the width of `t` (sign-extended for a signed type).
#[inline]
pub(crate) fn wrap(v: i64, t: Elem) -> i64 {
    match t {
        Elem::Bool | Elem::Byte | Elem::USInt => i64::from(v as u8),
        Elem::SInt => i64::from(v as i8),
        Elem::Word | Elem::UInt => i64::from(v as u16),
        Elem::Int => i64::from(v as i16),
        Elem::DWord | Elem::UDInt => i64::from(v as u32),
        Elem::DInt | Elem::Time => i64::from(v as i32),
        _ => v,
    }
}

/// Whether `t` is read without a sign.
pub(crate) fn unsigned(t: Elem) -> bool {
    matches!(t.class(), Class::Unsigned | Class::Bits | Class::Bool)
}

fn is_float(t: Elem) -> bool {
    t.class() == Class::Float
}

/// An output's value `v` of type `t` as the place of type `there` takes it: negated (a
/// BOOL's `NOT out =>`), converted when the place's type is one `t` widens to (TIME to LTIME
/// counts nanoseconds, an integer to a real its value).
#[inline]
pub(crate) fn output(v: V, negated: bool, t: Elem, there: Elem) -> Run<V> {
    let v = if negated {
        V::I(i64::from(v.int() == 0))
    } else {
        v
    };
    if t == there {
        Ok(v)
    } else {
        convert(v, t, there)
    }
}

pub(crate) fn neg(v: V, t: Elem) -> V {
    if is_float(t) {
        V::F(-v.float())
    } else {
        V::I(wrap(v.int().wrapping_neg(), t))
    }
}

pub(crate) fn not(v: V, t: Elem) -> V {
    if t == Elem::Bool {
        V::I(i64::from(v.int() == 0))
    } else {
        V::I(wrap(!v.int(), t))
    }
}

/// A real result, refused when it is not finite.
fn finite(v: f64) -> Run<V> {
    if v.is_finite() {
        Ok(V::F(v))
    } else {
        Err(Fault::OutOfRange)
    }
}

#[inline(always)]
pub(crate) fn binary(op: BinOp, t: Elem, x: V, y: V) -> Run<V> {
    match (op, x, y) {
        (BinOp::Eq | BinOp::Ne | BinOp::Lt | BinOp::Gt | BinOp::Le | BinOp::Ge, _, _) => {
            Ok(V::I(i64::from(compare(op, t, x, y))))
        }
        (_, V::I(a), V::I(b)) if !is_float(t) => integer(op, t, a, b),
        _ => {
            let (a, b) = (x.float(), y.float());
            match op {
                BinOp::Add => finite(a + b),
                BinOp::Sub => finite(a - b),
                BinOp::Mul => finite(a * b),
                BinOp::Div if b == 0.0 => Err(Fault::DivisionByZero),
                BinOp::Div => finite(a / b),
                BinOp::Pow => finite(a.powf(b)),
                _ => Err(Fault::OutOfRange),
            }
        }
    }
}

/// [`binary`] of two integers of type `t` (no real): the integer result.
#[inline(always)]
pub(crate) fn binary_int(op: BinOp, t: Elem, a: i64, b: i64) -> Run<i64> {
    match op {
        BinOp::Eq | BinOp::Ne | BinOp::Lt | BinOp::Gt | BinOp::Le | BinOp::Ge => {
            Ok(i64::from(compare_int(op, t, a, b)))
        }
        _ => integer(op, t, a, b).map(V::int),
    }
}

/// [`compare`] of two integers of type `t` (no real).
#[inline(always)]
pub(crate) fn compare_int(op: BinOp, t: Elem, a: i64, b: i64) -> bool {
    let ord = if unsigned(t) {
        (a as u64).cmp(&(b as u64))
    } else {
        a.cmp(&b)
    };
    holds(op, ord)
}

/// Whether comparison `op` holds of two values ordered `ord`.
#[inline(always)]
fn holds(op: BinOp, ord: std::cmp::Ordering) -> bool {
    match op {
        BinOp::Eq => ord.is_eq(),
        BinOp::Ne => ord.is_ne(),
        BinOp::Lt => ord.is_lt(),
        BinOp::Gt => ord.is_gt(),
        BinOp::Le => ord.is_le(),
        _ => ord.is_ge(),
    }
}

#[inline]
fn integer(op: BinOp, t: Elem, a: i64, b: i64) -> Run<V> {
    let v = match op {
        BinOp::Add => a.wrapping_add(b),
        BinOp::Sub => a.wrapping_sub(b),
        BinOp::Mul => a.wrapping_mul(b),
        BinOp::And => a & b,
        BinOp::Or => a | b,
        BinOp::Xor => a ^ b,
        BinOp::Div | BinOp::Mod if b == 0 => return Err(Fault::DivisionByZero),
        BinOp::Div if unsigned(t) => ((a as u64) / (b as u64)) as i64,
        BinOp::Div => a.wrapping_div(b),
        BinOp::Mod if unsigned(t) => ((a as u64) % (b as u64)) as i64,
        BinOp::Mod => a.wrapping_rem(b),
        _ => return Err(Fault::OutOfRange),
    };
    Ok(V::I(wrap(v, t)))
}

#[inline]
pub(crate) fn compare(op: BinOp, t: Elem, x: V, y: V) -> bool {
    let ord = if is_float(t) {
        x.float().partial_cmp(&y.float())
    } else if unsigned(t) {
        Some((x.int() as u64).cmp(&(y.int() as u64)))
    } else {
        Some(x.int().cmp(&y.int()))
    };
    match ord {
        Some(ord) => holds(op, ord),
        None => op == BinOp::Ne,
    }
}

/// `v` of type `from` as a `to`: reals round to the nearest integer; a value the integer
/// type cannot hold, or a real that is not finite, is a fault.
#[inline]
pub(crate) fn convert(v: V, from: Elem, to: Elem) -> Run<V> {
    match (is_float(from), is_float(to)) {
        (_, true) => {
            let f = match v {
                V::I(i) if unsigned(from) => i as u64 as f64,
                other => other.float(),
            };
            finite(f)
        }
        (true, false) => {
            let f = v.float().round();
            match to.range() {
                // `hi as f64 + 1.0` is exclusive: i64::MAX as f64 is already 2^63.
                Some((lo, hi)) if f >= lo as f64 && f < hi as f64 + 1.0 => {
                    Ok(V::I(f as i128 as i64))
                }
                _ if to == Elem::LTime || to == Elem::Time => Ok(V::I(wrap(f as i64, to))),
                _ => Err(Fault::OutOfRange),
            }
        }
        (false, false) if to == Elem::Bool => Ok(V::I(i64::from(v.int() != 0))),
        // TIME counts ms, LTIME ns (a TIME's fits an LTIME's 64 bits a million times over).
        (false, false) if (from, to) == (Elem::Time, Elem::LTime) => {
            Ok(V::I(v.int().saturating_mul(1_000_000)))
        }
        (false, false) if (from, to) == (Elem::LTime, Elem::Time) => {
            Ok(V::I(wrap(v.int() / 1_000_000, to)))
        }
        (false, false) => Ok(V::I(wrap(v.int(), to))),
    }
}

/// A standard function of values of type `t` (the selector of SEL and MUX and a shift's
/// count are integers).
pub(crate) fn standard(f: StdFn, t: Elem, v: &[V]) -> Run<V> {
    let real = |g: fn(f64) -> f64| finite(g(v[0].float()));
    match f {
        StdFn::Abs if is_float(t) => Ok(V::F(v[0].float().abs())),
        StdFn::Abs => Ok(V::I(wrap(v[0].int().wrapping_abs(), t))),
        StdFn::Sqrt => real(f64::sqrt),
        StdFn::Ln => real(f64::ln),
        StdFn::Log => real(f64::log10),
        StdFn::Exp => real(f64::exp),
        StdFn::Sin => real(f64::sin),
        StdFn::Cos => real(f64::cos),
        StdFn::Tan => real(f64::tan),
        StdFn::Asin => real(f64::asin),
        StdFn::Acos => real(f64::acos),
        StdFn::Atan => real(f64::atan),
        StdFn::Trunc => {
            let x = v[0].float().trunc();
            convert(V::F(x), Elem::LReal, Elem::DInt)
        }
        StdFn::Min | StdFn::Max => {
            let want = if f == StdFn::Min {
                BinOp::Lt
            } else {
                BinOp::Gt
            };
            let mut best = v[0];
            for x in &v[1..] {
                if compare(want, t, *x, best) {
                    best = *x;
                }
            }
            Ok(best)
        }
        StdFn::Limit => {
            let (lo, x, hi) = (v[0], v[1], v[2]);
            Ok(if compare(BinOp::Lt, t, x, lo) {
                lo
            } else if compare(BinOp::Gt, t, x, hi) {
                hi
            } else {
                x
            })
        }
        StdFn::Sel => Ok(if v[0].int() != 0 { v[2] } else { v[1] }),
        StdFn::Mux => {
            let k = v[0].int();
            match usize::try_from(k).ok().and_then(|k| v[1..].get(k)) {
                Some(x) => Ok(*x),
                None => Err(Fault::MuxSelector),
            }
        }
        StdFn::Shl | StdFn::Shr | StdFn::Rol | StdFn::Ror => {
            Ok(V::I(shift(f, t, v[0].int(), v[1].int())))
        }
        StdFn::Expt => finite(v[0].float().powf(v[1].float())),
        StdFn::Move => Ok(v[0]),
        // The clock and the program's memory are the runtime's (`Exec::std_fn`).
        StdFn::Now | StdFn::MemCpy | StdFn::MemSet | StdFn::MemCmp => Err(Fault::OutOfRange),
    }
}

fn shift(f: StdFn, t: Elem, x: i64, n: i64) -> i64 {
    let bits = 8 * t.size() as u32;
    let n = n.clamp(0, 64) as u32;
    let mask = if bits >= 64 {
        u64::MAX
    } else {
        (1u64 << bits) - 1
    };
    let u = x as u64 & mask;
    let r = match f {
        StdFn::Shl => u.checked_shl(n).unwrap_or(0),
        StdFn::Shr => u.checked_shr(n).unwrap_or(0),
        StdFn::Rol => {
            let n = n % bits;
            (u << n | u.checked_shr(bits - n).unwrap_or(0)) & mask
        }
        _ => {
            let n = n % bits;
            (u >> n | u.checked_shl(bits - n).unwrap_or(0)) & mask
        }
    };
    wrap(r as i64, t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers_wrap_to_their_width() {
        assert_eq!(wrap(32768, Elem::Int), -32768);
        assert_eq!(wrap(-1, Elem::UInt), 65535);
        assert_eq!(
            binary(BinOp::Add, Elem::SInt, V::I(127), V::I(1)),
            Ok(V::I(-128))
        );
        assert_eq!(
            binary(BinOp::Div, Elem::DInt, V::I(1), V::I(0)),
            Err(Fault::DivisionByZero)
        );
        assert_eq!(
            binary(BinOp::Gt, Elem::UDInt, V::I(wrap(-1, Elem::UDInt)), V::I(1)),
            Ok(V::I(1))
        );
        assert_eq!(convert(V::F(2.5), Elem::LReal, Elem::Int), Ok(V::I(3)));
        assert_eq!(
            convert(V::F(1e9), Elem::LReal, Elem::Int),
            Err(Fault::OutOfRange)
        );
        assert_eq!(shift(StdFn::Rol, Elem::Byte, 0x81, 1), 0x03);
    }
}
