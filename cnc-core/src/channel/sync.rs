//! `#SIGNAL SYN` / `#WAIT SYN` across channels: a board of counters per synchronisation id.
//! `#SIGNAL SYN [ID n COUNT k]` adds `k` signals to id `n`; `#WAIT SYN [ID n ...]` waits until
//! every listed id holds a signal and then consumes one of each. Fixed capacity, no allocation.

/// Distinct ids the board holds at once.
pub const SYNC_IDS: usize = 64;

/// The board, and what a waiting channel needs to know of the others: which run, and
/// whether one was stopped, reset or failed since it began to wait.
#[derive(Debug, Clone)]
pub struct SyncBoard {
    slots: [(u32, u32); SYNC_IDS],
    /// Bit `c`: channel `c` runs its program this tick.
    running: u32,
    /// Counts channels that stopped, were reset or failed while they ran.
    aborts: u32,
}

/// More distinct ids pending than the board holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("more than {SYNC_IDS} synchronisation ids pending at once")]
pub struct SyncFull;

impl Default for SyncBoard {
    fn default() -> Self {
        Self {
            slots: [(0, 0); SYNC_IDS],
            running: 0,
            aborts: 0,
        }
    }
}

impl SyncBoard {
    /// Adds `count` signals to `id`.
    pub fn signal(&mut self, id: u32, count: u32) -> Result<(), SyncFull> {
        if let Some(slot) = self.slots.iter_mut().find(|s| s.1 > 0 && s.0 == id) {
            slot.1 = slot.1.saturating_add(count);
            return Ok(());
        }
        let slot = self.slots.iter_mut().find(|s| s.1 == 0).ok_or(SyncFull)?;
        *slot = (id, count);
        Ok(())
    }

    /// The channels that may still signal this tick (bit `c` for channel `c`): running, or
    /// with a program selected and not started yet.
    pub fn set_running(&mut self, mask: u32) {
        self.running = mask;
    }

    /// Whether a channel other than `me` may still signal.
    pub fn others_running(&self, me: usize) -> bool {
        self.running & !(1u32 << me) != 0
    }

    /// A channel that ran was stopped, reset or failed.
    pub fn note_abort(&mut self) {
        self.aborts = self.aborts.wrapping_add(1);
    }

    /// The count of such aborts (a waiting channel compares it with the count when it began).
    pub fn aborts(&self) -> u32 {
        self.aborts
    }

    /// Signals pending for `id`.
    pub fn pending(&self, id: u32) -> u32 {
        self.slots
            .iter()
            .find(|s| s.1 > 0 && s.0 == id)
            .map_or(0, |s| s.1)
    }

    /// Consumes one signal of each id when all are there; `false` (nothing consumed) otherwise.
    pub fn try_wait(&mut self, ids: &[u32]) -> bool {
        if !ids.iter().all(|&id| self.pending(id) > 0) {
            return false;
        }
        for &id in ids {
            if let Some(slot) = self.slots.iter_mut().find(|s| s.1 > 0 && s.0 == id) {
                slot.1 -= 1;
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signals_are_counted_and_consumed() {
        let mut board = SyncBoard::default();
        assert!(!board.try_wait(&[1]));
        board.signal(1, 2).unwrap();
        board.signal(3, 1).unwrap();
        assert!(!board.try_wait(&[1, 2]), "id 2 missing: nothing consumed");
        assert_eq!(board.pending(1), 2);
        assert!(board.try_wait(&[1, 3]));
        assert!(board.try_wait(&[1]));
        assert!(!board.try_wait(&[1]));
        for id in 0..SYNC_IDS as u32 {
            board.signal(100 + id, 1).unwrap();
        }
        assert_eq!(board.signal(999, 1), Err(SyncFull));
    }
}
