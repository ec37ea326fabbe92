//! Memory advice: how the kernel backs a large heap buffer.

/// Asks the kernel to back the capacity of `buffer` with transparent huge pages (2 MiB) where
/// it spans whole ones: filling a large fresh buffer then takes one page fault per 2 MiB
/// instead of one per 4 KiB. Advice only: without THP support (or with THP disabled) nothing
/// changes. Call it right after reserving, before filling.
pub fn advise_huge_pages<T>(buffer: &mut Vec<T>) {
    #[cfg(target_os = "linux")]
    {
        const HUGE_PAGE: usize = 2 << 20;
        let start = buffer.as_mut_ptr() as usize;
        let bytes = buffer.capacity().saturating_mul(core::mem::size_of::<T>());
        let first = start.next_multiple_of(HUGE_PAGE);
        let end = start.saturating_add(bytes) & !(HUGE_PAGE - 1);
        if end > first {
            // SAFETY: [first, end) lies inside the allocation of `buffer`, which the `&mut`
            // keeps alive for the call, and is page aligned. MADV_HUGEPAGE changes only how
            // the kernel backs these pages: contents, protection and the mapping stay as they
            // are, so nothing Rust can observe changes. A failure leaves everything as it was.
            let _ = unsafe {
                libc::madvise(first as *mut libc::c_void, end - first, libc::MADV_HUGEPAGE)
            };
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = buffer;
}

#[cfg(test)]
mod tests {
    use super::advise_huge_pages;

    /// The advice changes nothing a program can see: empty, small and large buffers keep
    /// their contents and fill as before.
    #[test]
    fn advised_buffers_keep_and_take_their_contents() {
        let mut empty: Vec<u64> = Vec::new();
        advise_huge_pages(&mut empty);
        assert!(empty.is_empty());
        let mut small = vec![7u8; 100];
        advise_huge_pages(&mut small);
        assert!(small.iter().all(|&b| b == 7));
        let mut large: Vec<u64> = Vec::with_capacity(3 << 20);
        large.extend(0..1000);
        advise_huge_pages(&mut large);
        large.extend(1000..(3 << 20));
        assert!(large.iter().enumerate().all(|(i, &v)| v == i as u64));
    }
}
