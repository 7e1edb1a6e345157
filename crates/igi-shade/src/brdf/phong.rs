//! The glossy lobe: the modified Phong BRDF of Lafortune & Willems (1994),
//!
//! ```text
//! f_s(ω_o, ω_i) = ρ_s · (n + 2)/(2π) · max(0, r · ω_i)ⁿ,    r = 2(N·ω_o)N − ω_o,
//! ```
//!
//! the mirror direction r of ω_o about the shading normal N. It is reciprocal (r·ω_i is
//! symmetric in ω_o and ω_i) and conserves energy: the directional albedo
//! ∫ f_s cos θ_i dω_i is at most ρ_s (equal at normal incidence, less at grazing angles, where
//! part of the lobe falls below the surface). Sampling draws ω_i around r with density
//! (n + 1)/(2π) · cosⁿα (the lobe without the cos θ_i factor), so the estimator weight is
//! ρ_s · (n + 2)/(n + 1) · cos θ_i, which stays below 1 + 1/(n+1).
//!
//! The paper's BRDF shaders included a Phong model; a microfacet model would fit measured
//! materials better, but every glossy VPL evaluates this lobe at 8 lanes per packet per VPL,
//! and one `powf` per lane is the cheapest lobe with a closed-form sampling routine.

use glam::{Vec2, Vec3};
use igi_simd::F32x8;
use std::f32::consts::{FRAC_1_PI, PI};

/// The normalised lobe (n + 2)/(2π) · max(0, cos α)ⁿ at `cos_alpha` = r · ω_i: the glossy
/// BRDF per unit of ρ_s.
#[inline]
pub fn phong_lobe(exponent: f32, cos_alpha: f32) -> f32 {
    if cos_alpha <= 0.0 {
        return 0.0;
    }
    (exponent + 2.0) * (0.5 * FRAC_1_PI) * cos_alpha.powf(exponent)
}

/// [`phong_lobe`] of eight lanes.
#[inline(always)]
pub fn phong_lobe8(exponent: F32x8, cos_alpha: F32x8) -> F32x8 {
    let c = cos_alpha.max(F32x8::ZERO);
    let value = (exponent + F32x8::splat(2.0)) * F32x8::splat(0.5 * FRAC_1_PI) * c.powf(exponent);
    F32x8::select(cos_alpha.gt(F32x8::ZERO), value, F32x8::ZERO)
}

/// The mirror direction r = 2(N·ω)N − ω of the unit direction `w` (pointing away from the
/// surface) about the unit normal `n`: the axis of the glossy lobe.
#[inline]
pub fn mirror_direction(w: Vec3, n: Vec3) -> Vec3 {
    2.0 * n.dot(w) * n - w
}

/// A unit direction around the unit axis `r` with density (n + 1)/(2π) · cosⁿα (α the angle
/// to `r`), from a point of the unit square.
pub fn sample_phong(r: Vec3, exponent: f32, u: Vec2) -> Vec3 {
    let cos_alpha = u.x.powf(1.0 / (exponent + 1.0));
    let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    let (t, b) = r.any_orthonormal_pair();
    (t * (sin_alpha * phi.cos()) + b * (sin_alpha * phi.sin()) + r * cos_alpha).normalize()
}

/// The density of [`sample_phong`] at `cos_alpha` = r · ω_i.
#[inline]
pub fn phong_pdf(exponent: f32, cos_alpha: f32) -> f32 {
    if cos_alpha <= 0.0 {
        return 0.0;
    }
    (exponent + 1.0) * (0.5 * FRAC_1_PI) * cos_alpha.powf(exponent)
}
