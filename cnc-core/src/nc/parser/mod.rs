//! The parser: tokens to the program tree. It never gives up: a bad item is reported with its
//! span and what was expected, skipped, and parsing goes on with the next item.
//!
//! This module reads the program block by block (headers, local subroutines, blocks and their
//! items); `words` reads address words, `commands` the `#` commands, `statements` the `$`
//! statements and `expr` the expressions.

mod commands;
mod expr;
mod statements;
mod words;

use super::ast::arena_index;
use super::ast::*;
use super::lexer::{Lexer, Tok, Token};
use super::Diagnostic;

/// The highest P parameter number.
pub const MAX_PARAM: u32 = 999;

/// How a fresh program's reserved arenas are prepared before they fill, if at all: the
/// application installs the operating system's memory advice (huge pages) once at start
/// ([`set_buffer_advice`]); the parser itself makes no system call.
static BUFFER_ADVICE: std::sync::OnceLock<fn(&mut Program)> = std::sync::OnceLock::new();

/// Installs `advice`, called on every program's arenas right after they are reserved (see
/// [`BUFFER_ADVICE`]); `false` when one was installed before (the first stays).
pub fn set_buffer_advice(advice: fn(&mut Program)) -> bool {
    BUFFER_ADVICE.set(advice).is_ok()
}

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
        blocks_before: 0,
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
    /// Blocks of the windows before the current one (see [`Windows`]).
    blocks_before: usize,
}

/// A program parsed window by window: a checker that runs a straight program as it reads it
/// keeps one window of its tree in memory, not the whole tree.
pub struct Windows<'a> {
    parser: Parser<'a>,
    more: bool,
}

impl<'a> Windows<'a> {
    /// Windows of `src`.
    pub fn new(src: &'a str) -> Self {
        Self {
            parser: Parser {
                src,
                fast_lane: true,
                lexer: Lexer::new(src),
                tokens: Vec::with_capacity(32),
                pos: 0,
                diags: Vec::new(),
                blocks_before: 0,
            },
            more: true,
        }
    }

    /// Replaces the blocks of `window` with the next at most `max_blocks` (the program's name
    /// and local subroutines stay: a header belongs to the whole program); `false` when no
    /// block is left.
    pub fn next(&mut self, window: &mut Program, max_blocks: usize) -> bool {
        self.parser.blocks_before += window.blocks.len();
        window.blocks.clear();
        window.items.clear();
        if self.more {
            self.more = self.parser.fill(window, max_blocks);
        }
        !window.blocks.is_empty()
    }

