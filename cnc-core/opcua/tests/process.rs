//! `cnc-opcua` as a process beside a CNC's segment: it serves the image, answers
//! BadNoCommunication once the CNC has gone, attaches to a new CNC of the instance, and ends
//! cleanly on SIGTERM, saying why; bad input is refused at start, named.

use cnc_opcua::ImageSource;
use hli::access::{Leaf, Value};
use hli_transport::segment::CncSegment;
use opcua::types::{NodeId, StatusCode, Variant};
use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::time::Duration;
use support::{connect, free_port, namespace, read};
use tokio::io::{AsyncBufReadExt, Lines};
use tokio::process::ChildStderr;
use tokio::sync::mpsc::{unbounded_channel, UnboundedReceiver};

mod support;

const PATH: &str = "gpAx[1]^lr_state.command_position_acs_r";

/// The server process and its stderr, line by line.
struct Server {
    child: Child,
    lines: UnboundedReceiver<String>,
    said: Vec<String>,
}

/// How long one awaited line of the server may take.
const STEP_WATCHDOG: Duration = Duration::from_secs(30);

/// A test that fails leaves no server behind.
impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
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

    /// Waits for a line that contains `needle`; a watchdog of [`STEP_WATCHDOG`] names the
    /// step that did not come and what the server said before.
    async fn expect(&mut self, needle: &str) {
        let seen = tokio::time::timeout(STEP_WATCHDOG, async {
            while let Some(line) = self.lines.recv().await {
                self.said.push(line.clone());
                if line.contains(needle) {
                    return true;
                }
            }
            false
        });
        match seen.await {
            Ok(true) => {}
            Ok(false) => panic!("`{needle}` never said; it ended: {:?}", self.said),
            Err(_) => panic!(
                "`{needle}` not said within {STEP_WATCHDOG:?}: {:?}",
                self.said
            ),
        }
    }

    /// Waits for the exit; its code and everything said.
    async fn finish(mut self) -> (Option<i32>, Vec<String>) {
        while let Some(line) = self.lines.recv().await {
            self.said.push(line);
        }
        let said = std::mem::take(&mut self.said);
        let status = tokio::task::spawn_blocking(move || self.child.wait().unwrap());
        (status.await.unwrap().code(), said)
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
    sigterm(server.child.id());
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

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_killed_cnc_is_noticed_and_its_successor_attached() {
    tokio::time::timeout(Duration::from_secs(90), killed())
        .await
        .expect("watchdog");
}

/// The test that plays the CNC process of [`killed`], and its environment variable.
const CNC_ROLE: &str = "a_cnc_process_for_the_kill_test";
const CNC_ROLE_ENV: &str = "CNC_OPCUA_TEST_CNC";

/// Not a test of its own: this binary, run again by [`killed`] with [`CNC_ROLE_ENV`] set to an
/// instance, is its CNC. It creates the instance's segment, says `ready` and waits until it
/// is killed (or its stdin closes). Without the variable it does nothing.
#[test]
fn a_cnc_process_for_the_kill_test() {
    use std::io::Write;
    let Ok(instance) = std::env::var(CNC_ROLE_ENV) else {
        return;
    };
    let _segment = CncSegment::create(&instance, 1, 1).unwrap();
    println!("ready");
    std::io::stdout().flush().unwrap();
    let _ = std::io::stdin().lock().lines().count();
}

/// A CNC process killed with SIGKILL leaves its segment marked Ready: the server must see
/// the process gone, answer BadNoCommunication, and attach to the next CNC.
async fn killed() {
    let instance = format!("opcua-killed-{}", std::process::id());
    // This test binary again, as the CNC (it ends when its stdin closes, so with this test).
    let mut cnc = Command::new(std::env::current_exe().unwrap())
        .args([CNC_ROLE, "--exact", "--nocapture"])
        .env(CNC_ROLE_ENV, &instance)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let out = BufReader::new(cnc.stdout.take().unwrap());
    let ready = tokio::task::spawn_blocking(move || {
        out.lines()
            .map_while(Result::ok)
            .any(|line| line == "ready")
    });
    assert!(ready.await.unwrap(), "the CNC process did not start");
    let dir = std::env::temp_dir().join(format!("cnc-opcua-killed-{}", std::process::id()));
    let port = free_port().to_string();
    let pki = dir.join("server").display().to_string();
    let mut server = Server::start(&["--instance", &instance, "--port", &port, "--pki", &pki]);
    server.expect("serving on").await;
    let session = connect(port.parse().unwrap(), &dir.join("client")).await;
    let tick = NodeId::new(namespace(&session).await, "Machine.Tick");
    assert!(read(&session, &tick)
        .await
        .status
        .is_some_and(|s| s.is_good()));
    // The same source in this process: a write looks at the CNC's process at once, before
    // the periodic look has noticed it gone.
    let here = cnc_opcua::Instance::attach(&instance).unwrap();
    assert!(here.serves() && here.with_image_to_write(&mut |_| {}));

    cnc.kill().unwrap();
    cnc.wait().unwrap();
    assert!(here.with_image(&mut |_| {}), "reads wait for the look");
    assert!(
        !here.with_image_to_write(&mut |_| {}),
        "a write into a dead CNC's image"
    );
    assert!(
        !here.with_image(&mut |_| {}),
        "once a write found it dead, reads too"
    );
    server.expect("stopped").await;
    let value = read(&session, &tick).await;
    assert_eq!(value.status, Some(StatusCode::BadNoCommunication));

    // A server started now finds no CNC: the segment's process is dead.
    let pki_late = dir.join("late").display().to_string();
    let late = free_port().to_string();
    let args = ["--instance", &instance, "--port", &late, "--pki", &pki_late];
    let (code, said) = Server::start(&args).finish().await;
    assert_eq!(code, Some(3), "{said:?}");
    assert!(said.concat().contains("cannot be seen running"), "{said:?}");

    // The next CNC replaces the dead one's segment; the server attaches to it.
    let next = CncSegment::create(&instance, 1, 1).unwrap();
    server.expect("attached").await;
    assert!(read(&session, &tick)
        .await
        .status
        .is_some_and(|s| s.is_good()));

    let _ = session.disconnect().await;
    sigterm(server.child.id());
    let (code, said) = server.finish().await;
    assert_eq!(code, Some(0), "{said:?}");
    drop(next);
    let _ = std::fs::remove_dir_all(&dir);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_server_whose_log_reader_is_gone_still_stops_on_sigterm() {
    tokio::time::timeout(Duration::from_secs(60), deaf())
        .await
        .expect("watchdog");
}

/// The server's stderr is a pipe whose reader closes once it serves: its log lines then
/// fail, which must not keep it from stopping on SIGTERM (the line that says so panicked
/// and ended the task that waits for the signal, before it stopped the server).
async fn deaf() {
    let (cnc, dir, args) = one_cnc("deaf");
    let (mut child, mut lines) = spawn(&args);
    serving(&mut lines).await;
    drop(lines); // the pipe's read end closes
                 // The server says that SIGTERM stops it: into the closed pipe.
    sigterm(child.id().unwrap());
    let status = child.wait().await;
    assert_eq!(status.unwrap().code(), Some(0));
    drop(cnc);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A CNC segment of its own instance (named by `tag`), a directory for the certificates, and
/// the server's arguments for both.
fn one_cnc(tag: &str) -> (CncSegment, std::path::PathBuf, Vec<String>) {
    let instance = format!("opcua-{tag}-{}", std::process::id());
    let cnc = CncSegment::create(&instance, 1, 1).unwrap();
    let dir = std::env::temp_dir().join(format!("cnc-opcua-{tag}-{}", std::process::id()));
    let pki = dir.join("server").display().to_string();
    let port = free_port().to_string();
    let args = ["--instance", &instance, "--port", &port, "--pki", &pki];
    (cnc, dir, args.map(String::from).to_vec())
}

/// The server process, killed when the test fails (the watchdog drops it), its stdin and
/// stderr piped; and its stderr's lines.
fn spawn(
    args: &[String],
) -> (
    tokio::process::Child,
    Lines<tokio::io::BufReader<ChildStderr>>,
) {
    let mut child = tokio::process::Command::new(env!("CARGO_BIN_EXE_cnc-opcua"))
        .args(args)
        .stdin(Stdio::piped())
        .stderr(Stdio::piped())
        .kill_on_drop(true)
        .spawn()
        .unwrap();
    let stderr = child.stderr.take().unwrap();
    (child, tokio::io::BufReader::new(stderr).lines())
}

/// Reads `lines` until the server says it serves.
async fn serving(lines: &mut Lines<tokio::io::BufReader<ChildStderr>>) {
    while let Some(line) = lines.next_line().await.unwrap() {
        if line.contains("serving on") {
            return;
        }
    }
    panic!("the server ended before it served");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_server_started_with_end_with_stdin_ends_when_its_stdin_closes() {
    tokio::time::timeout(Duration::from_secs(60), orphaned())
        .await
        .expect("watchdog");
}

/// `cnc run --opcua` holds the server's stdin: when that process ends, even by SIGKILL, the
/// pipe closes and the server stops (it would otherwise serve on, an orphan).
async fn orphaned() {
    let (cnc, dir, mut args) = one_cnc("orphan");
    args.push("--end-with-stdin".into());
    let (mut child, mut lines) = spawn(&args);
    serving(&mut lines).await;
    drop(child.stdin.take());
    let mut said = Vec::new();
    while let Some(line) = lines.next_line().await.unwrap() {
        said.push(line);
    }
    assert_eq!(child.wait().await.unwrap().code(), Some(0), "{said:?}");
    assert!(said.concat().contains("stdin closed"), "{said:?}");
    drop(cnc);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Sends SIGTERM to the process `pid`.
fn sigterm(pid: u32) {
    let pid = pid.to_string();
    let sent = Command::new("kill").args(["-TERM", &pid]).status().unwrap();
    assert!(sent.success());
}
