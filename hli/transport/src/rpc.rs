//! The transport of the acyclic ADS-like calls from the PLC to the CNC: a mailbox of slots in
//! shared memory ([`mailbox`]) carrying the frames of [`hli::wire`], one call per PLC block
//! Execute edge (table writes, coupling commands, reads of characteristic values...), and bulk
//! calls whose numbers are written straight into the mailbox (FIFO row blocks). Nothing is
//! allocated on either side after opening. The vocabulary (call kinds, typed bodies, refusal
//! codes) is [`hli::calls`] and its families; this module is the transport alone. The
//! CNC-side handlers live with the CNC's view ([`hli::views::handle_read_axis_state`]) and in
//! the engines.

use core::time::Duration;
use hli::calls::{AcyclicCall, CallError, CallKind, ErrorCode, HandlerResult};
use hli::wire::{
    encode_body, AcyclicRequest, AcyclicResponse, BulkHeader, ACYCLIC_BODY_SIZE, BULK_MAX_VALUES,
};
use mailbox::{BulkLoan, Mailbox, Ticket, BULK_SLOTS, MAILBOX_SLOTS};
use std::sync::Arc;
use std::time::Instant;

pub mod mailbox;

/// Prints the type's name alone.
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

/// The PLC's end: sends calls and waits for their replies; sends FIFO row blocks.
pub struct AcyclicClient {
    calls: Arc<Mailbox>,
    next_invoke_id: u32,
    sent: u64,
}

impl AcyclicClient {
    /// Connects to `instance`'s calls (the CNC's server must have made its mailbox).
    pub fn open(instance: &str) -> Result<Self, CallError> {
        Ok(Self {
            calls: Arc::new(Mailbox::open(instance)?),
            next_invoke_id: 1,
            sent: 0,
        })
    }

    /// Loans a bulk call of `values` values in the shared memory the CNC will read: the PLC
    /// writes its rows straight into it ([`RowsLoan::write`]) and sends it whole
    /// ([`RowsLoan::send`]). A loan that is dropped, or whose process dies before the send,
    /// never reaches the CNC: there is no half block.
    pub fn loan_rows(&mut self, header: BulkHeader, values: usize) -> Result<RowsLoan, CallError> {
        Ok(RowsLoan {
            loan: self.calls.loan(header, values, true)?,
        })
    }

    /// Sends a bulk call (a FIFO row block: `FiFoWrite`, `FiFoOverwrite`): `values` holds
    /// `header.rows x header.columns` values, row after row, and is written once, straight
    /// into the shared memory the CNC reads it from. Poll the returned [`PendingRows`].
    pub fn start_rows(
        &mut self,
        header: BulkHeader,
        values: &[f64],
    ) -> Result<PendingRows, CallError> {
        let mut loan = self.calls.loan(header, values.len(), false)?;
        loan.write(0, values);
        let ticket = loan.send()?;
        self.sent += 1;
        Ok(PendingRows { ticket })
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

/// A row block being written in place (see [`AcyclicClient::loan_rows`]).
pub struct RowsLoan {
    loan: BulkLoan,
}

impl RowsLoan {
    /// How many values the block holds (each 0 until written).
    pub fn len(&self) -> usize {
        self.loan.len()
    }

    /// Whether it holds none.
    pub fn is_empty(&self) -> bool {
        self.loan.is_empty()
    }

    /// Writes `values` from value `at` on, row after row (those beyond the block are left
    /// out).
    pub fn write(&mut self, at: usize, values: &[f64]) {
        self.loan.write(at, values);
    }

    /// Sends the block whole.
    pub fn send(self) -> Result<PendingRows, CallError> {
        Ok(PendingRows {
            ticket: self.loan.send()?,
        })
    }
}

/// A row block on its way: poll it until it yields the CNC's reply.
pub struct PendingRows {
    ticket: Ticket,
}

impl PendingRows {
    /// The CNC's reply, decoded as `R` (the reply body of the bulk call's kind), once it has
    /// answered; `None` while it has not.
    pub fn poll<R: bytemuck::Pod>(&self) -> Option<Result<R, CallError>> {
        let response = self.ticket.take()?;
        Some(decode_reply_body(&response))
    }
}

/// The CNC's end: answers pending calls and row blocks when polled (once per tick, outside
/// the motion path).
pub struct AcyclicServer {
    calls: Mailbox,
    /// Per slot, the polls it stood half-way ([`Mailbox::serve`]).
    ages: core::cell::Cell<[u32; MAILBOX_SLOTS]>,
    /// The same for the bulk slots.
    bulk_ages: core::cell::Cell<[u32; BULK_SLOTS]>,
    /// Where a row block's numbers are copied for the handler (room made at opening).
    rows: core::cell::RefCell<Vec<f64>>,
}

impl AcyclicServer {
    /// Creates `instance`'s mailbox (replacing one a dead server left). It is removed when
    /// the server is dropped.
    pub fn open(instance: &str) -> Result<Self, CallError> {
        Ok(Self {
            calls: Mailbox::create(instance)?,
            ages: core::cell::Cell::new([0; MAILBOX_SLOTS]),
            bulk_ages: core::cell::Cell::new([0; BULK_SLOTS]),
            rows: core::cell::RefCell::new(Vec::with_capacity(BULK_MAX_VALUES)),
        })
    }

    /// Kept for the callers of the former transport, which mapped its clients' segments
    /// before the first tick: the mailbox is mapped at opening, so there is nothing to do.
    pub fn connect(&self) -> Result<(), CallError> {
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
        let mut ages = self.bulk_ages.get();
        // A handler that polls again finds the room taken: refused, never a panic.
        let Ok(mut rows) = self.rows.try_borrow_mut() else {
            return Err(CallError::Transport(
                "poll_rows called from its own handler".into(),
            ));
        };
        let refuse = response(0, 0, Err(ErrorCode::InvalidSize));
        let answered = self
            .calls
            .serve_bulk(&mut ages, &mut rows, refuse, |header, values| {
                let result = match CallKind::decode(header.kind) {
                    Some(kind) if kind.is_bulk() => handler(kind, header, values),
                    _ => Err(ErrorCode::ServiceNotSupported),
                };
                response(0, header.kind, result)
            });
        self.bulk_ages.set(ages);
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
