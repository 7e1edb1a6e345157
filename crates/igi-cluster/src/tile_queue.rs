//! [`TileQueue`]: which tile goes to which node next, for one frame (paper 2.1: tiles on
//! demand balance the load, since tiles cost differently and nodes differ).
//!
//! Fresh tiles go out in tile order. Once none is left, a node with room gets a copy of a tile
//! that another node has held past the deadline (a straggler or a node that is slowing down);
//! whichever copy comes back first counts, so a slow node delays a frame by at most a deadline.
//! Pure bookkeeping with the time passed in, so it is tested without clocks or threads.

use std::collections::HashMap;
use std::time::{Duration, Instant};

/// A copy of a tile handed out and not yet back.
#[derive(Clone, Copy, Debug)]
struct Loan {
    node: usize,
    since: Instant,
    /// A copy of this loan was handed to another node already.
    copied: bool,
}

/// The tiles of one frame: handed out, back, or waiting. Every operation a message triggers
/// costs O(1) (plus the copies of one tile), so rank 0 keeps up with many nodes; only the
/// search for an overdue tile, once no fresh tile is left, looks at every loan.
#[derive(Debug)]
pub struct TileQueue {
    total: u32,
    next: u32,
    remaining: u32,
    /// Loans by tile.
    loans: HashMap<u32, Vec<Loan>>,
    /// Loans by node.
    held: HashMap<usize, usize>,
}

impl TileQueue {
    /// A frame of `total` tiles, none handed out.
    pub fn new(total: u32) -> Self {
        Self { total, next: 0, remaining: total, loans: HashMap::new(), held: HashMap::new() }
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
        self.held.get(&node).copied().unwrap_or(0)
    }

    /// The next tile for `node` at time `now`: the next fresh tile, else a copy of the oldest
    /// tile another node has held longer than `deadline`. `None` if there is nothing to give.
    pub fn take(&mut self, node: usize, now: Instant, deadline: Duration) -> Option<u32> {
        let (tile, copy) = if self.next < self.total {
            self.next += 1;
            (self.next - 1, false)
        } else {
            let (tile, index) = self
                .loans
                .iter()
                .filter(|(_, copies)| !copies.iter().any(|l| l.node == node))
                .flat_map(|(&tile, copies)| copies.iter().enumerate().map(move |(i, l)| (tile, i, *l)))
                .filter(|(_, _, l)| !l.copied && now.saturating_duration_since(l.since) > deadline)
                .min_by_key(|(tile, _, l)| (l.since, *tile))
                .map(|(tile, i, _)| (tile, i))?;
            self.loans.get_mut(&tile)?[index].copied = true;
            (tile, true)
        };
        // A copy is not copied again.
        self.loans.entry(tile).or_default().push(Loan { node, since: now, copied: copy });
        *self.held.entry(node).or_default() += 1;
        Some(tile)
    }

    /// Records tile `tile` back from `node`. True if it is the first copy back (use its
    /// pixels); false for a late copy, a tile of no loan, or an index out of range. Loans
    /// exist only for tiles not back yet, so the first copy back voids the others.
    pub fn complete(&mut self, tile: u32, node: usize) -> bool {
        if !self.loans.get(&tile).is_some_and(|copies| copies.iter().any(|l| l.node == node)) {
            return false;
        }
        for copy in self.loans.remove(&tile).unwrap_or_default() {
            self.release(copy.node);
        }
        self.remaining -= 1;
        true
    }

    fn release(&mut self, node: usize) {
        if let Some(n) = self.held.get_mut(&node) {
            *n = n.saturating_sub(1);
        }
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
        assert_eq!(q.held_by(1), 1, "the stalled node's copy of tile 0 is void");
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
        assert!(q.complete(0, 1));
        assert_eq!(q.held_by(1), 0);
    }
}