    /// Every syntax diagnostic of the program (after the last window), located.
    pub fn finish(mut self) -> Vec<Diagnostic> {
        let src = self.parser.src;
        let mut diags: Vec<Diagnostic> = self
            .parser
            .lexer
            .errors
            .drain(..)
            .map(|e| Diagnostic::new(e.span, e.message, src))
            .collect();
        diags.append(&mut self.parser.diags);
        super::locate(&mut diags, src);
        diags
    }
}

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
        // Long programs fill tens of megabytes of fresh memory: the application's advice
        // puts them in huge pages where the system has them.
        if let Some(advise) = BUFFER_ADVICE.get() {
            advise(&mut program);
        }
        self.fill(&mut program, usize::MAX);
        if program.name.is_none() && !program.subs.is_empty() {
            self.close_sub(&mut program);
        }
        program
    }

    /// Parses on into `program` until it holds `max_blocks` more blocks or the source ends;
    /// `false` when the source has ended.
    fn fill(&mut self, program: &mut Program, max_blocks: usize) -> bool {
        let limit = program.blocks.len().saturating_add(max_blocks);
        loop {
            if program.blocks.len() >= limit {
                return true;
            }
            if self.fast_lane {
                if let Some(block) = self.lexer.simple_block(&mut program.items) {
                    program.blocks.push(block);
                    continue;
                }
            }
            if !self.lexer.next_block(&mut self.tokens) {
                return false;
            }
            self.pos = 0;
            if let Tok::Percent(name) = self.peek().clone() {
                let span = self.span();
                self.bump();
                if self.local_sub_header(&name, span, program) {
                    continue;
                }
                let after_subs = !program.subs.is_empty() && program.name.is_none();
                if after_subs {
                    self.close_sub(program);
                }
                let blocks_before = !program.blocks.is_empty() || self.blocks_before > 0;
                if (program.name.is_some() || blocks_before) && !after_subs {
                    self.error(
                        span,
                        "a program header \"%name\" must come first and only once",
                    );
                } else if name.is_empty() {
                    self.error(span, "expected a program name after \"%\"");
                } else {
                    program.name = Some(name);
                    program.main_start = arena_index(program.blocks.len());
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
    }

    /// `%L name` (the lexer gives `%L` and the name as separate tokens when blank-separated):
    /// opens a local subroutine, closing the one before. Returns false for other headers.
    fn local_sub_header(&mut self, header: &str, span: Span, program: &mut Program) -> bool {
        if !header.eq_ignore_ascii_case("L") {
            return false;
        }
        if self.at_end_of_block() {
            let found = self.describe();
            self.error(
                span,
                format!("%L: expected a subroutine name, found {found}"),
            );
            return true;
        }
        let name = self.raw_name().to_ascii_uppercase();
        if program.name.is_some() {
            self.error(
                span,
                "local subroutines (%L) stand before the main program's \"%name\"",
            );
        }
        if program.subs.iter().any(|s| s.name == name) {
            self.error(
                span,
                format!("local subroutine \"{name}\" is defined twice"),
            );
        }
        if !self.at_end_of_block() {
            let (s, found) = (self.span(), self.describe());
            self.error(
                s,
                format!("expected end of line after \"%L {name}\", found {found}"),
            );
        }
        if !program.subs.is_empty() {
            self.close_sub(program);
        } else if !program.blocks.is_empty() {
            self.error(
                span,
                "local subroutines (%L) stand at the start of the file",
            );
        }
        let start = arena_index(program.blocks.len());
        program.subs.push(LocalSub {
            name,
            blocks: start..start,
            span,
        });
        program.main_start = start;
        true
    }

    /// The source text of the tokens from the cursor to the next blank (a subroutine or file
    /// name: `UP_1`, `lib/gup_1.nc`), consumed.
    fn raw_name(&mut self) -> String {
        let first = self.pos;
        self.bump();
        while !self.at_end_of_block() && !self.token().spaced {
            self.bump();
        }
        let (start, end) = (
            self.tokens[first].span.start as usize,
            self.tokens[self.pos - 1].span.end as usize,
        );
        self.src.get(start..end).unwrap_or("").to_string()
    }

    /// Ends the last local subroutine at the current block; the main program starts here.
    fn close_sub(&mut self, program: &mut Program) {
        let end = arena_index(program.blocks.len());
        if let Some(sub) = program.subs.last_mut() {
            if sub.blocks.end <= sub.blocks.start {
                sub.blocks.end = end;
            }
        }
        program.main_start = end;
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
        // `N40:` marks a `$GOTO` target; the colon adds nothing else.
        if block.number.is_some() && self.is_punct(":") {
            self.bump();
        }
        let first = arena.len();
        while !self.at_end_of_block() {
            let before = self.pos;
            // `G04 2.5`: the dwell time may follow G04 bare.
            let after_dwell =
                arena.len() > first && matches!(arena.last(), Some(Item::G { code: 4, .. }));
            if after_dwell && self.starts_expression() {
                let span = self.span();
                if let Some(value) = self.expr() {
                    arena.push(Item::Axis(AxisWord {
                        name: AxisName::default(),
                        value,
                        span: self.extend(span),
                    }));
                }
                // Never stand still: a token no expression could take is skipped (reported).
                if self.pos == before {
                    self.bump();
                }
                continue;
            }
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
            Tok::Var(name) => {
                self.bump();
                self.assignment(Target::Var(name), span)
            }
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    static ADVISED: AtomicUsize = AtomicUsize::new(0);

    /// The advice the application installs is called on each program's reserved arenas
    /// (and only the first installed counts); without one the parser advises nothing.
    #[test]
    fn the_installed_buffer_advice_sees_every_programs_reserved_arenas() {
        fn count(p: &mut Program) {
            assert!(p.blocks.capacity() > 0 && p.blocks.is_empty());
            ADVISED.fetch_add(1, Ordering::SeqCst);
        }
        let before = ADVISED.load(Ordering::SeqCst);
        let _ = parse("G1 X1\n");
        assert_eq!(ADVISED.load(Ordering::SeqCst), before, "none installed yet");
        assert!(set_buffer_advice(count));
        assert!(!set_buffer_advice(|_| {}), "the first stays");
        let (program, _) = parse("G1 X1\nG1 X2\n");
        assert_eq!(program.blocks.len(), 2);
        // At least this parse (other tests of the process may parse meanwhile).
        assert!(ADVISED.load(Ordering::SeqCst) > before);
    }
}
