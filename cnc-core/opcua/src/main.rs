//! `cnc-opcua --instance NAME [--port 4840] [--pki DIR]`: serves a running CNC's image over
//! OPC UA, read-only and anonymous (`cnc opcua` runs it). SIGINT or SIGTERM end it.

#![forbid(unsafe_code)]

use std::process::ExitCode;
use std::sync::Arc;

fn usage() -> ExitCode {
    eprintln!("usage: cnc-opcua --instance NAME [--port 4840] [--pki DIR]");
    ExitCode::from(2)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (mut instance, mut port, mut pki) = (None, 4840u16, None);
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match (a.as_str(), it.next()) {
            ("--instance", Some(v)) => instance = Some(v.clone()),
            ("--port", Some(v)) => match v.parse() {
                Ok(p) => port = p,
                Err(_) => {
                    eprintln!("cnc-opcua: --port {v}: not a port number");
                    return ExitCode::from(2);
                }
            },
            ("--pki", Some(v)) => pki = Some(std::path::PathBuf::from(v)),
            _ => return usage(),
        }
    }
    let Some(instance) = instance else {
        return usage();
    };
    let segment = match hli::segment::PlcSegment::inspect(&instance) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("cnc-opcua: instance {instance}: {e}");
            return ExitCode::from(3);
        }
    };
    let pki = pki.unwrap_or_else(|| std::env::temp_dir().join(format!("cnc-opcua-{instance}")));
    let runtime = match tokio::runtime::Runtime::new() {
        Ok(r) => r,
        Err(e) => {
            eprintln!("cnc-opcua: {e}");
            return ExitCode::from(1);
        }
    };
    runtime.block_on(serve(Arc::new(segment), port, &pki))
}

async fn serve(
    segment: Arc<hli::segment::PlcSegment>,
    port: u16,
    pki: &std::path::Path,
) -> ExitCode {
    let (server, handle) = match cnc_opcua::build(segment, port, pki) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("cnc-opcua: {e}");
            return ExitCode::from(1);
        }
    };
    let stop = handle.clone();
    tokio::spawn(async move {
        let mut term =
            match tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()) {
                Ok(s) => s,
                Err(_) => return,
            };
        tokio::select! {
            _ = tokio::signal::ctrl_c() => eprintln!("cnc-opcua: SIGINT, stopping"),
            _ = term.recv() => eprintln!("cnc-opcua: SIGTERM, stopping"),
        }
        stop.cancel();
    });
    eprintln!("cnc-opcua: serving on opc.tcp://0.0.0.0:{port}/");
    match server.run().await {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("cnc-opcua: {e}");
            ExitCode::from(1)
        }
    }
}
