//! Acyclic ADS-like calls from the PLC to the CNC over an iceoryx2 request-response service:
//! what a PLC function block sends once per Execute edge (table writes, coupling commands,
//! FIFO row blocks, reads of characteristic values...). Payloads are fixed `#[repr(C)]` frames;
//! each call kind is a typed pair of request body and reply body ([`AcyclicCall`]). A request
//! is answered with a reply body or refused with an [`ErrorCode`].
//!
//! The engines add their kinds to [`CallKind`]; this crate ships the plumbing and one working
//! kind, [`ReadAxisState`].

use crate::enums::InvalidValue;
use crate::layout::HliAxisLrState;
use bytemuck::{Pod, Zeroable};
use core::time::Duration;
use iceoryx2::node::Node;
use iceoryx2::port::client::Client;
use iceoryx2::port::server::Server;
use iceoryx2::prelude::*;
use std::time::Instant;

/// Bytes available for a request or reply body.
pub const ACYCLIC_BODY_SIZE: usize = 240;

/// The request frame.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct AcyclicRequest {
    /// Caller's running id, echoed in the response.
    pub invoke_id: u32,
    /// Raw [`CallKind`].
    pub kind: u32,
    /// Addressed object (axis, channel, table id), kind-specific.
    pub target: u32,
    /// Valid bytes in `body`.
    pub body_len: u32,
    /// Kind-specific request body.
    pub body: [u8; ACYCLIC_BODY_SIZE],
}

/// The response frame.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct AcyclicResponse {
    /// Echo of the request's id.
    pub invoke_id: u32,
    /// Echo of the request's kind.
    pub kind: u32,
    /// 0 on success, else an [`ErrorCode`].
    pub error_code: u32,
    /// Valid bytes in `body`.
    pub body_len: u32,
    /// Kind-specific reply body.
    pub body: [u8; ACYCLIC_BODY_SIZE],
}

const _: () = assert!(core::mem::size_of::<AcyclicRequest>() == 256);
const _: () = assert!(core::mem::size_of::<AcyclicResponse>() == 256);

impl Default for AcyclicRequest {
    fn default() -> Self {
        Zeroable::zeroed()
    }
}
impl Default for AcyclicResponse {
    fn default() -> Self {
        Zeroable::zeroed()
    }
}

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

/// Numbers of the call kinds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CallKind {
    /// [`ReadAxisState`].
    ReadAxisState,
    /// [`AxisCommandCall`].
    AxisCommand,
}

impl CallKind {
    /// The raw kind number.
    pub fn raw(self) -> u32 {
        match self {
            CallKind::ReadAxisState => 1,
            CallKind::AxisCommand => 2,
        }
    }

    /// Decodes a raw kind number.
    pub fn decode(raw: u32) -> Option<Self> {
        match raw {
            1 => Some(CallKind::ReadAxisState),
            2 => Some(CallKind::AxisCommand),
            _ => None,
        }
    }
}

/// A typed call: request body `Self`, reply body `Reply`.
pub trait AcyclicCall: Pod {
    /// The kind number.
    const KIND: CallKind;
    /// The reply body.
    type Reply: Pod;
}

/// Reads the cyclic state of the axis given as `target`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct ReadAxisState {
    /// Reserved, must be 0.
    pub reserved: u32,
}

impl AcyclicCall for ReadAxisState {
    const KIND: CallKind = CallKind::ReadAxisState;
    type Reply = HliAxisLrState;
}

const _: () = assert!(core::mem::size_of::<HliAxisLrState>() <= ACYCLIC_BODY_SIZE);

/// A motion command for the axis given as `target` (what MC_Power, MC_MoveAbsolute ... send
/// on their Execute edge). Units are the axis's (mm or degree, per second...).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct AxisCommandCall {
    /// Raw [`crate::enums::AxisCommandKind`].
    pub command: u32,
    /// MC_Power: 1 enable, 0 disable. Others: 0.
    pub enable: u32,
    /// MC_MoveVelocity: 1 positive, -1 negative. Others: 0.
    pub direction: i32,
    /// Reserved, 0.
    pub reserved: u32,
    /// Target position (absolute) or distance (relative).
    pub position: f64,
    /// Velocity limit of the move (or the velocity of MC_MoveVelocity), > 0.
    pub velocity: f64,
    /// Acceleration limit, > 0.
    pub acceleration: f64,
    /// Deceleration limit, > 0 (also of MC_Halt and MC_Stop).
    pub deceleration: f64,
    /// Jerk limit, > 0 (also of MC_Halt and MC_Stop).
    pub jerk: f64,
}

