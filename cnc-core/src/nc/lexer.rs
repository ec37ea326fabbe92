//! Tokens of NC programs. Comments (`;` to the end of the line, `( ... )`) are dropped; a `\`
//! at the end of a line and a line break inside `[ ]` continue the block, any other line break
//! ends it.

pub use super::ast::Name;
use super::ast::Span;

/// What a token is.
#[derive(Debug, Clone, PartialEq)]
pub enum Tok {
    /// Letters and underscores, upper-cased (`G`, `X`, `TRACK_CS`, `SET_ZERO`).
    Word(Name),
    /// A variable with dots, upper-cased (`V.G.TRACK_CS.X`).
    Var(Name),
    /// A number, with its source text (leading zeros matter for nothing but printing).
    Num(f64),
    /// A word with a plain number glued to it (`G01`, `X10.5`, `N00860`, `ID3`): the parser
    /// reads it exactly like the word followed by an unspaced number.
    Addr(Name, f64),
    /// A double-quoted string.
    Str(String),
    /// `%name` up to the end of the line.
    Percent(String),
    /// One of `# $ = [ ] , + - * / < > == != <= >=`.
    Punct(&'static str),
    /// End of a block.
    Newline,
    /// A character that belongs to nothing.
    Bad(char),
}

/// A token with its place.
#[derive(Debug, Clone, PartialEq)]
pub struct Token {
    /// The token.
    pub tok: Tok,
    /// Where it stands.
    pub span: Span,
    /// Whether white space (or a comment) separates it from the previous token.
    pub spaced: bool,
}

/// A diagnostic of the lexer (unterminated comment or string).
#[derive(Debug, Clone, PartialEq)]
pub struct LexError {
    /// Where.
    pub span: Span,
    /// What.
    pub message: String,
}

pub(super) struct Cursor<'a> {
    pub(super) src: &'a str,
    pub(super) pos: usize,
    pub(super) line: u32,
}

impl Cursor<'_> {
    fn peek(&self) -> Option<char> {
        match self.src.as_bytes().get(self.pos) {
            Some(&b) if b.is_ascii() => Some(b as char),
            Some(_) => self.src[self.pos..].chars().next(),
            None => None,
        }
    }
    fn peek2(&self) -> Option<char> {
        match self.src.as_bytes().get(self.pos) {
            Some(&b) if b.is_ascii() => match self.src.as_bytes().get(self.pos + 1) {
                Some(&c) if c.is_ascii() => Some(c as char),
                Some(_) => self.src[self.pos + 1..].chars().next(),
                None => None,
            },
            _ => {
                let mut it = self.src[self.pos..].chars();
                it.next();
                it.next()
            }
        }
    }
    fn bump(&mut self) -> Option<char> {
        let c = self.peek()?;
        self.pos += c.len_utf8();
        if c == '\n' {
            self.line += 1;
        }
        Some(c)
    }
    /// Skips ASCII bytes (never a newline) while `keep` holds.
    fn skip_ascii_while(&mut self, keep: impl Fn(u8) -> bool) {
        let bytes = self.src.as_bytes();
        while self.pos < bytes.len()
            && bytes[self.pos] != b'\n'
            && bytes[self.pos].is_ascii()
            && keep(bytes[self.pos])
        {
            self.pos += 1;
        }
    }

    fn mark(&self) -> Span {
        Span {
            start: offset(self.pos),
            end: offset(self.pos),
        }
    }
    fn close(&self, mut span: Span) -> Span {
        span.end = offset(self.pos);
        span
    }
}

/// Splits `src` into tokens; never fails, reports problems in `errors`. (The parser streams
/// block by block through [`Lexer`]; this collects everything, for tests and tools.)
pub fn tokenize(src: &str, errors: &mut Vec<LexError>) -> Vec<Token> {
    let mut lexer = Lexer::new(src);
    let mut all = Vec::new();
    let mut block = Vec::new();
    while lexer.next_block(&mut block) {
        all.append(&mut block);
    }
    if all.is_empty() {
        all.push(Token {
            tok: Tok::Newline,
            span: lexer.c.mark(),
            spaced: true,
        });
    }
    errors.append(&mut lexer.errors);
    all
}

/// A lexer that hands out one block (logical line) at a time, so the parser works on a small
/// buffer instead of a token vector of the whole file.
pub struct Lexer<'a> {
    pub(super) c: Cursor<'a>,
    /// Open `[` brackets.
    pub(super) depth: usize,
    pub(super) spaced: bool,
    pub(super) finished: bool,
    /// The line of the first token of the block last handed out.
    pub(super) block_line: u32,
    /// Problems found so far (unterminated comments and strings, malformed numbers).
    pub errors: Vec<LexError>,
}

