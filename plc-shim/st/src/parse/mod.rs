//! The parser: tokens into a [`Unit`] by recursive descent. Declarations are here, statements
//! and expressions in [`stmt`]. The first error stops it, with its line and column; a word
//! the language reserves is refused as a name.

use crate::ast::{
    Init, Item, Name, Pou, PouKind, Section, TypeDecl, TypeDef, TypeRef, Unit, VarBlock, VarDecl,
};
use crate::diag::{Diagnostic, Pos};
use crate::lex::{lex, Tok, Token};

mod method;
mod stmt;

/// The words that open a variable section.
const SECTIONS: [&str; 7] = [
    "VAR",
    "VAR_INPUT",
    "VAR_OUTPUT",
    "VAR_IN_OUT",
    "VAR_GLOBAL",
    "VAR_TEMP",
    "VAR_EXTERNAL",
];

/// The words a name may not be (ASCII case ignored), besides [`SECTIONS`].
const RESERVED: &[&str] = &[
    "PROGRAM",
    "END_PROGRAM",
    "FUNCTION_BLOCK",
    "END_FUNCTION_BLOCK",
    "FUNCTION",
    "END_FUNCTION",
    "END_VAR",
    "CONSTANT",
    "RETAIN",
    "PERSISTENT",
    "TYPE",
    "END_TYPE",
    "STRUCT",
    "END_STRUCT",
    "ARRAY",
    "OF",
    "POINTER",
    "REFERENCE",
    "TO",
    "IF",
    "THEN",
    "ELSIF",
    "ELSE",
    "END_IF",
    "CASE",
    "END_CASE",
    "FOR",
    "BY",
    "DO",
    "END_FOR",
    "WHILE",
    "END_WHILE",
    "REPEAT",
    "UNTIL",
    "END_REPEAT",
    "EXIT",
    "CONTINUE",
    "RETURN",
    "AND",
    "AND_THEN",
    "OR",
    "OR_ELSE",
    "XOR",
    "NOT",
    "MOD",
    "TRUE",
    "FALSE",
    "AT",
];

/// The object-oriented extensions of the standard's third edition (TwinCAT 3, CODESYS 3):
/// refused by name where one would begin a declaration, never read as something else.
const OBJECT_ORIENTED: [&str; 4] = ["PROPERTY", "INTERFACE", "EXTENDS", "IMPLEMENTS"];

/// Whether `word` is reserved (ASCII case ignored).
fn reserved(word: &str) -> bool {
    let same = |r: &&str| r.eq_ignore_ascii_case(word);
    RESERVED.iter().any(same) || SECTIONS.iter().any(same)
}

/// Parses one file's text; `Err` is the first refusal, with its place.
pub fn parse(text: &str) -> Result<Unit, Diagnostic> {
    let tokens = lex(text)?;
    let mut p = Parser {
        tokens,
        at: 0,
        depth: 0,
    };
    let mut unit = Unit::default();
    while !p.at_eof() {
        // A METHOD or ACTION after its POU's END_..: the POU's.
        if p.method_start() {
            let pos = p.pos();
            let m = p.method()?;
            match unit.items.last_mut() {
                Some(Item::Pou(pou)) if pou.kind != PouKind::Function => pou.methods.push(m),
                _ => {
                    let why = "a METHOD or ACTION follows its FUNCTION_BLOCK or PROGRAM";
                    return Err(Diagnostic::new(pos, why));
                }
            }
            continue;
        }
        unit.items.push(p.item()?);
    }
    Ok(unit)
}

struct Parser {
    tokens: Vec<Token>,
    at: usize,
    /// How deep the expressions and statements being read are nested.
    depth: usize,
}

impl Parser {
    fn peek(&self) -> &Tok {
        &self.tokens[self.at].kind
    }

    fn peek_at(&self, ahead: usize) -> &Tok {
        let i = (self.at + ahead).min(self.tokens.len() - 1);
        &self.tokens[i].kind
    }

    fn pos(&self) -> Pos {
        self.tokens[self.at].pos
    }

    fn at_eof(&self) -> bool {
        matches!(self.peek(), Tok::Eof)
    }

    fn bump(&mut self) -> Token {
        let t = self.tokens[self.at].clone();
        if self.at + 1 < self.tokens.len() {
            self.at += 1;
        }
        t
    }

    fn error(&self, message: impl Into<String>) -> Diagnostic {
        Diagnostic::new(self.pos(), message)
    }

    /// What the current token is, for an error.
    fn found(&self) -> String {
        match self.peek() {
            Tok::Ident(s) => format!("`{s}`"),
            Tok::Eof => "the end of the file".into(),
            other => format!("{other:?}"),
        }
    }

