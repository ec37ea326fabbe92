//! `cnc-opcua` as a process beside a CNC's segment: it serves the image, answers
//! BadNoCommunication once the CNC has gone, attaches to a new CNC of the instance, and ends
//! cleanly on SIGTERM, saying why; bad input is refused at start, named.

use hli::access::{Leaf, Value};
use hli::segment::CncSegment;
use opcua::types::{NodeId, StatusCode, Variant};
use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::time::Duration;
use support::{connect, free_port, namespace, read};
use tokio::sync::mpsc::{unbounded_channel, UnboundedReceiver};

mod support;

const PATH: &str = "gpAx[1]^lr_state.command_position_acs_r";

/// The server process and its stderr, line by line.
struct Server {
    child: Child,
    lines: UnboundedReceiver<String>,
    said: Vec<String>,
}

impl Server {
    fn start(args: &[&str]) -> Server {
        let mut child = Command::new(env!("CARGO_BIN_EXE_cnc-opcua"))
            .args(args)
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let stderr = child.stderr.take().unwrap();
        let (tx, lines) = unbounded_channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                let _ = tx.send(line);
            }
        });
        Server {
            child,
            lines,
            said: Vec::new(),
        }
    }

    /// Waits for a line that contains `needle` (the watchdog bounds it).
    async fn expect(&mut self, needle: &str) {
        while let Some(line) = self.lines.recv().await {
            self.said.push(line.clone());
            if line.contains(needle) {
                return;
            }
        }
        panic!("`{needle}` never said: {:?}", self.said);
    }

    /// Waits for the exit; its code and everything said.
    async fn finish(mut self) -> (Option<i32>, Vec<String>) {
        while let Some(line) = self.lines.recv().await {
            self.said.push(line);
        }
        let status = tokio::task::spawn_blocking(move || self.child.wait().unwrap());
        (status.await.unwrap().code(), self.said)
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_server_process_serves_a_cnc_follows_its_restart_and_stops_on_sigterm() {
    tokio::time::timeout(Duration::from_secs(90), scenario())
        .await
        .expect("watchdog");
}

async fn scenario() {
    let instance = format!("opcua-{}", std::process::id());
    let cnc = CncSegment::create(&instance, 2, 8).unwrap();
    let leaf = Leaf::resolve(PATH).unwrap();
    leaf.write(cnc.memory(), Value::Int(-4242));
    let dir = std::env::temp_dir().join(format!("cnc-opcua-process-{}", std::process::id()));
    let port = free_port().to_string();
    let pki = dir.join("server").display().to_string();
    let mut server = Server::start(&["--instance", &instance, "--port", &port, "--pki", &pki]);
    server.expect("serving on").await;

    let session = connect(port.parse().unwrap(), &dir.join("client")).await;
    let id = NodeId::new(namespace(&session).await, PATH);
    assert_eq!(read(&session, &id).await.value, Some(Variant::Int32(-4242)));

    // The CNC stops: its segment closes, the values answer BadNoCommunication.
    drop(cnc);
    let value = read(&session, &id).await;
    assert_eq!(value.status, Some(StatusCode::BadNoCommunication));
    server.expect("stopped").await;

    // A new CNC of the instance: the server attaches to it and serves its values.
    let cnc = CncSegment::create(&instance, 2, 8).unwrap();
    leaf.write(cnc.memory(), Value::Int(777));
    server.expect("attached").await;
    assert_eq!(read(&session, &id).await.value, Some(Variant::Int32(777)));

    let _ = session.disconnect().await;
    let pid = server.child.id().to_string();
    assert!(Command::new("kill")
        .args(["-TERM", &pid])
        .status()
        .unwrap()
        .success());
    let (code, said) = server.finish().await;
    assert_eq!(code, Some(0), "{said:?}");
    assert!(said.iter().any(|l| l.contains("SIGTERM")), "{said:?}");
    drop(cnc);
    let _ = std::fs::remove_dir_all(&dir);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn bad_input_is_refused_at_start_with_its_name() {
    tokio::time::timeout(Duration::from_secs(60), refusals())
        .await
        .expect("watchdog");
}

async fn refusals() {
    let refused = |args: Vec<String>| async move {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        Server::start(&args).finish().await
    };
    let args = |list: &[&str]| list.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let nowhere = format!("opcua-nowhere-{}", std::process::id());
    let port = free_port().to_string();

    let (code, said) = refused(args(&["--instance", &nowhere, "--port", &port])).await;
    assert_eq!(code, Some(3), "{said:?}");
    assert!(said.concat().contains(&nowhere), "{said:?}");

    let taken = std::net::TcpListener::bind("0.0.0.0:0").unwrap();
    let busy = taken.local_addr().unwrap().port().to_string();
    let (code, said) = refused(args(&["--instance", &nowhere, "--port", &busy])).await;
    assert_eq!(code, Some(2), "{said:?}");
    assert!(said.concat().contains(&format!("port {busy}")), "{said:?}");

    let dir = std::env::temp_dir().join(format!("cnc-opcua-refusals-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, text, key) in [
        (
            "leaf.toml",
            "writable = ['gpAx[0]^no_such_leaf']\n[[users]]\nname = 'a'\npassword = 'b'\n",
            "writable[0]",
        ),
        (
            "owned.toml",
            "writable = ['header.cnc_heartbeat']\n[[users]]\nname = 'a'\npassword = 'b'\n",
            "writable[0]",
        ),
        (
            "cert.toml",
            "certificate = '/no/such/dir/cert.der'\nprivate_key = '/no/such/dir/key.pem'\n",
            "certificate",
        ),
    ] {
        let file = dir.join(name);
        std::fs::write(&file, text).unwrap();
        let file = file.display().to_string();
        let (code, said) = refused(args(&["--instance", &nowhere, "--config", &file])).await;
        assert_eq!(code, Some(2), "{name}: {said:?}");
        let said = said.concat();
        assert!(said.contains(&file) && said.contains(key), "{name}: {said}");
    }
    drop(taken);
    let _ = std::fs::remove_dir_all(&dir);
}
