//! The production builder: binned SAH after Wald 2007, "On fast Construction of SAH-based
//! Bounding Volume Hierarchies", parallel with rayon and deterministic.
//!
//! Primitive boxes are copied once into a compact [`PrimBox`] array with a parallel index array;
//! every node partitions its range of both arrays in place, so a node's primitives are always
//! contiguous and no node allocates. Large nodes bin in parallel chunks, and large subtrees build
//! as parallel `rayon::join` tasks. Neither changes the result: bins merge exactly, and every
//! subtree's nodes are laid out by the tree alone (depth first), never by the order in which
//! tasks finish. The output is identical at any thread count.

use rayon::prelude::*;

use super::bins::{BinMapping, BinSplit, Bins};
use super::box3a::Box3A;
use super::partition::{partition_at_median, partition_at_plane};
use super::prim_box::PrimBox;
use super::small_sweep::{SMALL_NODE_MAX, SortedSplit, best_sorted_split};
use super::{BuildParams, levels_to_split};
use crate::aabb::Aabb;
use crate::bvh::Bvh;
use crate::node::Node;
use crate::traverse::MAX_DEPTH;

/// Nodes with at least this many primitives bin in parallel chunks.
const PARALLEL_BINNING_MIN: usize = 1 << 14;
/// Primitives per chunk of parallel binning and of the initial bounds computation.
const CHUNK: usize = 1 << 12;
/// Nodes with at least this many primitives build their two subtrees as parallel tasks.
const PARALLEL_SUBTREE_MIN: usize = 1 << 12;

/// Builds a BVH over primitives given by their bounding boxes with the binned SAH.
///
/// Primitive `i` is `prim_bounds[i]`; the result's `prim_order` lists these indices in leaf
/// order. Boxes should be finite; empty boxes (of empty meshes, say) are allowed and end up in
/// leaves that no ray reaches. See [`Bvh`] for the layout and its invariants; an empty input
/// gives an empty BVH.
///
/// # Panics
/// If `params` is out of range (see [`BuildParams`]) or there are 2³¹ primitives or more.
pub fn build_binned_sah(prim_bounds: &[Aabb], params: &BuildParams) -> Bvh {
    params.assert_valid();
    let n = prim_bounds.len();
    if n == 0 {
        return Bvh::default();
    }
    assert!(n < 1 << 31, "a BVH holds fewer than 2^31 primitives, got {n}");

    let mut boxes = Vec::with_capacity(n);
    boxes.par_extend(prim_bounds.par_iter().map(PrimBox::from));
    let mut ids: Vec<u32> = (0..n as u32).collect();
    let (bounds, centroid_bounds) = boxes
        .par_chunks(CHUNK)
        .map(|chunk| (PrimBox::union_of(chunk), PrimBox::centroid_bounds_of(chunk)))
        .reduce(|| (Box3A::EMPTY, Box3A::EMPTY), |(b0, c0), (b1, c1)| (b0.union(b1), c0.union(c1)));

    let builder = Builder { params: *params };
    let root = Task { boxes: &mut boxes, ids: &mut ids, first: 0, depth: 1, bounds, centroid_bounds };
    let mut nodes = Vec::with_capacity(node_capacity(n));
    nodes.push(Node::default());
    nodes[0] = builder.subtree(root, &mut nodes);
    nodes.shrink_to_fit();
    Bvh { nodes, prim_order: ids }
}

/// A generous guess of the number of nodes of a subtree over `n` primitives, so that its node
/// array rarely grows. SAH leaves average well above one primitive, so there are far fewer
/// than the worst case of `2n - 1` nodes.
fn node_capacity(n: usize) -> usize {
    n + 1
}

/// The primitives of one node, contiguous in leaf order from `first`: their boxes and input
/// indices, with the node's depth (the root has depth 1) and the bounds of the boxes and of
/// their centroids.
struct Task<'a> {
    boxes: &'a mut [PrimBox],
    ids: &'a mut [u32],
    first: u32,
    depth: usize,
    bounds: Box3A,
    centroid_bounds: Box3A,
}

/// How a node is built.
enum Decision {
    /// A leaf over all of its primitives.
    Leaf,
    /// Split by the SAH.
    Split(Split),
    /// Split at the object median along an axis: when all centroids coincide (no plane
    /// separates them) or when the SAH split could exceed [`MAX_DEPTH`].
    Median(usize),
}

