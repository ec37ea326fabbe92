//! The transport of the acyclic ADS-like calls from the PLC to the CNC: a mailbox of call slots
//! in shared memory ([`mailbox`]) carrying the frames of [`crate::wire`], one call per PLC
//! block Execute edge (table writes, coupling commands, reads of characteristic values...),
//! without allocating on either side; and bulk calls whose numbers are written straight into
//! shared memory (FIFO row blocks), an iceoryx2 request-response service. The vocabulary (call kinds, typed bodies, refusal codes) is [`crate::calls`]
//! and its families; this module is the transport alone. The CNC-side handlers live with the CNC's view
//! ([`crate::views::handle_read_axis_state`]) and in the engines.

use crate::calls::{AcyclicCall, CallError, CallKind, ErrorCode, HandlerResult};
use crate::wire::{
    encode_body, AcyclicRequest, AcyclicResponse, BulkHeader, ACYCLIC_BODY_SIZE, BULK_MAX_VALUES,
};
use core::time::Duration;
use iceoryx2::node::Node;
use iceoryx2::port::client::Client;
use iceoryx2::port::server::Server;
use iceoryx2::prelude::*;
use mailbox::{Mailbox, Ticket, MAILBOX_SLOTS};
use std::sync::Arc;
use std::time::Instant;

pub mod mailbox;

/// Service name of an instance's bulk calls (FIFO row blocks).
pub fn rows_service_name(instance: &str) -> String {
    format!("cncplc/{instance}/fifo-rows")
}

type RowsClientPort = Client<ipc::Service, [f64], BulkHeader, AcyclicResponse, ()>;
type RowsServerPort = Server<ipc::Service, [f64], BulkHeader, AcyclicResponse, ()>;
type RowsPendingPort = iceoryx2::pending_response::PendingResponse<
    ipc::Service,
    [f64],
    BulkHeader,
    AcyclicResponse,
    (),
>;

fn transport(e: impl core::fmt::Debug) -> CallError {
    CallError::Transport(format!("{e:?}"))
}

/// The row service, from which each end makes its port.
type RowsService = iceoryx2::service::port_factory::request_response::PortFactory<
    ipc::Service,
    [f64],
    BulkHeader,
    AcyclicResponse,
    (),
>;

/// Prints the type's name alone: the iceoryx2 ports have nothing worth showing.
macro_rules! debug_by_name {
    ($($ty:ident),*) => {
        $(impl core::fmt::Debug for $ty {
            fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                f.write_str(stringify!($ty))
            }
        })*
    };
}

debug_by_name!(AcyclicClient, AcyclicServer, RowsLoan, PendingRows);

/// A service name as iceoryx2 takes it.
fn name_of(name: String) -> Result<ServiceName, CallError> {
    name.as_str().try_into().map_err(transport)
}

fn open_rows_service(node: &Node<ipc::Service>, instance: &str) -> Result<RowsService, CallError> {
    node.service_builder(&name_of(rows_service_name(instance))?)
        .request_response::<[f64], AcyclicResponse>()
        .request_user_header::<BulkHeader>()
        // A few FiFoWrite/FiFoOverwrite instances per group, each with one block on its way.
        .max_active_requests_per_client(16)
        .max_loaned_requests(4)
        .open_or_create()
        .map_err(transport)
}

/// A node of its own for one end of `instance`'s row service, and the end's port.
fn open_end<R, F: core::fmt::Debug>(
    instance: &str,
    rows: impl FnOnce(&RowsService) -> Result<R, F>,
) -> Result<(Node<ipc::Service>, R), CallError> {
    let node = NodeBuilder::new()
        .create::<ipc::Service>()
        .map_err(transport)?;
    let rows = rows(&open_rows_service(&node, instance)?).map_err(transport)?;
    Ok((node, rows))
}

/// The PLC's end: sends calls and waits for their replies; sends FIFO row blocks.
pub struct AcyclicClient {
    _node: Node<ipc::Service>,
    calls: Arc<Mailbox>,
    rows: RowsClientPort,
    next_invoke_id: u32,
    sent: u64,
}

impl AcyclicClient {
    /// Connects to `instance`'s calls (the CNC's server must have made its mailbox).
    pub fn open(instance: &str) -> Result<Self, CallError> {
        let calls = Arc::new(Mailbox::open(instance)?);
        let (node, rows) = open_end(instance, |rows| {
            rows.client_builder()
                .initial_max_slice_len(BULK_MAX_VALUES)
                .create()
        })?;
        Ok(Self {
            _node: node,
            calls,
            rows,
            next_invoke_id: 1,
            sent: 0,
        })
    }

