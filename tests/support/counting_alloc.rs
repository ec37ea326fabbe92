//! A global allocator that counts the allocations of the calling thread, for the no-allocation
//! tests of every crate (included with `#[path]`). The only `unsafe` outside `hli::raw` and
//! `cnc-os`: a global allocator cannot be written without `unsafe impl`. Test targets deny
//! `unsafe_code` (workspace lint); this module allows it for itself alone.

#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    /// Allocations made by this thread: the test harness's own threads may allocate while a
    /// test runs, which says nothing about the code under test.
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
    /// Frees made by this thread (a free in a cyclic path may take a lock as well).
    static DEALLOCATIONS: Cell<usize> = const { Cell::new(0) };
    /// Bytes this thread allocated minus the bytes it freed.
    static LIVE_BYTES: Cell<isize> = const { Cell::new(0) };
}

/// Bytes the current thread has allocated and not freed (frees of memory another thread
/// allocated count against it).
#[allow(dead_code)] // only the soak test asks
pub fn live_bytes() -> isize {
    LIVE_BYTES.with(Cell::get)
}

/// Frees the current thread has made so far.
#[allow(dead_code)] // not every test that includes this file counts frees
pub fn deallocations() -> usize {
    DEALLOCATIONS.with(Cell::get)
}

/// Allocations the current thread has made so far.
pub fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

// SAFETY: forwards to the system allocator unchanged; only counts calls.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|n| n.set(n.get() + 1));
        let _ = LIVE_BYTES.try_with(|n| n.set(n.get() + layout.size() as isize));
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        let _ = DEALLOCATIONS.try_with(|n| n.set(n.get() + 1));
        let _ = LIVE_BYTES.try_with(|n| n.set(n.get() - layout.size() as isize));
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;
