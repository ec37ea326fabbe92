//! Cross-process round-trip benchmark of the HLI handshakes against peers measured in the same
//! run: a plain cache-line flag ping-pong (the floor), iceoryx2 publish-subscribe, an iceoryx2
//! event ping-pong, a Unix-domain socket and a futex word in the segment (the wake-up
//! alternatives: a sleeping side woken by iceoryx2's event, by a socket, or by `futex(2)`). Every method moves a 32-byte
//! `HLI_COORDINATE_SYSTEM_INT` there and back (the flag floor moves a counter).
//!
//! Run: `cargo bench -p hli --bench handshake` (add `-- --quick` for a short run).
//! The bench binary spawns itself as the peer process. Reported: p50/p99/max per method as the
//! median over repeats, and each p50 as a ratio to the flag floor of the same run.

use bench_kit::median_u64 as median;
use hli::layout::HliCoordinateSystemInt;
use hli::views::{CncView, PlcView};
use hli_transport::events::{EventLink, Side};
use hli_transport::segment::{CncSegment, PlcSegment};
use iceoryx2::prelude::*;
use std::io::{BufRead, BufReader, Read, Write};
use std::os::unix::net::{UnixListener, UnixStream};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

const PEER_ENV: &str = "HLI_BENCH_PEER";
const WARMUP: usize = 2_000;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Method {
    Flag,
    HliPoll,
    Iox2PubSub,
    Uds,
    HliEvent,
    Iox2Event,
    Futex,
}

impl Method {
    const ALL: [Method; 7] = [
        Method::Flag,
        Method::HliPoll,
        Method::Iox2PubSub,
        Method::Uds,
        Method::HliEvent,
        Method::Iox2Event,
        Method::Futex,
    ];
    fn name(self) -> &'static str {
        match self {
            Method::Flag => "flag ping-pong (floor)",
            Method::HliPoll => "HLI command+request, polling",
            Method::Iox2PubSub => "iceoryx2 pub-sub ping-pong",
            Method::Uds => "Unix socket ping-pong",
            Method::HliEvent => "HLI command+request, event-woken",
            Method::Iox2Event => "iceoryx2 event ping-pong",
            Method::Futex => "futex word in the segment, ping-pong",
        }
    }
    fn key(self) -> &'static str {
        match self {
            Method::Flag => "flag",
            Method::HliPoll => "hli-poll",
            Method::Iox2PubSub => "iox2-pubsub",
            Method::Uds => "uds",
            Method::HliEvent => "hli-event",
            Method::Iox2Event => "iox2-event",
            Method::Futex => "futex",
        }
    }
    fn from_key(key: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.key() == key)
    }
    fn polling(self) -> bool {
        matches!(
            self,
            Method::Flag | Method::HliPoll | Method::Iox2PubSub | Method::Uds
        )
    }
}

fn cs(seq: u32) -> HliCoordinateSystemInt {
    let s = seq as i32;
    HliCoordinateSystemInt {
        translation: [s, s + 1, s + 2],
        fill_up_2: 0,
        rotation: [-s, 0, s],
        fill_up_1: 0,
    }
}

#[inline]
fn spin(spins: &mut u32) {
    *spins += 1;
    if (*spins).is_multiple_of(1024) {
        std::thread::yield_now();
    } else {
        std::hint::spin_loop();
    }
}

// ---------------------------------------------------------------- peer side (child process)

