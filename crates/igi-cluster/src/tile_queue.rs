//! [`TileQueue`]: which tile goes to which node next, for one frame (paper 2.1: tiles on
//! demand balance the load, since tiles cost differently and nodes differ).
//!
//! Tiles go out in tile order. A node that falls silent has its tiles withdrawn: those no other
//! node holds go out again first, so the others carry on at once. Once no tile is waiting, a
//! node with room gets a copy of a tile that another node has held past the deadline (a
//! straggler or a node that is slowing down). Whichever copy comes back first counts, from
//! whichever node (every node renders a tile to the same bytes), so a slow node delays a frame
//! by at most a deadline.
//! Pure bookkeeping with the time passed in, so it is tested without clocks or threads.

use std::collections::{HashMap, VecDeque};
use std::time::{Duration, Instant};

/// A copy of a tile handed out and not yet back.
#[derive(Clone, Copy, Debug)]
struct Loan {
    node: usize,
    since: Instant,
    /// Not to be copied (again): a copy of this loan went to another node, or it is a copy.
    copied: bool,
}

/// The tiles of one frame: handed out, back, or waiting. Every operation a message triggers
/// costs O(1) (plus the copies of one tile), so rank 0 keeps up with many nodes; only the
/// search for an overdue tile, once no tile is waiting, and withdrawing a silent node's
/// tiles look at every loan.
#[derive(Debug)]
pub struct TileQueue {
    total: u32,
    /// Tiles below this were handed out at least once.
    next: u32,
    remaining: u32,
    /// Tiles withdrawn from a silent node that no other node holds, oldest first.
    withdrawn: VecDeque<u32>,
    /// Tiles back.
    done: Vec<bool>,
    /// Loans by tile.
    loans: HashMap<u32, Vec<Loan>>,
    /// Loans by node.
    held: HashMap<usize, usize>,
}

impl TileQueue {
    /// A frame of `total` tiles, none handed out.
    pub fn new(total: u32) -> Self {
        Self {
            total,
            next: 0,
            remaining: total,
            withdrawn: VecDeque::new(),
            done: vec![false; total as usize],
            loans: HashMap::new(),
            held: HashMap::new(),
        }
    }

    /// True once every tile is back.
    pub fn is_complete(&self) -> bool {
        self.remaining == 0
    }

    /// Tiles waiting for a node: never handed out, or withdrawn from a silent node.
    pub fn waiting(&self) -> u32 {
        self.total - self.next + self.withdrawn.len() as u32
    }

    /// Tiles node `node` holds now.
    pub fn held_by(&self, node: usize) -> usize {
        self.held.get(&node).copied().unwrap_or(0)
    }

