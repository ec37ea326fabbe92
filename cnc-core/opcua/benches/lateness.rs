//! Does an OPC UA client slow the CNC? `cnc run` of the demo machine with `--opcua`, in
//! real time, with and without a client subscribed to 1,000 items sampled every 10 ms
//! (interleaved rounds, the same run otherwise): the CNC's tick start lateness p50/p99 from
//! its own report, the medians over the rounds, and the ratio with/without (target: p99 moved
//! by at most 5 %), with `cnc run`'s real-time options (the CNC on CPU 1, the server and the
//! client on CPU 0) and with the default scheduler. Whole processes: the CNC, its PLC and the
//! server (nice 19); the client runs in this process, at nice 19 too (it stands for another
//! computer of the plant). Needs `cnc` built beside this bench (`cargo build --release -p cnc-app`); says so
//! and skips otherwise. `CNC_BENCH_SMOKE=1`: one short round.

use bench_kit::{median, smoke};
use opcua::client::{ClientBuilder, DataChangeCallback, IdentityToken, Session};
use opcua::crypto::SecurityPolicy;
use opcua::types::{
    MessageSecurityMode, MonitoredItemCreateRequest, NodeId, TimestampsToReturn, UserTokenPolicy,
};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

const ITEMS: usize = 1_000;
/// The CNC's CPU in the real-time runs.
const CNC_CPU: usize = 1;
/// The CPU of the server and the client in the real-time runs.
const TOOL_CPU: usize = 0;
const SAMPLING_MS: f64 = 10.0;

/// `cnc run`'s arguments for a real-time run: the benchmarks' real-time options (as
/// tick_latency's) on [`CNC_CPU`], and the server's configuration (see [`config`]).
fn rt_args() -> Option<Vec<String>> {
    let options = plc_shim::realtime::RealtimeOptions {
        cpu: Some(CNC_CPU),
        ..plc_shim::realtime::RealtimeOptions::measured()
    };
    let mut args = options.to_args();
    args.extend(["--opcua-config".to_string(), config()?]);
    Some(args)
}

fn cnc() -> Option<PathBuf> {
    let me = std::env::current_exe().ok()?;
    let cnc = me.parent()?.parent()?.join("cnc");
    cnc.is_file().then_some(cnc)
}

fn scenario() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/demo/scenario.toml")
}

/// The first `ITEMS` leaves of the channels and axes.
fn items(ns: u16) -> Vec<NodeId> {
    hli::symbols::SymbolTable::global()
        .symbols()
        .iter()
        .filter(|s| matches!(s.kind, hli::symbols::SymbolKind::Leaf(_)))
        .filter(|s| s.path.starts_with("gpAx") || s.path.starts_with("gpCh"))
        .take(ITEMS)
        .map(|s| NodeId::new(ns, s.path.as_str()))
        .collect()
}

async fn subscribe(port: u16, pki: &Path, changes: Arc<AtomicU64>) -> Arc<Session> {
    let mut client = ClientBuilder::new()
        .application_name("cnc-opcua lateness bench")
        .application_uri("urn:cnc-opcua-bench")
        .pki_dir(pki)
        .create_sample_keypair(true)
        .trust_server_certs(true)
        .client()
        .unwrap();
    let url = format!("opc.tcp://127.0.0.1:{port}/");
    let endpoint = (
        url.as_str(),
        SecurityPolicy::None.to_str(),
        MessageSecurityMode::None,
        UserTokenPolicy::anonymous(),
    );
    let (session, event_loop) = client
        .connect_to_matching_endpoint(endpoint, IdentityToken::Anonymous)
        .await
        .unwrap();
    event_loop.spawn();
    assert!(session.wait_for_connection().await);
    let ns = session
        .get_namespace_index(cnc_opcua::NAMESPACE)
        .await
        .unwrap();
    let callback = DataChangeCallback::new(move |_, _| {
        changes.fetch_add(1, Ordering::Relaxed);
    });
    let sub = session
        .create_subscription(Duration::from_millis(100), 100, 10, 0, 0, true, callback)
        .await
        .unwrap();
    let requests: Vec<MonitoredItemCreateRequest> = items(ns)
        .into_iter()
        .map(|id| {
            let mut r: MonitoredItemCreateRequest = id.into();
            r.requested_parameters.sampling_interval = SAMPLING_MS;
            r.requested_parameters.queue_size = 10;
            r
        })
        .collect();
    let created = session
        .create_monitored_items(sub, TimestampsToReturn::Both, requests)
        .await
        .unwrap();
    let good = created
        .iter()
        .filter(|c| c.result.status_code.is_good())
        .count();
    if good != ITEMS {
        let first = created.iter().find(|c| !c.result.status_code.is_good());
        println!(
            "{good} of {ITEMS} items monitored; refused: {:?}",
            first.map(|c| c.result.status_code)
        );
    }
    session
}