fn peer_main(method: Method, name: &str, count: usize) {
    hli_transport::init_logging();
    let total = count + WARMUP;
    match method {
        Method::Flag => {
            let mem = PlcSegment::attach(name).expect("attach");
            let ping = mem.memory().place::<u64>(FLAG_PING);
            let pong = mem.memory().place::<u64>(FLAG_PONG);
            ready();
            for i in 1..=total as u64 {
                let mut s = 0;
                while ping.load_acquire() != i {
                    spin(&mut s);
                }
                pong.store_release(i);
            }
        }
        Method::HliPoll | Method::HliEvent => {
            let segment = PlcSegment::attach(name).expect("attach");
            // The peer plays the CNC: consume the command, echo it as request data.
            let view = CncView::new(segment.memory());
            let mut rx = view.dyn_cs_command(0).unwrap();
            let tx = view.dyn_cs_request(0).unwrap();
            let events =
                (method == Method::HliEvent).then(|| EventLink::open(name, Side::Cnc).unwrap());
            ready();
            for _ in 0..total {
                let mut s = 0;
                let value = loop {
                    if let Some(v) = rx.try_take().unwrap() {
                        break v;
                    }
                    match &events {
                        Some(e) => {
                            e.wait(Duration::from_millis(10)).unwrap();
                        }
                        None => spin(&mut s),
                    }
                };
                while tx.try_send(&value).is_err() {
                    spin(&mut s);
                }
                if let Some(e) = &events {
                    e.notify().unwrap();
                }
            }
        }
        Method::Iox2PubSub => {
            let node = NodeBuilder::new().create::<ipc::Service>().unwrap();
            let ping = pubsub(&node, &format!("{name}/ping"));
            let pong = pubsub(&node, &format!("{name}/pong"));
            let sub = ping.subscriber_builder().create().unwrap();
            let publisher = pong.publisher_builder().create().unwrap();
            ready();
            for _ in 0..total {
                let mut s = 0;
                let value = loop {
                    if let Some(sample) = sub.receive().unwrap() {
                        break *sample.payload();
                    }
                    spin(&mut s);
                };
                publisher.send_copy(value).unwrap();
            }
        }
        Method::Uds => {
            let mut stream = UnixStream::connect(name).unwrap();
            ready();
            let mut buf = [0u8; 32];
            for _ in 0..total {
                stream.read_exact(&mut buf).unwrap();
                stream.write_all(&buf).unwrap();
            }
        }
        Method::Futex => {
            let mem = PlcSegment::attach(name).expect("attach");
            let ping = mem.memory().place::<u32>(FLAG_PING).atomic();
            let pong = mem.memory().place::<u32>(FLAG_PONG).atomic();
            ready();
            for i in 1..=total as u32 {
                futex_await(ping, i);
                pong.store(i, Ordering::Release);
                cnc_os::futex::wake(pong, 1).unwrap();
            }
        }
        Method::Iox2Event => {
            let link = EventLink::open(name, Side::Plc).unwrap();
            ready();
            let mut answered = 0;
            while answered < total {
                if link.wait(Duration::from_millis(10)).unwrap() {
                    link.notify().unwrap();
                    answered += 1;
                }
            }
        }
    }
}

/// Sleeps on the futex `word` until it holds `value`.
fn futex_await(word: &AtomicU32, value: u32) {
    loop {
        let seen = word.load(Ordering::Acquire);
        if seen == value {
            return;
        }
        cnc_os::futex::wait(word, seen, Duration::from_millis(10)).unwrap();
    }
}

fn ready() {
    println!("ready");
    std::io::stdout().flush().unwrap();
}

type PubSubFactory = iceoryx2::service::port_factory::publish_subscribe::PortFactory<
    ipc::Service,
    HliCoordinateSystemInt,
    (),
>;

fn pubsub(node: &Node<ipc::Service>, name: &str) -> PubSubFactory {
    let service: ServiceName = name.try_into().unwrap();
    node.service_builder(&service)
        .publish_subscribe::<HliCoordinateSystemInt>()
        .subscriber_max_buffer_size(2)
        .history_size(0)
        .open_or_create()
        .unwrap()
}

// ---------------------------------------------------------------- measuring side

const FLAG_PING: usize = 256; // own cache lines inside the (otherwise unused) image
const FLAG_PONG: usize = 384;

fn spawn_peer(method: Method, name: &str, count: usize) -> Child {
    let mut child = Command::new(std::env::current_exe().unwrap())
        .env(PEER_ENV, format!("{} {} {}", method.key(), name, count))
        .stdout(Stdio::piped())
        .stdin(Stdio::null())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.as_mut().unwrap())
        .read_line(&mut line)
        .unwrap();
    assert_eq!(line.trim(), "ready", "peer for {method:?} did not start");
    child
}

