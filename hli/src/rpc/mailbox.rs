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
//! after [`STALE_POLLS`] polls.

use super::super::calls::CallError;
use super::super::desc::PlaceExt;
use super::super::raw::{ImageMemory, Place};
use super::super::wire::{AcyclicRequest, AcyclicResponse};
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
/// A slot: state, abandoned flag, ticket, reserved, then the request and the response.
const SLOT_BYTES: usize = 16 + 2 * FRAME_WORDS * 4;
const SIZE: usize = HEADER_BYTES + MAILBOX_SLOTS * SLOT_BYTES;

/// The object name of `instance`'s mailbox: 1..=200 characters of `[A-Za-z0-9_.-]`.
pub fn mailbox_name(instance: &str) -> Option<String> {
    let ok = !instance.is_empty()
        && instance.len() <= 200
        && instance
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b"_.-".contains(&b));
    ok.then(|| format!("cncplc_{instance}.calls"))
}

fn os(name: &str, what: impl core::fmt::Debug) -> CallError {
    CallError::Transport(format!("mailbox {name}: {what:?}"))
}

fn file_name(name: &str) -> Result<FileName, CallError> {
    FileName::new(name.as_bytes()).map_err(|e| os(name, e))
}

/// One slot of the mailbox.
#[derive(Clone, Copy)]
struct Slot<'m> {
    at: usize,
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
    fn frame(&self, second: bool) -> Place<'m, [u32; FRAME_WORDS]> {
        let offset = 16 + usize::from(second) * FRAME_WORDS * 4;
        self.memory.place::<[u32; FRAME_WORDS]>(self.at + offset)
    }
    fn request(&self) -> AcyclicRequest {
        bytemuck::cast(self.frame(false).read())
    }
    fn response(&self) -> AcyclicResponse {
        bytemuck::cast(self.frame(true).read())
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
}

impl Mailbox {
    fn slot(&self, i: usize) -> Slot<'_> {
        Slot {
            at: HEADER_BYTES + i * SLOT_BYTES,
            memory: &self.memory,
        }
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
                if let Ok(old) = Mailbox::open(instance) {
                    let pid = old.memory.place::<u32>(OFF_PID).load();
                    let stamp = old.memory.place::<u64>(OFF_STAMP).load();
                    if crate::segment::process_start_stamp(pid) == Some(stamp) {
                        return Err(os(&name, format!("in use by the live process {pid}")));
                    }
                }
                iceoryx2_bb_posix::shared_memory::SharedMemory::remove(&fname)
                    .map_err(|e| os(&name, e))?;
                create().map_err(|e| os(&name, e))?
            }
            Err(e) => return Err(os(&name, e)),
        };
        let memory = ImageMemory::shared(shm);
        let pid = std::process::id();
        memory.place::<u32>(OFF_SLOTS).store(MAILBOX_SLOTS as u32);
        memory.place::<u32>(OFF_PID).store(pid);
        let stamp = crate::segment::process_start_stamp(pid).unwrap_or(0);
        memory.place::<u64>(OFF_STAMP).store(stamp);
        memory.place::<u64>(0).store_release(MAGIC);
        Ok(Mailbox { memory, name })
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
        let memory = ImageMemory::shared(shm);
        let magic = memory.place::<u64>(0).load_acquire();
        let slots = memory.place::<u32>(OFF_SLOTS).load();
        if magic != MAGIC || slots as usize != MAILBOX_SLOTS {
            return Err(os(
                &name,
                format!("not a mailbox of this build ({slots} slots)"),
            ));
        }
        Ok(Mailbox { memory, name })
    }

    /// Claims a free slot and sends `request` in it: the slot and its ticket.
    pub fn send(&self, request: &AcyclicRequest) -> Result<(usize, u32), CallError> {
        for i in 0..MAILBOX_SLOTS {
            let slot = self.slot(i);
            if slot
                .state()
                .compare_exchange(FREE, WRITING, SeqCst, SeqCst)
                .is_err()
            {
                continue;
            }
            let ticket = self
                .memory
                .place::<u32>(OFF_TICKETS)
                .atomic()
                .fetch_add(1, SeqCst);
            slot.ticket().store(ticket, SeqCst);
            slot.abandoned().store(0, SeqCst);
            slot.frame(false).write(&bytemuck::cast(*request));
            slot.state().store(REQUEST, SeqCst);
            return Ok((i, ticket));
        }
        Err(os(&self.name, "all slots are taken"))
    }

    /// The reply in slot `i` under `ticket`, taken (the slot freed); `None` before it came.
    pub fn take(&self, i: usize, ticket: u32) -> Option<AcyclicResponse> {
        let slot = self.slot(i.min(MAILBOX_SLOTS - 1));
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
        let slot = self.slot(i.min(MAILBOX_SLOTS - 1));
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
        let mut answered = 0;
        while let Some(i) = self.oldest_request() {
            let slot = self.slot(i);
            if slot
                .state()
                .compare_exchange(REQUEST, ANSWERING, SeqCst, SeqCst)
                .is_err()
            {
                continue;
            }
            let response = answer(&slot.request());
            slot.frame(true).write(&bytemuck::cast(response));
            slot.state().store(REPLY, SeqCst);
            if slot.abandoned().load(SeqCst) != 0 {
                let _ = slot.state().compare_exchange(REPLY, FREE, SeqCst, SeqCst);
            }
            answered += 1;
        }
        for (i, age) in ages.iter_mut().enumerate() {
            let state = self.slot(i).state();
            match state.load(SeqCst) {
                FREE | REQUEST => *age = 0,
                _ if *age >= STALE_POLLS => {
                    state.store(FREE, SeqCst);
                    *age = 0;
                }
                _ => *age += 1,
            }
        }
        answered
    }

    /// The sent slot with the oldest ticket (tickets count up and wrap: the oldest is the one
    /// furthest behind the counter).
    fn oldest_request(&self) -> Option<usize> {
        let now = self.memory.place::<u32>(OFF_TICKETS).load();
        (0..MAILBOX_SLOTS)
            .filter(|&i| self.slot(i).state().load(SeqCst) == REQUEST)
            .max_by_key(|&i| now.wrapping_sub(self.slot(i).ticket().load(SeqCst)))
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
