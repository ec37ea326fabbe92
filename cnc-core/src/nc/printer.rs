//! Canonical source text of a tree: what [`super::parse`] reads back into an equal tree.

use super::ast::*;
use std::fmt::Write as _;

/// The program as canonical NC source.
pub fn print(program: &Program) -> String {
    let mut out = String::new();
    if let Some(name) = &program.name {
        let _ = writeln!(out, "%{name}");
    }
    for block in &program.blocks {
        let mut parts: Vec<String> = Vec::new();
        if let Some(n) = block.number {
            parts.push(format!("N{n}"));
        }
        parts.extend(program.items_of(block).iter().map(item));
        let _ = writeln!(out, "{}", parts.join(" "));
    }
    out
}

fn num(v: f64) -> String {
    format!("{v}")
}

/// An expression; the printed form parses back to the same tree.
pub fn expr(e: &Expr) -> String {
    fn go(e: &Expr, out: &mut String, parent_prec: u8, right: bool) {
        match e {
            Expr::Num(v) if *v < 0.0 => {
                out.push('-');
                out.push_str(&num(-v));
            }
            Expr::Num(v) => out.push_str(&num(*v)),
            Expr::Var(name) => out.push_str(name),
            Expr::Neg(inner) => {
                out.push('-');
                go(inner, out, 4, false);
            }
            Expr::Bin(bin) => {
                let (op, a, b) = &**bin;
                let prec = op.precedence();
                // Without grouping brackets in the language, only trees the precedence rules
                // produce are printable exactly; others print in that shape.
                let _ = (parent_prec, right);
                go(a, out, prec, false);
                let _ = write!(out, " {} ", op.symbol());
                go(b, out, prec + 1, true);
            }
        }
    }
    let mut out = String::new();
    go(e, &mut out, 0, false);
    out
}

fn entry(e: &Entry) -> String {
    let mut s = String::new();
    if let Some(k) = &e.key {
        s.push_str(k);
    }
    if let Some(g) = e.glued {
        s.push_str(&num(g));
    }
    if let Some(t) = &e.text {
        let _ = write!(s, "=\"{t}\"");
    } else if let Some(v) = &e.value {
        if e.key.is_some() {
            s.push('=');
        }
        s.push_str(&expr(v));
    }
    s
}

fn list(entries: &[Entry]) -> String {
    let items: Vec<String> = entries.iter().map(entry).collect();
    format!("[{}]", items.join(" "))
}

fn on_off(on: bool) -> &'static str {
    if on {
        "ON"
    } else {
        "OFF"
    }
}

/// `X10` for a number, `X=expr` otherwise; always `=` after a name that ends in a digit
/// (`X1=5`, not `X15`) and where `assigned` asks for it (`#PSET`).
fn axis_word(a: &AxisWord, assigned: bool) -> String {
    let digit_last = a.name.as_bytes().last().is_some_and(u8::is_ascii_digit);
    match &a.value {
        Expr::Num(v) if !assigned && !digit_last => format!("{}{}", a.name, num(*v)),
        v => format!("{}={}", a.name, expr(v)),
    }
}

fn item(i: &Item) -> String {
    match i {
        Item::G { code, .. } => format!("G{code}"),
        Item::M { code, .. } => format!("M{code}"),
        Item::Feed {
            value: Expr::Num(v),
            ..
        } if *v >= 0.0 => format!("F{}", num(*v)),
        Item::Feed { value, .. } => format!("F={}", expr(value)),
        Item::Axis(a) => axis_word(a, false),
        Item::IndependentAxis { axis, .. } => format!("{}{}", axis.name, list(&axis.options)),
        Item::Control { control, .. } => match control.as_ref() {
            Control::While(c) => format!("$WHILE {}", expr(c)),
            Control::EndWhile => "$ENDWHILE".into(),
            Control::If(c) => format!("$IF {}", expr(c)),
            Control::Else => "$ELSE".into(),
            Control::EndIf => "$ENDIF".into(),
        },
        Item::Command { command, .. } => match command.as_ref() {
            Command::TrackCs { on, options } if options.is_empty() => {
                format!("#TRACK CS {}", on_off(*on))
            }
            Command::TrackCs { on, options } => {
                format!("#TRACK CS {} {}", on_off(*on), list(options))
            }
            Command::TrackCsAbs => "#TRACK CS ABS".into(),
            Command::ChannelInterface { on, kind } => match kind {
                Some(k) => format!("#CHANNEL INTERFACE {} [{k}]", on_off(*on)),
                None => format!("#CHANNEL INTERFACE {}", on_off(*on)),
            },
            Command::Cs { on, name, values } => {
                let mut s = format!("#CS {}", on_off(*on));
                if let Some(n) = name {
                    let _ = write!(s, " [{n}]");
                }
                if !values.is_empty() {
                    let v: Vec<String> = values.iter().map(expr).collect();
                    let _ = write!(s, " [{}]", v.join(", "));
                }
                s
            }
            Command::Trafo { on, id } => {
                let mut s = "#TRAFO".to_string();
                if let Some(on) = on {
                    let _ = write!(s, " {}", on_off(*on));
                }
                if let Some(id) = id {
                    let _ = write!(s, " [{}]", expr(id));
                }
                s
            }
            Command::KinId { id } => format!("#KIN ID [{}]", expr(id)),
            Command::SignalSyn { options } => format!("#SIGNAL SYN {}", list(options)),
            Command::WaitSyn { options } => format!("#WAIT SYN {}", list(options)),
            Command::WaitIndpAll => "#WAIT INDP ALL".into(),
            Command::Flush { wait } => {
                format!("#FLUSH {}", if *wait { "WAIT" } else { "CONTINUE" })
            }
            Command::Pset { axes } => {
                let a: Vec<String> = axes.iter().map(|a| axis_word(a, true)).collect();
                format!("#PSET {}", a.join(" "))
            }
            Command::Preset { axes } if axes.is_empty() => "#PRESET".into(),
            Command::Preset { axes } => {
                let names: Vec<&str> = axes.iter().map(|a| a.as_str()).collect();
                format!("#PRESET {}", names.join(" "))
            }
        },
    }
}
