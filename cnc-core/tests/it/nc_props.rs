//! Property tests of the NC front end: generated valid programs survive print-and-reparse
//! unchanged; arbitrary input never panics the parser or the decoder.
//!
//! This file is also the fuzz driver: the toolchain here is stable, which cargo-fuzz refuses
//! (it needs nightly sanitizer flags), so the byte-level and mutation-level fuzzing runs as
//! proptest strategies. `PROPTEST_CASES=100000 cargo test -p cnc-core --test nc_props` runs a
//! longer campaign.

use cnc_core::nc::ast::*;
use cnc_core::nc::check::check_source;
use cnc_core::nc::{parse, parse_general, print};
use proptest::prelude::*;

fn span() -> Span {
    Span::default()
}

fn number() -> impl Strategy<Value = f64> {
    prop_oneof![
        (0u32..100_000).prop_map(f64::from),
        (0u32..10_000_000).prop_map(|v| f64::from(v) / 1000.0)
    ]
}

fn variable() -> impl Strategy<Value = Name> {
    prop_oneof![
        prop::sample::select(vec!["X", "Y", "Z", "A", "B", "C"])
            .prop_map(|a| Name::from(format!("V.G.TRACK_CS.{a}").as_str())),
        prop::sample::select(vec!["V.P.DEPTH", "V.L.I", "V.P.A_1", "V.L.STEP2"])
            .prop_map(Name::from),
    ]
}

fn atom() -> impl Strategy<Value = Expr> {
    prop_oneof![
        number().prop_map(Expr::Num),
        variable().prop_map(|v| Expr::Var(Box::new(v))),
        (1u32..1000).prop_map(Expr::Param),
    ]
}

fn any_op() -> impl Strategy<Value = BinOp> {
    prop::sample::select(vec![
        BinOp::Add,
        BinOp::Sub,
        BinOp::Mul,
        BinOp::Div,
        BinOp::Eq,
        BinOp::Ne,
        BinOp::Lt,
        BinOp::Le,
        BinOp::Gt,
        BinOp::Ge,
        BinOp::Mod,
        BinOp::Pow,
        BinOp::And,
        BinOp::Or,
        BinOp::Xor,
    ])
}

/// Expressions of any shape (the printer brackets what precedence alone would read otherwise),
/// with functions.
fn any_expr() -> impl Strategy<Value = Expr> {
    atom().prop_recursive(4, 24, 3, |inner| {
        prop_oneof![
            inner.clone().prop_map(|e| Expr::Neg(Box::new(e))),
            (any_op(), inner.clone(), inner.clone())
                .prop_map(|(op, a, b)| Expr::Bin(Box::new((op, a, b)))),
            (
                prop::sample::select(Func::ALL.to_vec()),
                inner.clone(),
                inner
            )
                .prop_map(|((f, _, n), a, b)| Expr::Call(Box::new((
                    f,
                    if n == 2 { vec![a, b] } else { vec![a] }
                )))),
        ]
    })
}

fn target() -> impl Strategy<Value = Target> {
    prop_oneof![
        (1u32..1000).prop_map(Target::Param),
        prop::sample::select(vec!["V.P.DEPTH", "V.L.I"]).prop_map(|n| Target::Var(Name::from(n))),
    ]
}

fn control() -> impl Strategy<Value = Control> {
    prop_oneof![
        any_expr().prop_map(Control::While),
        Just(Control::EndWhile),
        any_expr().prop_map(Control::If),
        any_expr().prop_map(Control::ElseIf),
        Just(Control::Else),
        Just(Control::EndIf),
        (target(), any_expr(), any_expr(), any_expr()).prop_map(|(var, start, end, step)| {
            Control::For {
                var,
                start,
                end,
                step,
            }
        }),
        Just(Control::EndFor),
        Just(Control::Do),
        any_expr().prop_map(Control::EndDo),
        any_expr().prop_map(Control::Switch),
        any_expr().prop_map(Control::Case),
        Just(Control::Default),
        Just(Control::EndSwitch),
        Just(Control::Break),
        Just(Control::Continue),
        (0u32..100_000).prop_map(Control::Goto),
    ]
}

