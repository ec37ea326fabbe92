//! The server against async-opcua's own client, in process over an image in memory: leaves
//! read with their ST type's OPC UA type, scaled siblings and summary objects in engineering
//! units, source timestamps from the CNC's tick, the tree browses from the HLI folder, writes
//! only by a logged-in user on configured leaves and by the handshake rules, limits on
//! sessions and subscriptions, BadNoCommunication without a CNC.

use cnc_opcua::config::{Config, Limits, User};
use cnc_opcua::{build, ImageSource, Options, NAMESPACE};
use hli::access::{Leaf, Value};
use hli::image::heap_image;
use hli::layout::image::HliSegmentHeader;
use hli::ImageMemory;
use opcua::client::Session;
use opcua::types::{
    BrowseDescription, BrowseDirection, DataValue, DateTime, NodeId, ReferenceTypeId, StatusCode,
    Variant, WriteValue,
};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;
use support::{connect, free_port, read, try_connect, Login};

mod support;

/// The image, present or not (as when the CNC stops).
struct Switchable {
    image: ImageMemory,
    present: AtomicBool,
}

impl ImageSource for Switchable {
    fn with_image(&self, f: &mut dyn FnMut(&ImageMemory)) -> bool {
        let present = self.present.load(Ordering::Acquire);
        if present {
            f(&self.image);
        }
        present
    }
}

const POSITION: &str = "gpAx[1]^lr_state.command_position_acs_r";
const FEED: &str = "gpCh[0]^channel_mc_control.path_override.feed_override_w";
const PAYLOAD: &str = "gpCh[0]^channel_mc_control.dyn_cs.command_w.translation[0]";
const SEMAPHORE: &str = "gpCh[0]^channel_mc_control.dyn_cs.command_semaphore_rw";

fn config(limits: Limits) -> Config {
    Config {
        users: vec![User {
            name: "operator".into(),
            password: "s3cret".into(),
        }],
        writable: vec![FEED.into(), PAYLOAD.into(), SEMAPHORE.into()],
        trust_client_certificates: true,
        limits,
        ..Config::default()
    }
}

/// A server over `source` on a free port: its port, namespace, handle and task.
struct Served {
    port: u16,
    ns: u16,
    handle: opcua::server::ServerHandle,
    task: tokio::task::JoinHandle<Result<(), String>>,
    dir: std::path::PathBuf,
}

fn serve(source: Arc<dyn ImageSource>, config: Config, tag: &str) -> Served {
    let dir = std::env::temp_dir().join(format!("cnc-opcua-{tag}-{}", std::process::id()));
    let port = free_port();
    let options = Options {
        port,
        pki_dir: dir.join("server"),
        config,
    };
    let (server, handle) = build(source, &options).unwrap();
    let ns = handle.get_namespace_index(NAMESPACE).unwrap();
    let task = tokio::spawn(server.run());
    Served {
        port,
        ns,
        handle,
        task,
        dir,
    }
}

