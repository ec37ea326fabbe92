//! The string functions at run time: a STRING computed into a buffer on the stack (at most
//! [`MAX_TEXT`] characters, as TwinCAT's string functions return STRING(255)), never on the
//! heap; numbers written and read as text by `core::fmt` and `str::parse`, which allocate
//! nothing.
//!
//! Lengths and positions count characters from 1, as IEC 61131-3's: a negative length, or a
//! position before the first character (before 0 for INSERT) is a fault naming it; a length
//! or position beyond the end reaches the end (`LEFT('abc', 5)` is 'abc', `MID('abc', 2, 7)`
//! is ''), as TwinCAT's functions do.

use super::{ops, Exec, Fault, Run, V};
use crate::ast::BinOp;
use crate::ir::{Addr, Ex, Text, TextEx, TextFn, MAX_TEXT};
use crate::types::{Class, Elem};
use core::cmp::Ordering;
use core::fmt::Write;

/// A computed STRING's characters.
pub(super) struct Buf {
    bytes: [u8; MAX_TEXT],
    len: usize,
}

impl Buf {
    pub(super) fn new() -> Buf {
        Buf {
            bytes: [0; MAX_TEXT],
            len: 0,
        }
    }

    /// Appends `more`, as much as still fits.
    fn push(&mut self, more: &[u8]) {
        let n = more.len().min(MAX_TEXT - self.len);
        self.bytes[self.len..self.len + n].copy_from_slice(&more[..n]);
        self.len += n;
    }

    pub(super) fn chars(&self) -> &[u8] {
        &self.bytes[..self.len]
    }
}

impl Write for Buf {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        self.push(s.as_bytes());
        Ok(())
    }
}

/// The characters before the first NUL.
pub(super) fn before_nul(bytes: &[u8]) -> &[u8] {
    let end = bytes.iter().position(|c| *c == 0).unwrap_or(bytes.len());
    &bytes[..end]
}

