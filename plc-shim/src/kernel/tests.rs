//! One table of blocks, every family, run through the same Execute, refusal, timeout and
//! restart cases against a stand-in CNC in this thread (an acyclic server polled by hand).

use super::{Outputs, DEFAULT_TIMEOUT_CYCLES, ERROR_NO_ANSWER};
use crate::blocks::cam_data::{CamData, McCamTableSelect};
use crate::blocks::dyn_cs::McDynCsTransition;
use crate::runtime::PlcIo;
use crate::timeline::instances::inputs_of;
use crate::timeline::registry::{BlockSpec, InputSpec, Target};
use hli::calls::ErrorCode;
use hli::views::PlcView;
use hli_transport::rpc::{AcyclicClient, AcyclicServer};
use std::sync::Arc;

/// What every block shows, whatever its extras.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
struct Seen {
    done: bool,
    busy: bool,
    aborted: bool,
    error: bool,
    error_id: u32,
}

fn seen<X>(o: Outputs<X>) -> Seen {
    Seen {
        done: o.done,
        busy: o.busy,
        aborted: o.command_aborted,
        error: o.error,
        error_id: o.error_id,
    }
}

/// A block under test: one cycle with this Execute, its outputs.
type Cycle = Box<dyn FnMut(&mut PlcIo<'_>, bool) -> Seen>;

macro_rules! block {
    ($block:expr, |$b:ident, $io:ident| $call:expr) => {
        block!($block, |_b| (), |$b, $io| $call)
    };
    ($block:expr, |$s:ident| $setup:expr, |$b:ident, $io:ident| $call:expr) => {{
        let mut $b = $block;
        let $s = &mut $b;
        $setup;
        Box::new(move |$io: &mut PlcIo<'_>, execute: bool| {
            $b.execute = execute;
            $call;
            seen($b.out)
        }) as Cycle
    }};
}

/// Every Execute-driven block that calls the CNC (all but a channel's, which write the
/// channel's units), read from the registry: a block that is declared is run through these
/// rules without a second edit. Each is made by its spec for axis 1 (FIFO group 0) with
/// its required inputs, table 1 and the data the table blocks send ([`send_ready`]).
fn blocks() -> Vec<(&'static str, Cycle)> {
    crate::timeline::registry::blocks()
        .filter(|spec| spec.execute && !matches!(spec.target, Target::Channel))
        .map(|spec| (spec.name, cycle_of(spec)))
        .collect()
}

/// The inputs of `spec` that a block needs to send anything: every required one, and the
/// table and its rows or points where it takes them.
fn send_ready(spec: &BlockSpec) -> toml::Table {
    let mut call = toml::Table::new();
    call.insert("block".into(), spec.name.into());
    if !matches!(spec.target, Target::Group) {
        call.insert("axis".into(), 1.into());
    }
    let needed = |i: &&InputSpec| i.required || ["table", "rows", "points"].contains(&i.key);
    for input in spec.inputs.iter().filter(needed) {
        let value = match input.key {
            "table" => toml::Value::Integer(1),
            _ => {
                let text = format!("v = {}", input.kind.example());
                toml::from_str::<toml::Table>(&text).unwrap()["v"].clone()
            }
        };
        call.insert(input.key.into(), value);
    }
    call
}

/// A block of `spec` with its [`send_ready`] inputs, as one cycle with a given Execute.
fn cycle_of(spec: &'static BlockSpec) -> Cycle {
    let call = send_ready(spec);
    let (inputs, room, _) = inputs_of(spec, &call).unwrap_or_else(|e| panic!("{}: {e}", spec.name));
    let mut block = (spec.make)(room);
    for (key, value) in &inputs {
        block.set(key, value);
    }
    let axis = u32::from(!matches!(spec.target, Target::Group));
    Box::new(move |io: &mut PlcIo<'_>, execute: bool| {
        *block.execute().expect("an Execute-driven block") = execute;
        seen(block.cycle(io, axis).0)
    })
}

/// The stand-in CNC of one case: an image with one channel and two axes, a server that
/// answers when told to, and a client for the blocks.
struct Cnc {
    memory: hli::ImageMemory,
    server: AcyclicServer,
    client: AcyclicClient,
    cycle: u64,
}