/// Blocks of the language core besides motion: assignments, calls, `$` statements, dwell,
/// messages and declarations.
fn core_block() -> impl Strategy<Value = Vec<Item>> {
    prop_oneof![
        prop::collection::vec((target(), any_expr()), 1..3).prop_map(|a| a
            .into_iter()
            .map(|(target, value)| Item::Assign {
                assign: Box::new(Assign { target, value }),
                span: span()
            })
            .collect()),
        (
            any::<bool>(),
            prop::sample::select(vec!["sub.nc", "lib/UP_1.NC", "CORNER", "x-2.spf"])
        )
            .prop_map(|(local, name)| vec![Item::Call {
                call: Box::new(SubCall {
                    local,
                    name: name.to_string()
                }),
                span: span()
            }]),
        control().prop_map(|c| vec![Item::Control {
            control: Box::new(c),
            span: span()
        }]),
        any_expr().prop_map(|value| vec![
            Item::G {
                code: 4,
                span: span()
            },
            Item::Axis(AxisWord {
                name: AxisName::default(),
                value,
                span: span()
            }),
        ]),
        prop_oneof![
            "[a-zA-Z0-9 .,:]{0,20}".prop_map(|t| Command::Msg {
                text: t.as_str().into()
            }),
            any_expr().prop_map(|seconds| Command::Time { seconds }),
            Just(Command::Var),
            Just(Command::EndVar),
        ]
        .prop_map(|command| vec![Item::Command {
            command: Box::new(command),
            span: span()
        }]),
    ]
}

/// Expressions in the shapes the parser produces: left-associative chains with precedence,
/// unary minus on atoms.
fn expr() -> impl Strategy<Value = Expr> {
    fn term() -> impl Strategy<Value = Expr> {
        (atom(), any::<bool>()).prop_map(|(a, neg)| if neg { Expr::Neg(Box::new(a)) } else { a })
    }
    (
        term(),
        prop::collection::vec(
            (prop::sample::select(vec![BinOp::Add, BinOp::Sub]), term()),
            0..3,
        ),
    )
        .prop_map(|(first, rest)| {
            rest.into_iter()
                .fold(first, |acc, (op, t)| Expr::Bin(Box::new((op, acc, t))))
        })
}

fn axis_name() -> impl Strategy<Value = AxisName> {
    // Names ending in a digit print as `X1=5`, never glued (`X15` is another word).
    prop::sample::select(vec![
        "X", "Y", "Z", "A", "B", "C", "AB", "AM", "AH", "AA", "X1", "Q12", "AXIS7",
    ])
    .prop_map(AxisName::from)
}

fn axis_word() -> impl Strategy<Value = AxisWord> {
    prop_oneof![
        (axis_name(), number()).prop_map(|(name, v)| AxisWord {
            name,
            value: Expr::Num(v),
            span: span()
        }),
        (axis_name(), expr()).prop_map(|(name, value)| AxisWord {
            name,
            value,
            span: span()
        }),
    ]
}

fn flag(key: &str) -> Entry {
    Entry {
        key: Some(key.into()),
        glued: None,
        value: None,
        text: None,
        span: span(),
    }
}

fn valued(key: &str, value: Expr) -> Entry {
    Entry {
        key: Some(key.into()),
        glued: None,
        value: Some(value),
        text: None,
        span: span(),
    }
}

