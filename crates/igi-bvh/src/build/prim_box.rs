//! A primitive's box as the binned builder stores it: 32 bytes, the two corners in SIMD
//! registers and the box's half area cached in the fourth lane of the upper corner. The area
//! is needed at every level (size bins, the leaf test); caching it costs no memory, since a
//! `Vec3A` corner takes 16 bytes anyway, and it moves along when primitives are partitioned.

use glam::{Vec3A, Vec4};

use super::box3a::Box3A;
use crate::aabb::Aabb;

/// A primitive's bounding box with its cached half area.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(32))]
pub(crate) struct PrimBox {
    /// Lower corner in `xyz`; `w` is 0.
    lower: Vec4,
    /// Upper corner in `xyz`; `w` is the half area of the box.
    upper: Vec4,
}

impl PrimBox {
    /// The box.
    #[inline(always)]
    pub fn bounds(&self) -> Box3A {
        Box3A { min: Vec3A::from_vec4(self.lower), max: Vec3A::from_vec4(self.upper) }
    }

    /// Centre point.
    #[inline(always)]
    pub fn centroid(&self) -> Vec3A {
        self.bounds().centroid()
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
        Self { lower: b.min.extend(0.0), upper: b.max.extend(b.half_area()) }
    }
}