impl AxisCommandCall {
    fn motion(kind: crate::enums::AxisCommandKind) -> Self {
        Self {
            command: kind.raw(),
            ..Self::default()
        }
    }
    /// MC_Power with `enable`.
    pub fn power(enable: bool) -> Self {
        Self {
            enable: u32::from(enable),
            ..Self::motion(crate::enums::AxisCommandKind::Power)
        }
    }
    /// MC_Reset.
    pub fn reset() -> Self {
        Self::motion(crate::enums::AxisCommandKind::Reset)
    }
    /// MC_MoveAbsolute to `position` with the limits `[velocity, acceleration, deceleration,
    /// jerk]`.
    pub fn move_absolute(position: f64, limits: [f64; 4]) -> Self {
        Self {
            position,
            ..Self::motion(crate::enums::AxisCommandKind::MoveAbsolute).with_limits(limits)
        }
    }
    /// MC_MoveRelative by `distance` with the limits `[velocity, acceleration, deceleration,
    /// jerk]`.
    pub fn move_relative(distance: f64, limits: [f64; 4]) -> Self {
        Self {
            position: distance,
            ..Self::motion(crate::enums::AxisCommandKind::MoveRelative).with_limits(limits)
        }
    }
    /// MC_MoveVelocity in `direction` (1 or -1) at `limits[0]`.
    pub fn move_velocity(direction: i32, limits: [f64; 4]) -> Self {
        Self {
            direction,
            ..Self::motion(crate::enums::AxisCommandKind::MoveVelocity).with_limits(limits)
        }
    }
    /// MC_Halt with `deceleration` and `jerk`.
    pub fn halt(deceleration: f64, jerk: f64) -> Self {
        Self {
            deceleration,
            jerk,
            ..Self::motion(crate::enums::AxisCommandKind::Halt)
        }
    }
    /// MC_Stop with `deceleration` and `jerk`.
    pub fn stop(deceleration: f64, jerk: f64) -> Self {
        Self {
            deceleration,
            jerk,
            ..Self::motion(crate::enums::AxisCommandKind::Stop)
        }
    }
    /// Releases MC_Stop's lock.
    pub fn stop_release() -> Self {
        Self::motion(crate::enums::AxisCommandKind::StopRelease)
    }
    fn with_limits(self, [velocity, acceleration, deceleration, jerk]: [f64; 4]) -> Self {
        Self {
            velocity,
            acceleration,
            deceleration,
            jerk,
            ..self
        }
    }
}

/// The reply to an [`AxisCommandCall`]: the command's id, or why the axis refused it.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct AxisCommandReply {
    /// Id the axis gave the command (see `HLI_AXIS_COMMAND_STATE`), 0 when refused.
    pub command_id: u32,
    /// 0 when accepted, else the raw [`crate::enums::AxisError`] of the refusal.
    pub error_id: u32,
}

impl AcyclicCall for AxisCommandCall {
    const KIND: CallKind = CallKind::AxisCommand;
    type Reply = AxisCommandReply;
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
    /// iceoryx2 failed.
    #[error("request-response service: {0}")]
    Transport(String),
}

/// Decodes a request body as `T`; a size mismatch is [`ErrorCode::InvalidSize`].
pub fn decode_body<T: Pod>(request: &AcyclicRequest) -> Result<T, ErrorCode> {
    let len = request.body_len as usize;
    if len != core::mem::size_of::<T>() {
        return Err(ErrorCode::InvalidSize);
    }
    Ok(bytemuck::pod_read_unaligned(&request.body[..len]))
}

fn encode_body<T: Pod>(value: &T) -> ([u8; ACYCLIC_BODY_SIZE], u32) {
    let bytes = bytemuck::bytes_of(value);
    let mut body = [0u8; ACYCLIC_BODY_SIZE];
    body[..bytes.len()].copy_from_slice(bytes);
    (body, bytes.len() as u32)
}