impl Exec<'_> {
    /// Appends the characters of `t` to `out`.
    pub(super) fn text_into(&mut self, t: &Text, base: u32, out: &mut Buf) -> Run<()> {
        match t {
            Text::Const(lit) => out.push(before_nul(lit)),
            Text::At(addr, n) => {
                let at = self.own(addr, base)?;
                let n = *n as usize;
                self.check(at, n)?;
                out.push(before_nul(&self.st.memory[at..at + n]));
            }
            Text::Fn(f) => self.text_fn(f, base, out)?,
        }
        Ok(())
    }

    fn text_fn(&mut self, f: &TextFn, base: u32, out: &mut Buf) -> Run<()> {
        let mut s = Buf::new();
        match f {
            TextFn::Concat(parts) => {
                for p in parts {
                    self.text_into(p, base, out)?;
                }
                return Ok(());
            }
            TextFn::Of(t, e) => {
                let v = self.eval(e, base)?;
                return write_value(out, *t, v);
            }
            TextFn::Call(c, size) => {
                self.call_function(c, base)?;
                let at = self.own(&c.value, base)?;
                let n = *size as usize;
                self.check(at, n)?;
                out.push(before_nul(&self.st.memory[at..at + n]));
                return Ok(());
            }
            TextFn::Left(a, _)
            | TextFn::Right(a, _)
            | TextFn::Mid(a, _, _)
            | TextFn::Insert(a, _, _)
            | TextFn::Delete(a, _, _)
            | TextFn::Replace(a, _, _, _) => self.text_into(a, base, &mut s)?,
        }
        let chars = s.chars();
        let len = chars.len();
        match f {
            TextFn::Left(_, n) => {
                let n = self.count(n, 0, base)?.min(len);
                out.push(&chars[..n]);
            }
            TextFn::Right(_, n) => {
                let n = self.count(n, 0, base)?.min(len);
                out.push(&chars[len - n..]);
            }
            TextFn::Mid(_, n, p) => {
                let (n, from) = (self.count(n, 0, base)?, self.count(p, 1, base)? - 1);
                let from = from.min(len);
                out.push(&chars[from..(from + n).min(len)]);
            }
            TextFn::Insert(_, b, p) => {
                // The values in their order: the second STRING before the position.
                let mut t = Buf::new();
                self.text_into(b, base, &mut t)?;
                let at = self.count(p, 0, base)?.min(len);
                out.push(&chars[..at]);
                out.push(t.chars());
                out.push(&chars[at..]);
            }
            TextFn::Delete(_, n, p) | TextFn::Replace(_, _, n, p) => {
                let mut t = Buf::new();
                if let TextFn::Replace(_, b, _, _) = f {
                    self.text_into(b, base, &mut t)?;
                }
                let (n, from) = (self.count(n, 0, base)?, self.count(p, 1, base)? - 1);
                let from = from.min(len);
                out.push(&chars[..from]);
                out.push(t.chars());
                out.push(&chars[(from + n).min(len)..]);
            }
            TextFn::Concat(_) | TextFn::Of(..) | TextFn::Call(..) => {}
        }
        Ok(())
    }

    /// A length or position of at least `lo` (a fault naming it below), at most
    /// [`MAX_TEXT`] where it is larger.
    fn count(&mut self, e: &Ex, lo: i64, base: u32) -> Run<usize> {
        let v = self.eval(e, base)?.int();
        if v < lo {
            return Err(self.fault_with(Fault::IndexOutOfRange, [v, lo, MAX_TEXT as i64]));
        }
        Ok(v.min(MAX_TEXT as i64) as usize)
    }

    /// Two STRINGs ordered by their bytes.
    pub(super) fn text_cmp(&mut self, x: &Text, y: &Text, base: u32) -> Run<Ordering> {
        let (mut a, mut b) = (Buf::new(), Buf::new());
        self.text_into(x, base, &mut a)?;
        self.text_into(y, base, &mut b)?;
        Ok(a.chars().cmp(b.chars()))
    }

    /// A value computed from STRINGs (out of line: its buffers stay off the tree walker's
    /// frames).
    #[inline(never)]
    pub(super) fn text_value(&mut self, e: &TextEx, base: u32) -> Run<V> {
        let mut a = Buf::new();
        match e {
            TextEx::Cmp(op, x, y) => {
                let o = self.text_cmp(x, y, base)?;
                Ok(V::I(i64::from(match op {
                    BinOp::Lt => o.is_lt(),
                    BinOp::Gt => o.is_gt(),
                    BinOp::Le => o.is_le(),
                    BinOp::Ge => o.is_ge(),
                    BinOp::Ne => o.is_ne(),
                    _ => o.is_eq(),
                })))
            }
            TextEx::Len(x) => {
                self.text_into(x, base, &mut a)?;
                Ok(V::I(a.chars().len() as i64))
            }
            TextEx::Find(x, y) => {
                let mut b = Buf::new();
                self.text_into(x, base, &mut a)?;
                self.text_into(y, base, &mut b)?;
                Ok(V::I(find(a.chars(), b.chars())))
            }
            TextEx::To(t, x) => {
                self.text_into(x, base, &mut a)?;
                read_value(a.chars(), *t)
            }
        }
    }

    /// A string function's result into the STRING of `size` bytes at `to` (its NUL
    /// included), cut to fit, the rest NUL.
    pub(super) fn store_text(&mut self, to: &Addr, size: u32, t: &Text, base: u32) -> Run<()> {
        let mut s = Buf::new();
        self.text_into(t, base, &mut s)?;
        let at = self.own(to, base)?;
        self.put_text(at, size as usize, s.chars())
    }

    /// `chars` into the STRING of `size` bytes at `at` of the program's memory (its NUL
    /// included), cut to fit, the rest NUL.
    pub(super) fn put_text(&mut self, at: usize, size: usize, chars: &[u8]) -> Run<()> {
        self.check(at, size)?;
        let place = &mut self.st.memory[at..at + size];
        let n = chars.len().min(size.saturating_sub(1));
        place[..n].copy_from_slice(&chars[..n]);
        place[n..].fill(0);
        Ok(())
    }
}

/// Where `needle` first starts in `hay`, from 1; 0 if nowhere (or if it is empty).
fn find(hay: &[u8], needle: &[u8]) -> i64 {
    if needle.is_empty() || needle.len() > hay.len() {
        return 0;
    }
    hay.windows(needle.len())
        .position(|w| w == needle)
        .map_or(0, |k| k as i64 + 1)
}