/// The server's configuration for the real-time runs: pinned to [`TOOL_CPU`].
fn config() -> Option<String> {
    let path = std::env::temp_dir().join(format!("cnc-opcua-bench-{}.toml", std::process::id()));
    std::fs::write(&path, format!("cpu = {TOOL_CPU}\n")).ok()?;
    Some(path.display().to_string())
}

/// One run: (lateness p50, p99 in us, data changes the client received).
fn run(with_client: bool, rt: bool, ticks: u64, tag: &str) -> Option<(f64, f64, u64)> {
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .ok()?
        .local_addr()
        .ok()?
        .port();
    let instance = format!("bench-opcua-{}-{tag}", std::process::id());
    let mut child = Command::new(cnc()?)
        .arg("run")
        .arg(scenario())
        .args(["--ticks", &ticks.to_string(), "--instance", &instance])
        .args(["--opcua", &port.to_string()])
        .args(if rt { rt_args()? } else { Vec::new() })
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .ok()?;
    let mut stderr = BufReader::new(child.stderr.take()?).lines();
    let _serving = stderr.find(|l| l.as_ref().is_ok_and(|l| l.contains("serving on")))?;
    let drain = std::thread::spawn(move || stderr.map_while(Result::ok).count());
    let changes = Arc::new(AtomicU64::new(0));
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .on_thread_start(move || {
            if rt {
                let _ = cnc_os::realtime::pin_to_cpu(TOOL_CPU);
            }
        })
        .build()
        .ok()?;
    let pki = std::env::temp_dir().join(format!("cnc-opcua-bench-{}", std::process::id()));
    let session = with_client.then(|| runtime.block_on(subscribe(port, &pki, changes.clone())));
    let out = child.wait_with_output().ok()?;
    // The server has gone with the run: the session's end is not waited for long.
    if let Some(session) = session {
        let end =
            async { tokio::time::timeout(Duration::from_secs(2), session.disconnect()).await };
        let _ = runtime.block_on(end);
    }
    runtime.shutdown_timeout(Duration::from_secs(1));
    let _ = drain.join();
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text.lines().find(|l| l.contains("start lateness"))?;
    let after = |key: &str| -> Option<f64> {
        let rest = &line[line.find("start lateness")?..];
        let at = rest.find(key)? + key.len();
        rest[at..].split(' ').next()?.parse::<f64>().ok()
    };
    Some((
        after("p50 ")? / 1000.0,
        after("p99 ")? / 1000.0,
        changes.load(Ordering::Relaxed),
    ))
}

fn main() {
    if cnc().is_none() {
        println!("skipped: no cnc binary beside this bench (cargo build --release -p cnc-app)");
        return;
    }
    // The client stands for another computer of the plant: here it shares the CNC's two
    // cores, so it runs at nice 19 as the server does.
    if let Err(e) = cnc_os::realtime::set_nice(19) {
        println!("the client runs at the default priority: nice 19 refused ({e})");
    }
    let (rounds, ticks) = if smoke() { (1, 3_000) } else { (5, 10_000) };
    println!("# OPC UA client against the CNC's tick lateness\n");
    println!("demo machine, {ticks} ticks of 1 ms, {rounds} interleaved rounds; the server runs in every run (nice 19); the client, in this process at nice 19, subscribes to {ITEMS} items sampled every {SAMPLING_MS} ms\n");
    println!("| scheduling | run | lateness p50 us | lateness p99 us | data changes received |\n|---|---|---:|---:|---:|");
    let mut ratios = Vec::new();
    for (rt, name) in [(true, "real-time options"), (false, "default scheduler")] {
        let (mut without, mut with) = (Vec::new(), Vec::new());
        for round in 0..rounds {
            without.extend(run(false, rt, ticks, &format!("a{round}{rt}")));
            with.extend(run(true, rt, ticks, &format!("b{round}{rt}")));
        }
        if without.is_empty() || with.is_empty() {
            println!("the runs did not report their lateness");
            std::process::exit(1);
        }
        let m = |v: &[(f64, f64, u64)], k: usize| {
            median(v.iter().map(|r| [r.0, r.1, r.2 as f64][k]).collect())
        };
        let (a, b) = ((m(&without, 0), m(&without, 1)), (m(&with, 0), m(&with, 1)));
        println!(
            "| {name} | without a client | {:.1} | {:.1} | - |",
            a.0, a.1
        );
        println!(
            "| {name} | with the client | {:.1} | {:.1} | {:.0} |",
            b.0,
            b.1,
            m(&with, 2)
        );
        ratios.push((name, b.1 / a.1));
    }
    println!();
    for (name, ratio) in ratios {
        let verdict = match (smoke(), ratio <= 1.05) {
            (true, _) => "smoke",
            (false, true) => "met",
            (false, false) => "missed",
        };
        println!("TARGET | p99 lateness with / without the client <= 1.05 ({name}) | {ratio:.3} | {verdict}");
    }
}
