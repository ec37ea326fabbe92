//! The front end on programs in the manuals' style and on bad input: every refusal names its
//! line and column, and no input makes it panic.

use plc_st::ast::{Arg, BinOp, Expr, Item, PouKind, Stmt, TypeDef, TypeRef};
use plc_st::parse_file;

fn data(name: &str) -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name);
    std::fs::read_to_string(path).unwrap()
}

fn error(text: &str) -> String {
    parse_file("t.st", text).unwrap_err().to_string()
}

#[test]
fn a_master_program_with_pointers_typed_literals_and_blocks_parses() {
    let unit = parse_file("rotary_master.st", &data("rotary_master.st")).unwrap();
    let kinds: Vec<&str> = unit
        .items
        .iter()
        .map(|i| match i {
            Item::Pou(p) => match p.kind {
                PouKind::Program => "PROGRAM",
                PouKind::FunctionBlock => "FUNCTION_BLOCK",
                PouKind::Function => "FUNCTION",
                PouKind::Method => "METHOD",
            },
            Item::Types(_) => "TYPE",
            Item::Globals(_) => "VAR_GLOBAL",
        })
        .collect();
    assert_eq!(
        kinds,
        [
            "TYPE",
            "TYPE",
            "VAR_GLOBAL",
            "FUNCTION",
            "FUNCTION_BLOCK",
            "PROGRAM"
        ]
    );
    let Item::Types(enum_type) = &unit.items[0] else {
        unreachable!()
    };
    let TypeDef::Enum { values, base } = &enum_type[0].def else {
        panic!("{enum_type:?}")
    };
    assert_eq!(values.len(), 4);
    assert!(matches!(base, Some(TypeRef::Named(n)) if n.is("INT")));
    let Item::Pou(main) = &unit.items[5] else {
        unreachable!()
    };
    // pDynCs : POINTER TO MC_CONTROL_DYN_CS_UNIT;
    let pointer = &main.vars[0].vars[0];
    assert!(
        matches!(&pointer.ty, TypeRef::Pointer(t, _) if matches!(&**t, TypeRef::Named(n) if n.is("MC_CONTROL_DYN_CS_UNIT")))
    );
    // pDynCs := ADR(gpCh[0]^channel_mc_control.dyn_cs); (`^name` is `^.name`)
    let Stmt::Assign { value, .. } = &main.body[0] else {
        panic!()
    };
    let Expr::Call { callee, args, .. } = value else {
        panic!("{value:?}")
    };
    assert!(matches!(&**callee, Expr::Name(n) if n.is("ADR")));
    let Arg::Positional(Expr::Field(inner, field)) = &args[0] else {
        panic!("{args:?}")
    };
    assert!(field.is("dyn_cs"));
    assert!(
        matches!(&**inner, Expr::Field(d, f) if f.is("channel_mc_control") && matches!(&**d, Expr::Deref(..)))
    );
    // The typed literal keeps its sign and type.
    let text = format!("{:?}", main.body);
    assert!(text.contains("Typed { ty: Name { text: \"DINT\""), "{text}");
    assert!(text.contains("Int(-13059200"), "{text}");
    // The duration is in nanoseconds, the output assignments are outputs (one negated).
    assert!(text.contains("Time(1500000000"), "{text}");
    assert!(text.contains("negated: true"), "{text}");
}

#[test]
fn operators_bind_as_the_standard_says() {
    let unit = parse_file(
        "t.st",
        "PROGRAM P VAR a : BOOL; END_VAR a := 1 + 2 * 3 ** 2 = 19 OR NOT a AND a; END_PROGRAM",
    )
    .unwrap();
    let Item::Pou(p) = &unit.items[0] else {
        unreachable!()
    };
    let Stmt::Assign { value, .. } = &p.body[0] else {
        panic!()
    };
    // OR is the root; its left side is the comparison, its right NOT a AND a.
    let Expr::Binary(BinOp::Or, lhs, rhs, _) = value else {
        panic!("{value:?}")
    };
    assert!(matches!(&**lhs, Expr::Binary(BinOp::Eq, ..)));
    assert!(matches!(&**rhs, Expr::Binary(BinOp::And, ..)));
    let Expr::Binary(BinOp::Eq, sum, _, _) = &**lhs else {
        unreachable!()
    };
    let Expr::Binary(BinOp::Add, _, product, _) = &**sum else {
        panic!("{sum:?}")
    };
    assert!(
        matches!(&**product, Expr::Binary(BinOp::Mul, _, power, _) if matches!(&**power, Expr::Binary(BinOp::Pow, ..)))
    );
}

