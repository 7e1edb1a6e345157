//! [`FailureDetector`]: which render nodes rank 0 suspects of having stopped, and which it
//! gives up for lost. A heartbeat failure detector (Chandra and Toueg, "Unreliable failure
//! detectors for reliable distributed systems", 1996): every message from a node counts as a
//! heartbeat; a node silent for longer than a short time is *suspected* (rank 0 gives it no
//! tiles and hands the ones it holds to the others), is trusted again as soon as it is heard
//! from, and is *lost* once it has been silent for longer than the limit.
//!
//! Silence is measured on a clock that runs only while rank 0 listens: whatever a node sends
//! while rank 0 is busy elsewhere (writing a frame, a viewer that idles) waits in the
//! transport, so that time proves nothing. The clock adds up over the frames, so a node that
//! stays silent is found however short each frame is.
//! Pure bookkeeping with the time passed in, so it is tested without clocks or threads.

use std::time::{Duration, Instant};

/// A node as the detector sees it.
#[derive(Clone, Copy, Debug)]
struct Watch {
    /// The listening clock when the node was last heard from.
    heard: Duration,
    suspected: bool,
}

/// The liveness of a job's render nodes, numbered 0.. in the order rank 0 keeps them.
#[derive(Debug)]
pub struct FailureDetector {
    suspect_after: Duration,
    limit: Duration,
    /// Listening time before the current stretch.
    listened: Duration,
    /// Start of the current stretch of listening.
    since: Option<Instant>,
    nodes: Vec<Watch>,
}

/// A node silent for longer than the limit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lost {
    /// The node's number.
    pub node: usize,
    /// How long rank 0 listened without hearing from it.
    pub silent: Duration,
}

impl FailureDetector {
    /// `nodes` nodes, all just heard from; a node silent for `suspect_after` is suspected, one
    /// silent for `limit` is lost.
    pub fn new(nodes: usize, suspect_after: Duration, limit: Duration) -> Self {
        let heard = Watch { heard: Duration::ZERO, suspected: false };
        Self { suspect_after, limit, listened: Duration::ZERO, since: None, nodes: vec![heard; nodes] }
    }

    /// Rank 0 starts listening at `now` (the clock runs).
    pub fn listen(&mut self, now: Instant) {
        if self.since.is_none() {
            self.since = Some(now);
        }
    }

    /// Rank 0 stops listening at `now` (the clock stops).
    pub fn pause(&mut self, now: Instant) {
        if let Some(since) = self.since.take() {
            self.listened += now.saturating_duration_since(since);
        }
    }

    /// The listening clock at `now`.
    fn clock(&self, now: Instant) -> Duration {
        self.listened + self.since.map_or(Duration::ZERO, |since| now.saturating_duration_since(since))
    }

    /// Node `node` was heard from at `now`. True if it was suspected: it is trusted again.
    pub fn heard(&mut self, node: usize, now: Instant) -> bool {
        let clock = self.clock(now);
        let Some(watch) = self.nodes.get_mut(node) else { return false };
        watch.heard = clock;
        std::mem::replace(&mut watch.suspected, false)
    }

    /// True while node `node` is suspected.
    pub fn is_suspected(&self, node: usize) -> bool {
        self.nodes.get(node).is_some_and(|w| w.suspected)
    }

    /// How long rank 0 has listened without hearing from node `node`, at `now`.
    pub fn silence(&self, node: usize, now: Instant) -> Duration {
        self.nodes.get(node).map_or(Duration::ZERO, |w| self.clock(now).saturating_sub(w.heard))
    }

    /// Suspects the nodes silent for longer than `suspect_after` at `now` and returns those
    /// it did not suspect before; the first node silent for longer than the limit is lost.
    pub fn check(&mut self, now: Instant) -> Result<Vec<usize>, Lost> {
        let clock = self.clock(now);
        let mut newly = Vec::new();
        for (node, watch) in self.nodes.iter_mut().enumerate() {
            let silent = clock.saturating_sub(watch.heard);
            if silent > self.limit {
                return Err(Lost { node, silent });
            }
            if silent > self.suspect_after && !watch.suspected {
                watch.suspected = true;
                newly.push(node);
            }
        }
        Ok(newly)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const S: Duration = Duration::from_secs(1);

    #[test]
    fn silence_counts_only_while_rank_0_listens_and_adds_up_over_the_frames() {
        let t0 = Instant::now();
        let mut d = FailureDetector::new(2, S, 5 * S);
        // Frame 1: both nodes heard, then node 1 falls silent.
        d.listen(t0);
        d.heard(0, t0 + S / 2);
        d.heard(1, t0 + S / 2);
        d.heard(0, t0 + S);
        d.pause(t0 + S);
        // Rank 0 writes the frame for a minute: nobody is suspected for that.
        d.listen(t0 + 61 * S);
        assert_eq!(d.check(t0 + 61 * S), Ok(vec![]));
        assert_eq!(d.silence(1, t0 + 61 * S), S / 2);
        // Half a second more of listening: node 1 is suspected, once.
        assert_eq!(d.check(t0 + 61 * S + S / 2 + S / 10), Ok(vec![1]));
        assert!(d.is_suspected(1) && !d.is_suspected(0));
        d.heard(0, t0 + 62 * S);
        assert_eq!(d.check(t0 + 62 * S), Ok(vec![]));
        d.pause(t0 + 62 * S);
        // Each frame short, the silence adds up: lost after 5 s of listening.
        for k in 0..3 {
            let start = t0 + (100 + 10 * k) * S;
            d.listen(start);
            d.heard(0, start + S);
            assert!(d.check(start + S).is_ok(), "frame {k}");
            d.pause(start + S);
        }
        d.listen(t0 + 200 * S);
        let lost = d.check(t0 + 201 * S).unwrap_err();
        assert_eq!(lost, Lost { node: 1, silent: 5 * S + S / 2 });
    }

    #[test]
    fn a_suspected_node_heard_from_is_trusted_again() {
        let t0 = Instant::now();
        let mut d = FailureDetector::new(1, S, 5 * S);
        d.listen(t0);
        assert_eq!(d.check(t0 + 2 * S), Ok(vec![0]));
        assert!(d.heard(0, t0 + 3 * S), "it was suspected");
        assert!(!d.is_suspected(0));
        assert!(!d.heard(0, t0 + 3 * S), "it is trusted");
        assert_eq!(d.check(t0 + 7 * S), Ok(vec![0]), "silent 4 s since it came back: suspected, not lost");
        assert_eq!(d.check(t0 + 7 * S), Ok(vec![]), "suspected once");
    }
}
