//! Model-based tests of the two handshake patterns over random interleavings, including a PLC
//! that breaks the protocol by writing through raw places.

use core::mem::offset_of;
use hli::handshake::{ProtocolViolation, SendError};
use hli::image::heap_image;
use hli::layout::*;
use hli::views::{CncView, PlcView};
use hli::{Bool, ImageMemory, Place, PlaceExt};
use proptest::prelude::*;

/// A payload that carries a sequence number and a checksum over it.
fn payload(seq: i32) -> HliCoordinateSystemInt {
    let t = [seq, seq.wrapping_mul(7), seq ^ 0x5555];
    let r = [seq.wrapping_add(1), -seq, 0];
    let mut p = HliCoordinateSystemInt {
        translation: t,
        fill_up_2: 0,
        rotation: r,
        fill_up_1: 0,
    };
    p.fill_up_1 = checksum(&p);
    p
}

fn checksum(p: &HliCoordinateSystemInt) -> i32 {
    let words = [
        p.translation[0],
        p.translation[1],
        p.translation[2],
        p.rotation[0],
        p.rotation[1],
        p.rotation[2],
    ];
    words.iter().fold(0x811c_9dc5u32 as i32, |h, w| {
        (h ^ w).wrapping_mul(16_777_619)
    })
}

fn is_whole(p: &HliCoordinateSystemInt) -> bool {
    checksum(p) == p.fill_up_1 && *p == payload(p.translation[0])
}

fn dyn_cs_unit(mem: &ImageMemory) -> Place<'_, McControlDynCsUnit> {
    CncView::new(mem).dyn_cs_unit(0).unwrap()
}

#[derive(Debug, Clone)]
enum Op {
    /// Correct PLC: write while FALSE, then TRUE (through the handle).
    PlcSend(i32),
    /// Broken PLC: write the payload regardless of the semaphore.
    PlcWriteRaw(i32),
    /// Broken PLC: set the semaphore TRUE regardless (TRUE twice, or commit without writing).
    PlcSetTrueRaw,
    /// Broken PLC: a garbage byte in the semaphore.
    PlcGarbage(u8),
    /// CNC tick: take if TRUE.
    CncTake,
}

fn correct_ops() -> impl Strategy<Value = Vec<Op>> {
    prop::collection::vec(
        prop_oneof![(0..1_000_000i32).prop_map(Op::PlcSend), Just(Op::CncTake)],
        0..200,
    )
}

