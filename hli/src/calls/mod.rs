//! The acyclic calls: what every call has in common, and the registry of the call kinds.
//!
//! Here: the ADS-style refusal codes ([`ErrorCode`]), why a call produced no reply
//! ([`CallError`]), the typed call ([`AcyclicCall`]), the body decoding a handler uses
//! ([`decode_body`], [`decode_reply`], [`reply`]), and the call kinds: [`CallKind`] is an
//! open number that every family extends, [`FAMILIES`] the registry of them all. The
//! vocabularies are one module per family, beside the engine that answers them: [`axis`],
//! [`cam`], [`fifo`], [`saw`], [`probe`], [`diag`].
//!
//! # How a family adds its calls
//!
//! One file in this folder holds the family's request and reply bodies (`#[repr(C)]`,
//! `Pod`) and declares its kinds, one line each, with the `calls!` macro of this module:
//!
//! ```ignore
//! calls! { family "cam";
//!     /// MC_CamIn / MC_CamInExt ([`CamInCall`]).
//!     CAM_IN = 11: CamInCall -> CamReply, command;
//!     /// Cam data read in parts ([`CamReadCall`]).
//!     CAM_READ = 18: CamReadCall -> CamValuesReply, read_only;
//! }
//! ```
//!
//! A line names the kind (`CallKind::CAM_IN`, its number on the wire), binds the request body
//! to it and to its reply (`impl AcyclicCall for CamInCall`), asserts at compile time that
//! both bodies fit a frame, and lists the kind in the family's `CALLS`. `read_only` kinds
//! only read: a stopped machine still answers them; `command` kinds change something; `bulk`
//! kinds change something with numbers that come in shared memory (the bulk service). The
//! family then joins with its `pub mod` here and one entry in [`FAMILIES`]. A kind number
//! used twice, in one family or across two, does not compile.

use crate::enums::InvalidValue;
use crate::wire::{encode_body, AcyclicRequest, ACYCLIC_BODY_SIZE};
use bytemuck::Pod;
use core::time::Duration;

