//! The address space: every node of the symbol table under `Objects/HLI` (folders for
//! structs and arrays, variables for leaves, a `_scaled` sibling in engineering units where
//! the HLI unit is known), and the summary objects a panel wants at once (`Objects/Machine`,
//! `Objects/Axes`, `Objects/Channels`, `Objects/FifoGroups`).

use crate::source::ImageSource;
use crate::units::{unit_of, Eu};
use crate::value::{self, data_type, variant, Reading};
use hli::access::{Leaf, Value};
use hli::layout::image::HLI_MAX_FIFO_GROUPS;
use hli::symbols::{SymbolKind, SymbolTable};
use opcua::server::address_space::{AccessLevel, AddressSpace, VariableBuilder};
use opcua::server::node_manager::memory::{InMemoryNodeManager, SimpleNodeManagerImpl};
use opcua::types::{
    DataTypeId, EUInformation, ExtensionObject, NodeId, ObjectId, QualifiedName, VariableTypeId,
    Variant,
};
use std::collections::HashSet;
use std::sync::{Arc, Mutex};

/// The node manager the server's nodes live in.
pub type Manager = InMemoryNodeManager<SimpleNodeManagerImpl>;

/// What the address space is built from.
pub struct Plan<'a> {
    /// The namespace index.
    pub ns: u16,
    /// Where values come from.
    pub source: &'a Arc<dyn ImageSource>,
    /// Leaves a logged-in user may write.
    pub writable: &'a HashSet<String>,
    /// Axes in degrees.
    pub rotary: &'a [usize],
    /// Axes and channels the CNC configured (summary objects for these).
    pub axes: usize,
    /// Channels the CNC configured.
    pub channels: usize,
}

/// The last part of an ST path (`gpCh[0]^channel_mc_control.dyn_cs` -> `dyn_cs`,
/// `...translation[1]` -> `[1]`).
pub fn browse_name(path: &str) -> &str {
    // A pointer node (`gpAx[0]^`) is named by its index.
    let path = path.strip_suffix('^').unwrap_or(path);
    let cut =
        path.rfind(['.', '^', '['])
            .map_or(0, |i| if path.as_bytes()[i] == b'[' { i } else { i + 1 });
    &path[cut..]
}

/// Whether `child` lies under `parent` in the tree of ST paths.
pub fn is_under(child: &str, parent: &str) -> bool {
    child.len() > parent.len()
        && child.starts_with(parent)
        && (parent.ends_with('^') || matches!(child.as_bytes()[parent.len()], b'.' | b'^' | b'['))
}

/// Builds every node of `plan` into `manager`.
pub fn populate(manager: &Manager, plan: &Plan<'_>) {
    let mut space = manager.address_space().write();
    image_tree(manager, &mut space, plan);
    summary(manager, &mut space, plan);
}

/// A variable read through `reading` (and written, when `write` names its leaf).
fn variable(
    manager: &Manager,
    space: &mut AddressSpace,
    plan: &Plan<'_>,
    node: (&NodeId, &str, &NodeId),
    reading: Reading,
    write: Option<(String, Leaf)>,
) {
    let (id, name, parent) = node;
    let (data_type, initial) = match &reading {
        Reading::Raw(leaf) => (
            data_type(leaf.scalar),
            variant(leaf.scalar, Value::Unsigned(0)),
        ),
        Reading::Scaled { .. } => (DataTypeId::Double, Variant::Double(0.0)),
        Reading::PlcAlive(_) => (DataTypeId::Boolean, Variant::Boolean(false)),
    };
    let access = if write.is_some() {
        AccessLevel::CURRENT_READ | AccessLevel::CURRENT_WRITE
    } else {
        AccessLevel::CURRENT_READ
    };
    VariableBuilder::new(id, QualifiedName::new(plan.ns, name), name)
        .data_type(data_type)
        .value(initial)
        .access_level(access)
        .user_access_level(access)
        .organized_by(parent.clone())
        .insert(space);
    let source = Arc::clone(plan.source);
    manager
        .inner()
        .add_read_callback(id.clone(), move |_, _, _| {
            Ok(value::read(&*source, &reading))
        });
    if let Some((path, leaf)) = write {
        let source = Arc::clone(plan.source);
        manager
            .inner()
            .add_write_callback(id.clone(), move |data, range| {
                value::write(&*source, &path, leaf, &data, range)
            });
    }
}

