//! The checker: every name resolved and every expression typed, over all files of a program
//! at once. It reports every refusal it finds (not only the first), each with its file, line
//! and column; a program with none is [`Checked`], the input of the compiler.
//!
//! Here: the declarations (types, POUs, global variables) and the resolution of types;
//! [`expr`] types the expressions, [`stmt`] checks the statements and calls.

use crate::ast::{Item, Name, Pou, PouKind, Section, TypeDef, TypeRef, Unit, VarDecl};
use crate::diag::{Diagnostic, Pos};
use crate::types::Elem;
use std::collections::HashMap;

mod consts;
mod expr;
mod function;
mod init;
mod lower;
mod method_calls;
mod methods;
pub use methods::MethodOf;
mod place;
pub(crate) mod reference;
pub mod std_lib;
mod std_type;
mod std_value;
mod stmt;
mod text;
mod to_type;

/// A type of the language.
#[derive(Debug, Clone, PartialEq)]
pub enum Type {
    /// An elementary type.
    Elem(Elem),
    /// STRING(n) (WSTRING is refused for now).
    Str(u32),
    /// An array: its dimensions' bounds and its element.
    Array(Vec<(i64, i64)>, Box<Type>),
    /// A declared structure (index into [`Checked::structs`]).
    Struct(usize),
    /// A declared enumeration (index into [`Checked::enums`]).
    Enum(usize),
    /// A pointer to a value of the type.
    Pointer(Box<Type>),
    /// An instance of a function block (index into [`Checked::pous`]).
    Fb(usize),
    /// An instance of a standard function block (TON, R_TRIG, ...).
    StdFb(std_lib::StdFb),
    /// Something already refused: no second refusal for it.
    Error,
}

/// A structure: its fields in order.
#[derive(Debug, Clone, PartialEq)]
pub struct StructDef {
    /// Its name.
    pub name: String,
    /// Name and type of each field.
    pub fields: Vec<(String, Type)>,
    /// A UNION: every field at offset 0, sharing the bytes.
    pub union: bool,
}

/// An enumeration: its values and base type.
#[derive(Debug, Clone, PartialEq)]
pub struct EnumDef {
    /// Its name.
    pub name: String,
    /// Name and number of each value.
    pub values: Vec<(String, i128)>,
    /// The integer type it is stored as.
    pub base: Elem,
}

/// A variable of a POU or the global list.
#[derive(Debug, Clone, PartialEq)]
pub struct Var {
    /// Its name.
    pub name: String,
    /// Its type.
    pub ty: Type,
    /// Its section.
    pub section: Section,
    /// Declared CONSTANT.
    pub constant: bool,
    /// Where it is declared.
    pub pos: Pos,
    /// A REFERENCE TO (its type the pointer it is underneath: `check::reference`).
    pub reference: bool,
}

/// A program, function block or function with its variables resolved.
#[derive(Debug, Clone, PartialEq)]
pub struct PouDef {
    /// Its name.
    pub name: String,
    /// Its kind.
    pub kind: PouKind,
    /// A function's return type.
    pub returns: Option<Type>,
    /// Every variable, inputs, outputs and in-outs in declaration order among them.
    pub vars: Vec<Var>,
    /// The file it is in (index into the files given).
    pub file: usize,
    /// A METHOD's or ACTION's POU and place among its variables.
    pub method: Option<methods::MethodOf>,
}

/// A checked program: the tables the compiler reads.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Checked {
    /// Declared structures.
    pub structs: Vec<StructDef>,
    /// Declared enumerations.
    pub enums: Vec<EnumDef>,
    /// Programs, function blocks and functions.
    pub pous: Vec<PouDef>,
    /// Global variables.
    pub globals: Vec<Var>,
}

/// What a type name stands for.
#[derive(Debug, Clone, PartialEq)]
enum Named {
    Struct(usize),
    Enum(usize),
    Alias(TypeRef, usize),
    Pou(usize),
}