/// A value of type `t` as text: TRUE/FALSE, an integer in decimal, a real as its shortest
/// form that reads back the same (with an exponent beyond 1e15 and below 1e-5), a duration
/// as `T#1s500ms` (`LTIME#..` down to ns).
/// A REAL beyond REAL's range (computed in LREAL) faults as its conversion would.
fn write_value(out: &mut Buf, t: Elem, v: V) -> Run<()> {
    if t == Elem::Real && !(v.float() as f32).is_finite() {
        return Err(Fault::OutOfRange);
    }
    let _ = match (t.class(), v) {
        (Class::Bool, v) => out.write_str(if v.int() != 0 { "TRUE" } else { "FALSE" }),
        (Class::Unsigned | Class::Bits, v) => write!(out, "{}", v.int() as u64),
        (Class::Float, v) => {
            let x = v.float();
            let y = if t == Elem::Real {
                f64::from(x as f32)
            } else {
                x
            };
            let big = y != 0.0 && !(1e-5..1e15).contains(&y.abs());
            match (t == Elem::Real, big) {
                (true, true) => write!(out, "{:e}", x as f32),
                (true, false) => write!(out, "{}", x as f32),
                (false, true) => write!(out, "{x:e}"),
                (false, false) => write!(out, "{x}"),
            }
        }
        (Class::Duration, v) => write_duration(out, t == Elem::LTime, v.int()),
        (_, v) => write!(out, "{}", v.int()),
    };
    Ok(())
}

fn write_duration(out: &mut Buf, ns: bool, v: i64) -> core::fmt::Result {
    out.write_str(if ns { "LTIME#" } else { "T#" })?;
    if v < 0 {
        out.write_str("-")?;
    }
    let mut rest = v.unsigned_abs();
    let ms: u64 = if ns { 1_000_000 } else { 1 };
    let units: [(&str, u64); 7] = [
        ("d", 86_400_000 * ms),
        ("h", 3_600_000 * ms),
        ("m", 60_000 * ms),
        ("s", 1000 * ms),
        ("ms", ms),
        ("us", if ns { 1000 } else { 0 }),
        ("ns", if ns { 1 } else { 0 }),
    ];
    if rest == 0 {
        return out.write_str(if ns { "0ns" } else { "0ms" });
    }
    for (name, size) in units {
        if size > 0 && rest >= size {
            write!(out, "{}{name}", rest / size)?;
            rest %= size;
        }
    }
    Ok(())
}

/// Text as a value of type `t`: TRUE/FALSE (or 1/0) for BOOL; an integer with a sign, `_`
/// between digits and `2#`, `8#`, `16#` bases; a finite real as Rust reads one. Spaces
/// around it are skipped; anything else is a fault, as is a value the type cannot hold.
fn read_value(text: &[u8], t: Elem) -> Run<V> {
    let s = core::str::from_utf8(text)
        .map_err(|_| Fault::NoNumber)?
        .trim_matches(' ');
    match t.class() {
        Class::Bool if s.eq_ignore_ascii_case("TRUE") || s == "1" => Ok(V::I(1)),
        Class::Bool if s.eq_ignore_ascii_case("FALSE") || s == "0" => Ok(V::I(0)),
        Class::Bool => Err(Fault::NoNumber),
        Class::Duration => read_duration(s, t),
        Class::Float => {
            // Rust reads `inf` and `NaN` too: no numbers here.
            let named = s
                .bytes()
                .any(|c| c.is_ascii_alphabetic() && c != b'e' && c != b'E');
            let x: f64 = s.parse().map_err(|_| Fault::NoNumber)?;
            if named {
                return Err(Fault::NoNumber);
            }
            if !x.is_finite() || (t == Elem::Real && x.abs() > f64::from(f32::MAX)) {
                return Err(Fault::OutOfRange);
            }
            ops::convert(V::F(x), Elem::LReal, t)
        }
        _ => {
            let x = read_integer(s).ok_or(Fault::NoNumber)?;
            match t.range() {
                Some((lo, hi)) if (lo..=hi).contains(&x) => Ok(V::I(x as i64)),
                _ => Err(Fault::OutOfRange),
            }
        }
    }
}

