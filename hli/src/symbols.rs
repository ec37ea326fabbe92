//! The symbol table: every struct node, array node and leaf of the image by its ST path, with
//! absolute offset, size, type and writer. Built once from the layout descriptions.
//!
//! Paths follow the controller's spelling: the per-channel and per-axis blocks are reached
//! through pointer arrays, `gpCh[0]^channel_mc_control.dyn_cs.command_w.translation[1]`,
//! `gpAx[6]^lr_state.current_position_acs_r`; the header is `header.magic`.

use crate::desc::{HliType, Kind, Scalar, SymbolWriter, TypeDesc};
use crate::layout::HliImage;
use std::collections::HashMap;
use std::sync::OnceLock;

/// What a symbol is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SymbolKind {
    /// A leaf with an elementary type.
    Leaf(Scalar),
    /// A struct node.
    Struct,
    /// An array node.
    Array,
}

/// One entry of the symbol table.
#[derive(Debug, Clone)]
pub struct Symbol {
    /// ST path.
    pub path: String,
    /// Offset from the start of the image, bytes.
    pub offset: usize,
    /// Size in bytes.
    pub size: usize,
    /// ST type name.
    pub type_name: String,
    /// Who writes it; [`SymbolWriter::Parent`] (printed MIXED) for a node whose leaves differ.
    pub writer: SymbolWriter,
    /// Leaf, struct or array.
    pub kind: SymbolKind,
}

/// All symbols of the image, in memory order (parents before children).
#[derive(Debug)]
pub struct SymbolTable {
    symbols: Vec<Symbol>,
    by_path: HashMap<String, usize>,
    hash: u64,
}

impl SymbolTable {
    /// The table of this build's image layout (built on first use).
    pub fn global() -> &'static SymbolTable {
        static TABLE: OnceLock<SymbolTable> = OnceLock::new();
        TABLE.get_or_init(|| SymbolTable::build(&HliImage::desc()))
    }

    fn build(root: &TypeDesc) -> SymbolTable {
        let mut symbols = Vec::new();
        if let Kind::Struct { fields, .. } = root.kind {
            for field in fields {
                let ty = (field.ty)();
                // The per-channel/axis/FIFO blocks are pointer arrays in the controller: their
                // elements are dereferenced with `^`.
                let deref = field.name.starts_with("gp");
                walk(
                    &mut symbols,
                    field.name.to_string(),
                    field.offset,
                    &ty,
                    own_writer(field.writer, None),
                    deref,
                );
            }
        }
        let by_path = symbols
            .iter()
            .enumerate()
            .map(|(i, s)| (s.path.clone(), i))
            .collect();
        let hash = layout_hash(&symbols);
        SymbolTable {
            symbols,
            by_path,
            hash,
        }
    }

    /// Every symbol, in memory order.
    pub fn symbols(&self) -> &[Symbol] {
        &self.symbols
    }

    /// The symbol at `path`.
    pub fn lookup(&self, path: &str) -> Option<&Symbol> {
        self.by_path.get(path).map(|&i| &self.symbols[i])
    }

    /// FNV-1a hash over every symbol's path, offset, size, type and writer: any change to the
    /// layout changes it.
    pub fn layout_hash(&self) -> u64 {
        self.hash
    }
}

fn own_writer(field: SymbolWriter, inherited: Option<SymbolWriter>) -> Option<SymbolWriter> {
    match field {
        SymbolWriter::Parent => inherited,
        explicit => Some(explicit),
    }
}

fn walk(
    out: &mut Vec<Symbol>,
    path: String,
    offset: usize,
    ty: &TypeDesc,
    writer: Option<SymbolWriter>,
    deref_elements: bool,
) {
    let index = out.len();
    out.push(Symbol {
        path: path.clone(),
        offset,
        size: ty.size,
        type_name: ty.st_name(),
        writer: writer.unwrap_or(SymbolWriter::Parent),
        kind: match ty.kind {
            Kind::Scalar(s) => SymbolKind::Leaf(s),
            Kind::Struct { .. } => SymbolKind::Struct,
            Kind::Array { .. } => SymbolKind::Array,
        },
    });
    match ty.kind {
        Kind::Scalar(_) => {}
        Kind::Struct { fields, .. } => {
            for field in fields {
                let child = (field.ty)();
                let sep = if path.ends_with('^') { "" } else { "." };
                walk(
                    out,
                    format!("{path}{sep}{}", field.name),
                    offset + field.offset,
                    &child,
                    own_writer(field.writer, writer),
                    false,
                );
            }
        }
        Kind::Array { elem, len } => {
            let elem_ty = elem();
            let suffix = if deref_elements { "^" } else { "" };
            for i in 0..len {
                walk(
                    out,
                    format!("{path}[{i}]{suffix}"),
                    offset + i * elem_ty.size,
                    &elem_ty,
                    writer,
                    false,
                );
            }
        }
    }
    // A node with no writer of its own reports one only when all its leaves agree.
    if writer.is_none() {
        let leaves = out[index + 1..]
            .iter()
            .filter(|s| matches!(s.kind, SymbolKind::Leaf(_)));
        let mut writers = leaves.map(|s| s.writer);
        if let Some(first) = writers.next() {
            if writers.all(|w| w == first) {
                out[index].writer = first;
            }
        }
    }
}

