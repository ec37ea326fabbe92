//! The parser: tokens to the program tree. It never gives up: a bad item is reported with its
//! span and what was expected, skipped, and parsing goes on with the next item.

use super::ast::arena_index;
use super::ast::*;
use super::lexer::{Lexer, Name, Tok, Token};
use super::Diagnostic;

/// Parses `src`; the tree holds everything that could be understood.
pub fn parse(src: &str) -> (Program, Vec<Diagnostic>) {
    parse_with(src, true)
}

/// [`parse`] without the fast lane for plain blocks: every line through the general lexer and
/// parser. The same result, slower; for the tests that hold the fast lane to it.
pub fn parse_general(src: &str) -> (Program, Vec<Diagnostic>) {
    parse_with(src, false)
}

fn parse_with(src: &str, fast_lane: bool) -> (Program, Vec<Diagnostic>) {
    let mut p = Parser {
        src,
        fast_lane,
        lexer: Lexer::new(src),
        tokens: Vec::with_capacity(32),
        pos: 0,
        diags: Vec::new(),
    };
    let program = p.program();
    let mut diags: Vec<Diagnostic> = p
        .lexer
        .errors
        .drain(..)
        .map(|e| Diagnostic::new(e.span, e.message, src))
        .collect();
    diags.append(&mut p.diags);
    super::locate(&mut diags, src);
    (program, diags)
}

/// The parser works on one block at a time: `tokens` holds the current block, ending with a
/// newline token.
struct Parser<'a> {
    src: &'a str,
    /// Whether plain blocks take the fast lane (see `fast_lane.rs`).
    fast_lane: bool,
    lexer: Lexer<'a>,
    tokens: Vec<Token>,
    pos: usize,
    diags: Vec<Diagnostic>,
}

const TRACK_FLAGS: &[&str] = &[
    "SET_ZERO",
    "ABSOLUTE",
    "KIN_BASE",
    "WAIT",
    "ROT_TRANS",
    "RELATIVE",
    "SIMU",
];
const TRACK_VALUES: &[&str] = &[
    "CH", "ID", "OPTION", "FILTER", "X", "Y", "Z", "A", "B", "C", "LOG_FILE",
];

