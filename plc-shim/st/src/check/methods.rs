//! METHODs and ACTIONs (TwinCAT 3's, CODESYS 3's) as POUs of their own, run on their
//! function block's instance (their PROGRAM's memory).
//!
//! Before the checker reads the files, each method of a POU `P` becomes a POU `P.M` placed
//! after `P`: `P`'s own variables (the same types in the same order, so at the same
//! offsets; their initial values left to `P`, a CONSTANT's kept), then room for the methods
//! declared before `M`, then `M`'s own variables and its value. `P` itself gets room for
//! every method's variables and value after its own, under names no program can write
//! (`M.x`). So a method's body reads and writes the instance as `P`'s body does, its own
//! variables live in the instance without meeting another method's (a method may call
//! another of the same instance), and a call of `M` is a function call whose frame is the
//! instance: its own variables start from zero and their initial values at every call, as
//! a function's, while `P`'s keep theirs ([`MethodOf`]).
//!
//! An ACTION is a method without variables of its own and without a value.

use crate::ast::{
    Init, Item, Method, Name, Pou, PouKind, Section, TypeRef, Unit, VarBlock, VarDecl,
};
use crate::diag::Pos;

/// What makes a POU a method: found by the checker from its name (upper case, `P.M`).
#[derive(Debug, Clone, PartialEq)]
pub struct MethodOf {
    /// The POU it belongs to (index into [`super::Checked::pous`]).
    pub parent: usize,
    /// Its index among the POU's variables where its own begin (the POU's before).
    pub own_from: usize,
    /// Its name as written (`M_Reset`).
    pub name: String,
    /// PRIVATE or PROTECTED: called only from its POU's body and methods.
    pub private: bool,
    /// An ACTION.
    pub action: bool,
}

/// A method as the desugaring found it: its POU's name, its parent's, and what the checker
/// needs beside the variables.
#[derive(Debug, Clone)]
pub(super) struct Found {
    /// The method's POU name in upper case (`FB_AXIS.M_RESET`).
    pub key: String,
    /// Its parent's name in upper case.
    pub parent: String,
    /// Its name as written.
    pub name: Name,
    /// PRIVATE or PROTECTED.
    pub private: bool,
    /// An ACTION.
    pub action: bool,
    /// How many variables of its own it has (its value's slot of a method without a value
    /// counted).
    pub own: usize,
}

/// The name of a method's value slot when it has no value (no name a program can write).
const NO_VALUE: &str = "()";

/// The base of a call of a method on the current instance (no name a program can write).
pub(super) const THIS: &str = "THIS^";

/// The files with every method as a POU of its own, and the methods found.
pub(super) fn desugar(files: &[(String, Unit)]) -> (Vec<(String, Unit)>, Vec<Found>) {
    let mut found = Vec::new();
    let out = files
        .iter()
        .map(|(file, unit)| {
            let mut items = Vec::with_capacity(unit.items.len());
            for item in &unit.items {
                match item {
                    Item::Pou(p) if !p.methods.is_empty() => {
                        let (parent, methods) = split(p, &mut found);
                        items.push(Item::Pou(parent));
                        items.extend(methods.into_iter().map(Item::Pou));
                    }
                    other => items.push(other.clone()),
                }
            }
            (file.clone(), Unit { items })
        })
        .collect();
    (out, found)
}

/// POU `p` with room for its methods' variables, and each method as a POU.
fn split(p: &Pou, found: &mut Vec<Found>) -> (Pou, Vec<Pou>) {
    // P's own variables as each method sees them: the initial values are P's to set, once.
    let inherited: Vec<VarBlock> = p.vars.iter().map(without_inits).collect();
    let mut room: Vec<VarBlock> = Vec::new();
    let mut methods = Vec::new();
    for m in &p.methods {
        let own = own_vars(m);
        found.push(Found {
            key: format!("{}.{}", p.name.text, m.name.text).to_ascii_uppercase(),
            parent: p.name.text.to_ascii_uppercase(),
            name: m.name.clone(),
            private: m.private,
            action: m.action,
            own: own
                .iter()
                .map(|b| b.vars.iter().map(|d| d.names.len()).sum::<usize>())
                .sum(),
        });
        let mut vars = inherited.clone();
        vars.extend(room.iter().cloned());
        vars.extend(own.iter().cloned());
        methods.push(Pou {
            kind: PouKind::Method,
            name: Name {
                text: format!("{}.{}", p.name.text, m.name.text),
                pos: m.name.pos,
            },
            returns: m.returns.clone(),
            vars,
            body: m.body.clone(),
            methods: Vec::new(),
        });
        room.extend(hidden(m, &own));
    }
    let mut parent = p.clone();
    parent.methods.clear();
    parent.vars.extend(room);
    (parent, methods)
}

/// A method's own variable sections, with the slot of its value when it has none (where a
/// method with a value keeps it: after its own variables).
fn own_vars(m: &Method) -> Vec<VarBlock> {
    let mut own = m.vars.clone();
    if m.returns.is_none() {
        own.push(slot(
            m.name.pos,
            NO_VALUE.to_string(),
            bool_type(m.name.pos),
        ));
    }
    own
}

/// The room method `m` takes in its POU: its own variables (`own`) under names no program
/// writes, plain VAR without initial values, and its value's slot.
fn hidden(m: &Method, own: &[VarBlock]) -> Vec<VarBlock> {
    let rename = |n: &Name| Name {
        text: format!("{}.{}", m.name.text, n.text),
        pos: n.pos,
    };
    let mut room: Vec<VarBlock> = own
        .iter()
        .map(|b| VarBlock {
            section: Section::Var,
            constant: false,
            retain: false,
            vars: (b.vars.iter())
                .map(|d| VarDecl {
                    names: d.names.iter().map(rename).collect(),
                    ty: d.ty.clone(),
                    init: None,
                })
                .collect(),
            pos: b.pos,
        })
        .collect();
    if let Some(ty) = &m.returns {
        room.push(slot(
            m.name.pos,
            format!("{}.{NO_VALUE}", m.name.text),
            ty.clone(),
        ));
    }
    room
}

fn slot(pos: Pos, text: String, ty: TypeRef) -> VarBlock {
    VarBlock {
        section: Section::Var,
        constant: false,
        retain: false,
        vars: vec![VarDecl {
            names: vec![Name { text, pos }],
            ty,
            init: None,
        }],
        pos,
    }
}

fn bool_type(pos: Pos) -> TypeRef {
    TypeRef::Named(Name {
        text: "BOOL".into(),
        pos,
    })
}

/// A section of the POU's as a method sees it: a CONSTANT keeps its values (the method
/// reads them), the others are the POU's to set.
fn without_inits(b: &VarBlock) -> VarBlock {
    let mut b = b.clone();
    if !b.constant {
        for d in &mut b.vars {
            d.init = None::<Init>;
        }
    }
    b
}