/// Runs `count` measured round trips (after a warm-up) and returns their durations in ns.
fn measure(method: Method, count: usize, tag: &str) -> Vec<u64> {
    let name = format!("bench{}-{}-{tag}", std::process::id(), method.key());
    let mut samples = vec![0u64; count];
    let total = count + WARMUP;
    let record = |samples: &mut Vec<u64>, i: usize, t0: Instant| {
        if i >= WARMUP {
            samples[i - WARMUP] = t0.elapsed().as_nanos() as u64;
        }
    };
    match method {
        Method::Flag => {
            let segment = CncSegment::create(&name, 1, 1).unwrap();
            let mut child = spawn_peer(method, &name, count);
            let ping = segment.memory().place::<u64>(FLAG_PING);
            let pong = segment.memory().place::<u64>(FLAG_PONG);
            for i in 0..total {
                let v = i as u64 + 1;
                let t0 = Instant::now();
                ping.store_release(v);
                let mut s = 0;
                while pong.load_acquire() != v {
                    spin(&mut s);
                }
                record(&mut samples, i, t0);
            }
            child.wait().unwrap();
        }
        Method::HliPoll | Method::HliEvent => {
            let segment = CncSegment::create(&name, 1, 1).unwrap();
            // The measuring side plays the PLC.
            let events =
                (method == Method::HliEvent).then(|| EventLink::open(&name, Side::Plc).unwrap());
            let mut child = spawn_peer(method, &name, count);
            let view = PlcView::new(segment.memory());
            let tx = view.dyn_cs_command(0).unwrap();
            let mut rx = view.dyn_cs_request(0).unwrap();
            for i in 0..total {
                let value = cs(i as u32);
                let t0 = Instant::now();
                tx.try_send(&value).unwrap();
                if let Some(e) = &events {
                    e.notify().unwrap();
                }
                let mut s = 0;
                loop {
                    if let Some(echo) = rx.try_take().unwrap() {
                        assert_eq!(echo, value);
                        break;
                    }
                    match &events {
                        Some(e) => {
                            if !e.wait(Duration::from_millis(10)).unwrap() {
                                e.notify().unwrap(); // a wake-up lost before the peer listened
                            }
                        }
                        None => spin(&mut s),
                    }
                }
                record(&mut samples, i, t0);
            }
            child.wait().unwrap();
        }
        Method::Iox2PubSub => {
            let node = NodeBuilder::new().create::<ipc::Service>().unwrap();
            let ping = pubsub(&node, &format!("{name}/ping"));
            let pong = pubsub(&node, &format!("{name}/pong"));
            let publisher = ping.publisher_builder().create().unwrap();
            let sub = pong.subscriber_builder().create().unwrap();
            let mut child = spawn_peer(method, &name, count);
            for i in 0..total {
                let value = cs(i as u32);
                let t0 = Instant::now();
                publisher.send_copy(value).unwrap();
                let mut s = 0;
                loop {
                    if let Some(sample) = sub.receive().unwrap() {
                        assert_eq!(*sample.payload(), value);
                        break;
                    }
                    spin(&mut s);
                }
                record(&mut samples, i, t0);
            }
            child.wait().unwrap();
        }
        Method::Uds => {
            let path = std::env::temp_dir().join(format!("{name}.sock"));
            let _ = std::fs::remove_file(&path);
            let listener = UnixListener::bind(&path).unwrap();
            let mut child = spawn_peer(method, path.to_str().unwrap(), count);
            let (mut stream, _) = listener.accept().unwrap();
            let mut buf = [0u8; 32];
            for i in 0..total {
                let value = cs(i as u32);
                let t0 = Instant::now();
                stream.write_all(bytemuck::bytes_of(&value)).unwrap();
                stream.read_exact(&mut buf).unwrap();
                record(&mut samples, i, t0);
                assert_eq!(&buf[..], bytemuck::bytes_of(&value));
            }
            child.wait().unwrap();
            let _ = std::fs::remove_file(&path);
        }
        Method::Futex => {
            let segment = CncSegment::create(&name, 1, 1).unwrap();
            let mut child = spawn_peer(method, &name, count);
            let ping = segment.memory().place::<u32>(FLAG_PING).atomic();
            let pong = segment.memory().place::<u32>(FLAG_PONG).atomic();
            for i in 0..total {
                let v = i as u32 + 1;
                let t0 = Instant::now();
                ping.store(v, Ordering::Release);
                cnc_os::futex::wake(ping, 1).unwrap();
                futex_await(pong, v);
                record(&mut samples, i, t0);
            }
            child.wait().unwrap();
        }
        Method::Iox2Event => {
            let link = EventLink::open(&name, Side::Cnc).unwrap();
            let mut child = spawn_peer(method, &name, count);
            for i in 0..total {
                let t0 = Instant::now();
                link.notify().unwrap();
                while !link.wait(Duration::from_millis(10)).unwrap() {
                    link.notify().unwrap();
                }
                record(&mut samples, i, t0);
            }
            child.wait().unwrap();
        }
    }
    samples
}

