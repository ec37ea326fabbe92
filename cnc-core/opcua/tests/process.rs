//! `cnc-opcua` as a process beside a CNC's segment: it serves the image, answers
//! BadNoCommunication once the CNC has gone, and ends cleanly on SIGTERM, saying why.

use hli::access::{Leaf, Value};
use hli::segment::CncSegment;
use opcua::types::{NodeId, ReadValueId, StatusCode, TimestampsToReturn, Variant};
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::time::Duration;
use support::{connect, free_port};

mod support;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_server_process_serves_a_cnc_and_stops_on_sigterm() {
    tokio::time::timeout(Duration::from_secs(60), scenario())
        .await
        .expect("watchdog");
}

async fn scenario() {
    let instance = format!("opcua-{}", std::process::id());
    let cnc = CncSegment::create(&instance, 2, 8).unwrap();
    let path = "gpAx[1]^lr_state.command_position_acs_r";
    let leaf = Leaf::resolve(path).unwrap();
    leaf.write(cnc.memory(), Value::Int(-4242));
    let dir = std::env::temp_dir().join(format!("cnc-opcua-process-{}", std::process::id()));
    let port = free_port();
    let mut child = Command::new(env!("CARGO_BIN_EXE_cnc-opcua"))
        .args([
            "--instance",
            &instance,
            "--port",
            &port.to_string(),
            "--pki",
        ])
        .arg(dir.join("server"))
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Ready when it says it serves.
    let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
    let ready = tokio::task::spawn_blocking(move || {
        let first = lines.next().unwrap().unwrap();
        (first, lines)
    });
    let (first, lines) = ready.await.unwrap();
    assert!(first.contains("serving on"), "{first}");

    let session = connect(port, &dir.join("client")).await;
    let ns = session
        .read(
            &[ReadValueId::from(NodeId::from(
                opcua::types::VariableId::Server_NamespaceArray,
            ))],
            TimestampsToReturn::Neither,
            0.0,
        )
        .await
        .unwrap()[0]
        .value
        .clone();
    let Some(Variant::Array(array)) = ns else {
        panic!("namespace array: {ns:?}");
    };
    let index = array
        .values
        .iter()
        .position(|v| matches!(v, Variant::String(s) if s.as_ref() == cnc_opcua::NAMESPACE))
        .expect("our namespace") as u16;
    let id = NodeId::new(index, path);
    let read = |session: std::sync::Arc<opcua::client::Session>, id: NodeId| async move {
        session
            .read(&[ReadValueId::from(id)], TimestampsToReturn::Both, 0.0)
            .await
            .unwrap()
            .remove(0)
    };
    let value = read(session.clone(), id.clone()).await;
    assert_eq!(
        value.value,
        Some(cnc_opcua::variant(leaf.scalar, Value::Int(-4242)))
    );

    // The CNC stops: its segment closes, the values answer BadNoCommunication.
    drop(cnc);
    let value = read(session.clone(), id.clone()).await;
    assert_eq!(value.status, Some(StatusCode::BadNoCommunication));

    let _ = session.disconnect().await;
    let pid = child.id().to_string();
    assert!(Command::new("kill")
        .args(["-TERM", &pid])
        .status()
        .unwrap()
        .success());
    let (status, said) = tokio::task::spawn_blocking(move || {
        let said: Vec<String> = lines.map_while(Result::ok).collect();
        (child.wait().unwrap(), said)
    })
    .await
    .unwrap();
    assert!(status.success(), "{status:?}: {said:?}");
    assert!(said.iter().any(|l| l.contains("SIGTERM")), "{said:?}");
    let _ = std::fs::remove_dir_all(&dir);
}