/// Declares a family's call kinds (see the module documentation): the `CallKind`
/// constants, then what every family has ([`call_specs!`]).
macro_rules! calls {
    (
        family $family:literal;
        $(
            $(#[doc = $doc:literal])*
            $kind:ident = $raw:literal : $call:ident -> $reply:ty, $access:ident;
        )*
    ) => {
        impl $crate::calls::CallKind {
            $(
                $(#[doc = $doc])*
                pub const $kind: $crate::calls::CallKind = $crate::calls::CallKind($raw);
            )*
        }

        $crate::call_specs! { family $family;
            $($kind ($crate::calls::CallKind::$kind): $call -> $reply, $access;)*
        }
    };
}

/// Declares the call kinds of an extension family: an engine outside this crate, with its
/// own numbers (which [`register_extension`] checks against every other). The same lines as
/// `calls!` of the built-in families; the kinds become constants of the declaring module
/// (`my_family::PHASE_GEAR_IN`) rather than of [`CallKind`], and the module's `CALLS` is
/// what the extension registers.
///
/// ```ignore
/// hli::extension_calls! { family "phase_gear";
///     /// Couple with a ratio and a phase.
///     PHASE_GEAR_IN = 70: PhaseGearInCall -> PhaseGearReply, command;
/// }
/// ```
#[macro_export]
macro_rules! extension_calls {
    (
        family $family:literal;
        $(
            $(#[doc = $doc:literal])*
            $kind:ident = $raw:literal : $call:ident -> $reply:ty, $access:ident;
        )*
    ) => {
        $(
            $(#[doc = $doc])*
            pub const $kind: $crate::calls::CallKind = $crate::calls::CallKind::declare($raw);
        )*

        $crate::call_specs! { family $family;
            $($kind ($kind): $call -> $reply, $access;)*
        }
    };
}

/// What every family declares beside its kinds (the part `calls!` and `extension_calls!`
/// share): the `AcyclicCall` implementations, frame-size assertions and the family's
/// `CALLS`. Each line names a kind, the path of its constant, its bodies and its access.
#[doc(hidden)]
#[macro_export]
macro_rules! call_specs {
    (
        family $family:literal;
        $($kind:ident ($path:path): $call:ident -> $reply:ty, $access:ident;)*
    ) => {
        $(
            impl $crate::calls::AcyclicCall for $call {
                const KIND: $crate::calls::CallKind = $path;
                type Reply = $reply;
            }

            const _: () = assert!(
                core::mem::size_of::<$call>() <= $crate::wire::ACYCLIC_BODY_SIZE
                    && core::mem::size_of::<$reply>() <= $crate::wire::ACYCLIC_BODY_SIZE
            );
        )*

        /// This family's call kinds (what its registry entry lists).
        pub const CALLS: &[$crate::calls::CallSpec] = &[
            $(
                $crate::calls::CallSpec {
                    kind: $path,
                    name: stringify!($kind),
                    read_only: $crate::call_specs!(@read_only $access),
                    bulk: $crate::call_specs!(@bulk $access),
                    family: $family,
                },
            )*
        ];
    };
    (@read_only read_only) => { true };
    (@read_only command) => { false };
    (@read_only bulk) => { false };
    (@bulk bulk) => { true };
    (@bulk command) => { false };
    (@bulk read_only) => { false };
}

pub mod axis;
pub mod cam;
pub mod diag;
pub mod fifo;
pub mod probe;
pub mod saw;

/// Every family's call kinds: the registry [`CallKind::decode`] and [`CallKind::spec`] read.
pub const FAMILIES: &[&[CallSpec]] = &[
    axis::CALLS,
    cam::CALLS,
    fifo::CALLS,
    saw::CALLS,
    probe::CALLS,
    diag::CALLS,
];

/// The kind of an acyclic call: its number on the wire. Each family declares its kinds as
/// constants (`CallKind::CAM_IN`, ... see the family modules), which also work as patterns;
/// a number off the wire becomes a kind through [`CallKind::decode`], which knows the
/// declared kinds only.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct CallKind(u32);

/// What the registry knows of a call kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CallSpec {
    /// The kind.
    pub kind: CallKind,
    /// Its name as declared (`"CAM_IN"`).
    pub name: &'static str,
    /// Whether the call only reads (a stopped machine answers it).
    pub read_only: bool,
    /// Whether it is a bulk call: its numbers come in shared memory by the bulk service, never
    /// in a frame (and nothing else comes by the bulk service).
    pub bulk: bool,
    /// The family that declares it (`"cam"`).
    pub family: &'static str,
}

impl CallKind {
    /// The kind of an extension family (an engine outside this crate, [`register_extension`]):
    /// its number must be one no built-in family declares, which registration checks. The
    /// built-in families name theirs as `CallKind::NAME` constants instead.
    pub const fn declare(raw: u32) -> CallKind {
        CallKind(raw)
    }

    /// The raw kind number.
    pub const fn raw(self) -> u32 {
        self.0
    }

    /// The kind of a raw number, if a family declares it (a built-in one or a registered
    /// extension).
    pub fn decode(raw: u32) -> Option<CallKind> {
        CallKind(raw).spec().map(|spec| spec.kind)
    }

    /// The kind's entry in the registry: a built-in family's, else a registered extension's.
    pub fn spec(self) -> Option<&'static CallSpec> {
        builtin_spec(self.0).or_else(|| {
            let extensions = EXTENSIONS.get()?;
            extensions
                .iter()
                .flat_map(|f| f.iter())
                .find(|s| s.kind == self)
        })
    }

    /// Whether the call only reads (a stopped machine still answers it).
    pub fn is_read_only(self) -> bool {
        self.spec().is_some_and(|spec| spec.read_only)
    }

    /// Whether the kind is a bulk call ([`CallSpec::bulk`]).
    pub fn is_bulk(self) -> bool {
        self.spec().is_some_and(|spec| spec.bulk)
    }
}

/// The built-in families' entry for number `raw`.
const fn builtin_spec(raw: u32) -> Option<&'static CallSpec> {
    let mut f = 0;
    while f < FAMILIES.len() {
        let family: &'static [CallSpec] = FAMILIES[f];
        let mut i = 0;
        while i < family.len() {
            if family[i].kind.0 == raw {
                return Some(&family[i]);
            }
            i += 1;
        }
        f += 1;
    }
    None
}

/// The call families of engines outside this crate, registered once per process.
static EXTENSIONS: std::sync::OnceLock<&'static [&'static [CallSpec]]> = std::sync::OnceLock::new();

/// Why extension families were not registered.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RegisterError {
    /// A number a built-in family or another extension kind already declares.
    #[error("call kind {name} = {raw}: the number is declared already")]
    Taken {
        /// The extension kind's name.
        name: &'static str,
        /// Its number.
        raw: u32,
    },
    /// Other extension families were registered before.
    #[error("other extension call families are registered already")]
    Registered,
}

/// Registers the call families of engines outside this crate, once per process, before the
/// first call is decoded (a program's `main`, a test's first line). Registering the same
/// families again is allowed; others are refused, as is a number declared twice.
pub fn register_extension(families: &'static [&'static [CallSpec]]) -> Result<(), RegisterError> {
    let specs = || families.iter().flat_map(|f| f.iter());
    for (i, spec) in specs().enumerate() {
        let twice = specs().take(i).any(|o| o.kind == spec.kind);
        if twice || builtin_spec(spec.kind.0).is_some() {
            let (name, raw) = (spec.name, spec.kind.0);
            return Err(RegisterError::Taken { name, raw });
        }
    }
    let set = EXTENSIONS.get_or_init(|| families);
    if core::ptr::eq(*set, families) {
        Ok(())
    } else {
        Err(RegisterError::Registered)
    }
}