fn track_options() -> impl Strategy<Value = Vec<Entry>> {
    (
        prop::sample::select(vec!["ID", "CH"]),
        0u32..13,
        prop::collection::vec(
            prop::sample::select(vec!["SET_ZERO", "KIN_BASE", "WAIT", "SIMU", "RELATIVE"]),
            0..3,
        ),
        prop::option::of(0u32..2000),
        prop::option::of(expr()),
    )
        .prop_map(|(source, id, flags, filter, x)| {
            let mut v = vec![valued(source, Expr::Num(f64::from(id)))];
            let mut seen = Vec::new();
            for f in flags {
                if !seen.contains(&f) {
                    seen.push(f);
                    v.push(flag(f));
                }
            }
            if let Some(f) = filter {
                v.push(valued("FILTER", Expr::Num(f64::from(f))));
            }
            if let Some(x) = x {
                v.push(valued("X", x));
            }
            v
        })
}

fn command() -> impl Strategy<Value = Command> {
    prop_oneof![
        (any::<bool>(), track_options()).prop_map(|(on, options)| Command::TrackCs {
            on,
            options: if on { options } else { vec![flag("WAIT")] }
        }),
        Just(Command::TrackCsAbs),
        (
            any::<bool>(),
            prop::sample::select(vec!["DYN_CS", "TRACK_CS"])
        )
            .prop_map(|(on, k)| Command::ChannelInterface {
                on,
                kind: Some(k.into())
            }),
        prop::collection::vec(expr(), 1..7).prop_map(|values| Command::Cs {
            on: true,
            name: Some("OFFS".into()),
            values
        }),
        Just(Command::Cs {
            on: false,
            name: None,
            values: vec![]
        }),
        (0u32..300).prop_map(|id| Command::Trafo {
            on: None,
            id: Some(Expr::Num(f64::from(id)))
        }),
        any::<bool>().prop_map(|on| Command::Trafo {
            on: Some(on),
            id: None
        }),
        (1u32..20, 1u32..5).prop_map(|(id, count)| Command::SignalSyn {
            options: vec![
                Entry {
                    key: Some("ID".into()),
                    glued: Some(f64::from(id)),
                    value: None,
                    text: None,
                    span: span()
                },
                Entry {
                    key: Some("COUNT".into()),
                    glued: Some(f64::from(count)),
                    value: None,
                    text: None,
                    span: span()
                },
            ]
        }),
        Just(Command::WaitIndpAll),
        any::<bool>().prop_map(|wait| Command::Flush { wait }),
        prop::collection::vec(axis_word(), 1..3).prop_map(|axes| Command::Pset { axes }),
        Just(Command::Preset { axes: vec![] }),
    ]
}

fn motion_block() -> impl Strategy<Value = Vec<Item>> {
    (
        prop::option::of(prop::sample::select(vec![0u32, 1, 90, 91])),
        prop::collection::vec(axis_word(), 0..4),
        prop::option::of(number()),
        prop::option::of(0u32..200),
    )
        .prop_map(|(g, axes, feed, m)| {
            let mut items = Vec::new();
            if let Some(code) = g {
                items.push(Item::G { code, span: span() });
            }
            let mut names = Vec::new();
            for a in axes {
                if !names.contains(&a.name) {
                    names.push(a.name);
                    items.push(Item::Axis(a));
                }
            }
            if let Some(f) = feed {
                items.push(Item::Feed {
                    value: Expr::Num(f),
                    span: span(),
                });
            }
            if let Some(code) = m {
                items.push(Item::M { code, span: span() });
            }
            items
        })
}

fn block() -> impl Strategy<Value = (Option<u32>, Vec<Item>)> {
    (
        prop::option::of(0u32..100_000),
        prop_oneof![
            motion_block(),
            command().prop_map(|command| vec![Item::Command {
                command: Box::new(command),
                span: span()
            }]),
            core_block(),
        ],
    )
        // A block holds something: an empty one gets a number (a filter would reject too many
        // cases in long campaigns).
        .prop_map(|(n, items)| {
            let n = if items.is_empty() { n.or(Some(1)) } else { n };
            (n, items)
        })
}