    /// Loans a bulk call of `values` values in the shared memory the CNC will read: the PLC
    /// computes its rows straight into it ([`RowsLoan::values_mut`]) and sends it whole
    /// ([`RowsLoan::send`]). A loan that is dropped, or whose process dies before the send,
    /// never reaches the CNC: there is no half block.
    pub fn loan_rows(&mut self, header: BulkHeader, values: usize) -> Result<RowsLoan, CallError> {
        let mut loan = self.rows.loan_slice(values).map_err(transport)?;
        *loan.user_header_mut() = header;
        Ok(RowsLoan { loan })
    }

    /// Sends a bulk call (a FIFO row block: `FiFoWrite`, `FiFoOverwrite`): `values` holds
    /// `header.rows x header.columns` values, row after row, and is written once, straight
    /// into the shared memory the CNC reads it from. Poll the returned [`PendingRows`].
    pub fn start_rows(
        &mut self,
        header: BulkHeader,
        values: &[f64],
    ) -> Result<PendingRows, CallError> {
        let mut loan = self
            .rows
            .loan_slice_uninit(values.len())
            .map_err(transport)?;
        *loan.user_header_mut() = header;
        let pending = loan.write_from_slice(values).send().map_err(transport)?;
        self.sent += 1;
        Ok(PendingRows { pending })
    }

    /// Calls sent by [`AcyclicClient::start`] and [`AcyclicClient::start_rows`] (and so by
    /// [`AcyclicClient::call`]); loaned row blocks are not counted.
    pub fn sent(&self) -> u64 {
        self.sent
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
        let request = AcyclicRequest {
            invoke_id,
            kind: C::KIND.raw(),
            target,
            body_len,
            body,
        };
        let (slot, ticket) = self.calls.send(&request)?;
        self.sent += 1;
        Ok(PendingCall {
            ticket: Ticket {
                mailbox: Arc::clone(&self.calls),
                slot,
                ticket,
                taken: core::cell::Cell::new(false),
            },
            invoke_id,
            _call: core::marker::PhantomData,
        })
    }
}

/// A call on its way: poll it until it yields the reply or the refusal. Dropped before, it
/// gives the call up (the CNC still carries it out, as a frame already sent).
pub struct PendingCall<C: AcyclicCall> {
    ticket: Ticket,
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
        let response = self.ticket.take()?;
        Some(decode_response::<C>(&response, self.invoke_id))
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
    decode_reply_body(response)
}

/// The body of an answered response as `R`, or its refusal.
fn decode_reply_body<R: bytemuck::Pod>(response: &AcyclicResponse) -> Result<R, CallError> {
    if response.error_code != 0 {
        let code = ErrorCode::decode(response.error_code)
            .map_err(|e| CallError::Malformed(e.to_string()))?;
        return Err(CallError::Refused { code });
    }
    let len = response.body_len as usize;
    if len != core::mem::size_of::<R>() {
        return Err(CallError::Malformed(format!(
            "reply body of {len} bytes, expected {}",
            core::mem::size_of::<R>()
        )));
    }
    Ok(bytemuck::pod_read_unaligned(&response.body[..len]))
}

type RowsLoanPort =
    iceoryx2::request_mut::RequestMut<ipc::Service, [f64], BulkHeader, AcyclicResponse, ()>;

/// A row block being written in place (see [`AcyclicClient::loan_rows`]).
pub struct RowsLoan {
    loan: RowsLoanPort,
}

impl RowsLoan {
    /// The block's values, row after row (zero until written).
    pub fn values_mut(&mut self) -> &mut [f64] {
        self.loan.payload_mut()
    }

    /// Sends the block whole.
    pub fn send(self) -> Result<PendingRows, CallError> {
        let pending = self.loan.send().map_err(transport)?;
        Ok(PendingRows { pending })
    }
}

/// A row block on its way: poll it until it yields the CNC's reply.
pub struct PendingRows {
    pending: RowsPendingPort,
}

