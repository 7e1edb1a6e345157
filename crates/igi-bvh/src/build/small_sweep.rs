//! The exact SAH split of a small node: its primitives sorted by centroid on each axis and every
//! position swept, as in the full-sweep builder. Up to 16 primitives this is as fast as binning
//! (no bins to clear and sweep; measured on the conference room, larger limits get slower) and
//! better: binning with K bins can only approximate the best of the n - 1 object splits.

use super::box3a::Box3A;
use super::prim_box::PrimBox;

/// The largest node, in primitives, handled by [`best_sorted_split`].
pub(crate) const SMALL_NODE_MAX: usize = 16;

/// An object split of a small node: the primitives in `order[..left_count]` go left.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SortedSplit {
    /// The node's primitives (indices into its range) sorted by centroid on the split axis.
    pub order: [u8; SMALL_NODE_MAX],
    /// Number of primitives going left.
    pub left_count: usize,
    /// `A(L) N(L) + A(R) N(R)` with half areas.
    pub area_count_sum: f32,
}

/// The object split with the lowest `A(L) N(L) + A(R) N(R)` of a node of 2 ..=
/// [`SMALL_NODE_MAX`] primitives (ties to the lowest axis, then the leftmost position).
pub(crate) fn best_sorted_split(boxes: &[PrimBox]) -> SortedSplit {
    let n = boxes.len();
    debug_assert!((2..=SMALL_NODE_MAX).contains(&n));
    // Sort keys: the centroid coordinate as an integer that orders like `f32::total_cmp`, with
    // the primitive's index in the low bits, so that all keys differ and equal centroids keep
    // their order. Padding sorts last.
    let mut keys = [[i64::MAX; SMALL_NODE_MAX]; 3];
    for (i, b) in boxes.iter().enumerate() {
        let c = b.centroid();
        for (axis, axis_keys) in keys.iter_mut().enumerate() {
            let bits = c[axis].to_bits() as i32;
            let ordered = bits ^ (((bits >> 31) as u32) >> 1) as i32;
            axis_keys[i] = i64::from(ordered) << 8 | i as i64;
        }
    }

    let mut best = SortedSplit { order: [0; SMALL_NODE_MAX], left_count: 0, area_count_sum: f32::INFINITY };
    for axis_keys in &keys {
        // Rank sort: a primitive's position is the number of smaller keys. Branch-free, and
        // vectorised over the fixed-size key array.
        let mut order = [0u8; SMALL_NODE_MAX];
        for (i, &key) in axis_keys[..n].iter().enumerate() {
            let rank: u32 = axis_keys.iter().map(|&other| u32::from(other < key)).sum();
            order[rank as usize % SMALL_NODE_MAX] = i as u8;
        }

        let mut right_costs = [0.0f32; SMALL_NODE_MAX];
        let mut right = Box3A::EMPTY;
        for i in (1..n).rev() {
            right = right.union(boxes[order[i] as usize].bounds());
            right_costs[i] = right.half_area() * (n - i) as f32;
        }
        let mut left = Box3A::EMPTY;
        for i in 1..n {
            left = left.union(boxes[order[i - 1] as usize].bounds());
            let cost = left.half_area() * i as f32 + right_costs[i];
            if best.left_count == 0 || cost < best.area_count_sum {
                best = SortedSplit { order, left_count: i, area_count_sum: cost };
            }
        }
    }
    best
}