    /// Whether the current token is keyword `kw`.
    fn is_kw(&self, kw: &str) -> bool {
        matches!(self.peek(), Tok::Ident(s) if s.eq_ignore_ascii_case(kw))
    }

    /// Takes keyword `kw` if it is next.
    fn eat_kw(&mut self, kw: &str) -> bool {
        let is = self.is_kw(kw);
        if is {
            self.bump();
        }
        is
    }

    fn expect_kw(&mut self, kw: &str) -> Result<(), Diagnostic> {
        if self.eat_kw(kw) {
            Ok(())
        } else {
            Err(self.error(format!("expected `{kw}`, found {}", self.found())))
        }
    }

    fn eat(&mut self, tok: &Tok) -> bool {
        let is = self.peek() == tok;
        if is {
            self.bump();
        }
        is
    }

    fn expect(&mut self, tok: &Tok, what: &str) -> Result<(), Diagnostic> {
        if self.eat(tok) {
            Ok(())
        } else {
            Err(self.error(format!("expected {what}, found {}", self.found())))
        }
    }

    /// A name that is not a reserved word.
    fn name(&mut self) -> Result<Name, Diagnostic> {
        let pos = self.pos();
        match self.peek().clone() {
            Tok::Ident(text) if !reserved(&text) => {
                self.bump();
                Ok(Name { text, pos })
            }
            Tok::Ident(text) => Err(self.error(format!("`{text}` is reserved, not a name"))),
            _ => Err(self.error(format!("expected a name, found {}", self.found()))),
        }
    }

    /// Refuses the next word if it is one of [`OBJECT_ORIENTED`]'s followed by a name (as
    /// `METHOD M_Reset`, `EXTENDS FB_Base`: a variable of such a name is no declaration).
    pub(super) fn refuse_object_oriented(&self) -> Result<(), Diagnostic> {
        let Tok::Ident(word) = self.peek() else {
            return Ok(());
        };
        // `action S= b;` is a variable set, not a declaration.
        let set = matches!(self.peek_at(1), Tok::Ident(w)
            if w.eq_ignore_ascii_case("S") || w.eq_ignore_ascii_case("R"))
            && matches!(self.peek_at(2), Tok::Eq);
        let named = matches!(self.peek_at(1), Tok::Ident(_)) && !set;
        match OBJECT_ORIENTED
            .iter()
            .find(|w| w.eq_ignore_ascii_case(word))
        {
            Some(w) if named => Err(self.error(format!(
                "`{w}` is not supported: of the object-oriented extensions only METHOD \
                 and ACTION are (PROPERTY, INTERFACE, EXTENDS and IMPLEMENTS are not; write \
                 a property as a method or a variable)"
            ))),
            _ => Ok(()),
        }
    }

    fn item(&mut self) -> Result<Item, Diagnostic> {
        if self.eat_kw("PROGRAM") {
            return self.pou(PouKind::Program, "END_PROGRAM").map(Item::Pou);
        }
        if self.eat_kw("FUNCTION_BLOCK") {
            return self
                .pou(PouKind::FunctionBlock, "END_FUNCTION_BLOCK")
                .map(Item::Pou);
        }
        if self.eat_kw("FUNCTION") {
            return self.pou(PouKind::Function, "END_FUNCTION").map(Item::Pou);
        }
        if self.eat_kw("TYPE") {
            return self.types().map(Item::Types);
        }
        if self.is_kw("VAR_GLOBAL") {
            return self.var_block().map(Item::Globals);
        }
        self.refuse_object_oriented()?;
        Err(self.error(format!(
            "expected PROGRAM, FUNCTION_BLOCK, FUNCTION, TYPE or VAR_GLOBAL, found {}",
            self.found()
        )))
    }

    fn pou(&mut self, kind: PouKind, end: &str) -> Result<Pou, Diagnostic> {
        let name = self.name()?;
        self.refuse_object_oriented()?;
        let returns = match kind {
            PouKind::Function => {
                self.expect(&Tok::Colon, "`:` and the function's return type")?;
                Some(self.type_ref()?)
            }
            _ => None,
        };
        let mut vars = Vec::new();
        while self.is_var_section() {
            vars.push(self.var_block()?);
        }
        let body = self.statements(&[end])?;
        let mut methods = Vec::new();
        while self.method_start() {
            if kind == PouKind::Function {
                let why = "a FUNCTION has no METHOD or ACTION: they belong to a FUNCTION_BLOCK or PROGRAM";
                return Err(self.error(why));
            }
            methods.push(self.method()?);
        }
        self.expect_kw(end)?;
        Ok(Pou {
            kind,
            name,
            returns,
            vars,
            body,
            methods,
        })
    }

