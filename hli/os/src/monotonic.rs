//! The CNC's tick clock: CLOCK_MONOTONIC, with a sleep to an absolute deadline so that the
//! tick period does not drift by the time spent computing a sleep duration (the thread can be
//! preempted between reading the clock and going to sleep; an absolute deadline is immune).

use core::time::Duration;
use iceoryx2_pal_posix::posix;

fn to_duration(ts: &posix::timespec) -> Duration {
    Duration::new(ts.tv_sec as u64, ts.tv_nsec as u32)
}

/// Now, on CLOCK_MONOTONIC (time since an arbitrary start, usually boot).
pub fn now() -> Duration {
    let mut ts = posix::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec for the duration of the call;
    // CLOCK_MONOTONIC exists on every platform iceoryx2 supports, so the call cannot fail
    // (and on failure `ts` stays zero, a harmless value).
    let _ = unsafe { posix::clock_gettime(posix::CLOCK_MONOTONIC, &mut ts) };
    to_duration(&ts)
}

/// Sleeps until CLOCK_MONOTONIC reaches `deadline` (a value of [`now`]); returns at once
/// when it has passed. A signal interrupting the sleep sleeps again to the same deadline.
pub fn sleep_until(deadline: Duration) {
    let ts = posix::timespec {
        tv_sec: deadline.as_secs() as _,
        tv_nsec: deadline.subsec_nanos() as _,
    };
    loop {
        // SAFETY: `ts` is a valid timespec; the remaining-time pointer may be null with
        // TIMER_ABSTIME (it is not written for absolute sleeps).
        let rc = unsafe {
            posix::clock_nanosleep(
                posix::CLOCK_MONOTONIC,
                posix::CLOCK_TIMER_ABSTIME,
                &ts,
                core::ptr::null_mut(),
            )
        };
        // clock_nanosleep returns the error number itself; only EINTR is worth a retry.
        if rc != posix::Errno::EINTR as i32 || now() >= deadline {
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sleeping_to_a_deadline_returns_after_it() {
        let deadline = now() + Duration::from_millis(2);
        sleep_until(deadline);
        assert!(now() >= deadline);
        sleep_until(Duration::ZERO); // passed long ago: returns at once
    }
}
