//! Progress of a long run on a terminal. The tick loop only stores its tick in an atomic (no
//! lock, no IO, no allocation in the tick); a thread of its own draws the bar ten times a
//! second. Nothing is drawn, and no thread started, when stderr is not a terminal.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// The tick counter the loop writes; cheap to clone.
#[derive(Debug, Clone, Default)]
pub struct TickCounter(Arc<AtomicU64>);

impl TickCounter {
    /// Stores the tick just finished.
    pub fn set(&self, tick: u64) {
        self.0.store(tick, Ordering::Relaxed);
    }
}

/// A bar drawn by its own thread until dropped.
#[derive(Debug)]
pub struct Progress {
    done: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Progress {
    /// Starts drawing `counter` out of `total` ticks (a spinner when unknown) with `label`,
    /// if stderr is a terminal.
    pub fn start(counter: &TickCounter, total: Option<u64>, label: &str) -> Option<Progress> {
        if !std::io::stderr().is_terminal() {
            return None;
        }
        let bar = match total {
            Some(n) => indicatif::ProgressBar::new(n).with_style(
                indicatif::ProgressStyle::with_template(
                    "{msg} [{bar:40}] {pos}/{len} ticks ({elapsed}, ~{eta} left)",
                )
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
                .progress_chars("=> "),
            ),
            None => indicatif::ProgressBar::new_spinner().with_style(
                indicatif::ProgressStyle::with_template("{spinner} {msg}: tick {pos} ({elapsed})")
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
            ),
        };
        bar.set_message(label.to_string());
        let done = Arc::new(AtomicBool::new(false));
        let stop = done.clone();
        let ticks = counter.0.clone();
        let thread = std::thread::spawn(move || {
            while !stop.load(Ordering::Acquire) {
                bar.set_position(ticks.load(Ordering::Relaxed));
                bar.tick();
                std::thread::sleep(Duration::from_millis(100));
            }
            bar.finish_and_clear();
        });
        Some(Progress {
            done,
            thread: Some(thread),
        })
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.done.store(true, Ordering::Release);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}