/// The `EngineeringUnits` property of `id`.
fn engineering_units(space: &mut AddressSpace, ns: u16, id: &str, eu: Eu) {
    let info = EUInformation {
        namespace_uri: "http://www.opcfoundation.org/UA/units/un/cefact".into(),
        unit_id: eu.unit_id(),
        display_name: eu.symbol().into(),
        description: eu.symbol().into(),
    };
    let property = NodeId::new(ns, format!("{id}#EngineeringUnits"));
    VariableBuilder::new(&property, "EngineeringUnits", "EngineeringUnits")
        .data_type(DataTypeId::EUInformation)
        .value(Variant::from(ExtensionObject::from_message(info)))
        .access_level(AccessLevel::CURRENT_READ)
        .user_access_level(AccessLevel::CURRENT_READ)
        .has_type_definition(VariableTypeId::PropertyType)
        .property_of(NodeId::new(ns, id))
        .insert(space);
}

/// `Objects/HLI`: the symbol table's tree.
fn image_tree(manager: &Manager, space: &mut AddressSpace, plan: &Plan<'_>) {
    let root = NodeId::new(plan.ns, "HLI");
    let objects: NodeId = ObjectId::ObjectsFolder.into();
    space.add_folder(&root, QualifiedName::new(plan.ns, "HLI"), "HLI", &objects);
    // The symbols come parents first: a stack of the open folders finds each one's parent.
    let mut open: Vec<(&str, NodeId)> = Vec::new();
    for symbol in SymbolTable::global().symbols() {
        let path = symbol.path.as_str();
        while open.last().is_some_and(|(p, _)| !is_under(path, p)) {
            open.pop();
        }
        let parent = open.last().map_or(root.clone(), |(_, id)| id.clone());
        let id = NodeId::new(plan.ns, path);
        let name = browse_name(path);
        let SymbolKind::Leaf(scalar) = symbol.kind else {
            space.add_folder(&id, QualifiedName::new(plan.ns, name), name, &parent);
            open.push((path, id));
            continue;
        };
        let leaf = Leaf {
            offset: symbol.offset,
            scalar,
            writer: symbol.writer,
        };
        let write = plan
            .writable
            .contains(path)
            .then(|| (path.to_owned(), leaf));
        variable(
            manager,
            space,
            plan,
            (&id, name, &parent),
            Reading::Raw(leaf),
            write,
        );
        if let Some(unit) = unit_of(path, plan.rotary) {
            let scaled_path = format!("{path}_scaled");
            let scaled = NodeId::new(plan.ns, scaled_path.as_str());
            let name = format!("{name}_scaled");
            let reading = Reading::Scaled {
                leaf,
                per_unit: unit.per_unit,
            };
            variable(
                manager,
                space,
                plan,
                (&scaled, &name, &parent),
                reading,
                None,
            );
            engineering_units(space, plan.ns, &scaled_path, unit.eu);
        }
    }
}

/// One summary variable: its name, its leaf, and (raw increments per unit, unit) when it is
/// served scaled.
struct Item {
    name: &'static str,
    path: String,
    scale: Option<(f64, Eu)>,
}

fn item(name: &'static str, path: String, scale: Option<(f64, Eu)>) -> Item {
    Item { name, path, scale }
}

/// A folder of summary variables at `id` under `parent`.
fn summary_folder(
    manager: &Manager,
    space: &mut AddressSpace,
    plan: &Plan<'_>,
    (id, name, parent): (&str, &str, &NodeId),
    items: Vec<Item>,
) -> NodeId {
    let folder = NodeId::new(plan.ns, id);
    space.add_folder(&folder, QualifiedName::new(plan.ns, name), name, parent);
    for it in items {
        // The paths are this crate's own: the symbol table has them (a test reads them all).
        let Ok(leaf) = Leaf::resolve(&it.path) else {
            continue;
        };
        let node_path = format!("{id}.{}", it.name);
        let node = NodeId::new(plan.ns, node_path.as_str());
        let reading = match it.scale {
            Some((per_unit, _)) => Reading::Scaled { leaf, per_unit },
            None => Reading::Raw(leaf),
        };
        variable(
            manager,
            space,
            plan,
            (&node, it.name, &folder),
            reading,
            None,
        );
        if let Some((_, eu)) = it.scale {
            engineering_units(space, plan.ns, &node_path, eu);
        }
    }
    folder
}

