//! McDynCsTransition's PLCopen outputs against a scripted CNC in lockstep: Done when the goal
//! state comes, CommandAborted when the tracking returns to its start state after leaving it,
//! Error with 0x4803 at ERROR, Busy while the command word is not taken, and a result shown
//! for one cycle when Execute fell before it came. MFunctionHandshake takes and acknowledges.

use hli::enums::{DynCsState, DynCsTransitionError};
use hli::layout::{HliDynCsTransitionResult, HliMFunctionRequest};
use plc_shim::blocks::dyn_cs::{MFunctionHandshake, McDynCsTransition};
use plc_shim::runtime::{PlcIo, PlcProgram, PlcRuntime};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// The CNC's side: which commands it took (tick, +1/-1) and the states it plays after each.
struct Cnc {
    taken: Vec<(u64, i32)>,
    acks: Vec<(i32, u32)>,
    plan: Vec<DynCsState>,
    /// What the CNC reports of the transitions (`dyn_cs_result`).
    result: HliDynCsTransitionResult,
}

impl Default for Cnc {
    fn default() -> Self {
        Self {
            taken: Vec::new(),
            acks: Vec::new(),
            plan: Vec::new(),
            result: bytemuck::Zeroable::zeroed(),
        }
    }
}

fn script(cnc: Arc<Mutex<Cnc>>) -> impl FnMut(&hli::views::CncView<'_>, u64) + Send + 'static {
    move |view, tick| {
        let mut cnc = cnc.lock().unwrap();
        // Ticks 20..=22: the 2nd command waits untaken (the block stays Busy, not Active).
        let hold = cnc.taken.len() == 1 && (20..23).contains(&tick);
        if !hold {
            if let Ok(Some((command, _))) = view.dyn_cs_transition(0).unwrap().try_take() {
                cnc.taken.push((tick, command.raw()));
                cnc.result.taken_count_r += 1;
                cnc.result.command_r = command.raw();
                cnc.result.error_id_r = 0;
                cnc.result.states_seen_r = 0;
                cnc.plan = match cnc.taken.len() {
                    // 1st: ON, then someone switches off: back to INACTIVE after ACTIVATING.
                    1 => vec![
                        DynCsState::Activating,
                        DynCsState::Activating,
                        DynCsState::Deactivating,
                        DynCsState::Inactive,
                    ],
                    // 2nd: ON, ERROR.
                    2 => vec![DynCsState::Activating, DynCsState::Error],
                    // 4th: refused (+1 while on): the state stays.
                    4 => {
                        cnc.result.error_id_r = DynCsTransitionError::AlreadyOn.raw();
                        Vec::new()
                    }
                    // 3rd: ON, ACTIVE after three ticks.
                    _ => vec![
                        DynCsState::Activating,
                        DynCsState::Activating,
                        DynCsState::Activating,
                        DynCsState::Active,
                    ],
                };
                cnc.plan.reverse();
            }
        }
        if let Some(state) = cnc.plan.pop() {
            view.set_dyn_cs_state(0, state).unwrap();
            cnc.result.states_seen_r |= state.seen_bit();
        }
        view.write_dyn_cs_result(0, &cnc.result).unwrap();
        if tick == 2 {
            let request = HliMFunctionRequest {
                m_code: 100,
                block_nr: 7,
                request_id: 41,
            };
            view.m_function_request(0)
                .unwrap()
                .try_send(&request)
                .unwrap();
        }
        if let Ok(Some(ack)) = view.m_function_ack(0).unwrap().try_take() {
            cnc.acks.push((ack.m_code, ack.request_id));
        }
    }
}

/// Drives the block by cycle and records its outputs.
#[derive(Default)]
struct Driver {
    block: McDynCsTransition,
    m: MFunctionHandshake,
    log: Vec<String>,
}

impl PlcProgram for Driver {
    fn cycle(&mut self, io: &mut PlcIo<'_>) {
        let c = io.cycle;
        // Three commands: Execute held until a result (1st), a one-cycle pulse (2nd, its
        // result comes later), held (3rd).
        self.block.execute = matches!(c, 3..=12 | 18 | 30..=45 | 50..=55);
        self.block.call(io, 0);
        let o = self.block.out;
        let word = [
            (o.busy, "Busy"),
            (o.active, "Active"),
            (o.done, "Done"),
            (o.command_aborted, "Aborted"),
            (o.error, "Error"),
        ]
        .iter()
        .filter(|(on, _)| *on)
        .map(|(_, n)| *n)
        .collect::<Vec<_>>()
        .join("+");
        let line = if o.error {
            format!("{word} {:#x}", o.error_id)
        } else {
            word
        };
        if self
            .log
            .last()
            .is_none_or(|l| !l.ends_with(&format!(" {line}")))
        {
            self.log.push(format!("{c} {line}"));
        }
        self.m.call(io, 0);
        if self.m.m_code() == Some(100) {
            self.m.acknowledge(io, 0);
        }
    }
}

#[test]
fn the_transition_block_reports_done_aborted_and_error_as_plcopen_says() {
    hli_transport::init_logging();
    let instance = tests::unique_instance("dyncs-fb");
    let cnc = Arc::new(Mutex::new(Cnc::default()));
    let thread = tests::lockstep_script(&instance, 60, 1, script(cnc.clone()));
    let mut runtime = PlcRuntime::attach(&instance, 2_000, Duration::from_millis(5)).unwrap();
    let mut driver = Driver::default();
    runtime.run(&mut driver, Some(1_000)).unwrap();
    thread.join().unwrap();
    let cnc = cnc.lock().unwrap();
    assert_eq!(
        cnc.taken.iter().map(|t| t.1).collect::<Vec<_>>(),
        [1, 1, 1, 1],
        "{:?}",
        cnc.taken
    );
    // Cycle c runs after the CNC's tick c + 1.
    let expected = [
        "0 ",
        // 1st: sent at once, taken (Active) in the next tick, ACTIVATING, then back to
        // INACTIVE: CommandAborted, held while Execute stays TRUE (to cycle 12).
        "3 Busy",
        "4 Busy+Active",
        "7 Aborted",
        "13 ",
        // 2nd: a one-cycle pulse; the CNC holds the word three ticks (Busy, not Active),
        // then ACTIVATING, ERROR: shown for one cycle although Execute fell long before.
        "18 Busy",
        "22 Busy+Active",
        "23 Error 0x4803",
        "24 ",
        // 3rd: ACTIVE after three ticks of ACTIVATING: Done, held to cycle 45.
        "30 Busy",
        "31 Busy+Active",
        "34 Done",
        "46 ",
        // 4th: refused by the CNC (+1 while ACTIVE): Error with the CNC's reason, not Done.
        "50 Busy",
        "51 Error 0x4517",
        "56 ",
    ];
    assert_eq!(driver.log, expected, "{:?}", driver.log);
    assert_eq!(cnc.acks, [(100, 41)]);
    assert_eq!(driver.m.received, 1);
    assert_eq!(driver.m.acknowledged, 1);
}
