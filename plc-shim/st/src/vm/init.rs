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
        // The instances' own initial values first, as in a POU (`init_pou`).
        for (at, ty) in globals {
            self.init_instances(&ty, at).map_err(|f| self.fault_at(f))?;
        }
        let code = self.code;
        self.block(&code.global_inits, 0)
            .map_err(|f| self.fault_at(f))?;
        for pou in 0..self.code.checked.pous.len() {
            if self.code.checked.pous[pou].kind == PouKind::Program {
                let base = self.code.layout.statics[pou];
                self.init_pou(pou, base).map_err(|f| self.fault_at(f))?;
            }
        }
        Ok(())
    }

    /// The initial values of the instances among POU `pou`'s variables at `base`, then the
    /// POU's own: an instance's initialiser (`fbDelay : TON := (PT := T#2S)`) is among the
    /// latter and wins over the block's declared initial values.
    fn init_pou(&mut self, pou: usize, base: u32) -> Run<()> {
        for k in 0..self.code.checked.pous[pou].vars.len() {
            let ty = self.code.checked.pous[pou].vars[k].ty.clone();
            let offset = self.code.layout.pous[pou].2[k];
            self.init_instances(&ty, base + offset)?;
        }
        let code = self.code;
        self.block(&code.bodies[pou].0, base)?;
        Ok(())
    }

    fn init_instances(&mut self, ty: &Type, at: u32) -> Run<()> {
        match ty {
            Type::Fb(i) => self.init_pou(*i, at),
            Type::Struct(i) => {
                for k in 0..self.code.checked.structs[*i].fields.len() {
                    let field = self.code.checked.structs[*i].fields[k].1.clone();
                    let offset = self.code.layout.structs[*i].2[k];
                    self.init_instances(&field, at + offset)?;
                }
                Ok(())
            }
            Type::Array(dims, element)
                if matches!(**element, Type::Fb(_) | Type::Struct(_) | Type::Array(..)) =>
            {
                let (size, align) = self.code.layout.size_align(&self.code.checked, element);
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
