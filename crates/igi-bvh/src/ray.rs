//! Rays and hit records, for single rays and 8-ray packets.

use glam::Vec3;
use igi_simd::{F32x8, I32x8, M32x8, Vec3x8};

/// Marks "no primitive" in [`Hit::prim`] and [`HitPacket8::prim`].
pub const INVALID_ID: u32 = u32::MAX;

/// A ray `origin + t * dir` for `t` in `[tnear, tfar]`. `dir` need not be unit length; `t` is
/// measured in units of `dir`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Origin.
    pub origin: Vec3,
    /// Direction (not necessarily normalised, never zero).
    pub dir: Vec3,
    /// Smallest accepted hit distance.
    pub tnear: f32,
    /// Largest accepted hit distance.
    pub tfar: f32,
}

impl Ray {
    /// A ray over `[0, inf)`.
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self { origin, dir, tnear: 0.0, tfar: f32::INFINITY }
    }

    /// The point at distance `t`.
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.dir
    }
}

/// The closest hit of a ray: distance, barycentrics and what was hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the ray (in units of its direction).
    pub t: f32,
    /// Barycentric weight of the triangle's second vertex.
    pub u: f32,
    /// Barycentric weight of the triangle's third vertex.
    pub v: f32,
    /// Instance that was hit.
    pub instance: u32,
    /// Triangle within the instance's mesh (in the mesh's BVH leaf order), or [`INVALID_ID`].
    pub prim: u32,
}

impl Hit {
    /// A miss at distance `tfar`.
    pub fn miss(tfar: f32) -> Self {
        Self { t: tfar, u: 0.0, v: 0.0, instance: INVALID_ID, prim: INVALID_ID }
    }

    /// True if something was hit.
    pub fn is_hit(&self) -> bool {
        self.prim != INVALID_ID
    }
}

/// Eight rays in structure-of-arrays form, traced together by the packet kernels.
#[derive(Clone, Copy, Debug)]
pub struct RayPacket8 {
    /// Origins.
    pub origin: Vec3x8,
    /// Directions (not necessarily normalised; never zero in an active lane).
    pub dir: Vec3x8,
    /// Smallest accepted hit distances.
    pub tnear: F32x8,
    /// Largest accepted hit distances.
    pub tfar: F32x8,
}

impl RayPacket8 {
    /// The packet of eight single rays.
    pub fn from_rays(rays: &[Ray; 8]) -> Self {
        Self {
            origin: Vec3x8::from_lanes(rays.map(|r| r.origin.to_array())),
            dir: Vec3x8::from_lanes(rays.map(|r| r.dir.to_array())),
            tnear: F32x8::from_array(rays.map(|r| r.tnear)),
            tfar: F32x8::from_array(rays.map(|r| r.tfar)),
        }
    }

    /// Lane `i` as a single ray.
    pub fn ray(&self, i: usize) -> Ray {
        Ray {
            origin: Vec3::from(self.origin.lane(i)),
            dir: Vec3::from(self.dir.lane(i)),
            tnear: self.tnear.lane(i),
            tfar: self.tfar.lane(i),
        }
    }
}

/// The closest hits of an 8-ray packet.
#[derive(Clone, Copy, Debug)]
pub struct HitPacket8 {
    /// Distances (the ray's `tfar` where nothing was hit).
    pub t: F32x8,
    /// Barycentric weights of the second vertex.
    pub u: F32x8,
    /// Barycentric weights of the third vertex.
    pub v: F32x8,
    /// Instances hit (`INVALID_ID as i32` where nothing was hit).
    pub instance: I32x8,
    /// Triangles hit (`INVALID_ID as i32` where nothing was hit).
    pub prim: I32x8,
}

impl HitPacket8 {
    /// Lanes where something was hit.
    pub fn hit_mask(&self) -> M32x8 {
        !self.prim.eq(I32x8::splat(INVALID_ID as i32))
    }
}