impl<'a> Lexer<'a> {
    /// A lexer at the start of `src`.
    pub fn new(src: &'a str) -> Self {
        Self {
            c: Cursor {
                src,
                pos: 0,
                line: 1,
            },
            depth: 0,
            spaced: true,
            finished: false,
            block_line: 1,
            errors: Vec::new(),
        }
    }

    /// The common tokens in one pass over their bytes: blanks, plain words (not variables)
    /// and plain decimal numbers. Returns `false` (having consumed nothing) for anything else,
    /// which the general path below handles.
    fn fast_token(&mut self, out: &mut Vec<Token>) -> bool {
        let bytes = self.c.src.as_bytes();
        let start = self.c.pos;
        let Some(&first) = bytes.get(start) else {
            return false;
        };
        let mut p = start;
        let tok = match first {
            b' ' | b'\t' | b'\r' => {
                while p < bytes.len() && matches!(bytes[p], b' ' | b'\t' | b'\r') {
                    p += 1;
                }
                self.c.pos = p;
                self.spaced = true;
                return true;
            }
            b'A'..=b'Z' | b'a'..=b'z' | b'_' => {
                let mut name = Name::new();
                while p < bytes.len() && (bytes[p].is_ascii_alphabetic() || bytes[p] == b'_') {
                    if !name.push(bytes[p].to_ascii_uppercase()) {
                        return false; // too long: the general path reports it
                    }
                    p += 1;
                }
                if bytes.get(p) == Some(&b'.') {
                    return false; // a variable
                }
                // A signed number glued to an address (`X-60`) belongs to it as well.
                let (sign, digits_at) = match bytes.get(p) {
                    Some(b'-') => (-1.0, p + 1),
                    Some(b'+') => (1.0, p + 1),
                    _ => (1.0, p),
                };
                match bytes.get(digits_at) {
                    Some(b'0'..=b'9') => match plain_number(&bytes[digits_at..]) {
                        Some((value, len)) => {
                            p = digits_at + len;
                            Tok::Addr(name, sign * value)
                        }
                        None => Tok::Word(name),
                    },
                    _ => Tok::Word(name),
                }
            }
            b'0'..=b'9' => match plain_number(&bytes[p..]) {
                Some((value, len)) => {
                    p += len;
                    Tok::Num(value)
                }
                None => return false, // long or malformed: the general path judges it
            },
            _ => return false,
        };
        let span = Span {
            start: offset(start),
            end: offset(p),
        };
        self.c.pos = p;
        out.push(Token {
            tok,
            span,
            spaced: self.spaced,
        });
        self.spaced = false;
        true
    }

    /// Replaces `out` with the tokens of the next non-empty block, ending with a newline
    /// token; `false` when the input is exhausted.
    pub fn next_block(&mut self, out: &mut Vec<Token>) -> bool {
        out.clear();
        if self.finished {
            return false;
        }
        while let Some(ch) = self.c.peek() {
            if out.is_empty() {
                // Tokens never span a line break, so the first token's line is this one.
                self.block_line = self.c.line;
                if ch == '#' && self.depth == 0 && self.comment_section() {
                    continue;
                }
            }
            if self.fast_token(out) {
                continue;
            }
            self.general_token(ch, out);
            if out.last().is_some_and(|t| t.tok == Tok::Newline) {
                return true;
            }
        }
        self.finished = true;
        if out.is_empty() {
            return false;
        }
        out.push(Token {
            tok: Tok::Newline,
            span: self.c.mark(),
            spaced: true,
        });
        true
    }

    /// What [`Lexer::fast_token`] left at `ch` (the cursor's character): one token, blank,
    /// comment, continuation or line break, by the general path.
    fn general_token(&mut self, ch: char, out: &mut Vec<Token>) {
        let start = self.c.mark();
        match ch {
            ' ' | '\t' | '\r' => {
                self.c
                    .skip_ascii_while(|b| b == b' ' || b == b'\t' || b == b'\r');
                self.spaced = true;
            }
            '\n' => self.line_break(start, out),
            ';' => self.line_comment(),
            '(' => self.paren_comment(start),
            '\\' => self.continuation(start, out),
            '%' => self.percent(start, out),
            '"' => self.string(start, out),
            '0'..='9' | '.' if ch != '.' || self.c.peek2().is_some_and(|d| d.is_ascii_digit()) => {
                self.number(start, out)
            }
            x if x.is_ascii_alphabetic() || x == '_' => self.word_or_variable(start, out),
            _ => self.punct(ch, start, out),
        }
    }
}

