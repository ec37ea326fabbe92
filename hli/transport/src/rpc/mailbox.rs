//! The calls' mailbox: a fixed array of call slots in a shared-memory object of its own
//! (`cncplc_<instance>.calls`), created by the CNC's server and opened by each client. A call
//! claims a free slot, writes its request and marks it; the CNC answers every marked slot in
//! its tick; the caller takes the reply and frees the slot. Nothing is allocated on either
//! side after opening (iceoryx2's request-response gives every request a reference-counted
//! state of its own: one allocation per call in the PLC cycle).
//!
//! ```text
//!  Free ─client claims─► Writing ─request written─► Request ─server takes─► Answering
//!   ▲                                                                          │
//!   └──────────── client takes the reply (or the server, if abandoned) ◄── Reply
//! ```
//!
//! Every slot also holds the ticket of its claim (a counter of the mailbox): a caller only
//! ever reads or frees the slot while the ticket is its own. A caller that gives up its call
//! (a block restarted while Busy) marks the slot abandoned; the call still runs, as a frame
//! already sent would, and whichever side sees the reply first frees the slot. A slot a dead
//! client left (claimed and never sent, or answered and never taken) is freed by the server
//! after [`STALE_POLLS`] polls, once its process is gone (every slot names its claimant's
//! pid). The state and the ticket are two words: a holder's ticket check and the next
//! claimant's ticket store could meet only after 2^32 calls.

use hli::calls::CallError;
use hli::desc::PlaceExt;
use hli::raw::{ImageMemory, Place};
use hli::wire::{AcyclicRequest, AcyclicResponse, BulkHeader, BULK_MAX_VALUES};
use iceoryx2_bb_posix::shared_memory::{
    AccessMode, CreationMode, Permission, SharedMemoryBuilder, SharedMemoryCreationError,
};
use iceoryx2_bb_system_types::file_name::{FileName, SemanticString};
use std::sync::atomic::Ordering::SeqCst;
use std::sync::Arc;

/// Slots of a mailbox: calls on their way at once, from every client together.
pub const MAILBOX_SLOTS: usize = 64;
/// Polls after which the server frees a slot a client left half-way (claimed and never
/// sent, or answered and never taken): a minute at a 1 ms tick.
pub const STALE_POLLS: u32 = 60_000;
/// "HLI-MBX1" as a little-endian u64.
const MAGIC: u64 = u64::from_le_bytes(*b"HLI-MBX1");

const FREE: u32 = 0;
const WRITING: u32 = 1;
const REQUEST: u32 = 2;
const ANSWERING: u32 = 3;
const REPLY: u32 = 4;

/// Words of a frame (requests and responses are 256 bytes).
const FRAME_WORDS: usize = 64;
const _: () = assert!(core::mem::size_of::<AcyclicRequest>() == FRAME_WORDS * 4);
const _: () = assert!(core::mem::size_of::<AcyclicResponse>() == FRAME_WORDS * 4);

/// Header: magic (u64), slot count, the server's pid, its start stamp (u64), the ticket
/// counter; then the slots.
const HEADER_BYTES: usize = 32;
const OFF_SLOTS: usize = 8;
const OFF_PID: usize = 12;
const OFF_STAMP: usize = 16;
const OFF_TICKETS: usize = 24;
/// A slot: state, abandoned flag, ticket, the claimant's pid, then the request and the
/// response.
const SLOT_BYTES: usize = 16 + 2 * FRAME_WORDS * 4;
/// Bulk slots (FIFO row blocks, numbers written in place): calls of this kind on their way
/// at once.
pub const BULK_SLOTS: usize = 8;
/// A bulk slot: state, abandoned flag, ticket, the claimant's pid, the [`BulkHeader`], the
/// count of numbers (and a pad word), the numbers, then the response.
const BULK_SLOT_BYTES: usize = BULK_VALUES_AT + BULK_MAX_VALUES * 8 + FRAME_WORDS * 4;
const BULK_VALUES_AT: usize = 40;
const OFF_BULK: usize = HEADER_BYTES + MAILBOX_SLOTS * SLOT_BYTES;
const SIZE: usize = OFF_BULK + BULK_SLOTS * BULK_SLOT_BYTES;
/// Every slot, calls first (`0..MAILBOX_SLOTS`), then bulk.
const ALL_SLOTS: usize = MAILBOX_SLOTS + BULK_SLOTS;

