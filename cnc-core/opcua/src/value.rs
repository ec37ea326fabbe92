//! Values between the image and OPC UA: what a node reads (a leaf raw, a leaf scaled to its
//! engineering unit, or a figure the server derives), the source timestamp of the CNC tick
//! that wrote it, and a client's write checked by the handshake rules of `plc set`.

use crate::source::ImageSource;
use hli::access::{Leaf, Value};
use hli::desc::Scalar;
use hli::layout::image::HliSegmentHeader;
use hli::protocol::{check_protocol, show, Refusal, Refused, Write};
use hli::ImageMemory;
use opcua::types::{DataValue, DateTime, NumericRange, StatusCode, Variant};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// How long the PLC's heartbeat may stand still before the PLC counts as not alive.
const PLC_ALIVE_WITHIN: Duration = Duration::from_secs(1);

/// What a node reads.
pub enum Reading {
    /// A leaf in its own ST type.
    Raw(Leaf),
    /// A leaf divided by `per_unit`, as a Double in its engineering unit.
    Scaled {
        /// The leaf.
        leaf: Leaf,
        /// Raw increments per engineering unit.
        per_unit: f64,
    },
    /// Whether a PLC is attached and its heartbeat was seen to move within the last second
    /// (the heartbeat last seen and when it was seen to change: never, at the first look).
    PlcAlive(Mutex<Option<PlcSeen>>),
}

/// What [`Reading::PlcAlive`] saw last: of which CNC's image (its pid and start stamp: a new
/// CNC's PLC heartbeat is not compared with the old one's), the heartbeat, and when it was
/// seen to change (never, at the first look).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PlcSeen {
    cnc: (u32, u64),
    beats: u64,
    moved_at: Option<Instant>,
}

/// The OPC UA type of an ST type.
pub fn data_type(scalar: Scalar) -> opcua::types::DataTypeId {
    use opcua::types::DataTypeId as T;
    match scalar {
        Scalar::Bool => T::Boolean,
        Scalar::Usint => T::Byte,
        Scalar::Sint => T::SByte,
        Scalar::Uint => T::UInt16,
        Scalar::Int => T::Int16,
        Scalar::Udint => T::UInt32,
        Scalar::Dint => T::Int32,
        Scalar::Ulint => T::UInt64,
        Scalar::Lint => T::Int64,
        Scalar::Real => T::Float,
        Scalar::Lreal => T::Double,
    }
}

/// A leaf's raw value as the variant of its OPC UA type (the image holds it in range).
pub fn variant(scalar: Scalar, value: Value) -> Variant {
    let (i, u, r) = match value {
        Value::Int(i) => (i, i as u64, i as f64),
        Value::Unsigned(u) => (u as i64, u, u as f64),
        Value::Real(r) => (r as i64, r as u64, r),
    };
    match scalar {
        Scalar::Bool => Variant::Boolean(u != 0),
        Scalar::Usint => Variant::Byte(u as u8),
        Scalar::Sint => Variant::SByte(i as i8),
        Scalar::Uint => Variant::UInt16(u as u16),
        Scalar::Int => Variant::Int16(i as i16),
        Scalar::Udint => Variant::UInt32(u as u32),
        Scalar::Dint => Variant::Int32(i as i32),
        Scalar::Ulint => Variant::UInt64(u),
        Scalar::Lint => Variant::Int64(i),
        Scalar::Real => Variant::Float(r as f32),
        Scalar::Lreal => Variant::Double(r),
    }
}

/// Whether a client's value has the OPC UA type of `scalar` (no conversions: a panel that
/// writes a Double into a UDINT has the wrong node).
fn same_type(scalar: Scalar, value: &Variant) -> bool {
    std::mem::discriminant(&variant(scalar, Value::Unsigned(0))) == std::mem::discriminant(value)
}

/// A client's value as the image's, when its variant is a number or a boolean.
fn value_of(variant: &Variant) -> Option<Value> {
    Some(match *variant {
        Variant::Boolean(b) => Value::Unsigned(u64::from(b)),
        Variant::Byte(v) => Value::Unsigned(v.into()),
        Variant::UInt16(v) => Value::Unsigned(v.into()),
        Variant::UInt32(v) => Value::Unsigned(v.into()),
        Variant::UInt64(v) => Value::Unsigned(v),
        Variant::SByte(v) => Value::Int(v.into()),
        Variant::Int16(v) => Value::Int(v.into()),
        Variant::Int32(v) => Value::Int(v.into()),
        Variant::Int64(v) => Value::Int(v),
        Variant::Float(v) => Value::Real(v.into()),
        Variant::Double(v) => Value::Real(v),
        _ => return None,
    })
}