/// Service name of an instance's acyclic calls.
pub fn service_name(instance: &str) -> String {
    format!("cncplc/{instance}/acyclic")
}

type AcyclicClientPort = Client<ipc::Service, AcyclicRequest, (), AcyclicResponse, ()>;
type AcyclicServerPort = Server<ipc::Service, AcyclicRequest, (), AcyclicResponse, ()>;

fn transport(e: impl core::fmt::Debug) -> CallError {
    CallError::Transport(format!("{e:?}"))
}

fn open_service(
    node: &Node<ipc::Service>,
    instance: &str,
) -> Result<
    iceoryx2::service::port_factory::request_response::PortFactory<
        ipc::Service,
        AcyclicRequest,
        (),
        AcyclicResponse,
        (),
    >,
    CallError,
> {
    let name: ServiceName = service_name(instance)
        .as_str()
        .try_into()
        .map_err(transport)?;
    node.service_builder(&name)
        .request_response::<AcyclicRequest, AcyclicResponse>()
        // One pending call per PLC block and axis: 32 axes with a move and a power block each.
        .max_active_requests_per_client(64)
        .open_or_create()
        .map_err(transport)
}

/// The PLC's end: sends calls and waits for their replies.
pub struct AcyclicClient {
    _node: Node<ipc::Service>,
    port: AcyclicClientPort,
    next_invoke_id: u32,
}

impl core::fmt::Debug for AcyclicClient {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("AcyclicClient")
    }
}

impl AcyclicClient {
    /// Connects to `instance`'s service (creating it if the server is not up yet).
    pub fn open(instance: &str) -> Result<Self, CallError> {
        let node = NodeBuilder::new()
            .create::<ipc::Service>()
            .map_err(transport)?;
        let port = open_service(&node, instance)?
            .client_builder()
            .create()
            .map_err(transport)?;
        Ok(Self {
            _node: node,
            port,
            next_invoke_id: 1,
        })
    }

    /// Sends `call` to `target` and waits up to `timeout` for the reply.
    pub fn call<C: AcyclicCall>(
        &mut self,
        target: u32,
        call: &C,
        timeout: Duration,
    ) -> Result<C::Reply, CallError> {
        let pending = self.start(target, call)?;
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(result) = pending.poll() {
                return result;
            }
            if Instant::now() >= deadline {
                return Err(CallError::Timeout(timeout));
            }
            std::thread::yield_now();
        }
    }

    /// Sends `call` to `target` without waiting: a PLC block sends on its Execute edge and
    /// polls the returned [`PendingCall`] in the following cycles (it stays Busy meanwhile).
    pub fn start<C: AcyclicCall>(
        &mut self,
        target: u32,
        call: &C,
    ) -> Result<PendingCall<C>, CallError> {
        let (body, body_len) = encode_body(call);
        let invoke_id = self.next_invoke_id;
        self.next_invoke_id = self.next_invoke_id.wrapping_add(1);
        let pending = self
            .port
            .send_copy(AcyclicRequest {
                invoke_id,
                kind: C::KIND.raw(),
                target,
                body_len,
                body,
            })
            .map_err(transport)?;
        Ok(PendingCall {
            pending,
            invoke_id,
            _call: core::marker::PhantomData,
        })
    }
}

type PendingPort = iceoryx2::pending_response::PendingResponse<
    ipc::Service,
    AcyclicRequest,
    (),
    AcyclicResponse,
    (),
>;

/// A call on its way: poll it until it yields the reply or the refusal.
pub struct PendingCall<C: AcyclicCall> {
    pending: PendingPort,
    invoke_id: u32,
    _call: core::marker::PhantomData<C>,
}

impl<C: AcyclicCall> core::fmt::Debug for PendingCall<C> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "PendingCall({})", self.invoke_id)
    }
}

