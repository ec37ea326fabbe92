//! A child process that never outlives its test, and signals sent to a process.

use std::io::{self, Read};
use std::process::{Child, Command, ExitStatus, Output};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Kills `child` when dropped unless it has exited: a hung child never outlives its test.
pub struct ChildGuard(pub Child);

impl ChildGuard {
    /// The child's process id.
    pub fn id(&self) -> u32 {
        self.0.id()
    }

    /// Kills the child and every process of its group (a child started by [`crate::Cli`] leads a
    /// group of its own, so a PLC that `cnc run` spawned goes with it and no pipe stays open).
    pub fn kill_group(&mut self) {
        kill(&["-KILL", "--", &format!("-{}", self.id())]);
        let _ = self.0.kill();
    }

    /// Sends the signal `name` to the child: [`signal`].
    pub fn signal(&self, name: &str) -> bool {
        signal(self.id(), name)
    }

    /// Waits for the child to exit, up to `limit`; kills it and returns `None` on expiry.
    pub fn wait_with_watchdog(&mut self, limit: Duration) -> Option<ExitStatus> {
        let deadline = Instant::now() + limit;
        loop {
            if let Ok(Some(status)) = self.0.try_wait() {
                return Some(status);
            }
            if Instant::now() > deadline {
                self.kill_group();
                return None;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    /// [`ChildGuard::wait_with_watchdog`], collecting what the child writes to its piped
    /// stdout and stderr (those the test has not taken). `Err` (`TimedOut`) when the watchdog
    /// killed it; the error carries what it printed.
    pub fn wait_with_output(&mut self, limit: Duration) -> io::Result<Output> {
        // As std's `wait_with_output`: a child reading its stdin to the end gets its end.
        drop(self.0.stdin.take());
        let out = drain(self.0.stdout.take());
        let err = drain(self.0.stderr.take());
        let status = self.wait_with_watchdog(limit);
        let (stdout, stderr) = (join(out), join(err));
        match status {
            Some(status) => Ok(Output {
                status,
                stdout,
                stderr,
            }),
            None => Err(io::Error::new(
                io::ErrorKind::TimedOut,
                format!(
                    "watchdog: killed after {limit:?}\nstdout:\n{}\nstderr:\n{}",
                    String::from_utf8_lossy(&stdout),
                    String::from_utf8_lossy(&stderr)
                ),
            )),
        }
    }
}

impl Drop for ChildGuard {
    fn drop(&mut self) {
        if let Ok(None) = self.0.try_wait() {
            self.kill_group();
            let _ = self.0.wait();
        }
    }
}

/// Sends the signal `name` (`"TERM"`, `"KILL"`, `"STOP"`, ...) to process `pid` with
/// `kill -NAME PID`; true when `kill` delivered it.
pub fn signal(pid: u32, name: &str) -> bool {
    kill(&[&format!("-{name}"), &pid.to_string()])
}

/// Runs `kill ARGS`; true when it delivered. `kill` returns at once, so it runs without the
/// watchdog (whose expiry calls it: through [`crate::Cli`] it would call itself).
fn kill(args: &[&str]) -> bool {
    Command::new("kill")
        .args(args)
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|status| status.success())
}

fn drain(pipe: Option<impl Read + Send + 'static>) -> Option<JoinHandle<Vec<u8>>> {
    pipe.map(|mut pipe| {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            let _ = pipe.read_to_end(&mut bytes);
            bytes
        })
    })
}

fn join(reader: Option<JoinHandle<Vec<u8>>>) -> Vec<u8> {
    reader.and_then(|r| r.join().ok()).unwrap_or_default()
}

/// The PLC process of `instance` (a `plc` or `cnc plc` with `--instance INSTANCE`), found in
/// /proc by its command line.
pub fn plc_pid(instance: &str) -> Option<u32> {
    for entry in std::fs::read_dir("/proc").ok()?.flatten() {
        let Ok(pid) = entry.file_name().to_string_lossy().parse::<u32>() else {
            continue;
        };
        let Ok(cmd) = std::fs::read(entry.path().join("cmdline")) else {
            continue;
        };
        let cmd = String::from_utf8_lossy(&cmd).replace('\0', " ");
        if cmd.contains(" plc ") && cmd.contains(&format!("--instance {instance} ")) {
            return Some(pid);
        }
    }
    None
}