fn header_u64(memory: &ImageMemory, offset: usize) -> u64 {
    memory.place::<u64>(offset).load_acquire()
}

fn header_u32(memory: &ImageMemory, offset: usize) -> u32 {
    memory.place::<u32>(offset).load_acquire()
}

/// 100 ns ticks from 1601-01-01 (OPC UA's epoch) to 1970-01-01.
const UNIX_EPOCH_TICKS: i64 = 116_444_736_000_000_000;

/// When the tick that wrote the image's current heartbeat was due, by the epoch and cycle
/// the CNC announced; the server's clock when it announced none (or nonsense).
pub fn tick_stamp(memory: &ImageMemory) -> DateTime {
    use core::mem::offset_of;
    let epoch = header_u64(memory, offset_of!(HliSegmentHeader, cnc_epoch_ns));
    let cycle = header_u32(memory, offset_of!(HliSegmentHeader, cnc_cycle_ns));
    let beats = header_u64(memory, offset_of!(HliSegmentHeader, cnc_heartbeat));
    let ns = beats
        .checked_mul(u64::from(cycle))
        .and_then(|t| t.checked_add(epoch))
        .filter(|_| epoch != 0 && cycle != 0)
        .and_then(|ns| i64::try_from(ns / 100).ok())
        .and_then(|ticks| ticks.checked_add(UNIX_EPOCH_TICKS));
    ns.map_or_else(DateTime::now, DateTime::from)
}

impl Reading {
    fn read(&self, memory: &ImageMemory) -> Variant {
        match self {
            Reading::Raw(leaf) => variant(leaf.scalar, leaf.read(memory)),
            Reading::Scaled { leaf, per_unit } => {
                Variant::Double(leaf.read(memory).as_f64() / per_unit)
            }
            Reading::PlcAlive(seen) => {
                use core::mem::offset_of;
                let pid = header_u32(memory, offset_of!(HliSegmentHeader, plc_pid));
                let beats = header_u64(memory, offset_of!(HliSegmentHeader, plc_heartbeat));
                let cnc = (
                    header_u32(memory, offset_of!(HliSegmentHeader, cnc_pid)),
                    header_u64(memory, offset_of!(HliSegmentHeader, cnc_start_stamp)),
                );
                let now = Instant::now();
                let mut seen = seen.lock().unwrap_or_else(|e| e.into_inner());
                // Alive once the heartbeat is seen to move, until it stands for a second.
                let moved = match *seen {
                    Some(last) if last.cnc == cnc && last.beats == beats => last
                        .moved_at
                        .is_some_and(|at| now.duration_since(at) < PLC_ALIVE_WITHIN),
                    last => {
                        let moved = last.is_some_and(|last| last.cnc == cnc);
                        let moved_at = moved.then_some(now);
                        *seen = Some(PlcSeen {
                            cnc,
                            beats,
                            moved_at,
                        });
                        moved
                    }
                };
                Variant::Boolean(pid != 0 && moved)
            }
        }
    }
}

/// What `reading` reads now, dated by the CNC's tick; `BadNoCommunication` while no CNC
/// serves the image.
pub fn read(source: &dyn ImageSource, reading: &Reading) -> DataValue {
    let mut found = None;
    source.with_image(&mut |memory| found = Some((reading.read(memory), tick_stamp(memory))));
    match found {
        Some((value, stamp)) => DataValue {
            value: Some(value),
            status: Some(StatusCode::Good),
            source_timestamp: Some(stamp),
            server_timestamp: Some(DateTime::now()),
            ..Default::default()
        },
        None => DataValue {
            value: None,
            status: Some(StatusCode::BadNoCommunication),
            source_timestamp: Some(DateTime::now()),
            server_timestamp: Some(DateTime::now()),
            ..Default::default()
        },
    }
}

