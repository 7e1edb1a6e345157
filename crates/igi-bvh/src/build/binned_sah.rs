//! The production builder: binned SAH after Wald 2007, "On fast Construction of SAH-based
//! Bounding Volume Hierarchies", parallel with rayon and deterministic.
//!
//! Primitive boxes are copied once into a compact [`PrimBox`] array with a parallel index array;
//! every node partitions its range of both arrays in place, so a node's primitives are always
//! contiguous and no node allocates. Nodes are written once, into one array (see
//! [`SparseNodes`]). Large nodes bin in parallel chunks, and large subtrees build
//! as parallel `rayon::join` tasks. Neither changes the result: bins merge exactly, and every
//! subtree's nodes are laid out by the tree alone (depth first), never by the order in which
//! tasks finish. The output is identical at any thread count.

use rayon::prelude::*;

use super::bins::{BinMapping, BinSplit, Bins};
use super::box3a::Box3A;
use super::node_region::{NodeRegion, SparseNodes, SparseTree, descendant_capacity};
use super::partition::{partition_at_median, partition_at_plane};
use super::prim_box::PrimBox;
use super::small_subtree::{SMALL_NODE_MAX, build_small_subtree};
use super::{BuildParams, levels_to_split, prim_count};
use crate::aabb::Aabb;
use crate::bvh::Bvh;
use crate::node::Node;
use crate::traverse::TRAVERSAL_STACK_SIZE;

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
    build_binned_sah_by(prim_bounds.len(), |i| prim_bounds[i], params)
}

/// [`build_binned_sah`] over `n` primitives whose boxes `bounds(i)` computes as the builder
/// reads them, so that no array of boxes lives beside the builder's own: for a mesh, its
/// triangles' boxes. On the 50-million-triangle meshes of issue 17 that array was 24 of the
/// peak's bytes per triangle.
///
/// # Panics
/// As [`build_binned_sah`].
pub fn build_binned_sah_by(n: usize, bounds: impl Fn(usize) -> Aabb + Sync, params: &BuildParams) -> Bvh {
    match build_binned_sah_tree_by(n, bounds, params) {
        Some((tree, prim_order)) => Bvh { nodes: tree.into_compact(), prim_order },
        None => Bvh::default(),
    }
}

/// [`build_binned_sah_by`] before the tree is compacted: the tree as the builder left it, and
/// the input index of each primitive in leaf order; `None` for an empty input.
///
/// # Panics
/// As [`build_binned_sah`].
pub(crate) fn build_binned_sah_tree_by(
    n: usize,
    bounds: impl Fn(usize) -> Aabb + Sync,
    params: &BuildParams,
) -> Option<(SparseTree, Vec<u32>)> {
    let n = prim_count(n, params)?;

    let mut boxes = Vec::with_capacity(n);
    boxes.par_extend((0..n).into_par_iter().map(|i| PrimBox::from(&bounds(i))));
    let mut ids: Vec<u32> = (0..n as u32).collect();
    let (bounds, centroid_bounds) = boxes
        .par_chunks(CHUNK)
        .map(|chunk| (PrimBox::union_of(chunk), PrimBox::centroid_bounds_of(chunk)))
        .reduce(|| (Box3A::EMPTY, Box3A::EMPTY), |(b0, c0), (b1, c1)| (b0.union(b1), c0.union(c1)));

    let builder = Builder { params: *params };
    let root = Task { boxes: &mut boxes, ids: &mut ids, first: 0, depth: 1, bounds, centroid_bounds };
    let mut nodes = SparseNodes::new(n);
    let root = builder.subtree(root, &mut nodes.below_root(), &mut Bins::new());
    Some((nodes.with_root(root), ids))
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
    /// Split at a bin plane.
    Plane(BinSplit, BinMapping),
    /// Split at the object median along an axis: when all centroids coincide (no plane
    /// separates them) or when the SAH split could exceed [`TRAVERSAL_STACK_SIZE`] levels.
    Median(usize),
}

/// The builder's shared, read-only state.
struct Builder {
    params: BuildParams,
}

