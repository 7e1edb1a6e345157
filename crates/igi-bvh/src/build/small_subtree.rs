//! Small subtrees: a node of at most [`SMALL_NODE_MAX`] primitives is built in one go with exact
//! SAH object splits, the sweep over every position of the primitives' centroid order on each
//! axis (MacDonald & Booth 1990), as in the full-sweep reference builder. The three orders are
//! sorted once for the whole subtree and split in step with it, and the primitives move into
//! leaf order once at the end. At this size that is both faster than binning (no bins to clear
//! and sweep per node; on the conference room a limit of 12 builds 5 % slower, 24 no faster)
//! and better: K bins can only approximate the best of the n - 1 object splits.

use super::box3a::Box3A;
use super::node_region::NodeRegion;
use super::prim_box::PrimBox;
use super::{BuildParams, levels_to_split};
use crate::node::Node;
use crate::traverse::TRAVERSAL_STACK_SIZE;

/// The largest node, in primitives, built as a small subtree.
pub(crate) const SMALL_NODE_MAX: usize = 16;

/// Builds the subtree over a node of 1 ..= [`SMALL_NODE_MAX`] primitives at `depth` (the root
/// has depth 1), whose boxes' union is `bounds` and whose leaf-order range starts at `first`.
/// Returns its root and writes the other nodes to `nodes` depth first; `boxes` and `ids` are
/// reordered into leaf order. Leaf, split and depth rules are those of the binned builder.
pub(crate) fn build_small_subtree(
    params: &BuildParams,
    boxes: &mut [PrimBox],
    ids: &mut [u32],
    first: u32,
    depth: usize,
    bounds: Box3A,
    nodes: &mut NodeRegion,
) -> Node {
    let n = boxes.len();
    debug_assert!((1..=SMALL_NODE_MAX).contains(&n));
    let mut subtree = SmallSubtree { params, boxes, orders: centroid_orders(boxes), first };
    let root = subtree.node(0, n, depth, bounds, nodes);

    // Leaves own their ranges of positions in order, so the first order is the leaf order.
    let leaf_order = subtree.orders[0];
    let mut sorted_boxes = [PrimBox::default(); SMALL_NODE_MAX];
    let mut sorted_ids = [0; SMALL_NODE_MAX];
    for (i, &p) in leaf_order[..n].iter().enumerate() {
        sorted_boxes[i] = boxes[p as usize];
        sorted_ids[i] = ids[p as usize];
    }
    boxes.copy_from_slice(&sorted_boxes[..n]);
    ids.copy_from_slice(&sorted_ids[..n]);
    root
}

/// The primitives' local indices sorted by centroid on each axis. A rank sort: a primitive's
/// position is the number of smaller keys, counted branch-free over fixed-size arrays. Keys are
/// the centroid coordinate as an integer that orders like `f32::total_cmp`, with the local index
/// in the low bits, so that all keys differ and equal centroids keep their input order.
fn centroid_orders(boxes: &[PrimBox]) -> [[u8; SMALL_NODE_MAX]; 3] {
    let mut keys = [[i64::MAX; SMALL_NODE_MAX]; 3];
    for (i, b) in boxes.iter().enumerate() {
        let c = b.centroid();
        for (axis, axis_keys) in keys.iter_mut().enumerate() {
            let bits = c[axis].to_bits() as i32;
            let ordered = bits ^ (((bits >> 31) as u32) >> 1) as i32;
            axis_keys[i] = i64::from(ordered) << 8 | i as i64;
        }
    }
    keys.map(|axis_keys| {
        let mut order = [0; SMALL_NODE_MAX];
        for (i, &key) in axis_keys[..boxes.len()].iter().enumerate() {
            let smaller =
                axis_keys.iter().enumerate().fold(0u32, |m, (j, &other)| m | u32::from(other < key) << j);
            order[smaller.count_ones() as usize % SMALL_NODE_MAX] = i as u8;
        }
        order
    })
}

/// An object split: the first `left_count` primitives of the node's range of `orders[axis]`
/// go left.
#[derive(Clone, Copy)]
struct Split {
    axis: usize,
    left_count: usize,
    /// `A(L) N(L) + A(R) N(R)` with half areas.
    area_count_sum: f32,
}

/// A small subtree under construction. Each node owns a range of positions, holding the same
/// primitives in all three orders.
struct SmallSubtree<'a> {
    params: &'a BuildParams,
    boxes: &'a [PrimBox],
    /// Local primitive indices sorted by centroid on each axis, within each node's range.
    orders: [[u8; SMALL_NODE_MAX]; 3],
    /// Leaf-order index of the subtree's first primitive.
    first: u32,
}

