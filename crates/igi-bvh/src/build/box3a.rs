//! The builders' working bounding box: two `Vec3A` corners, 32 bytes, one SSE register each.
//!
//! [`Aabb`] stores `Vec3`s (24 bytes) for a compact public API; the builders copy primitive
//! bounds into this form once so that growing, merging and centroid computations run on whole
//! registers and two boxes share a 64-byte cache line.
//!
//! Empty primitive boxes (an instance of an empty mesh, say) are copied as [`Box3A::VOID`],
//! an empty box with finite corners: its centroid is the origin rather than NaN
//! (`0.5 · (∞ - ∞)`), so binning, partitioning and centroid bounds need no NaN handling, and its
//! union with any finite box is still that box. Node boxes are written back with
//! [`Aabb::EMPTY`]'s corners whenever they are empty.

use glam::Vec3A;

use crate::aabb::Aabb;
use crate::node::Node;

/// An axis-aligned box with SIMD corners. Empty when `min > max` on some axis.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub(crate) struct Box3A {
    /// Lower corner.
    pub min: Vec3A,
    /// Upper corner.
    pub max: Vec3A,
}

impl Box3A {
    /// The empty box, identity of [`Box3A::union`].
    pub const EMPTY: Self = Self { min: Vec3A::INFINITY, max: Vec3A::NEG_INFINITY };

    /// The empty box with finite corners that stands in for empty primitive boxes.
    pub const VOID: Self = Self { min: Vec3A::MAX, max: Vec3A::MIN };

    /// The smallest box containing both boxes.
    #[inline(always)]
    pub fn union(self, o: Self) -> Self {
        Self { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    /// This box grown to contain the point `p`.
    #[inline(always)]
    pub fn grow(self, p: Vec3A) -> Self {
        Self { min: self.min.min(p), max: self.max.max(p) }
    }

    /// True if the box contains no point.
    #[inline(always)]
    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    /// Centre point.
    #[inline(always)]
    pub fn centroid(&self) -> Vec3A {
        0.5 * (self.min + self.max)
    }

    /// Half the surface area (MacDonald & Booth 1990). Only meaningful for a non-empty box:
    /// callers know from primitive counts whether a box is empty, so there is no test here.
    #[inline(always)]
    pub fn half_area(&self) -> f32 {
        let e = self.max - self.min;
        e.x * e.y + e.y * e.z + e.z * e.x
    }

    /// The union of a slice of boxes ([`Box3A::EMPTY`] for an empty slice).
    pub fn union_of(boxes: &[Self]) -> Self {
        boxes.iter().fold(Self::EMPTY, |acc, b| acc.union(*b))
    }

    /// A leaf node with this box over `count` primitives starting at leaf-order index `first`.
    #[inline]
    pub fn leaf(&self, first: u32, count: u32) -> Node {
        debug_assert!(count > 0, "a leaf holds at least one primitive");
        let (min, max) = self.node_corners();
        Node { min, offset: first, max, count }
    }

    /// An inner node with this box whose children are nodes `children` and `children + 1`.
    #[inline]
    pub fn inner(&self, children: u32) -> Node {
        let (min, max) = self.node_corners();
        Node { min, offset: children, max, count: 0 }
    }

    /// The corners as stored in a node: those of [`Aabb::EMPTY`] if the box is empty.
    #[inline]
    pub fn node_corners(&self) -> ([f32; 3], [f32; 3]) {
        let b = if self.is_empty() { Self::EMPTY } else { *self };
        (b.min.to_array(), b.max.to_array())
    }
}

impl From<&Aabb> for Box3A {
    /// The box of `b`, or [`Box3A::VOID`] if `b` is empty.
    #[inline(always)]
    fn from(b: &Aabb) -> Self {
        let b = Self { min: b.min.into(), max: b.max.into() };
        if b.is_empty() { Self::VOID } else { b }
    }
}