/// A client's write of `leaf` at `path`: its type, its range, then the handshake rules of
/// `plc set` against the image as it is now; written only when all pass.
pub fn write(
    source: &dyn ImageSource,
    path: &str,
    leaf: Leaf,
    data: &DataValue,
    range: &NumericRange,
) -> StatusCode {
    if range.has_range() {
        return StatusCode::BadIndexRangeInvalid;
    }
    let given = data.value.as_ref().filter(|v| same_type(leaf.scalar, v));
    let Some(value) = given.and_then(value_of) else {
        return StatusCode::BadTypeMismatch;
    };
    if !value.as_f64().is_finite() {
        return StatusCode::BadOutOfRange;
    }
    let Ok(value) = leaf.check(path, value) else {
        return StatusCode::BadOutOfRange;
    };
    let mut status = StatusCode::BadNoCommunication;
    source.with_image_to_write(&mut |memory| {
        let one = [Write { path, leaf, value }];
        status = match check_protocol(memory, &one) {
            Ok(()) => {
                leaf.write(memory, value);
                crate::say!("write {path} := {}", show(&leaf, value));
                StatusCode::Good
            }
            Err(Refused {
                reason: Refusal::CncOwned,
                ..
            }) => StatusCode::BadNotWritable,
            // The unit's semaphore or command word says the other side has not taken the
            // last datum: try again later.
            Err(_) => StatusCode::BadInvalidState,
        };
    });
    status
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tick_is_dated_by_the_epoch_and_cycle_the_cnc_announced() {
        use core::mem::offset_of;
        let image = hli::image::heap_image(1, 1);
        let at = |field: usize| image.place::<u64>(field);
        // 2026-01-01T00:00:00Z is 1_767_225_600 s after the Unix epoch.
        at(offset_of!(HliSegmentHeader, cnc_epoch_ns)).store_release(1_767_225_600 * 1_000_000_000);
        at(offset_of!(HliSegmentHeader, cnc_heartbeat)).store_release(2_500);
        let stamp = tick_stamp(&image);
        let cycle_ns = image
            .place::<u32>(offset_of!(HliSegmentHeader, cnc_cycle_ns))
            .load();
        assert_eq!(cycle_ns, 1_000_000, "the default cycle");
        assert_eq!(stamp, DateTime::from((2026, 1, 1, 0, 0, 2, 500_000_000)));
        at(offset_of!(HliSegmentHeader, cnc_epoch_ns)).store_release(0);
        let now = DateTime::now();
        assert!(
            (tick_stamp(&image).ticks() - now.ticks()).abs() < 10_000_000,
            "no epoch: now"
        );
    }

    #[test]
    fn a_plc_is_alive_once_its_heartbeat_is_seen_to_move() {
        use core::mem::offset_of;
        let image = hli::image::heap_image(1, 1);
        let pid = image.place::<u32>(offset_of!(HliSegmentHeader, plc_pid));
        let beats = image.place::<u64>(offset_of!(HliSegmentHeader, plc_heartbeat));
        let alive = Reading::PlcAlive(Mutex::new(None));
        pid.store_release(4242);
        beats.store_release(7);
        // A PLC that left its pid and heartbeat behind: never seen moving.
        assert_eq!(alive.read(&image), Variant::Boolean(false));
        assert_eq!(alive.read(&image), Variant::Boolean(false));
        beats.store_release(8);
        assert_eq!(alive.read(&image), Variant::Boolean(true));
        assert_eq!(
            alive.read(&image),
            Variant::Boolean(true),
            "within the second"
        );
        // A new CNC (another start stamp) whose PLC heartbeat differs: not yet seen moving.
        let stamp = image.place::<u64>(offset_of!(HliSegmentHeader, cnc_start_stamp));
        stamp.store_release(stamp.load() + 1);
        beats.store_release(3);
        assert_eq!(alive.read(&image), Variant::Boolean(false), "a new CNC");
        beats.store_release(4);
        assert_eq!(alive.read(&image), Variant::Boolean(true));
        pid.store_release(0);
        assert_eq!(alive.read(&image), Variant::Boolean(false), "detached");
    }

    #[test]
    fn client_values_map_to_the_image_and_odd_variants_do_not() {
        assert_eq!(value_of(&Variant::Boolean(true)), Some(Value::Unsigned(1)));
        assert_eq!(value_of(&Variant::Int32(-5)), Some(Value::Int(-5)));
        assert_eq!(value_of(&Variant::Double(1.5)), Some(Value::Real(1.5)));
        assert_eq!(value_of(&Variant::from("12")), None);
    }
}
