//! Payloads with checksums for the torn-write tests, and the `hli-peer` helper process.

use crate::child::ChildGuard;
use crate::cli::Cli;
use hli::layout::HliCoordinateSystemInt;
use std::io::{BufRead, BufReader};
use std::process::Stdio;

/// A payload carrying `seq` and a checksum over it (in `fill_up_1`).
pub fn payload(seq: u32) -> HliCoordinateSystemInt {
    let s = seq as i32;
    let mut p = HliCoordinateSystemInt {
        translation: [s, s.wrapping_mul(-3), s ^ 0x0F0F_0F0F],
        fill_up_2: 0,
        rotation: [s.wrapping_add(17), s.rotate_left(7), !s],
        fill_up_1: 0,
    };
    p.fill_up_1 = checksum(&p);
    p
}

/// FNV-style checksum over the six words.
pub fn checksum(p: &HliCoordinateSystemInt) -> i32 {
    p.translation
        .iter()
        .chain(p.rotation.iter())
        .fold(0x811c_9dc5u32, |h, &w| {
            (h ^ w as u32).wrapping_mul(16_777_619)
        }) as i32
}

/// The sequence number of a whole payload; `None` when it is torn or corrupt.
pub fn verify(p: &HliCoordinateSystemInt) -> Option<u32> {
    let seq = p.translation[0] as u32;
    (payload(seq) == *p).then_some(seq)
}

/// Starts the `hli-peer` helper binary (path from the calling test's `CARGO_BIN_EXE_hli-peer`)
/// in `mode` for `instance` and waits for its `ready` line.
pub fn spawn_ready_peer(peer_exe: &str, mode: &str, instance: &str) -> ChildGuard {
    spawn_peer_saying(peer_exe, &[mode, instance], "ready")
}

/// Starts the `hli-peer` helper binary with `args` (stdin and stdout piped: closing its stdin
/// is how some modes are told to end) and waits for it to print `first_line`.
pub fn spawn_peer_saying(peer_exe: &str, args: &[&str], first_line: &str) -> ChildGuard {
    let mut child = Cli::new(peer_exe)
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("spawn hli-peer");
    let mut line = String::new();
    BufReader::new(child.0.stdout.as_mut().expect("piped stdout"))
        .read_line(&mut line)
        .expect("read the peer's first line");
    assert_eq!(line.trim(), first_line, "hli-peer {args:?} did not start");
    child
}

/// Removes the segment a killed CNC peer left behind: takes it over as stale (its process is
/// gone) and drops it, which unlinks it. Tests that SIGKILL a CNC call this last, so a test
/// run leaves nothing in /dev/shm.
pub fn remove_stale_segment(instance: &str) {
    // The calls' mailbox a killed CNC left: taken over (its process is gone) and dropped.
    if let Err(e) = hli_transport::rpc::mailbox::Mailbox::create(instance) {
        panic!("{instance}: the stale mailbox could not be taken over: {e}");
    }
    match hli_transport::segment::CncSegment::create(instance, 1, 1) {
        Ok(segment) => assert!(
            segment.replaced_stale().is_some(),
            "{instance}: the segment was expected to be stale"
        ),
        Err(e) => panic!("{instance}: the stale segment could not be taken over: {e}"),
    }
}
