//! Real-time settings of the calling thread and process: SCHED_FIFO priority, CPU pinning,
//! locked memory, a pre-faulted stack, timer slack. Each returns the OS error when the system
//! refuses (no privilege, a CPU that does not exist), so the caller can go on without it.

use std::io;

fn check(result: libc::c_int) -> io::Result<()> {
    if result == 0 {
        Ok(())
    } else {
        Err(io::Error::last_os_error())
    }
}

/// Runs the calling thread under SCHED_FIFO at `priority` (1..=99).
pub fn set_fifo_priority(priority: i32) -> io::Result<()> {
    let param = libc::sched_param {
        sched_priority: priority,
    };
    // SAFETY: `param` is a valid, initialised sched_param that outlives the call; pid 0
    // names the calling thread. The call only changes the thread's scheduling.
    check(unsafe { libc::sched_setscheduler(0, libc::SCHED_FIFO, &param) })
}

/// Gives the calling thread, and every thread it starts afterwards, the nice value `nice`
/// (0..=19; 19 yields the CPU to everything else first): for tools beside the real-time
/// processes.
pub fn set_nice(nice: i32) -> io::Result<()> {
    // SAFETY: setpriority takes integers only; PRIO_PROCESS with who = 0 names the calling
    // thread on Linux. The call only changes its scheduling weight.
    check(unsafe { libc::setpriority(libc::PRIO_PROCESS as _, 0, nice) })
}

/// Pins the calling thread to CPU `cpu`.
pub fn pin_to_cpu(cpu: usize) -> io::Result<()> {
    if cpu >= libc::CPU_SETSIZE as usize {
        return Err(io::Error::from(io::ErrorKind::InvalidInput));
    }
    // SAFETY: cpu_set_t is plain data for which all-zero is the empty set.
    let mut set: libc::cpu_set_t = unsafe { core::mem::zeroed() };
    // SAFETY: `cpu` is below CPU_SETSIZE (checked above), so CPU_SET stays inside `set`.
    unsafe { libc::CPU_SET(cpu, &mut set) };
    // SAFETY: `set` is a valid cpu_set_t of the size passed; pid 0 is the calling thread.
    check(unsafe { libc::sched_setaffinity(0, core::mem::size_of::<libc::cpu_set_t>(), &set) })
}

/// Locks every current and future page of the process in memory (no page faults later).
pub fn lock_memory() -> io::Result<()> {
    // SAFETY: mlockall takes only flags and changes no memory the program can see.
    check(unsafe { libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE) })
}

/// Sets the calling thread's timer slack (how late the kernel may wake it to batch
/// wake-ups), in nanoseconds; 1 is the least.
pub fn set_timer_slack(nanoseconds: u64) -> io::Result<()> {
    // SAFETY: PR_SET_TIMERSLACK takes one integer argument by value; the others are unused.
    check(unsafe {
        libc::prctl(
            libc::PR_SET_TIMERSLACK,
            nanoseconds as libc::c_ulong,
            0,
            0,
            0,
        )
    })
}

/// Asks the kernel to keep every CPU's wake-up latency at most `microseconds` (PM QoS: the
/// value written to `/dev/cpu_dma_latency`, held while the file stays open): no deep idle
/// state whose exit delays a timer's wake-up. `cyclictest` does the same by default. The file
/// stays open until the process ends.
pub fn hold_cpu_wake_latency(microseconds: u32) -> io::Result<()> {
    use std::io::Write;
    static HELD: std::sync::OnceLock<std::fs::File> = std::sync::OnceLock::new();
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/cpu_dma_latency")?;
    let value = i32::try_from(microseconds).unwrap_or(i32::MAX);
    file.write_all(&value.to_ne_bytes())?;
    // A second request keeps the first file (and its value) open.
    let _ = HELD.set(file);
    Ok(())
}

/// Touches `bytes` of stack below the caller, so that (with locked memory) the stack the
/// tick will use is mapped before it runs.
pub fn prefault_stack(bytes: usize) {
    const CHUNK: usize = 64 * 1024;
    fn touch(remaining: usize) {
        let mut page = [0u8; CHUNK];
        // Keep the writes: the optimiser must not drop the array.
        std::hint::black_box(&mut page);
        if remaining > CHUNK {
            touch(remaining - CHUNK);
        }
        std::hint::black_box(&page);
    }
    touch(bytes);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Timer slack and stack pre-faulting work unprivileged; a CPU beyond the set is
    /// refused with an error, not a crash.
    #[test]
    fn settings_apply_or_report_why_not() {
        set_timer_slack(50_000).expect("timer slack");
        prefault_stack(256 * 1024);
        assert!(pin_to_cpu(usize::MAX).is_err());
        assert!(set_fifo_priority(1000).is_err(), "priority out of range");
    }
}
