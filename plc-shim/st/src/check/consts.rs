//! Named integer constants where the layout needs a number before anything runs: array
//! bounds and STRING lengths (`ARRAY[0..MAX_AXES - 1] OF AXIS_REF`, `STRING(MSG_LEN)`), as
//! TwinCAT and CODESYS take them. Such a name is a VAR_GLOBAL CONSTANT, or a VAR CONSTANT of
//! the POU being declared (found first), of an integer type, whose initial value is itself
//! such a constant: literals, their arithmetic, other named constants. A constant whose value
//! leads back to itself is refused, as is any other name.

use super::Checker;
use crate::ast::{Expr, Init, Item, Name, TypeRef, Unit};
use crate::diag::Pos;
use crate::types::Elem;
use std::collections::HashMap;

/// A named constant's declaration.
#[derive(Debug, Clone)]
struct Def {
    value: Option<Expr>,
    ty: TypeRef,
    file: String,
    /// A POU's own (its value's names are that POU's first).
    local: bool,
}

/// Every named constant of the program, by upper-case name.
#[derive(Debug, Default)]
pub(super) struct Consts {
    globals: HashMap<String, Def>,
    /// Per POU (upper-case name): its own.
    locals: HashMap<String, HashMap<String, Def>>,
    /// The POU whose declarations are being resolved.
    pub(super) scope: Option<String>,
    /// The constants being evaluated, innermost last.
    evaluating: Vec<String>,
}

impl Consts {
    /// The constants `files` declare.
    pub(super) fn of(files: &[(String, Unit)]) -> Consts {
        let mut c = Consts::default();
        for (file, unit) in files {
            for item in &unit.items {
                let (blocks, pou) = match item {
                    Item::Globals(block) => (std::slice::from_ref(block), None),
                    Item::Pou(p) => (p.vars.as_slice(), Some(p.name.text.to_ascii_uppercase())),
                    Item::Types(_) => continue,
                };
                for block in blocks.iter().filter(|b| b.constant) {
                    for d in &block.vars {
                        for n in &d.names {
                            let def = Def {
                                value: match &d.init {
                                    Some(Init::Expr(e)) => Some(e.clone()),
                                    _ => None,
                                },
                                ty: d.ty.clone(),
                                file: file.clone(),
                                local: pou.is_some(),
                            };
                            let key = n.text.to_ascii_uppercase();
                            let table = match &pou {
                                Some(p) => c.locals.entry(p.clone()).or_default(),
                                None => &mut c.globals,
                            };
                            // A name declared twice is refused where it is declared.
                            table.entry(key).or_insert(def);
                        }
                    }
                }
            }
        }
        c
    }

    fn find(&self, key: &str) -> Option<Def> {
        let local = self
            .scope
            .as_ref()
            .and_then(|p| self.locals.get(p)?.get(key));
        local.or_else(|| self.globals.get(key)).cloned()
    }
}

impl Checker {
    /// The value of named constant `n` in an array bound or a STRING length, or a refusal.
    pub(super) fn named_const(&mut self, n: &Name) -> Option<i128> {
        let key = n.text.to_ascii_uppercase();
        let Some(def) = self.consts.find(&key) else {
            return self.refuse_const(
                n.pos,
                format!(
                    "`{}` is no named integer constant (a VAR_GLOBAL CONSTANT or the POU's own \
                     VAR CONSTANT)",
                    n.text
                ),
            );
        };
        let integer = match &def.ty {
            TypeRef::Named(t) => Elem::named(&t.text.to_ascii_uppercase()),
            _ => None,
        };
        if !integer.is_some_and(Elem::is_integer) {
            return self.refuse_const(
                n.pos,
                format!("constant `{}` is of no integer type", n.text),
            );
        }
        let Some(value) = def.value else {
            let why = format!("constant `{}` has no initial value", n.text);
            return self.refuse_const(n.pos, why);
        };
        if self.consts.evaluating.contains(&key) {
            let why = format!("constant `{}` is defined by itself", n.text);
            return self.refuse_const(n.pos, why);
        }
        // Its value is read where it is declared: that file, that scope.
        self.consts.evaluating.push(key);
        let file = std::mem::replace(&mut self.file, def.file);
        let scope = if def.local {
            self.consts.scope.clone()
        } else {
            self.consts.scope.take()
        };
        let v = self.const_int(&value);
        self.consts.scope = scope;
        self.file = file;
        self.consts.evaluating.pop();
        v
    }

    fn refuse_const(&mut self, pos: Pos, why: String) -> Option<i128> {
        self.refuse(pos, why);
        None
    }
}
