//! A user function's call as a value: its inputs stored into its frame, its VAR_IN_OUTs
//! copied in before the call and back after it leaf by leaf (as a function block's), its
//! value read from the frame.

use super::expr::Ctx;
use super::lower::R;
use super::place::plus;
use super::{Checker, Type};
use crate::ast::{Arg, Expr, Section};
use crate::diag::Pos;
use crate::ir::{Addr, BlockOutput, Ex, FnCall};
use crate::layout::Layout;
use crate::types::Elem;

impl Checker {
    /// A VAR_IN_OUT of type `ty` given `value`: each leaf's offset in the parameter, type
    /// and place in the caller's variable (copied in before the call and back after it);
    /// a variable at an index a function computes, or of more than 64 leaves, is refused.
    pub(super) fn in_out_leaves(
        &mut self,
        value: &Expr,
        ty: &Type,
        ctx: Ctx,
        l: &Layout,
    ) -> R<Vec<(u32, Elem, Addr)>> {
        self.leaves_of(value, ty, "VAR_IN_OUT", ctx, l)
    }

    /// As [`Checker::in_out_leaves`] for a parameter of the role named (a VAR_IN_OUT, or a
    /// structure's or array's input, passed by value).
    fn leaves_of(
        &mut self,
        value: &Expr,
        ty: &Type,
        role: &str,
        ctx: Ctx,
        l: &Layout,
    ) -> R<Vec<(u32, Elem, Addr)>> {
        let (from, _) = self.place(value, ctx, l)?;
        if crate::vm::callees::addr_calls(&from) {
            let what = format!("a {role}'s variable at an index a function computes");
            return Err(self.unsupported(value.pos(), &what));
        }
        let leaves = match ty {
            Type::Elem(t) => vec![(0, *t)],
            _ => self.leaves(ty, l).ok_or_else(|| {
                let what = format!("a {role} of more than 64 values or of this type");
                self.unsupported(value.pos(), &what)
            })?,
        };
        Ok(leaves
            .into_iter()
            .map(|(at, t)| (at, t, plus(from.clone(), at)))
            .collect())
    }

    /// Function `i`'s parameters in their order, its inputs and VAR_IN_OUTs: their
    /// variables' indices.
    pub(super) fn parameters(&self, i: usize) -> Vec<usize> {
        let vars = &self.out.pous[i].vars;
        // A method's own: its POU's inputs are the instance's.
        (self.own_from(i)..vars.len())
            .filter(|k| matches!(vars[*k].section, Section::Input | Section::InOut))
            .collect()
    }

    /// The parameter (its place among `params`) that `arg`, the call's `k`th argument,
    /// gives: by position, or by name.
    pub(super) fn parameter_of(
        &self,
        i: usize,
        params: &[usize],
        arg: &Arg,
        k: usize,
    ) -> Option<usize> {
        let vars = &self.out.pous[i].vars;
        match arg {
            Arg::Positional(_) => (k < params.len()).then_some(k),
            Arg::Input(n, _) => params
                .iter()
                .position(|x| vars[*x].name.eq_ignore_ascii_case(&n.text)),
            Arg::Output { .. } => None,
        }
    }

    /// A call of function `i` whose value is elementary, as a value.
    pub(super) fn function_value(
        &mut self,
        i: usize,
        args: &[Arg],
        pos: Pos,
        ctx: Ctx,
        l: &Layout,
    ) -> R<Ex> {
        let Some(Type::Elem(ty)) = self.out.pous[i].returns.clone() else {
            return Err(self.unsupported(pos, "a function whose value is no elementary value"));
        };
        Ok(Ex::Call(
            Box::new(self.function_call_ir(i, args, pos, ctx, l)?),
            ty,
        ))
    }