/// The best SAH split of a node.
enum Split {
    /// At a bin plane, for large nodes.
    Plane(BinSplit, BinMapping),
    /// In the centroid order on one axis, for small nodes.
    Sorted(SortedSplit),
}

impl Split {
    /// `A(L) N(L) + A(R) N(R)` with half areas.
    fn area_count_sum(&self) -> f32 {
        match self {
            Split::Plane(split, _) => split.area_count_sum,
            Split::Sorted(split) => split.area_count_sum,
        }
    }

    /// Number of primitives going left.
    fn left_count(&self) -> usize {
        match self {
            Split::Plane(split, _) => split.left_count,
            Split::Sorted(split) => split.left_count,
        }
    }
}

/// The builder's shared, read-only state.
struct Builder {
    params: BuildParams,
}

impl Builder {
    /// Builds the subtree over `task` and returns its root node. The other nodes are pushed onto
    /// `nodes` depth first: the root's two children as a pair, then the left child's subtree,
    /// then the right child's. Every index in the returned nodes refers to `nodes`, and children
    /// always come after their parent. Large subtrees build the right child's subtree in a
    /// parallel task into a separate array, appended and re-indexed afterwards: same layout.
    fn subtree(&self, task: Task, nodes: &mut Vec<Node>) -> Node {
        let n = task.boxes.len();
        let bounds = task.bounds;
        let (left, right) = match self.decide(&task) {
            Decision::Leaf => return bounds.leaf(task.first, n as u32),
            Decision::Split(Split::Plane(split, mapping)) => task.split_at_plane(&split, &mapping),
            Decision::Split(Split::Sorted(split)) => task.split_sorted(&split),
            Decision::Median(axis) => task.split_at_median(axis),
        };

        let pair = nodes.len();
        nodes.extend([Node::default(); 2]);
        if n >= PARALLEL_SUBTREE_MIN {
            let (left_root, (right_root, right_nodes)) = rayon::join(
                || self.subtree(left, nodes),
                || {
                    let mut right_nodes = Vec::with_capacity(node_capacity(right.boxes.len()));
                    (self.subtree(right, &mut right_nodes), right_nodes)
                },
            );
            let base = nodes.len() as u32;
            nodes[pair] = left_root;
            nodes[pair + 1] = reindexed(right_root, base);
            nodes.extend(right_nodes.iter().map(|&node| reindexed(node, base)));
        } else {
            nodes[pair] = self.subtree(left, nodes);
            nodes[pair + 1] = self.subtree(right, nodes);
        }
        bounds.inner(pair as u32)
    }

    /// Chooses between a leaf and the best split with the SAH: the exact object split for small
    /// nodes, the best bin plane otherwise. A single primitive is always a leaf; more than
    /// `max_leaf_size` primitives are always split. A split whose larger side could not be
    /// finished within [`MAX_DEPTH`] by halving gives way to a leaf or a median split, so every
    /// node at depth `d` with `n` primitives keeps `d + levels_to_split(n) <= MAX_DEPTH`, which
    /// holds at the root for any `n < 2³¹`. Kept out of line so that the bins live in this
    /// short-lived frame, not in every frame of the recursion.
    #[inline(never)]
    fn decide(&self, task: &Task) -> Decision {
        let n = task.boxes.len();
        if n == 1 {
            return Decision::Leaf;
        }
        let max_leaf = self.params.max_leaf_size as usize;
        let leaf_allowed = n <= max_leaf;
        let area = task.bounds.half_area();
        // Every split costs at least `C_trav A + C_isect Σ A(prim)`: each child's area is at
        // least that of each of its primitives. A leaf that beats this bound needs no search.
        if leaf_allowed {
            let prim_area_sum: f32 = task.boxes.iter().map(PrimBox::half_area).sum();
            if self.params.leaf_is_cheaper(n, area, prim_area_sum) {
                return Decision::Leaf;
            }
        }
        let split = if n <= SMALL_NODE_MAX {
            Some(Split::Sorted(best_sorted_split(task.boxes)))
        } else {
            let mapping = BinMapping::new(&task.bounds, &task.centroid_bounds, self.params.bins as usize);
            let max_isolated = 2 * self.params.max_leaf_size as usize;
            let split = bin(task.boxes, &mapping).best_split(mapping.count(), max_isolated);
            split.map(|split| Split::Plane(split, mapping))
        };
        match split {
            Some(split) if leaf_allowed && self.params.leaf_is_cheaper(n, area, split.area_count_sum()) => {
                Decision::Leaf
            }
            Some(split) if task.children_fit_depth(split.left_count(), max_leaf) => Decision::Split(split),
            _ if leaf_allowed => Decision::Leaf,
            _ => {
                let extent = task.centroid_bounds.max - task.centroid_bounds.min;
                Decision::Median(extent.max_position())
            }
        }
    }
}

