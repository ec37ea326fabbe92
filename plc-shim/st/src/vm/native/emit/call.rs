//! A whole block call ([`super::Op::Call`]): its statement's place and step, its inputs
//! stored into the instance as instructions, and its body run by the `call` callback (the
//! block's host, or the POU's body), as [`super::super::super::Exec::call`] does.

use super::super::super::fast::Input;
use super::Emit;
use cranelift_codegen::ir::InstBuilder;

impl Emit<'_, '_> {
    /// [`super::Op::Call`] `k`, on at operation `next`.
    pub(super) fn block_call(&mut self, k: u32, next: u64) -> bool {
        let codes = self.codes;
        let Some(c) = codes.call_ops.get(k as usize) else {
            return false;
        };
        let Some(inputs) = codes.inputs.get(c.inputs.0 as usize..c.inputs.1 as usize) else {
            return false;
        };
        self.set_site(c.site);
        self.step();
        let at = self.own(c.at, c.relative);
        for &(offset, input) in inputs {
            let to = self.b.ins().iadd_imm_s(at, i64::from(offset));
            match input {
                Input::Const(bytes) => self.set(to, bytes),
                Input::Value(t, s) => {
                    let v = self.src(s);
                    self.write(to, t, v);
                }
            }
        }
        self.call_back(self.call, k);
        self.goto(next);
        true
    }
}
