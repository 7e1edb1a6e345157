//! [`CancelToken`]: a request to abandon a frame, checked between tiles. A frame's cost
//! depends on settings a viewer's user (or a browser) chooses, so a frame can take far longer
//! than the next input is worth waiting for; whoever starts a frame may hand its token to
//! whoever learns that the frame is no longer wanted (new input, a newer cluster job, a
//! shutdown). The tile scheduler and a cluster node's render threads look at it before each
//! tile, never inside a tile, so a tile that starts is finished as usual and a frame whose
//! every tile was rendered is the same image as ever (only frames that complete are shown).

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// Not cancelled: the deadline of a token nobody has cancelled.
const NEVER: u64 = u64::MAX;

/// A shared, cloneable request to stop a frame between tiles, now or at a deadline.
#[derive(Clone, Debug)]
pub struct CancelToken(Arc<Deadline>);

#[derive(Debug)]
struct Deadline {
    /// The time the deadline is counted from.
    origin: Instant,
    /// Nanoseconds after `origin` from which the token counts as cancelled.
    at: AtomicU64,
}

impl Default for CancelToken {
    fn default() -> Self {
        Self(Arc::new(Deadline { origin: Instant::now(), at: AtomicU64::new(NEVER) }))
    }
}

impl CancelToken {
    /// A token nobody has cancelled yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Cancels the frame now.
    pub fn cancel(&self) {
        self.0.at.store(0, Ordering::Relaxed);
    }

    /// Cancels the frame at `when` (or now, if that has passed) unless it was cancelled
    /// earlier: the earliest request wins.
    pub fn cancel_at(&self, when: Instant) {
        let after = when.saturating_duration_since(self.0.origin).as_nanos();
        self.0.at.fetch_min(u64::try_from(after).unwrap_or(NEVER - 1), Ordering::Relaxed);
    }

    /// True once the frame should stop.
    pub fn is_cancelled(&self) -> bool {
        match self.0.at.load(Ordering::Relaxed) {
            NEVER => false,
            0 => true,
            at => self.0.origin.elapsed().as_nanos() >= u128::from(at),
        }
    }
}

/// A frame was cancelled before its last tile; it has no image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("the frame was cancelled")]
pub struct Cancelled;

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn cancelled_now_at_a_deadline_or_never() {
        let token = CancelToken::new();
        assert!(!token.is_cancelled());
        token.cancel_at(Instant::now() + Duration::from_secs(3600));
        assert!(!token.is_cancelled(), "the deadline is an hour away");
        let clone = token.clone();
        clone.cancel_at(Instant::now());
        assert!(token.is_cancelled(), "the earlier deadline wins, for every clone");
        let later = CancelToken::new();
        later.cancel();
        later.cancel_at(Instant::now() + Duration::from_secs(3600));
        assert!(later.is_cancelled(), "a later deadline does not undo a cancel");
    }
}
