//! The image as Structured Text declarations, from the same descriptions as the Rust code and
//! the C header ([`crate::c_header`]): a `TYPE` block with every unit under its ST name
//! (`MC_CONTROL_DYN_CS_UNIT`, `HLI_COORDINATE_SYSTEM_INT`, ...) and a global list with the
//! controller's pointer arrays (`gpCh`, `gpAx`, `gpFifo`), so a PLC program in ST reaches the
//! image as the manuals write it: `pDynCs := ADR(gpCh[0]^.channel_mc_control.dyn_cs);`.

use crate::desc::{HliType, Kind, TypeDesc};
use crate::layout::HliImage;
use std::fmt::Write as _;

/// The declarations' text (an ST file of its own).
pub fn generate() -> String {
    let mut types = String::new();
    let mut emitted: Vec<&'static str> = Vec::new();
    let image = HliImage::desc();
    let Kind::Struct { fields, .. } = image.kind else {
        return String::new();
    };
    let mut globals = String::new();
    for field in fields {
        let ty = (field.ty)();
        let name = field.name;
        if let (true, Kind::Array { elem, len }) = (name.starts_with("gp"), ty.kind) {
            let element = elem();
            emit_struct(&mut types, &element, &mut emitted);
            let _ = writeln!(
                globals,
                "    {name} : ARRAY[0..{}] OF POINTER TO {};",
                len - 1,
                st_type(&element)
            );
        }
    }
    let mut out = String::from(
        "(* The HLI image as ST declarations, generated from the layout descriptions. *)\n",
    );
    let _ = write!(
        out,
        "TYPE\n{types}END_TYPE\n\nVAR_GLOBAL\n{globals}END_VAR\n"
    );
    out
}

/// Who writes each field of each unit: (structure, field, writer), for a checker that refuses
/// a PLC program's write to a field the CNC or the drives write.
pub fn field_writers() -> Vec<(&'static str, &'static str, crate::desc::SymbolWriter)> {
    let mut out = Vec::new();
    let mut seen: Vec<&'static str> = Vec::new();
    collect_writers(&HliImage::desc(), &mut seen, &mut out);
    out
}

fn collect_writers(
    ty: &TypeDesc,
    seen: &mut Vec<&'static str>,
    out: &mut Vec<(&'static str, &'static str, crate::desc::SymbolWriter)>,
) {
    let Kind::Struct { name, fields } = innermost(ty).kind else {
        return;
    };
    if seen.contains(&name) {
        return;
    }
    seen.push(name);
    for field in fields {
        out.push((name, field.name, field.writer));
        collect_writers(&(field.ty)(), seen, out);
    }
}

/// The ST spelling of a type in a declaration.
fn st_type(ty: &TypeDesc) -> String {
    match ty.kind {
        Kind::Scalar(s) => s.st_name().to_string(),
        Kind::Struct { name, .. } => name.to_string(),
        Kind::Array { elem, len } => format!("ARRAY[0..{}] OF {}", len - 1, st_type(&elem())),
    }
}

/// The innermost element type of a (possibly nested) array type, or the type itself.
fn innermost(ty: &TypeDesc) -> TypeDesc {
    match ty.kind {
        Kind::Array { elem, .. } => innermost(&elem()),
        _ => *ty,
    }
}

/// `ty` and the structures it uses, each once, the used ones first.
fn emit_struct(out: &mut String, ty: &TypeDesc, emitted: &mut Vec<&'static str>) {
    let Kind::Struct { name, fields } = ty.kind else {
        return;
    };
    if emitted.contains(&name) {
        return;
    }
    for field in fields {
        emit_struct(out, &innermost(&(field.ty)()), emitted);
    }
    emitted.push(name);
    let _ = writeln!(out, "    {name} :\n    STRUCT");
    for field in fields {
        let _ = writeln!(
            out,
            "        {} : {}; (* offset {}, written by {} *)",
            field.name,
            st_type(&(field.ty)()),
            field.offset,
            field.writer.label()
        );
    }
    out.push_str("    END_STRUCT\n");
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_units_carry_the_manuals_names_and_the_pointer_arrays_are_global() {
        let st = super::generate();
        assert!(
            st.contains("    MC_CONTROL_DYN_CS_UNIT :\n    STRUCT\n"),
            "{st}"
        );
        assert!(st.contains("    HLI_COORDINATE_SYSTEM_INT :\n    STRUCT\n"));
        assert!(st.contains("    gpCh : ARRAY[0..11] OF POINTER TO "));
        assert!(st.contains("    gpAx : ARRAY[0..31] OF POINTER TO "));
        // Each structure once, after the ones it uses.
        let unit = st.find("    MC_CONTROL_DYN_CS_UNIT :").unwrap();
        let cs = st.find("    HLI_COORDINATE_SYSTEM_INT :").unwrap();
        assert!(cs < unit);
        assert_eq!(st.matches("    HLI_COORDINATE_SYSTEM_INT :").count(), 1);
    }

    #[test]
    fn each_field_names_its_writer() {
        use crate::desc::SymbolWriter;
        let writers = super::field_writers();
        let find = |s: &str, f: &str| writers.iter().find(|w| w.0 == s && w.1 == f).map(|w| w.2);
        assert_eq!(
            find("MC_CONTROL_DYN_CS_UNIT", "enable_w"),
            Some(SymbolWriter::Plc)
        );
        assert_eq!(
            find("MC_CONTROL_DYN_CS_UNIT", "state_r"),
            Some(SymbolWriter::Cnc)
        );
    }
}
