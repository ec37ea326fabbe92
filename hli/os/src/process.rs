//! Child processes: asking one to end, waiting for one and reading what it used.

/// Waits for `child` to end and returns whether it exited with status 0 and its peak resident
/// memory in KiB (the kernel's `ru_maxrss` of that one process), for benchmarks that compare
/// whole processes.
pub fn wait_with_peak_memory(child: std::process::Child) -> std::io::Result<(bool, i64)> {
    let pid = child.id() as libc::pid_t;
    let mut status: libc::c_int = 0;
    // SAFETY: `rusage` is a plain C struct of integers, for which all zero bytes are valid.
    let mut usage: libc::rusage = unsafe { core::mem::zeroed() };
    // SAFETY: `pid` is our own child, not yet waited for (we own its `Child`); both pointers are
    // to live locals of the right types for the duration of the call.
    let waited = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    if waited != pid {
        return Err(std::io::Error::last_os_error());
    }
    let success = libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0;
    Ok((success, usage.ru_maxrss))
}

/// Asks `child` to end (SIGTERM), the way an operator's `kill` does: it stops in its own
/// controlled way. Not waited for.
pub fn terminate(child: &std::process::Child) -> std::io::Result<()> {
    let pid = libc::pid_t::try_from(child.id()).map_err(std::io::Error::other)?;
    // SAFETY: kill(2) takes two integers and touches no memory of ours; `pid` is our own child,
    // not yet waited for (we hold its `Child`), so the pid cannot belong to another process.
    if unsafe { libc::kill(pid, libc::SIGTERM) } != 0 {
        return Err(std::io::Error::last_os_error());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::wait_with_peak_memory;
    use std::process::Command;

    /// The exit status is read as success or failure, and a process that ran has used some
    /// memory.
    #[test]
    fn reports_the_exit_status_and_a_peak() {
        let ok = Command::new("true").spawn().expect("spawn true");
        let (success, peak) = wait_with_peak_memory(ok).expect("wait4");
        assert!(success);
        assert!(peak > 0, "peak {peak} KiB");
        let failed = Command::new("false").spawn().expect("spawn false");
        assert!(!wait_with_peak_memory(failed).expect("wait4").0);
    }
}
