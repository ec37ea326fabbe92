//! The only module of `hli` that contains `unsafe` code.
//!
//! Shared memory is written by another process at any moment, so Rust may never hold a `&T` or
//! `&mut T` into it. Everything outside this module reaches the image through [`Place`], a typed
//! offset into an [`ImageMemory`], and every access is an atomic load or store of exactly the
//! leaf's own size. That keeps three promises:
//!
//! * a concurrent writer in the other process can make a copied value stale, never undefined
//!   behaviour: leaves are plain integers or floats for which every bit pattern is valid;
//! * a given byte range is always accessed with atomics of one size (the size of the leaf that
//!   lives there), so mixed-size atomic races cannot happen between our own processes;
//! * bounds and alignment are checked when a [`Place`] is derived, so a wrong offset is a panic
//!   at start-up (a programming error), never an out-of-bounds access.
//!
//! Besides the image, the module holds `zero_copy_send!`, the `unsafe impl` that lets iceoryx2
//! copy a plain-data payload between the processes. The crate root denies `unsafe_code` and
//! allows it for this module alone; the macro's expansion carries its own allow, so the
//! `unsafe impl` it writes (for `layout::dyn_cs`'s coordinate system, which the handshake bench's
//! iceoryx2 pub-sub baseline sends) is still text of this module.
//! System calls that are not about the interface (sleeping, memory advice, real-time settings)
//! are in the `cnc-os` crate.

use core::marker::PhantomData;
use core::ptr::NonNull;
use core::sync::atomic::{
    AtomicI16, AtomicI32, AtomicI64, AtomicI8, AtomicU16, AtomicU32, AtomicU64, AtomicU8, Ordering,
};

/// Memory that holds one HLI image: a heap buffer (for in-process mode and tests) or a mapping
/// the transport made (a shared-memory segment, `hli_transport`), whose owner keeps it alive
/// for as long as `self` lives.
pub struct ImageMemory {
    base: NonNull<u8>,
    len: usize,
    // Keeps the memory behind `base` alive for as long as `self`.
    backing: Backing,
}

enum Backing {
    Heap(#[allow(dead_code)] Box<[AtomicU64]>),
    Mapped(Box<dyn core::any::Any + Send + Sync>),
}

impl core::fmt::Debug for ImageMemory {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let kind = match self.backing {
            Backing::Heap(_) => "heap",
            Backing::Mapped(_) => "shared",
        };
        write!(f, "ImageMemory({kind}, {} bytes)", self.len)
    }
}

// SAFETY: the memory is only ever accessed through atomics (see `Place`), so sharing the pointer
// between threads cannot create a data race; the backing (a heap buffer of atomics or a mapping
// that is only unmapped on drop) has no thread affinity.
unsafe impl Send for ImageMemory {}
// SAFETY: as above; `&ImageMemory` only hands out `Place`s whose accesses are atomic.
unsafe impl Sync for ImageMemory {}

/// Alignment every image base must have: the largest leaf is 8 bytes wide.
pub const IMAGE_ALIGN: usize = 8;

impl ImageMemory {
    /// A zeroed heap-backed image of `len` bytes (rounded up to whole 8-byte words).
    pub fn heap(len: usize) -> Self {
        let words = len.div_ceil(8).max(1);
        let buffer: Box<[AtomicU64]> = (0..words).map(|_| AtomicU64::new(0)).collect();
        let base = NonNull::from(&buffer[0]).cast::<u8>();
        Self {
            base,
            len: words * 8,
            backing: Backing::Heap(buffer),
        }
    }

    /// Takes over a mapping of `len` bytes at `base` and the `owner` that keeps it mapped
    /// (a shared-memory object); the owner is dropped, and the mapping with it, when the
    /// result is.
    ///
    /// # Safety
    /// `base..base + len` must be mapped read-write for as long as `owner` lives, accessed by
    /// nothing but atomics of each leaf's size (the other process included), and `base`
    /// must be [`IMAGE_ALIGN`]-aligned (checked).
    pub unsafe fn mapped(
        base: NonNull<u8>,
        len: usize,
        owner: Box<dyn core::any::Any + Send + Sync>,
    ) -> Self {
        assert_eq!(
            base.as_ptr() as usize % IMAGE_ALIGN,
            0,
            "image base must be 8-byte aligned"
        );
        Self {
            base,
            len,
            backing: Backing::Mapped(owner),
        }
    }