/// The summary objects: the machine, each configured axis and channel, each FIFO group.
fn summary(manager: &Manager, space: &mut AddressSpace, plan: &Plan<'_>) {
    let objects: NodeId = ObjectId::ObjectsFolder.into();
    let machine = vec![
        item("Tick", "header.cnc_heartbeat".into(), None),
        item("CycleUs", "header.cnc_cycle_ns".into(), Some((1e3, Eu::Us))),
        item(
            "LatenessP99Us",
            "header.cnc_late_p99_ns".into(),
            Some((1e3, Eu::Us)),
        ),
        item(
            "LatenessMaxUs",
            "header.cnc_late_max_ns".into(),
            Some((1e3, Eu::Us)),
        ),
    ];
    let folder = summary_folder(
        manager,
        space,
        plan,
        ("Machine", "Machine", &objects),
        machine,
    );
    let alive = NodeId::new(plan.ns, "Machine.PlcAlive");
    let reading = Reading::PlcAlive(Mutex::new(None));
    variable(
        manager,
        space,
        plan,
        (&alive, "PlcAlive", &folder),
        reading,
        None,
    );

    let axes = NodeId::new(plan.ns, "Axes");
    space.add_folder(&axes, QualifiedName::new(plan.ns, "Axes"), "Axes", &objects);
    for i in 0..plan.axes {
        let at = |leaf: &str| format!("gpAx[{i}]^lr_state.{leaf}");
        let unit = |leaf: &str| unit_of(&at(leaf), plan.rotary).map(|u| (u.per_unit, u.eu));
        let items = vec![
            item(
                "Position",
                at("current_position_acs_r"),
                unit("current_position_acs_r"),
            ),
            item(
                "Velocity",
                at("current_velocity_r"),
                unit("current_velocity_r"),
            ),
            item("State", at("axis_state_r"), None),
            item("ErrorId", at("error_id_r"), None),
        ];
        let (id, name) = (format!("Axes.Axis{i}"), format!("Axis{i}"));
        summary_folder(manager, space, plan, (&id, &name, &axes), items);
    }

    let channels = NodeId::new(plan.ns, "Channels");
    let name = QualifiedName::new(plan.ns, "Channels");
    space.add_folder(&channels, name, "Channels", &objects);
    for i in 0..plan.channels {
        let items = vec![
            item(
                "State",
                format!("gpCh[{i}]^channel_control.state_r.state"),
                None,
            ),
            item(
                "Block",
                format!("gpCh[{i}]^bahn_state.active_block_nr_r"),
                None,
            ),
            item(
                "DynCsState",
                format!("gpCh[{i}]^channel_mc_control.dyn_cs.state_r.actual_state"),
                None,
            ),
            item("ErrorId", format!("gpCh[{i}]^bahn_state.error_id_r"), None),
        ];
        let (id, name) = (format!("Channels.Channel{i}"), format!("Channel{i}"));
        summary_folder(manager, space, plan, (&id, &name, &channels), items);
    }

    let groups = NodeId::new(plan.ns, "FifoGroups");
    let name = QualifiedName::new(plan.ns, "FifoGroups");
    space.add_folder(&groups, name, "FifoGroups", &objects);
    for i in 0..HLI_MAX_FIFO_GROUPS {
        let items = vec![
            item("Entries", format!("gpFifo[{i}]^entries_r"), None),
            item("Capacity", format!("gpFifo[{i}]^capacity_r"), None),
            item("State", format!("gpFifo[{i}]^group_state_r"), None),
        ];
        let (id, name) = (format!("FifoGroups.Group{i}"), format!("Group{i}"));
        summary_folder(manager, space, plan, (&id, &name, &groups), items);
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
        // The element of a pointer array holds its unit, named by its index.
        assert_eq!(browse_name("gpAx[3]^"), "[3]");
        assert!(is_under("gpAx[3]^lr_state", "gpAx[3]^"));
        assert!(!is_under("gpAx[3]^lr_state", "gpAx[3]^lr"));
    }

    #[test]
    fn every_summary_path_is_in_the_symbol_table() {
        for path in [
            "header.cnc_heartbeat",
            "header.cnc_cycle_ns",
            "header.cnc_late_p99_ns",
            "header.cnc_late_max_ns",
            "gpAx[31]^lr_state.current_position_acs_r",
            "gpAx[31]^lr_state.current_velocity_r",
            "gpAx[31]^lr_state.axis_state_r",
            "gpAx[31]^lr_state.error_id_r",
            "gpCh[11]^channel_control.state_r.state",
            "gpCh[11]^bahn_state.active_block_nr_r",
            "gpCh[11]^channel_mc_control.dyn_cs.state_r.actual_state",
            "gpCh[11]^bahn_state.error_id_r",
            "gpFifo[7]^entries_r",
            "gpFifo[7]^capacity_r",
            "gpFifo[7]^group_state_r",
        ] {
            assert!(Leaf::resolve(path).is_ok(), "{path}");
        }
    }
}