/// The general path's tokens, one kind each; `start` marks where the token begins (the cursor,
/// which stands on its first character).
impl Lexer<'_> {
    /// `\n`: ends the block, unless an open `[` continues it.
    fn line_break(&mut self, start: Span, out: &mut Vec<Token>) {
        self.c.bump();
        // Inside `[ ]` a list may run on over the next line, unless that line plainly
        // starts a new block: then the bracket was left open and the block ends here.
        if self.depth > 0 && starts_new_block(&self.c.src[self.c.pos..]) {
            self.depth = 0;
        }
        if self.depth == 0 {
            push(out, Tok::Newline, self.c.close(start), true);
        }
        self.spaced = true;
    }

    /// `; ...` to the end of the line.
    fn line_comment(&mut self) {
        while self.c.peek().is_some_and(|x| x != '\n') {
            self.c.bump();
        }
        self.spaced = true;
    }

    /// `( ... )`, nested; reported when its line ends first (outside `[ ]`).
    fn paren_comment(&mut self, start: Span) {
        // Comments nest: `(a (b) c)` is one comment.
        let mut closed = false;
        let mut open = 0u32;
        while let Some(x) = self.c.bump() {
            if x == '(' {
                open += 1;
            }
            if x == ')' {
                open -= 1;
                if open == 0 {
                    closed = true;
                    break;
                }
            }
            if x == '\n' && self.depth == 0 {
                break;
            }
        }
        if !closed {
            self.errors.push(LexError {
                span: self.c.close(start),
                message: "comment \"(\" is not closed by \")\" on its line".into(),
            });
        }
        self.spaced = true;
    }

    /// `\`: continues the block on the next line. The rest of its line must be blank (or a
    /// comment); else the `\` is a bad character.
    fn continuation(&mut self, start: Span, out: &mut Vec<Token>) {
        self.c.bump();
        let rest_blank = {
            let tail = &self.c.src[self.c.pos..];
            let line = tail.split('\n').next().unwrap_or("");
            let code = line.split(';').next().unwrap_or("");
            code.trim().is_empty()
        };
        if rest_blank {
            while self.c.peek().is_some_and(|x| x != '\n') {
                self.c.bump();
            }
            self.c.bump();
        } else {
            push(out, Tok::Bad('\\'), self.c.close(start), self.spaced);
        }
        self.spaced = true;
    }

    /// `%name`: a program or subroutine header.
    fn percent(&mut self, start: Span, out: &mut Vec<Token>) {
        self.c.bump();
        let mut name = String::new();
        while let Some(x) = self.c.peek() {
            if x.is_whitespace() || x == ';' || x == '(' {
                break;
            }
            name.push(x);
            self.c.bump();
        }
        push(out, Tok::Percent(name), self.c.close(start), self.spaced);
        self.spaced = false;
    }

    /// `"text"`, reported when its line ends first.
    fn string(&mut self, start: Span, out: &mut Vec<Token>) {
        self.c.bump();
        let mut text = String::new();
        let mut closed = false;
        while let Some(x) = self.c.peek() {
            if x == '\n' {
                break;
            }
            self.c.bump();
            if x == '"' {
                closed = true;
                break;
            }
            text.push(x);
        }
        if !closed {
            self.errors.push(LexError {
                span: self.c.close(start),
                message: "string is not closed by '\"' on its line".into(),
            });
        }
        push(out, Tok::Str(text), self.c.close(start), self.spaced);
        self.spaced = false;
    }

    /// A number the fast path did not take (long or malformed); reported as such, read as 0.
    fn number(&mut self, start: Span, out: &mut Vec<Token>) {
        let from = self.c.pos;
        self.c.skip_ascii_while(|b| b.is_ascii_digit() || b == b'.');
        let text = &self.c.src[from..self.c.pos];
        match parse_decimal(text) {
            Ok(v) if v.is_finite() => push(out, Tok::Num(v), self.c.close(start), self.spaced),
            Ok(_) => {
                self.errors.push(LexError {
                    span: self.c.close(start),
                    message: format!(
                        "number with {} digits is too large (the largest is about 1.8e308)",
                        text.len()
                    ),
                });
                push(out, Tok::Num(0.0), self.c.close(start), self.spaced);
            }
            Err(_) => {
                self.errors.push(LexError {
                    span: self.c.close(start),
                    message: format!("malformed number \"{text}\""),
                });
                push(out, Tok::Num(0.0), self.c.close(start), self.spaced);
            }
        }
        self.spaced = false;
    }

    /// A word, or a variable with dots (`V.G.TRACK_CS.X`); a name too long is reported.
    fn word_or_variable(&mut self, start: Span, out: &mut Vec<Token>) {
        let mut name = Name::new();
        let from = self.c.pos;
        self.c
            .skip_ascii_while(|b| b.is_ascii_alphabetic() || b == b'_');
        let mut fits = true;
        for &b in &self.c.src.as_bytes()[from..self.c.pos] {
            fits &= name.push(b.to_ascii_uppercase());
        }
        // `V.G.TRACK_CS.X`: a variable runs on through dots, letters and digits.
        let is_var = self.c.peek() == Some('.')
            && self
                .c
                .peek2()
                .is_some_and(|d| d.is_ascii_alphanumeric() || d == '_');
        if is_var {
            while let Some(y) = self.c.peek() {
                if y.is_ascii_alphanumeric() || y == '_' || y == '.' {
                    fits &= name.push(y.to_ascii_uppercase() as u8);
                    self.c.bump();
                } else {
                    break;
                }
            }
        }
        if !fits {
            self.errors.push(LexError {
                span: self.c.close(start),
                message: format!("name longer than {} characters", Name::CAPACITY),
            });
        }
        let tok = if is_var {
            Tok::Var(name)
        } else {
            Tok::Word(name)
        };
        push(out, tok, self.c.close(start), self.spaced);
        self.spaced = false;
    }

    /// Punctuation (one or two characters, `[` and `]` counted), or a bad character.
    fn punct(&mut self, ch: char, start: Span, out: &mut Vec<Token>) {
        self.c.bump();
        let next = self.c.peek();
        let punct: Option<&'static str> = match (ch, next) {
            ('=', Some('=')) => Some("=="),
            ('!', Some('=')) => Some("!="),
            ('<', Some('=')) => Some("<="),
            ('>', Some('=')) => Some(">="),
            ('<', Some('>')) => Some("!="),
            ('*', Some('*')) => Some("**"),
            _ => None,
        };
        let tok = if let Some(p) = punct {
            self.c.bump();
            Tok::Punct(p)
        } else {
            match ch {
                '#' => Tok::Punct("#"),
                '$' => Tok::Punct("$"),
                '=' => Tok::Punct("="),
                '[' => {
                    self.depth += 1;
                    Tok::Punct("[")
                }
                ']' => {
                    self.depth = self.depth.saturating_sub(1);
                    Tok::Punct("]")
                }
                ',' => Tok::Punct(","),
                ':' => Tok::Punct(":"),
                '+' => Tok::Punct("+"),
                '-' => Tok::Punct("-"),
                '*' => Tok::Punct("*"),
                '/' => Tok::Punct("/"),
                '<' => Tok::Punct("<"),
                '>' => Tok::Punct(">"),
                other => Tok::Bad(other),
            }
        };
        push(out, tok, self.c.close(start), self.spaced);
        self.spaced = false;
    }
}