impl Cnc {
    fn new(case: &str, block: &str) -> Cnc {
        let name: String = block.chars().filter(char::is_ascii_alphanumeric).collect();
        let instance = format!("kernel-{case}-{name}-{}", std::process::id());
        Cnc {
            memory: hli::image::heap_image(1, 2),
            server: AcyclicServer::open(&instance).unwrap(),
            client: AcyclicClient::open(&instance).unwrap(),
            cycle: 0,
        }
    }

    /// One PLC cycle of `block`.
    fn run(&mut self, block: &mut Cycle, execute: bool) -> Seen {
        self.run_on(block, execute, crate::runtime::Link::Operational)
    }

    /// One PLC cycle of `block` with the link to the CNC in state `link`.
    fn run_on(&mut self, block: &mut Cycle, execute: bool, link: crate::runtime::Link) -> Seen {
        self.cycle += 1;
        let mut io = PlcIo {
            view: PlcView::new(&self.memory),
            memory: &self.memory,
            acyclic: &mut self.client,
            cycle: self.cycle,
            link,
        };
        block(&mut io, execute)
    }

    /// Refuses every call and row block on its way; how many.
    fn refuse(&self) -> usize {
        let calls = self
            .server
            .poll(|_, _| Err(ErrorCode::InvalidData))
            .unwrap();
        let rows = self.server.poll_rows(|_, _, _| Err(ErrorCode::InvalidData));
        calls + rows.unwrap()
    }

    /// Cycles with `execute` until the block stops being Busy (refusing what comes); the
    /// outputs then.
    fn until_answered(&mut self, block: &mut Cycle, execute: bool) -> Seen {
        for _ in 0..10_000 {
            self.refuse();
            let out = self.run(block, execute);
            if !out.busy {
                return out;
            }
            std::thread::yield_now();
        }
        panic!("watchdog: the block never left Busy");
    }
}

const REFUSED: Seen = Seen {
    done: false,
    busy: false,
    aborted: false,
    error: true,
    error_id: 0x706,
};

/// The outputs of every block whose command ends because the CNC is gone.
const NOT_OPERATIONAL: Seen = Seen {
    done: false,
    busy: false,
    aborted: false,
    error: true,
    error_id: ERROR_NO_ANSWER,
};

#[test]
fn a_lost_cnc_ends_every_command_with_an_error_at_once() {
    use crate::runtime::Link::NotOperational;
    for (name, mut block) in blocks() {
        let mut cnc = Cnc::new("lost", name);
        assert!(cnc.run(&mut block, true).busy, "{name}: Busy from the edge");
        // The call is on its way, never answered: the loss ends it in the same cycle.
        assert_eq!(
            cnc.run_on(&mut block, true, NotOperational),
            NOT_OPERATIONAL,
            "{name}: a running command"
        );
        assert_eq!(
            cnc.run_on(&mut block, false, NotOperational),
            Seen::default(),
            "{name}: cleared with the falling edge"
        );
        cnc.refuse(); // what went out so far (MC_Stop releases on the falling edge)
                      // A new Execute while the CNC is gone sends nothing and fails at once.
        assert_eq!(
            cnc.run_on(&mut block, true, NotOperational),
            NOT_OPERATIONAL,
            "{name}: a rising Execute"
        );
        assert_eq!(cnc.refuse(), 0, "{name}: no call on a lost link");
    }
}

#[test]
fn a_refusal_holds_while_execute_stays_true_and_clears_when_it_falls() {
    for (name, mut block) in blocks() {
        let mut cnc = Cnc::new("held", name);
        let first = cnc.run(&mut block, true);
        assert!(
            first.busy && !first.error,
            "{name}: Busy from the edge: {first:?}"
        );
        assert_eq!(cnc.until_answered(&mut block, true), REFUSED, "{name}");
        assert_eq!(cnc.run(&mut block, true), REFUSED, "{name}: held");
        let fell = cnc.run(&mut block, false);
        assert_eq!(
            fell,
            Seen::default(),
            "{name}: cleared with the falling edge"
        );
    }
}

#[test]
fn a_short_pulse_shows_its_result_for_one_cycle() {
    for (name, mut block) in blocks() {
        let mut cnc = Cnc::new("pulse", name);
        cnc.run(&mut block, true);
        assert!(
            cnc.run(&mut block, false).busy,
            "{name}: still Busy after the pulse"
        );
        assert_eq!(cnc.until_answered(&mut block, false), REFUSED, "{name}");
        assert_eq!(
            cnc.run(&mut block, false),
            Seen::default(),
            "{name}: shown once"
        );
    }
}