#[test]
fn refusals_name_line_and_column() {
    for (text, expect) in [
        (
            "PROGRAM P\n  x := ;\nEND_PROGRAM",
            "t.st:2:8: error: expected a value",
        ),
        (
            "PROGRAM P\nVAR\n  IF : INT;\nEND_VAR\nEND_PROGRAM",
            "t.st:3:3: error: `IF` is reserved, not a name",
        ),
        (
            "PROGRAM P\n  (* open",
            "t.st:2:3: error: a comment `(*` without its `*)`",
        ),
        (
            "PROGRAM P\n  s := 'abc\nEND_PROGRAM",
            "t.st:2:8: error: a string without its closing `'`",
        ),
        (
            "PROGRAM P\n  x := 3#12;\nEND_PROGRAM",
            "t.st:2:8: error: base 3#: 2#, 8# or 16#",
        ),
        (
            "PROGRAM P\n  t := T#5parsecs;\nEND_PROGRAM",
            "t.st:2:8: error: duration unit \"parsecs\"",
        ),
        (
            "PROGRAM P\n  IF x THEN y := 1;\nEND_PROGRAM",
            "t.st:3:1: error: expected ELSIF or ELSE or END_IF",
        ),
        (
            "PROGRAM P\n  x + 1;\nEND_PROGRAM",
            "t.st:2:5: error: expected `:=` or a call",
        ),
        (
            "PROGRAM P\nVAR x AT %IX0.0 : BOOL; END_VAR\nEND_PROGRAM",
            "t.st:2:7: error: `AT %..` locations are not supported",
        ),
        (
            "FUNCTION F\n  F := 1;\nEND_FUNCTION",
            "t.st:2:3: error: expected `:` and the function's return type",
        ),
        (
            "x := 1;",
            "t.st:1:1: error: expected PROGRAM, FUNCTION_BLOCK, FUNCTION, TYPE or VAR_GLOBAL",
        ),
        (
            "FUNCTION F : INT\nVAR_IN_OUT a : ARRAY[*] OF INT; END_VAR\nEND_FUNCTION",
            "t.st:2:22: error: `ARRAY[*]` (an array of any length) is not supported",
        ),
        // The object-oriented extensions, where TwinCAT and CODESYS write them.
        (
            "FUNCTION_BLOCK FB\nMETHOD ABSTRACT M : BOOL\nEND_METHOD\nEND_FUNCTION_BLOCK",
            "t.st:2:8: error: `ABSTRACT` is not supported",
        ),
        (
            "FUNCTION_BLOCK FB\nMETHOD FB_init : BOOL\nEND_METHOD\nEND_FUNCTION_BLOCK",
            "t.st:2:8: error: `FB_init` is not supported: nothing calls it here",
        ),
        (
            "FUNCTION F : INT\n  F := 1;\nMETHOD M : BOOL\nEND_METHOD\nEND_FUNCTION",
            "t.st:3:1: error: a FUNCTION has no METHOD or ACTION",
        ),
        (
            "FUNCTION_BLOCK FB_Saw EXTENDS FB_Axis\nEND_FUNCTION_BLOCK",
            "t.st:1:23: error: `EXTENDS` is not supported",
        ),
        (
            "FUNCTION_BLOCK FB_Saw IMPLEMENTS I_Cut\nEND_FUNCTION_BLOCK",
            "t.st:1:23: error: `IMPLEMENTS` is not supported",
        ),
        (
            "INTERFACE I_Cut\nEND_INTERFACE",
            "t.st:1:1: error: `INTERFACE` is not supported",
        ),
        (
            "FUNCTION_BLOCK FB\nPROPERTY Speed : LREAL\nEND_PROPERTY\nEND_FUNCTION_BLOCK",
            "t.st:2:1: error: `PROPERTY` is not supported",
        ),
        // A calendar literal.
        (
            "PROGRAM P\nVAR t : TIME; END_VAR\n  t := DT#2026-11-30-12:00:00;\nEND_PROGRAM",
            "t.st:3:8: error: DATE, TIME_OF_DAY and DATE_AND_TIME are not supported",
        ),
        // A type followed by `(`: a subrange type or FB_init's values.
        (
            "TYPE T_Percent : INT(0..100); END_TYPE",
            "t.st:1:21: error: `INT(..)` is not supported: a subrange type",
        ),
        (
            "PROGRAM P\nVAR fbLog : FB_Logger('main'); END_VAR\nEND_PROGRAM",
            "t.st:2:22: error: `FB_Logger(..)` is not supported",
        ),
    ] {
        let e = error(text);
        assert!(
            e.starts_with(expect),
            "{text:?}:\n  got  {e}\n  want {expect}"
        );
    }
}

