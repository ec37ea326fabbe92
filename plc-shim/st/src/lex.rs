//! The lexer: source text into tokens with their line and column. Keywords are identifiers
//! here (the parser knows them, ASCII case ignored); numbers keep their base and typed
//! literals their type prefix (`DINT#-13059200`, `16#FF`, `T#1s500ms`); comments
//! (`(* .. *)`, nested, and `// ..`) and pragmas (`{attribute ..}`) are skipped.

use crate::diag::{Diagnostic, Pos};

/// A token and where it starts.
#[derive(Debug, Clone, PartialEq)]
pub struct Token {
    /// What it is.
    pub kind: Tok,
    /// Its first character.
    pub pos: Pos,
}

/// The kinds of token.
#[derive(Debug, Clone, PartialEq)]
pub enum Tok {
    /// A name or a keyword, as written.
    Ident(String),
    /// An integer literal (its base already applied; a sign is the parser's, but for a typed
    /// literal's).
    Int(i128),
    /// A real literal.
    Real(f64),
    /// A duration literal (`T#..`, `TIME#..`, `LTIME#..`), in nanoseconds; an LTIME's with
    /// `true`.
    Time(i128, bool),
    /// A string literal `'..'` with its `$` escapes resolved.
    Str(String),
    /// A type prefix of a typed literal: `DINT` of `DINT#5` (the literal follows).
    TypePrefix(String),
    /// `:=`.
    Assign,
    /// `=>`.
    OutAssign,
    /// `:`.
    Colon,
    /// `;`.
    Semi,
    /// `,`.
    Comma,
    /// `.`.
    Dot,
    /// `..`.
    Range,
    /// `(`.
    LParen,
    /// `)`.
    RParen,
    /// `[`.
    LBracket,
    /// `]`.
    RBracket,
    /// `^`.
    Caret,
    /// `+`.
    Plus,
    /// `-`.
    Minus,
    /// `*`.
    Star,
    /// `**`.
    Power,
    /// `/`.
    Slash,
    /// `=`.
    Eq,
    /// `<>`.
    Ne,
    /// `<`.
    Lt,
    /// `>`.
    Gt,
    /// `<=`.
    Le,
    /// `>=`.
    Ge,
    /// `&` (AND).
    Amp,
    /// The end of the text.
    Eof,
}

/// Tokens of `text`, ending with [`Tok::Eof`]; the first error stops the lexer.
pub fn lex(text: &str) -> Result<Vec<Token>, Diagnostic> {
    let mut lexer = Lexer {
        chars: text.chars().collect(),
        at: 0,
        pos: Pos { line: 1, col: 1 },
    };
    let mut out = Vec::new();
    loop {
        lexer.skip_blanks()?;
        let pos = lexer.pos;
        let Some(c) = lexer.peek(0) else {
            out.push(Token {
                kind: Tok::Eof,
                pos,
            });
            return Ok(out);
        };
        let kind = lexer.token(c, pos, out.last())?;
        out.push(Token { kind, pos });
    }
}

struct Lexer {
    chars: Vec<char>,
    at: usize,
    pos: Pos,
}

impl Lexer {
    fn peek(&self, ahead: usize) -> Option<char> {
        self.chars.get(self.at + ahead).copied()
    }

    fn bump(&mut self) -> Option<char> {
        let c = self.peek(0)?;
        self.at += 1;
        if c == '\n' {
            self.pos.line += 1;
            self.pos.col = 1;
        } else {
            self.pos.col += 1;
        }
        Some(c)
    }

    fn error(&self, pos: Pos, message: impl Into<String>) -> Diagnostic {
        Diagnostic::new(pos, message)
    }

    /// Blanks, comments and pragmas.
    fn skip_blanks(&mut self) -> Result<(), Diagnostic> {
        loop {
            match (self.peek(0), self.peek(1)) {
                (Some(c), _) if c.is_whitespace() => {
                    self.bump();
                }
                (Some('/'), Some('/')) => {
                    while self.peek(0).is_some_and(|c| c != '\n') {
                        self.bump();
                    }
                }
                (Some('('), Some('*')) => self.block_comment()?,
                (Some('{'), _) => {
                    let start = self.pos;
                    while self.bump().is_some_and(|c| c != '}') {}
                    if self.at > self.chars.len() || self.chars[self.at - 1] != '}' {
                        return Err(self.error(start, "a pragma `{` without its `}`"));
                    }
                }
                _ => return Ok(()),
            }
        }
    }

    /// A `(* .. *)` comment, nested ones included.
    fn block_comment(&mut self) -> Result<(), Diagnostic> {
        let start = self.pos;
        let mut depth = 0u32;
        loop {
            match (self.peek(0), self.peek(1)) {
                (Some('('), Some('*')) => {
                    self.bump();
                    self.bump();
                    depth += 1;
                }
                (Some('*'), Some(')')) => {
                    self.bump();
                    self.bump();
                    depth -= 1;
                    if depth == 0 {
                        return Ok(());
                    }
                }
                (Some(_), _) => {
                    self.bump();
                }
                (None, _) => return Err(self.error(start, "a comment `(*` without its `*)`")),
            }
        }
    }

