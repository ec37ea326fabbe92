//! The flying-saw blocks against a stand-in CNC, and the following of a coupling's image.

use super::*;
use hli::calls::saw::{SawCharacReply, SawReply};
use hli::calls::{decode_body, reply, CallKind};
use hli::layout::HliAxis;
use hli::views::{CncView, PlcView};
use hli::PlaceExt;
use hli_transport::rpc::{AcyclicClient, AcyclicServer};

#[test]
fn the_library_names_its_version() {
    let v = saw_library_version();
    assert_eq!(v, concat!("cncplc-saw ", env!("CARGO_PKG_VERSION")));
    assert!(v.len() <= 20, "fits a STRING(20)");
}

fn state(coupling: CouplingState, master: i32, axis: AxisState, error: u32) -> HliAxisLrState {
    HliAxisLrState {
        axis_state_r: axis.raw(),
        coupling_state_r: coupling.raw(),
        master_axis_r: master,
        error_id_r: error,
        ..bytemuck::Zeroable::zeroed()
    }
}

#[test]
fn the_image_is_ours_only_for_our_kind_and_master() {
    let pos = CouplingState::GearPosition;
    let sync = AxisState::SlaveSynchronous;
    let image = |s| read_image(Some(s), pos, 2);
    assert_eq!(
        image(state(pos, 2, sync, 0)),
        Image::Ours { synchronous: true }
    );
    let synchronizing = AxisState::SlaveSynchronizing;
    assert_eq!(
        image(state(pos, 2, synchronizing, 0)),
        Image::Ours { synchronous: false }
    );
    let velocity = CouplingState::GearVelocity;
    assert_eq!(image(state(velocity, 2, sync, 0)), Image::Other);
    assert_eq!(image(state(pos, 3, sync, 0)), Image::Other);
    assert_eq!(image(state(pos, 2, sync, 0x4711)), Image::Faulted(0x4711));
    assert_eq!(read_image(None, pos, 2), Image::Other);
}

fn waited(cycles: u64) -> Waited {
    Waited { cycles, timeout: 3 }
}

fn outputs(step: Step<()>) -> (bool, Outputs) {
    match step {
        Step::Running(out) => (false, out),
        Step::Ended(out) => (true, out),
    }
}

const FRESH: GearFollow = GearFollow {
    master: 0,
    command_id: 0,
    seen: false,
    synced: false,
};

/// The book's view of a coupling still under way.
const BUSY: CommandView = CommandView::Busy(false);

/// A new coupling of the slave by another block, of the same kind to the same master: the
/// image looks like ours, the book shows our command aborted: CommandAborted.
#[test]
fn a_coupling_replaced_in_the_book_is_aborted_though_the_image_looks_like_ours() {
    let mut f = GearFollow {
        command_id: 7,
        ..FRESH
    };
    let ours = Image::Ours { synchronous: true };
    let (ended, out) = outputs(follow_gear(&mut f, ours, BUSY, waited(1)));
    assert!(!ended && out.in_sync, "{out:?}");
    let (ended, out) = outputs(follow_gear(&mut f, ours, CommandView::Aborted, waited(2)));
    assert!(ended && out.command_aborted && !out.in_sync, "{out:?}");
}

#[test]
fn a_coupling_is_busy_until_in_sync_then_aborted_when_it_goes_away() {
    let mut f = FRESH;
    let ours = |synchronous| Image::Ours { synchronous };
    // The reply's own cycle: its image may be older.
    assert_eq!(
        outputs(follow_gear(&mut f, ours(true), BUSY, waited(0))),
        (false, STARTED)
    );
    // Not shown yet.
    let step = follow_gear(&mut f, Image::Other, BUSY, waited(1));
    assert_eq!(outputs(step), (false, STARTED));
    let step = follow_gear(&mut f, ours(false), BUSY, waited(2));
    assert_eq!(outputs(step), (false, STARTED));
    let (ended, out) = outputs(follow_gear(&mut f, ours(true), BUSY, waited(3)));
    assert!(!ended && out.in_sync && out.start_sync && !out.busy && !out.active);
    // A rollback stop: still coupled.
    let (ended, out) = outputs(follow_gear(&mut f, ours(false), BUSY, waited(4)));
    assert!(
        !ended && !out.in_sync && !out.busy && !out.command_aborted,
        "{out:?}"
    );
    // MC_GearOut, or another coupling.
    let (ended, out) = outputs(follow_gear(&mut f, Image::Other, BUSY, waited(5)));
    assert!(ended && out.command_aborted && !out.busy, "{out:?}");
}

#[test]
fn faults_and_unseen_couplings_end_the_following() {
    let (ended, out) = outputs(follow_gear(
        &mut { FRESH },
        Image::Faulted(0x4711),
        BUSY,
        waited(1),
    ));
    assert!(
        ended && out.error && out.error_id == 0x4711 && out.start_sync,
        "{out:?}"
    );
    let mut f = FRESH;
    let (ended, out) = outputs(follow_gear(&mut f, Image::Other, BUSY, waited(3)));
    assert!(!ended && out.busy, "still waiting for the image");
    let (ended, out) = outputs(follow_gear(&mut f, Image::Other, BUSY, waited(4)));
    assert!(ended && out.command_aborted, "never shown: ended unseen");
}

fn io<'a>(memory: &'a hli::ImageMemory, client: &'a mut AcyclicClient, cycle: u64) -> PlcIo<'a> {
    PlcIo {
        view: PlcView::new(memory),
        memory,
        acyclic: client,
        cycle,
        link: crate::runtime::Link::Operational,
    }
}

