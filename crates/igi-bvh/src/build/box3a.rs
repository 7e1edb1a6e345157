//! The builders' working bounding box: two `Vec3A` corners, 32 bytes, one SSE register each.
//!
//! [`Aabb`] stores `Vec3`s (24 bytes) for a compact public API; the builders copy primitive
//! bounds into this form once so that growing, merging and centroid computations run on whole
//! registers and two boxes share a 64-byte cache line.

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

    /// The smallest box containing both boxes.
    #[inline(always)]
    pub fn union(self, o: Self) -> Self {
        Self { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    /// This box grown to contain the point `p`. NaN coordinates are ignored: they come from the
    /// centroids of empty (or infinite) primitive boxes, which take no room.
    #[inline(always)]
    pub fn grow(self, p: Vec3A) -> Self {
        let nan = p.is_nan_mask();
        Self {
            min: Vec3A::select(nan, self.min, self.min.min(p)),
            max: Vec3A::select(nan, self.max, self.max.max(p)),
        }
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

    /// The bounds of the centroids of a slice of boxes.
    pub fn centroid_bounds_of(boxes: &[Self]) -> Self {
        boxes.iter().fold(Self::EMPTY, |acc, b| acc.grow(b.centroid()))
    }

    /// A leaf node with this box over `count` primitives starting at leaf-order index `first`.
    #[inline]
    pub fn leaf(&self, first: u32, count: u32) -> Node {
        debug_assert!(count > 0, "a leaf holds at least one primitive");
        Node { min: self.min.to_array(), offset: first, max: self.max.to_array(), count }
    }

    /// An inner node with this box whose children are nodes `children` and `children + 1`.
    #[inline]
    pub fn inner(&self, children: u32) -> Node {
        Node { min: self.min.to_array(), offset: children, max: self.max.to_array(), count: 0 }
    }
}

impl From<&Aabb> for Box3A {
    #[inline(always)]
    fn from(b: &Aabb) -> Self {
        Self { min: b.min.into(), max: b.max.into() }
    }
}
