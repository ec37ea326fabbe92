//! `cnc-opcua --instance NAME [--port 4840] [--pki DIR] [--config FILE]`: serves a running
//! CNC's image over OPC UA (`cnc opcua` runs it). It attaches again when a new CNC of the
//! instance starts; SIGINT or SIGTERM end it. Exit codes: 0 stopped by a signal, 1 the server
//! failed, 2 bad usage, configuration or port, 3 no CNC of that instance.

#![forbid(unsafe_code)]

use cnc_opcua::source::Change;
use cnc_opcua::{Config, Instance, Options};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Duration;

/// How often the server looks whether its CNC is gone or back.
const REATTACH_EVERY: Duration = Duration::from_millis(200);

const USAGE: &str = "usage: cnc-opcua --instance NAME [--port 4840] [--pki DIR] [--config FILE]";

/// The command line.
struct Args {
    instance: String,
    port: Option<u16>,
    pki: Option<PathBuf>,
    config: Option<PathBuf>,
}

fn parse(args: &[String]) -> Result<Args, String> {
    let (mut instance, mut port, mut pki, mut config) = (None, None, None, None);
    let mut it = args.iter();
    while let Some(a) = it.next() {
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
    })
}

/// The server's nice value: every thread of it yields the CPU to the CNC and the PLC first.
const NICE: i32 = 19;

fn main() -> ExitCode {
    // Before the runtime starts its threads, which inherit it.
    if let Err(e) = cnc_os::realtime::set_nice(NICE) {
        eprintln!("cnc-opcua: nice {NICE}: {e} (runs at the default priority)");
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
    if let Err(e) = std::net::TcpListener::bind(("0.0.0.0", port)) {
        return fail(2, &format!("port {port}: {e}"));
    }
    let instance = match Instance::attach(&args.instance) {
        Ok(i) => Arc::new(i),
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
        Ok(runtime) => runtime.block_on(serve(instance, options)),
        Err(e) => fail(1, &e.to_string()),
    }
}

fn fail(code: u8, message: &str) -> ExitCode {
    eprintln!("cnc-opcua: {message}");
    ExitCode::from(code)
}

/// Serves until a signal; reports the CNC going and coming back.
async fn serve(instance: Arc<Instance>, options: Options) -> ExitCode {
    let source: Arc<dyn cnc_opcua::ImageSource> = instance.clone();
    let (server, handle) = match cnc_opcua::build(source, &options) {
        Ok(s) => s,
        Err(e) => return fail(1, &e.to_string()),
    };
    let stop = handle.clone();
    tokio::spawn(async move {
        let kind = tokio::signal::unix::SignalKind::terminate();
        let Ok(mut term) = tokio::signal::unix::signal(kind) else {
            return;
        };
        tokio::select! {
            _ = tokio::signal::ctrl_c() => eprintln!("cnc-opcua: SIGINT, stopping"),
            _ = term.recv() => eprintln!("cnc-opcua: SIGTERM, stopping"),
        }
        stop.cancel();
    });
    tokio::spawn(async move {
        let mut ready = true;
        loop {
            tokio::time::sleep(REATTACH_EVERY).await;
            match instance.refresh(ready) {
                Change::Same => {}
                Change::Gone => {
                    eprintln!("cnc-opcua: the CNC of `{}` stopped; values answer BadNoCommunication until it is back", instance.name());
                    ready = false;
                }
                Change::Back => {
                    eprintln!(
                        "cnc-opcua: a CNC of `{}` started; attached to it",
                        instance.name()
                    );
                    ready = true;
                }
            }
        }
    });
    eprintln!("cnc-opcua: serving on opc.tcp://0.0.0.0:{}/", options.port);
    match server.run().await {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => fail(1, &e.to_string()),
    }
}