    /// A call of function `i`: its values, in their order, into its frame.
    pub(super) fn function_call_ir(
        &mut self,
        i: usize,
        args: &[Arg],
        pos: Pos,
        ctx: Ctx,
        l: &Layout,
    ) -> R<FnCall> {
        let params = self.parameters(i);
        let (mut stores, mut texts, mut back) = (Vec::new(), Vec::new(), Vec::new());
        let mut outputs = Vec::new();
        for (k, arg) in args.iter().enumerate() {
            let value = match arg {
                Arg::Positional(v) | Arg::Input(_, v) => v,
                Arg::Output {
                    name,
                    target,
                    negated,
                } => {
                    outputs.push(self.function_output(i, (name, target, *negated), ctx, l)?);
                    continue;
                }
            };
            let Some(var) = self.parameter_of(i, &params, arg, k).map(|p| params[p]) else {
                return Err(self.unsupported(value.pos(), "this argument"));
            };
            let (ty, offset) = (self.out.pous[i].vars[var].ty.clone(), l.pous[i].2[var]);
            if self.out.pous[i].vars[var].section == Section::InOut {
                for (at, t, leaf) in self.in_out_leaves(value, &ty, ctx, l)? {
                    stores.push((offset + at, t, Ex::Load(Box::new(leaf.clone()), t)));
                    back.push((offset + at, t, leaf));
                }
                continue;
            }
            match ty {
                Type::Elem(t) => stores.push((offset, t, self.value_as(value, t, ctx, l)?)),
                Type::Str(n) => {
                    let text = self.text_for(n, value, ctx, l)?;
                    texts.push((stores.len(), offset, n + 1, text));
                }
                // A structure or an array is passed by value, leaf by leaf, as a block's.
                Type::Struct(_) | Type::Array(..) => {
                    for (at, t, leaf) in self.leaves_of(value, &ty, "input", ctx, l)? {
                        stores.push((offset + at, t, Ex::Load(Box::new(leaf), t)));
                    }
                }
                _ => {
                    let what = "an input that is no elementary value, STRING, structure or array";
                    return Err(self.unsupported(value.pos(), what));
                }
            }
        }
        if stores.len() > crate::ir::MAX_CALL_INPUTS {
            return Err(self.unsupported(pos, "a call with more than 32 values"));
        }
        if texts.len() > crate::ir::MAX_TEXT_INPUTS {
            return Err(self.unsupported(pos, "a call with more than 4 STRING values"));
        }
        Ok(FnCall {
            pou: i,
            inputs: stores,
            texts,
            value: Addr::Static(l.statics[i] + *l.pous[i].2.last().unwrap_or(&0)),
            back,
            outputs,
            this: None,
        })
    }

    /// The VAR_OUTPUT `name` of function `i`: its variable's index.
    pub(super) fn output_var(&self, i: usize, name: &str) -> Option<usize> {
        let from = self.own_from(i);
        (self.out.pous[i].vars.iter().skip(from))
            .position(|v| v.name.eq_ignore_ascii_case(name) && v.section == Section::Output)
            .map(|k| k + from)
    }

    /// Where a method's own variables begin among its POU's (0 for other POUs).
    pub(super) fn own_from(&self, i: usize) -> usize {
        self.out.pous[i].method.as_ref().map_or(0, |m| m.own_from)
    }

    /// Output `name => target` of function `i` (checked: an elementary output into a place
    /// it widens to).
    fn function_output(
        &mut self,
        i: usize,
        (name, target, negated): (&crate::ast::Name, &Expr, bool),
        ctx: Ctx,
        l: &Layout,
    ) -> R<BlockOutput> {
        let (Some(var), Type::Elem(to_ty)) =
            (self.output_var(i, &name.text), self.expr(target, ctx))
        else {
            return Err(self.unsupported(name.pos, "this output"));
        };
        let Type::Elem(ty) = self.out.pous[i].vars[var].ty else {
            return Err(self.unsupported(name.pos, "this output"));
        };
        let (to, _) = self.place(target, ctx, l)?;
        if crate::vm::callees::addr_calls(&to) {
            return Err(self.unsupported(
                target.pos(),
                "an output's variable at an index a function computes",
            ));
        }
        Ok((l.pous[i].2[var], ty, to, negated, to_ty))
    }
}