/// The declared name (`CAM_IN`).
impl core::fmt::Debug for CallKind {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self.spec() {
            Some(spec) => f.write_str(spec.name),
            None => write!(f, "CallKind({})", self.0),
        }
    }
}

/// How many registered kinds have the number `raw`.
const fn declarations(raw: u32) -> usize {
    let mut count = 0;
    let mut f = 0;
    while f < FAMILIES.len() {
        let mut i = 0;
        while i < FAMILIES[f].len() {
            if FAMILIES[f][i].kind.0 == raw {
                count += 1;
            }
            i += 1;
        }
        f += 1;
    }
    count
}

// No kind number is declared twice.
const _: () = {
    let mut f = 0;
    while f < FAMILIES.len() {
        let mut i = 0;
        while i < FAMILIES[f].len() {
            assert!(
                declarations(FAMILIES[f][i].kind.0) == 1,
                "a call kind number is declared twice"
            );
            i += 1;
        }
        f += 1;
    }
};

macro_rules! codes {
    ($( $(#[doc = $d:literal])* $name:ident = $v:literal ),* $(,)?) => {
        /// Why a call was refused: ADS-style device error codes.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum ErrorCode { $( $(#[doc = $d])* $name, )* }
        impl ErrorCode {
            /// The numeric code.
            pub fn raw(self) -> u32 { match self { $( ErrorCode::$name => $v, )* } }
            /// Decodes a numeric code.
            pub fn decode(raw: u32) -> Result<Self, InvalidValue> {
                $( if raw == $v { return Ok(ErrorCode::$name); } )*
                Err(InvalidValue { type_name: "ErrorCode", raw: raw as i64,
                                   allowed: concat!($(stringify!($v), " "),*) })
            }
        }
    };
}

codes! {
    /// The call kind is not known to the server (0x701, service not supported).
    ServiceNotSupported = 0x701,
    /// The target (axis, channel, table) does not exist (0x703, invalid index offset).
    InvalidTarget = 0x703,
    /// The body has the wrong size for the kind (0x705, invalid size).
    InvalidSize = 0x705,
    /// The body's values are not acceptable (0x706, invalid data).
    InvalidData = 0x706,
    /// The addressed object is busy or in a state that refuses the call (0x712, busy).
    Busy = 0x712,
}

/// A typed call: request body `Self`, reply body `Reply`.
pub trait AcyclicCall: Pod {
    /// The kind number.
    const KIND: CallKind;
    /// The reply body.
    type Reply: Pod;
}

/// Why a call did not produce a reply.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CallError {
    /// The server refused it.
    #[error("refused with error 0x{:X} ({code:?})", code.raw())]
    Refused {
        /// The server's code.
        code: ErrorCode,
    },
    /// The server answered with something that does not decode.
    #[error("malformed response: {0}")]
    Malformed(String),
    /// No answer within the timeout.
    #[error("no response within {0:?}")]
    Timeout(Duration),
    /// The transport (the call mailbox, `hli_transport::rpc::mailbox`) failed: opening it, or a loan
    /// taken away.
    #[error("call mailbox: {0}")]
    Transport(String),
    /// Every slot of the call mailbox is taken (calls on their way at once); nothing was sent.
    #[error("call mailbox: every slot is taken")]
    SlotsTaken,
    /// A bulk call of more numbers than a slot holds; nothing was sent.
    #[error("call mailbox: {0} numbers, more than a bulk slot holds")]
    TooLarge(usize),
}

/// Decodes a request body as `T`; a size mismatch is [`ErrorCode::InvalidSize`].
pub fn decode_body<T: Pod>(request: &AcyclicRequest) -> Result<T, ErrorCode> {
    let len = request.body_len as usize;
    if len != core::mem::size_of::<T>() {
        return Err(ErrorCode::InvalidSize);
    }
    Ok(bytemuck::pod_read_unaligned(&request.body[..len]))
}

/// Decodes a handler's reply body as `C`'s reply; a size mismatch is
/// [`ErrorCode::InvalidSize`].
pub fn decode_reply<C: AcyclicCall>(
    body: &[u8; ACYCLIC_BODY_SIZE],
    len: u32,
) -> Result<C::Reply, ErrorCode> {
    if len as usize != core::mem::size_of::<C::Reply>() {
        return Err(ErrorCode::InvalidSize);
    }
    Ok(bytemuck::pod_read_unaligned(&body[..len as usize]))
}

/// A reply a handler produces: the encoded body or a refusal.
pub type HandlerResult = Result<([u8; ACYCLIC_BODY_SIZE], u32), ErrorCode>;

/// Encodes a typed reply for a handler.
pub fn reply<T: Pod>(value: &T) -> HandlerResult {
    Ok(encode_body(value))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The numbers on the wire as released: none may change. A new kind needs no line here
    /// (its number is its declaration's; a number used twice does not compile).
    const WIRE: &[(CallKind, u32)] = &[
        (CallKind::READ_AXIS_STATE, 1),
        (CallKind::AXIS_COMMAND, 2),
        (CallKind::CAM_TABLE_SELECT, 10),
        (CallKind::CAM_IN, 11),
        (CallKind::CAM_OUT, 12),
        (CallKind::CAM_SCALING, 13),
        (CallKind::CAM_POINTS_WRITE, 14),
        (CallKind::CAM_POINTS_READ, 15),
        (CallKind::CAM_ONLINE_MODE, 16),
        (CallKind::CAM_ROWS_WRITE, 17),
        (CallKind::CAM_READ, 18),
        (CallKind::CAM_TABLE_WEIGHT, 19),
        (CallKind::CAM_MULTI_COUPLE, 20),
        (CallKind::CAM_MULTI_TABLE, 21),
        (CallKind::CAM_TABLE_DELETE, 22),
        (CallKind::FIFO_DIMENSION, 30),
        (CallKind::FIFO_INTEGRATE, 31),
        (CallKind::FIFO_DISINTEGRATE, 32),
        (CallKind::FIFO_START, 33),
        (CallKind::FIFO_STOP, 34),
        (CallKind::FIFO_OVERRIDE, 35),
        (CallKind::FIFO_PARAMETERS, 36),
        (CallKind::FIFO_WRITE_ROWS, 37),
        (CallKind::FIFO_OVERWRITE_ROWS, 38),
        (CallKind::SAW_GEAR_IN, 40),
        (CallKind::SAW_GEAR_OUT, 41),
        (CallKind::SAW_CHARAC, 42),
        (CallKind::PROBE_ARM, 50),
        (CallKind::PROBE_ABORT, 51),
        (CallKind::DYN_CS_HISTORY_READ, 60),
        (CallKind::DYN_CS_LOG_READ, 61),
    ];

    #[test]
    fn every_kind_keeps_its_number_and_the_registry_holds_them_all() {
        let registered: Vec<CallKind> = FAMILIES
            .iter()
            .flat_map(|f| f.iter().map(|s| s.kind))
            .collect();
        for &(kind, raw) in WIRE {
            assert!(registered.contains(&kind), "{kind:?} left the registry");
            assert_eq!(kind.raw(), raw);
            assert_eq!(CallKind::decode(raw), Some(kind));
            assert_eq!(kind.spec().map(|s| s.kind), Some(kind));
        }
        // Only a declared number decodes.
        for raw in (0..=1000).chain([u32::MAX]) {
            let declared = registered.iter().any(|k| k.raw() == raw);
            assert_eq!(CallKind::decode(raw).is_some(), declared, "{raw}");
        }
    }

    #[test]
    fn the_reads_a_stopped_machine_answers() {
        // The released kinds a stopped machine answers; every other released kind changes
        // something and stays refused by a stopped machine. A new kind is its declaration.
        const READS: [CallKind; 7] = [
            CallKind::READ_AXIS_STATE,
            CallKind::CAM_POINTS_READ,
            CallKind::CAM_READ,
            CallKind::FIFO_DIMENSION,
            CallKind::SAW_CHARAC,
            CallKind::DYN_CS_HISTORY_READ,
            CallKind::DYN_CS_LOG_READ,
        ];
        for &(kind, _) in WIRE {
            assert_eq!(kind.is_read_only(), READS.contains(&kind), "{kind:?}");
        }
    }

    #[test]
    fn a_kind_prints_its_name_and_matches_as_a_pattern() {
        assert_eq!(format!("{:?}", CallKind::CAM_IN), "CAM_IN");
        assert_eq!(CallKind::FIFO_START.spec().map(|s| s.family), Some("fifo"));
        assert_eq!(<cam::CamReadCall as AcyclicCall>::KIND, CallKind::CAM_READ);
        let family = |kind| match kind {
            CallKind::CAM_IN | CallKind::CAM_OUT => "cam",
            CallKind::PROBE_ARM => "probe",
            _ => "other",
        };
        assert_eq!(family(CallKind::decode(12).unwrap()), "cam");
        assert_eq!(family(CallKind::PROBE_ARM), "probe");
        assert_eq!(family(CallKind::AXIS_COMMAND), "other");
    }
}