fn program() -> impl Strategy<Value = Program> {
    (
        prop::option::of("[A-Za-z][A-Za-z0-9_-]{0,12}"),
        prop::collection::vec(
            ("[A-Z][A-Z0-9_]{0,8}", prop::collection::vec(block(), 0..5)),
            0..3,
        ),
        prop::collection::vec(block(), 0..40),
    )
        .prop_map(|(name, subs, blocks)| {
            // Local subroutines have different names (the index makes them so), and after them
            // the main program has a name; `%L` alone opens a local subroutine, so no main
            // program is called L.
            let subs: Vec<(String, _)> = subs
                .into_iter()
                .enumerate()
                .map(|(i, (n, b))| (format!("{n}{i}"), b))
                .collect();
            let name = match name {
                Some(n) if n.eq_ignore_ascii_case("L") => Some("MAIN".to_string()),
                None if !subs.is_empty() => Some("MAIN".to_string()),
                other => other,
            };
            let mut program = Program {
                name,
                ..Program::default()
            };
            for (sub, sub_blocks) in subs {
                let start = program.blocks.len() as u32;
                for (number, items) in sub_blocks {
                    program.push_block(number, items, span(), 0);
                }
                program.subs.push(LocalSub {
                    name: sub,
                    blocks: start..program.blocks.len() as u32,
                    span: span(),
                });
            }
            program.main_start = program.blocks.len() as u32;
            for (number, items) in blocks {
                program.push_block(number, items, span(), 0);
            }
            program
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn printed_programs_reparse_unchanged(p in program()) {
        let text = print(&p);
        let (again, diags) = parse(&text);
        prop_assert!(diags.is_empty(), "{text}\n{diags:#?}");
        prop_assert_eq!(&again, &p, "{}", text);
        // And printing is a fixed point.
        prop_assert_eq!(print(&again), text);
    }

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..400)) {
        let src = String::from_utf8_lossy(&bytes);
        let (p, _) = parse(&src);
        let axes: Vec<String> = ["X", "Y", "Z"].map(String::from).to_vec();
        let _ = (&p, check_source(&src, &axes));
    }

    /// Structured fuzzing: valid programs with random splices of NC-ish fragments.
    #[test]
    fn mutated_programs_never_panic(
        p in program(),
        cuts in prop::collection::vec((0usize..2000, prop::sample::select(vec![
            "[", "]", "=", "#", "$", "%", "\\\n", "\n", "(", ")", ";", "-", "--", "..", "1e9", "X=", "#TRACK CS ON [", "$WHILE", "N", "G", "\"", "V.G.", "99999999999999999999",
        ])), 0..8),
    ) {
        let mut text = print(&p);
        for (at, piece) in cuts {
            let at = at.min(text.len());
            if text.is_char_boundary(at) {
                text.insert_str(at, piece);
            }
        }
        if std::env::var_os("NC_PROPS_TRACE").is_some() {
            std::fs::write("/tmp/nc_props_last.nc", &text).unwrap();
        }
        let (tree, diags) = parse(&text);
        for d in &diags {
            prop_assert!(d.line >= 1 && d.col >= 1, "{:?}", d);
        }
        let axes: Vec<String> = ["X", "Y", "Z", "A", "B", "C", "AB", "AM", "AH", "AA"].map(String::from).to_vec();
        let _ = (&tree, check_source(&text, &axes));
    }
}

