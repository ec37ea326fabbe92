//! The fast lane of the parser: a block that is one line of plain address words
//! (`N10 G1 X12.5 Y-3 F500 ; comment`) is read straight from the bytes into items, without
//! tokens. Anything else on the line (`=`, `[`, `#`, `$`, `(`, a variable, a glued word, a
//! malformed number, the last line without a line break...) sends the whole line to the general
//! lexer and parser, which also report all errors. The fast lane must give the very tree,
//! spans included, that the general path gives; a property test holds it to that.

use super::ast::{arena_index, AxisName, AxisWord, Block, Expr, Item, Span};
use super::lexer::{offset, Lexer};

/// Packed names of the addresses the fast lane knows (see [`upper_case`]).
const N: u64 = b'N' as u64;
const G: u64 = b'G' as u64;
const M: u64 = b'M' as u64;
const F: u64 = b'F' as u64;
const P: u64 = b'P' as u64;
const L: u64 = b'L' as u64;
const LL: u64 = u16::from_le_bytes(*b"LL") as u64;
const PP: u64 = u16::from_le_bytes(*b"PP") as u64;
const PPP: u64 = u32::from_le_bytes(*b"PPP\0") as u64;

impl Lexer<'_> {
    /// Reads the next block through the fast lane into `arena`; `None` (having consumed and
    /// kept nothing) when the line needs the general path.
    pub(super) fn simple_block(&mut self, arena: &mut Vec<Item>) -> Option<Block> {
        if self.depth != 0 || self.finished {
            return None;
        }
        let first_item = arena.len();
        let block = self.simple_line(arena);
        if block.is_none() {
            arena.truncate(first_item);
        }
        block
    }

    fn simple_line(&mut self, arena: &mut Vec<Item>) -> Option<Block> {
        let bytes = self.c.src.as_bytes();
        let first_item = arena_index(arena.len());
        let mut p = self.c.pos;
        let mut number = None;
        let mut block_span: Option<Span> = None;
        loop {
            while p < bytes.len() && matches!(bytes[p], b' ' | b'\t' | b'\r') {
                p += 1;
            }
            match bytes.get(p)? {
                b'\n' => break,
                b';' => {
                    while bytes.get(p).is_some_and(|&b| b != b'\n') {
                        p += 1;
                    }
                    bytes.get(p)?; // the last line, unterminated: general path
                    break;
                }
                b if b.is_ascii_alphabetic() => {}
                _ => return None,
            }
            let start = p;
            let (name, value) = word(bytes, &mut p)?;
            let span = Span {
                start: offset(start),
                end: offset(p),
            };
            match block_span.as_mut() {
                None => {
                    block_span = Some(span);
                    if name == N {
                        // The saturating conversion and the comparison refuse fractions,
                        // negative numbers and numbers beyond u32 at once.
                        let n = value as u32;
                        if f64::from(n) != value {
                            return None;
                        }
                        number = Some(n);
                        continue;
                    }
                }
                Some(block) => block.end = span.end,
            }
            arena.push(match name {
                G | M => {
                    let code = value as u32;
                    if f64::from(code) != value {
                        return None;
                    }
                    if name == G {
                        Item::G { code, span }
                    } else {
                        Item::M { code, span }
                    }
                }
                F => Item::Feed {
                    value: Expr::Num(value),
                    span,
                },
                N => return None,
                // `P1`, `L`, `LL` start assignments and calls: the general path reads them.
                P | PP | PPP | L | LL => return None,
                _ => Item::Axis(AxisWord {
                    name: AxisName::from_packed(name),
                    value: Expr::Num(value),
                    span,
                }),
            });
        }
        let span = block_span?;
        // Past the line break: the lexer stands where the general path would after the block.
        let line = self.c.line;
        self.c.pos = p + 1;
        self.c.line += 1;
        self.spaced = true;
        Some(Block {
            number,
            items: first_item..arena_index(arena.len()),
            span,
            line,
        })
    }
}

/// Letters, an optional glued sign, a plain number, then a blank or the line break: the name
/// (upper case, packed as by [`upper_case`]) and the value; `p` moves past the word.
///
/// The word is read from one 16-byte window: its parts are found by shifting the window, not
/// by stepping through bytes. A word that does not fit (eight letters or more, eight digits
/// or more in a part) takes the general path.
#[inline(always)]
fn word(bytes: &[u8], p: &mut usize) -> Option<(u64, f64)> {
    let window = sixteen_bytes(bytes, *p);
    let letters = leading_letters(window as u64);
    if letters == 8 {
        return None;
    }
    let name = upper_case(window as u64, letters);
    let mut rest = window >> (8 * letters);
    let mut len = letters;
    // Exactly as the lexer glues a signed number to its address (`X-60`).
    let sign = rest as u8;
    if sign == b'-' || sign == b'+' {
        rest >>= 8;
        len += 1;
    }
    let (magnitude, digits_len) = decimal(rest)?;
    len += digits_len;
    let after = (rest >> (8 * digits_len)) as u8;
    if !matches!(after, b' ' | b'\t' | b'\r' | b'\n') {
        return None;
    }
    *p += len;
    Some((name, if sign == b'-' { -magnitude } else { magnitude }))
}