/// Checks `files` (name and tree) as one program: the tables, or every refusal.
pub fn check(files: &[(String, Unit)]) -> Result<Checked, Vec<Diagnostic>> {
    checker(files).map(|(c, _)| c.out)
}

/// Files by name, parsed.
type Files = Vec<(String, Unit)>;

/// The checker of `files`, and the files as it read them (`TO_<type>` calls named).
fn checker(files: &[(String, Unit)]) -> Result<(Checker, Files), Vec<Diagnostic>> {
    // Methods and actions as POUs of their own, run on their POU's memory.
    let (files, found) = methods::desugar(files);
    let files = &files[..];
    let mut c = Checker {
        consts: consts::Consts::of(files),
        ..Checker::default()
    };
    c.collect(files);
    c.resolve_types(files);
    c.resolve_vars(files);
    c.bind_methods(&found, files);
    c.check_externals(files);
    let files = c.name_conversions(files);
    c.check_bodies(&files);
    if c.errors.is_empty() {
        Ok((c, files))
    } else {
        c.errors
            .sort_by(|a, b| (&a.file, a.pos).cmp(&(&b.file, b.pos)));
        // A POU's variable refused once, not again in each of its methods.
        c.errors.dedup();
        Err(c.errors)
    }
}

/// A program checked and lowered: what the runtime runs.
#[derive(Debug, Clone, PartialEq)]
pub struct Compiled {
    /// The tables.
    pub checked: Checked,
    /// Where everything lives.
    pub layout: crate::layout::Layout,
    /// Per POU: the stores of its variables' initial values, and its statements.
    pub bodies: Vec<(Vec<crate::ir::St>, Vec<crate::ir::St>)>,
    /// Per POU: where among its initial values those of its variables holding function
    /// block instances begin (`fbDelay : TON := (PT := T#2S)`): they run after the
    /// instances' own initial values, the others before (`vm::init`).
    pub late_inits: Vec<usize>,
    /// The global variables' initial values, run once before the programs'.
    pub global_inits: Vec<crate::ir::St>,
    /// Where among them those of the globals holding instances begin (as `late_inits`).
    pub global_late_from: usize,
    /// The files, by the index statements carry.
    pub files: Vec<String>,
    /// Every initialiser of a function block instance (`fbDelay : TON := (PT := T#2S)` is
    /// none: a standard block): the block's POU, and the file and place it is written at.
    pub fb_inits: Vec<(usize, String, Pos)>,
}