#[derive(Debug, Clone, Copy, Default)]
struct Summary {
    p50: u64,
    p99: u64,
    max: u64,
}

fn summarize(mut samples: Vec<u64>) -> Summary {
    samples.sort_unstable();
    let at =
        |q: f64| samples[((q * samples.len() as f64).ceil() as usize).clamp(1, samples.len()) - 1];
    Summary {
        p50: at(0.5),
        p99: at(0.99),
        max: *samples.last().unwrap(),
    }
}

fn main() {
    if let Ok(spec) = std::env::var(PEER_ENV) {
        let mut parts = spec.split(' ');
        let method = Method::from_key(parts.next().unwrap()).unwrap();
        let name = parts.next().unwrap().to_string();
        let count = parts.next().unwrap().parse().unwrap();
        peer_main(method, &name, count);
        return;
    }
    hli_transport::init_logging();
    let quick = std::env::args().any(|a| a == "--quick");
    // CNC_BENCH_SMOKE=1 (CI): one short repeat, to show the bench runs; no figure is meant.
    let smoke = std::env::var("CNC_BENCH_SMOKE").is_ok_and(|v| v == "1");
    let repeats = if smoke {
        1
    } else if quick {
        3
    } else {
        5
    };
    let (poll_count, event_count) = if smoke {
        (500, 100)
    } else if quick {
        (20_000, 3_000)
    } else {
        (200_000, 20_000)
    };

    println!(
        "cross-process round trip, 32-byte payload there and back; {repeats} repeats, median of each statistic; {} cores",
        std::thread::available_parallelism().map(|n| n.get()).unwrap_or(0)
    );
    let mut results = Vec::new();
    for method in Method::ALL {
        let count = if method.polling() {
            poll_count
        } else {
            event_count
        };
        let runs: Vec<Summary> = (0..repeats)
            .map(|r| summarize(measure(method, count, &r.to_string())))
            .collect();
        let s = Summary {
            p50: median(runs.iter().map(|s| s.p50).collect()),
            p99: median(runs.iter().map(|s| s.p99).collect()),
            max: median(runs.iter().map(|s| s.max).collect()),
        };
        results.push((method, s, count));
    }
    let floor = results[0].1.p50 as f64;
    println!(
        "| method | round trips | p50 ns | p99 ns | max ns | p50 / floor |\n|---|---:|---:|---:|---:|---:|"
    );
    for (method, s, count) in &results {
        println!(
            "| {} | {} | {} | {} | {} | {:.2} |",
            method.name(),
            count,
            s.p50,
            s.p99,
            s.max,
            s.p50 as f64 / floor
        );
    }
    let get = |m: Method| results.iter().find(|(x, _, _)| *x == m).unwrap().1.p50 as f64;
    let verdict = |ok: bool| if ok { "met" } else { "MISSED" };
    let hli_poll = get(Method::HliPoll);
    let pubsub = get(Method::Iox2PubSub);
    let hli_event = get(Method::HliEvent);
    let iox_event = get(Method::Iox2Event);
    println!(
        "TARGET | HLI polling handshake p50 <= 2x the flag ping-pong floor | {:.2}x | {}",
        hli_poll / floor,
        verdict(hli_poll <= 2.0 * floor)
    );
    println!(
        "TARGET | HLI polling handshake >= 2x faster than iceoryx2 pub-sub | {:.2}x | {}",
        pubsub / hli_poll,
        verdict(pubsub >= 2.0 * hli_poll)
    );
    println!(
        "TARGET | HLI event-woken handshake within 1.5x of iceoryx2 event ping-pong | {:.2}x | {}",
        hli_event / iox_event,
        verdict(hli_event <= 1.5 * iox_event)
    );
    let futex = get(Method::Futex);
    println!(
        "wake-up alternatives, p50 round trip: futex word {:.1} us, iceoryx2 event {:.1} us, Unix socket {:.1} us, polling {:.1} us (futex / iceoryx2 event {:.2}x)",
        futex / 1e3,
        iox_event / 1e3,
        get(Method::Uds) / 1e3,
        hli_poll / 1e3,
        futex / iox_event
    );
}