impl Served {
    async fn stop(self, sessions: &[&Arc<Session>]) {
        for s in sessions {
            let _ = s.disconnect().await;
        }
        self.handle.cancel();
        self.task.await.unwrap().unwrap();
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

async fn write(session: &Session, id: NodeId, value: Variant) -> StatusCode {
    let w = WriteValue {
        node_id: id,
        attribute_id: opcua::types::AttributeId::Value as u32,
        index_range: Default::default(),
        value: DataValue::value_only(value),
    };
    session.write(&[w]).await.unwrap()[0]
}

async fn with_watchdog<F: std::future::Future<Output = ()>>(f: F) {
    tokio::time::timeout(Duration::from_secs(90), f)
        .await
        .expect("watchdog")
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_client_reads_leaves_in_units_with_tick_stamps_browses_and_sees_the_cnc_go() {
    with_watchdog(reads()).await;
}

async fn reads() {
    let source = Arc::new(Switchable {
        image: heap_image(2, 8),
        present: AtomicBool::new(true),
    });
    let leaf = Leaf::resolve(POSITION).unwrap();
    leaf.write(&source.image, Value::Int(123_456));
    // Heartbeat 2,500 of a 1 ms CNC whose heartbeat 0 was due at 2026-01-01T00:00:00Z.
    let header = |field| source.image.place::<u64>(field);
    header(core::mem::offset_of!(HliSegmentHeader, cnc_epoch_ns))
        .store_release(1_767_225_600 * 1_000_000_000);
    header(core::mem::offset_of!(HliSegmentHeader, cnc_heartbeat)).store_release(2_500);
    let served = serve(source.clone(), Config::default(), "reads");
    let session = connect(served.port, &served.dir.join("client")).await;
    let ns = served.ns;

    // The leaf, with the OPC UA type of its ST type, dated by its tick.
    let id = NodeId::new(ns, POSITION);
    let value = read(&session, &id).await;
    assert_eq!(value.value, Some(Variant::Int32(123_456)));
    let tick = DateTime::from((2026, 1, 1, 0, 0, 2, 500_000_000));
    assert_eq!(value.source_timestamp, Some(tick));
    // Beside it, in millimetres, with its unit; and in the axis's summary.
    let scaled = read(&session, &NodeId::new(ns, format!("{POSITION}_scaled"))).await;
    assert_eq!(scaled.value, Some(Variant::Double(12.3456)));
    let eu = NodeId::new(ns, format!("{POSITION}_scaled#EngineeringUnits"));
    let eu = format!("{:?}", read(&session, &eu).await);
    assert!(eu.contains("\"mm\"") && eu.contains("5066068"), "{eu}");
    let summary = read(&session, &NodeId::new(ns, "Axes.Axis1.Position")).await;
    assert_eq!(
        summary.value,
        Some(Variant::Double(0.0)),
        "current, not command"
    );
    Leaf::resolve("gpAx[1]^lr_state.current_position_acs_r")
        .unwrap()
        .write(&source.image, Value::Int(-25_000));
    let summary = read(&session, &NodeId::new(ns, "Axes.Axis1.Position")).await;
    assert_eq!(summary.value, Some(Variant::Double(-2.5)));
    let tick_now = read(&session, &NodeId::new(ns, "Machine.Tick")).await;
    assert_eq!(tick_now.value, Some(Variant::UInt64(2_500)));

    // The tree browses from the HLI folder: gpAx, its element [1], lr_state, the leaf.
    let children = |node: &str| {
        let browse = BrowseDescription {
            node_id: NodeId::new(ns, node),
            browse_direction: BrowseDirection::Forward,
            reference_type_id: ReferenceTypeId::Organizes.into(),
            include_subtypes: true,
            node_class_mask: 0,
            result_mask: 0x3f,
        };
        let session = session.clone();
        async move {
            let results = session.browse(&[browse], 1000, None).await.unwrap();
            results[0]
                .references
                .iter()
                .flatten()
                .map(|r| format!("{}:{}", r.browse_name.namespace_index, r.browse_name.name))
                .collect::<Vec<String>>()
        }
    };
    for (node, child) in [
        ("HLI", "gpAx"),
        ("gpAx", "[1]"),
        ("gpAx[1]^", "lr_state"),
        ("gpAx[1]^lr_state", "command_position_acs_r"),
        ("gpAx[1]^lr_state", "command_position_acs_r_scaled"),
    ] {
        // Browse names in the server's namespace, as a browse path names them.
        let names = children(node).await;
        let child = format!("{ns}:{child}");
        assert!(names.contains(&child), "{node}: {child} in {names:?}");
    }
    let axes = children("gpAx").await;
    assert_eq!(
        axes.len(),
        32,
        "one element per axis, each by its index: {axes:?}"
    );

    // The CNC goes: the value answers BadNoCommunication; back, the value again.
    source.present.store(false, Ordering::Release);
    let value = read(&session, &id).await;
    assert_eq!(value.status, Some(StatusCode::BadNoCommunication));
    source.present.store(true, Ordering::Release);
    assert_eq!(
        read(&session, &id).await.value,
        Some(Variant::Int32(123_456))
    );
    served.stop(&[&session]).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn only_a_logged_in_user_writes_and_only_configured_leaves_by_the_handshake() {
    with_watchdog(writes()).await;
}

async fn writes() {
    let source = Arc::new(Switchable {
        image: heap_image(2, 8),
        present: AtomicBool::new(true),
    });
    let image = &source.image;
    let served = serve(source.clone(), config(Limits::default()), "writes");
    let (ns, pki) = (served.ns, served.dir.join("client"));
    let feed = NodeId::new(ns, FEED);

    // Anonymous, on either endpoint: refused.
    let anonymous = connect(served.port, &pki).await;
    let refused = write(&anonymous, feed.clone(), Variant::UInt32(500_000)).await;
    assert_eq!(refused, StatusCode::BadUserAccessDenied);
    let secure = try_connect(served.port, &pki, Login::AnonymousSecure, 20)
        .await
        .unwrap();
    let refused = write(&secure, feed.clone(), Variant::UInt32(500_000)).await;
    assert_eq!(refused, StatusCode::BadUserAccessDenied);
    let before = Leaf::resolve(FEED).unwrap().read(image);

    // A wrong password is no session; the user's is.
    let wrong = try_connect(served.port, &pki, Login::User("operator", "guess"), 0).await;
    assert!(wrong.is_none(), "a wrong password logs in");
    let user = try_connect(served.port, &pki, Login::User("operator", "s3cret"), 20)
        .await
        .expect("the user logs in");
    assert_eq!(Leaf::resolve(FEED).unwrap().read(image), before);
    assert_eq!(
        write(&user, feed.clone(), Variant::UInt32(500_000)).await,
        StatusCode::Good
    );
    assert_eq!(
        Leaf::resolve(FEED).unwrap().read(image),
        Value::Unsigned(500_000)
    );
    // The wrong type, a leaf not opened, a CNC-owned one: refused.
    let wrong_type = write(&user, feed.clone(), Variant::Double(0.5)).await;
    assert_eq!(wrong_type, StatusCode::BadTypeMismatch);
    let rapid = NodeId::new(
        ns,
        "gpCh[0]^channel_mc_control.path_override.rapid_override_w",
    );
    // (async-opcua answers a node without write access BadUserAccessDenied.)
    let denied = StatusCode::BadUserAccessDenied;
    assert_eq!(write(&user, rapid, Variant::UInt32(1)).await, denied);
    let position = NodeId::new(ns, POSITION);
    assert_eq!(write(&user, position, Variant::Int32(1)).await, denied);

    // The handshake: a payload only while its semaphore is FALSE, the semaphore only set.
    let payload = NodeId::new(ns, PAYLOAD);
    let semaphore = NodeId::new(ns, SEMAPHORE);
    assert_eq!(
        write(&user, payload.clone(), Variant::Int32(7_000)).await,
        StatusCode::Good
    );
    assert_eq!(
        write(&user, semaphore.clone(), Variant::Boolean(true)).await,
        StatusCode::Good
    );
    let pending = write(&user, payload.clone(), Variant::Int32(8_000)).await;
    assert_eq!(
        pending,
        StatusCode::BadInvalidState,
        "the CNC has not taken it"
    );
    let clear = write(&user, semaphore.clone(), Variant::Boolean(false)).await;
    assert_eq!(
        clear,
        StatusCode::BadInvalidState,
        "the CNC clears it, not a client"
    );
    assert_eq!(
        Leaf::resolve(PAYLOAD).unwrap().read(image),
        Value::Int(7_000)
    );
    // The CNC takes it: the next datum goes in.
    Leaf::resolve(SEMAPHORE)
        .unwrap()
        .write(image, Value::Unsigned(0));
    assert_eq!(
        write(&user, payload, Variant::Int32(8_000)).await,
        StatusCode::Good
    );
    assert_eq!(
        Leaf::resolve(PAYLOAD).unwrap().read(image),
        Value::Int(8_000)
    );

    // No CNC: nothing is written.
    source.present.store(false, Ordering::Release);
    let gone = write(&user, feed, Variant::UInt32(1)).await;
    assert_eq!(gone, StatusCode::BadNoCommunication);
    served.stop(&[&anonymous, &secure, &user]).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn sessions_and_subscriptions_stop_at_their_limits() {
    with_watchdog(limits()).await;
}

async fn limits() {
    let source: Arc<dyn ImageSource> = Arc::new(heap_image(1, 2));
    let limits = Limits {
        max_sessions: 2,
        max_subscriptions_per_session: 1,
        ..Limits::default()
    };
    let served = serve(source, config(limits), "limits");
    let pki = served.dir.join("client");
    let a = connect(served.port, &pki).await;
    let b = connect(served.port, &pki).await;
    let c = try_connect(served.port, &pki, Login::Anonymous, 0).await;
    assert!(c.is_none(), "a third session");
    let sub = || {
        a.create_subscription(
            Duration::from_millis(100),
            10,
            3,
            0,
            0,
            true,
            opcua::client::DataChangeCallback::new(|_, _| {}),
        )
    };
    sub().await.expect("the first subscription");
    let second = sub().await;
    assert_eq!(second.err(), Some(StatusCode::BadTooManySubscriptions));
    // Once a session ends, another may open.
    let _ = b.disconnect().await;
    let d = try_connect(served.port, &pki, Login::Anonymous, 20).await;
    assert!(d.is_some(), "a session after one closed");
    served.stop(&[&a, &d.unwrap()]).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_subscription_of_more_items_than_a_message_may_hold_delivers_them_all() {
    with_watchdog(many_items()).await;
}

/// 1,500 items that change every 2 ms, sampled every 10 ms and published every 500 ms: each
/// publish holds up to 15,000 changes, far past async-opcua's 327 KB message limit, so the
/// server splits them over messages (`MAX_NOTIFICATIONS_PER_PUBLISH`). 30,000 changes arrive.
async fn many_items() {
    use opcua::client::DataChangeCallback;
    use opcua::types::{MonitoredItemCreateRequest, TimestampsToReturn};
    use std::sync::atomic::AtomicUsize;
    const ITEMS: usize = 1_500;
    const EXPECTED: usize = 20 * ITEMS;
    let source = Arc::new(Switchable {
        image: heap_image(12, 32),
        present: AtomicBool::new(true),
    });
    let leaves: Vec<(String, Leaf)> = hli::symbols::SymbolTable::global()
        .symbols()
        .iter()
        .filter(|s| {
            matches!(
                s.kind,
                hli::symbols::SymbolKind::Leaf(hli::desc::Scalar::Dint)
            )
        })
        .take(ITEMS)
        .map(|s| (s.path.clone(), Leaf::resolve(&s.path).unwrap()))
        .collect();
    assert_eq!(leaves.len(), ITEMS);
    let served = serve(source.clone(), Config::default(), "many");
    let session = connect(served.port, &served.dir.join("client")).await;
    // The "CNC": every leaf takes a new value every 2 ms.
    let writer = {
        let (source, leaves) = (source.clone(), leaves.clone());
        tokio::spawn(async move {
            for k in 0i64.. {
                for (_, leaf) in &leaves {
                    leaf.write(&source.image, Value::Int(k));
                }
                tokio::time::sleep(Duration::from_millis(2)).await;
            }
        })
    };
    let received = Arc::new(AtomicUsize::new(0));
    let (count, all) = (received.clone(), Arc::new(tokio::sync::Notify::new()));
    let done = all.clone();
    let callback = DataChangeCallback::new(move |_, _| {
        if count.fetch_add(1, Ordering::Relaxed) + 1 == EXPECTED {
            done.notify_one();
        }
    });
    let sub = session
        .create_subscription(Duration::from_millis(500), 100, 10, 0, 0, true, callback)
        .await
        .unwrap();
    let items: Vec<MonitoredItemCreateRequest> = leaves
        .iter()
        .map(|(path, _)| {
            let mut item: MonitoredItemCreateRequest = NodeId::new(served.ns, path.as_str()).into();
            item.requested_parameters.sampling_interval = 10.0;
            item.requested_parameters.queue_size = 50;
            item
        })
        .collect();
    // Two requests: one of 1,500 would pass the client's 1,000-element array limit.
    for half in items.chunks(ITEMS / 2) {
        let created = session
            .create_monitored_items(sub, TimestampsToReturn::Both, half.to_vec())
            .await
            .unwrap();
        assert!(created.iter().all(|c| c.result.status_code.is_good()));
    }
    all.notified().await;
    assert!(received.load(Ordering::Relaxed) >= EXPECTED);
    writer.abort();
    served.stop(&[&session]).await;
}