/// The object name of `instance`'s mailbox: 1..=200 characters of `[A-Za-z0-9_.-]`.
pub fn mailbox_name(instance: &str) -> Option<String> {
    crate::segment::instance_ok(instance, 200).then(|| format!("cncplc_{instance}.calls"))
}

fn os(name: &str, what: impl core::fmt::Debug) -> CallError {
    CallError::Transport(format!("mailbox {name}: {what:?}"))
}

fn file_name(name: &str) -> Result<FileName, CallError> {
    FileName::new(name.as_bytes()).map_err(|e| os(name, e))
}

/// One slot of the mailbox: where it starts, and where its response frame is.
#[derive(Clone, Copy)]
struct Slot<'m> {
    at: usize,
    response_at: usize,
    memory: &'m ImageMemory,
}

impl<'m> Slot<'m> {
    fn word(&self, offset: usize) -> Place<'m, u32> {
        self.memory.place::<u32>(self.at + offset)
    }
    fn state(&self) -> &'m std::sync::atomic::AtomicU32 {
        self.word(0).atomic()
    }
    fn abandoned(&self) -> &'m std::sync::atomic::AtomicU32 {
        self.word(4).atomic()
    }
    fn ticket(&self) -> &'m std::sync::atomic::AtomicU32 {
        self.word(8).atomic()
    }
    /// The pid of the process that claimed the slot.
    fn pid(&self) -> Place<'m, u32> {
        self.word(12)
    }
    /// The count of numbers of a bulk slot.
    fn count(&self) -> Place<'m, u32> {
        self.word(32)
    }
    fn request_frame(&self) -> Place<'m, [u32; FRAME_WORDS]> {
        self.memory.place::<[u32; FRAME_WORDS]>(self.at + 16)
    }
    fn response_frame(&self) -> Place<'m, [u32; FRAME_WORDS]> {
        self.memory
            .place::<[u32; FRAME_WORDS]>(self.at + self.response_at)
    }
    fn request(&self) -> AcyclicRequest {
        bytemuck::cast(self.request_frame().read())
    }
    fn response(&self) -> AcyclicResponse {
        bytemuck::cast(self.response_frame().read())
    }
    fn header(&self) -> Place<'m, [u32; 4]> {
        self.memory.place::<[u32; 4]>(self.at + 16)
    }
    /// Number `k` of a bulk slot.
    fn value(&self, k: usize) -> Place<'m, f64> {
        self.memory.place::<f64>(self.at + BULK_VALUES_AT + 8 * k)
    }
    /// Whether the slot is `state` under `ticket`.
    fn is(&self, state: u32, ticket: u32) -> bool {
        self.state().load(SeqCst) == state && self.ticket().load(SeqCst) == ticket
    }
}

/// A mailbox mapping, either end's.
#[derive(Debug)]
pub struct Mailbox {
    memory: ImageMemory,
    name: String,
    /// This process's pid, written into the slots it claims (read once: no system call per
    /// call).
    pid: u32,
}