    fn is_var_section(&self) -> bool {
        SECTIONS.iter().any(|s| self.is_kw(s))
    }

    fn var_block(&mut self) -> Result<VarBlock, Diagnostic> {
        let pos = self.pos();
        let Tok::Ident(word) = self.bump().kind else {
            return Err(Diagnostic::new(pos, "expected a VAR section"));
        };
        let section = match word.to_ascii_uppercase().as_str() {
            "VAR" => Section::Var,
            "VAR_INPUT" => Section::Input,
            "VAR_OUTPUT" => Section::Output,
            "VAR_IN_OUT" => Section::InOut,
            "VAR_GLOBAL" => Section::Global,
            "VAR_TEMP" => Section::Temp,
            _ => Section::External,
        };
        let (mut constant, mut retain) = (false, false);
        loop {
            if self.eat_kw("CONSTANT") {
                constant = true;
            } else if self.eat_kw("RETAIN") || self.eat_kw("PERSISTENT") {
                retain = true;
            } else {
                break;
            }
        }
        let mut vars = Vec::new();
        while !self.eat_kw("END_VAR") {
            if self.at_eof() {
                return Err(Diagnostic::new(pos, "a VAR section without its END_VAR"));
            }
            vars.push(self.var_decl()?);
        }
        Ok(VarBlock {
            section,
            constant,
            retain,
            vars,
            pos,
        })
    }

    /// A field's name: any word, a reserved one included (the image has a field `program`),
    /// since it only ever follows a `.`.
    fn field_name(&mut self) -> Result<Name, Diagnostic> {
        let pos = self.pos();
        match self.peek().clone() {
            Tok::Ident(text) => {
                self.bump();
                Ok(Name { text, pos })
            }
            _ => Err(self.error(format!("expected a field name, found {}", self.found()))),
        }
    }

    /// `a, b : TYPE := init;` (a location `AT %..` is refused by name); `field` for a
    /// structure's fields, whose names may be reserved words.
    fn var_decl_of(&mut self, field: bool) -> Result<VarDecl, Diagnostic> {
        let name = |p: &mut Self| if field { p.field_name() } else { p.name() };
        let mut names = vec![name(self)?];
        while self.eat(&Tok::Comma) {
            names.push(name(self)?);
        }
        if self.is_kw("AT") {
            return Err(self.error(
                "`AT %..` locations are not supported: the image is reached through gpCh/gpAx",
            ));
        }
        self.expect(&Tok::Colon, "`:` and a type")?;
        let ty = self.type_ref()?;
        let init = if self.eat(&Tok::Assign) {
            Some(self.init()?)
        } else {
            None
        };
        self.expect(&Tok::Semi, "`;`")?;
        Ok(VarDecl { names, ty, init })
    }

    fn var_decl(&mut self) -> Result<VarDecl, Diagnostic> {
        self.var_decl_of(false)
    }

    fn type_ref(&mut self) -> Result<TypeRef, Diagnostic> {
        self.nested(Self::type_ref_inner)
    }

    fn type_ref_inner(&mut self) -> Result<TypeRef, Diagnostic> {
        let pos = self.pos();
        if self.eat_kw("ARRAY") {
            self.expect(&Tok::LBracket, "`[` and the array's bounds")?;
            let mut ranges = Vec::new();
            loop {
                if matches!(self.peek(), Tok::Star) {
                    return Err(self.error(
                        "`ARRAY[*]` (an array of any length) is not supported: declare its \
                         bounds, or pass a POINTER and the count",
                    ));
                }
                let lo = self.expr()?;
                self.expect(&Tok::Range, "`..` between the bounds")?;
                let hi = self.expr()?;
                ranges.push((lo, hi));
                if !self.eat(&Tok::Comma) {
                    break;
                }
            }
            self.expect(&Tok::RBracket, "`]`")?;
            self.expect_kw("OF")?;
            let element = Box::new(self.type_ref()?);
            return Ok(TypeRef::Array {
                ranges,
                element,
                pos,
            });
        }
        if self.eat_kw("POINTER") {
            self.expect_kw("TO")?;
            return Ok(TypeRef::Pointer(Box::new(self.type_ref()?), pos));
        }
        if self.eat_kw("REFERENCE") {
            self.expect_kw("TO")?;
            return Ok(TypeRef::Reference(Box::new(self.type_ref()?), pos));
        }
        let wide = self.is_kw("WSTRING");
        if wide || self.is_kw("STRING") {
            self.bump();
            let len = if self.eat(&Tok::LParen) || self.eat(&Tok::LBracket) {
                let n = self.expr()?;
                if !self.eat(&Tok::RParen) {
                    self.expect(&Tok::RBracket, "`)` after the string's length")?;
                }
                Some(Box::new(n))
            } else {
                None
            };
            return Ok(TypeRef::String { len, wide, pos });
        }
        let name = self.name()?;
        if matches!(self.peek(), Tok::LParen) {
            return Err(self.error(format!(
                "`{}(..)` is not supported: a subrange type (`INT(0..100)`) or FB_init's \
                 values; declare the type itself and check the range where it is written",
                name.text
            )));
        }
        Ok(TypeRef::Named(name))
    }