impl Parser<'_> {
    fn peek(&self) -> &Tok {
        &self.tokens[self.pos].tok
    }
    fn peek_at(&self, ahead: usize) -> &Tok {
        let i = (self.pos + ahead).min(self.tokens.len() - 1);
        &self.tokens[i].tok
    }
    fn token(&self) -> &Token {
        &self.tokens[self.pos]
    }
    fn span(&self) -> Span {
        self.tokens[self.pos].span
    }
    fn bump(&mut self) {
        if self.pos + 1 < self.tokens.len() {
            self.pos += 1;
        }
    }
    /// The current token's kind without borrowing the parser (names are Copy; strings are
    /// rare and cloned).
    fn current(&self) -> Tok {
        self.tokens[self.pos].tok.clone()
    }
    /// `span` extended to the end of the last token consumed.
    fn extend(&self, mut span: Span) -> Span {
        if self.pos > 0 {
            let last = self.tokens[self.pos - 1].span;
            if last.end > span.end {
                span.end = last.end;
            }
        }
        span
    }
    /// `span` extended to the end of the block's last token.
    fn to_block_end(&self, mut span: Span) -> Span {
        let mut i = self.pos;
        while i < self.tokens.len() && self.tokens[i].tok != Tok::Newline {
            i += 1;
        }
        if i > 0 && self.tokens[i - 1].span.end > span.end {
            span.end = self.tokens[i - 1].span.end;
        }
        span
    }
    fn at_end_of_block(&self) -> bool {
        matches!(self.peek(), Tok::Newline)
    }
    fn is_punct(&self, p: &str) -> bool {
        // Byte loop instead of `==`: the strings are one or two bytes, a memcmp call is not.
        matches!(self.peek(), Tok::Punct(q) if q.len() == p.len() && q.bytes().zip(p.bytes()).all(|(a, b)| a == b))
    }
    fn is_word(&self, w: &str) -> bool {
        matches!(self.peek(), Tok::Word(x) if x == w)
    }
    fn error(&mut self, span: Span, message: impl Into<String>) {
        self.diags
            .push(Diagnostic::new(span, message.into(), self.src));
    }
    fn describe(&self) -> String {
        match self.peek() {
            Tok::Newline => "end of block".into(),
            _ => {
                let s = self.span();
                format!(
                    "\"{}\"",
                    self.src.get(s.start as usize..s.end as usize).unwrap_or("")
                )
            }
        }
    }
    fn expect_word(&mut self, word: &str, context: &str) -> bool {
        if self.is_word(word) {
            self.bump();
            true
        } else {
            let found = self.describe();
            let span = self.span();
            self.error(span, format!("{context}: expected {word}, found {found}"));
            false
        }
    }
    /// Skips to the end of the current block.
    fn recover(&mut self) {
        while !self.at_end_of_block() {
            self.bump();
        }
    }

    fn program(&mut self) -> Program {
        let mut program = Program::default();
        // Reserving up front saves the copies of growing. The sizes are generous guesses from
        // the source length (a block with its line break takes a few bytes, an item takes a
        // few bytes with its blank: `X1 `): reserved and untouched memory costs nothing, while
        // counting the lines first cost a tenth of the parse. Capped: beyond it, growth is
        // amortised anyway.
        const RESERVE_CAP: usize = 1 << 20;
        program
            .blocks
            .reserve((self.src.len() / 8 + 1).min(RESERVE_CAP));
        program.items.reserve((self.src.len() / 4).min(RESERVE_CAP));
        // Long programs fill tens of megabytes of fresh memory: in huge pages where the
        // system has them, one page fault per 2 MiB instead of one per 4 KiB.
        hli::raw::advise_huge_pages(&mut program.blocks);
        hli::raw::advise_huge_pages(&mut program.items);
        loop {
            if self.fast_lane {
                if let Some(block) = self.lexer.simple_block(&mut program.items) {
                    program.blocks.push(block);
                    continue;
                }
            }
            if !self.lexer.next_block(&mut self.tokens) {
                break;
            }
            self.pos = 0;
            if let Tok::Percent(name) = self.peek().clone() {
                let span = self.span();
                self.bump();
                if program.name.is_some() || !program.blocks.is_empty() {
                    self.error(
                        span,
                        "a program header \"%name\" must come first and only once",
                    );
                } else if name.is_empty() {
                    self.error(span, "expected a program name after \"%\"");
                } else {
                    program.name = Some(name);
                }
                if !self.at_end_of_block() {
                    let s = self.span();
                    let found = self.describe();
                    self.error(
                        s,
                        format!("expected end of line after the program header, found {found}"),
                    );
                }
                continue;
            }
            let items_before = program.items.len();
            if let Some(block) = self.block(&mut program.items) {
                program.blocks.push(block);
            } else {
                program.items.truncate(items_before);
            }
        }
        program
    }

    fn block(&mut self, arena: &mut Vec<Item>) -> Option<Block> {
        let span = self.span();
        let mut block = Block {
            number: None,
            items: 0..0,
            span,
            line: self.lexer.block_line,
        };
        if let Tok::Addr(n, value) = *self.peek() {
            if n == "N" {
                self.bump();
                if value.fract() == 0.0 && value >= 0.0 && value <= f64::from(u32::MAX) {
                    block.number = Some(value as u32);
                } else {
                    self.error(
                        span,
                        format!("block number must be a whole number, found {value}"),
                    );
                }
            }
        } else if self.is_word("N")
            && matches!(self.peek_at(1), Tok::Num(_))
            && !self.tokens[self.pos + 1].spaced
        {
            self.bump();
            if let Tok::Num(n) = self.current() {
                self.bump();
                if n.fract() == 0.0 && n >= 0.0 && n <= f64::from(u32::MAX) {
                    block.number = Some(n as u32);
                } else {
                    self.error(
                        span,
                        format!("block number must be a whole number, found {n}"),
                    );
                }
            }
        }
        let first = arena.len();
        while !self.at_end_of_block() {
            let before = self.pos;
            if let Some(item) = self.item() {
                arena.push(item);
            }
            if self.pos == before {
                self.bump();
            }
        }
        block.items = arena_index(first)..arena_index(arena.len());
        block.span = self.extend(block.span);
        (block.number.is_some() || !block.items.is_empty()).then_some(block)
    }

    fn item(&mut self) -> Option<Item> {
        let span = self.span();
        match self.peek().clone() {
            Tok::Punct("#") => {
                let full = self.to_block_end(span);
                self.bump();
                let command = self.command(full)?;
                let span = self.extend(span);
                Some(Item::Command {
                    command: Box::new(command),
                    span,
                })
            }
            Tok::Punct("$") => {
                let full = self.to_block_end(span);
                self.bump();
                let control = self.control(full)?;
                let span = self.extend(span);
                Some(Item::Control {
                    control: Box::new(control),
                    span,
                })
            }
            Tok::Word(_) | Tok::Addr(..) => self.word_item(span),
            Tok::Percent(_) => {
                self.bump();
                self.error(
                    span,
                    "a program header \"%name\" must stand on its own first line",
                );
                None
            }
            _ => {
                let found = self.describe();
                self.bump();
                self.error(
                    span,
                    format!("unexpected {found}: expected an address word (G, M, F, axis), a #command or a $statement"),
                );
                None
            }
        }
    }

    /// The word at the cursor with the number glued to it, if any (`G01` arrives as one
    /// address token from the lexer, `G 01` never glues); consumed. `None` if no word is there.
    fn take_word(&mut self) -> Option<(Name, Option<f64>)> {
        match *self.peek() {
            Tok::Word(w) => {
                self.bump();
                Some((w, self.glued_number()))
            }
            Tok::Addr(w, n) => {
                self.bump();
                Some((w, Some(n)))
            }
            _ => None,
        }
    }

    /// A number written directly after a word (`G01`, `ID3`), consumed.
    fn glued_number(&mut self) -> Option<f64> {
        match self.peek() {
            Tok::Num(n) if !self.token().spaced => {
                let n = *n;
                self.bump();
                Some(n)
            }
            _ => None,
        }
    }

    /// The axis name of a word with an optional glued whole number (`X`, `X1`); a sign or a
    /// decimal point is reported and the block skipped, a name longer than
    /// [`AxisName::CAPACITY`] is reported.
    fn axis_name(&mut self, word: Name, glued: Option<f64>, span: Span) -> Option<AxisName> {
        let with_number;
        let name = match glued {
            None => word.as_str(),
            Some(n) if n.fract() == 0.0 && n >= 0.0 => {
                with_number = format!("{word}{}", n as u64);
                &with_number
            }
            Some(_) => {
                self.error(
                    span,
                    "an axis name is letters and digits only (no sign, no decimal point)",
                );
                self.recover();
                return None;
            }
        };
        let axis = AxisName::parse(name);
        if axis.is_none() {
            self.error(
                span,
                format!(
                    "axis name \"{name}\" is longer than {} characters",
                    AxisName::CAPACITY
                ),
            );
        }
        axis
    }

    /// `G01`, `F500`, `M30`, `X10`, `AB=90`, `X1=5`, `X1[...]`.
    fn word_item(&mut self, span: Span) -> Option<Item> {
        let (word, glued) = self.take_word()?;
        // `NAME=expr` / `NAME3=expr`
        if self.is_punct("=") {
            // A name that is too long is reported; its value is still read, so that the
            // rest of the block is checked as usual.
            let name = self.axis_name(word, glued, span);
            if name.is_none() && self.at_end_of_block() {
                return None;
            }
            self.bump();
            let value = self.expr();
            let (name, value) = (name?, value?);
            return Some(match name.as_str() {
                "F" => Item::Feed {
                    value,
                    span: self.extend(span),
                },
                "G" | "M" | "N" => {
                    self.error(
                        span,
                        format!("{name}=... is not allowed: write {name}<number>"),
                    );
                    return None;
                }
                _ => Item::Axis(AxisWord {
                    name,
                    value,
                    span: self.extend(span),
                }),
            });
        }
        // `X1[INDP_ASYN ...]`
        if self.is_punct("[") {
            let name = self.axis_name(word, glued, span);
            if name.is_none() && self.at_end_of_block() {
                return None;
            }
            let options = self.bracket_list();
            let (name, options) = (name?, options?);
            return Some(Item::IndependentAxis {
                axis: Box::new(IndependentAxis { name, options }),
                span: self.extend(span),
            });
        }
        // `X-60`: a signed number glued to the address.
        let glued = glued.or_else(|| {
            let sign = match self.peek() {
                Tok::Punct("-") => -1.0,
                Tok::Punct("+") => 1.0,
                _ => return None,
            };
            match self.peek_at(1) {
                Tok::Num(n) if !self.token().spaced && !self.tokens[self.pos + 1].spaced => {
                    let n = *n;
                    self.bump();
                    self.bump();
                    Some(sign * n)
                }
                _ => None,
            }
        });
        let Some(value) = glued else {
            let found = self.describe();
            self.error(
                span,
                format!(
                    "address \"{word}\" needs a value: expected a number or \"=\", found {found}"
                ),
            );
            return None;
        };
        match word.as_bytes() {
            b"G" | b"M" => {
                if value.fract() != 0.0 || value < 0.0 {
                    self.error(
                        span,
                        format!("{word} code must be a whole number, found {value}"),
                    );
                    return None;
                }
                let code = value as u32;
                let span = self.extend(span);
                Some(if word.as_bytes() == b"G" {
                    Item::G { code, span }
                } else {
                    Item::M { code, span }
                })
            }
            b"F" => Some(Item::Feed {
                value: Expr::Num(value),
                span: self.extend(span),
            }),
            b"N" => {
                self.error(span, "a block number N must come first in its block");
                None
            }
            _ => Some(Item::Axis(AxisWord {
                name: self.axis_name(word, None, span)?,
                value: Expr::Num(value),
                span: self.extend(span),
            })),
        }
    }

    fn on_off(&mut self, context: &str) -> Option<bool> {
        match self.peek() {
            Tok::Word(w) if w == "ON" => {
                self.bump();
                Some(true)
            }
            Tok::Word(w) if w == "OFF" => {
                self.bump();
                Some(false)
            }
            _ => {
                let (span, found) = (self.span(), self.describe());
                self.error(
                    span,
                    format!("{context}: expected ON or OFF, found {found}"),
                );
                None
            }
        }
    }

    fn command(&mut self, span: Span) -> Option<Command> {
        let name = match self.peek().clone() {
            Tok::Word(w) if !self.token().spaced => {
                self.bump();
                w
            }
            _ => {
                let found = self.describe();
                self.error(
                    span,
                    format!("expected a command name after \"#\", found {found}"),
                );
                self.recover();
                return None;
            }
        };
        let result = match name.as_str() {
            "TRACK" | "TRACK_CS" => {
                if name == "TRACK" && !self.expect_word("CS", "#TRACK CS") {
                    self.recover();
                    return None;
                }
                if self.is_word("ABS") {
                    self.bump();
                    Some(Command::TrackCsAbs)
                } else {
                    let on = self.on_off("#TRACK CS")?;
                    let options = if self.is_punct("[") {
                        self.bracket_list()?
                    } else {
                        Vec::new()
                    };
                    self.check_track_options(&options);
                    Some(Command::TrackCs { on, options })
                }
            }
            "CHANNEL" => {
                if !self.expect_word("INTERFACE", "#CHANNEL INTERFACE") {
                    self.recover();
                    return None;
                }
                let on = self.on_off("#CHANNEL INTERFACE")?;
                let mut kind = None;
                if self.is_punct("[") {
                    let entries = self.bracket_list()?;
                    for e in entries {
                        match (&e.key, &e.value, e.glued) {
                            (Some(k), None, None) if k == "DYN_CS" || k == "TRACK_CS" => {
                                if kind.replace(*k).is_some() {
                                    self.error(
                                        e.span,
                                        "#CHANNEL INTERFACE names its interface once",
                                    );
                                }
                            }
                            _ => self
                                .error(e.span, "#CHANNEL INTERFACE: expected DYN_CS or TRACK_CS"),
                        }
                    }
                }
                Some(Command::ChannelInterface { on, kind })
            }
            "CS" => {
                let on = self.on_off("#CS")?;
                let mut name = None;
                let mut values = Vec::new();
                let mut lists = 0;
                while self.is_punct("[") {
                    lists += 1;
                    let entries = self.bracket_list()?;
                    let is_name = entries.len() == 1
                        && entries[0].key.is_some()
                        && entries[0].value.is_none()
                        && entries[0].glued.is_none();
                    if is_name && name.is_none() && values.is_empty() {
                        name = entries[0].key;
                    } else {
                        for e in entries {
                            match (e.key, e.value) {
                                (None, Some(v)) => values.push(v),
                                _ => self.error(
                                    e.span,
                                    "#CS: expected a value (number, variable or expression)",
                                ),
                            }
                        }
                    }
                    if lists > 2 {
                        self.error(span, "#CS takes at most a name list and a value list");
                    }
                }
                Some(Command::Cs { on, name, values })
            }
            "TRAFO" => {
                let on = match self.peek() {
                    Tok::Word(w) if w == "ON" || w == "OFF" => self.on_off("#TRAFO"),
                    _ => None,
                };
                let id = if self.is_punct("[") {
                    let entries = self.bracket_list()?;
                    match entries.as_slice() {
                        [Entry {
                            key: None,
                            value: Some(v),
                            ..
                        }] => Some(v.clone()),
                        _ => {
                            self.error(span, "#TRAFO [..]: expected one kinematic id");
                            None
                        }
                    }
                } else {
                    None
                };
                if on.is_none() && id.is_none() {
                    let found = self.describe();
                    self.error(
                        span,
                        format!("#TRAFO: expected ON, OFF or [id], found {found}"),
                    );
                    return None;
                }
                Some(Command::Trafo { on, id })
            }
            "KIN" => {
                if !self.expect_word("ID", "#KIN ID") {
                    self.recover();
                    return None;
                }
                let entries = if self.is_punct("[") {
                    self.bracket_list()?
                } else {
                    Vec::new()
                };
                match entries.as_slice() {
                    [Entry {
                        key: None,
                        value: Some(v),
                        ..
                    }] => Some(Command::KinId { id: v.clone() }),
                    _ => {
                        self.error(span, "#KIN ID: expected [id]");
                        None
                    }
                }
            }
            "SIGNAL" => {
                if !self.expect_word("SYN", "#SIGNAL SYN") {
                    self.recover();
                    return None;
                }
                let options = self.required_list("#SIGNAL SYN")?;
                self.check_keys(&options, &["ID", "COUNT"], "#SIGNAL SYN");
                Some(Command::SignalSyn { options })
            }
            "WAIT" => match self.peek().clone() {
                Tok::Word(w) if w == "SYN" => {
                    self.bump();
                    let options = self.required_list("#WAIT SYN")?;
                    self.check_keys(&options, &["ID"], "#WAIT SYN");
                    Some(Command::WaitSyn { options })
                }
                Tok::Word(w) if w == "INDP" => {
                    self.bump();
                    self.expect_word("ALL", "#WAIT INDP ALL")
                        .then_some(Command::WaitIndpAll)
                }
                _ => {
                    let found = self.describe();
                    self.error(span, format!("#WAIT: expected SYN or INDP, found {found}"));
                    None
                }
            },
            "FLUSH" => match self.peek().clone() {
                Tok::Word(w) if w == "WAIT" || w == "CONTINUE" => {
                    self.bump();
                    Some(Command::Flush { wait: w == "WAIT" })
                }
                _ => {
                    let found = self.describe();
                    self.error(
                        span,
                        format!("#FLUSH: expected WAIT or CONTINUE, found {found}"),
                    );
                    None
                }
            },
            "PSET" => {
                let mut axes = Vec::new();
                while matches!(self.peek(), Tok::Word(_) | Tok::Addr(..)) {
                    let s = self.span();
                    match self.word_item(s) {
                        Some(Item::Axis(a)) => axes.push(a),
                        _ => self.error(s, "#PSET: expected axis assignments such as X=10"),
                    }
                }
                if axes.is_empty() {
                    self.error(span, "#PSET: expected at least one axis assignment");
                }
                Some(Command::Pset { axes })
            }
            "PRESET" => {
                let mut axes = Vec::new();
                while let Some((w, glued)) = self.take_word() {
                    let s = self.span();
                    axes.push(self.axis_name(w, glued, s)?);
                }
                Some(Command::Preset { axes })
            }
            other => {
                self.error(
                    span,
                    format!("unknown command \"#{other}\" (known: #TRACK CS, #CHANNEL INTERFACE, #CS, #TRAFO, #KIN ID, #SIGNAL SYN, #WAIT SYN, #WAIT INDP, #FLUSH, #PSET, #PRESET)"),
                );
                self.recover();
                return None;
            }
        };
        if result.is_none() {
            self.recover();
        }
        result
    }

    fn required_list(&mut self, context: &str) -> Option<Vec<Entry>> {
        if self.is_punct("[") {
            self.bracket_list()
        } else {
            let (span, found) = (self.span(), self.describe());
            self.error(span, format!("{context}: expected \"[\", found {found}"));
            None
        }
    }

    fn check_keys(&mut self, entries: &[Entry], allowed: &[&str], context: &str) {
        for e in entries {
            let ok = e.key.as_deref().is_some_and(|k| allowed.contains(&k))
                && (e.glued.is_some() || e.value.is_some());
            if !ok {
                self.error(
                    e.span,
                    format!("{context}: expected {} with a value", allowed.join(" or ")),
                );
            }
        }
    }

    fn check_track_options(&mut self, entries: &[Entry]) {
        for e in entries {
            let Some(key) = e.key.as_deref() else {
                self.error(e.span, "#TRACK CS: expected an option name");
                continue;
            };
            if TRACK_FLAGS.contains(&key) {
                if e.value.is_some() || e.glued.is_some() || e.text.is_some() {
                    self.error(e.span, format!("#TRACK CS: option {key} takes no value"));
                }
            } else if TRACK_VALUES.contains(&key) {
                if e.value.is_none() && e.text.is_none() && e.glued.is_none() {
                    self.error(
                        e.span,
                        format!("#TRACK CS: option {key} needs a value: {key}=..."),
                    );
                }
            } else {
                self.error(
                    e.span,
                    format!("#TRACK CS: unknown option \"{key}\" (expected CH, ID, SET_ZERO, ABSOLUTE, OPTION, KIN_BASE, FILTER, WAIT, ROT_TRANS, RELATIVE, X, Y, Z, A, B, C, SIMU or LOG_FILE)"),
                );
            }
        }
    }

    /// `[ entry entry, entry ... ]`; the list may run over several lines.
    fn bracket_list(&mut self) -> Option<Vec<Entry>> {
        let open = self.span();
        self.bump(); // [
        let mut entries = Vec::new();
        loop {
            match self.peek().clone() {
                Tok::Punct("]") => {
                    self.bump();
                    return Some(entries);
                }
                Tok::Punct(",") => {
                    self.bump();
                }
                Tok::Newline => {
                    self.error(open, "\"[\" is not closed by \"]\"");
                    return None;
                }
                Tok::Word(_) | Tok::Addr(..) => {
                    let span = self.span();
                    let (w, glued) = self.take_word()?;
                    let (mut value, mut text) = (None, None);
                    if self.is_punct("=") {
                        self.bump();
                        if let Tok::Str(s) = self.peek().clone() {
                            self.bump();
                            text = Some(std::sync::Arc::from(s));
                        } else {
                            value = Some(self.expr()?);
                        }
                    }
                    entries.push(Entry {
                        key: Some(w),
                        glued,
                        value,
                        text,
                        span: self.extend(span),
                    });
                }
                _ => {
                    let span = self.span();
                    let value = self.expr()?;
                    entries.push(Entry {
                        key: None,
                        glued: None,
                        value: Some(value),
                        text: None,
                        span: self.extend(span),
                    });
                }
            }
        }
    }

    fn control(&mut self, span: Span) -> Option<Control> {
        let word = match self.peek().clone() {
            Tok::Word(w) => {
                self.bump();
                w
            }
            _ => {
                let found = self.describe();
                self.error(
                    span,
                    format!(
                        "expected WHILE, ENDWHILE, IF, ELSE or ENDIF after \"$\", found {found}"
                    ),
                );
                self.recover();
                return None;
            }
        };
        let control = match word.as_str() {
            "WHILE" => Control::While(self.expr()?),
            "ENDWHILE" => Control::EndWhile,
            "IF" => Control::If(self.expr()?),
            "ELSE" => Control::Else,
            "ENDIF" => Control::EndIf,
            other => {
                self.error(span, format!("unknown statement \"${other}\" (known: $WHILE, $ENDWHILE, $IF, $ELSE, $ENDIF)"));
                self.recover();
                return None;
            }
        };
        if !self.at_end_of_block() {
            let (s, found) = (self.span(), self.describe());
            self.error(
                s,
                format!("expected end of block after ${word}, found {found}"),
            );
            self.recover();
        }
        Some(control)
    }

    /// Expression with precedence climbing; unary minus binds tightest.
    fn expr(&mut self) -> Option<Expr> {
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
            let rhs = self.binary(op.precedence() + 1)?;
            lhs = Expr::Bin(Box::new((op, lhs, rhs)));
        }
        Some(lhs)
    }

    fn binary_operator(&self) -> Option<BinOp> {
        let Tok::Punct(p) = self.peek() else {
            return None;
        };
        Some(match *p {
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
            _ => {
                let (span, found) = (self.span(), self.describe());
                self.error(
                    span,
                    format!("expected a number, a variable or \"-\", found {found}"),
                );
                None
            }
        }
    }
}