/// METHODs and ACTIONs inside their POU after its body, or right after its END_..; access
/// words before a method's name (PRIVATE and PROTECTED kept as private).
#[test]
fn methods_and_actions_belong_to_their_pou() {
    let text = "FUNCTION_BLOCK FB\nVAR n : INT; END_VAR\n  n := n + 1;\n\
                METHOD M_Reset : BOOL\n  n := 0;\nEND_METHOD\n\
                ACTION A_Log:\n  n := n;\nEND_ACTION\nEND_FUNCTION_BLOCK\n\
                method PROTECTED FINAL M_Set\nVAR_INPUT v : INT; END_VAR\n  n := v;\nEND_METHOD\n\
                PROGRAM P\nACTION A_Init:\nEND_ACTION\nEND_PROGRAM";
    let unit = parse_file("t.st", text).unwrap();
    let Item::Pou(fb) = &unit.items[0] else {
        panic!("{unit:?}")
    };
    let found: Vec<(&str, bool, bool)> = (fb.methods.iter())
        .map(|m| (m.name.text.as_str(), m.action, m.private))
        .collect();
    assert_eq!(
        found,
        [
            ("M_Reset", false, false),
            ("A_Log", true, false),
            ("M_Set", false, true)
        ]
    );
    assert_eq!(fb.body.len(), 1);
    let Item::Pou(p) = &unit.items[1] else {
        panic!("{unit:?}")
    };
    assert_eq!(p.methods.len(), 1);
}

/// The object-oriented extensions' words are refused only where they begin a declaration: a
/// variable or a block may still be called so.
#[test]
fn a_variable_named_as_an_extension_word_is_a_variable() {
    let text = "FUNCTION_BLOCK Action\nVAR_INPUT method : INT; END_VAR\nEND_FUNCTION_BLOCK\n\
                PROGRAM P\nVAR property, interface : INT; extends : Action; action, method : BOOL; END_VAR\n\
                property := 1;\ninterface := property;\nextends(method := interface);\n\
                action S= property > 0;\nmethod R= FALSE;\n\
                END_PROGRAM";
    let unit = parse_file("t.st", text).unwrap();
    assert_eq!(unit.items.len(), 2);
}

#[test]
fn deep_nesting_is_refused_not_a_stack_overflow() {
    let deep = format!(
        "PROGRAM P x := {}1{}; END_PROGRAM",
        "(".repeat(5000),
        ")".repeat(5000)
    );
    assert!(error(&deep).contains("nested deeper than"));
}

proptest::proptest! {
    /// Any text, and any sequence of the language's own words and signs, gives a tree or a
    /// refusal with a place: never a panic.
    #[test]
    fn no_input_makes_the_parser_panic(text in "\\PC{0,200}") {
        let _ = parse_file("p.st", &text);
    }

    #[test]
    fn no_sequence_of_tokens_makes_the_parser_panic(words in proptest::collection::vec(
        proptest::sample::select(vec![
            "PROGRAM", "P", "END_PROGRAM", "VAR", "END_VAR", "x", ":", "INT", ";", ":=", "1",
            "IF", "THEN", "END_IF", "CASE", "OF", "END_CASE", "(", ")", "[", "]", "^", ".",
            "FOR", "TO", "DO", "END_FOR", "DINT#", "-", "T#1s", "'s'", ",", "..", "=>", "NOT",
            "ARRAY", "POINTER", "STRUCT", "END_STRUCT", "TYPE", "END_TYPE", "ELSE", "(*", "*)",
        ]), 0..60)) {
        let _ = parse_file("p.st", &words.join(" "));
    }
}