impl Mailbox {
    /// Slot `i`: a call slot below [`MAILBOX_SLOTS`], a bulk slot from there on.
    fn slot(&self, i: usize) -> Slot<'_> {
        let i = i.min(ALL_SLOTS - 1);
        match i.checked_sub(MAILBOX_SLOTS) {
            None => Slot {
                at: HEADER_BYTES + i * SLOT_BYTES,
                response_at: 16 + FRAME_WORDS * 4,
                memory: &self.memory,
            },
            Some(b) => Slot {
                at: OFF_BULK + b * BULK_SLOT_BYTES,
                response_at: BULK_VALUES_AT + BULK_MAX_VALUES * 8,
                memory: &self.memory,
            },
        }
    }

    /// Claims a free slot among `slots` for writing: the slot and its ticket.
    fn claim(&self, slots: core::ops::Range<usize>) -> Result<(usize, u32), CallError> {
        for i in slots {
            let slot = self.slot(i);
            if slot
                .state()
                .compare_exchange(FREE, WRITING, SeqCst, SeqCst)
                .is_err()
            {
                continue;
            }
            let tickets = self.memory.place::<u32>(OFF_TICKETS).atomic();
            let ticket = tickets.fetch_add(1, SeqCst);
            slot.ticket().store(ticket, SeqCst);
            slot.abandoned().store(0, SeqCst);
            slot.pid().store(self.pid);
            return Ok((i, ticket));
        }
        Err(CallError::SlotsTaken)
    }

    /// Creates `instance`'s mailbox for the server; one a dead server left is replaced, one a
    /// live server holds is refused.
    pub fn create(instance: &str) -> Result<Mailbox, CallError> {
        let name = mailbox_name(instance).ok_or_else(|| os(instance, "invalid instance name"))?;
        let fname = file_name(&name)?;
        let create = || {
            SharedMemoryBuilder::new(&fname)
                .is_memory_locked(false)
                .creation_mode(CreationMode::CreateExclusive)
                .size(SIZE)
                .permission(Permission::OWNER_READ_WRITE)
                .zero_memory(true)
                .create()
        };
        let shm = match create() {
            Ok(shm) => shm,
            Err(SharedMemoryCreationError::AlreadyExist) => {
                // Whatever its shape (another build's, one half made): its server's pid and
                // start stamp decide, read before anything else of it.
                let old = SharedMemoryBuilder::new(&fname)
                    .is_memory_locked(false)
                    .open_existing(AccessMode::ReadWrite);
                if let Ok(old) = old.map(crate::raw::shared) {
                    if old.len() >= HEADER_BYTES {
                        let pid = old.place::<u32>(OFF_PID).load();
                        let stamp = old.place::<u64>(OFF_STAMP).load();
                        if crate::segment::process_start_stamp(pid) == Some(stamp) {
                            return Err(os(&name, format!("in use by the live process {pid}")));
                        }
                    }
                }
                iceoryx2_bb_posix::shared_memory::SharedMemory::remove(&fname)
                    .map_err(|e| os(&name, e))?;
                create().map_err(|e| os(&name, e))?
            }
            Err(e) => return Err(os(&name, e)),
        };
        let memory = crate::raw::shared(shm);
        let pid = std::process::id();
        memory.place::<u32>(OFF_SLOTS).store(MAILBOX_SLOTS as u32);
        memory.place::<u32>(OFF_PID).store(pid);
        let stamp = crate::segment::process_start_stamp(pid).unwrap_or(0);
        memory.place::<u64>(OFF_STAMP).store(stamp);
        memory.place::<u64>(0).store_release(MAGIC);
        Ok(Mailbox { memory, name, pid })
    }

    /// Opens `instance`'s mailbox for a client: it must be there, with this build's shape.
    pub fn open(instance: &str) -> Result<Mailbox, CallError> {
        let name = mailbox_name(instance).ok_or_else(|| os(instance, "invalid instance name"))?;
        let shm = SharedMemoryBuilder::new(&file_name(&name)?)
            .is_memory_locked(false)
            .open_existing(AccessMode::ReadWrite)
            .map_err(|e| os(&name, format!("no CNC serves calls here ({e:?})")))?;
        if shm.size() < SIZE {
            return Err(os(&name, format!("{} bytes, expected {SIZE}", shm.size())));
        }
        let memory = crate::raw::shared(shm);
        let magic = memory.place::<u64>(0).load_acquire();
        let slots = memory.place::<u32>(OFF_SLOTS).load();
        if magic != MAGIC || slots as usize != MAILBOX_SLOTS {
            return Err(os(
                &name,
                format!("not a mailbox of this build ({slots} slots)"),
            ));
        }
        let pid = std::process::id();
        Ok(Mailbox { memory, name, pid })
    }

    /// Claims a free slot and sends `request` in it: the slot and its ticket.
    pub fn send(&self, request: &AcyclicRequest) -> Result<(usize, u32), CallError> {
        let (i, ticket) = self.claim(0..MAILBOX_SLOTS)?;
        let slot = self.slot(i);
        slot.request_frame().write(&bytemuck::cast(*request));
        slot.state().store(REQUEST, SeqCst);
        Ok((i, ticket))
    }

    /// Claims a bulk slot for `count` numbers under `header`, to be written in place and sent
    /// whole ([`BulkLoan`]), its numbers 0 if `zeroed` (else what the slot held before: for a
    /// caller that writes them all); more than [`BULK_MAX_VALUES`] numbers are refused.
    pub fn loan(
        self: &Arc<Self>,
        header: BulkHeader,
        count: usize,
        zeroed: bool,
    ) -> Result<BulkLoan, CallError> {
        if count > BULK_MAX_VALUES {
            return Err(CallError::TooLarge(count));
        }
        let (slot, ticket) = self.claim(MAILBOX_SLOTS..ALL_SLOTS)?;
        let s = self.slot(slot);
        s.header().write(&bytemuck::cast(header));
        s.count().store(count as u32);
        for k in (0..count).filter(|_| zeroed) {
            s.value(k).store(0.0);
        }
        Ok(BulkLoan {
            mailbox: Arc::clone(self),
            slot,
            ticket,
            count,
            sent: false,
        })
    }

    /// The reply in slot `i` under `ticket`, taken (the slot freed); `None` before it came.
    pub fn take(&self, i: usize, ticket: u32) -> Option<AcyclicResponse> {
        let slot = self.slot(i);
        if !slot.is(REPLY, ticket) {
            return None;
        }
        let response = slot.response();
        slot.state()
            .compare_exchange(REPLY, FREE, SeqCst, SeqCst)
            .ok()
            .map(|_| response)
    }

    /// Gives up the call in slot `i` under `ticket`: it still runs; the slot is freed by
    /// whichever side sees the reply first.
    pub fn abandon(&self, i: usize, ticket: u32) {
        let slot = self.slot(i);
        if slot.ticket().load(SeqCst) != ticket || slot.state().load(SeqCst) == FREE {
            return;
        }
        slot.abandoned().store(1, SeqCst);
        if slot.is(REPLY, ticket) {
            let _ = slot.state().compare_exchange(REPLY, FREE, SeqCst, SeqCst);
        }
    }

    /// Answers every sent request with `answer`, oldest ticket first (the order the calls
    /// were sent in, whichever slots they took); `ages` (the server's own, one per slot)
    /// counts the polls a slot stood in any other state than free or sent, to free what a
    /// dead client (or a garbled state word) left. Returns how many it answered.
    pub fn serve(
        &self,
        ages: &mut [u32; MAILBOX_SLOTS],
        mut answer: impl FnMut(&AcyclicRequest) -> AcyclicResponse,
    ) -> usize {
        let answered = self.answer_each(0..MAILBOX_SLOTS, |slot| answer(&slot.request()));
        self.age(0, ages);
        answered
    }

    /// Answers every sent bulk call with `answer(header, numbers)`, oldest first, the numbers
    /// copied into `buffer` (room for [`BULK_MAX_VALUES`]: nothing allocated); a count above
    /// that room, or other than rows x columns, is answered with `refuse` without `answer`.
    pub fn serve_bulk(
        &self,
        ages: &mut [u32; BULK_SLOTS],
        buffer: &mut Vec<f64>,
        refuse: AcyclicResponse,
        mut answer: impl FnMut(&BulkHeader, &[f64]) -> AcyclicResponse,
    ) -> usize {
        let answered = self.answer_each(MAILBOX_SLOTS..ALL_SLOTS, |slot| {
            let header: BulkHeader = bytemuck::cast(slot.header().read());
            let count = slot.count().load() as usize;
            let shape = (header.rows as usize).checked_mul(header.columns as usize);
            if count > BULK_MAX_VALUES || count > buffer.capacity() || shape != Some(count) {
                let mut refused = refuse;
                refused.kind = header.kind;
                return refused;
            }
            buffer.clear();
            buffer.extend((0..count).map(|k| slot.value(k).load()));
            answer(&header, buffer)
        });
        self.age(MAILBOX_SLOTS, ages);
        answered
    }

    /// Answers the sent slots among `slots`, oldest ticket first.
    fn answer_each(
        &self,
        slots: core::ops::Range<usize>,
        mut answer: impl FnMut(&Slot<'_>) -> AcyclicResponse,
    ) -> usize {
        let mut answered = 0;
        // At most one answer per slot and poll: a peer that keeps sending cannot hold the
        // server here.
        for _ in slots.clone() {
            let Some(i) = self.oldest_request(slots.clone()) else {
                break;
            };
            let slot = self.slot(i);
            if slot
                .state()
                .compare_exchange(REQUEST, ANSWERING, SeqCst, SeqCst)
                .is_err()
            {
                continue;
            }
            let response = answer(&slot);
            slot.response_frame().write(&bytemuck::cast(response));
            slot.state().store(REPLY, SeqCst);
            if slot.abandoned().load(SeqCst) != 0 {
                let _ = slot.state().compare_exchange(REPLY, FREE, SeqCst, SeqCst);
            }
            answered += 1;
        }
        answered
    }

    /// Counts the polls each slot from `first` on stood neither free nor sent; after
    /// [`STALE_POLLS`] it frees the slot if the process that claimed it is gone (a live one,
    /// however slow, keeps it; asked again after as many polls).
    fn age(&self, first: usize, ages: &mut [u32]) {
        for (i, age) in ages.iter_mut().enumerate() {
            let slot = self.slot(first + i);
            match slot.state().load(SeqCst) {
                FREE | REQUEST => *age = 0,
                stuck if *age >= STALE_POLLS => {
                    *age = 0;
                    let pid = slot.pid().load();
                    if crate::segment::process_start_stamp(pid).is_none() {
                        let _ = slot.state().compare_exchange(stuck, FREE, SeqCst, SeqCst);
                    }
                }
                _ => *age += 1,
            }
        }
    }

    /// The sent slot among `slots` with the oldest ticket (tickets count up and wrap: the
    /// oldest is the one furthest behind the counter).
    fn oldest_request(&self, slots: core::ops::Range<usize>) -> Option<usize> {
        let now = self.memory.place::<u32>(OFF_TICKETS).load();
        slots
            .filter(|&i| self.slot(i).state().load(SeqCst) == REQUEST)
            .max_by_key(|&i| now.wrapping_sub(self.slot(i).ticket().load(SeqCst)))
    }
}