    /// The owner of a mapped image, if it is one and of type `T`.
    pub fn owner<T: core::any::Any>(&self) -> Option<&T> {
        match &self.backing {
            Backing::Mapped(owner) => owner.downcast_ref(),
            Backing::Heap(_) => None,
        }
    }

    /// The region's first byte, for code that reaches the leaves with one aligned load or
    /// store of each leaf's size (the ST runtime's native code): the instructions the
    /// relaxed atomics of [`Place`] are on x86-64 and AArch64.
    pub fn base_ptr(&self) -> *mut u8 {
        self.base.as_ptr()
    }

    /// Length of the region in bytes.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the region has no bytes at all.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// A typed place at `offset`; panics when `T` does not fit there or is misaligned.
    pub fn place<T>(&self, offset: usize) -> Place<'_, T> {
        let fits = offset
            .checked_add(core::mem::size_of::<T>())
            .is_some_and(|end| end <= self.len);
        assert!(
            fits,
            "place at {offset} (+{}) outside image of {} bytes",
            core::mem::size_of::<T>(),
            self.len
        );
        assert_eq!(
            offset % core::mem::align_of::<T>(),
            0,
            "misaligned place at {offset}"
        );
        Place {
            base: self.base,
            offset,
            _marker: PhantomData,
        }
    }

    /// Copies the whole region out with byte-wide atomic loads (diagnostics and golden tests).
    pub fn snapshot(&self) -> Vec<u8> {
        (0..self.len)
            .map(|offset| self.place::<u8>(offset).load())
            .collect()
    }
}

/// A `T` that lives at a fixed offset inside an [`ImageMemory`].
///
/// A `Place` is a capability, not a reference: it never yields `&T`. Leaves are loaded and
/// stored atomically; structs are copied leaf by leaf by the `desc` layer above.
pub struct Place<'m, T> {
    base: NonNull<u8>,
    offset: usize,
    _marker: PhantomData<PlaceMarker<'m, T>>,
}

/// Ties a place to its image's lifetime; `fn() -> T` keeps `Place` Send/Sync-neutral in `T`.
type PlaceMarker<'m, T> = (&'m ImageMemory, fn() -> T);

impl<T> Clone for Place<'_, T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for Place<'_, T> {}

impl<T> core::fmt::Debug for Place<'_, T> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "Place<{}>@{}", core::any::type_name::<T>(), self.offset)
    }
}

impl<'m, T> Place<'m, T> {
    /// Offset of this place from the start of the image, in bytes.
    pub fn offset(&self) -> usize {
        self.offset
    }

    /// The sub-place of type `F` at `field_offset` inside `T` (from `core::mem::offset_of!`).
    /// Panics if `F` does not fit inside `T` there or is misaligned.
    pub fn field<F>(self, field_offset: usize) -> Place<'m, F> {
        assert!(
            field_offset + core::mem::size_of::<F>() <= core::mem::size_of::<T>(),
            "field at {field_offset} does not fit in {}",
            core::any::type_name::<T>()
        );
        let offset = self.offset + field_offset;
        assert_eq!(offset % core::mem::align_of::<F>(), 0, "misaligned field");
        Place {
            base: self.base,
            offset,
            _marker: PhantomData,
        }
    }

    /// Reinterprets the place as a different type of the same or smaller size. Used by the
    /// symbol table to reach a leaf by its offset; every Pod bit pattern is valid.
    pub fn cast<U>(self) -> Place<'m, U> {
        self.field::<U>(0)
    }

    fn address(&self) -> *mut u8 {
        // SAFETY: `offset + size_of::<T>() <= len` was checked when this place was derived, so
        // the resulting pointer stays inside the mapped region.
        unsafe { self.base.as_ptr().add(self.offset) }
    }
}

impl<'m, E, const N: usize> Place<'m, [E; N]> {
    /// The element place at `index`; `None` when out of bounds.
    pub fn get(self, index: usize) -> Option<Place<'m, E>> {
        (index < N).then(|| self.field::<E>(index * core::mem::size_of::<E>()))
    }

    /// The element place at `index`; panics when out of bounds (indices from constants).
    pub fn at(self, index: usize) -> Place<'m, E> {
        self.get(index).expect("index within the array")
    }
}

