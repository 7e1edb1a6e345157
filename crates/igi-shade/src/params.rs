//! [`BrdfParams`]: what a surface shader computes and the BRDF shaders read.
//!
//! The BRDF at a point is a sum of lobes (paper 3.2), each weighted by its own reflectance:
//!
//! ```text
//! f = diffuse/π  +  specular · (n+2)/(2π) · cosⁿα  +  mirror · δ_reflect  +  glass · (dielectric)
//! ```
//!
//! with α the angle between ω_i and the mirror direction of ω_o, n = `exponent` (modified
//! Phong, Lafortune & Willems 1994: energy-conserving and reciprocal), and the dielectric a
//! smooth interface of index `ior` that reflects with Fresnel weight F and refracts 1 − F.
//! A surface conserves energy when `diffuse + specular + mirror + glass ≤ 1` per channel;
//! [`BrdfParams::conserving`] scales a surface that asks for more.

use glam::Vec3;
use igi_simd::{F32x8, M32x8, Vec3x8};

/// BRDF parameters of one surface point. See the module documentation for the model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrdfParams {
    /// Lambertian reflectance ρ_d (linear RGB).
    pub diffuse: Vec3,
    /// Reflectance ρ_s of the glossy (modified Phong) lobe.
    pub specular: Vec3,
    /// Phong exponent n of the glossy lobe (≥ 0; larger is sharper).
    pub exponent: f32,
    /// Reflectance of the perfect mirror lobe.
    pub mirror: Vec3,
    /// Weight of the smooth dielectric (glass) lobe, in [0, 1].
    pub glass: f32,
    /// Index of refraction of the inside (the side opposite the geometric normal) of the glass
    /// lobe.
    pub ior: f32,
    /// Unit shading normal (bump and normal maps change it), in the hemisphere of the
    /// geometric normal.
    pub shading_normal: Vec3,
    /// Emitted radiance toward the front side (seen by camera rays).
    pub emission: Vec3,
}

impl BrdfParams {
    /// A black, non-emitting surface with shading normal `n`.
    pub fn black(n: Vec3) -> Self {
        Self {
            diffuse: Vec3::ZERO,
            specular: Vec3::ZERO,
            exponent: 1.0,
            mirror: Vec3::ZERO,
            glass: 0.0,
            ior: 1.5,
            shading_normal: n,
            emission: Vec3::ZERO,
        }
    }

    /// True if the surface has a lobe the VPLs light (diffuse or glossy).
    pub fn has_non_delta(&self) -> bool {
        self.diffuse.max_element() > 0.0 || self.specular.max_element() > 0.0
    }

    /// True if the surface has a mirror or glass lobe (which the camera path follows).
    pub fn has_delta(&self) -> bool {
        self.mirror.max_element() > 0.0 || self.glass > 0.0
    }

    /// The parameters with every reflectance clamped to [0, 1], non-finite values replaced,
    /// and the lobes scaled down together where their sum exceeds 1 in some channel, so the
    /// surface never creates energy.
    pub fn conserving(self) -> Self {
        let clean = |v: Vec3| if v.is_finite() { v.clamp(Vec3::ZERO, Vec3::ONE) } else { Vec3::ZERO };
        let (diffuse, specular, mirror) = (clean(self.diffuse), clean(self.specular), clean(self.mirror));
        let glass = if self.glass.is_finite() { self.glass.clamp(0.0, 1.0) } else { 0.0 };
        let total = (diffuse + specular + mirror + Vec3::splat(glass)).max_element();
        let k = if total > 1.0 { 1.0 / total } else { 1.0 };
        let exponent = if self.exponent.is_finite() { self.exponent.clamp(0.0, 1.0e6) } else { 1.0 };
        let ior = if self.ior.is_finite() && self.ior > 0.0 { self.ior } else { 1.5 };
        let emission = if self.emission.is_finite() { self.emission.max(Vec3::ZERO) } else { Vec3::ZERO };
        Self {
            diffuse: diffuse * k,
            specular: specular * k,
            exponent,
            mirror: mirror * k,
            glass: glass * k,
            ior,
            shading_normal: self.shading_normal,
            emission,
        }
    }
}

/// [`BrdfParams`] of eight points, structure of arrays: the output of a
/// [`crate::SurfaceShader`].
#[derive(Clone, Copy, Debug)]
pub struct BrdfParams8 {
    /// Lambertian reflectance ρ_d.
    pub diffuse: Vec3x8,
    /// Reflectance of the glossy lobe.
    pub specular: Vec3x8,
    /// Phong exponent of the glossy lobe.
    pub exponent: F32x8,
    /// Reflectance of the mirror lobe.
    pub mirror: Vec3x8,
    /// Weight of the glass lobe.
    pub glass: F32x8,
    /// Index of refraction of the glass lobe.
    pub ior: F32x8,
    /// Unit shading normals.
    pub shading_normal: Vec3x8,
    /// Emitted radiance.
    pub emission: Vec3x8,
}

impl BrdfParams8 {
    /// Eight black, non-emitting surfaces with shading normals `n`: what a shader receives
    /// before it writes anything.
    pub fn black(n: Vec3x8) -> Self {
        let zero = Vec3x8::splat([0.0; 3]);
        Self {
            diffuse: zero,
            specular: zero,
            exponent: F32x8::splat(1.0),
            mirror: zero,
            glass: F32x8::ZERO,
            ior: F32x8::splat(1.5),
            shading_normal: n,
            emission: zero,
        }
    }

    /// Lane `i` as scalar parameters.
    pub fn lane(&self, i: usize) -> BrdfParams {
        BrdfParams {
            diffuse: Vec3::from(self.diffuse.lane(i)),
            specular: Vec3::from(self.specular.lane(i)),
            exponent: self.exponent.lane(i),
            mirror: Vec3::from(self.mirror.lane(i)),
            glass: self.glass.lane(i),
            ior: self.ior.lane(i),
            shading_normal: Vec3::from(self.shading_normal.lane(i)),
            emission: Vec3::from(self.emission.lane(i)),
        }
    }

    /// Keeps `self` in the lanes of `m` and takes `other` elsewhere.
    pub fn select(m: M32x8, a: &Self, b: &Self) -> Self {
        let v = |x: Vec3x8, y: Vec3x8| Vec3x8::select(m, x, y);
        let f = |x: F32x8, y: F32x8| F32x8::select(m, x, y);
        Self {
            diffuse: v(a.diffuse, b.diffuse),
            specular: v(a.specular, b.specular),
            exponent: f(a.exponent, b.exponent),
            mirror: v(a.mirror, b.mirror),
            glass: f(a.glass, b.glass),
            ior: f(a.ior, b.ior),
            shading_normal: v(a.shading_normal, b.shading_normal),
            emission: v(a.emission, b.emission),
        }
    }
}
