//! A child process that never outlives its test.

use std::process::Child;
use std::time::{Duration, Instant};

/// Kills `child` when dropped unless it has exited: a hung child never outlives its test.
pub struct ChildGuard(pub Child);

impl ChildGuard {
    /// Waits for the child to exit, up to `limit`; kills it and returns `None` on expiry.
    pub fn wait_with_watchdog(&mut self, limit: Duration) -> Option<std::process::ExitStatus> {
        let deadline = Instant::now() + limit;
        loop {
            if let Ok(Some(status)) = self.0.try_wait() {
                return Some(status);
            }
            if Instant::now() > deadline {
                let _ = self.0.kill();
                return None;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}

impl Drop for ChildGuard {
    fn drop(&mut self) {
        if let Ok(None) = self.0.try_wait() {
            let _ = self.0.kill();
            let _ = self.0.wait();
        }
    }
}