/// `digits[.digits]` at the start of `window` (first byte lowest), each part shorter than 8
/// digits and the integer part not empty: the same value and length as the lexer's
/// `plain_number` (mantissa / 10^fraction digits, exact for these sizes). `None` otherwise; a
/// second dot ends the number (the caller then refuses the word).
#[inline(always)]
fn decimal(window: u128) -> Option<(f64, usize)> {
    let int_part = window as u64;
    let int_digits = leading_digits(int_part);
    if int_digits == 0 || int_digits == 8 {
        return None;
    }
    let after_int = window >> (8 * int_digits);
    if after_int as u8 != b'.' {
        // Whole numbers (N, G, M, most feeds) need no division, the slowest step here.
        return Some((digits_value(int_part, int_digits) as f64, int_digits));
    }
    let fraction_part = (after_int >> 8) as u64;
    let fraction = leading_digits(fraction_part);
    if fraction == 8 {
        return None;
    }
    let all = int_digits + fraction;
    let mantissa = if all <= 8 {
        // Both parts in one register: the integer digits, then the fraction's in place of
        // the dot and after it.
        let int_only = int_part & ((1u64 << (8 * int_digits)) - 1);
        digits_value(int_only | (fraction_part << (8 * int_digits)), all)
    } else {
        digits_value(int_part, int_digits) * POW10_INT[fraction]
            + digits_value(fraction_part, fraction)
    };
    Some((mantissa as f64 / POW10[fraction], int_digits + 1 + fraction))
}

const POW10: [f64; 8] = [1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7];
const POW10_INT: [u64; 8] = [1, 10, 100, 1_000, 10_000, 100_000, 1_000_000, 10_000_000];

/// The sixteen bytes from `at` as a little-endian number (the first byte lowest), zero-padded
/// past the end of `bytes`.
#[inline(always)]
fn sixteen_bytes(bytes: &[u8], at: usize) -> u128 {
    if let Some(&chunk) = bytes.get(at..at + 16).and_then(|c| c.first_chunk::<16>()) {
        return u128::from_le_bytes(chunk);
    }
    let mut word = [0u8; 16];
    let rest = bytes.get(at..).unwrap_or(&[]);
    let n = rest.len().min(16);
    word[..n].copy_from_slice(&rest[..n]);
    u128::from_le_bytes(word)
}

/// How many of the word's bytes, from the first, are ASCII digits (0..=8).
fn leading_digits(word: u64) -> usize {
    const ONES: u64 = 0x0101_0101_0101_0101;
    // Digits become 0..=9. Adding 0x76 sets the high bit of every byte of 10 or more (a byte
    // of 0x8A or more has it already, hence the OR); a digit byte stays below 0x80 and carries
    // nothing into the next byte, so the lowest flagged byte is the first non-digit exactly.
    let x = word ^ (ONES * u64::from(b'0'));
    let non_digit = (x.wrapping_add(ONES * 0x76) | x) & (ONES * 0x80);
    (non_digit.trailing_zeros() / 8) as usize
}

/// How many of the word's bytes, from the first, are ASCII letters (0..=8).
fn leading_letters(word: u64) -> usize {
    const ONES: u64 = 0x0101_0101_0101_0101;
    const HIGH: u64 = ONES * 0x80;
    // Folded to lower case, a letter is a byte in 0x61..=0x7A. Adding 0x1F (0x05) sets the
    // high bit of a byte of 0x61 (0x7B) or more; below 0x80 nothing carries into the next
    // byte, and a byte of 0x80 or more is a non-letter anyway, so the lowest flagged byte is
    // the first non-letter exactly.
    let lower = word | (ONES * 0x20);
    let at_least_a = lower.wrapping_add(ONES * 0x1F) & HIGH;
    let past_z = lower.wrapping_add(ONES * 0x05) & HIGH;
    let non_letter = (!at_least_a | past_z | word) & HIGH;
    (non_letter.trailing_zeros() / 8) as usize
}

/// The first `n` (0..8) bytes of `word`, letters, in upper case; the bytes above are zero.
fn upper_case(word: u64, n: usize) -> u64 {
    let keep = (1u64 << (8 * n)) - 1;
    (word & keep) & !(0x2020_2020_2020_2020 & keep)
}

/// The value of the first `n` (0..=8) bytes of `word`, all ASCII digits, first most significant.
fn digits_value(word: u64, n: usize) -> u64 {
    if n == 0 {
        return 0;
    }
    // Keep the n digits (as 0..=9) and move them to the top: the freed low bytes are leading
    // zeros. Then combine neighbours pairwise: 2 digits per 16 bits, 4 per 32, 8 per 64.
    let digits = (word & 0x0F0F_0F0F_0F0F_0F0F) << (8 * (8 - n));
    let pairs = (digits.wrapping_mul(10 << 8 | 1) >> 8) & 0x00FF_00FF_00FF_00FF;
    let quads = (pairs.wrapping_mul(100 << 16 | 1) >> 16) & 0x0000_FFFF_0000_FFFF;
    quads.wrapping_mul(10_000 << 32 | 1) >> 32
}