impl Lexer<'_> {
    /// At a line starting `#COMMENT BEGIN`: skips through the line holding `#COMMENT END`
    /// (reported when missing) and returns true.
    fn comment_section(&mut self) -> bool {
        let rest = &self.c.src[self.c.pos..];
        if !starts_with_words(rest, &["#COMMENT", "BEGIN"]) {
            return false;
        }
        let start = self.c.mark();
        loop {
            // Past the current line.
            while self.c.peek().is_some_and(|x| x != '\n') {
                self.c.bump();
            }
            if self.c.bump().is_none() {
                self.errors.push(LexError {
                    span: self.c.close(start),
                    message: "#COMMENT BEGIN is not closed by #COMMENT END".into(),
                });
                return true;
            }
            let line = &self.c.src[self.c.pos..];
            let trimmed = line.trim_start_matches([' ', '\t']);
            if starts_with_words(trimmed, &["#COMMENT", "END"]) {
                while self.c.peek().is_some_and(|x| x != '\n') {
                    self.c.bump();
                }
                self.c.bump();
                self.spaced = true;
                return true;
            }
        }
    }
}

/// Whether `text` starts with these words (case-insensitive), separated by blanks, the last
/// one ending the text or followed by a blank, a comment or the line break.
fn starts_with_words(mut text: &str, words: &[&str]) -> bool {
    for (i, word) in words.iter().enumerate() {
        if i > 0 {
            let trimmed = text.trim_start_matches([' ', '\t']);
            if trimmed.len() == text.len() {
                return false;
            }
            text = trimmed;
        }
        match text.get(..word.len()) {
            Some(head) if head.eq_ignore_ascii_case(word) => text = &text[word.len()..],
            _ => return false,
        }
    }
    text.chars()
        .next()
        .is_none_or(|c| matches!(c, ' ' | '\t' | '\r' | '\n' | ';' | '('))
}

