//! Named integer constants where the layout needs a number before anything runs: array
//! bounds and STRING lengths (`ARRAY[0..MAX_AXES - 1] OF AXIS_REF`, `STRING(MSG_LEN)`), as
//! TwinCAT and CODESYS take them. Such a name is a VAR_GLOBAL CONSTANT, or a VAR CONSTANT of
//! the POU being declared (found first), of an integer type, whose initial value is itself
//! such a constant: literals, their arithmetic, other named constants. A constant whose value
//! leads back to itself is refused, as is any other name.

use super::Checker;
use crate::ast::{Expr, Init, Item, Name, Section, TypeRef, Unit};
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
    /// Per POU (upper-case name): its own variables, `Some` for a VAR CONSTANT (a variable
    /// of another section hides a global constant of its name).
    locals: HashMap<String, HashMap<String, Option<Def>>>,
    /// The POU whose declarations are being resolved.
    pub(super) scope: Option<String>,
    /// The constants being evaluated, innermost last (`POU.NAME` for a POU's own).
    evaluating: Vec<String>,
}

impl Consts {
    /// The constants `files` declare: the global lists' VAR_GLOBAL CONSTANT and each POU's
    /// VAR CONSTANT (its VAR_EXTERNAL names the global one).
    pub(super) fn of(files: &[(String, Unit)]) -> Consts {
        let mut c = Consts::default();
        for (file, unit) in files {
            for item in &unit.items {
                let (blocks, pou) = match item {
                    Item::Globals(block) => (std::slice::from_ref(block), None),
                    Item::Pou(p) => (p.vars.as_slice(), Some(p.name.text.to_ascii_uppercase())),
                    Item::Types(_) => continue,
                };
                for block in blocks.iter().filter(|b| b.section != Section::External) {
                    let constant =
                        block.constant && matches!(block.section, Section::Var | Section::Global);
                    for d in &block.vars {
                        let def = constant.then(|| Def {
                            value: match &d.init {
                                Some(Init::Expr(e)) => Some(e.clone()),
                                _ => None,
                            },
                            ty: d.ty.clone(),
                            file: file.clone(),
                            local: pou.is_some(),
                        });
                        for n in &d.names {
                            let key = n.text.to_ascii_uppercase();
                            // A name declared twice is refused where it is declared.
                            match (&pou, &def) {
                                (Some(p), _) => {
                                    let own = c.locals.entry(p.clone()).or_default();
                                    own.entry(key).or_insert_with(|| def.clone());
                                }
                                (None, Some(def)) => {
                                    c.globals.entry(key).or_insert_with(|| def.clone());
                                }
                                (None, None) => {}
                            }
                        }
                    }
                }
            }
        }
        c
    }

    /// Constant `key` in the scope, and the name a chain of them knows it by; `None` for a
    /// variable of the POU's or an unknown name.
    fn find(&self, key: &str) -> Option<(Def, String)> {
        if let Some(p) = &self.scope {
            if let Some(own) = self.locals.get(p).and_then(|vars| vars.get(key)) {
                return own.clone().map(|d| (d, format!("{p}.{key}")));
            }
        }
        self.globals.get(key).map(|d| (d.clone(), key.to_string()))
    }
}

impl Checker {
    /// The value of named constant `n` in an array bound or a STRING length, or a refusal.
    pub(super) fn named_const(&mut self, n: &Name) -> Option<i128> {
        let Some((def, key)) = self.consts.find(&n.text.to_ascii_uppercase()) else {
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

    /// Value `v` of enumeration `ty` in an array bound (`E_Axis.X`, `E_Axis#X`); refused for
    /// no enumeration of that name, no such value, or one declared after its use.
    pub(super) fn enum_const(&mut self, ty: &Name, v: &Name) -> Option<i128> {
        let Some(i) = self.enum_index(ty) else {
            return self.refuse_const(ty.pos, format!("`{}` is no enumeration", ty.text));
        };
        match self.enum_number(i, &v.text) {
            Some(x) => Some(x),
            None if self.out.enums[i].values.is_empty() => {
                let why = format!("enumeration `{}` is declared after its use here", ty.text);
                self.refuse_const(ty.pos, why)
            }
            None => {
                let why = format!("enumeration `{}` has no value `{}` here", ty.text, v.text);
                self.refuse_const(v.pos, why)
            }
        }
    }

    /// The enumeration `ty` names.
    pub(super) fn enum_index(&self, ty: &Name) -> Option<usize> {
        match self.names.get(&ty.text.to_ascii_uppercase()) {
            Some(super::Named::Enum(i)) => Some(*i),
            _ => None,
        }
    }

    /// The number of value `name` of enumeration `i`, if it has that value (so far).
    pub(super) fn enum_number(&self, i: usize, name: &str) -> Option<i128> {
        let values = &self.out.enums[i].values;
        let found = values.iter().find(|(v, _)| v.eq_ignore_ascii_case(name));
        found.map(|(_, x)| *x)
    }

    /// The number of `e` when it is an enumeration's value (`E_Axis.X`, `E_Axis#X`).
    pub(super) fn enum_literal(&self, e: &Expr) -> Option<i128> {
        let (ty, v) = match e {
            Expr::Field(ty, v) => match &**ty {
                Expr::Name(ty) => (ty, v),
                _ => return None,
            },
            Expr::Typed { ty, value } => match &**value {
                Expr::Name(v) => (ty, v),
                _ => return None,
            },
            _ => return None,
        };
        self.enum_number(self.enum_index(ty)?, &v.text)
    }

    fn refuse_const(&mut self, pos: Pos, why: String) -> Option<i128> {
        self.refuse(pos, why);
        None
    }
}
