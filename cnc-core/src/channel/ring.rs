//! A ring of fixed capacity for the diagnosis history and the switching log, read by
//! sequence number (what `cnc diag` asks for one entry at a time).

/// An entry of a [`Ring`] read by sequence number, and the window the ring keeps.
#[derive(Debug, Clone, Copy)]
pub struct RingRead<'a, T> {
    /// The entry and its sequence number (`None`: nothing at or after the one asked for).
    pub entry: Option<(u64, &'a T)>,
    /// Entries pushed so far.
    pub recorded: u64,
    /// Entries kept.
    pub kept: usize,
}

/// A ring of fixed capacity, filled at start-up (no allocation afterwards).
#[derive(Debug, Clone)]
pub struct Ring<T: Copy + Default> {
    entries: Vec<T>,
    next: usize,
    len: usize,
    /// Entries pushed since creation: the sequence number the next one gets.
    recorded: u64,
}

impl<T: Copy + Default> Ring<T> {
    /// A ring of `capacity` entries (0 keeps nothing).
    pub fn new(capacity: usize) -> Self {
        Self {
            entries: vec![T::default(); capacity],
            next: 0,
            len: 0,
            recorded: 0,
        }
    }

    /// Appends, dropping the oldest entry when full.
    pub fn push(&mut self, value: T) {
        if self.entries.is_empty() {
            return;
        }
        self.entries[self.next] = value;
        self.next = (self.next + 1) % self.entries.len();
        self.len = (self.len + 1).min(self.entries.len());
        self.recorded += 1;
    }

    /// The entry with sequence number `sequence` (or the oldest kept one if `sequence` is
    /// older; none when nothing is kept at or after it) and the window kept.
    pub fn read(&self, sequence: u64) -> RingRead<'_, T> {
        RingRead {
            entry: self.at_or_after(sequence),
            recorded: self.recorded,
            kept: self.len,
        }
    }

    fn at_or_after(&self, sequence: u64) -> Option<(u64, &T)> {
        let oldest = self.recorded - self.len as u64;
        let sequence = sequence.max(oldest);
        if sequence >= self.recorded {
            return None;
        }
        let back = (self.recorded - sequence) as usize;
        let cap = self.entries.len();
        Some((sequence, &self.entries[(self.next + cap - back) % cap]))
    }

    /// Oldest first.
    pub fn iter(&self) -> impl Iterator<Item = &T> {
        let cap = self.entries.len();
        let start = (self.next + cap - self.len) % cap.max(1);
        (0..self.len).map(move |i| &self.entries[(start + i) % cap])
    }

    /// Number of entries kept.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether nothing is kept.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}
