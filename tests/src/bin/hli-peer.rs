//! Child process for the multi-process tests. Modes:
//!
//! * `plc-handshakes INSTANCE N`: attach as PLC; send N commands and read N requests, checking
//!   order and checksums; exit 0 when all N of each were whole and in order.
//! * `cnc-crash INSTANCE`: create the segment, print `ready`, then abort (no cleanup).
//! * `cnc-beat INSTANCE`: create the segment, print `ready`, beat every millisecond until
//!   stdin closes.
//! * `plc-half-block INSTANCE`: send a whole FIFO row block of 10 rows x 3, then loan a
//!   second, write half of it, print `half`, and abort when stdin closes (a PLC dying
//!   mid-write; the test takes the whole block first, so no cleanup of the dead process by
//!   another test's iceoryx2 node can take it away).

#![forbid(unsafe_code)]

use hli::views::PlcView;
use hli_transport::segment::{CncSegment, PlcSegment};
use std::io::{BufRead, Write};
use std::process::ExitCode;

fn main() -> ExitCode {
    hli_transport::init_logging();
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args
        .iter()
        .map(String::as_str)
        .collect::<Vec<_>>()
        .as_slice()
    {
        ["plc-handshakes", instance, n] => plc_handshakes(instance, n.parse().expect("count")),
        ["cnc-crash", instance] => {
            let _segment = CncSegment::create(instance, 1, 1).expect("create");
            println!("ready");
            std::io::stdout().flush().ok();
            std::process::abort();
        }
        ["cnc-beat", instance] => {
            // Its mailbox first, as a CNC makes it; it answers no call.
            let _calls = hli_transport::rpc::AcyclicServer::open(instance).expect("mailbox");
            let segment = CncSegment::create(instance, 1, 1).expect("create");
            println!("ready");
            std::io::stdout().flush().ok();
            let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
            let flag = stop.clone();
            std::thread::spawn(move || {
                let _ = std::io::stdin().lock().lines().count();
                flag.store(true, std::sync::atomic::Ordering::Release);
            });
            while !stop.load(std::sync::atomic::Ordering::Acquire) {
                segment.beat();
                std::thread::sleep(std::time::Duration::from_millis(1));
            }
            ExitCode::SUCCESS
        }
        ["plc-half-block", instance] => {
            let mut client = hli_transport::rpc::AcyclicClient::open(instance).expect("client");
            let header = hli::calls::fifo::rows_header(0, 3, 10, false);
            let whole: Vec<f64> = (0..30).map(f64::from).collect();
            let _sent = client.start_rows(header, &whole).expect("send");
            let mut loan = client.loan_rows(header, 30).expect("loan");
            let half: Vec<f64> = (0..15).map(|i| 100.0 + f64::from(i)).collect();
            loan.write(0, &half);
            println!("half");
            std::io::stdout().flush().ok();
            let _ = std::io::stdin().lock().read_line(&mut String::new());
            std::process::abort();
        }
        other => {
            eprintln!("hli-peer: unknown arguments {other:?}");
            ExitCode::from(2)
        }
    }
}

fn plc_handshakes(instance: &str, n: u32) -> ExitCode {
    let segment = match PlcSegment::attach(instance) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("attach: {e}");
            return ExitCode::from(1);
        }
    };
    let view = PlcView::new(segment.memory());
    let tx = view.dyn_cs_command(0).expect("channel 0");
    let mut rx = view.dyn_cs_request(0).expect("channel 0");
    let (mut sent, mut read, mut spins) = (0u32, 0u32, 0u32);
    while sent < n || read < n {
        let mut progressed = false;
        if sent < n && tx.try_send(&tests::payload(sent)).is_ok() {
            sent += 1;
            progressed = true;
        }
        if read < n {
            match rx.try_take() {
                Ok(Some(p)) => {
                    if tests::verify(&p) != Some(read) {
                        eprintln!("request {read}: got {p:?}");
                        return ExitCode::from(4);
                    }
                    read += 1;
                    progressed = true;
                }
                Ok(None) => {}
                Err(e) => {
                    eprintln!("request {read}: {e}");
                    return ExitCode::from(5);
                }
            }
        }
        if progressed {
            spins = 0;
        } else {
            spins += 1;
            if spins % 64 == 0 {
                std::thread::yield_now();
            }
        }
    }
    println!(
        "sent {sent} read {read} violations {}",
        rx.stats().violations()
    );
    if rx.stats().violations() == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(6)
    }
}