/// The bins of `boxes`, in parallel chunks for large nodes.
fn bin(boxes: &[PrimBox], mapping: &BinMapping) -> Bins {
    if boxes.len() >= PARALLEL_BINNING_MIN {
        boxes
            .par_chunks(CHUNK)
            .fold(Bins::new, |mut bins, chunk| {
                bins.add(chunk, mapping);
                bins
            })
            .reduce(Bins::new, |a, b| a.merge(&b))
    } else {
        let mut bins = Bins::new();
        bins.add(boxes, mapping);
        bins
    }
}

/// `node` moved from its own array into a larger one at `base`.
#[inline]
fn reindexed(mut node: Node, base: u32) -> Node {
    if !node.is_leaf() {
        node.offset += base;
    }
    node
}

impl<'a> Task<'a> {
    /// True if both children of a split with `left_count` primitives on the left can be
    /// finished within [`MAX_DEPTH`], halving if need be, with leaves of `max_leaf` primitives.
    fn children_fit_depth(&self, left_count: usize, max_leaf: usize) -> bool {
        let larger = left_count.max(self.boxes.len() - left_count);
        self.depth + 1 + levels_to_split(larger, max_leaf) <= MAX_DEPTH
    }

    /// Partitions the primitives at a bin plane. The children's bounds come from the bins,
    /// their centroid bounds from the partition.
    fn split_at_plane(self, split: &BinSplit, mapping: &BinMapping) -> (Task<'a>, Task<'a>) {
        let (mid, left_centroids, right_centroids) =
            partition_at_plane(self.boxes, self.ids, mapping, split.axis, split.bin);
        debug_assert_eq!(mid, split.left_count, "partition disagrees with the bins");
        self.children(mid, [split.left, split.right], [left_centroids, right_centroids])
    }

    /// Reorders a small node's primitives into the split's order.
    fn split_sorted(self, split: &SortedSplit) -> (Task<'a>, Task<'a>) {
        let n = self.boxes.len();
        let mut boxes = [PrimBox::default(); SMALL_NODE_MAX];
        let mut ids = [0; SMALL_NODE_MAX];
        for (i, &from) in split.order[..n].iter().enumerate() {
            boxes[i] = self.boxes[from as usize];
            ids[i] = self.ids[from as usize];
        }
        self.boxes.copy_from_slice(&boxes[..n]);
        self.ids.copy_from_slice(&ids[..n]);
        let mid = split.left_count;
        let (left, right) = self.boxes.split_at(mid);
        let bounds = [PrimBox::union_of(left), PrimBox::union_of(right)];
        let centroids = [PrimBox::centroid_bounds_of(left), PrimBox::centroid_bounds_of(right)];
        self.children(mid, bounds, centroids)
    }

    /// Partitions the primitives at the centroid median on `axis`.
    fn split_at_median(self, axis: usize) -> (Task<'a>, Task<'a>) {
        let mid = partition_at_median(self.boxes, self.ids, axis);
        let (left, right) = self.boxes.split_at(mid);
        let bounds = [PrimBox::union_of(left), PrimBox::union_of(right)];
        let centroids = [PrimBox::centroid_bounds_of(left), PrimBox::centroid_bounds_of(right)];
        self.children(mid, bounds, centroids)
    }

    /// The two children after partitioning: the first `mid` primitives and the rest.
    fn children(self, mid: usize, bounds: [Box3A; 2], centroids: [Box3A; 2]) -> (Task<'a>, Task<'a>) {
        let (left_boxes, right_boxes) = self.boxes.split_at_mut(mid);
        let (left_ids, right_ids) = self.ids.split_at_mut(mid);
        let depth = self.depth + 1;
        (
            Task {
                boxes: left_boxes,
                ids: left_ids,
                first: self.first,
                depth,
                bounds: bounds[0],
                centroid_bounds: centroids[0],
            },
            Task {
                boxes: right_boxes,
                ids: right_ids,
                first: self.first + mid as u32,
                depth,
                bounds: bounds[1],
                centroid_bounds: centroids[1],
            },
        )
    }
}
