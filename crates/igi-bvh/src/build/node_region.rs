//! Where the binned builder writes its nodes: one array sized for the largest possible tree,
//! cut into disjoint regions for the subtrees that build in parallel, and copied once at the
//! end, without the gaps, into the depth-first layout of [`Bvh`](crate::bvh::Bvh).
//!
//! A subtree over `m` primitives has at most `2m - 2` nodes below its root, so a node can hand
//! its left child a region of exactly that bound and its right child everything after it,
//! before either is built. Every task writes its nodes where they stay until the final copy, so
//! no subtree is built in an array of its own and appended (on a 10-million-triangle mesh those
//! appends, and shrinking an over-allocated array, which copies it, were 25 of the peak's bytes
//! per triangle). The array is allocated but never initialised, so the slots the tree leaves
//! unused are address space, not memory: only the pages nodes are written to become resident.

use std::mem::MaybeUninit;

use crate::bvh::BinaryTree;
use crate::node::Node;

/// The most nodes below the root of a subtree over `prims` primitives: `2 prims - 2`.
pub(crate) fn descendant_capacity(prims: usize) -> usize {
    2 * prims - 2
}

/// The node array of a build over `prims` primitives, with room for the largest tree.
pub(crate) struct SparseNodes {
    /// Always of length 0: the capacity holds the slots, written through [`NodeRegion`]s.
    nodes: Vec<Node>,
}

impl SparseNodes {
    /// An array with room for every node of a tree over `prims >= 1` primitives.
    pub fn new(prims: usize) -> Self {
        Self { nodes: Vec::with_capacity(1 + descendant_capacity(prims)) }
    }

    /// The region for the root's descendants: every slot after the root's.
    pub fn below_root(&mut self) -> NodeRegion<'_> {
        let slots = &mut self.nodes.spare_capacity_mut()[1..];
        NodeRegion { slots, start: 1, used: 0 }
    }

    /// The finished tree whose root is `root`.
    pub fn with_root(self, root: Node) -> SparseTree {
        SparseTree { nodes: self, root }
    }

    /// The node in slot `index`, a slot of a child pair named by a node of the tree.
    fn read(&self, index: usize) -> Node {
        assert!(index < self.nodes.capacity());
        // SAFETY: in bounds (checked), and written: `NodeRegion::push_pair` wrote both slots of
        // every pair, and the tree names only such pairs (an inner node's `offset` is an index
        // `push_pair` returned).
        unsafe { self.nodes.as_ptr().add(index).read() }
    }

    /// Adds the number of nodes below `node` to `count`.
    fn count_below(&self, node: Node, count: &mut usize) {
        if !node.is_leaf() {
            *count += 2;
            self.count_below(self.read(node.offset as usize), count);
            self.count_below(self.read(node.offset as usize + 1), count);
        }
    }

    /// Appends the descendants of `nodes[parent]` (whose `offset` is still a slot of this
    /// array) to `nodes`, depth first, and points the parent at its new children.
    fn copy_below(&self, parent: usize, nodes: &mut Vec<Node>) {
        let node = nodes[parent];
        if node.is_leaf() {
            return;
        }
        let (old, new) = (node.offset as usize, nodes.len());
        nodes.extend([self.read(old), self.read(old + 1)]);
        nodes[parent].offset = new as u32;
        self.copy_below(new, nodes);
        self.copy_below(new + 1, nodes);
    }
}

/// A finished build as the builder left it: the root, and below it the nodes in their slots,
/// with the unused slots of the parallel tasks' regions between subtrees. It is a
/// [`BinaryTree`] as it stands: the collapse into a wide tree reads it without the copy into
/// [`Bvh`](crate::bvh::Bvh)'s compact array (on a 10-million-triangle mesh that copy took
/// 0.33-0.44 s, and the tree's size in memory again).
pub(crate) struct SparseTree {
    nodes: SparseNodes,
    root: Node,
}

impl SparseTree {
    /// The nodes reachable from the root, copied into an array of their exact size, depth
    /// first without gaps: the root, its child pair, the left child's subtree, the right
    /// child's subtree. The caller frees what it no longer needs first (the builder's primitive
    /// boxes), since for a moment both arrays are resident.
    pub fn into_compact(self) -> Vec<Node> {
        let mut count = 1;
        self.nodes.count_below(self.root, &mut count);
        let mut nodes = Vec::with_capacity(count);
        nodes.push(self.root);
        self.nodes.copy_below(0, &mut nodes);
        debug_assert_eq!(nodes.len(), count);
        nodes
    }
}

impl BinaryTree for SparseTree {
    fn node(&self, index: usize) -> Node {
        if index == 0 { self.root } else { self.nodes.read(index) }
    }

    fn slots(&self) -> usize {
        self.nodes.nodes.capacity()
    }
}

/// The slots a subtree writes its nodes to, a contiguous part of a [`SparseNodes`] array.
pub(crate) struct NodeRegion<'a> {
    slots: &'a mut [MaybeUninit<Node>],
    /// Index of `slots[0]` in the whole array.
    start: usize,
    /// Slots written so far, from the first.
    used: usize,
}

impl<'a> NodeRegion<'a> {
    /// Takes the next two slots for a child pair and returns the index of the first. Both are
    /// written at once, so every slot the tree refers to holds a node.
    pub fn push_pair(&mut self) -> usize {
        let pair = self.used;
        self.slots[pair].write(Node::default());
        self.slots[pair + 1].write(Node::default());
        self.used += 2;
        self.start + pair
    }

    /// Stores `node` at index `at` of the whole array, a slot taken by [`NodeRegion::push_pair`].
    pub fn set(&mut self, at: usize, node: Node) {
        self.slots[at - self.start].write(node);
    }

    /// Splits the unused slots in two: the first `left` of them, and the rest. This region
    /// keeps only the slots it has taken, so it can still [`NodeRegion::set`] them.
    pub fn split_unused(&mut self, left: usize) -> (NodeRegion<'a>, NodeRegion<'a>) {
        let (taken, unused) = std::mem::take(&mut self.slots).split_at_mut(self.used);
        self.slots = taken;
        let (l, r) = unused.split_at_mut(left);
        let start = self.start + self.used;
        (NodeRegion { slots: l, start, used: 0 }, NodeRegion { slots: r, start: start + left, used: 0 })
    }
}
