//! The string functions (LEN, LEFT, RIGHT, MID, CONCAT, INSERT, DELETE, REPLACE, FIND), the
//! conversions to and from STRING and the ordering of STRINGs: their values as IEC 61131-3
//! and TwinCAT give them, their faults with the numbers they name, the refusals at load, and
//! a cycle that computes strings without allocating.

use plc_st::vm::Fault;

use crate::support::{load, refused};

use crate::counting_alloc;

/// Runs one cycle of program MAIN (after `before`) whose BOOLs `ok1` .. `ok<n>` hold the
/// checks' results, and names the checks that failed.
fn checks(before: &str, vars: &str, body: &str, n: usize) {
    let oks: Vec<String> = (1..=n).map(|k| format!("ok{k}")).collect();
    let text = format!(
        "{before}PROGRAM MAIN\nVAR\n    {} : BOOL;\n{vars}\nEND_VAR\n{body}\nEND_PROGRAM",
        oks.join(", ")
    );
    let mut p = load(&text);
    p.cycle(0)
        .unwrap_or_else(|f| panic!("{}", p.fault_text(&f)));
    let failed: Vec<&String> = oks
        .iter()
        .filter(|ok| p.read_var(&format!("MAIN.{ok}")) != Some(1.0))
        .collect();
    assert!(failed.is_empty(), "checks that failed: {failed:?}");
}

