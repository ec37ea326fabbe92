//! `cnc-opcua --instance NAME [--port 4840] [--pki DIR] [--config FILE]`: serves a running
//! CNC's image over OPC UA (`cnc opcua` runs it). It attaches again when a new CNC of the
//! instance starts; SIGINT or SIGTERM end it. Exit codes: 0 stopped by a signal, 1 the server
//! failed, 2 bad usage, configuration or port, 3 no CNC of that instance.

#![forbid(unsafe_code)]

use cnc_opcua::source::Change;
use cnc_opcua::{Config, Instance, Options};
use opcua::server::ServerHandle;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Duration;

/// How often the server looks whether its CNC is gone or back.
const REATTACH_EVERY: Duration = Duration::from_millis(200);

const USAGE: &str = "usage: cnc-opcua --instance NAME [--port 4840] [--pki DIR] [--config FILE] \
                     [--end-with-stdin]";

/// The command line.
struct Args {
    instance: String,
    port: Option<u16>,
    pki: Option<PathBuf>,
    config: Option<PathBuf>,
    /// End when stdin closes (a server started beside a run ends with it).
    end_with_stdin: bool,
}

fn parse(args: &[String]) -> Result<Args, String> {
    let (mut instance, mut port, mut pki, mut config) = (None, None, None, None);
    let mut end_with_stdin = false;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        if a == "--end-with-stdin" {
            end_with_stdin = true;
            continue;
        }
        match (a.as_str(), it.next()) {
            ("--instance", Some(v)) => instance = Some(v.clone()),
            ("--port", Some(v)) => {
                port = Some(
                    v.parse()
                        .map_err(|_| format!("--port {v}: not a port number"))?,
                )
            }
            ("--pki", Some(v)) => pki = Some(PathBuf::from(v)),
            ("--config", Some(v)) => config = Some(PathBuf::from(v)),
            _ => return Err(USAGE.into()),
        }
    }
    Ok(Args {
        instance: instance.ok_or(USAGE)?,
        port,
        pki,
        config,
        end_with_stdin,
    })
}

/// The server's nice value: every thread of it yields the CPU to the CNC and the PLC first.
const NICE: i32 = 19;

fn main() -> ExitCode {
    // Before the runtime starts its threads, which inherit it.
    if let Err(e) = cnc_os::realtime::set_nice(NICE) {
        cnc_opcua::say!("nice {NICE}: {e} (runs at the default priority)");
    }
    let argv: Vec<String> = std::env::args().skip(1).collect();
    let args = match parse(&argv) {
        Ok(a) => a,
        Err(e) => return fail(2, &e),
    };
    let config = match &args.config {
        Some(path) => match Config::load(path) {
            Ok(c) => c,
            Err(e) => return fail(2, &format!("configuration refused: {e}")),
        },
        None => Config::default(),
    };
    if let Some(cpu) = config.cpu {
        // Before the runtime starts its threads, which inherit it.
        if let Err(e) = cnc_os::realtime::pin_to_cpu(cpu) {
            return fail(2, &format!("configuration refused: cpu = {cpu}: {e}"));
        }
    }
    let port = args.port.or(config.port).unwrap_or(4840);
    // Bound here and kept: the server says it serves once it listens.
    let listener = match std::net::TcpListener::bind(("0.0.0.0", port)) {
        Ok(l) => l,
        Err(e) => return fail(2, &format!("port {port}: {e}")),
    };
    let instance = match Instance::attach(&args.instance) {
        Ok(i) if i.serves() => Arc::new(i),
        Ok(_) => {
            let why = "the CNC process of its segment cannot be seen running from here \
                       (it ended, or it runs in another PID namespace)";
            return fail(3, &format!("instance {}: {why}", args.instance));
        }
        Err(e) => return fail(3, &format!("instance {}: {e}", args.instance)),
    };
    let pki = args
        .pki
        .unwrap_or_else(|| std::env::temp_dir().join(format!("cnc-opcua-{}", args.instance)));
    let options = Options {
        port,
        pki_dir: pki,
        config,
    };
    match tokio::runtime::Runtime::new() {
        Ok(runtime) => runtime.block_on(serve(instance, options, listener, args.end_with_stdin)),
        Err(e) => fail(1, &e.to_string()),
    }
}