impl PendingRows {
    /// The CNC's reply, decoded as `R` (the reply body of the bulk call's kind), once it has
    /// answered; `None` while it has not.
    pub fn poll<R: bytemuck::Pod>(&self) -> Option<Result<R, CallError>> {
        let response = match self.pending.receive() {
            Ok(Some(response)) => response,
            Ok(None) => return None,
            Err(e) => return Some(Err(transport(e))),
        };
        let response: &AcyclicResponse = response.payload();
        Some(decode_reply_body(response))
    }
}

/// The CNC's end: answers pending calls and row blocks when polled (once per tick, outside
/// the motion path).
pub struct AcyclicServer {
    _node: Node<ipc::Service>,
    calls: Mailbox,
    /// Per slot, the polls it stood half-way ([`Mailbox::serve`]).
    ages: core::cell::Cell<[u32; MAILBOX_SLOTS]>,
    rows: RowsServerPort,
}

impl AcyclicServer {
    /// Creates `instance`'s mailbox (replacing one a dead server left) and opens (or creates)
    /// its row service's server port. The mailbox is removed when the server is dropped.
    pub fn open(instance: &str) -> Result<Self, CallError> {
        let calls = Mailbox::create(instance)?;
        let (node, rows) = open_end(instance, |rows| rows.server_builder().create())?;
        Ok(Self {
            _node: node,
            calls,
            ages: core::cell::Cell::new([0; MAILBOX_SLOTS]),
            rows,
        })
    }

    /// Connects to the clients there are now (maps their segments), so that the first call a
    /// client sends is not answered in a tick that also maps its segment (with locked memory
    /// that populates the whole mapping: milliseconds). Called before the first tick.
    pub fn connect(&self) -> Result<(), CallError> {
        self.rows.has_requests().map_err(transport)?;
        Ok(())
    }

    /// Answers every pending bulk call with `handler(kind, header, values)`. An unknown or
    /// non-bulk kind is refused with [`ErrorCode::ServiceNotSupported`] and a payload that is not
    /// `rows x columns` values with [`ErrorCode::InvalidSize`], before the handler sees them.
    /// Returns how many calls were answered.
    pub fn poll_rows(
        &self,
        mut handler: impl FnMut(CallKind, &BulkHeader, &[f64]) -> HandlerResult,
    ) -> Result<usize, CallError> {
        let mut answered = 0;
        while let Some(active) = self.rows.receive().map_err(transport)? {
            let header = *active.user_header();
            let values: &[f64] = active.payload();
            let expected = (header.rows as usize).checked_mul(header.columns as usize);
            let result = match CallKind::decode(header.kind) {
                Some(kind) if !kind.is_bulk() => Err(ErrorCode::ServiceNotSupported),
                None => Err(ErrorCode::ServiceNotSupported),
                Some(_) if expected != Some(values.len()) => Err(ErrorCode::InvalidSize),
                Some(kind) => handler(kind, &header, values),
            };
            active
                .send_copy(response(0, header.kind, result))
                .map_err(transport)?;
            answered += 1;
        }
        Ok(answered)
    }

    /// Answers every pending request with `handler(kind, request)`. Unknown and bulk kinds are
    /// refused with [`ErrorCode::ServiceNotSupported`] without calling the handler. Returns how
    /// many requests were answered.
    pub fn poll(
        &self,
        mut handler: impl FnMut(CallKind, &AcyclicRequest) -> HandlerResult,
    ) -> Result<usize, CallError> {
        let mut ages = self.ages.get();
        let answered = self.calls.serve(&mut ages, |request| {
            let result = match CallKind::decode(request.kind) {
                // A bulk kind's numbers never come in a frame.
                Some(kind) if kind.is_bulk() => Err(ErrorCode::ServiceNotSupported),
                // A body longer than a frame holds is no body.
                Some(_) if request.body_len as usize > ACYCLIC_BODY_SIZE => {
                    Err(ErrorCode::InvalidSize)
                }
                Some(kind) => handler(kind, request),
                None => Err(ErrorCode::ServiceNotSupported),
            };
            response(request.invoke_id, request.kind, result)
        });
        self.ages.set(ages);
        Ok(answered)
    }
}

/// The response frame of a handler's result.
fn response(invoke_id: u32, kind: u32, result: HandlerResult) -> AcyclicResponse {
    let (error_code, body, body_len) = match result {
        Ok((body, len)) => (0, body, len),
        Err(code) => (code.raw(), [0u8; ACYCLIC_BODY_SIZE], 0),
    };
    AcyclicResponse {
        invoke_id,
        kind,
        error_code,
        body_len,
        body,
    }
}
