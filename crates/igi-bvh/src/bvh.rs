//! The binary BVH: a flat array of [`Node`]s and the order of the primitives in its leaves.

use crate::build::BuildParams;
use crate::node::Node;

/// A binary bounding volume hierarchy over primitives `0 .. n`, as built by
/// [`build_binned_sah`](crate::build::build_binned_sah) and
/// [`build_sweep_sah`](crate::build::build_sweep_sah).
///
/// Invariants, relied on by the traversal kernels and by [`Bvh::refit`]:
/// - An empty BVH (no primitives) has no nodes at all: traversal must check `nodes.is_empty()`
///   before reading the root.
/// - Otherwise node 0 is the root. A BVH over one primitive is a single leaf.
/// - The children of inner node `i` are `offset` and `offset + 1`, and `offset > i`: children
///   always come after their parent. Nodes are laid out depth first, so the nodes of the left
///   child's subtree are contiguous and directly follow the child pair.
/// - Leaf `i` holds the primitives `prim_order[offset .. offset + count]`, with
///   `1 <= count <= BuildParams::MAX_LEAF_SIZE`; every leaf-order index lies in exactly one leaf.
/// - `prim_order` is a permutation of `0 .. n`: `prim_order[j]` is the input index of the `j`-th
///   primitive in leaf order.
/// - Every node's box is the exact union of its primitives' boxes (no padding, no rounding), or
///   [`Aabb::EMPTY`](crate::aabb::Aabb::EMPTY)'s if all of them are empty.
/// - The depth (see [`Bvh::depth`]) is at most
///   [`TRAVERSAL_STACK_SIZE`](crate::traverse::TRAVERSAL_STACK_SIZE), so the traversal stacks
///   never overflow.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Bvh {
    /// The nodes, root first.
    pub nodes: Vec<Node>,
    /// Input index of each primitive in leaf order.
    pub prim_order: Vec<u32>,
}

/// Read access to a binary tree in [`Bvh`]'s depth-first layout whose array may leave unused
/// slots between subtrees (a build before it is compacted); only slots the tree names are
/// read.
pub(crate) trait BinaryTree: Sync {
    /// The node in slot `index`: 0 is the root, the others are named by an inner node's
    /// `offset`.
    fn node(&self, index: usize) -> Node;

    /// The number of slots, 0 for an empty tree.
    fn slots(&self) -> usize;
}

impl BinaryTree for Bvh {
    fn node(&self, index: usize) -> Node {
        self.nodes[index]
    }

    fn slots(&self) -> usize {
        self.nodes.len()
    }
}

/// [`Bvh::sah_cost`] of any [`BinaryTree`], summed from the root down.
pub(crate) fn sah_cost(tree: &impl BinaryTree, params: &BuildParams) -> f32 {
    if tree.slots() == 0 {
        return 0.0;
    }
    let root_area = f64::from(tree.node(0).bounds().half_area());
    let mut sum = 0.0f64;
    let mut stack = vec![0usize];
    while let Some(index) = stack.pop() {
        let node = tree.node(index);
        let cost = if node.is_leaf() {
            params.intersection_cost * node.count as f32
        } else {
            stack.extend([node.offset as usize + 1, node.offset as usize]);
            params.traversal_cost
        };
        let area = f64::from(node.bounds().half_area());
        sum += f64::from(cost) * if root_area > 0.0 { area / root_area } else { 1.0 };
    }
    sum as f32
}

impl Bvh {
    /// The SAH cost of the tree (MacDonald & Booth 1990): the expected cost of a ray that hits
    /// the root box, `Σ_inner C_trav A(n)/A(root) + Σ_leaves C_isect count(n) A(n)/A(root)`
    /// with the costs of `params`. Zero for an empty BVH. If the root box has no area (all
    /// primitives on one axis-parallel line or point, or empty), every node is weighted by 1.
    pub fn sah_cost(&self, params: &BuildParams) -> f32 {
        sah_cost(self, params)
    }

    /// Number of nodes on the longest path from the root to a leaf (0 for an empty BVH, 1 for a
    /// single leaf).
    pub fn depth(&self) -> usize {
        // Parents come before children, so one forward sweep sees every node's depth before
        // its children need it.
        let mut depths = vec![0u32; self.nodes.len()];
        let mut deepest = 0;
        for (i, node) in self.nodes.iter().enumerate() {
            let depth = if i == 0 { 1 } else { depths[i] };
            if node.is_leaf() {
                deepest = deepest.max(depth);
            } else {
                depths[node.offset as usize] = depth + 1;
                depths[node.offset as usize + 1] = depth + 1;
            }
        }
        deepest as usize
    }

    /// Number of leaves.
    pub fn leaf_count(&self) -> usize {
        self.nodes.iter().filter(|node| node.is_leaf()).count()
    }

    /// Heap memory held by the nodes and the primitive order, in bytes.
    pub fn bytes(&self) -> usize {
        self.nodes.capacity() * size_of::<Node>() + self.prim_order.capacity() * size_of::<u32>()
    }
}
