//! What the segment's checks read from the operating system: a process's start time (a live
//! owner against a reused pid) and a segment file's owner.

use super::AttachError;

/// Start time of a process (clock ticks since boot) and whether it is still running, from
/// `/proc`; `None` where there is no such process. Tells a live owner from a reused pid.
pub(crate) fn process_start_stamp(pid: u32) -> Option<u64> {
    start_stamp_at(&stat_path(pid))
}

pub(super) fn stat_path(pid: u32) -> String {
    format!("/proc/{pid}/stat")
}

/// [`process_start_stamp`] from the process's `stat` file, read into a buffer on the stack
/// (no allocation: the PLC asks from its wait).
pub(super) fn start_stamp_at(path: &str) -> Option<u64> {
    use std::io::Read;
    let mut buf = [0u8; 4096];
    let mut file = std::fs::File::open(path).ok()?;
    let mut len = 0;
    loop {
        let n = file.read(buf.get_mut(len..)?).ok()?;
        if n == 0 {
            break;
        }
        len += n;
    }
    let stat = core::str::from_utf8(&buf[..len]).ok()?;
    // The command name (field 2) is in parentheses and may contain spaces.
    let after_name = stat.get(stat.rfind(')')? + 2..)?;
    let mut fields = after_name.split_whitespace();
    let state = fields.next()?;
    if state == "Z" || state == "X" {
        return None; // exited, not yet reaped
    }
    // After the state come fields 4.., the start time is field 22.
    fields.nth(22 - 4)?.parse().ok()
}

/// The process's effective user, from `/proc/self/status` (`Uid:` real, effective, ...); the
/// owner of `/proc/self` would be root for a process given file capabilities.
fn effective_uid() -> Option<u32> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let uids = status.lines().find_map(|l| l.strip_prefix("Uid:"))?;
    uids.split_whitespace().nth(1)?.parse().ok()
}

/// Refuses a segment file another user owns (owner-only permissions keep others out of ours;
/// this keeps us out of theirs, where the mode would let us in).
pub(super) fn check_owner(name: &str) -> Result<(), AttachError> {
    use std::os::unix::fs::MetadataExt;
    let owner = std::fs::metadata(format!("/dev/shm/{name}")).map(|m| m.uid());
    match (owner, effective_uid()) {
        (Ok(owner), Some(me)) if owner != me => Err(AttachError::ForeignOwner {
            name: name.to_string(),
            owner,
            me,
        }),
        _ => Ok(()),
    }
}
