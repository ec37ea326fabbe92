//! `#TRACK CS ON [LOG_FILE=..]` written while the CNC runs: after each tick the run loop hands
//! the switching-log events that are new since the last tick to a writer thread over a
//! wait-free ring (no allocation, no system call in the loop); the thread formats them, appends
//! them to the channel's file and flushes. At the end of the run `cnc run` writes the complete
//! listing (history and log) over it, as before.

use cnc_core::channel::dyn_cs::TrackEvent;
use cnc_core::channel::{diagnosis::event_lines, Channel};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

/// One event of one channel, with the file its program named.
struct Item {
    channel: usize,
    file: Arc<str>,
    tick: u64,
    event: TrackEvent,
}

/// Events the ring holds; beyond them the loop counts what it drops.
const RING: usize = 4096;

/// The run loop's side.
pub struct LogStream {
    producer: rtrb::Producer<Item>,
    /// Per channel: the next log sequence number to forward.
    next: Vec<u64>,
    dropped: u64,
    done: Arc<AtomicBool>,
    writer: Option<JoinHandle<Result<u64, String>>>,
}

impl LogStream {
    /// Starts the writer thread for `channels` channels; files with a relative name go under
    /// `dir`.
    pub fn start(dir: &Path, channels: usize) -> Self {
        let (producer, consumer) = rtrb::RingBuffer::new(RING);
        let done = Arc::new(AtomicBool::new(false));
        let (flag, dir) = (done.clone(), dir.to_path_buf());
        let writer = std::thread::Builder::new()
            .name("cnc-log-file".into())
            .spawn(move || write_loop(consumer, &dir, &flag))
            .ok();
        Self {
            producer,
            next: vec![0; channels],
            dropped: 0,
            done,
            writer,
        }
    }

    /// Hands on what each channel with a LOG_FILE logged since the last call. Does not
    /// allocate.
    pub fn forward(&mut self, channels: &[Channel]) {
        for (i, c) in channels.iter().enumerate() {
            let (Some(file), Some(next)) = (c.log_file_name(), self.next.get_mut(i)) else {
                continue;
            };
            let tracker = c.tracker();
            while let Some((seq, (tick, event))) = tracker.log_at(*next).entry {
                let item = Item {
                    channel: i,
                    file: file.clone(),
                    tick: *tick,
                    event: *event,
                };
                if self.producer.push(item).is_err() {
                    self.dropped += 1;
                }
                *next = seq + 1;
            }
        }
    }

    /// Stops the writer after it wrote everything handed on; the events written, or why the
    /// files could not be written.
    pub fn finish(mut self) -> Result<u64, String> {
        self.done.store(true, Ordering::Release);
        let written = match self.writer.take() {
            Some(handle) => handle.join().map_err(|_| "writer panicked".to_string())??,
            None => return Err("the writer thread could not start".into()),
        };
        if self.dropped > 0 {
            return Err(format!("{} events dropped (writer too slow)", self.dropped));
        }
        Ok(written)
    }
}

fn write_loop(
    mut consumer: rtrb::Consumer<Item>,
    dir: &Path,
    done: &AtomicBool,
) -> Result<u64, String> {
    let mut files: Vec<(usize, PathBuf, std::io::BufWriter<std::fs::File>)> = Vec::new();
    let mut written = 0;
    loop {
        let last = done.load(Ordering::Acquire);
        while let Ok(item) = consumer.pop() {
            write_item(&mut files, dir, &item)?;
            written += 1;
        }
        for (_, path, file) in &mut files {
            file.flush()
                .map_err(|e| format!("{}: {e}", path.display()))?;
        }
        if last {
            return Ok(written);
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

fn write_item(
    files: &mut Vec<(usize, PathBuf, std::io::BufWriter<std::fs::File>)>,
    dir: &Path,
    item: &Item,
) -> Result<(), String> {
    let path = dir.join(&*item.file);
    let fail = |e: std::io::Error| format!("{}: {e}", path.display());
    // Channels naming the same file share it (the first one's header).
    let at = match files.iter().position(|(_, p, _)| *p == path) {
        Some(at) => at,
        None => {
            if let Some(parent) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(parent).map_err(fail)?;
            }
            let mut file = std::io::BufWriter::new(std::fs::File::create(&path).map_err(fail)?);
            writeln!(file, "BAHN LOGGING KANAL-NR.: {}", item.channel + 1).map_err(fail)?;
            writeln!(file, "=====\ntime level message\n-----").map_err(fail)?;
            files.push((item.channel, path.clone(), file));
            files.len() - 1
        }
    };
    let file = &mut files[at].2;
    for (tick, level, message) in event_lines(item.tick, &item.event) {
        writeln!(file, "{tick} {level:08x} {message}").map_err(fail)?;
    }
    Ok(())
}
