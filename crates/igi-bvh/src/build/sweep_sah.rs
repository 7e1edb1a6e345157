//! The quality reference: a full-sweep SAH builder that evaluates every object split, i.e. every
//! position in the primitives' centroid order on each of the three axes (MacDonald & Booth 1990;
//! the "full SAH" sweep that Wald 2007 compares binning against). It is single threaded and
//! costs O(n log n) for the initial sorts plus O(n) per tree level; use it to measure the
//! quality of [`build_binned_sah`](super::build_binned_sah), not to render.

use glam::Vec3A;

use super::box3a::Box3A;
use super::{BuildParams, levels_to_split, prim_count};
use crate::aabb::Aabb;
use crate::bvh::Bvh;
use crate::node::Node;
use crate::traverse::TRAVERSAL_STACK_SIZE;

/// Builds a BVH over primitives given by their bounding boxes with the full-sweep SAH.
///
/// Same contract, layout and leaf rules as [`build_binned_sah`](super::build_binned_sah), so
/// the two builders' [`Bvh::sah_cost`] compare directly. `bins` is not used.
///
/// # Panics
/// If `params` is out of range (see [`BuildParams`]) or there are 2³¹ primitives or more.
pub fn build_sweep_sah(prim_bounds: &[Aabb], params: &BuildParams) -> Bvh {
    let Some(n) = prim_count(prim_bounds.len(), params) else { return Bvh::default() };

    let boxes: Vec<Box3A> = prim_bounds.iter().map(Box3A::from).collect();
    let centroids: Vec<Vec3A> = boxes.iter().map(Box3A::centroid).collect();
    // Primitive indices sorted by centroid along each axis (ties by index, for a total order).
    let orders = [0, 1, 2].map(|axis| {
        let mut order: Vec<u32> = (0..n as u32).collect();
        order.sort_unstable_by(|&a, &b| {
            let (ca, cb) = (centroids[a as usize][axis], centroids[b as usize][axis]);
            ca.total_cmp(&cb).then(a.cmp(&b))
        });
        order
    });

    let mut builder = SweepBuilder {
        params: *params,
        boxes,
        orders,
        goes_left: vec![false; n],
        right_costs: vec![0.0; n],
        scratch: Vec::with_capacity(n),
        nodes: vec![Node::default()],
    };
    let bounds = Box3A::union_of(&builder.boxes);
    builder.nodes[0] = builder.subtree(0, n, 1, bounds);
    let [prim_order, _, _] = builder.orders;
    let mut nodes = builder.nodes;
    nodes.shrink_to_fit();
    Bvh { nodes, prim_order }
}

/// A split position in one axis's centroid order.
#[derive(Clone, Copy)]
struct Split {
    axis: usize,
    /// Number of primitives going left: the first `left_count` in the axis's order.
    left_count: usize,
    /// `A(L) N(L) + A(R) N(R)` with half areas.
    area_count_sum: f32,
}

/// The builder's state: boxes, the three centroid orders (each node owns the same range in all
/// three, holding the same primitives), scratch space, and the nodes built so far.
struct SweepBuilder {
    params: BuildParams,
    boxes: Vec<Box3A>,
    orders: [Vec<u32>; 3],
    goes_left: Vec<bool>,
    right_costs: Vec<f32>,
    scratch: Vec<u32>,
    nodes: Vec<Node>,
}

impl SweepBuilder {
    /// Builds the subtree at `depth` (the root has depth 1) over
    /// `orders[·][first .. first + count]`, whose boxes' union is `bounds`, and returns its root;
    /// the other nodes are pushed depth first. Leaf, split and depth rules are those of the
    /// binned builder, with the object median of the best axis as the depth-limited split.
    fn subtree(&mut self, first: usize, count: usize, depth: usize, bounds: Box3A) -> Node {
        if count == 1 {
            return bounds.leaf(first as u32, 1);
        }
        let max_leaf = self.params.max_leaf_size as usize;
        let leaf_allowed = count <= max_leaf;
        let mut split = self.best_split(first, count);
        if leaf_allowed && self.params.leaf_is_cheaper(count, bounds.half_area(), split.area_count_sum) {
            return bounds.leaf(first as u32, count as u32);
        }
        let larger = split.left_count.max(count - split.left_count);
        if depth + 1 + levels_to_split(larger, max_leaf) > TRAVERSAL_STACK_SIZE {
            if leaf_allowed {
                return bounds.leaf(first as u32, count as u32);
            }
            split.left_count = count / 2;
        }

        self.partition(first, count, &split);
        let mid = first + split.left_count;
        let order = &self.orders[split.axis];
        let left_bounds = self.union(&order[first..mid]);
        let right_bounds = self.union(&order[mid..first + count]);

        let pair = self.nodes.len();
        self.nodes.extend([Node::default(); 2]);
        self.nodes[pair] = self.subtree(first, split.left_count, depth + 1, left_bounds);
        self.nodes[pair + 1] = self.subtree(mid, count - split.left_count, depth + 1, right_bounds);
        bounds.inner(pair as u32)
    }

    /// The split with the lowest `A(L) N(L) + A(R) N(R)` over all `count - 1` positions of all
    /// three axes (ties to the lowest axis, then the leftmost position).
    fn best_split(&mut self, first: usize, count: usize) -> Split {
        let mut best = Split { axis: 0, left_count: count / 2, area_count_sum: f32::INFINITY };
        for axis in 0..3 {
            let order = &self.orders[axis][first..first + count];
            let mut right = Box3A::EMPTY;
            for i in (1..count).rev() {
                right = right.union(self.boxes[order[i] as usize]);
                self.right_costs[i] = right.half_area() * (count - i) as f32;
            }
            let mut left = Box3A::EMPTY;
            for i in 1..count {
                left = left.union(self.boxes[order[i - 1] as usize]);
                let cost = left.half_area() * i as f32 + self.right_costs[i];
                if cost < best.area_count_sum {
                    best = Split { axis, left_count: i, area_count_sum: cost };
                }
            }
        }
        best
    }

    /// Reorders the node's range in the two other axes' orders so that the primitives going
    /// left come first, each side keeping its sorted order (a stable partition).
    fn partition(&mut self, first: usize, count: usize, split: &Split) {
        let range = first..first + count;
        let (left, right) = self.orders[split.axis][range.clone()].split_at(split.left_count);
        for &id in left {
            self.goes_left[id as usize] = true;
        }
        for &id in right {
            self.goes_left[id as usize] = false;
        }
        for axis in (0..3).filter(|&a| a != split.axis) {
            let order = &mut self.orders[axis][range.clone()];
            self.scratch.clear();
            self.scratch.extend(order.iter().filter(|&&id| !self.goes_left[id as usize]));
            let mut next = 0;
            for i in 0..count {
                let id = order[i];
                if self.goes_left[id as usize] {
                    order[next] = id;
                    next += 1;
                }
            }
            order[next..].copy_from_slice(&self.scratch);
        }
    }

    /// The union of the boxes of the primitives `ids`.
    fn union(&self, ids: &[u32]) -> Box3A {
        ids.iter().fold(Box3A::EMPTY, |acc, &id| acc.union(self.boxes[id as usize]))
    }
}
