//! Canonical source text of a tree: what [`super::parse`] reads back into an equal tree.

use super::ast::*;
use std::fmt::Write as _;

/// The program as canonical NC source.
pub fn print(program: &Program) -> String {
    let mut out = String::new();
    for (b, block) in program.blocks.iter().enumerate() {
        let b = arena_index(b);
        for sub in program.subs.iter().filter(|s| s.blocks.start == b) {
            let _ = writeln!(out, "%L {}", sub.name);
        }
        if b == program.main_start {
            if let Some(name) = &program.name {
                let _ = writeln!(out, "%{name}");
            }
        }
        let mut parts: Vec<String> = Vec::new();
        if let Some(n) = block.number {
            parts.push(format!("N{n}"));
        }
        parts.extend(program.items_of(block).iter().map(item));
        let _ = writeln!(out, "{}", parts.join(" "));
    }
    // Headers after the last block: empty subroutines, or a main program without blocks.
    let end = arena_index(program.blocks.len());
    for sub in program.subs.iter().filter(|s| s.blocks.start == end) {
        let _ = writeln!(out, "%L {}", sub.name);
    }
    if program.main_start == end {
        if let Some(name) = &program.name {
            let _ = writeln!(out, "%{name}");
        }
    }
    out
}

fn num(v: f64) -> String {
    format!("{v}")
}

/// An expression; the printed form parses back to the same tree (square brackets group
/// where the precedence rules alone would read it otherwise).
pub fn expr(e: &Expr) -> String {
    fn go(e: &Expr, out: &mut String) {
        match e {
            Expr::Num(v) if *v < 0.0 => {
                out.push('-');
                out.push_str(&num(-v));
            }
            Expr::Num(v) => out.push_str(&num(*v)),
            Expr::Var(name) => out.push_str(name),
            Expr::Param(n) => {
                let _ = write!(out, "P{n}");
            }
            Expr::Neg(inner) => {
                out.push('-');
                operand(inner, out, u8::MAX);
            }
            Expr::Call(call) => {
                let (func, args) = &**call;
                let _ = write!(out, "{}[", func.name());
                for (i, a) in args.iter().enumerate() {
                    if i > 0 {
                        out.push_str(", ");
                    }
                    go(a, out);
                }
                out.push(']');
            }
            Expr::Bin(bin) => {
                let (op, a, b) = &**bin;
                let prec = op.precedence();
                // Left-associative operators need brackets around a right operand of the same
                // strength, the power (right-associative) around a left one.
                let (left_min, right_min) = if *op == BinOp::Pow {
                    (prec + 1, prec)
                } else {
                    (prec, prec + 1)
                };
                operand(a, out, left_min);
                let _ = write!(out, " {} ", op.symbol());
                operand(b, out, right_min);
            }
        }
    }
    /// `e` as an operand that binds at least `min` strongly; bracketed when it does not.
    fn operand(e: &Expr, out: &mut String, min: u8) {
        let weaker = match e {
            Expr::Bin(bin) => bin.0.precedence() < min,
            // `-2` read back is a negation: bracket it where a negation would not be read.
            Expr::Num(v) if *v < 0.0 => min == u8::MAX,
            Expr::Neg(_) => min == u8::MAX,
            _ => false,
        };
        if weaker {
            out.push('[');
            go(e, out);
            out.push(']');
        } else {
            go(e, out);
        }
    }
    let mut out = String::new();
    go(e, &mut out);
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
        // The bare dwell time after G04.
        Item::Axis(a) if a.name.as_bytes().is_empty() => expr(&a.value),
        Item::Axis(a) => axis_word(a, false),
        Item::IndependentAxis { axis, .. } => format!("{}{}", axis.name, list(&axis.options)),
        Item::Control { control, .. } => match control.as_ref() {
            Control::While(c) => format!("$WHILE {}", expr(c)),
            Control::EndWhile => "$ENDWHILE".into(),
            Control::If(c)
            | Control::ElseIf(c)
            | Control::EndDo(c)
            | Control::Switch(c)
            | Control::Case(c) => {
                format!("${} {}", control.keyword(), expr(c))
            }
            Control::For {
                var,
                start,
                end,
                step,
            } => format!(
                "$FOR {var} = {}, {}, {}",
                expr(start),
                expr(end),
                expr(step)
            ),
            Control::Goto(n) => format!("$GOTO N{n}"),
            other => format!("${}", other.keyword()),
        },
        Item::Assign { assign, .. } => format!("{} = {}", assign.target, expr(&assign.value)),
        Item::Call { call, .. } => {
            format!("{} {}", if call.local { "LL" } else { "L" }, call.name)
        }
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
            Command::Msg { text } => format!("#MSG [\"{text}\"]"),
            Command::Time { seconds } => format!("#TIME {}", expr(seconds)),
            Command::Contour { options } => format!("#CONTOUR MODE {}", list(options)),
            Command::Var => "#VAR".into(),
            Command::EndVar => "#ENDVAR".into(),
        },
    }
}
