//! [`TileQueue`]: which tile goes to which node next, for one frame (paper 2.1: tiles on
//! demand balance the load, since tiles cost differently and nodes differ).
//!
//! Fresh tiles go out in tile order. Once none is left, a node with room gets a copy of a tile
//! that another node has held past the deadline (a straggler or a node that is slowing down);
//! whichever copy comes back first counts, so a slow node delays a frame by at most a deadline.
//! Pure bookkeeping with the time passed in, so it is tested without clocks or threads.

use std::time::{Duration, Instant};

/// A tile handed out and not yet back.
#[derive(Clone, Copy, Debug)]
struct Loan {
    tile: u32,
    node: usize,
    since: Instant,
    /// A copy was handed to another node already.
    copied: bool,
}

/// The tiles of one frame: handed out, back, or waiting.
#[derive(Debug)]
pub struct TileQueue {
    total: u32,
    next: u32,
    done: Vec<bool>,
    remaining: u32,
    loans: Vec<Loan>,
}

impl TileQueue {
    /// A frame of `total` tiles, none handed out.
    pub fn new(total: u32) -> Self {
        Self { total, next: 0, done: vec![false; total as usize], remaining: total, loans: Vec::new() }
    }

    /// True once every tile is back.
    pub fn is_complete(&self) -> bool {
        self.remaining == 0
    }

    /// Tiles not handed out yet.
    pub fn fresh(&self) -> u32 {
        self.total - self.next
    }

    /// Tiles node `node` holds now.
    pub fn held_by(&self, node: usize) -> usize {
        self.loans.iter().filter(|l| l.node == node).count()
    }

    /// The next tile for `node` at time `now`: the next fresh tile, else a copy of the oldest
    /// tile another node has held longer than `deadline`. `None` if there is nothing to give.
    pub fn take(&mut self, node: usize, now: Instant, deadline: Duration) -> Option<u32> {
        if self.next < self.total {
            let tile = self.next;
            self.next += 1;
            self.loans.push(Loan { tile, node, since: now, copied: false });
            return Some(tile);
        }
        let held_by_node = |tile: u32, loans: &[Loan]| loans.iter().any(|l| l.tile == tile && l.node == node);
        let overdue = self
            .loans
            .iter()
            .enumerate()
            .filter(|(_, l)| !l.copied && now.saturating_duration_since(l.since) > deadline)
            .filter(|(_, l)| !held_by_node(l.tile, &self.loans))
            .min_by_key(|(_, l)| l.since)
            .map(|(i, _)| i)?;
        self.loans[overdue].copied = true;
        let tile = self.loans[overdue].tile;
        self.loans.push(Loan { tile, node, since: now, copied: true });
        Some(tile)
    }

    /// Records tile `tile` back from `node`. True if it is the first copy back (use its
    /// pixels); false for a late copy, a tile of no loan, or an index out of range.
    pub fn complete(&mut self, tile: u32, node: usize) -> bool {
        let Some(position) = self.loans.iter().position(|l| l.tile == tile && l.node == node) else {
            return false;
        };
        self.loans.swap_remove(position);
        let first = !std::mem::replace(&mut self.done[tile as usize], true);
        if first {
            self.remaining -= 1;
            // The other copies are void: their nodes may take new work.
            self.loans.retain(|l| l.tile != tile);
        }
        first
    }

    /// The longest any node has held a tile it has not returned, at `now`.
    pub fn oldest_loan(&self, now: Instant) -> Option<(usize, Duration)> {
        self.loans
            .iter()
            .map(|l| (l.node, now.saturating_duration_since(l.since)))
            .max_by_key(|&(_, held)| held)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DEADLINE: Duration = Duration::from_secs(1);

    #[test]
    fn fresh_tiles_in_order_then_nothing_until_a_deadline_passes() {
        let t0 = Instant::now();
        let mut q = TileQueue::new(3);
        assert_eq!(q.take(1, t0, DEADLINE), Some(0));
        assert_eq!(q.take(2, t0, DEADLINE), Some(1));
        assert_eq!(q.take(1, t0, DEADLINE), Some(2));
        assert_eq!(q.held_by(1), 2);
        assert!(q.complete(1, 2));
        assert_eq!(q.take(2, t0 + DEADLINE / 2, DEADLINE), None, "nothing overdue yet");
        // Node 1 stalls: node 2 gets a copy of its oldest tile, then of the next.
        let late = t0 + 2 * DEADLINE;
        assert_eq!(q.take(2, late, DEADLINE), Some(0));
        assert_eq!(q.take(2, late, DEADLINE), Some(2));
        assert_eq!(q.take(2, late, DEADLINE), None, "each tile is copied once");
        assert!(q.complete(0, 2));
        assert!(!q.complete(0, 1), "the stalled node's copy is late and void");
        assert!(!q.is_complete());
        assert!(q.complete(2, 2));
        assert!(q.is_complete());
    }

    #[test]
    fn a_node_never_gets_a_copy_of_its_own_tile_and_unknown_tiles_are_ignored() {
        let t0 = Instant::now();
        let mut q = TileQueue::new(1);
        assert_eq!(q.take(1, t0, DEADLINE), Some(0));
        assert_eq!(q.take(1, t0 + 5 * DEADLINE, DEADLINE), None);
        assert!(!q.complete(0, 3), "node 3 was never given tile 0");
        assert!(!q.complete(7, 1));
        assert_eq!(q.oldest_loan(t0 + DEADLINE), Some((1, DEADLINE)));
        assert!(q.complete(0, 1));
        assert_eq!(q.oldest_loan(t0), None);
    }
}