#[test]
fn no_answer_is_an_error_after_the_timeout() {
    for (name, mut block) in blocks() {
        let mut cnc = Cnc::new("timeout", name);
        for _ in 0..=DEFAULT_TIMEOUT_CYCLES {
            let out = cnc.run(&mut block, true);
            assert!(out.busy, "{name}: Busy while waiting: {out:?}");
        }
        let out = cnc.run(&mut block, true);
        assert!(
            out.error && out.error_id == ERROR_NO_ANSWER,
            "{name}: {out:?}"
        );
    }
}

#[test]
fn a_rising_edge_while_busy_sends_the_new_command() {
    for (name, mut block) in blocks() {
        let mut cnc = Cnc::new("restart", name);
        cnc.run(&mut block, true);
        cnc.run(&mut block, false);
        cnc.run(&mut block, true);
        let mut sent = 0;
        for _ in 0..10_000 {
            sent += cnc.refuse();
            if sent >= 3 || (sent == 2 && name != "MC_Stop") {
                break;
            }
            std::thread::yield_now();
        }
        // MC_Stop also releases its lock when Execute falls.
        let expected = if name == "MC_Stop" { 3 } else { 2 };
        assert_eq!(sent, expected, "{name}: both commands went out");
        assert_eq!(cnc.until_answered(&mut block, true), REFUSED, "{name}");
    }
}

#[test]
fn a_dyn_cs_transition_nobody_takes_times_out() {
    let mut cnc = Cnc::new("timeout", "dyncs");
    let mut b = McDynCsTransition::default();
    let mut block: Cycle = Box::new(move |io: &mut PlcIo<'_>, execute| {
        b.execute = execute;
        b.call(io, 0);
        seen(b.out)
    });
    for _ in 0..=DEFAULT_TIMEOUT_CYCLES {
        let out = cnc.run(&mut block, true);
        assert!(out.busy, "written, then waiting: {out:?}");
    }
    let out = cnc.run(&mut block, true);
    assert!(out.error && out.error_id == ERROR_NO_ANSWER, "{out:?}");
}

#[test]
fn a_dyn_cs_transition_fails_at_once_on_a_state_that_is_no_tracking_state() {
    let mut cnc = Cnc::new("invalid", "dyncs");
    let mut b = McDynCsTransition::default();
    let mut block: Cycle = Box::new(move |io: &mut PlcIo<'_>, execute| {
        b.execute = execute;
        b.call(io, 0);
        seen(b.out)
    });
    assert!(
        cnc.run(&mut block, true).busy,
        "written, waiting for the CNC"
    );
    let state =
        hli::access::Leaf::resolve("gpCh[0]^channel_mc_control.dyn_cs.state_r.actual_state");
    state
        .unwrap()
        .write(&cnc.memory, hli::access::Value::Unsigned(99));
    let out = cnc.run(&mut block, true);
    let invalid = crate::blocks::dyn_cs::DynCsBlockError::InvalidState.code();
    assert!(out.error && out.error_id == invalid, "{out:?}");
}

