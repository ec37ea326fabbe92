//! An OPC UA server over the HLI image.
//!
//! It attaches to a running CNC's segment read-only, the way `plc watch` does (never the PLC
//! slot, never the tick), and serves every node of the image's symbol table under its ST path:
//! structs and arrays as folders, leaves as variables of the OPC UA type that matches their ST
//! type. A value is read from the image when a client reads it or a subscription samples it
//! (leaf-wise atomic loads); while no CNC serves the image, values answer
//! `BadNoCommunication`.

#![forbid(unsafe_code)]

use hli::access::{Leaf, Value};
use hli::desc::Scalar;
use hli::symbols::{SymbolKind, SymbolTable};
use hli::ImageMemory;
use opcua::server::address_space::AccessLevel;
use opcua::server::node_manager::memory::{
    simple_node_manager, InMemoryNodeManager, SimpleNodeManagerImpl,
};
use opcua::server::{Server, ServerBuilder, ServerHandle};
use opcua::types::{DataTypeId, DataValue, DateTime, NodeId, ObjectId, StatusCode, Variant};
use std::sync::Arc;

/// The namespace of the image's nodes.
pub const NAMESPACE: &str = "urn:cnc-plc-runtime:hli";

/// Where the served values come from.
pub trait ImageSource: Send + Sync + 'static {
    /// The image while a CNC serves it, else `None`.
    fn image(&self) -> Option<&ImageMemory>;
}

impl ImageSource for ImageMemory {
    fn image(&self) -> Option<&ImageMemory> {
        Some(self)
    }
}

impl ImageSource for hli::segment::PlcSegment {
    fn image(&self) -> Option<&ImageMemory> {
        (self.cnc_state() == Ok(hli::enums::SegmentState::Ready)).then(|| self.memory())
    }
}

/// Why the server could not be built.
#[derive(Debug)]
pub struct BuildError(pub String);

impl std::fmt::Display for BuildError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "OPC UA server: {}", self.0)
    }
}

impl std::error::Error for BuildError {}

/// The server on `port` (all interfaces), anonymous and read-only, its address space built
/// from the symbol table and read from `source`. Run it with `server.run().await`; the handle
/// stops it (`cancel`).
pub fn build(
    source: Arc<dyn ImageSource>,
    port: u16,
    pki_dir: &std::path::Path,
) -> Result<(Server, ServerHandle), BuildError> {
    let (server, handle) = ServerBuilder::new_anonymous("cnc-plc-runtime HLI")
        .application_uri("urn:cnc-plc-runtime:opcua")
        .product_uri("urn:cnc-plc-runtime")
        .host("0.0.0.0")
        .port(port)
        .pki_dir(pki_dir)
        .create_sample_keypair(true)
        .max_sessions(16)
        .with_node_manager(simple_node_manager(
            opcua::server::diagnostics::NamespaceMetadata {
                namespace_uri: NAMESPACE.to_owned(),
                ..Default::default()
            },
            "hli",
        ))
        .build()
        .map_err(BuildError)?;
    let manager = handle
        .node_managers()
        .get_of_type::<InMemoryNodeManager<SimpleNodeManagerImpl>>()
        .ok_or_else(|| BuildError("no node manager".into()))?;
    let ns = handle
        .get_namespace_index(NAMESPACE)
        .ok_or_else(|| BuildError("no namespace".into()))?;
    populate(&manager, ns, &source);
    Ok((server, handle))
}

/// The OPC UA type of an ST type.
pub fn data_type(scalar: Scalar) -> DataTypeId {
    match scalar {
        Scalar::Bool => DataTypeId::Boolean,
        Scalar::Usint => DataTypeId::Byte,
        Scalar::Sint => DataTypeId::SByte,
        Scalar::Uint => DataTypeId::UInt16,
        Scalar::Int => DataTypeId::Int16,
        Scalar::Udint => DataTypeId::UInt32,
        Scalar::Dint => DataTypeId::Int32,
        Scalar::Ulint => DataTypeId::UInt64,
        Scalar::Lint => DataTypeId::Int64,
        Scalar::Real => DataTypeId::Float,
        Scalar::Lreal => DataTypeId::Double,
    }
}

