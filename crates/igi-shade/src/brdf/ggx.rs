//! The glossy lobe of glTF 2.0 metallic-roughness materials ([`GlossyModel::Ggx`]), as the
//! specification's appendix B defines it:
//!
//! ```text
//! f(ω_o, ω_i) = (1 − F)·c_diff/π  +  F · D(h) · V(ω_i, ω_o),     h = (ω_o + ω_i)/|ω_o + ω_i|
//! F = F₀ + (1 − F₀)·s,   s = (1 − ω_o·h)⁵                       (Schlick)
//! D(h) = α² / (π ((N·h)²(α² − 1) + 1)²)                          (GGX / Trowbridge–Reitz)
//! V = 0.5 / (N·ω_i √((N·ω_o)²(1 − α²) + α²) + N·ω_o √((N·ω_i)²(1 − α²) + α²))
//! ```
//!
//! with α = roughness², V = G₂/(4 N·ω_i N·ω_o) the **height-correlated** Smith masking-shadowing
//! term (Heitz 2014), c_diff = mix(base, 0, metallic) and F₀ = mix(0.04, base, metallic): the
//! spec's implementation sample (`fresnel_mix` of the dielectric and `conductor_fresnel` of the
//! metal, mixed by metallic, is exactly this one F with that F₀). [`BrdfParams`] holds
//! `glossy` = F₀ and `diffuse` = c_diff·(1 − F₀), so that
//!
//! ```text
//! f = diffuse·(1 − s)/π  +  (glossy·(1 − s) + s) · D·V
//! ```
//!
//! and every factor that depends on the directions is one of the two scalars s and D·V
//! ([`ggx_terms`]). The VPL loop accumulates the light weighted by each of them per point and
//! multiplies `diffuse` and `glossy` back in after the discontinuity filter, as for Phong.
//!
//! The lobe is reciprocal (ω_o·h = ω_i·h, and D, V are symmetric). It is single-scattering:
//! light that the microfacets mask after one bounce is lost, so a white metal (F₀ = 1) reflects
//! less than 1 at high roughness: 0.916 at roughness 0.5 and 1 − ln 2 = 0.307 at roughness 1
//! seen head-on (0.78 at 85°; the white-furnace test of `tests/brdf.rs`); glTF accepts this
//! loss. The layering is the specification's approximation, not energy-conserving toward
//! grazing views: the diffuse weight 1 − F(ω_o·h) follows each direction's half vector rather
//! than the specular lobe's albedo, so a white dielectric reflects up to 1.025 at 60° and
//! 1.84 at 89° (roughness 0.05); within 1 up to 45°.
//!
//! Sampling draws the microfacet normal from the distribution of visible normals (Heitz 2018,
//! "Sampling the GGX distribution of visible normals"), density
//! p(ω_i) = G₁(ω_o)·D(h) / (4 N·ω_o), so the specular weight f·cos/p is F·G₂/G₁ ≤ 1.

#[cfg(doc)]
use crate::{BrdfParams, GlossyModel};
use glam::{Vec2, Vec3};
use igi_simd::Lanes;
use std::f32::consts::{FRAC_1_PI, PI};

/// Schlick's Fresnel weight s = (1 − cos)⁵ at the cosine `cos` between ω_o and h, clamped to
/// [0, 1].
#[inline(always)]
pub fn schlick_weight<T: Lanes>(cos: T) -> T {
    let (zero, one) = (T::splat(0.0), T::splat(1.0));
    let m = one - cos;
    let m = T::select(m.lt(zero), zero, T::select(m.gt(one), one, m));
    let m2 = m * m;
    m2 * m2 * m
}

/// The GGX normal distribution D(h) of width `alpha` at a half vector h with
/// `cos2` = (N·h)² and `sin2` = |N × h|², written α²/(π (sin²θ + α² cos²θ)²): the
/// textbook denominator (N·h)²(α² − 1) + 1 cancels to α² at the peak, which in f32 loses
/// percents of D for α below 0.01.
#[inline(always)]
pub fn ggx_d<T: Lanes>(alpha: T, cos2: T, sin2: T) -> T {
    let a2 = alpha * alpha;
    let t = sin2 + a2 * cos2;
    a2 * T::splat(FRAC_1_PI) / (t * t)
}

/// The height-correlated Smith visibility V = G₂/(4 N·ω_i N·ω_o) of width `alpha` at the
/// cosines `cos_i` = N·ω_i and `cos_o` = N·ω_o (both positive).
#[inline(always)]
pub fn smith_v<T: Lanes>(alpha: T, cos_i: T, cos_o: T) -> T {
    let a2 = alpha * alpha;
    let rest = T::splat(1.0) - a2;
    let lambda_o = (cos_o * cos_o * rest + a2).sqrt();
    let lambda_i = (cos_i * cos_i * rest + a2).sqrt();
    T::splat(0.5) / (cos_i * lambda_o + cos_o * lambda_i)
}

