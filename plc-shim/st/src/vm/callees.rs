//! Which POUs a body calls (block bodies and functions), for the register file's size: the
//! deepest chain of calls ([`super::code::Codes`]).

use crate::ir::{Addr, BlockInput, BlockOutput, Ex, FnCall, St, StKind, Text, TextEx, TextFn};

/// Every POU a statement calls (block bodies and functions), in the statements it holds too.
pub(super) fn of_st(s: &St, out: &mut Vec<usize>) {
    own_parts(s, out);
    if let StKind::CallFb { pou, .. } = &s.kind {
        out.push(*pou);
    }
    let mut inner = |body: &[St]| body.iter().for_each(|s| of_st(s, out));
    match &s.kind {
        StKind::If(arms, otherwise) => {
            arms.iter().for_each(|(_, body)| inner(body));
            inner(otherwise);
        }
        StKind::Case(_, arms, otherwise) => {
            arms.iter().for_each(|(_, body)| inner(body));
            inner(otherwise);
        }
        StKind::For { body, .. } | StKind::While(_, body) | StKind::Repeat(body, _) => inner(body),
        _ => {}
    }
}

/// Whether a statement's own expressions and places (not the statements it holds) call a
/// user function (the only thing in an expression that may write memory).
pub(crate) fn calls_in(s: &St) -> bool {
    let mut out = Vec::new();
    own_parts(s, &mut out);
    !out.is_empty()
}

/// The functions a statement's own expressions and places call (not a block it calls, nor
/// the statements it holds).
fn own_parts(s: &St, out: &mut Vec<usize>) {
    match &s.kind {
        StKind::Store(a, _, e) | StKind::StorePtr(a, e) => {
            of_addr(a, out);
            of_ex(e, out);
        }
        StKind::Copy(a, b, _) => {
            of_addr(a, out);
            of_addr(b, out);
        }
        StKind::Bytes(a, _) => of_addr(a, out),
        StKind::Text(a, _, t) => {
            of_addr(a, out);
            of_text(t, out);
        }
        StKind::If(arms, _) => arms.iter().for_each(|(c, _)| of_ex(c, out)),
        StKind::Case(sel, ..) | StKind::Eval(sel) => of_ex(sel, out),
        StKind::For {
            var, from, to, by, ..
        } => {
            of_addr(var, out);
            [from, to, by].into_iter().for_each(|e| of_ex(e, out));
        }
        StKind::While(c, _) | StKind::Repeat(_, c) => of_ex(c, out),
        StKind::CallFb {
            instance,
            inputs,
            outputs,
            ..
        }
        | StKind::CallStdFb {
            instance,
            inputs,
            outputs,
            ..
        } => of_call(instance, inputs, outputs, out),
        StKind::Exit | StKind::Continue | StKind::Return => {}
    }
}

fn of_call(a: &Addr, inputs: &[BlockInput], outputs: &[BlockOutput], out: &mut Vec<usize>) {
    of_addr(a, out);
    inputs.iter().for_each(|(_, _, e)| of_ex(e, out));
    outputs.iter().for_each(|(_, _, a, _, _)| of_addr(a, out));
}

/// Whether finding place `a` calls a user function (an index computed by one).
pub(crate) fn addr_calls(a: &Addr) -> bool {
    let mut out = Vec::new();
    of_addr(a, &mut out);
    !out.is_empty()
}

fn of_addr(a: &Addr, out: &mut Vec<usize>) {
    match a {
        Addr::Offset(inner, _) => of_addr(inner, out),
        Addr::Index { base, index, .. } => {
            of_addr(base, out);
            of_ex(index, out);
        }
        Addr::Deref(e) => of_ex(e, out),
        Addr::Static(_) | Addr::Instance(_) | Addr::Via { .. } => {}
    }
}

fn of_ex(e: &Ex, out: &mut Vec<usize>) {
    match e {
        Ex::Load(a, _) | Ex::LoadPtr(a) | Ex::AddrOf(a) => of_addr(a, out),
        Ex::Neg(x, _) | Ex::Not(x, _) | Ex::Conv(_, _, x) => of_ex(x, out),
        Ex::Bin(_, _, a, b) => {
            of_ex(a, out);
            of_ex(b, out);
        }
        Ex::TextEq(pair) => {
            of_text(&pair.0, out);
            of_text(&pair.1, out);
        }
        Ex::Text(e) => match &**e {
            TextEx::Cmp(_, a, b) | TextEx::Find(a, b) => {
                of_text(a, out);
                of_text(b, out);
            }
            TextEx::Len(a) | TextEx::To(_, a) => of_text(a, out),
        },
        Ex::Std(_, _, args) => args.iter().for_each(|a| of_ex(a, out)),
        Ex::Call(c, _) => of_fn_call(c, out),
        Ex::Int(_) | Ex::Real(_) | Ex::Var { .. } => {}
    }
}

/// A user function's call: the function, and what its values call.
fn of_fn_call(c: &FnCall, out: &mut Vec<usize>) {
    out.push(c.pou);
    c.inputs.iter().for_each(|(_, _, e)| of_ex(e, out));
    c.texts.iter().for_each(|(_, _, _, t)| of_text(t, out));
    of_addr(&c.value, out);
    c.back.iter().for_each(|(_, _, a)| of_addr(a, out));
    c.outputs.iter().for_each(|(_, _, a, _, _)| of_addr(a, out));
    if let Some(this) = &c.this {
        of_addr(&this.instance, out);
    }
}

fn of_text(t: &Text, out: &mut Vec<usize>) {
    match t {
        Text::Const(_) => {}
        Text::At(a, _) => of_addr(a, out),
        Text::Fn(f) => match &**f {
            TextFn::Concat(parts) => parts.iter().for_each(|p| of_text(p, out)),
            TextFn::Of(_, e) => of_ex(e, out),
            TextFn::Call(c, _) => of_fn_call(c, out),
            TextFn::Left(a, n) | TextFn::Right(a, n) => {
                of_text(a, out);
                of_ex(n, out);
            }
            TextFn::Mid(a, n, p) | TextFn::Delete(a, n, p) => {
                of_text(a, out);
                of_ex(n, out);
                of_ex(p, out);
            }
            TextFn::Insert(a, b, p) => {
                of_text(a, out);
                of_text(b, out);
                of_ex(p, out);
            }
            TextFn::Replace(a, b, n, p) => {
                of_text(a, out);
                of_text(b, out);
                of_ex(n, out);
                of_ex(p, out);
            }
        },
    }
}