    /// The next tile for `node` at time `now`: a withdrawn tile, else the next fresh one, else
    /// a copy of the oldest tile another node has held longer than `deadline`. `None` if there
    /// is nothing to give.
    pub fn take(&mut self, node: usize, now: Instant, deadline: Duration) -> Option<u32> {
        let (tile, copy) = if let Some(tile) = self.withdrawn.pop_front() {
            (tile, false)
        } else if self.next < self.total {
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
        self.loans.entry(tile).or_default().push(Loan { node, since: now, copied: copy });
        *self.held.entry(node).or_default() += 1;
        Some(tile)
    }

    /// Records tile `tile` back. True if it is the first copy back (use its pixels); false for
    /// a late copy, a tile not handed out yet, or an index out of range. The node that sent it
    /// need not hold it any more: a silent node that comes back may return a tile withdrawn
    /// from it, and its pixels are as good as any other node's.
    pub fn complete(&mut self, tile: u32) -> bool {
        if tile >= self.next || self.done[tile as usize] {
            return false;
        }
        match self.loans.remove(&tile) {
            Some(copies) => copies.into_iter().for_each(|copy| self.release(copy.node)),
            None => self.withdrawn.retain(|&t| t != tile),
        }
        self.done[tile as usize] = true;
        self.remaining -= 1;
        true
    }

    /// Takes back every tile `node` holds (it fell silent): the ones no other node holds wait
    /// for the next nodes with room, before any fresh tile; the others may be copied again.
    /// Returns how many tiles it held.
    pub fn withdraw(&mut self, node: usize) -> usize {
        let mut orphans = Vec::new();
        for (&tile, copies) in &mut self.loans {
            let before = copies.len();
            copies.retain(|l| l.node != node);
            if copies.len() < before {
                copies.iter_mut().for_each(|l| l.copied = false);
                if copies.is_empty() {
                    orphans.push(tile);
                }
            }
        }
        orphans.sort_unstable();
        for tile in &orphans {
            self.loans.remove(tile);
        }
        self.withdrawn.extend(orphans);
        self.held.remove(&node).unwrap_or(0)
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
        assert!(q.complete(1));
        assert_eq!(q.take(2, t0 + DEADLINE / 2, DEADLINE), None, "nothing overdue yet");
        // Node 1 stalls: node 2 gets a copy of its oldest tile, then of the next.
        let late = t0 + 2 * DEADLINE;
        assert_eq!(q.take(2, late, DEADLINE), Some(0));
        assert_eq!(q.take(2, late, DEADLINE), Some(2));
        assert_eq!(q.take(2, late, DEADLINE), None, "each tile is copied once");
        assert!(q.complete(0));
        assert_eq!(q.held_by(1), 1, "the stalled node's copy of tile 0 is void");
        assert!(!q.complete(0), "the stalled node's copy is late and void");
        assert!(!q.is_complete());
        assert!(q.complete(2));
        assert!(q.is_complete());
    }

    #[test]
    fn a_node_never_gets_a_copy_of_its_own_tile_and_unknown_tiles_are_ignored() {
        let t0 = Instant::now();
        let mut q = TileQueue::new(2);
        assert_eq!(q.take(1, t0, DEADLINE), Some(0));
        assert_eq!(q.take(1, t0, DEADLINE), Some(1));
        assert!(q.complete(1));
        assert_eq!(q.take(1, t0 + 5 * DEADLINE, DEADLINE), None);
        assert!(!q.complete(7), "out of range");
        assert!(!q.complete(1), "back already");
        assert!(q.complete(0));
        assert_eq!(q.held_by(1), 0);
        assert!(!TileQueue::new(2).complete(0), "never handed out");
    }

    #[test]
    fn a_silent_nodes_tiles_go_out_again_first_without_waiting_for_the_deadline() {
        let t0 = Instant::now();
        let mut q = TileQueue::new(6);
        for (node, tile) in [(1, 0), (2, 1), (1, 2), (2, 3)] {
            assert_eq!(q.take(node, t0, DEADLINE), Some(tile));
        }
        assert_eq!(q.waiting(), 2);
        // Node 2 falls silent: its tiles 1 and 3 wait again, before the fresh tiles 4 and 5.
        assert_eq!(q.withdraw(2), 2);
        assert_eq!((q.held_by(2), q.waiting()), (0, 4));
        assert_eq!(q.take(1, t0, DEADLINE), Some(1));
        assert_eq!(q.take(1, t0, DEADLINE), Some(3));
        assert_eq!(q.take(1, t0, DEADLINE), Some(4));
        // Node 2 comes back and returns the tile 3 it was given first: it counts, once.
        assert!(q.complete(3));
        assert!(!q.complete(3));
        assert_eq!(q.held_by(1), 4, "node 1 holds 0, 1, 2 and 4");
        [0, 1, 2, 4].into_iter().for_each(|t| assert!(q.complete(t)));
        assert_eq!(q.take(2, t0, DEADLINE), Some(5));
        assert!(q.complete(5));
        assert!(q.is_complete());
    }

    #[test]
    fn a_withdrawn_tile_back_before_it_went_out_again_is_not_handed_out() {
        let t0 = Instant::now();
        let mut q = TileQueue::new(2);
        assert_eq!(q.take(1, t0, DEADLINE), Some(0));
        assert_eq!(q.withdraw(1), 1);
        assert!(q.complete(0), "node 1 came back with it");
        assert_eq!(q.waiting(), 1);
        assert_eq!(q.take(2, t0, DEADLINE), Some(1));
        assert_eq!(q.take(2, t0, DEADLINE), None);
    }

    #[test]
    fn a_tile_whose_copy_was_withdrawn_may_be_copied_again() {
        let t0 = Instant::now();
        let mut q = TileQueue::new(1);
        assert_eq!(q.take(1, t0, DEADLINE), Some(0));
        let late = t0 + 2 * DEADLINE;
        assert_eq!(q.take(2, late, DEADLINE), Some(0), "a copy of node 1's overdue tile");
        assert_eq!(q.take(3, late, DEADLINE), None, "copied once");
        assert_eq!(q.withdraw(2), 1);
        assert_eq!(q.waiting(), 0, "node 1 still holds it");
        assert_eq!(q.take(3, late, DEADLINE), Some(0), "the copy went silent: another copy");
    }
}
