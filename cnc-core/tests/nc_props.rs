//! Property tests of the NC front end: generated valid programs survive print-and-reparse
//! unchanged; arbitrary input never panics the parser or the decoder.
//!
//! This file is also the fuzz driver: the toolchain here is stable, which cargo-fuzz refuses
//! (it needs nightly sanitizer flags), so the byte-level and mutation-level fuzzing runs as
//! proptest strategies. `PROPTEST_CASES=100000 cargo test -p cnc-core --test nc_props` runs a
//! longer campaign.

use cnc_core::nc::ast::*;
use cnc_core::nc::decode::ZeroVars;
use cnc_core::nc::{decode_program, parse, print};
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
    prop::sample::select(vec!["X", "Y", "Z", "A", "B", "C"])
        .prop_map(|a| Name::from(format!("V.G.TRACK_CS.{a}").as_str()))
}

fn atom() -> impl Strategy<Value = Expr> {
    prop_oneof![number().prop_map(Expr::Num), variable().prop_map(Expr::Var)]
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
            rest.into_iter().fold(first, |acc, (op, t)| {
                Expr::Bin(op, Box::new(acc), Box::new(t))
            })
        })
}

fn axis_name() -> impl Strategy<Value = Name> {
    prop::sample::select(vec!["X", "Y", "Z", "A", "B", "C", "AB", "AM", "AH", "AA"])
        .prop_map(Name::from)
}

fn axis_word() -> impl Strategy<Value = AxisWord> {
    prop_oneof![
        (axis_name(), number()).prop_map(|(name, v)| AxisWord {
            name,
            value: Expr::Num(v),
            assigned: false,
            span: span()
        }),
        (axis_name(), expr()).prop_map(|(name, value)| AxisWord {
            name,
            value,
            assigned: true,
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
        prop::collection::vec(axis_word(), 1..3).prop_map(|axes| Command::Pset {
            axes: axes
                .into_iter()
                .map(|a| AxisWord {
                    assigned: true,
                    ..a
                })
                .collect()
        }),
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

fn block() -> impl Strategy<Value = Block> {
    (
        prop::option::of(0u32..100_000),
        prop_oneof![
            motion_block(),
            command().prop_map(|command| vec![Item::Command {
                command,
                span: span()
            }])
        ],
    )
        .prop_filter("blocks hold something", |(n, items)| {
            n.is_some() || !items.is_empty()
        })
        .prop_map(|(number, items)| Block {
            number,
            items,
            span: span(),
        })
}

fn program() -> impl Strategy<Value = Program> {
    (
        prop::option::of("[A-Za-z][A-Za-z0-9_-]{0,12}"),
        prop::collection::vec(block(), 0..40),
    )
        .prop_map(|(name, blocks)| Program { name, blocks })
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
        let _ = decode_program(&p, &src, &axes, &ZeroVars);
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
        let (tree, diags) = parse(&text);
        for d in &diags {
            prop_assert!(d.line >= 1 && d.col >= 1, "{:?}", d);
        }
        let axes: Vec<String> = ["X", "Y", "Z", "A", "B", "C", "AB", "AM", "AH", "AA"].map(String::from).to_vec();
        let _ = decode_program(&tree, &text, &axes, &ZeroVars);
    }
}