fn any_ops() -> impl Strategy<Value = Vec<Op>> {
    prop::collection::vec(
        prop_oneof![
            4 => (0..1_000_000i32).prop_map(Op::PlcSend),
            1 => (0..1_000_000i32).prop_map(Op::PlcWriteRaw),
            1 => Just(Op::PlcSetTrueRaw),
            1 => (2u8..=255).prop_map(Op::PlcGarbage),
            4 => Just(Op::CncTake),
        ],
        0..200,
    )
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Sem {
    False,
    True,
    Garbage(u8),
}

proptest! {
    /// With a protocol-abiding PLC every committed command is consumed exactly once, whole and
    /// in order, and a send is refused exactly while the previous one is pending.
    #[test]
    fn command_pattern_delivers_each_commit_exactly_once(ops in correct_ops()) {
        let mem = heap_image(1, 0);
        let tx = PlcView::new(&mem).dyn_cs_command(0).unwrap();
        let mut rx = CncView::new(&mem).dyn_cs_command(0).unwrap();
        let mut committed = Vec::new();
        let mut consumed = Vec::new();
        let mut pending = false;
        for op in &ops {
            match *op {
                Op::PlcSend(seq) => match tx.try_send(&payload(seq)) {
                    Ok(()) => { prop_assert!(!pending); pending = true; committed.push(seq); }
                    Err(SendError::Busy) => prop_assert!(pending),
                    Err(e) => prop_assert!(false, "unexpected {e:?}"),
                },
                Op::CncTake => match rx.try_take() {
                    Ok(Some(p)) => { prop_assert!(pending); prop_assert!(is_whole(&p)); pending = false; consumed.push(p.translation[0]); }
                    Ok(None) => prop_assert!(!pending),
                    Err(e) => prop_assert!(false, "unexpected {e:?}"),
                },
                _ => unreachable!(),
            }
        }
        if pending {
            consumed.push(rx.try_take().unwrap().unwrap().translation[0]);
        }
        prop_assert_eq!(&consumed, &committed);
        prop_assert_eq!(rx.stats().violations(), 0);
    }

    /// A PLC that breaks the protocol never crashes the CNC side: every outcome is exactly what
    /// the model predicts, every taken payload is whole, and every violation the CNC can observe
    /// is counted.
    #[test]
    fn command_pattern_survives_a_broken_plc(ops in any_ops()) {
        let mem = heap_image(1, 0);
        let unit = dyn_cs_unit(&mem);
        let sem_place = unit.field::<u8>(offset_of!(McControlDynCsUnit, command_semaphore_rw));
        let payload_place = unit.field::<HliCoordinateSystemInt>(offset_of!(McControlDynCsUnit, command_w));
        let tx = PlcView::new(&mem).dyn_cs_command(0).unwrap();
        let mut rx = CncView::new(&mem).dyn_cs_command(0).unwrap();

        let mut sem = Sem::False;
        let mut memory_payload = HliCoordinateSystemInt::default_zeroed();
        let (mut taken, mut garbage_seen) = (0u64, 0u64);
        for op in &ops {
            match *op {
                Op::PlcSend(seq) => {
                    let result = tx.try_send(&payload(seq));
                    match sem {
                        Sem::False => { prop_assert_eq!(result, Ok(())); memory_payload = payload(seq); sem = Sem::True; }
                        Sem::True => prop_assert_eq!(result, Err(SendError::Busy)),
                        Sem::Garbage(raw) => prop_assert_eq!(result, Err(SendError::Violation(ProtocolViolation::SemaphoreGarbage { raw }))),
                    }
                }
                Op::PlcWriteRaw(seq) => { payload_place.write(&payload(seq)); memory_payload = payload(seq); }
                Op::PlcSetTrueRaw => { sem_place.store_release(1); sem = Sem::True; }
                Op::PlcGarbage(raw) => { sem_place.store_release(raw); sem = Sem::Garbage(raw); }
                Op::CncTake => {
                    let result = rx.try_take();
                    match sem {
                        Sem::False => prop_assert_eq!(result, Ok(None)),
                        Sem::True => {
                            let got = result.unwrap().unwrap();
                            prop_assert_eq!(got, memory_payload);
                            prop_assert!(got == HliCoordinateSystemInt::default_zeroed() || is_whole(&got));
                            taken += 1;
                            sem = Sem::False;
                        }
                        Sem::Garbage(raw) => {
                            prop_assert_eq!(result, Err(ProtocolViolation::SemaphoreGarbage { raw }));
                            garbage_seen += 1;
                            sem = Sem::False;
                        }
                    }
                }
            }
            prop_assert_eq!(Bool(sem_place.load()).get().ok(), match sem { Sem::False => Some(false), Sem::True => Some(true), Sem::Garbage(_) => None });
        }
        prop_assert_eq!(rx.stats().taken, taken);
        prop_assert_eq!(rx.stats().garbage, garbage_seen);
    }

    /// The request pattern, CNC writing and PLC reading: data is read only while valid
    /// (semaphore TRUE), each published value is read at most once, and the CNC never
    /// overwrites a value the PLC has not read.
    #[test]
    fn request_pattern_reads_only_valid_data(ops in prop::collection::vec(prop_oneof![(0..1_000_000i32).prop_map(Some), Just(None)], 0..200)) {
        let mem = heap_image(1, 0);
        let tx = CncView::new(&mem).dyn_cs_request(0).unwrap();
        let mut rx = PlcView::new(&mem).dyn_cs_request(0).unwrap();
        let mut published = Vec::new();
        let mut read = Vec::new();
        for op in &ops {
            match op {
                Some(seq) => if tx.try_send(&payload(*seq)).is_ok() { published.push(*seq) },
                None => if let Some(p) = rx.try_take().unwrap() { prop_assert!(is_whole(&p)); read.push(p.translation[0]) },
            }
            prop_assert!(published.len() - read.len() <= 1);
        }
        let unread = published.len() - read.len();
        prop_assert_eq!(&published[..published.len() - unread], &read[..]);
    }
}

trait Zeroed {
    fn default_zeroed() -> Self;
}
impl Zeroed for HliCoordinateSystemInt {
    fn default_zeroed() -> Self {
        bytemuck::Zeroable::zeroed()
    }
}