/// Pieces of lines near the fast lane's edges: plain words, and everything that must send a
/// line to the general path.
fn fragment() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => prop::sample::select(vec![
            "N10", "n00860", "N4294967295", "N4294967296", "N-3", "N1.5", "G1", "G01", "g0",
            "G1.5", "G-1", "M30", "M3.0", "F500", "f-5", "X10", "X-60", "x+2.5", "Y.5",
            "Z1.", "Z1..2", "AB90", "X1", "ABCDEFGHIJKLMNOPQRSTUVWXYZ1", "X1234567890123456",
            "X123456789012345", "X12.345678901234", "E3", "X1E3", "X1Y2", "X", "X 10", "N",
            "X1234567.1234567", "X12345678", "X1.12345678", "ABCDEFG-1234567.1234567",
            "X1.2.3", "X7.", "N1234567",
        ]).prop_map(String::from),
        // Words of every length around the register edges (7 and 8 letters or digits).
        2 => "[A-Za-z]{1,8}[-+]?[0-9]{0,9}(\\.[0-9]{0,9})?",
        1 => prop::sample::select(vec![
            " ", "  ", "\t", "\r", ";", "; note", "(c)", "=", "[", "]", "#", "$", "%p", "_",
            "V.G.TRACK_CS.X", "\\", "\"s\"", "ä", "-", "+", ".", "1",
        ]).prop_map(String::from),
    ]
}

fn fragment_lines() -> impl Strategy<Value = String> {
    prop::collection::vec(
        (
            prop::collection::vec((fragment(), prop::bool::weighted(0.8)), 0..7),
            prop::bool::weighted(0.9),
        ),
        0..6,
    )
    .prop_map(|lines| {
        let mut text = String::new();
        for (parts, newline) in lines {
            for (part, space) in parts {
                text.push_str(&part);
                if space {
                    text.push(' ');
                }
            }
            if newline {
                text.push('\n');
            }
        }
        text
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2048))]

    /// The fast lane for plain blocks gives the very tree (spans included: the debug form
    /// prints them, unlike tree equality) and diagnostics that the general path gives.
    #[test]
    fn fast_lane_matches_general_path(text in fragment_lines()) {
        let fast = parse(&text);
        let general = parse_general(&text);
        prop_assert_eq!(format!("{fast:#?}"), format!("{general:#?}"), "{:?}", text);
    }
}

/// What a check reports: the rendered diagnostics and the decoded elements.
fn checked_whole(src: &str, axes: &[String]) -> (Vec<String>, Vec<cnc_core::nc::Decoded>) {
    let (diags, decoded) = check_source(src, axes);
    (diags.iter().map(|d| d.render("F")).collect(), decoded)
}

fn checked_straight(
    src: &str,
    axes: &[String],
) -> Option<(Vec<String>, Vec<cnc_core::nc::Decoded>)> {
    use cnc_core::nc::decode::{DecoderSetup, ZeroVars};
    let mut decoded = Vec::new();
    let mut keep = |step: &[cnc_core::nc::Decoded]| decoded.extend_from_slice(step);
    let diags = cnc_core::nc::straight::check_straight(
        src,
        axes,
        &DecoderSetup::default(),
        &ZeroVars,
        Some(&mut keep),
    )?;
    Some((diags.iter().map(|d| d.render("F")).collect(), decoded))
}

fn straight_program() -> impl Strategy<Value = String> {
    prop::collection::vec(
        prop_oneof![
            4 => motion_block(),
            1 => command().prop_map(|command| vec![Item::Command {
                command: Box::new(command),
                span: span()
            }]),
            1 => prop::collection::vec((target(), any_expr()), 1..3).prop_map(|a| a
                .into_iter()
                .map(|(target, value)| Item::Assign { assign: Box::new(Assign { target, value }), span: span() })
                .collect()),
        ],
        0..60,
    )
    .prop_map(|blocks| {
        let mut program = Program::default();
        for items in blocks {
            program.push_block(None, items, span(), 0);
        }
        print(&program)
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// A straight program checked window by window reports what the whole-program check
    /// reports, and decodes the same blocks.
    #[test]
    fn straight_check_matches_the_whole_program_check(
        text in straight_program(),
        lines in fragment_lines(),
    ) {
        let axes: Vec<String> = ["X", "Y", "Z", "A", "B", "C", "AB", "X1"].map(String::from).to_vec();
        for src in [text, lines] {
            if let Some(straight) = checked_straight(&src, &axes) {
                prop_assert_eq!(straight, checked_whole(&src, &axes), "{}", src);
            }
        }
    }
}
