//! The parser: tokens to the program tree. It never gives up: a bad item is reported with its
//! span and what was expected, skipped, and parsing goes on with the next item.

use super::ast::arena_index;
use super::ast::*;
use super::lexer::{Lexer, Name, Tok, Token};
use super::Diagnostic;

/// The highest P parameter number.
pub const MAX_PARAM: u32 = 999;

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

    /// Whether the token at the cursor can start an expression.
    fn starts_expression(&self) -> bool {
        match self.peek() {
            Tok::Num(_) | Tok::Var(_) | Tok::Punct("[" | "-" | "+") => true,
            Tok::Addr(w, n) => {
                *w == "P"
                    || (*w == "ATAN" && *n == 2.0 && matches!(self.peek_at(1), Tok::Punct("[")))
            }
            Tok::Word(w) => Func::named(w).is_some() && matches!(self.peek_at(1), Tok::Punct("[")),
            _ => false,
        }
    }

    /// `= expr` after an assignment's target (consumed already).
    fn assignment(&mut self, target: Target, span: Span) -> Option<Item> {
        if !self.is_punct("=") {
            let found = self.describe();
            self.error(
                span,
                format!("expected \"=\" after \"{target}\" (an assignment), found {found}"),
            );
            self.recover();
            return None;
        }
        self.bump();
        let value = self.expr()?;
        Some(Item::Assign {
            assign: Box::new(Assign { target, value }),
            span: self.extend(span),
        })
    }

    /// The P parameter number glued to `P` (`P12`), if the word is one.
    fn param_number(word: Name, glued: Option<f64>) -> Option<u32> {
        let n = glued?;
        (word == "P" && n.fract() == 0.0 && (1.0..=f64::from(MAX_PARAM)).contains(&n))
            .then_some(n as u32)
    }

    /// `L name [P1=..]`, `LL name [P1=..]`: the name runs to the next blank.
    fn sub_call(&mut self, local: bool, span: Span) -> Option<Item> {
        let keyword = if local { "LL" } else { "L" };
        if self.at_end_of_block() || !self.token().spaced {
            let found = self.describe();
            self.error(
                span,
                format!("{keyword}: expected a blank and a subroutine name, found {found}"),
            );
            self.recover();
            return None;
        }
        let name = self.raw_name();
        if !self.at_end_of_block() {
            let (at, found) = (self.span(), self.describe());
            self.error(
                at,
                format!("{keyword} {name} takes no arguments (set P parameters before the call), found {found}"),
            );
            self.recover();
        }
        Some(Item::Call {
            call: Box::new(SubCall { local, name }),
            span: self.extend(span),
        })
    }

    /// `G01`, `F500`, `M30`, `X10`, `AB=90`, `X1=5`, `X1[...]`, `I5`, `P1=2`, `L sub.nc`.
    fn word_item(&mut self, span: Span) -> Option<Item> {
        let (word, glued) = self.take_word()?;
        if glued.is_none() && (word == "L" || word == "LL") {
            return self.sub_call(word == "LL", span);
        }
        if word == "P" || word == "PP" || word == "PPP" {
            return self.param_assignment(word, glued, span);
        }
        if self.is_punct("=") {
            return self.assigned_word(word, glued, span);
        }
        // `X[P1 * 2]`: an expression in brackets right after the address.
        let independent = matches!(self.peek_at(1), Tok::Word(w) if w.starts_with("INDP"));
        // `G4 [..]`: a code word ends at its number; the bracket is the next item.
        let code = glued.is_some() && matches!(word.as_str(), "G" | "M" | "N");
        let bracket = self.is_punct("[") && !code;
        if bracket && !self.token().spaced && !independent {
            return self.bracketed_word(word, glued, span);
        }
        if bracket {
            return self.independent_axis(word, glued, span);
        }
        self.numbered_word(word, glued, span)
    }

    /// `P12 = expr` after `P12` (`word` and `glued`); indirect (`PP1`) and indexed (`P[..]`)
    /// parameters are reported and the block skipped.
    fn param_assignment(&mut self, word: Name, glued: Option<f64>, span: Span) -> Option<Item> {
        if word == "PP" || word == "PPP" {
            self.error(span, "indirect P parameters (PP1) are not supported");
            self.recover();
            return None;
        }
        if glued.is_none() && self.is_punct("[") {
            self.error(
                span,
                "indexed P parameters (P[..]) and P arrays are not supported",
            );
            self.recover();
            return None;
        }
        let Some(n) = Self::param_number(word, glued) else {
            self.error(
                span,
                format!("a P parameter is P and a whole number 1..={MAX_PARAM}, such as P12"),
            );
            self.recover();
            return None;
        };
        self.assignment(Target::Param(n), span)
    }

    /// `X=expr`, `F=expr`, the cursor on the `=`; `G=`, `M=` and `N=` are reported.
    fn assigned_word(&mut self, word: Name, glued: Option<f64>, span: Span) -> Option<Item> {
        // A name that is too long is reported; its value is still read, so that the
        // rest of the block is checked as usual.
        let name = self.axis_name(word, glued, span);
        if name.is_none() && self.at_end_of_block() {
            return None;
        }
        self.bump();
        let value = self.expr();
        let (name, value) = (name?, value?);
        Some(match name.as_str() {
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
        })
    }

    /// `X[P1 * 2]`, `F[..]`: the value in brackets right after the address.
    fn bracketed_word(&mut self, word: Name, glued: Option<f64>, span: Span) -> Option<Item> {
        let name = self.axis_name(word, glued, span)?;
        let value = self.expr()?;
        Some(if name.as_str() == "F" {
            Item::Feed {
                value,
                span: self.extend(span),
            }
        } else {
            Item::Axis(AxisWord {
                name,
                value,
                span: self.extend(span),
            })
        })
    }

    /// `X1[INDP_ASYN ...]`: an independent axis command, the cursor on the `[`.
    fn independent_axis(&mut self, word: Name, glued: Option<f64>, span: Span) -> Option<Item> {
        let name = self.axis_name(word, glued, span);
        if name.is_none() && self.at_end_of_block() {
            return None;
        }
        let options = self.bracket_list();
        let (name, options) = (name?, options?);
        Some(Item::IndependentAxis {
            axis: Box::new(IndependentAxis { name, options }),
            span: self.extend(span),
        })
    }

    /// A word with its number: `G01`, `M30`, `F500`, `X10`, also signed (`X-60`).
    fn numbered_word(&mut self, word: Name, glued: Option<f64>, span: Span) -> Option<Item> {
        // `X-60`: a signed number glued to the address.
        let glued = glued.or_else(|| self.signed_glued_number());
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

    /// A sign and a number glued to the word before (`X-60`), consumed.
    fn signed_glued_number(&mut self) -> Option<f64> {
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

    /// A `#` command, the cursor after the `#` (`span` runs to the end of the block). A command
    /// that cannot be read is reported and gives `None`. Then the rest of the block is skipped,
    /// except where a part of the command failed (its ON/OFF, its bracket list, an axis name,
    /// or `#TRAFO` given neither ON, OFF nor an id): parsing goes on where that part stopped.
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
        match name.as_str() {
            "TRACK" | "TRACK_CS" => self.track_cs(name),
            "CHANNEL" => self.channel_interface(),
            "CS" => self.cs(span),
            "TRAFO" => self.trafo(span),
            "KIN" => self.kin_id(span),
            "SIGNAL" => self.signal_syn(),
            "WAIT" => self.wait(span),
            "FLUSH" => self.flush(span),
            "PSET" => self.pset(span),
            "PRESET" => self.preset(),
            "MSG" => self.msg(span),
            "TIME" => self.time(),
            "VAR" => Some(Command::Var),
            "ENDVAR" => Some(Command::EndVar),
            "COMMENT" => {
                self.error(
                    span,
                    "#COMMENT END without #COMMENT BEGIN (a comment section is #COMMENT BEGIN ... #COMMENT END, each on its own line)",
                );
                self.recover();
                None
            }
            other => {
                self.error(
                    span,
                    format!("unknown command \"#{other}\" (known: #TRACK CS, #CHANNEL INTERFACE, #CS, #TRAFO, #KIN ID, #SIGNAL SYN, #WAIT SYN, #WAIT INDP, #FLUSH, #PSET, #PRESET, #MSG, #TIME, #VAR, #ENDVAR, #COMMENT BEGIN/END)"),
                );
                self.recover();
                None
            }
        }
    }

    /// `#TRACK CS ABS`, `#TRACK CS ON|OFF [options]` (`name` is `TRACK` or `TRACK_CS`).
    fn track_cs(&mut self, name: Name) -> Option<Command> {
        if name == "TRACK" && !self.expect_word("CS", "#TRACK CS") {
            self.recover();
            return None;
        }
        if self.is_word("ABS") {
            self.bump();
            return Some(Command::TrackCsAbs);
        }
        let on = self.on_off("#TRACK CS")?;
        let options = if self.is_punct("[") {
            self.bracket_list()?
        } else {
            Vec::new()
        };
        self.check_track_options(&options);
        Some(Command::TrackCs { on, options })
    }

    /// `#CHANNEL INTERFACE ON|OFF [DYN_CS|TRACK_CS]`, after `CHANNEL`.
    fn channel_interface(&mut self) -> Option<Command> {
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
                            self.error(e.span, "#CHANNEL INTERFACE names its interface once");
                        }
                    }
                    _ => self.error(e.span, "#CHANNEL INTERFACE: expected DYN_CS or TRACK_CS"),
                }
            }
        }
        Some(Command::ChannelInterface { on, kind })
    }

    /// `#CS ON|OFF [name] [values]`, after `CS`.
    fn cs(&mut self, span: Span) -> Option<Command> {
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

    /// `#TRAFO ON|OFF`, `#TRAFO [id]`, `#TRAFO ON [id]`, after `TRAFO`.
    fn trafo(&mut self, span: Span) -> Option<Command> {
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

    /// `#KIN ID [id]`, after `KIN`.
    fn kin_id(&mut self, span: Span) -> Option<Command> {
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
                self.recover();
                None
            }
        }
    }

    /// `#SIGNAL SYN [ID.. COUNT..]`, after `SIGNAL`.
    fn signal_syn(&mut self) -> Option<Command> {
        if !self.expect_word("SYN", "#SIGNAL SYN") {
            self.recover();
            return None;
        }
        let options = self.required_list("#SIGNAL SYN")?;
        self.check_keys(&options, &["ID", "COUNT"], "#SIGNAL SYN");
        Some(Command::SignalSyn { options })
    }

    /// `#WAIT SYN [ID..]`, `#WAIT INDP ALL`, after `WAIT`.
    fn wait(&mut self, span: Span) -> Option<Command> {
        match self.peek().clone() {
            Tok::Word(w) if w == "SYN" => {
                self.bump();
                let options = self.required_list("#WAIT SYN")?;
                self.check_keys(&options, &["ID"], "#WAIT SYN");
                Some(Command::WaitSyn { options })
            }
            Tok::Word(w) if w == "INDP" => {
                self.bump();
                if self.expect_word("ALL", "#WAIT INDP ALL") {
                    Some(Command::WaitIndpAll)
                } else {
                    self.recover();
                    None
                }
            }
            _ => {
                let found = self.describe();
                self.error(span, format!("#WAIT: expected SYN or INDP, found {found}"));
                self.recover();
                None
            }
        }
    }

    /// `#FLUSH WAIT|CONTINUE`, after `FLUSH`.
    fn flush(&mut self, span: Span) -> Option<Command> {
        match self.peek().clone() {
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
                self.recover();
                None
            }
        }
    }

    /// `#PSET X=10 ...`, after `PSET`.
    fn pset(&mut self, span: Span) -> Option<Command> {
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

    /// `#PRESET`, `#PRESET X ...`, after `PRESET`.
    fn preset(&mut self) -> Option<Command> {
        let mut axes = Vec::new();
        while let Some((w, glued)) = self.take_word() {
            let s = self.span();
            axes.push(self.axis_name(w, glued, s)?);
        }
        Some(Command::Preset { axes })
    }

    /// `#MSG ["text"]`, also `#MSG SAVE ["text"]` (the message is shown either way), after
    /// `MSG`.
    fn msg(&mut self, span: Span) -> Option<Command> {
        if self.is_word("SAVE") {
            self.bump();
        }
        let text = if self.is_punct("[") {
            self.bump();
            let text = match self.peek().clone() {
                Tok::Str(t) => {
                    self.bump();
                    Some(t)
                }
                _ => None,
            };
            if self.is_punct("]") {
                self.bump();
            } else {
                self.error(span, "#MSG: expected \"]\" after the text");
            }
            text
        } else {
            None
        };
        match text {
            Some(t) => Some(Command::Msg {
                text: std::sync::Arc::from(t),
            }),
            None => {
                self.error(span, "#MSG: expected [\"text\"]");
                self.recover();
                None
            }
        }
    }

    /// `#TIME t`, after `TIME`.
    fn time(&mut self) -> Option<Command> {
        let Some(seconds) = self.expr() else {
            self.recover();
            return None;
        };
        Some(Command::Time { seconds })
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
                // A P parameter or a function is a value, not a key.
                Tok::Word(_) | Tok::Addr(..) if !self.starts_expression() => {
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
            "ELSEIF" => Control::ElseIf(self.expr()?),
            "ELSE" => Control::Else,
            "ENDIF" => Control::EndIf,
            "FOR" => self.for_statement(span)?,
            "ENDFOR" => Control::EndFor,
            "DO" => Control::Do,
            "ENDDO" => Control::EndDo(self.expr()?),
            "SWITCH" => Control::Switch(self.expr()?),
            "CASE" => Control::Case(self.expr()?),
            "DEFAULT" => Control::Default,
            "ENDSWITCH" => Control::EndSwitch,
            "BREAK" => Control::Break,
            "CONTINUE" => Control::Continue,
            "GOTO" => {
                let target = match *self.peek() {
                    Tok::Addr(w, n) if w == "N" && n.fract() == 0.0 && n >= 0.0 => {
                        self.bump();
                        Some(n as u32)
                    }
                    _ => None,
                };
                let Some(target) = target else {
                    let found = self.describe();
                    self.error(
                        span,
                        format!("$GOTO: expected a block number such as N100, found {found}"),
                    );
                    self.recover();
                    return None;
                };
                Control::Goto(target)
            }
            other => {
                self.error(span, format!("unknown statement \"${other}\" (known: $IF, $ELSEIF, $ELSE, $ENDIF, $WHILE, $ENDWHILE, $DO, $ENDDO, $FOR, $ENDFOR, $SWITCH, $CASE, $DEFAULT, $ENDSWITCH, $BREAK, $CONTINUE, $GOTO)"));
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

    /// `$FOR P1 = start, end, step` (the step may be left out: 1).
    fn for_statement(&mut self, span: Span) -> Option<Control> {
        let var = match *self.peek() {
            Tok::Addr(w, n) => Self::param_number(w, Some(n)).map(Target::Param),
            Tok::Var(v) => Some(Target::Var(v)),
            _ => None,
        };
        let Some(var) = var else {
            let found = self.describe();
            self.error(
                span,
                format!("$FOR: expected a counter such as P1, found {found}"),
            );
            self.recover();
            return None;
        };
        self.bump();
        if !self.is_punct("=") {
            let found = self.describe();
            self.error(span, format!("$FOR {var}: expected \"=\", found {found}"));
            self.recover();
            return None;
        }
        self.bump();
        let start = self.expr()?;
        let mut bounds = Vec::with_capacity(2);
        while self.is_punct(",") && bounds.len() < 2 {
            self.bump();
            bounds.push(self.expr()?);
        }
        let mut bounds = bounds.into_iter();
        let Some(end) = bounds.next() else {
            self.error(span, format!("$FOR {var}: expected \"start, end[, step]\""));
            self.recover();
            return None;
        };
        let step = bounds.next().unwrap_or(Expr::Num(1.0));
        Some(Control::For {
            var,
            start,
            end,
            step,
        })
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
            // The power is right-associative: 2**3**2 is 2**9.
            let next = if op == BinOp::Pow {
                op.precedence()
            } else {
                op.precedence() + 1
            };
            let rhs = self.binary(next)?;
            lhs = Expr::Bin(Box::new((op, lhs, rhs)));
        }
        Some(lhs)
    }

    fn binary_operator(&self) -> Option<BinOp> {
        let p = match self.peek() {
            Tok::Punct(p) => *p,
            Tok::Word(w) => {
                return match w.as_str() {
                    "MOD" => Some(BinOp::Mod),
                    "AND" => Some(BinOp::And),
                    "OR" => Some(BinOp::Or),
                    "XOR" => Some(BinOp::Xor),
                    _ => None,
                }
            }
            _ => return None,
        };
        Some(match p {
            "**" => BinOp::Pow,
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

    /// The `]` that closes the bracket opened at `open`, consumed.
    fn close_bracket(&mut self, open: Span) -> Option<()> {
        if self.is_punct("]") {
            self.bump();
            Some(())
        } else {
            let found = self.describe();
            self.error(
                open,
                format!("\"[\" is not closed by \"]\" (found {found})"),
            );
            None
        }
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
            Tok::Addr(w, n) if w == "P" => {
                let span = self.span();
                self.bump();
                match Self::param_number(w, Some(n)) {
                    Some(n) => Some(Expr::Param(n)),
                    None => {
                        self.error(
                            span,
                            format!("a P parameter is P and a whole number 1..={MAX_PARAM}"),
                        );
                        None
                    }
                }
            }
            Tok::Punct("[") => {
                let open = self.span();
                self.bump();
                let inner = self.expr()?;
                self.close_bracket(open)?;
                Some(inner)
            }
            // `ATAN2` arrives as the word ATAN with a glued 2.
            Tok::Addr(w, n)
                if w == "ATAN" && n == 2.0 && matches!(self.peek_at(1), Tok::Punct("[")) =>
            {
                self.call(Func::Atan2)
            }
            Tok::Word(w)
                if Func::named(&w).is_some() && matches!(self.peek_at(1), Tok::Punct("[")) =>
            {
                self.call(Func::named(&w)?)
            }
            Tok::Word(w) => {
                let (span, found) = (self.span(), self.describe());
                let hint = if Func::named(&w).is_some() {
                    format!("{w} is a function: write {w}[...]")
                } else if matches!(self.peek_at(1), Tok::Punct("[")) {
                    let known: Vec<&str> = Func::ALL.iter().map(|f| f.1).collect();
                    format!("unknown function {w} (known: {})", known.join(", "))
                } else {
                    format!(
                        "expected a number, a variable, P.., a function or \"[\", found {found}"
                    )
                };
                self.error(span, hint);
                None
            }
            _ => {
                let (span, found) = (self.span(), self.describe());
                self.error(
                    span,
                    format!(
                        "expected a number, a variable, P.., a function or \"[\", found {found}"
                    ),
                );
                None
            }
        }
    }

    /// `FUNC[args]`, the cursor on the function's name.
    fn call(&mut self, func: Func) -> Option<Expr> {
        let span = self.span();
        self.bump();
        let open = self.span();
        self.bump();
        let mut args = vec![self.expr()?];
        while self.is_punct(",") {
            self.bump();
            args.push(self.expr()?);
        }
        self.close_bracket(open)?;
        if args.len() != func.arity() {
            self.error(
                span,
                format!(
                    "{}[...] takes {} argument(s), found {}",
                    func.name(),
                    func.arity(),
                    args.len()
                ),
            );
            return None;
        }
        Some(Expr::Call(Box::new((func, args))))
    }
}