impl SmallSubtree<'_> {
    /// Builds the subtree over the positions `lo .. hi` at `depth` with box `bounds`.
    fn node(&mut self, lo: usize, hi: usize, depth: usize, bounds: Box3A, nodes: &mut NodeRegion) -> Node {
        let n = hi - lo;
        let max_leaf = self.params.max_leaf_size as usize;
        let leaf_allowed = n <= max_leaf;
        let area = bounds.half_area();
        // Every split costs at least `C_trav A + C_isect Σ A(prim)`: each child's area is at
        // least that of each of its primitives. A leaf that beats this bound needs no search.
        let prim_area_sum =
            || self.orders[0][lo..hi].iter().map(|&p| self.boxes[p as usize].half_area()).sum();
        if n == 1 || leaf_allowed && self.params.leaf_is_cheaper(n, area, prim_area_sum()) {
            return self.leaf(lo, hi, bounds);
        }

        let mut split = self.best_split(lo, hi);
        if leaf_allowed && self.params.leaf_is_cheaper(n, area, split.area_count_sum) {
            return self.leaf(lo, hi, bounds);
        }
        let larger = split.left_count.max(n - split.left_count);
        if depth + 1 + levels_to_split(larger, max_leaf) > TRAVERSAL_STACK_SIZE {
            if leaf_allowed {
                return self.leaf(lo, hi, bounds);
            }
            split.left_count = n / 2;
        }

        self.partition(lo, hi, &split);
        let mid = lo + split.left_count;
        let left_bounds = self.union(split.axis, lo, mid);
        let right_bounds = self.union(split.axis, mid, hi);
        let pair = nodes.push_pair();
        let left = self.node(lo, mid, depth + 1, left_bounds, nodes);
        nodes.set(pair, left);
        let right = self.node(mid, hi, depth + 1, right_bounds, nodes);
        nodes.set(pair + 1, right);
        bounds.inner(pair as u32)
    }

    /// A leaf over the positions `lo .. hi`.
    fn leaf(&self, lo: usize, hi: usize, bounds: Box3A) -> Node {
        bounds.leaf(self.first + lo as u32, (hi - lo) as u32)
    }

    /// The split with the lowest `A(L) N(L) + A(R) N(R)` over all positions of all three axes
    /// (ties to the lowest axis, then the leftmost position).
    fn best_split(&self, lo: usize, hi: usize) -> Split {
        let n = hi - lo;
        let mut best = Split { axis: 0, left_count: 0, area_count_sum: f32::INFINITY };
        for (axis, order) in self.orders.iter().enumerate() {
            let order = &order[lo..hi];
            let mut right_costs = [0.0f32; SMALL_NODE_MAX];
            let mut right = Box3A::EMPTY;
            for i in (1..n).rev() {
                right = right.union(self.boxes[order[i] as usize].bounds());
                right_costs[i] = right.half_area() * (n - i) as f32;
            }
            let mut left = Box3A::EMPTY;
            for i in 1..n {
                left = left.union(self.boxes[order[i - 1] as usize].bounds());
                let cost = left.half_area() * i as f32 + right_costs[i];
                if best.left_count == 0 || cost < best.area_count_sum {
                    best = Split { axis, left_count: i, area_count_sum: cost };
                }
            }
        }
        best
    }

    /// Splits the positions `lo .. hi` of the two other orders like the split axis's order,
    /// keeping both sides sorted (a stable, branch-free partition).
    fn partition(&mut self, lo: usize, hi: usize, split: &Split) {
        let goes_left =
            self.orders[split.axis][lo..lo + split.left_count].iter().fold(0u32, |m, &p| m | 1 << p);
        for axis in (0..3).filter(|&a| a != split.axis) {
            let order = &mut self.orders[axis][lo..hi];
            let (mut left, mut right) = ([0u8; SMALL_NODE_MAX], [0u8; SMALL_NODE_MAX]);
            let (mut l, mut r) = (0, 0);
            for &p in order.iter() {
                let is_left = (goes_left >> p & 1) as usize;
                left[l] = p;
                right[r] = p;
                l += is_left;
                r += 1 - is_left;
            }
            for (k, p) in order.iter_mut().enumerate() {
                *p = if k < l { left[k] } else { right[k - l] };
            }
        }
    }

    /// The union of the boxes at the positions `lo .. hi` of `orders[axis]`.
    fn union(&self, axis: usize, lo: usize, hi: usize) -> Box3A {
        self.orders[axis][lo..hi]
            .iter()
            .fold(Box3A::EMPTY, |acc, &p| acc.union(self.boxes[p as usize].bounds()))
    }
}