/// A plain decimal `digits[.digits]` at the start of `bytes` with at most 15 digits: its exact
/// value (see [`parse_decimal`]) and length. `None` for anything the general path must judge
/// (a second dot, more digits).
pub(super) fn plain_number(bytes: &[u8]) -> Option<(f64, usize)> {
    const POW10: [f64; 16] = [
        1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
    ];
    let mut mantissa: u64 = 0;
    let mut digits = 0u32;
    let mut fraction: Option<usize> = None;
    let mut p = 0;
    while p < bytes.len() {
        match bytes[p] {
            d @ b'0'..=b'9' => {
                mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d - b'0'));
                digits += 1;
                if let Some(f) = fraction.as_mut() {
                    *f += 1;
                }
            }
            b'.' if fraction.is_none() => fraction = Some(0),
            b'.' => return None,
            _ => break,
        }
        p += 1;
    }
    if digits == 0 || digits > 15 {
        return None;
    }
    Some((mantissa as f64 / POW10[fraction.unwrap_or(0)], p))
}

pub(super) fn offset(pos: usize) -> u32 {
    pos.min(u32::MAX as usize) as u32
}

/// Parses `digits[.digits]`. Short numbers take the exact fast path (mantissa below 2^53 and
/// a power of ten below 10^22 are exact doubles, so one division rounds correctly); anything
/// else goes to the standard library.
fn parse_decimal(text: &str) -> Result<f64, core::num::ParseFloatError> {
    match plain_number(text.as_bytes()) {
        Some((value, len)) if len == text.len() => Ok(value),
        _ => text.parse(),
    }
}

/// Whether a line begins a block of its own: empty, or a block number, `#`, `$` or `%`.
fn starts_new_block(rest: &str) -> bool {
    let line = rest.split('\n').next().unwrap_or("").trim_start();
    let mut chars = line.chars();
    match chars.next() {
        None | Some('#' | '$' | '%') => true,
        Some('N' | 'n') => chars.next().is_some_and(|c| c.is_ascii_digit()),
        _ => false,
    }
}

fn push(out: &mut Vec<Token>, tok: Tok, span: Span, spaced: bool) {
    // Collapse runs of newlines: empty lines make no blocks.
    if tok == Tok::Newline && out.last().is_none_or(|t| t.tok == Tok::Newline) {
        return;
    }
    out.push(Token { tok, span, spaced });
}

#[cfg(test)]
mod tests {
    use super::parse_decimal;
    use proptest::prelude::*;

    #[test]
    fn decimal_fast_path_edges() {
        assert_eq!(parse_decimal("0").unwrap(), 0.0);
        assert_eq!(parse_decimal("00860").unwrap(), 860.0);
        assert_eq!(parse_decimal("1305.92").unwrap(), 1305.92);
        assert_eq!(parse_decimal(".5").unwrap(), 0.5);
        assert_eq!(parse_decimal("5.").unwrap(), 5.0);
        assert_eq!(
            parse_decimal("12345678901234567890").unwrap(),
            12345678901234567890.0
        );
        assert!(parse_decimal("1.2.3").is_err());
        assert!(parse_decimal(".").is_err());
    }

    proptest! {
        /// The fast path agrees with the standard library bit for bit.
        #[test]
        fn decimal_parsing_matches_std(int in 0u64..10_000_000_000, frac in 0u64..1_000_000, frac_digits in 0usize..7) {
            let text = if frac_digits == 0 { format!("{int}") } else { format!("{int}.{:0width$}", frac % 10u64.pow(frac_digits as u32), width = frac_digits) };
            prop_assert_eq!(parse_decimal(&text).unwrap().to_bits(), text.parse::<f64>().unwrap().to_bits(), "{}", text);
        }
    }
}