/// The two direction-dependent scalars of the lobe for unit directions `wo` and `wi` above
/// the unit normal `n` (N·ω_o, N·ω_i > 0; other lanes give meaningless values for the caller
/// to mask): Schlick's weight s = (1 − ω_o·h)⁵ and D(h)·V. One or eight lanes, bit for bit
/// the same.
#[inline(always)]
pub fn ggx_terms<T: Lanes>(alpha: T, n: [T; 3], wo: [T; 3], wi: [T; 3]) -> (T, T) {
    let dot = |a: [T; 3], b: [T; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    // The unnormalised half vector: D is homogeneous of degree 0 in it.
    let h = [wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]];
    let len2 = dot(h, h);
    let cross = [n[1] * h[2] - n[2] * h[1], n[2] * h[0] - n[0] * h[2], n[0] * h[1] - n[1] * h[0]];
    let cos_h = dot(n, h);
    let (cos2, sin2) = (cos_h * cos_h / len2, dot(cross, cross) / len2);
    let s = schlick_weight(dot(wo, h) / len2.sqrt());
    (s, ggx_d(alpha, cos2, sin2) * smith_v(alpha, dot(n, wi), dot(n, wo)))
}

/// The BRDF of [`GlossyModel::Ggx`] from its parameters (`diffuse` = c_diff·(1 − F₀),
/// `f0` = F₀) and the [`ggx_terms`] `(s, dv)` of a pair of directions.
#[inline]
pub fn ggx_brdf(diffuse: Vec3, f0: Vec3, (s, dv): (f32, f32)) -> Vec3 {
    diffuse * ((1.0 - s) * FRAC_1_PI) + (f0 * (1.0 - s) + Vec3::splat(s)) * dv
}

/// [`ggx_terms`] of one pair of `Vec3` directions.
#[inline]
pub fn ggx_terms_vec3(alpha: f32, n: Vec3, wo: Vec3, wi: Vec3) -> (f32, f32) {
    ggx_terms(alpha, n.to_array(), wo.to_array(), wi.to_array())
}

/// Smith's masking G₁ of the direction at cosine `cos` = N·ω to the normal.
#[inline]
fn smith_g1(alpha: f32, cos: f32) -> f32 {
    let a2 = alpha * alpha;
    2.0 * cos / (cos + (a2 + (1.0 - a2) * cos * cos).sqrt())
}

/// A direction ω_i for the unit view `wo` above the unit normal `n`: a microfacet normal h
/// drawn from the GGX distribution of normals visible from `wo` (Heitz 2018), `wo` reflected
/// about it. It may fall below the surface (the caller drops it); its density is
/// [`ggx_pdf`].
pub fn sample_ggx(n: Vec3, wo: Vec3, alpha: f32, u: Vec2) -> Vec3 {
    let (t, b) = n.any_orthonormal_pair();
    let local = Vec3::new(wo.dot(t), wo.dot(b), wo.dot(n));
    // The view in the frame where the GGX ellipsoid is the unit hemisphere.
    let vh = Vec3::new(alpha * local.x, alpha * local.y, local.z).normalize();
    let len2 = vh.x * vh.x + vh.y * vh.y;
    let t1 = if len2 > 0.0 { Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt() } else { Vec3::X };
    let t2 = vh.cross(t1);
    // A point on the projected half disc.
    let r = u.x.sqrt();
    let phi = 2.0 * PI * u.y;
    let p1 = r * phi.cos();
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
    let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    let m = Vec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(0.0)).normalize();
    let h = (t * m.x + b * m.y + n * m.z).normalize();
    (2.0 * wo.dot(h) * h - wo).normalize()
}

/// The density of [`sample_ggx`] at `wi` (both unit and above `n`): G₁(ω_o)·D(h)/(4 N·ω_o).
pub fn ggx_pdf(n: Vec3, wo: Vec3, wi: Vec3, alpha: f32) -> f32 {
    let cos_o = n.dot(wo);
    let h = (wo + wi).normalize_or_zero();
    if cos_o <= 0.0 || h == Vec3::ZERO {
        return 0.0;
    }
    let cos_h = n.dot(h);
    smith_g1(alpha, cos_o) * ggx_d(alpha, cos_h * cos_h, n.cross(h).length_squared()) / (4.0 * cos_o)
}

/// The probability weights with which the BSDF picks the diffuse and the glossy lobe of a
/// [`GlossyModel::Ggx`] surface seen at cosine `cos_o`: their reflectances with Schlick's
/// weight of the view, so a grazing view samples the specular lobe that dominates there.
#[inline]
pub fn ggx_lobe_weights(diffuse: Vec3, f0: Vec3, cos_o: f32) -> (f32, f32) {
    let s = schlick_weight(cos_o);
    (diffuse.max_element() * (1.0 - s), (f0 * (1.0 - s) + Vec3::splat(s)).max_element())
}