/// A scalar that lives in shared memory and is accessed with an atomic of its own size.
pub trait AtomicLeaf: Copy + sealed::Sealed {
    /// Atomic load of the value at `place`.
    fn load_at(place: Place<'_, Self>, order: Ordering) -> Self;
    /// Atomic store of `value` at `place`.
    fn store_at(place: Place<'_, Self>, value: Self, order: Ordering);
}

mod sealed {
    pub trait Sealed {}
}

macro_rules! leaf_via_atomic {
    ($($t:ty => $atomic:ty),* $(,)?) => {$(
        impl sealed::Sealed for $t {}
        impl AtomicLeaf for $t {
            #[inline]
            fn load_at(place: Place<'_, Self>, order: Ordering) -> Self {
                // SAFETY: the place is in bounds and aligned for `$t` (checked on derivation),
                // `$atomic` has the same size and alignment as `$t`, and the memory is only ever
                // accessed atomically (module invariant), so creating the atomic view is sound.
                let atomic = unsafe { <$atomic>::from_ptr(place.address().cast()) };
                atomic.load(order)
            }
            #[inline]
            fn store_at(place: Place<'_, Self>, value: Self, order: Ordering) {
                // SAFETY: as in `load_at`.
                let atomic = unsafe { <$atomic>::from_ptr(place.address().cast()) };
                atomic.store(value, order)
            }
        }
    )*};
}

leaf_via_atomic!(
    u8 => AtomicU8, i8 => AtomicI8, u16 => AtomicU16, i16 => AtomicI16,
    u32 => AtomicU32, i32 => AtomicI32, u64 => AtomicU64, i64 => AtomicI64,
);

macro_rules! float_leaf {
    ($($t:ty => $bits:ty),* $(,)?) => {$(
        impl sealed::Sealed for $t {}
        impl AtomicLeaf for $t {
            #[inline]
            fn load_at(place: Place<'_, Self>, order: Ordering) -> Self {
                <$t>::from_bits(<$bits as AtomicLeaf>::load_at(place.cast(), order))
            }
            #[inline]
            fn store_at(place: Place<'_, Self>, value: Self, order: Ordering) {
                <$bits as AtomicLeaf>::store_at(place.cast(), value.to_bits(), order)
            }
        }
    )*};
}

float_leaf!(f32 => u32, f64 => u64);

impl<T: AtomicLeaf> Place<'_, T> {
    /// Relaxed atomic load (payload words; ordering comes from the semaphore).
    pub fn load(self) -> T {
        T::load_at(self, Ordering::Relaxed)
    }
    /// Relaxed atomic store.
    pub fn store(self, value: T) {
        T::store_at(self, value, Ordering::Relaxed)
    }
    /// Acquire load: everything the other side wrote before its release store is visible.
    pub fn load_acquire(self) -> T {
        T::load_at(self, Ordering::Acquire)
    }
    /// Release store: everything written before it is visible to an acquire load of it.
    pub fn store_release(self, value: T) {
        T::store_at(self, value, Ordering::Release)
    }
}

impl<'m> Place<'m, u32> {
    /// The word as an atomic for as long as the image lives: a futex word that both
    /// processes wait on and wake.
    #[inline]
    pub fn atomic(self) -> &'m AtomicU32 {
        // SAFETY: as in `AtomicLeaf::load_at` for u32; the mapping outlives `'m`.
        unsafe { AtomicU32::from_ptr(self.address().cast()) }
    }
}

impl Place<'_, u64> {
    /// Atomic increment (heartbeats); returns the new value.
    #[inline]
    pub fn increment(self) -> u64 {
        // SAFETY: as in `AtomicLeaf::load_at` for u64.
        let atomic = unsafe { AtomicU64::from_ptr(self.address().cast()) };
        atomic.fetch_add(1, Ordering::Release).wrapping_add(1)
    }
}

/// `ZeroCopySend` for plain-data types iceoryx2 moves between processes by copying their bytes
/// into shared memory. Invoked where the type is defined (`layout::dyn_cs`); the type must
/// be bytemuck `Pod`, which the expansion checks.
macro_rules! zero_copy_send {
    ($($t:ty),*) => {$(
        const _: fn() = || {
            fn plain_data<T: bytemuck::Pod>() {}
            plain_data::<$t>();
        };
        // SAFETY: `$t` is `#[repr(C)]` plain old data (bytemuck `Pod`, checked above): no
        // pointers, no references, no process-local handles, every bit pattern valid. Both
        // processes are built from this crate, so the default type name identifies the same
        // layout.
        #[allow(unsafe_code)]
        unsafe impl iceoryx2_bb_elementary_traits::zero_copy_send::ZeroCopySend for $t {}
    )*};
}
pub(crate) use zero_copy_send;
