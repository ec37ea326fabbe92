//! A program's variables by name, for the tools (`plc get|set|watch MAIN.fbCam.Busy`): every
//! elementary variable and STRING of the globals and the PROGRAMs, into structures, function
//! block instances (their inputs, outputs and locals; a standard block's inputs and outputs)
//! and arrays (each element, up to [`MAX_LISTED_ELEMENTS`] of an array), with its place in
//! the program's memory.

use super::{write_mem, Fault, Program, V};
use crate::ast::PouKind;
use crate::check::Type;
use crate::types::Elem;

/// The most elements of one array the symbols list.
pub const MAX_LISTED_ELEMENTS: u64 = 256;

/// An elementary variable or a STRING: its path (`MAIN.fbCam.Busy`, `MAIN.a[3]`, `gCount`),
/// its place in the program's memory and its type (an enumeration's base type; a STRING's
/// size in `text`).
#[derive(Debug, Clone, PartialEq)]
pub struct Symbol {
    /// Its path.
    pub path: String,
    /// Its offset in the program's memory.
    pub offset: u32,
    /// Its type (a STRING's: BYTE).
    pub elem: Elem,
    /// A STRING's size with its NUL (`STRING(n)`: n + 1 bytes); `None` for an elementary
    /// variable.
    pub text: Option<u32>,
}

impl Program {
    /// Every elementary variable and STRING by path, at most `limit` of them, in
    /// declaration order.
    pub fn symbols(&self, limit: usize) -> Vec<Symbol> {
        let (c, l) = (&self.code.checked, &self.code.layout);
        let mut out = Vec::new();
        // CONSTANTs are not listed: a tool neither needs to read nor may write them.
        for (g, var) in c.globals.iter().enumerate().filter(|(_, v)| !v.constant) {
            self.list(&var.name, &var.ty, l.globals[g], limit, &mut out);
        }
        for (i, pou) in c.pous.iter().enumerate() {
            if pou.kind == PouKind::Program {
                // Not the room of methods' variables (`M.x`): they live for one call.
                let listed = |v: &&crate::check::Var| !v.constant && !v.name.contains('.');
                for (k, v) in pou.vars.iter().enumerate().filter(|(_, v)| listed(v)) {
                    let path = format!("{}.{}", pou.name, v.name);
                    self.list(&path, &v.ty, l.statics[i] + l.pous[i].2[k], limit, &mut out);
                }
            }
        }
        out
    }

    fn list(&self, path: &str, ty: &Type, at: u32, limit: usize, out: &mut Vec<Symbol>) {
        let (c, l) = (&self.code.checked, &self.code.layout);
        if out.len() >= limit {
            return;
        }
        let leaf = |elem| Symbol {
            path: path.to_string(),
            offset: at,
            elem,
            text: None,
        };
        match ty {
            Type::Elem(e) => out.push(leaf(*e)),
            Type::Str(n) => out.push(Symbol {
                text: Some(n + 1),
                ..leaf(Elem::Byte)
            }),
            Type::Enum(i) => out.push(leaf(c.enums[*i].base)),
            Type::Struct(i) => {
                for (k, (name, t)) in c.structs[*i].fields.iter().enumerate() {
                    let at = at + l.structs[*i].2[k];
                    self.list(&format!("{path}.{name}"), t, at, limit, out);
                }
            }
            Type::Fb(i) => {
                for (k, v) in c.pous[*i]
                    .vars
                    .iter()
                    .enumerate()
                    .filter(|(_, v)| !v.constant && !v.name.contains('.'))
                {
                    let at = at + l.pous[*i].2[k];
                    self.list(&format!("{path}.{}", v.name), &v.ty, at, limit, out);
                }
            }
            Type::Array(dims, element) => {
                let (size, align) = l.size_align(c, element);
                let stride = size.div_ceil(align) * align;
                let lens: Vec<u64> = dims.iter().map(|(lo, hi)| hi.abs_diff(*lo) + 1).collect();
                let total = lens.iter().try_fold(1u64, |n, len| n.checked_mul(*len));
                let n = total.unwrap_or(u64::MAX).min(MAX_LISTED_ELEMENTS);
                // Row-major, the last index fastest: `a[1,1]`, `a[1,2]`, ...
                for k in 0..n as u32 {
                    let (mut rest, mut index) = (u64::from(k), Vec::with_capacity(dims.len()));
                    for (d, len) in dims.iter().zip(&lens).rev() {
                        index.push((d.0 + (rest % len) as i64).to_string());
                        rest /= len;
                    }
                    index.reverse();
                    let at = at + k * stride;
                    let name = format!("{path}[{}]", index.join(","));
                    self.list(&name, element, at, limit, out);
                }
            }
            Type::StdFb(fb) => {
                for &(name, elem, _) in fb.members() {
                    // Every member has its place (`layout::std_fb`); one without is left out.
                    if let Some(offset) = crate::layout::std_member(*fb, name) {
                        let member = format!("{path}.{name}");
                        self.list(&member, &Type::Elem(elem), at + offset, limit, out);
                    }
                }
            }
            // Pointers: not listed.
            _ => {}
        }
    }

    /// The program's memory, as its variables are laid out in it.
    pub fn memory(&self) -> &[u8] {
        &self.state.memory
    }

    /// A tool's write of `value` to the variable at `offset` of type `elem` (a symbol's):
    /// refused if the value is not finite, not whole for an integer, or beyond the type (an
    /// enumeration's base type; TIME and LTIME in ms and ns).
    pub fn write_symbol(&mut self, offset: u32, elem: Elem, value: f64) -> Result<(), Fault> {
        let range = match elem {
            Elem::Time => Some((i128::from(i32::MIN), i128::from(i32::MAX))),
            Elem::LTime => Some((i128::from(i64::MIN), i128::from(i64::MAX))),
            _ => elem.range(),
        };
        // `hi as f64 + 1.0` is exclusive: i64::MAX as f64 is already 2^63.
        let fits = |(lo, hi): (i128, i128)| value >= lo as f64 && value < hi as f64 + 1.0;
        let v = match elem {
            Elem::Real if (value as f32).is_finite() => V::F(value),
            Elem::LReal if value.is_finite() => V::F(value),
            Elem::Real | Elem::LReal => return Err(Fault::OutOfRange),
            _ => match range {
                Some(r) if value.fract() == 0.0 && fits(r) => V::I(value as i128 as i64),
                _ => return Err(Fault::OutOfRange),
            },
        };
        write_mem(&mut self.state.memory, offset as usize, elem, v)
    }
}