impl Builder {
    /// Builds the subtree over `task` and returns its root node. The other nodes are written to
    /// `nodes` depth first: the root's two children as a pair, then the left child's subtree,
    /// then the right child's, so children always come after their parent. Large subtrees build
    /// their children's subtrees as parallel tasks, each in its own part of the region (see
    /// [`SparseNodes`]). `bins` is scratch space, reused by every node of a task.
    fn subtree(&self, task: Task, nodes: &mut NodeRegion, bins: &mut Bins) -> Node {
        let n = task.boxes.len();
        let bounds = task.bounds;
        if n <= SMALL_NODE_MAX {
            return build_small_subtree(
                &self.params,
                task.boxes,
                task.ids,
                task.first,
                task.depth,
                bounds,
                nodes,
            );
        }
        let (left, right) = match self.decide(&task, bins) {
            Decision::Leaf => return bounds.leaf(task.first, n as u32),
            Decision::Plane(split, mapping) => task.split_at_plane(&split, &mapping),
            Decision::Median(axis) => task.split_at_median(axis),
        };

        let pair = nodes.push_pair();
        let (left_root, right_root) = if n >= PARALLEL_SUBTREE_MIN {
            let (mut left_nodes, mut right_nodes) = nodes.split_unused(descendant_capacity(left.boxes.len()));
            rayon::join(
                || self.subtree(left, &mut left_nodes, bins),
                || self.subtree(right, &mut right_nodes, &mut Bins::new()),
            )
        } else {
            let left_root = self.subtree(left, nodes, bins);
            (left_root, self.subtree(right, nodes, bins))
        };
        nodes.set(pair, left_root);
        nodes.set(pair + 1, right_root);
        bounds.inner(pair as u32)
    }

    /// Chooses between a leaf and the best bin plane with the SAH (nodes of more than
    /// [`SMALL_NODE_MAX`] primitives). More than `max_leaf_size` primitives are always split. A
    /// split whose larger side could not be finished within [`TRAVERSAL_STACK_SIZE`] levels by
    /// halving gives way to a leaf or a median split, so every node at depth `d` with `n`
    /// primitives keeps `d + levels_to_split(n) <= TRAVERSAL_STACK_SIZE`, which holds at the root
    /// for any `n < 2³¹`.
    fn decide(&self, task: &Task, bins: &mut Bins) -> Decision {
        let n = task.boxes.len();
        let max_leaf = self.params.max_leaf_size as usize;
        let leaf_allowed = n <= max_leaf;
        let mapping = BinMapping::new(&task.bounds, &task.centroid_bounds, self.params.bins as usize);
        fill_bins(bins, task.boxes, &mapping);
        match bins.best_split(mapping.count()) {
            Some(split)
                if leaf_allowed
                    && self.params.leaf_is_cheaper(n, task.bounds.half_area(), split.area_count_sum) =>
            {
                Decision::Leaf
            }
            Some(split) if task.children_fit_depth(split.left_count, max_leaf) => {
                Decision::Plane(split, mapping)
            }
            _ if leaf_allowed => Decision::Leaf,
            _ => {
                let extent = task.centroid_bounds.max - task.centroid_bounds.min;
                Decision::Median(extent.max_position())
            }
        }
    }
}

/// Sets `bins` to the bins of `boxes`, binned in parallel chunks for large nodes.
fn fill_bins(bins: &mut Bins, boxes: &[PrimBox], mapping: &BinMapping) {
    if boxes.len() >= PARALLEL_BINNING_MIN {
        *bins = boxes
            .par_chunks(CHUNK)
            .fold(Bins::new, |mut bins, chunk| {
                bins.add(chunk, mapping);
                bins
            })
            .reduce(Bins::new, |a, b| a.merge(&b));
    } else {
        bins.clear(mapping.count());
        bins.add(boxes, mapping);
    }
}

impl<'a> Task<'a> {
    /// True if both children of a split with `left_count` primitives on the left can be
    /// finished within [`TRAVERSAL_STACK_SIZE`] levels, halving if need be, with leaves of
    /// `max_leaf` primitives.
    fn children_fit_depth(&self, left_count: usize, max_leaf: usize) -> bool {
        let larger = left_count.max(self.boxes.len() - left_count);
        self.depth + 1 + levels_to_split(larger, max_leaf) <= TRAVERSAL_STACK_SIZE
    }

    /// Partitions the primitives at a bin plane. The children's bounds come from the bins,
    /// their centroid bounds from the partition.
    fn split_at_plane(self, split: &BinSplit, mapping: &BinMapping) -> (Task<'a>, Task<'a>) {
        let (mid, left_centroids, right_centroids) =
            partition_at_plane(self.boxes, self.ids, mapping, split.axis, split.bin);
        debug_assert_eq!(mid, split.left_count, "partition disagrees with the bins");
        self.children(mid, [split.left, split.right], [left_centroids, right_centroids])
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
