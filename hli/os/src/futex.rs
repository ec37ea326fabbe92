//! A futex word that several processes map (Linux `futex(2)` without the private flag): one
//! side sleeps while the word holds the value it last saw, the other changes the word and
//! wakes it. One system call each way, no socket and no file descriptor.

use core::sync::atomic::AtomicU32;
use core::time::Duration;
use std::io;

/// Sleeps while `word` holds `expected`, at most `timeout`. Returns at once when the word
/// differs already; otherwise when woken, on timeout or on a signal: the caller reads the
/// word again in every case. `Err` only for a refused call (not for a timeout or a signal).
pub fn wait(word: &AtomicU32, expected: u32, timeout: Duration) -> io::Result<()> {
    let ts = libc::timespec {
        tv_sec: timeout.as_secs().min(i64::MAX as u64) as libc::time_t,
        tv_nsec: timeout.subsec_nanos() as libc::c_long,
    };
    // SAFETY: `word` is a live, aligned u32 for the duration of the call (the kernel reads it
    // atomically and compares it with `expected`); `ts` is a valid timespec that outlives the
    // call; the last two arguments are unused by FUTEX_WAIT.
    let r = unsafe {
        libc::syscall(
            libc::SYS_futex,
            word.as_ptr(),
            libc::FUTEX_WAIT,
            expected,
            &ts as *const libc::timespec,
            core::ptr::null::<u32>(),
            0u32,
        )
    };
    if r == 0 {
        return Ok(());
    }
    let e = io::Error::last_os_error();
    match e.raw_os_error() {
        Some(libc::EAGAIN) | Some(libc::ETIMEDOUT) | Some(libc::EINTR) => Ok(()),
        _ => Err(e),
    }
}

/// Wakes up to `waiters` processes sleeping on `word`; how many woke.
pub fn wake(word: &AtomicU32, waiters: u32) -> io::Result<usize> {
    let n = waiters.min(i32::MAX as u32) as libc::c_int;
    // SAFETY: `word` is a live, aligned u32; FUTEX_WAKE only uses its address as the key and
    // reads no other argument but the count.
    let r = unsafe { libc::syscall(libc::SYS_futex, word.as_ptr(), libc::FUTEX_WAKE, n) };
    if r < 0 {
        Err(io::Error::last_os_error())
    } else {
        Ok(r as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::sync::atomic::Ordering;
    use std::sync::Arc;

    #[test]
    fn a_changed_word_returns_at_once_and_a_wake_ends_the_wait() {
        let word = Arc::new(AtomicU32::new(1));
        // The word differs from the expected value: no sleep (the test's watchdog is the
        // 60 s timeout, which would show as a hang, never as a pass).
        wait(&word, 0, Duration::from_secs(60)).unwrap();
        let sleeper = {
            let word = Arc::clone(&word);
            std::thread::spawn(move || {
                while word.load(Ordering::Acquire) == 1 {
                    wait(&word, 1, Duration::from_secs(60)).unwrap();
                }
            })
        };
        word.store(2, Ordering::Release);
        wake(&word, 1).unwrap();
        sleeper.join().unwrap();
        assert_eq!(word.load(Ordering::Acquire), 2);
    }
}
