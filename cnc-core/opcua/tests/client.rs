//! The server against async-opcua's own client: a leaf written into the image reads back
//! through OPC UA with its ST type's OPC UA type; the image's tree browses from the HLI folder;
//! without a CNC the values answer BadNoCommunication.

use cnc_opcua::{build, ImageSource, NAMESPACE};
use hli::access::{Leaf, Value};
use hli::segment::heap_image;
use hli::ImageMemory;
use opcua::client::Session;
use opcua::types::{
    BrowseDescription, BrowseDirection, NodeId, ReadValueId, ReferenceTypeId, StatusCode,
    TimestampsToReturn, Variant,
};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;
use support::{connect, free_port};

mod support;

/// The image, present or not (as when the CNC stops).
struct Switchable {
    image: ImageMemory,
    present: AtomicBool,
}

impl ImageSource for Switchable {
    fn image(&self) -> Option<&ImageMemory> {
        self.present.load(Ordering::Acquire).then_some(&self.image)
    }
}

async fn read(session: &Session, id: &NodeId) -> opcua::types::DataValue {
    let values = session
        .read(
            &[ReadValueId::from(id.clone())],
            TimestampsToReturn::Both,
            0.0,
        )
        .await
        .unwrap();
    values.into_iter().next().unwrap()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_client_reads_leaves_browses_the_tree_and_sees_the_cnc_go() {
    let watchdog = Duration::from_secs(60);
    tokio::time::timeout(watchdog, scenario())
        .await
        .expect("watchdog");
}

async fn scenario() {
    let source = Arc::new(Switchable {
        image: heap_image(2, 8),
        present: AtomicBool::new(true),
    });
    let position = "gpAx[1]^lr_state.command_position_acs_r";
    let leaf = Leaf::resolve(position).unwrap();
    leaf.write(&source.image, Value::Int(123_456));
    let dir = std::env::temp_dir().join(format!("cnc-opcua-test-{}", std::process::id()));
    let port = free_port();
    let (server, handle) = build(source.clone(), port, &dir.join("server")).unwrap();
    let served = tokio::spawn(server.run());
    let session = connect(port, &dir.join("client")).await;
    let ns = handle.get_namespace_index(NAMESPACE).unwrap();

    // The leaf, with the OPC UA type of its ST type.
    let id = NodeId::new(ns, position);
    let value = read(&session, &id).await;
    let expected = cnc_opcua::variant(leaf.scalar, Value::Int(123_456));
    assert_eq!(value.value, Some(expected.clone()));
    assert!(matches!(
        expected,
        Variant::Int32(123_456) | Variant::Double(_)
    ));

    // gpAx[1] browses down to lr_state, which holds the leaf.
    let browse = |node: NodeId| BrowseDescription {
        node_id: node,
        browse_direction: BrowseDirection::Forward,
        reference_type_id: ReferenceTypeId::Organizes.into(),
        include_subtypes: true,
        node_class_mask: 0,
        result_mask: 0x3f,
    };
    let results = session
        .browse(&[browse(NodeId::new(ns, "gpAx[1]^lr_state"))], 1000, None)
        .await
        .unwrap();
    let names: Vec<String> = results[0]
        .references
        .iter()
        .flatten()
        .map(|r| r.browse_name.name.to_string())
        .collect();
    assert!(
        names.iter().any(|n| n == "command_position_acs_r"),
        "{names:?}"
    );

    // The CNC goes: the value answers BadNoCommunication; back, the value again.
    source.present.store(false, Ordering::Release);
    let value = read(&session, &id).await;
    assert_eq!(value.status, Some(StatusCode::BadNoCommunication));
    source.present.store(true, Ordering::Release);
    assert_eq!(read(&session, &id).await.value, Some(expected));

    let _ = session.disconnect().await;
    handle.cancel();
    served.await.unwrap().unwrap();
    let _ = std::fs::remove_dir_all(&dir);
}