/// A leaf's raw value as the variant of its OPC UA type (the image holds it in range).
pub fn variant(scalar: Scalar, value: Value) -> Variant {
    let (i, u, r) = match value {
        Value::Int(i) => (i, i as u64, i as f64),
        Value::Unsigned(u) => (u as i64, u, u as f64),
        Value::Real(r) => (r as i64, r as u64, r),
    };
    match scalar {
        Scalar::Bool => Variant::Boolean(u != 0),
        Scalar::Usint => Variant::Byte(u as u8),
        Scalar::Sint => Variant::SByte(i as i8),
        Scalar::Uint => Variant::UInt16(u as u16),
        Scalar::Int => Variant::Int16(i as i16),
        Scalar::Udint => Variant::UInt32(u as u32),
        Scalar::Dint => Variant::Int32(i as i32),
        Scalar::Ulint => Variant::UInt64(u),
        Scalar::Lint => Variant::Int64(i),
        Scalar::Real => Variant::Float(r as f32),
        Scalar::Lreal => Variant::Double(r),
    }
}

/// The last part of an ST path (`gpCh[0]^channel_mc_control.dyn_cs` -> `dyn_cs`,
/// `...translation[1]` -> `[1]`).
fn browse_name(path: &str) -> &str {
    let cut =
        path.rfind(['.', '^', '['])
            .map_or(0, |i| if path.as_bytes()[i] == b'[' { i } else { i + 1 });
    &path[cut..]
}

/// Whether `child` lies under `parent` in the tree of ST paths.
fn is_under(child: &str, parent: &str) -> bool {
    child.len() > parent.len()
        && child.starts_with(parent)
        && matches!(child.as_bytes()[parent.len()], b'.' | b'^' | b'[')
}

/// Folders for the struct and array nodes, variables for the leaves, each leaf read from
/// `source` on demand.
fn populate(
    manager: &InMemoryNodeManager<SimpleNodeManagerImpl>,
    ns: u16,
    source: &Arc<dyn ImageSource>,
) {
    let root = NodeId::new(ns, "HLI");
    let objects: NodeId = ObjectId::ObjectsFolder.into();
    let mut space = manager.address_space().write();
    space.add_folder(&root, "HLI", "HLI", &objects);
    // The symbols come parents first: a stack of the open folders finds each one's parent.
    let mut open: Vec<(&str, NodeId)> = Vec::new();
    for symbol in SymbolTable::global().symbols() {
        let path = symbol.path.as_str();
        while open.last().is_some_and(|(p, _)| !is_under(path, p)) {
            open.pop();
        }
        let parent = open.last().map_or(root.clone(), |(_, id)| id.clone());
        let id = NodeId::new(ns, path);
        let name = browse_name(path);
        match symbol.kind {
            SymbolKind::Struct | SymbolKind::Array => {
                space.add_folder(&id, name, name, &parent);
                open.push((path, id));
            }
            SymbolKind::Leaf(scalar) => {
                opcua::server::address_space::VariableBuilder::new(&id, name, name)
                    .data_type(data_type(scalar))
                    .value(variant(scalar, Value::Unsigned(0)))
                    .access_level(AccessLevel::CURRENT_READ)
                    .user_access_level(AccessLevel::CURRENT_READ)
                    .organized_by(parent)
                    .insert(&mut *space);
                let leaf = Leaf {
                    offset: symbol.offset,
                    scalar,
                    writer: symbol.writer,
                };
                let source = Arc::clone(source);
                manager
                    .inner()
                    .add_read_callback(id, move |_, _, _| Ok(read(&*source, &leaf)));
            }
        }
    }
}

/// A leaf's value now, or `BadNoCommunication` while no CNC serves the image.
fn read(source: &dyn ImageSource, leaf: &Leaf) -> DataValue {
    match source.image() {
        Some(image) => DataValue::new_at(variant(leaf.scalar, leaf.read(image)), DateTime::now()),
        None => DataValue {
            value: None,
            status: Some(StatusCode::BadNoCommunication),
            source_timestamp: Some(DateTime::now()),
            ..Default::default()
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn browse_names_are_the_last_part_of_the_path() {
        assert_eq!(browse_name("gpCh[0]^channel_mc_control.dyn_cs"), "dyn_cs");
        assert_eq!(browse_name("gpCh[0]"), "[0]");
        assert_eq!(
            browse_name("gpCh[0]^channel_mc_control"),
            "channel_mc_control"
        );
        assert_eq!(browse_name("header"), "header");
        assert!(is_under("gpCh[0]^x", "gpCh[0]"));
        assert!(!is_under("gpCh[10]", "gpCh[1]"));
    }
}