impl<C: AcyclicCall> PendingCall<C> {
    /// The reply (or refusal) once the server has answered, `None` while it has not.
    pub fn poll(&self) -> Option<Result<C::Reply, CallError>> {
        let response = match self.pending.receive() {
            Ok(Some(response)) => response,
            Ok(None) => return None,
            Err(e) => return Some(Err(transport(e))),
        };
        let response: &AcyclicResponse = response.payload();
        Some(decode_response::<C>(response, self.invoke_id))
    }
}

fn decode_response<C: AcyclicCall>(
    response: &AcyclicResponse,
    invoke_id: u32,
) -> Result<C::Reply, CallError> {
    if response.invoke_id != invoke_id || response.kind != C::KIND.raw() {
        return Err(CallError::Malformed(format!(
            "response id/kind {}/{} for request {}/{}",
            response.invoke_id,
            response.kind,
            invoke_id,
            C::KIND.raw()
        )));
    }
    if response.error_code != 0 {
        let code = ErrorCode::decode(response.error_code)
            .map_err(|e| CallError::Malformed(e.to_string()))?;
        return Err(CallError::Refused { code });
    }
    let len = response.body_len as usize;
    if len != core::mem::size_of::<C::Reply>() {
        return Err(CallError::Malformed(format!(
            "reply body of {len} bytes, expected {}",
            core::mem::size_of::<C::Reply>()
        )));
    }
    Ok(bytemuck::pod_read_unaligned(&response.body[..len]))
}

/// A reply a handler produces: the encoded body or a refusal.
pub type HandlerResult = Result<([u8; ACYCLIC_BODY_SIZE], u32), ErrorCode>;

/// Encodes a typed reply for a handler.
pub fn reply<T: Pod>(value: &T) -> HandlerResult {
    Ok(encode_body(value))
}

/// The CNC's end: answers pending calls when polled (once per tick, outside the motion path).
pub struct AcyclicServer {
    _node: Node<ipc::Service>,
    port: AcyclicServerPort,
}

impl core::fmt::Debug for AcyclicServer {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("AcyclicServer")
    }
}

impl AcyclicServer {
    /// Opens (or creates) `instance`'s service and its server port.
    pub fn open(instance: &str) -> Result<Self, CallError> {
        let node = NodeBuilder::new()
            .create::<ipc::Service>()
            .map_err(transport)?;
        let port = open_service(&node, instance)?
            .server_builder()
            .create()
            .map_err(transport)?;
        Ok(Self { _node: node, port })
    }

    /// Answers every pending request with `handler(kind, request)`. Unknown kinds are refused
    /// with [`ErrorCode::ServiceNotSupported`] without calling the handler. Returns how many
    /// requests were answered.
    pub fn poll(
        &self,
        mut handler: impl FnMut(CallKind, &AcyclicRequest) -> HandlerResult,
    ) -> Result<usize, CallError> {
        let mut answered = 0;
        while let Some(active) = self.port.receive().map_err(transport)? {
            let request: &AcyclicRequest = active.payload();
            let result = match CallKind::decode(request.kind) {
                Some(kind) => handler(kind, request),
                None => Err(ErrorCode::ServiceNotSupported),
            };
            let (error_code, body, body_len) = match result {
                Ok((body, len)) => (0, body, len),
                Err(code) => (code.raw(), [0u8; ACYCLIC_BODY_SIZE], 0),
            };
            active
                .send_copy(AcyclicResponse {
                    invoke_id: request.invoke_id,
                    kind: request.kind,
                    error_code,
                    body_len,
                    body,
                })
                .map_err(transport)?;
            answered += 1;
        }
        Ok(answered)
    }
}

/// The standard handler for [`ReadAxisState`] over a CNC view: validates the index.
pub fn handle_read_axis_state(
    view: &crate::views::CncView<'_>,
    request: &AcyclicRequest,
) -> HandlerResult {
    let body: ReadAxisState = decode_body(request)?;
    if body.reserved != 0 {
        return Err(ErrorCode::InvalidData);
    }
    let axis = view
        .axis(request.target as usize)
        .map_err(|_| ErrorCode::InvalidTarget)?;
    let state: HliAxisLrState = crate::desc::PlaceExt::read(
        axis.field::<HliAxisLrState>(core::mem::offset_of!(crate::layout::HliAxis, lr_state)),
    );
    reply(&state)
}
