//! A peer's heartbeat, watched from one's own cycle.

/// Watches a peer's heartbeat from one's own cycle: the peer is lost when its counter has not
/// moved for `limit` consecutive observations. No clocks, no sleeps: the observer's own cycle
/// is the time base.
#[derive(Debug, Clone)]
pub struct HeartbeatWatch {
    last: Option<u64>,
    unchanged: u32,
    limit: u32,
}

/// Verdict of a [`HeartbeatWatch`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PeerLiveness {
    /// The counter moved recently.
    Alive,
    /// The counter has not moved yet since the watch started.
    NotStarted,
    /// The counter stood still for `limit` observations.
    Lost,
}

impl HeartbeatWatch {
    /// A watch that declares the peer lost after `limit` unchanged observations.
    pub fn new(limit: u32) -> Self {
        Self {
            last: None,
            unchanged: 0,
            limit: limit.max(1),
        }
    }

    /// Feeds the current heartbeat value.
    pub fn observe(&mut self, value: u64) -> PeerLiveness {
        match self.last {
            Some(last) if last == value => {
                self.unchanged = self.unchanged.saturating_add(1);
            }
            Some(_) => self.unchanged = 0,
            None => {
                self.last = Some(value);
                return PeerLiveness::NotStarted;
            }
        }
        self.last = Some(value);
        if self.unchanged >= self.limit {
            PeerLiveness::Lost
        } else {
            PeerLiveness::Alive
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heartbeat_watch_declares_loss_after_limit() {
        let mut w = HeartbeatWatch::new(3);
        assert_eq!(w.observe(5), PeerLiveness::NotStarted);
        assert_eq!(w.observe(6), PeerLiveness::Alive);
        assert_eq!(w.observe(6), PeerLiveness::Alive);
        assert_eq!(w.observe(6), PeerLiveness::Alive);
        assert_eq!(w.observe(6), PeerLiveness::Lost);
        assert_eq!(w.observe(7), PeerLiveness::Alive);
    }
}
