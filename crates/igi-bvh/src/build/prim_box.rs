//! A primitive's box as the binned builder stores it: 32 bytes, the negated lower corner and the
//! upper corner, with the box's half area cached in the fourth lane of the upper corner.
//!
//! The area is needed at every level (size bins, the leaf test); caching it costs no memory,
//! since a 3-vector takes 16 bytes in a SIMD register anyway, and it moves along when primitives
//! are partitioned. The negated lower corner makes the 32 bytes a [`BoxLanes`], whose union with
//! another box is a single 8-lane maximum: binning, the hottest loop of the builder, does one
//! such union per primitive and axis.

use glam::{Vec3A, Vec4};
use igi_simd::F32x8;

use super::box3a::Box3A;
use crate::aabb::Aabb;

/// A primitive's bounding box with its cached half area.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(32))]
pub(crate) struct PrimBox {
    /// Lower corner, negated, in `xyz`; `w` is 0.
    neg_lower: Vec4,
    /// Upper corner in `xyz`; `w` is the half area of the box.
    upper: Vec4,
}

impl PrimBox {
    /// The box.
    #[inline(always)]
    pub fn bounds(&self) -> Box3A {
        Box3A { min: -Vec3A::from_vec4(self.neg_lower), max: Vec3A::from_vec4(self.upper) }
    }

    /// The box as eight lanes, see [`BoxLanes`].
    #[inline(always)]
    pub fn lanes(&self) -> BoxLanes {
        let (l, u) = (self.neg_lower, self.upper);
        BoxLanes(F32x8::from_array([l.x, l.y, l.z, l.w, u.x, u.y, u.z, u.w]))
    }

    /// Centre point.
    #[inline(always)]
    pub fn centroid(&self) -> Vec3A {
        0.5 * self.double_centroid()
    }

    /// Twice the centre point, `min + max`.
    #[inline(always)]
    pub fn double_centroid(&self) -> Vec3A {
        Vec3A::from_vec4(self.upper - self.neg_lower)
    }

    /// Half the surface area (∞ for an empty primitive, see [`Box3A::VOID`]).
    #[inline(always)]
    pub fn half_area(&self) -> f32 {
        self.upper.w
    }

    /// The union of the primitives' boxes ([`Box3A::EMPTY`] for none).
    pub fn union_of(prims: &[Self]) -> Box3A {
        prims.iter().fold(Box3A::EMPTY, |acc, p| acc.union(p.bounds()))
    }

    /// The bounds of the primitives' centroids.
    pub fn centroid_bounds_of(prims: &[Self]) -> Box3A {
        prims.iter().fold(Box3A::EMPTY, |acc, p| acc.grow(p.centroid()))
    }
}

impl From<&Aabb> for PrimBox {
    #[inline(always)]
    fn from(b: &Aabb) -> Self {
        let b = Box3A::from(b);
        Self { neg_lower: (-b.min).extend(0.0), upper: b.max.extend(b.half_area()) }
    }
}

/// A box as eight SIMD lanes: the lower corner negated in lanes 0-2, the upper corner in lanes
/// 4-6, so that the union of two boxes is one lane-wise maximum (lanes 3 and 7 are scratch).
#[derive(Clone, Copy, Debug)]
pub(crate) struct BoxLanes(F32x8);

impl BoxLanes {
    /// The empty box.
    pub const EMPTY: Self = Self(F32x8::from_array([f32::NEG_INFINITY; 8]));

    /// The smallest box containing both boxes.
    #[inline(always)]
    pub fn union(self, o: Self) -> Self {
        Self(self.0.max(o.0))
    }

    /// The box.
    #[inline(always)]
    pub fn bounds(self) -> Box3A {
        let a = self.0.to_array();
        Box3A { min: -Vec3A::new(a[0], a[1], a[2]), max: Vec3A::new(a[4], a[5], a[6]) }
    }
}