/// A bulk slot claimed for writing: its numbers are written in place and sent whole; dropped
/// unsent, the slot is freed and nothing reaches the CNC (a process that dies while writing
/// leaves it claimed, and the server frees it after [`STALE_POLLS`]: never a half block).
#[derive(Debug)]
pub struct BulkLoan {
    mailbox: Arc<Mailbox>,
    slot: usize,
    ticket: u32,
    count: usize,
    sent: bool,
}

impl BulkLoan {
    /// How many numbers the loan holds.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether it holds none.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Writes `values` from number `at` on (those beyond the loan are left out).
    pub fn write(&mut self, at: usize, values: &[f64]) {
        let slot = self.mailbox.slot(self.slot);
        let end = self.count.min(at.saturating_add(values.len()));
        for (k, v) in (at..end).zip(values) {
            slot.value(k).store(*v);
        }
    }

    /// Sends the block whole: the ticket of the call; `Err` if the slot is no longer this
    /// loan's (freed as a dead process's: nothing is sent).
    pub fn send(mut self) -> Result<Ticket, CallError> {
        let slot = self.mailbox.slot(self.slot);
        let ours = slot.ticket().load(SeqCst) == self.ticket
            && slot
                .state()
                .compare_exchange(WRITING, REQUEST, SeqCst, SeqCst)
                .is_ok();
        if !ours {
            return Err(os(&self.mailbox.name, "the loan's slot was taken away"));
        }
        self.sent = true;
        Ok(Ticket {
            mailbox: Arc::clone(&self.mailbox),
            slot: self.slot,
            ticket: self.ticket,
            taken: core::cell::Cell::new(false),
        })
    }
}

impl Drop for BulkLoan {
    fn drop(&mut self) {
        let slot = self.mailbox.slot(self.slot);
        if !self.sent && slot.ticket().load(SeqCst) == self.ticket {
            let _ = slot.state().compare_exchange(WRITING, FREE, SeqCst, SeqCst);
        }
    }
}

/// A call on its way in a mailbox: its slot and ticket. Dropped before its reply came, it
/// gives the call up ([`Mailbox::abandon`]).
#[derive(Debug)]
pub struct Ticket {
    pub(super) mailbox: Arc<Mailbox>,
    pub(super) slot: usize,
    pub(super) ticket: u32,
    pub(super) taken: core::cell::Cell<bool>,
}

impl Ticket {
    /// The reply, taken, once it came.
    pub fn take(&self) -> Option<AcyclicResponse> {
        if self.taken.get() {
            return None;
        }
        let reply = self.mailbox.take(self.slot, self.ticket);
        self.taken.set(reply.is_some());
        reply
    }
}

impl Drop for Ticket {
    fn drop(&mut self) {
        if !self.taken.get() {
            self.mailbox.abandon(self.slot, self.ticket);
        }
    }
}

#[cfg(test)]
mod tests;