fn show(memory: &hli::ImageMemory, coupling: CouplingState, master: i32, axis: AxisState) {
    CncView::new(memory)
        .axis(1)
        .unwrap()
        .field::<HliAxisLrState>(core::mem::offset_of!(HliAxis, lr_state))
        .write(&state(coupling, master, axis, 0));
}

/// A stand-in CNC in this thread: an acyclic server polled by hand and an image with two
/// axes whose slave image the test writes.
struct StandIn {
    server: AcyclicServer,
    client: AcyclicClient,
    memory: hli::ImageMemory,
    cycle: u64,
}

impl StandIn {
    fn new(name: &str) -> StandIn {
        hli_transport::init_logging();
        let instance = format!("saw-{name}-{}", std::process::id());
        StandIn {
            server: AcyclicServer::open(&instance).unwrap(),
            client: AcyclicClient::open(&instance).unwrap(),
            memory: hli::image::heap_image(0, 2),
            cycle: 0,
        }
    }

    /// PLC cycles of `call` until it says it is through.
    fn run(&mut self, call: &mut dyn FnMut(&mut PlcIo<'_>, &AcyclicServer) -> bool) {
        loop {
            self.cycle += 1;
            assert!(self.cycle < 100_000, "watchdog: no answer");
            if call(
                &mut io(&self.memory, &mut self.client, self.cycle),
                &self.server,
            ) {
                break;
            }
            std::thread::yield_now();
        }
    }
}

/// The couplings against a stand-in CNC: the coupling call, the slave's image written by
/// hand, MC_GearOut.
#[test]
fn couplings_against_a_stand_in_cnc() {
    let mut cnc = StandIn::new("couplings");
    let pos = CouplingState::GearPosition;
    let mut gear = McGearInPos {
        execute: true,
        master: 0,
        slave: 1,
        master_sync_position: 100.0,
        ..McGearInPos::default()
    };
    cnc.run(&mut |io, _| {
        gear.call(io);
        true
    });
    let answered = cnc.server.poll(|kind, request| {
        assert_eq!((kind, request.target), (CallKind::SAW_GEAR_IN, 1));
        let call: SawGearInCall = decode_body(request)?;
        assert_eq!(
            (call.target, call.master_sync_position),
            (SawSyncTarget::Position.raw(), 100.0)
        );
        reply(&SawReply::default())
    });
    assert_eq!(answered.unwrap(), 1);
    cnc.run(&mut |io, _| {
        gear.call(io);
        gear.out.start_sync
    });
    assert!(gear.out.busy && gear.out.active, "{:?}", gear.out);
    for (axis, in_sync) in [
        (AxisState::SlaveSynchronizing, false),
        (AxisState::SlaveSynchronous, true),
    ] {
        show(&cnc.memory, pos, 0, axis);
        cnc.run(&mut |io, _| {
            gear.call(io);
            true
        });
        assert_eq!((gear.out.in_sync, gear.out.busy), (in_sync, !in_sync));
    }

    let mut gear_out = McGearOut {
        execute: true,
        slave: 1,
        ..McGearOut::default()
    };
    cnc.run(&mut |io, _| {
        gear_out.call(io);
        true
    });
    let answered = cnc.server.poll(|kind, _| {
        assert_eq!(kind, CallKind::SAW_GEAR_OUT);
        reply(&SawReply::default())
    });
    assert_eq!(answered.unwrap(), 1);
    cnc.run(&mut |io, _| {
        gear_out.call(io);
        !gear_out.out.busy
    });
    assert!(gear_out.out.done, "{:?}", gear_out.out);
    show(
        &cnc.memory,
        CouplingState::Uncoupled,
        -1,
        AxisState::Inactive,
    );
    cnc.run(&mut |io, _| {
        gear.call(io);
        true
    });
    assert!(
        gear.out.command_aborted && !gear.out.in_sync,
        "{:?}",
        gear.out
    );
}

/// The characteristic values against a stand-in CNC, in three parts: the values, then the
/// organisation fields.
#[test]
fn the_read_takes_three_parts() {
    let mut cnc = StandIn::new("read");
    let mut read = McReadFlyingSawCharacteristics {
        execute: true,
        slave: 1,
        ..McReadFlyingSawCharacteristics::default()
    };
    cnc.run(&mut |io, server| {
        read.call(io);
        server
            .poll(|_, request| {
                let call: SawCharacCall = decode_body(request)?;
                let mut values = [0.0; SAW_CHARAC_PART];
                for (i, v) in values.iter_mut().enumerate() {
                    *v = (call.part as usize * SAW_CHARAC_PART + i + 1) as f64;
                }
                if call.part == 2 {
                    values[..5].copy_from_slice(&[254.0, 3.0, 1.0, 22.0, 0.0]);
                }
                let part = call.part;
                reply(&SawCharacReply {
                    error_id: 0,
                    part,
                    plan: 1,
                    reserved: 0,
                    values,
                })
            })
            .unwrap();
        !read.out.busy
    });
    assert!(read.out.done, "{:?}", read.out);
    let got: Vec<(&str, f64)> = read.characteristics().collect();
    assert_eq!(got.len(), 31);
    assert_eq!(got[0], ("fMasterVeloNom", 1.0));
    assert_eq!(got[16], ("fSlaveAccMin", 17.0));
    assert_eq!(got[30], ("fSlaveAccEff", 31.0));
    let org = read.organisation;
    assert_eq!((org.table_id, org.rows, org.columns), (254, 3, 1));
    assert_eq!((org.table_type, org.periodic), (22, false));
}
