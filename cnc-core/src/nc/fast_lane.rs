//! The fast lane of the parser: a block that is one line of plain address words
//! (`N10 G1 X12.5 Y-3 F500 ; comment`) is read straight from the bytes into items, without
//! tokens. Anything else on the line (`=`, `[`, `#`, `$`, `(`, a variable, a glued word, a
//! malformed number, the last line without a line break...) sends the whole line to the general
//! lexer and parser, which also report all errors. The fast lane must give the very tree,
//! spans included, that the general path gives; a property test holds it to that.

use super::ast::{arena_index, AxisWord, Block, Expr, Item, Name, Span};
use super::lexer::{offset, Lexer};

/// One address word read by the fast lane.
struct Word {
    name: Name,
    value: f64,
    span: Span,
}

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
        let line_start = self.c.pos;
        let first_item = arena_index(arena.len());
        let mut p = line_start;
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
            let word = self.word(bytes, line_start, &mut p)?;
            let first = block_span.is_none();
            match block_span.as_mut() {
                None => block_span = Some(word.span),
                Some(span) => span.end = word.span.end,
            }
            arena.push(match word.name.as_bytes() {
                b"N" if first => {
                    let whole = word.value.fract() == 0.0
                        && word.value >= 0.0
                        && word.value <= f64::from(u32::MAX);
                    if !whole {
                        return None;
                    }
                    number = Some(word.value as u32);
                    continue;
                }
                b"N" => return None,
                b"G" | b"M" => {
                    if word.value.fract() != 0.0 || word.value < 0.0 {
                        return None;
                    }
                    let code = word.value as u32;
                    if word.name.as_bytes() == b"G" {
                        Item::G {
                            code,
                            span: word.span,
                        }
                    } else {
                        Item::M {
                            code,
                            span: word.span,
                        }
                    }
                }
                b"F" => Item::Feed {
                    value: Expr::Num(word.value),
                    span: word.span,
                },
                _ => Item::Axis(AxisWord {
                    name: word.name,
                    value: Expr::Num(word.value),
                    assigned: false,
                    span: word.span,
                }),
            });
        }
        let span = block_span?;
        // Past the line break: the lexer stands where the general path would after the block.
        self.c.pos = p + 1;
        self.c.line += 1;
        self.c.col = 1;
        self.spaced = true;
        Some(Block {
            number,
            items: first_item..arena_index(arena.len()),
            span,
        })
    }

    /// Letters, an optional glued sign, a plain number, then a blank or the line break.
    fn word(&self, bytes: &[u8], line_start: usize, p: &mut usize) -> Option<Word> {
        let start = *p;
        let mut name = Name::new();
        while bytes.get(*p).is_some_and(u8::is_ascii_alphabetic) {
            if !name.push(bytes[*p].to_ascii_uppercase()) {
                return None;
            }
            *p += 1;
        }
        // Exactly as the lexer glues a signed number to its address (`X-60`).
        let sign = match bytes.get(*p) {
            Some(b'-') => -1.0,
            _ => 1.0,
        };
        if matches!(bytes.get(*p), Some(b'-' | b'+')) {
            *p += 1;
        }
        if !bytes.get(*p).is_some_and(u8::is_ascii_digit) {
            return None;
        }
        let (magnitude, len) = decimal(&bytes[*p..])?;
        *p += len;
        if !matches!(bytes.get(*p), Some(b' ' | b'\t' | b'\r' | b'\n')) {
            return None;
        }
        let value = sign * magnitude;
        Some(Word {
            name,
            value,
            span: Span {
                start: offset(start),
                end: offset(*p),
                line: self.c.line,
                // The line is ASCII up to here, so characters are bytes.
                col: self.c.col + (start - line_start) as u32,
            },
        })
    }
}

/// `digits[.digits]` with at most 15 digits at the start of `bytes`: the same value and length
/// as the lexer's `plain_number` (mantissa / 10^fraction digits, exact for these sizes), in two
/// tight loops instead of one with a state check per digit. `None` when there are too many
/// digits; a second dot stops the number (the caller then refuses the word).
fn decimal(bytes: &[u8]) -> Option<(f64, usize)> {
    const POW10: [f64; 16] = [
        1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
    ];
    let mut mantissa: u64 = 0;
    let mut p = 0;
    while let Some(&d) = bytes.get(p).filter(|d| d.is_ascii_digit()) {
        mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d - b'0'));
        p += 1;
    }
    let mut digits = p;
    let mut fraction = 0;
    if bytes.get(p) == Some(&b'.') {
        p += 1;
        let from = p;
        while let Some(&d) = bytes.get(p).filter(|d| d.is_ascii_digit()) {
            mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d - b'0'));
            p += 1;
        }
        fraction = p - from;
        digits += fraction;
    }
    if digits == 0 || digits > 15 {
        return None;
    }
    Some((mantissa as f64 / POW10[fraction], p))
}