fn fail(code: u8, message: &str) -> ExitCode {
    cnc_opcua::say!("{message}");
    ExitCode::from(code)
}

/// Serves until a signal (or, with `--end-with-stdin`, until stdin closes); reports the CNC
/// going and coming back.
async fn serve(
    instance: Arc<Instance>,
    options: Options,
    listener: std::net::TcpListener,
    end_with_stdin: bool,
) -> ExitCode {
    let listener = match listener
        .set_nonblocking(true)
        .and_then(|()| tokio::net::TcpListener::from_std(listener))
    {
        Ok(l) => l,
        Err(e) => return fail(1, &format!("port {}: {e}", options.port)),
    };
    let source: Arc<dyn cnc_opcua::ImageSource> = instance.clone();
    let (server, handle) = match cnc_opcua::build(source, &options) {
        Ok(s) => s,
        Err(e) => return fail(1, &e.to_string()),
    };
    match stop_on_signal(handle.clone()) {
        Ok(waiting) => drop(tokio::spawn(waiting)),
        Err(e) => return fail(1, &format!("signal handlers: {e}")),
    }
    if end_with_stdin {
        stop_when_stdin_closes(handle);
    }
    tokio::spawn(follow(instance));
    cnc_opcua::say!("serving on opc.tcp://0.0.0.0:{}/", options.port);
    match server.run_with(listener).await {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => fail(1, &e.to_string()),
    }
}

/// Stops the server on SIGINT or SIGTERM, saying which. The handlers are installed before it
/// returns (so before the server says it serves); the returned task waits for them.
fn stop_on_signal(server: ServerHandle) -> std::io::Result<impl std::future::Future<Output = ()>> {
    use tokio::signal::unix::{signal, SignalKind};
    let mut int = signal(SignalKind::interrupt())?;
    let mut term = signal(SignalKind::terminate())?;
    Ok(async move {
        let name = tokio::select! {
            _ = int.recv() => "SIGINT",
            _ = term.recv() => "SIGTERM",
        };
        stop(&server, name);
        tokio::select! {
            _ = int.recv() => {}
            _ = term.recv() => {}
        }
        cnc_opcua::say!("a second signal while stopping: ending at once");
        std::process::exit(1);
    })
}

/// How long the server may take to close its connections once stopped.
const STOP_DEADLINE: Duration = Duration::from_secs(5);

/// Stops the server, saying why; ends the process if it has not stopped within
/// [`STOP_DEADLINE`] (a connection that does not close).
fn stop(server: &ServerHandle, why: &str) {
    cnc_opcua::say!("{why}, stopping");
    server.cancel();
    std::thread::spawn(|| {
        std::thread::sleep(STOP_DEADLINE);
        cnc_opcua::say!("still stopping after {STOP_DEADLINE:?}: ending at once");
        std::process::exit(1);
    });
}

/// Stops the server when stdin reaches its end: the process that started it (and holds the
/// pipe's other end) closed it or ended, even by SIGKILL.
fn stop_when_stdin_closes(server: ServerHandle) {
    std::thread::spawn(move || {
        let mut sink = std::io::sink();
        let _ = std::io::copy(&mut std::io::stdin().lock(), &mut sink);
        stop(&server, "stdin closed (the process that started it ended)");
    });
}

/// Looks every [`REATTACH_EVERY`] whether the CNC went or a new one came; says both.
async fn follow(instance: Arc<Instance>) {
    let mut ready = true;
    loop {
        tokio::time::sleep(REATTACH_EVERY).await;
        match instance.refresh(ready) {
            Change::Same => {}
            Change::Gone => {
                let name = instance.name();
                cnc_opcua::say!(
                    "the CNC of `{name}` stopped; values answer BadNoCommunication until it is back"
                );
                ready = false;
            }
            Change::Back => {
                cnc_opcua::say!("a CNC of `{}` started; attached to it", instance.name());
                ready = true;
            }
        }
    }
}