    fn token(&mut self, c: char, pos: Pos, last: Option<&Token>) -> Result<Tok, Diagnostic> {
        if c.is_ascii_alphabetic() || c == '_' {
            return self.word(pos);
        }
        if c.is_ascii_digit() {
            return self.number(pos);
        }
        if c == '\'' {
            return self.string(pos);
        }
        // A direct address (`%IX0.0`): read whole, refused by the parser where it stands.
        if c == '%' {
            let mut text = String::new();
            while let Some(c) = self
                .peek(0)
                .filter(|c| c.is_ascii_alphanumeric() || matches!(c, '%' | '.' | '*'))
            {
                text.push(c);
                self.bump();
            }
            return Ok(Tok::Ident(text));
        }
        // A sign right after a type prefix belongs to the literal (`DINT#-5`).
        if let (Some(Tok::TypePrefix(_)), '-' | '+') = (last.map(|t| &t.kind), c) {
            return self.signed_literal(pos);
        }
        self.punct(c, pos)
    }

    /// A name, a keyword, or a type prefix `NAME#` (the literal after it is the next token).
    fn word(&mut self, pos: Pos) -> Result<Tok, Diagnostic> {
        let mut name = String::new();
        while let Some(c) = self
            .peek(0)
            .filter(|c| c.is_ascii_alphanumeric() || *c == '_')
        {
            name.push(c);
            self.bump();
        }
        if self.peek(0) != Some('#') {
            return Ok(Tok::Ident(name));
        }
        self.bump();
        let upper = name.to_ascii_uppercase();
        if matches!(upper.as_str(), "T" | "TIME" | "LTIME") {
            return self.duration(pos, upper == "LTIME");
        }
        // A calendar literal (digits follow: `DT#2026-11-30-12:00:00`); `D#On` of an
        // enumeration named D stays a typed literal.
        if crate::types::is_date_type(&upper) && self.peek(0).is_some_and(|c| c.is_ascii_digit()) {
            let why = format!("{} (`{name}#`)", crate::types::DATES_REFUSED);
            return Err(self.error(pos, &why));
        }
        Ok(Tok::TypePrefix(name))
    }

    /// `-5` or `+2.5` after a type prefix.
    fn signed_literal(&mut self, pos: Pos) -> Result<Tok, Diagnostic> {
        let negative = self.bump() == Some('-');
        match self.peek(0) {
            Some(c) if c.is_ascii_digit() => match self.number(pos)? {
                Tok::Int(v) if negative => Ok(Tok::Int(-v)),
                Tok::Real(v) if negative => Ok(Tok::Real(-v)),
                other => Ok(other),
            },
            _ => Err(self.error(pos, "a sign must be followed by a number")),
        }
    }

    /// Digits of `base` with `_` between them.
    fn digits(&mut self, base: u32) -> String {
        let mut text = String::new();
        while let Some(c) = self.peek(0).filter(|c| c.is_digit(base) || *c == '_') {
            if c != '_' {
                text.push(c);
            }
            self.bump();
        }
        text
    }