    /// An initial value: an expression, `[..]` for an array, `(a := .., ..)` for a struct.
    fn init(&mut self) -> Result<Init, Diagnostic> {
        self.nested(Self::init_inner)
    }

    fn init_inner(&mut self) -> Result<Init, Diagnostic> {
        if self.eat(&Tok::LBracket) {
            let mut items = Vec::new();
            loop {
                // `n(value)` repeats value n times.
                let repeat = matches!(self.peek(), Tok::Int(_)) && *self.peek_at(1) == Tok::LParen;
                if repeat {
                    let count = self.expr_primary_literal()?;
                    self.expect(&Tok::LParen, "`(`")?;
                    let value = self.init()?;
                    self.expect(&Tok::RParen, "`)`")?;
                    items.push((Some(count), value));
                } else {
                    items.push((None, self.init()?));
                }
                if !self.eat(&Tok::Comma) {
                    break;
                }
            }
            self.expect(&Tok::RBracket, "`]` after the array's values")?;
            return Ok(Init::Array(items));
        }
        let is_struct = *self.peek() == Tok::LParen
            && matches!(self.peek_at(1), Tok::Ident(_))
            && *self.peek_at(2) == Tok::Assign;
        if is_struct {
            self.bump();
            let mut fields = Vec::new();
            loop {
                let name = self.name()?;
                self.expect(&Tok::Assign, "`:=`")?;
                fields.push((name, self.init()?));
                if !self.eat(&Tok::Comma) {
                    break;
                }
            }
            self.expect(&Tok::RParen, "`)` after the structure's values")?;
            return Ok(Init::Struct(fields));
        }
        Ok(Init::Expr(self.expr()?))
    }

    /// `TYPE name : definition; .. END_TYPE`.
    fn types(&mut self) -> Result<Vec<TypeDecl>, Diagnostic> {
        let mut decls = Vec::new();
        while !self.eat_kw("END_TYPE") {
            if self.at_eof() {
                return Err(self.error("a TYPE block without its END_TYPE"));
            }
            let name = self.name()?;
            self.expect(&Tok::Colon, "`:` and the type's definition")?;
            let def = self.type_def()?;
            // END_STRUCT may be followed by `;`.
            self.eat(&Tok::Semi);
            decls.push(TypeDecl { name, def });
        }
        Ok(decls)
    }

    fn type_def(&mut self) -> Result<TypeDef, Diagnostic> {
        for (open, close) in [("STRUCT", "END_STRUCT"), ("UNION", "END_UNION")] {
            if !self.eat_kw(open) {
                continue;
            }
            let mut fields = Vec::new();
            while !self.eat_kw(close) {
                if self.at_eof() {
                    return Err(self.error(format!("a {open} without its {close}")));
                }
                fields.push(self.var_decl_of(true)?);
            }
            return Ok(if open == "UNION" {
                TypeDef::Union(fields)
            } else {
                TypeDef::Struct(fields)
            });
        }
        if self.eat(&Tok::LParen) {
            let mut values = Vec::new();
            loop {
                let name = self.name()?;
                let value = if self.eat(&Tok::Assign) {
                    Some(self.expr()?)
                } else {
                    None
                };
                values.push((name, value));
                if !self.eat(&Tok::Comma) {
                    break;
                }
            }
            self.expect(&Tok::RParen, "`)` after the enumeration's values")?;
            let base = match self.peek() {
                Tok::Ident(_) => Some(self.type_ref()?),
                _ => None,
            };
            return Ok(TypeDef::Enum { values, base });
        }
        let ty = self.type_ref()?;
        let init = if self.eat(&Tok::Assign) {
            Some(self.init()?)
        } else {
            None
        };
        Ok(TypeDef::Alias(ty, init))
    }
}