/// A duration as the language writes one (`T#1s500ms`, `TIME#-2.5s`, `LTIME#1s5us`, the
/// prefix optional, `_` between parts and between digits): a TIME in whole ms (cut toward
/// 0, as a literal's), an LTIME in ns; counted in whole ns, so every LTIME reads back.
fn read_duration(s: &str, t: Elem) -> Run<V> {
    let starts = |p: &str| s.get(..p.len()).is_some_and(|h| h.eq_ignore_ascii_case(p));
    let prefix = ["LTIME#", "TIME#", "T#"].into_iter().find(|p| starts(p));
    let rest = &s[prefix.map_or(0, str::len)..];
    let (negative, mut rest) = match rest.strip_prefix('-') {
        Some(r) => (true, r),
        None => (false, rest),
    };
    if rest.is_empty() {
        return Err(Fault::NoNumber);
    }
    let mut ns = 0i128;
    while !rest.is_empty() {
        let (part, after) = duration_part(rest)?;
        ns = ns.checked_add(part).ok_or(Fault::OutOfRange)?;
        rest = after.strip_prefix('_').unwrap_or(after);
    }
    let ns = if negative { -ns } else { ns };
    let (v, most) = match t {
        Elem::LTime => (ns, i128::from(i64::MAX)),
        _ => (ns / 1_000_000, i128::from(i32::MAX)),
    };
    if !(-most - 1..=most).contains(&v) {
        return Err(Fault::OutOfRange);
    }
    Ok(V::I(v as i64))
}

/// One part of a duration (`2.5s`): its ns (a fraction rounded to the nearest), and the
/// rest of the text.
fn duration_part(s: &str) -> Run<(i128, &str)> {
    const UNITS: [(&str, i128); 7] = [
        ("d", 86_400_000_000_000),
        ("h", 3_600_000_000_000),
        ("m", 60_000_000_000),
        ("s", 1_000_000_000),
        ("ms", 1_000_000),
        ("us", 1_000),
        ("ns", 1),
    ];
    let (whole, _, beyond, after) = digits(s).ok_or(Fault::NoNumber)?;
    if beyond {
        // More than 18 digits before the point: beyond every duration.
        return Err(Fault::OutOfRange);
    }
    // Digits of the fraction beyond 18 are below a ns.
    let (numerator, denominator, after) = match after.strip_prefix('.') {
        Some(r) => digits(r).map_or((0, 1, r), |(v, p, _, a)| (v, p, a)),
        None => (0, 1, after),
    };
    let unit_end = after.find(|c: char| !c.is_ascii_alphabetic());
    let (unit, after) = after.split_at(unit_end.unwrap_or(after.len()));
    let scale = UNITS
        .iter()
        .find(|(name, _)| unit.eq_ignore_ascii_case(name))
        .ok_or(Fault::NoNumber)?
        .1;
    // At most 10^18 * 8.64e13 each: far within i128.
    let ns = whole * scale + (numerator * scale + denominator / 2) / denominator;
    Ok((ns, after))
}

/// The first (at most 18) digits at the start of `s` (`_` allowed between two): their
/// value and 10 to their count, whether more digits were left out, and the rest; `None` if
/// `s` does not start with a digit.
fn digits(s: &str) -> Option<(i128, i128, bool, &str)> {
    let bytes = s.as_bytes();
    if !bytes.first()?.is_ascii_digit() {
        return None;
    }
    let (mut value, mut power, mut more, mut k) = (0i128, 1i128, false, 0);
    while k < bytes.len() {
        let c = bytes[k];
        let between = c == b'_' && bytes.get(k + 1).is_some_and(u8::is_ascii_digit);
        if c.is_ascii_digit() {
            if power < 1_000_000_000_000_000_000 {
                value = value * 10 + i128::from(c - b'0');
                power *= 10;
            } else {
                more = true;
            }
        } else if !between {
            break;
        }
        k += 1;
    }
    Some((value, power, more, &s[k..]))
}

/// An integer as the language writes one, `None` if `s` is none.
fn read_integer(s: &str) -> Option<i128> {
    let (negative, s) = match s.as_bytes().first()? {
        b'-' => (true, &s[1..]),
        b'+' => (false, &s[1..]),
        _ => (false, s),
    };
    let (radix, digits) = match s.split_once('#') {
        Some(("2", d)) => (2, d),
        Some(("8", d)) => (8, d),
        Some(("16", d)) => (16, d),
        Some(_) => return None,
        None => (10, s),
    };
    let ok = !digits.is_empty()
        && !digits.starts_with('_')
        && !digits.ends_with('_')
        && !digits.contains("__");
    // Beyond every type's range: held one past ULINT's largest, so that it is out of range.
    let beyond = i128::from(u64::MAX) + 1;
    let mut v: i128 = 0;
    for c in digits.chars().filter(|c| *c != '_') {
        v = (v * radix + i128::from(c.to_digit(radix as u32)?)).min(beyond);
    }
    ok.then_some(if negative { -v } else { v })
}
