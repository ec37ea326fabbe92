//! UNION (TwinCAT, CODESYS): fields that share their bytes, little-endian as the program's
//! memory holds them; copied, passed and initialised as a structure is.

use crate::support::{refused, run};

#[test]
fn a_unions_fields_share_their_bytes() {
    let p = run(
        "TYPE U_Word :
UNION
    nRaw : UDINT;
    fValue : REAL;
    aBytes : ARRAY[0..3] OF BYTE;
    wLow : WORD;
END_UNION
END_TYPE
TYPE ST_Frame : STRUCT nId : INT; uData : U_Word; END_STRUCT END_TYPE
FUNCTION F_Low : WORD
VAR_IN_OUT u : U_Word; END_VAR
    F_Low := u.wLow;
    u.aBytes[3] := 16#7F;
END_FUNCTION
PROGRAM MAIN
VAR
    u, v : U_Word;
    stFrame : ST_Frame := (nId := 3, uData := (nRaw := 16#3F800000));
    fOne, fFrame : REAL;
    b0, b3 : BYTE;
    nCopy : UDINT;
    wLow : WORD;
    nSize : UDINT;
END_VAR
    u.nRaw := 16#3F800000;
    fOne := u.fValue;
    u.nRaw := 16#04030201;
    b0 := u.aBytes[0];
    v := u;
    nCopy := v.nRaw;
    wLow := F_Low(v);
    b3 := v.aBytes[3];
    fFrame := stFrame.uData.fValue;
    nSize := SIZEOF(u);
END_PROGRAM",
        1,
    );
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    assert_eq!(var("fOne"), 1.0);
    assert_eq!(var("b0"), 1.0);
    assert_eq!(var("nCopy"), f64::from(0x0403_0201u32));
    assert_eq!(var("wLow"), f64::from(0x0201u16));
    assert_eq!(var("b3"), 127.0);
    assert_eq!(var("fFrame"), 1.0);
    assert_eq!(var("nSize"), 4.0);
}

#[test]
fn a_union_holds_no_block_instance() {
    let e = refused("TYPE U : UNION t : TON; n : DINT; END_UNION END_TYPE");
    assert!(
        e.starts_with("main.st:1:6: error: UNION U: a function block instance shares no bytes"),
        "{e}"
    );
    let e = refused("TYPE U : UNION n : DINT;");
    assert!(e.contains("a UNION without its END_UNION"), "{e}");
}
