//! The one `unsafe` step of the transport: a mapped shared-memory object taken over as an
//! image (`hli::ImageMemory::mapped`). The crate root denies `unsafe_code` and allows it for
//! this module alone.

use hli::ImageMemory;
use iceoryx2_bb_posix::shared_memory::SharedMemory;

/// A shared-memory object that keeps an image mapped.
pub struct Mapping(pub SharedMemory);

// SAFETY: the object is a handle to a mapping that is only unmapped when it is dropped; it has
// no thread affinity, and the memory behind it is only ever accessed through atomics (`Place`).
unsafe impl Send for Mapping {}
// SAFETY: as above; a shared `&Mapping` only reads the handle's fields.
unsafe impl Sync for Mapping {}

/// Takes over a mapped shared-memory object as an image; the mapping lives as long as the
/// result (its owner is a [`Mapping`]). The object must be mapped read-write (every access
/// may store).
pub fn shared(shm: SharedMemory) -> ImageMemory {
    let (base, len) = (shm.base_address(), shm.size());
    // SAFETY: `shm` maps `base..base + len` read-write until it is dropped, and the image owns
    // it from here on; every access to the image is an atomic of a leaf's own size (the
    // promise `hli::raw` keeps for both processes); `mapped` checks the alignment.
    unsafe { ImageMemory::mapped(base, len, Box::new(Mapping(shm))) }
}