fn layout_hash(symbols: &[Symbol]) -> u64 {
    const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
    const FNV_PRIME: u64 = 0x0000_0100_0000_01b3;
    let mut hash = FNV_OFFSET;
    for s in symbols {
        for byte in table_line(s).bytes() {
            hash ^= u64::from(byte);
            hash = hash.wrapping_mul(FNV_PRIME);
        }
    }
    hash
}

/// Formats the table as `PATH OFFSET SIZE TYPE WRITER`, one line per symbol.
pub fn format_table(table: &SymbolTable) -> String {
    let mut out = String::with_capacity(table.symbols().len() * 80);
    for s in table.symbols() {
        out.push_str(&table_line(s));
    }
    out
}

/// A symbol's line of the table, `PATH OFFSET SIZE TYPE WRITER`: what [`format_table`] prints
/// and what the layout hash is taken over.
fn table_line(s: &Symbol) -> String {
    format!(
        "{} {} {} {} {}\n",
        s.path,
        s.offset,
        s.size,
        s.type_name,
        s.writer.label()
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::*;
    use core::mem::{offset_of, size_of};

    fn sym(path: &str) -> &'static Symbol {
        SymbolTable::global()
            .lookup(path)
            .unwrap_or_else(|| panic!("no symbol {path}"))
    }

    #[test]
    fn issue_examples_resolve_to_the_rust_offsets() {
        let ch0 = offset_of!(HliImage, gpCh);
        let dyn_cs = ch0 + offset_of!(HliChannel, channel_mc_control);
        let s = sym("gpCh[0]^channel_mc_control.dyn_cs.command_w.translation[1]");
        assert_eq!(s.offset, dyn_cs + 40 + 4);
        assert_eq!(s.size, 4);
        assert_eq!(s.type_name, "DINT");
        assert_eq!(s.writer, SymbolWriter::Plc);

        let ax6 = offset_of!(HliImage, gpAx) + 6 * size_of::<HliAxis>();
        let s = sym("gpAx[6]^lr_state.current_position_acs_r");
        assert_eq!(s.offset, ax6);
        assert_eq!(s.writer, SymbolWriter::Cnc);
    }

    #[test]
    fn nodes_carry_types_and_writers() {
        let unit = sym("gpCh[3]^channel_mc_control.dyn_cs");
        assert_eq!(unit.type_name, "MC_CONTROL_DYN_CS_UNIT");
        assert_eq!(unit.size, 128);
        assert_eq!(unit.kind, SymbolKind::Struct);
        assert_eq!(unit.writer, SymbolWriter::Parent, "mixed writers");
        assert_eq!(
            sym("gpCh[3]^channel_mc_control.dyn_cs.command_semaphore_rw").writer,
            SymbolWriter::Both
        );
        assert_eq!(
            sym("gpCh[3]^channel_mc_control.dyn_cs.transition_w.command").writer,
            SymbolWriter::Both
        );
        assert_eq!(
            sym("gpCh[3]^channel_mc_control.dyn_cs.transition_w.f_wait").writer,
            SymbolWriter::Plc
        );
        assert_eq!(
            sym("gpCh[3]^channel_mc_control.dyn_cs.request_r").writer,
            SymbolWriter::Cnc
        );
        assert_eq!(
            sym("gpCh[11]^bahn_state.coord_r[31].position_dyncs_r").type_name,
            "DINT"
        );
        assert_eq!(sym("gpAx[31]^enc_in.nStatus4").type_name, "USINT");
        assert_eq!(sym("gpAx[31]^enc_in").writer, SymbolWriter::Io);
        assert_eq!(sym("gpFifo[7]^rows_consumed_r").type_name, "ULINT");
        assert_eq!(
            sym("gpCh[0]^channel_mc_control.dyn_cs.request_r.translation").type_name,
            "ARRAY[0..2]OF(DINT)"
        );
    }

    #[test]
    fn leaves_tile_the_image_without_overlap() {
        let table = SymbolTable::global();
        let mut leaves: Vec<_> = table
            .symbols()
            .iter()
            .filter(|s| matches!(s.kind, SymbolKind::Leaf(_)))
            .collect();
        leaves.sort_by_key(|s| s.offset);
        let mut end = 0;
        for leaf in &leaves {
            assert_eq!(leaf.offset, end, "gap or overlap before {}", leaf.path);
            end = leaf.offset + leaf.size;
        }
        assert_eq!(end, size_of::<HliImage>());
        assert!(table.symbols().len() > 5_000);
        assert!(table.lookup("gpCh[12]^bahn_state").is_none());
    }
}