/// Checks and lowers `files`: the program, or every refusal.
pub fn compile(files: &[(String, Unit)]) -> Result<Compiled, Vec<Diagnostic>> {
    let (mut c, named) = checker(files)?;
    let files = &named[..];
    let layout = crate::layout::Layout::of(&c.out).map_err(|e| {
        let file = files.first().map_or("", |(f, _)| f.as_str());
        vec![Diagnostic::new(Pos { line: 1, col: 1 }, e).in_file(file)]
    })?;
    let mut bodies = vec![(Vec::new(), Vec::new()); c.out.pous.len()];
    let mut late_inits = vec![0; c.out.pous.len()];
    let (mut errors, mut global_inits, mut global_late) = (Vec::new(), Vec::new(), Vec::new());
    for (f, (file, unit)) in files.iter().enumerate() {
        c.file = file.clone();
        match c.lower_global_inits(unit, f as u16, &layout) {
            Ok((inits, late)) => {
                global_inits.extend(inits);
                global_late.extend(late);
            }
            Err(e) => errors.push(e),
        }
        for item in &unit.items {
            let Item::Pou(p) = item else { continue };
            // Its own constants first (an initialiser's repetition count).
            c.consts.scope = Some(p.name.text.to_ascii_uppercase());
            let lowered = c.lower_pou(p, f as u16, &layout);
            c.consts.scope = None;
            match lowered {
                Ok((i, (inits, late), body)) => {
                    bodies[i] = (inits, body);
                    late_inits[i] = late;
                }
                Err(e) => errors.push(e),
            }
        }
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    let global_late_from = global_inits.len();
    global_inits.extend(global_late);
    Ok(Compiled {
        checked: c.out,
        layout,
        bodies,
        late_inits,
        global_inits,
        global_late_from,
        files: files.iter().map(|(f, _)| f.clone()).collect(),
        fb_inits: c.fb_inits,
    })
}

#[derive(Default)]
struct Checker {
    out: Checked,
    /// Type names (upper case) to what they are.
    names: HashMap<String, Named>,
    /// Global variable names (upper case) to their index.
    globals: HashMap<String, usize>,
    errors: Vec<Diagnostic>,
    /// The file being checked.
    file: String,
    /// The POU whose body is being checked.
    calls_from: usize,
    /// Calls seen so far: (caller, callee) POU indices.
    call_graph: Vec<(usize, usize)>,
    /// The named integer constants (array bounds, STRING lengths).
    consts: consts::Consts,
    /// Initialisers of function block instances: the block's POU, the file and place.
    fb_inits: Vec<(usize, String, Pos)>,
}

impl Checker {
    fn refuse(&mut self, pos: Pos, message: impl Into<String>) {
        self.errors
            .push(Diagnostic::new(pos, message).in_file(&self.file));
    }

    /// Every type, POU and global name, and refusals of names declared twice.
    fn collect(&mut self, files: &[(String, Unit)]) {
        for (f, (file, unit)) in files.iter().enumerate() {
            self.file = file.clone();
            for item in &unit.items {
                match item {
                    Item::Types(decls) => {
                        for d in decls {
                            let named = match &d.def {
                                TypeDef::Struct(_) | TypeDef::Union(_) => {
                                    self.out.structs.push(StructDef {
                                        name: d.name.text.clone(),
                                        fields: Vec::new(),
                                        union: matches!(d.def, TypeDef::Union(_)),
                                    });
                                    Named::Struct(self.out.structs.len() - 1)
                                }
                                TypeDef::Enum { .. } => {
                                    self.out.enums.push(EnumDef {
                                        name: d.name.text.clone(),
                                        values: Vec::new(),
                                        base: Elem::Int,
                                    });
                                    Named::Enum(self.out.enums.len() - 1)
                                }
                                TypeDef::Alias(ty, _) => Named::Alias(ty.clone(), f),
                            };
                            self.declare_type(&d.name, named);
                        }
                    }
                    Item::Pou(p) => self.collect_pou(p, f),
                    Item::Globals(_) => {}
                }
            }
        }
    }

    fn collect_pou(&mut self, p: &Pou, file: usize) {
        self.out.pous.push(PouDef {
            name: p.name.text.clone(),
            kind: p.kind,
            returns: None,
            vars: Vec::new(),
            file,
            method: None,
        });
        let index = self.out.pous.len() - 1;
        self.declare_type(&p.name, Named::Pou(index));
    }

    fn declare_type(&mut self, name: &Name, named: Named) {
        let key = name.text.to_ascii_uppercase();
        if Elem::named(&key).is_some() || std_lib::is_reserved_name(&key) {
            self.refuse(name.pos, format!("`{}` is a standard name", name.text));
        } else if self.names.insert(key, named).is_some() {
            self.refuse(name.pos, format!("`{}` is declared twice", name.text));
        }
    }

    /// Enum values, then struct fields (whose array bounds may name an enumeration's value
    /// declared anywhere), each in declaration order.
    fn resolve_types(&mut self, files: &[(String, Unit)]) {
        for enums in [true, false] {
            for (file, unit) in files {
                self.file = file.clone();
                for item in &unit.items {
                    let Item::Types(decls) = item else { continue };
                    for d in decls {
                        let key = d.name.text.to_ascii_uppercase();
                        match (&d.def, self.names.get(&key).cloned(), enums) {
                            (
                                TypeDef::Struct(fields) | TypeDef::Union(fields),
                                Some(Named::Struct(i)),
                                false,
                            ) => {
                                let fields = self.fields(fields);
                                self.out.structs[i].fields = fields;
                                if self.out.structs[i].union {
                                    self.union_fields(i, &d.name);
                                }
                            }
                            (TypeDef::Enum { values, base }, Some(Named::Enum(i)), true) => {
                                self.enum_values(i, values, base.as_ref());
                            }
                            _ => {}
                        }
                    }
                }
            }
        }
    }

    /// A UNION's fields share their bytes: a function block instance among them (whose
    /// state is its block's) is refused.
    fn union_fields(&mut self, i: usize, name: &Name) {
        let instance = |t: &Type| match t {
            Type::Fb(_) | Type::StdFb(_) => true,
            Type::Array(_, e) => matches!(**e, Type::Fb(_) | Type::StdFb(_)),
            _ => false,
        };
        if self.out.structs[i].fields.iter().any(|(_, t)| instance(t)) {
            let why = format!(
                "UNION {}: a function block instance shares no bytes",
                name.text
            );
            self.refuse(name.pos, why);
        }
    }

    fn fields(&mut self, decls: &[VarDecl]) -> Vec<(String, Type)> {
        let mut fields: Vec<(String, Type)> = Vec::new();
        for d in decls {
            let ty = self.type_of(&d.ty, 0);
            for n in &d.names {
                if fields.iter().any(|(f, _)| f.eq_ignore_ascii_case(&n.text)) {
                    self.refuse(n.pos, format!("field `{}` is declared twice", n.text));
                }
                fields.push((n.text.clone(), ty.clone()));
            }
        }
        fields
    }

    fn enum_values(
        &mut self,
        index: usize,
        values: &[(Name, Option<crate::ast::Expr>)],
        base: Option<&TypeRef>,
    ) {
        let base = match base.map(|b| self.type_of(b, 0)) {
            None => Elem::Int,
            Some(Type::Elem(e)) if e.is_integer() => e,
            Some(Type::Error) => Elem::Int,
            Some(_) => {
                let pos = values.first().map_or(Pos::default(), |v| v.0.pos);
                self.refuse(pos, "an enumeration's base type is an integer type");
                Elem::Int
            }
        };
        let mut next = 0i128;
        // Each value stored as it is found (a later one may name an earlier one).
        self.out.enums[index].values.clear();
        for (name, value) in values {
            if let Some(v) = value {
                next = self.const_int(v).unwrap_or(next);
            }
            let out = &self.out.enums[index].values;
            if out.iter().any(|(n, _)| n.eq_ignore_ascii_case(&name.text)) {
                self.refuse(name.pos, format!("value `{}` is declared twice", name.text));
            }
            if base
                .range()
                .is_some_and(|(lo, hi)| !(lo..=hi).contains(&next))
            {
                self.refuse(name.pos, format!("{next} does not fit {}", base.name()));
            }
            let out = &mut self.out.enums[index].values;
            out.push((name.text.clone(), next));
            next = next.saturating_add(1);
        }
        self.out.enums[index].base = base;
    }

    /// The type a declaration writes; `depth` bounds aliases of aliases.
    fn type_of(&mut self, ty: &TypeRef, depth: usize) -> Type {
        match ty {
            TypeRef::Named(n) => self.named_type(n, depth),
            TypeRef::Pointer(t, _) => Type::Pointer(Box::new(self.type_of(t, depth))),
            TypeRef::Reference(_, pos) => {
                // A variable's own type only (`decl_type`): one inside another type would be
                // read without `^` in places the rewrite does not see.
                self.refuse(
                    *pos,
                    "REFERENCE TO inside a type (an array's element, a structure's field, a \
                     pointer's target) is not supported: use POINTER TO with ADR() and `^`",
                );
                Type::Error
            }
            TypeRef::String { len, wide, pos } => {
                if *wide {
                    self.refuse(*pos, "WSTRING is not supported: use STRING");
                    return Type::Error;
                }
                let n = match len {
                    None => 80,
                    Some(e) => match self.const_int(e) {
                        Some(n) if (1..=255).contains(&n) => n as u32,
                        Some(n) => {
                            self.refuse(*pos, format!("STRING({n}): 1 to 255 characters"));
                            return Type::Error;
                        }
                        None => return Type::Error,
                    },
                };
                Type::Str(n)
            }
            TypeRef::Array {
                ranges,
                element,
                pos,
            } => self.array_type(ranges, element, *pos, depth),
        }
    }

    fn array_type(
        &mut self,
        ranges: &[(crate::ast::Expr, crate::ast::Expr)],
        element: &TypeRef,
        pos: Pos,
        depth: usize,
    ) -> Type {
        let mut dims = Vec::new();
        let mut elements = 1i128;
        for (lo, hi) in ranges {
            let (Some(lo), Some(hi)) = (self.const_int(lo), self.const_int(hi)) else {
                return Type::Error;
            };
            if lo.abs() > MAX_BOUND || hi.abs() > MAX_BOUND {
                self.refuse(
                    pos,
                    format!("ARRAY[{lo}..{hi}]: bounds within +-{MAX_BOUND}"),
                );
                return Type::Error;
            }
            if hi < lo {
                self.refuse(
                    pos,
                    format!("ARRAY[{lo}..{hi}]: the upper bound lies below the lower"),
                );
                return Type::Error;
            }
            elements = elements.saturating_mul(hi - lo + 1);
            dims.push((lo as i64, hi as i64));
        }
        if elements > MAX_ARRAY_ELEMENTS {
            self.refuse(
                pos,
                format!("an array of {elements} elements: at most {MAX_ARRAY_ELEMENTS}"),
            );
            return Type::Error;
        }
        let element = self.type_of(element, depth);
        Type::Array(dims, Box::new(element))
    }

    /// What SIZEOF measures: a variable's (or any expression's) type, or a type named
    /// (`SIZEOF(INT)`, `SIZEOF(ST_Cmd)`) where no variable of that name is in reach.
    fn sizeof_type(&mut self, e: &crate::ast::Expr, ctx: expr::Ctx) -> Type {
        if let crate::ast::Expr::Name(n) = e {
            let key = n.text.to_ascii_uppercase();
            let a_type = Elem::named(&key).is_some()
                || std_lib::StdFb::named(&key).is_some()
                || self.names.contains_key(&key);
            let no_variable = matches!(
                self.meaning(&n.text, ctx),
                None | Some(expr::Meaning::EnumType(_))
            );
            if a_type && no_variable {
                return self.named_type(n, 0);
            }
        }
        self.expr(e, ctx)
    }

    /// Whether a variable of type `ty` holds function block instances (an instance, an
    /// array or structure of them): its initialiser runs after their own initial values.
    fn holds_instances(&self, ty: &Type) -> bool {
        match ty {
            Type::Fb(_) | Type::StdFb(_) => true,
            Type::Array(_, element) => self.holds_instances(element),
            Type::Struct(i) => {
                (self.out.structs[*i].fields.iter()).any(|(_, t)| self.holds_instances(t))
            }
            _ => false,
        }
    }

    fn named_type(&mut self, n: &Name, depth: usize) -> Type {
        let key = n.text.to_ascii_uppercase();
        if let Some(e) = Elem::named(&key) {
            return Type::Elem(e);
        }
        if let Some(fb) = std_lib::StdFb::named(&key) {
            return Type::StdFb(fb);
        }
        match self.names.get(&key).cloned() {
            Some(Named::Struct(i)) => Type::Struct(i),
            Some(Named::Enum(i)) => Type::Enum(i),
            Some(Named::Pou(i)) if self.out.pous[i].kind == PouKind::FunctionBlock => Type::Fb(i),
            Some(Named::Pou(_)) => {
                self.refuse(
                    n.pos,
                    format!("`{}` is no type: only a FUNCTION_BLOCK can be", n.text),
                );
                Type::Error
            }
            Some(Named::Alias(ty, _)) if depth < 16 => self.type_of(&ty, depth + 1),
            Some(Named::Alias(..)) => {
                self.refuse(n.pos, format!("type `{}` is defined by itself", n.text));
                Type::Error
            }
            None if crate::types::is_date_type(&key) => {
                self.refuse(
                    n.pos,
                    format!("{} (`{}`)", crate::types::DATES_REFUSED, n.text),
                );
                Type::Error
            }
            None => {
                self.refuse(n.pos, format!("unknown type `{}`", n.text));
                Type::Error
            }
        }
    }

    /// Every POU's variables and return type, and the global list.
    fn resolve_vars(&mut self, files: &[(String, Unit)]) {
        for (file, unit) in files {
            self.file = file.clone();
            for item in &unit.items {
                match item {
                    Item::Globals(block) => {
                        for d in &block.vars {
                            let (ty, reference) =
                                self.decl_type(d, (block.section, block.constant));
                            for n in &d.names {
                                self.declare_global(n, ty.clone(), (block.constant, reference));
                            }
                        }
                    }
                    Item::Pou(p) => self.pou_vars(p),
                    Item::Types(_) => {}
                }
            }
        }
    }

    /// Every VAR_EXTERNAL names a global of its type (the POU's variable of that name
    /// stands for the global: `Checker::meaning`).
    fn check_externals(&mut self, files: &[(String, Unit)]) {
        for p in 0..self.out.pous.len() {
            // A method's are its POU's, checked there.
            if self.out.pous[p].method.is_some() {
                continue;
            }
            for k in 0..self.out.pous[p].vars.len() {
                let v = &self.out.pous[p].vars[k];
                if v.section != Section::External {
                    continue;
                }
                let global = self.globals.get(&v.name.to_ascii_uppercase()).copied();
                let why = match global.map(|g| &self.out.globals[g]) {
                    None => format!("VAR_EXTERNAL `{}`: no global variable of that name", v.name),
                    Some(g) if g.ty != v.ty || g.reference != v.reference => {
                        let (want, got) = (self.type_name(&g.ty), self.type_name(&v.ty));
                        format!("VAR_EXTERNAL `{}` is {got}: the global is {want}", v.name)
                    }
                    Some(_) => continue,
                };
                let pos = v.pos;
                self.file = files
                    .get(self.out.pous[p].file)
                    .map_or_else(String::new, |(n, _)| n.clone());
                self.refuse(pos, why);
            }
        }
    }

    fn declare_global(&mut self, n: &Name, ty: Type, (constant, reference): (bool, bool)) {
        let key = n.text.to_ascii_uppercase();
        if self.globals.contains_key(&key) {
            self.refuse(n.pos, format!("global `{}` is declared twice", n.text));
            return;
        }
        self.out.globals.push(Var {
            name: n.text.clone(),
            ty,
            section: Section::Global,
            constant,
            pos: n.pos,
            reference,
        });
        self.globals.insert(key, self.out.globals.len() - 1);
    }

    fn pou_vars(&mut self, p: &Pou) {
        let Some(Named::Pou(index)) = self.names.get(&p.name.text.to_ascii_uppercase()).cloned()
        else {
            return;
        };
        // Its own constants first in its array bounds and STRING lengths.
        self.consts.scope = Some(p.name.text.to_ascii_uppercase());
        self.pou_vars_in_scope(p, index);
        self.consts.scope = None;
    }

    fn pou_vars_in_scope(&mut self, p: &Pou, index: usize) {
        let returns = p.returns.as_ref().map(|r| self.type_of(r, 0));
        let mut vars: Vec<Var> = Vec::new();
        for block in &p.vars {
            if block.section == Section::Global {
                self.refuse(
                    block.pos,
                    "VAR_GLOBAL inside a POU: declare it in a global list",
                );
                continue;
            }
            for d in &block.vars {
                let (ty, reference) = self.decl_type(d, (block.section, block.constant));
                for n in &d.names {
                    if vars.iter().any(|v| v.name.eq_ignore_ascii_case(&n.text)) {
                        self.refuse(n.pos, format!("`{}` is declared twice", n.text));
                    }
                    vars.push(Var {
                        name: n.text.clone(),
                        ty: ty.clone(),
                        section: block.section,
                        constant: block.constant,
                        pos: n.pos,
                        reference,
                    });
                }
            }
        }
        self.out.pous[index].returns = returns;
        self.out.pous[index].vars = vars;
    }

    /// The value of a constant integer expression (literals, named integer constants and
    /// `+ - * / MOD` of them), or a refusal.
    fn const_int(&mut self, e: &crate::ast::Expr) -> Option<i128> {
        use crate::ast::{BinOp, Expr, UnOp};
        let value = match e {
            Expr::Int(v, _) => Some(*v),
            // An enumeration's value: `E_Axis.X`, `E_Axis#X`.
            Expr::Field(ty, v) => match &**ty {
                Expr::Name(ty) if self.enum_index(ty).is_some() => return self.enum_const(ty, v),
                _ => None,
            },
            Expr::Typed { ty, value } if Elem::named(&ty.text.to_ascii_uppercase()).is_none() => {
                return match &**value {
                    Expr::Name(v) => self.enum_const(ty, v),
                    _ => {
                        let why = format!("`{}#..`: an enumeration's value is named", ty.text);
                        self.refuse(ty.pos, why);
                        None
                    }
                };
            }
            Expr::Typed { value, .. } => return self.const_int(value),
            Expr::Name(n) => return self.named_const(n),
            Expr::Unary(UnOp::Neg, inner, _) => self.const_int(inner)?.checked_neg(),
            Expr::Binary(op, l, r, pos) => {
                let (a, b) = (self.const_int(l)?, self.const_int(r)?);
                let v = match op {
                    BinOp::Add => a.checked_add(b),
                    BinOp::Sub => a.checked_sub(b),
                    BinOp::Mul => a.checked_mul(b),
                    BinOp::Div | BinOp::Mod if b == 0 => {
                        self.refuse(*pos, "a constant divided by zero");
                        return None;
                    }
                    BinOp::Div => a.checked_div(b),
                    BinOp::Mod => a.checked_rem(b),
                    _ => None,
                };
                if v.is_none() {
                    self.refuse(*pos, "not an integer constant");
                }
                return v;
            }
            _ => None,
        };
        if value.is_none() {
            self.refuse(
                e.pos(),
                "an integer constant is wanted here (literals, named integer constants, \
                 enumeration values and their arithmetic)",
            );
        }
        value
    }

    fn check_bodies(&mut self, files: &[(String, Unit)]) {
        for (file, unit) in files {
            self.file = file.clone();
            for item in &unit.items {
                match item {
                    Item::Pou(p) => self.check_pou(p),
                    Item::Globals(block) => self.check_global_inits(block),
                    Item::Types(_) => {}
                }
            }
        }
    }

    /// The global variables' initial values against their types.
    fn check_global_inits(&mut self, block: &crate::ast::VarBlock) {
        for d in &block.vars {
            let Some(init) = &d.init else {
                continue;
            };
            for n in &d.names {
                let key = n.text.to_ascii_uppercase();
                if let Some(ty) = self
                    .globals
                    .get(&key)
                    .map(|i| self.out.globals[*i].ty.clone())
                {
                    self.check_init(init, &ty, n.pos, expr::GLOBAL);
                }
            }
        }
    }
}

/// The most elements an array may have (a program's memory is sized at load).
pub const MAX_ARRAY_ELEMENTS: i128 = 1 << 20;

/// The largest array bound (either sign): far beyond any program's, small enough that no
/// index arithmetic overflows.
pub const MAX_BOUND: i128 = 1 << 40;