#[test]
fn the_string_functions_give_what_iec_and_twincat_give() {
    let vars = "    s : STRING(80) := 'Hello World';
    sEmpty, sOut : STRING(80);
    sShort : STRING(4);
    n : INT := 3;";
    let body = "
    ok1 := LEN(s) = 11 AND LEN(sEmpty) = 0 AND LEN('') = 0;
    ok2 := LEFT(s, 5) = 'Hello' AND LEFT(s, 0) = '' AND LEFT(s, 99) = s;
    ok3 := RIGHT(s, 5) = 'World' AND RIGHT(s, 99) = 'Hello World';
    ok4 := MID(s, 3, 7) = 'Wor' AND MID(s, 99, 7) = 'World' AND MID(s, 2, 12) = '';
    ok5 := CONCAT('part', '_', INT_TO_STRING(n), '.nc') = 'part_3.nc';
    ok6 := INSERT('ac', 'b', 1) = 'abc' AND INSERT('ac', 'b', 0) = 'bac'
        AND INSERT('ac', 'b', 9) = 'acb';
    ok7 := DELETE(s, 6, 6) = 'Hello' AND DELETE(s, 1, 1) = 'ello World'
        AND DELETE(s, 5, 20) = s;
    ok8 := REPLACE(s, 'there', 5, 7) = 'Hello there' AND REPLACE('abc', 'X', 0, 2) = 'aXbc';
    ok9 := FIND(s, 'o') = 5 AND FIND(s, 'World') = 7 AND FIND(s, 'x') = 0
        AND FIND(s, '') = 0 AND FIND('ab', 'abc') = 0;
    ok10 := 'abc' < 'abd' AND 'ab' < 'abc' AND 'b' > 'abc' AND s >= s AND s <= s
        AND NOT ('abc' < 'abc');
    sOut := CONCAT(LEFT(s, 5), ', PLC');
    ok11 := sOut = 'Hello, PLC' AND LEN(sOut) = 10;
    (* Cut to the target, as TwinCAT's functions are. *)
    sShort := CONCAT(s, s);
    ok12 := sShort = 'Hell' AND LEN(sShort) = 4;
    ok13 := UPPER_OK();
";
    // A function of the program's own may use them too.
    let upper = "FUNCTION UPPER_OK : BOOL VAR t : STRING(20); END_VAR
    t := CONCAT('a', 'b');
    UPPER_OK := t = 'ab';
END_FUNCTION
";
    checks(upper, vars, body, 13);
}

#[test]
fn numbers_become_text_and_text_numbers() {
    let vars = "    i : INT := -42;
    u : UDINT := 4000000000;
    w : WORD := 16#FFFF;
    b : BOOL := TRUE;
    r : REAL := 0.1;
    x : LREAL := 1.5;
    t : TIME := T#1M2S30MS;
    lt : LTIME;
    nInt : INT;
    nU : ULINT;
    f : LREAL;
    fr : REAL;
    bb : BOOL;";
    let body = "
    ok1 := INT_TO_STRING(i) = '-42' AND UDINT_TO_STRING(u) = '4000000000'
        AND WORD_TO_STRING(w) = '65535';
    ok2 := BOOL_TO_STRING(b) = 'TRUE' AND BOOL_TO_STRING(FALSE) = 'FALSE';
    ok3 := REAL_TO_STRING(r) = '0.1' AND LREAL_TO_STRING(x) = '1.5'
        AND LREAL_TO_STRING(100.0) = '100' AND LREAL_TO_STRING(1.0E20) = '1e20'
        AND LREAL_TO_STRING(-2.5E-7) = '-2.5e-7';
    ok4 := TIME_TO_STRING(t) = 'T#1m2s30ms';
    ok10 := TIME_TO_STRING(T#0MS) = 'T#0ms';
    lt := LINT_TO_LTIME(1000005001);
    ok11 := LTIME_TO_STRING(lt) = 'LTIME#1s5us1ns';
    nInt := STRING_TO_INT(' -123 ');
    ok5 := nInt = -123 AND STRING_TO_INT('16#7F') = 127 AND STRING_TO_INT('1_000') = 1000;
    nU := STRING_TO_ULINT('18446744073709551615');
    ok6 := nU = ULINT#18446744073709551615;
    f := STRING_TO_LREAL('2.5e3');
    fr := STRING_TO_REAL('0.25');
    ok7 := f = 2500.0 AND fr = 0.25;
    bb := STRING_TO_BOOL('true');
    ok8 := bb AND NOT STRING_TO_BOOL('0');
    (* Text and back. *)
    ok9 := STRING_TO_DINT(DINT_TO_STRING(-2147483648)) = -2147483648;
    (* Durations as the language writes them, the prefix optional. *)
    ok12 := STRING_TO_TIME('T#1m2s30ms') = t AND STRING_TO_TIME(TIME_TO_STRING(t)) = t
        AND STRING_TO_TIME('time#-2.5s') = T#-2500MS AND STRING_TO_TIME(' 1h_30m ') = T#90M
        AND STRING_TO_TIME('T#1ms900us') = T#1MS AND STRING_TO_TIME('1d') = T#24H;
    ok13 := STRING_TO_LTIME(LTIME_TO_STRING(lt)) = lt
        AND STRING_TO_LTIME('LTIME#1.5us') = LINT_TO_LTIME(1500);
    (* Counted in whole ns: decimal fractions exact, the largest LTIME read back. *)
    ok14 := STRING_TO_TIME('T#8.2s') = T#8200MS AND STRING_TO_TIME('T#1.001s') = T#1001MS
        AND STRING_TO_TIME('T#1_500ms') = T#1500MS AND STRING_TO_TIME('T#-1.9ms') = T#-1MS;
    lt := LINT_TO_LTIME(LINT#9223372036854775807);
    ok15 := STRING_TO_LTIME(LTIME_TO_STRING(lt)) = lt
        AND LTIME_TO_LINT(STRING_TO_LTIME('LTIME#200d1ns')) = LINT#17280000000000001;
";
    checks("", vars, body, 15);
}

fn fault(body: &str) -> (Fault, [i64; 3], String) {
    let text = format!(
        "PROGRAM MAIN\nVAR s : STRING(20) := 'abc'; n : INT; i : SINT; END_VAR\n{body}\nEND_PROGRAM"
    );
    let mut p = load(&text);
    let f = p.cycle(0).expect_err("a fault");
    (f.fault, f.values, p.fault_text(&f))
}

#[test]
fn a_bad_length_position_or_number_faults_with_its_place() {
    let (f, values, text) = fault("  s := MID(s, 2, 0);");
    assert_eq!(f, Fault::IndexOutOfRange);
    assert_eq!(values, [0, 1, 255]);
    assert!(
        text.starts_with("main.st:3:3: fault: index 0 outside [1..255]"),
        "{text}"
    );
    let (f, values, _) = fault("  s := LEFT(s, n - 1);");
    assert_eq!((f, values), (Fault::IndexOutOfRange, [-1, 0, 255]));
    let (f, values, _) = fault("  s := INSERT(s, 'x', -2);");
    assert_eq!((f, values), (Fault::IndexOutOfRange, [-2, 0, 255]));
    let (f, _, text) = fault("  n := STRING_TO_INT('12x');");
    assert_eq!(f, Fault::NoNumber);
    assert!(text.contains("holds none"), "{text}");
    let (f, _, _) = fault("  n := STRING_TO_INT(s);");
    assert_eq!(f, Fault::NoNumber);
    let (f, _, _) = fault("  i := STRING_TO_SINT('300');");
    assert_eq!(f, Fault::OutOfRange);
    let (f, _, _) = fault("  n := REAL_TO_INT(STRING_TO_REAL('1e39'));");
    assert_eq!(f, Fault::OutOfRange);
    let (f, _, _) = fault("  n := LREAL_TO_INT(STRING_TO_LREAL('1e400'));");
    assert_eq!(f, Fault::OutOfRange);
    // Rust reads these as reals; they are no numbers.
    for text in ["inf", "NaN", "-infinity"] {
        let (f, _, _) = fault(&format!("  n := LREAL_TO_INT(STRING_TO_LREAL('{text}'));"));
        assert_eq!(f, Fault::NoNumber, "{text}");
    }
    // Beyond every integer type: out of range, not no number.
    let (f, _, _) = fault("  n := ULINT_TO_INT(STRING_TO_ULINT('18446744073709551616'));");
    assert_eq!(f, Fault::OutOfRange);
    let (f, _, _) = fault("  n := LINT_TO_INT(STRING_TO_LINT('-99999999999999999999999'));");
    assert_eq!(f, Fault::OutOfRange);
    // Durations: no unit, an unknown one, nothing after the prefix, beyond TIME's 32 bits.
    for text in ["T#12", "T#1x", "T#", "T#-", "5 s", "T#.5s", "T#1.2.3s"] {
        let (f, _, _) = fault(&format!("  n := TIME_TO_INT(STRING_TO_TIME('{text}'));"));
        assert_eq!(f, Fault::NoNumber, "{text}");
    }
    for text in ["T#25d", "T#-25d"] {
        let (f, _, _) = fault(&format!("  n := TIME_TO_INT(STRING_TO_TIME('{text}'));"));
        assert_eq!(f, Fault::OutOfRange, "{text}");
    }
    for text in ["LTIME#107000d", "LTIME#1234567890123456789012h"] {
        let (f, _, _) = fault(&format!(
            "  n := LINT_TO_INT(LTIME_TO_LINT(STRING_TO_LTIME('{text}')));"
        ));
        assert_eq!(f, Fault::OutOfRange, "{text}");
    }
    // A REAL beyond REAL's range (computed in LREAL) as text.
    let (f, _, _) = fault("  s := REAL_TO_STRING(REAL#1.0E30 * REAL#1.0E30);");
    assert_eq!(f, Fault::OutOfRange);
}

#[test]
fn values_are_taken_in_their_order_and_long_lengths_reach_the_end() {
    let before = "VAR_GLOBAL g : INT; END_VAR
FUNCTION Bump : INT g := g + 1; Bump := g; END_FUNCTION
";
    let vars = "    s : STRING(20) := 'Hello';
    u : UDINT := 3000000000;
    b : LINT := 4294967296;";
    let body = "
    (* INSERT's and REPLACE's second STRING before their numbers, as written. *)
    ok1 := INSERT('ab', INT_TO_STRING(Bump()), Bump()) = 'ab1';
    ok2 := REPLACE('abcd', INT_TO_STRING(Bump()), Bump() - 2, Bump() - 3) = 'a3d';
    ok3 := LEFT(s, u) = s AND LEFT(s, b) = s AND MID(s, 1, b + 1) = '' AND RIGHT(s, u) = s;
";
    checks(before, vars, body, 3);
    // The first fault in the values' order is the one named.
    let (f, values, _) = fault("  s := INSERT(s, MID(s, 1, 0), -1);");
    assert_eq!((f, values), (Fault::IndexOutOfRange, [0, 1, 255]));
}

#[test]
fn what_the_string_functions_do_not_take_is_refused_at_load() {
    let program = |body: &str| {
        format!(
            "FUNCTION_BLOCK FB_Name VAR_INPUT sName : STRING(20); END_VAR END_FUNCTION_BLOCK
PROGRAM MAIN
VAR s : STRING(20); n : INT; fb : FB_Name; END_VAR
{body}
END_PROGRAM"
        )
    };
    let e = refused(&program("  s := LEFT(n, 2);"));
    assert!(
        e.contains("main.st:4:13: error: LEFT takes a STRING here, not a INT"),
        "{e}"
    );
    let e = refused(&program("  s := LEFT(s, 'a');"));
    assert!(
        e.contains("LEFT takes an integer of at most 63 bits here, not a STRING(1)"),
        "{e}"
    );
    let e = refused(&program("  s := CONCAT(s);"));
    assert!(e.contains("CONCAT takes 2 to 16 values"), "{e}");
    let e = refused(&program("  s := MID(s, 2);"));
    assert!(e.contains("MID takes 3 values"), "{e}");
    let e = refused(&program("  n := LEN(s) + LEN(n);"));
    assert!(e.contains("LEN takes a STRING here, not a INT"), "{e}");
    let e = refused(&program("  n := STRING_TO_TIME(s);"));
    assert!(e.contains("TIME where INT is wanted"), "{e}");
    let e = refused(&program("  n := CONCAT(s, s);"));
    assert!(
        e.contains("main.st:4:8: error: STRING(40) where INT is wanted"),
        "{e}"
    );
    let e = refused("FUNCTION_BLOCK Concat END_FUNCTION_BLOCK");
    assert!(e.contains("`Concat` is a standard name"), "{e}");
    let e = refused("FUNCTION REAL_TO_STRING : INT REAL_TO_STRING := 1; END_FUNCTION");
    assert!(e.contains("`REAL_TO_STRING` is a standard name"), "{e}");
    let e = refused(&program("  s := USINT_TO_STRING(300);"));
    assert!(
        e.contains("main.st:4:24: error: 300 does not fit a USINT"),
        "{e}"
    );
    let e = refused(&program("  s := LEFT(s, ULINT#3);"));
    assert!(
        e.contains("LEFT takes an integer of at most 63 bits here, not a ULINT"),
        "{e}"
    );
}

/// FUNCTIONs that take STRINGs and whose value is a STRING (TwinCAT's `F_Name : STRING`).
const FUNCTIONS: &str = "VAR_GLOBAL nTicks : INT; END_VAR
FUNCTION F_Name : STRING
VAR_INPUT sBase : STRING; nPart : UINT; sExt : STRING(8); END_VAR
    F_Name := CONCAT(sBase, '_', UINT_TO_STRING(nPart), sExt);
END_FUNCTION
FUNCTION F_Short : STRING(3)
VAR_INPUT s : STRING(10); END_VAR
    F_Short := LEFT(s, 10);
END_FUNCTION
FUNCTION F_Tick : STRING
    nTicks := nTicks + 1;
    F_Tick := INT_TO_STRING(nTicks);
END_FUNCTION
FUNCTION F_Both : STRING
VAR_INPUT s : STRING; n : INT; END_VAR
    F_Both := CONCAT(s, '/', INT_TO_STRING(n));
END_FUNCTION
";

#[test]
fn functions_take_strings_and_give_them() {
    let vars = "    s : STRING(80);
    sBase : STRING(20) := 'abc';
    sShort : STRING(4);
    n : UINT := 3;";
    let body = "
    ok1 := F_Name('part', 7, '.nc') = 'part_7.nc';
    s := F_Name(sExt := '.st', nPart := n, sBase := sBase);
    ok2 := s = 'abc_3.st';
    ok3 := F_Name(CONCAT('a', 'b'), 1, '') = 'ab_1';
    ok4 := F_Name(F_Name('x', 1, ''), 2, '.nc') = 'x_1_2.nc';
    ok5 := F_Name('a', 1, '') <> F_Name('b', 1, '') AND F_Name('a', 1, '') = F_Name('a', 1, '');
    ok6 := LEN(F_Short('abcdef')) = 3 AND F_Short('abcdef') = 'abc';
    sShort := F_Name('abcdef', 1, '');
    ok7 := sShort = 'abcd';
    ok8 := CONCAT(F_Name('a', 1, ''), F_Name('b', 2, '')) = 'a_1b_2';
    (* The values in their order: the STRING's call before the INT it changes. *)
    ok9 := F_Both(F_Tick(), nTicks) = '1/1' AND F_Both(n := nTicks, s := F_Tick()) = '2/1';
    ok10 := F_Short(s) = 'abc' AND STRING_TO_INT(F_Tick()) = 3;
    (* A call as a statement, for what it does. *)
    F_Tick();
    CONCAT(F_Tick(), 'x');
    LEN(F_Tick());
    FIND(s, 'b');
    ok11 := nTicks = 6;";
    let vars = vars.replace("s : STRING(80);", "s : STRING(10);");
    checks(FUNCTIONS, &vars, body, 11);
}

#[test]
fn what_a_function_cannot_take_as_a_string_is_refused_at_load() {
    let program = |body: &str| {
        format!(
            "{FUNCTIONS}FUNCTION_BLOCK FB_Name VAR_INPUT sName : STRING(20); n : INT; END_VAR END_FUNCTION_BLOCK
FUNCTION F_Five : INT
VAR_INPUT a, b, c, d : STRING(4); e : STRING(4) := 'e'; END_VAR
    F_Five := 5;
END_FUNCTION
PROGRAM MAIN
VAR sLong : STRING(20); s : STRING(80); n : INT; fb : FB_Name; fbs : ARRAY[0..1] OF FB_Name; END_VAR
{body}
END_PROGRAM"
        )
    };
    let e = refused(&program("  s := F_Short(sLong);"));
    assert!(
        e.contains("main.st:25:16: error: a STRING(20) into a STRING(10): it may not fit"),
        "{e}"
    );
    let e = refused(&program("  s := F_Short('abcdefghijk');"));
    assert!(
        e.contains("main.st:25:16: error: 'abcdefghijk' has 11 characters: a STRING(10) holds 10"),
        "{e}"
    );
    let e = refused(&program("  n := F_Five('a', 'b', 'c', 'd', 'e');"));
    assert!(e.contains("a call with more than 4 STRING values"), "{e}");
    let e = refused(&program(
        "  fbs[n](sName := F_Short('a'), n := F_Five('a', 'b', 'c', 'd'));",
    ));
    assert!(
        e.contains("main.st:25:3: error: a computed STRING input of an instance at a computed place beside inputs that call a function"),
        "{e}"
    );
    let e = refused(&program("  s := F_Short(n);"));
    assert!(
        e.contains("main.st:25:16: error: INT where STRING(10) is wanted"),
        "{e}"
    );
    let e = refused(&program("  n := F_Short('a');"));
    assert!(
        e.contains("main.st:25:8: error: STRING(3) where INT is wanted"),
        "{e}"
    );
}

#[test]
fn a_computed_string_goes_to_a_block_input() {
    let before = format!(
        "{FUNCTIONS}FUNCTION_BLOCK FB_Echo
VAR_INPUT sIn : STRING(12); nIn : INT; END_VAR
VAR_OUTPUT sOut : STRING(12); nOut : INT; END_VAR
    sOut := sIn;
    nOut := nIn;
END_FUNCTION_BLOCK
"
    );
    let vars = "    fb : FB_Echo;
    fbs : ARRAY[0..1] OF FB_Echo;
    k : INT := 1;
    s2 : STRING(12);";
    let body = "
    fb(sIn := CONCAT('part_', INT_TO_STRING(k), '.nc'), nIn := k + 1);
    ok1 := fb.sOut = 'part_1.nc' AND fb.nOut = 2 AND fb.sIn = 'part_1.nc';
    fb(sIn := F_Name('abcdefgh', 12, '.nc'));
    ok2 := fb.sOut = 'abcdefgh_12.' AND fb.nOut = 2;
    fbs[k](sIn := LEFT('xyz', 2), sOut => s2);
    ok3 := fbs[1].sOut = 'xy' AND s2 = 'xy' AND fbs[0].sOut = '';
    fb(sIn := 'abc', sOut => sLong);
    ok4 := sLong = 'abc';
    (* The inputs in their order: nIn reads the STRING input before the call stores it. *)
    fb(nIn := LEN(fb.sIn), sIn := CONCAT('x', 'y'));
    ok5 := fb.nOut = 3 AND fb.sOut = 'xy';
    fb(sIn := F_Name('a', 1, ''), nIn := STRING_TO_INT(F_Tick()) + LEN(fb.sIn));
    ok6 := fb.sOut = 'a_1' AND fb.nOut = 4 AND nTicks = 1;";
    checks(
        &before,
        &vars.replace("s2 :", "sLong : STRING(40);\n    s2 :"),
        body,
        6,
    );
    let text = format!(
        "{before}PROGRAM MAIN VAR fb : FB_Echo; s : STRING(5); END_VAR
    fb(sIn := 'a', sOut => s);
END_PROGRAM"
    );
    let e = refused(&text);
    assert!(
        e.contains("main.st:25:28: error: a STRING(12) output into a STRING(5)"),
        "{e}"
    );
}

/// After the load, a cycle that computes strings allocates nothing.
#[test]
fn a_cycle_with_strings_allocates_nothing() {
    let mut p = load(&format!(
        "{FUNCTIONS}PROGRAM MAIN
VAR s : STRING(80); n : DINT; k : INT; bLess : BOOL; END_VAR
    n := n + 1;
    s := CONCAT('part_', DINT_TO_STRING(n), '.nc');
    s := REPLACE(INSERT(s, LEFT('xyz', 2), 5), 'P', 1, 1);
    k := FIND(s, '.nc') + LEN(MID(s, 3, 2)) + STRING_TO_INT(RIGHT('a42', 2));
    bLess := DELETE(s, 1, 1) < s;
    k := k + LEN(F_Name(s, 7, '.nc')) - LEN(s) - 5;
    k := k + DINT_TO_INT(TIME_TO_DINT(STRING_TO_TIME('T#1m_1s')) - 61000);
END_PROGRAM"
    ));
    p.cycle(0).unwrap();
    let before = counting_alloc::allocations();
    for k in 1..1000 {
        p.cycle(k * 1_000_000).unwrap();
    }
    assert_eq!(counting_alloc::allocations() - before, 0);
    // 'Part_xy1000.nc': '.nc' at 12, 'art' 3 characters, 42.
    assert_eq!(p.read_var("MAIN.k"), Some(12.0 + 3.0 + 42.0));
}