/// tTimeout from a timeline: every block that has it (`TimelineBlock::timeout_cycles`; every
/// cam, compatibility, FIFO, saw and channel block) ends with ERROR_NO_ANSWER after the cycles
/// it was given, where the default would still wait.
#[test]
fn a_timeline_timeout_ends_every_block_that_has_one_after_its_cycles() {
    use crate::timeline::registry::{Value, FAMILIES};
    const CYCLES: u64 = 7;
    let mut with = 0;
    for spec in FAMILIES.iter().flat_map(|f| f.iter()) {
        let mut block = (spec.make)(None);
        if !block.timeout_cycles(CYCLES) {
            continue;
        }
        with += 1;
        let axis = match spec.target {
            Target::Group | Target::Channel => 0,
            _ => 1,
        };
        let mut fresh = (spec.make)(None);
        // Table 1 and two points, for the blocks that send nothing without them.
        let points = [hli::calls::cam::McMotionFunctionPoint::default(); 2];
        for b in [&mut block, &mut fresh] {
            b.timeout_cycles(CYCLES);
            b.set("table", &Value::Int(1));
            if spec.name == "MC_WriteMotionFunction" {
                b.set("points", &Value::Points(Arc::new(points)));
            }
            b.set("rows", &Value::Rows(Arc::new([[0.0, 0.0], [1.0, 1.0]])));
        }
        fresh.timeout_cycles(DEFAULT_TIMEOUT_CYCLES);
        let mut cnc = Cnc::new("tl-timeout", spec.name);
        // Both blocks in each PLC cycle.
        let mut run = |b: &mut Box<dyn crate::timeline::registry::TimelineBlock>, cycle| {
            *b.execute().unwrap() = true;
            let mut io = PlcIo {
                view: PlcView::new(&cnc.memory),
                memory: &cnc.memory,
                acyclic: &mut cnc.client,
                cycle,
                link: crate::runtime::Link::Operational,
            };
            b.cycle(&mut io, axis).0
        };
        for cycle in 1..=CYCLES + 1 {
            let out = run(&mut block, cycle);
            assert!(out.busy, "{}: Busy while waiting: {out:?}", spec.name);
            run(&mut fresh, cycle);
        }
        let out = run(&mut block, CYCLES + 2);
        assert!(
            out.error && out.error_id == ERROR_NO_ANSWER,
            "{}: {out:?}",
            spec.name
        );
        let out = run(&mut fresh, CYCLES + 2);
        assert!(out.busy && !out.error, "{}: default: {out:?}", spec.name);
    }
    assert!(with >= 30, "blocks with tTimeout: {with}");
}

/// MC_CAM_REF (seed 000 5.1.16.2): a description that does not match its array is refused
/// with the seed's code before anything is sent; a matching one sends as many rows as it
/// says (three of an array of five).
#[test]
fn an_mc_cam_ref_is_checked_against_its_array_and_sends_its_rows() {
    use crate::blocks::cam_data::CamRef;
    let rows: Arc<[[f64; 2]]> = Arc::from(vec![
        [0.0, 0.0],
        [1.0, 1.0],
        [2.0, 4.0],
        [3.0, 9.0],
        [4.0, 16.0],
    ]);
    let table = |array_size, table_type, count, columns| CamRef {
        data: CamData::Rows {
            rows: rows.clone(),
            table_type: 0,
            interpolation: 0,
        },
        array_size,
        table_type,
        rows: count,
        columns,
        held: None,
    };
    let points = CamRef {
        data: CamData::Points(Arc::from(
            vec![hli::calls::cam::McMotionFunctionPoint::default(); 3],
        )),
        array_size: 3 * core::mem::size_of::<hli::calls::cam::McMotionFunctionPoint>() as u32,
        table_type: 22,
        rows: 3,
        columns: 1,
        held: None,
    };
    assert_eq!(points.check(), Ok(3));
    for (case, cam_ref, code) in [
        ("size", table(72, 10, 5, 2), 0x4B31),
        ("type", table(80, 12, 5, 2), 0x4B35),
        ("rows", table(80, 11, 6, 2), 0x4B36),
        ("one-row", table(80, 11, 1, 2), 0x4B36),
        ("columns", table(80, 10, 5, 3), 0x4B37),
    ] {
        let mut cnc = Cnc::new("camref", case);
        let mut select = block!(
            McCamTableSelect::default(),
            |s| {
                s.table = 1;
                s.cam_ref = Some(cam_ref.clone());
            },
            |b, io| b.call(io)
        );
        let seen = cnc.run(&mut select, true);
        assert!(seen.error && seen.error_id == code, "{case}: {seen:?}");
        assert_eq!(cnc.refuse(), 0, "{case}: nothing sent");
    }
    let mut cnc = Cnc::new("camref", "three");
    let mut select = block!(
        McCamTableSelect::default(),
        |s| {
            s.table = 1;
            s.cam_ref = Some(table(80, 10, 3, 2));
        },
        |b, io| b.call(io)
    );
    assert!(cnc.run(&mut select, true).busy);
    let mut sent = None;
    cnc.server
        .poll(|_, request| {
            let call: hli::calls::cam::CamRowsWriteCall = hli::calls::decode_body(request)?;
            sent = Some((call.total, call.count, call.table_type));
            Err(ErrorCode::InvalidData)
        })
        .unwrap();
    assert_eq!(sent, Some((3, 3, 10)));
}
