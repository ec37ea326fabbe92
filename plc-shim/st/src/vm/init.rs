//! Every variable's initial value, once at load: the globals' and programs' instances and
//! every function block instance inside them.

use super::{Exec, FaultAt, Run};
use crate::ast::PouKind;
use crate::check::Type;

impl Exec<'_> {
    /// Every variable's initial value: the globals' and programs' instances, and every
    /// function block instance inside them.
    pub(super) fn initialise(&mut self) -> Result<(), FaultAt> {
        let globals: Vec<(u32, Type)> = (0..self.code.checked.globals.len())
            .map(|i| {
                (
                    self.code.layout.globals[i],
                    self.code.checked.globals[i].ty.clone(),
                )
            })
            .collect();
        // The globals' initial values, the instances' own, then the instances'
        // initialisers (as in a POU, `init_pou`).
        let code = self.code;
        let (early, late) = split(&code.global_inits, code.global_late_from);
        self.block(early, 0).map_err(|f| self.fault_at(f))?;
        for (at, ty) in globals {
            self.init_instances(&ty, at).map_err(|f| self.fault_at(f))?;
        }
        self.block(late, 0).map_err(|f| self.fault_at(f))?;
        for pou in 0..self.code.checked.pous.len() {
            if self.code.checked.pous[pou].kind == PouKind::Program {
                let base = self.code.layout.statics[pou];
                self.init_pou(pou, base).map_err(|f| self.fault_at(f))?;
            }
        }
        Ok(())
    }

    /// POU `pou`'s initial values at `base`, then those of the instances among its
    /// variables, then the instances' initialisers (`fbDelay : TON := (PT := T#2S)`): they
    /// win over the blocks' declared initial values. A function's frame at each call too
    /// (nothing allocated: the types are read where they are).
    pub(super) fn init_pou(&mut self, pou: usize, base: u32) -> Run<()> {
        let code = self.code;
        let late_from = code.late_inits.get(pou).copied().unwrap_or(usize::MAX);
        let (early, late) = split(&code.bodies[pou].0, late_from);
        self.block(early, base)?;
        // A method's instances are its POU's, set when the POU's instance was.
        let from = (code.checked.pous[pou].method.as_ref()).map_or(0, |m| m.own_from);
        for (var, offset) in (code.checked.pous[pou].vars.iter())
            .zip(&code.layout.pous[pou].2)
            .skip(from)
        {
            self.init_instances(&var.ty, base + offset)?;
        }
        self.block(late, base)?;
        Ok(())
    }

    fn init_instances(&mut self, ty: &'_ Type, at: u32) -> Run<()> {
        let code = self.code;
        match ty {
            Type::Fb(i) => self.init_pou(*i, at),
            Type::Struct(i) => {
                let fields = code.checked.structs[*i].fields.iter();
                for ((_, field), offset) in fields.zip(&code.layout.structs[*i].2) {
                    self.init_instances(field, at + offset)?;
                }
                Ok(())
            }
            Type::Array(dims, element)
                if matches!(**element, Type::Fb(_) | Type::Struct(_) | Type::Array(..)) =>
            {
                let (size, align) = code.layout.size_align(&code.checked, element);
                let stride = size.div_ceil(align) * align;
                let count: i64 = dims.iter().map(|(lo, hi)| hi - lo + 1).product();
                for k in 0..count as u32 {
                    self.init_instances(element, at + k * stride)?;
                }
                Ok(())
            }
            _ => Ok(()),
        }
    }
}

/// `inits` before and from `at` (all before when `at` lies beyond them).
fn split(inits: &[crate::ir::St], at: usize) -> (&[crate::ir::St], &[crate::ir::St]) {
    inits.split_at(at.min(inits.len()))
}