#[cfg(test)]
mod tests {
    use super::{
        decimal, digits_value, leading_digits, leading_letters, sixteen_bytes, upper_case, word,
    };
    use proptest::prelude::*;

    /// The reference: `plain_number` of the lexer one digit at a time, limited to what the
    /// fast lane takes (an integer part of 1 to 7 digits, a fraction of at most 7).
    fn decimal_by_digit(bytes: &[u8]) -> Option<(f64, usize)> {
        let int_digits = bytes.iter().take_while(|b| b.is_ascii_digit()).count();
        let mut p = int_digits;
        let mut fraction = 0;
        if bytes.get(p) == Some(&b'.') {
            fraction = bytes[p + 1..]
                .iter()
                .take_while(|b| b.is_ascii_digit())
                .count();
            p += 1 + fraction;
        }
        if !(1..=7).contains(&int_digits) || fraction > 7 {
            return None;
        }
        let mantissa = bytes[..p]
            .iter()
            .filter(|b| b.is_ascii_digit())
            .fold(0u64, |m, &d| m * 10 + u64::from(d - b'0'));
        Some((mantissa as f64 / 10f64.powi(fraction as i32), p))
    }

    fn window(text: &[u8]) -> u128 {
        sixteen_bytes(text, 0)
    }

    #[test]
    fn eight_digits_at_a_time() {
        assert_eq!(leading_digits(u64::from_le_bytes(*b"1234567x")), 7);
        assert_eq!(leading_digits(u64::from_le_bytes(*b"12345678")), 8);
        assert_eq!(leading_digits(u64::from_le_bytes(*b"x2345678")), 0);
        assert_eq!(leading_digits(u64::from_le_bytes(*b"9\xff000000")), 1);
        assert_eq!(
            digits_value(u64::from_le_bytes(*b"12345678"), 8),
            12_345_678
        );
        assert_eq!(digits_value(u64::from_le_bytes(*b"0860 X1."), 4), 860);
        assert_eq!(decimal(window(b"123.456 ")), Some((123.456, 7)));
        assert_eq!(decimal(window(b"5.")), Some((5.0, 2)));
        assert_eq!(decimal(window(b"1.2.3")), Some((1.2, 3)));
        assert_eq!(
            decimal(window(b"1234567.1234567 ")),
            Some((1_234_567.123_456_7, 15))
        );
        assert_eq!(decimal(window(b"12345678")), None);
        assert_eq!(decimal(window(b"1.12345678")), None);
        assert_eq!(decimal(window(b".5")), None);
        let word_of = |text: &[u8; 8]| u64::from_le_bytes(*text);
        assert_eq!(leading_letters(word_of(b"X12.5 Y1")), 1);
        assert_eq!(leading_letters(word_of(b"ab=90 X1")), 2);
        assert_eq!(leading_letters(word_of(b"AzZa@[`{")), 4);
        assert_eq!(leading_letters(word_of(b"INDPASYN")), 8);
        assert_eq!(leading_letters(word_of(b"\xe1bc00000")), 0);
        assert_eq!(
            upper_case(word_of(b"ab=90 X1"), 2),
            u64::from(u16::from_le_bytes(*b"AB"))
        );
        let mut p = 4;
        assert_eq!(
            word(b"N10 x-12.5\n", &mut p),
            Some((u64::from(b'X'), -12.5))
        );
        assert_eq!(p, 10);
        assert_eq!(word(b"X1.2.3 ", &mut 0), None);
        assert_eq!(
            word(b"X12", &mut 0),
            None,
            "no blank or line break after it"
        );
    }

    proptest! {
        /// Letters in one register agree with byte-by-byte classification.
        #[test]
        fn letters_in_a_register_match_byte_by_byte(raw in any::<[u8; 8]>()) {
            let expected = raw.iter().take_while(|b| b.is_ascii_alphabetic()).count();
            let word = u64::from_le_bytes(raw);
            prop_assert_eq!(leading_letters(word), expected);
            if expected < 8 {
                let mut upper = [0u8; 8];
                for (u, b) in upper.iter_mut().zip(&raw).take(expected) {
                    *u = b.to_ascii_uppercase();
                }
                prop_assert_eq!(upper_case(word, expected), u64::from_le_bytes(upper));
            }
        }

        /// The number read from a register agrees with reading it digit by digit.
        #[test]
        fn register_matches_digit_by_digit(
            text in "[0-9]{0,9}(\\.[0-9]{0,9})?[ .x\n-]?[0-9]{0,3}",
            raw in proptest::collection::vec(any::<u8>(), 0..24),
        ) {
            prop_assert_eq!(decimal(window(text.as_bytes())), decimal_by_digit(text.as_bytes()));
            prop_assert_eq!(decimal(window(&raw)), decimal_by_digit(&raw));
        }
    }
}