    /// `123`, `1_000`, `16#FF`, `8#17`, `2#1010`, `1.5`, `1.5E-3`, `2E3`.
    fn number(&mut self, pos: Pos) -> Result<Tok, Diagnostic> {
        let int = self.digits(10);
        if self.peek(0) == Some('#') {
            let base = match int.as_str() {
                "16" => 16,
                "8" => 8,
                "2" => 2,
                _ => return Err(self.error(pos, format!("base {int}#: 2#, 8# or 16#"))),
            };
            self.bump();
            let digits = self.digits(base);
            return i128::from_str_radix(&digits, base)
                .map(Tok::Int)
                .map_err(|_| self.error(pos, format!("no digits of base {base} after {base}#")));
        }
        let fraction =
            self.peek(0) == Some('.') && self.peek(1).is_some_and(|c| c.is_ascii_digit());
        let exponent = |l: &Self| matches!(l.peek(0), Some('e' | 'E'));
        if !fraction && !exponent(self) {
            return int
                .parse()
                .map(Tok::Int)
                .map_err(|_| self.error(pos, format!("{int}: too large an integer")));
        }
        let mut text = int;
        if fraction {
            self.bump();
            text.push('.');
            text.push_str(&self.digits(10));
        }
        if exponent(self) {
            self.bump();
            text.push('e');
            if let Some(sign) = self.peek(0).filter(|c| *c == '-' || *c == '+') {
                text.push(sign);
                self.bump();
            }
            let digits = self.digits(10);
            if digits.is_empty() {
                return Err(self.error(pos, "an exponent needs digits"));
            }
            text.push_str(&digits);
        }
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(Tok::Real(v)),
            _ => Err(self.error(pos, format!("{text}: not a finite number"))),
        }
    }

    /// The rest of `T#1h2m3s4ms5us6ns` (`1.5s`, `-2s`, `_` between parts): nanoseconds.
    fn duration(&mut self, pos: Pos, long: bool) -> Result<Tok, Diagnostic> {
        let negative = self.peek(0) == Some('-');
        if negative {
            self.bump();
        }
        let mut total = 0f64;
        let mut parts = 0;
        while self.peek(0).is_some_and(|c| c.is_ascii_digit()) {
            let mut value = self.digits(10);
            if self.peek(0) == Some('.') {
                self.bump();
                value.push('.');
                value.push_str(&self.digits(10));
            }
            let mut unit = String::new();
            while let Some(c) = self.peek(0).filter(char::is_ascii_alphabetic) {
                unit.push(c.to_ascii_lowercase());
                self.bump();
            }
            let scale = match unit.as_str() {
                "d" => 86_400e9,
                "h" => 3_600e9,
                "m" => 60e9,
                "s" => 1e9,
                "ms" => 1e6,
                "us" => 1e3,
                "ns" => 1.0,
                _ => {
                    return Err(self.error(
                        pos,
                        format!("duration unit {unit:?}: d, h, m, s, ms, us or ns"),
                    ))
                }
            };
            total += value.parse::<f64>().unwrap_or(0.0) * scale;
            parts += 1;
            if self.peek(0) == Some('_') {
                self.bump();
            }
        }
        if parts == 0 {
            return Err(self.error(pos, "a duration needs a value and a unit (T#1s)"));
        }
        let ns = total.round() as i128;
        Ok(Tok::Time(if negative { -ns } else { ns }, long))
    }

    /// `'text'` with `$$`, `$'`, `$L`, `$N`, `$P`, `$R`, `$T` and `$hh`.
    fn string(&mut self, pos: Pos) -> Result<Tok, Diagnostic> {
        self.bump();
        let mut text = String::new();
        loop {
            match self.bump() {
                None | Some('\n') => {
                    return Err(self.error(pos, "a string without its closing `'`"))
                }
                Some('\'') => return Ok(Tok::Str(text)),
                Some('$') => text.push(self.escape(pos)?),
                Some(c) => text.push(c),
            }
        }
    }

    fn escape(&mut self, pos: Pos) -> Result<char, Diagnostic> {
        let c = self
            .bump()
            .ok_or_else(|| self.error(pos, "a `$` at the end of a string"))?;
        Ok(match c.to_ascii_uppercase() {
            '$' => '$',
            '\'' => '\'',
            'L' | 'N' => '\n',
            'P' => '\u{c}',
            'R' => '\r',
            'T' => '\t',
            h if h.is_ascii_hexdigit() => {
                let low = self.bump().filter(char::is_ascii_hexdigit);
                let low = low.ok_or_else(|| self.error(pos, "`$` and two hex digits"))?;
                let code = u8::from_str_radix(&format!("{h}{low}"), 16).unwrap_or(0);
                char::from(code)
            }
            other => return Err(self.error(pos, format!("unknown escape `${other}`"))),
        })
    }

    fn punct(&mut self, c: char, pos: Pos) -> Result<Tok, Diagnostic> {
        let next = self.peek(1);
        let (tok, len) = match (c, next) {
            (':', Some('=')) => (Tok::Assign, 2),
            ('=', Some('>')) => (Tok::OutAssign, 2),
            ('.', Some('.')) => (Tok::Range, 2),
            ('*', Some('*')) => (Tok::Power, 2),
            ('<', Some('>')) => (Tok::Ne, 2),
            ('<', Some('=')) => (Tok::Le, 2),
            ('>', Some('=')) => (Tok::Ge, 2),
            (':', _) => (Tok::Colon, 1),
            (';', _) => (Tok::Semi, 1),
            (',', _) => (Tok::Comma, 1),
            ('.', _) => (Tok::Dot, 1),
            ('(', _) => (Tok::LParen, 1),
            (')', _) => (Tok::RParen, 1),
            ('[', _) => (Tok::LBracket, 1),
            (']', _) => (Tok::RBracket, 1),
            ('^', _) => (Tok::Caret, 1),
            ('+', _) => (Tok::Plus, 1),
            ('-', _) => (Tok::Minus, 1),
            ('*', _) => (Tok::Star, 1),
            ('/', _) => (Tok::Slash, 1),
            ('=', _) => (Tok::Eq, 1),
            ('<', _) => (Tok::Lt, 1),
            ('>', _) => (Tok::Gt, 1),
            ('&', _) => (Tok::Amp, 1),
            _ => return Err(self.error(pos, format!("unexpected character {c:?}"))),
        };
        for _ in 0..len {
            self.bump();
        }
        Ok(tok)
    }
}
