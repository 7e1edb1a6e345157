//! The BVH node layout shared by the builders and the traversal kernels.
//!
//! A binary BVH in one flat array, 32 bytes per node (two nodes per 64-byte cache line). The
//! two children of an inner node are stored next to each other, so one index reaches both and
//! the packet kernels load both boxes from one cache line. Leaves reference a contiguous range
//! of primitives: the builders reorder primitives into leaf order.

/// One BVH node: a bounding box plus either two children or a range of primitives.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(32))]
pub struct Node {
    /// Lower corner of the node's bounding box.
    pub min: [f32; 3],
    /// Inner node: index of the left child (the right child is `offset + 1`).
    /// Leaf: index of the first primitive in leaf order.
    pub offset: u32,
    /// Upper corner of the node's bounding box.
    pub max: [f32; 3],
    /// Number of primitives of a leaf; 0 marks an inner node.
    pub count: u32,
}

impl Node {
    /// True if the node is a leaf.
    #[inline(always)]
    pub fn is_leaf(&self) -> bool {
        self.count != 0
    }

    /// The box corners as eight floats: `min` at indices 0..3, `max` at 4..7 (indices 3 and 7
    /// hold `offset` and `count` and must not be read as coordinates).
    #[inline(always)]
    pub(crate) fn coords(&self) -> &[f32; 8] {
        // SAFETY: `Node` is `repr(C)` with eight 4-byte fields and no padding (size 32, checked
        // below), and every bit pattern is a valid f32.
        unsafe { &*(self as *const Node as *const [f32; 8]) }
    }

    /// The node's bounding box.
    #[inline]
    pub fn bounds(&self) -> crate::Aabb {
        crate::Aabb { min: self.min.into(), max: self.max.into() }
    }
}

const _: () = assert!(std::mem::size_of::<Node>() == 32);
