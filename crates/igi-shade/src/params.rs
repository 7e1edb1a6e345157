//! [`BrdfParams`]: what a surface shader computes and the BRDF shaders read.
//!
//! The BRDF at a point is a sum of lobes (paper 3.2), each weighted by its own reflectance:
//!
//! ```text
//! f = diffuse/π  +  glossy · (n+2)/(2π) · cosⁿα  +  mirror · δ_reflect  +  glass · (dielectric)
//! ```
//!
//! with α the angle between ω_i and the mirror direction of ω_o, n = `exponent` (modified
//! Phong, Lafortune & Willems 1994: energy-conserving and reciprocal), and the dielectric a
//! smooth interface of index `ior` that reflects with Fresnel weight F and refracts 1 − F.
//! That is the [`GlossyModel::Phong`] of MTL and the scene files. glTF's metallic-roughness
//! materials choose [`GlossyModel::Ggx`] instead, which replaces the first two terms by the
//! glTF 2.0 BRDF (appendix B; see [`crate::brdf::ggx`]):
//!
//! ```text
//! f = diffuse/π · (1 − s)  +  (glossy · (1 − s) + s) · D(h)·V,    s = (1 − ω_o·h)⁵
//! ```
//!
//! with `glossy` = F₀, `diffuse` = c_diff·(1 − F₀) and the GGX width `alpha`.
//! A surface conserves energy when `diffuse + glossy + mirror + glass ≤ 1` per channel;
//! [`BrdfParams::conserving`] scales a surface that asks for more.

use glam::Vec3;
use igi_simd::{F32x8, Vec3x8};

/// The microfacet model of the glossy lobe: how [`BrdfParams::glossy`] and the lobe's width
/// are read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GlossyModel {
    /// Modified Phong (MTL, scene files, procedural shaders): `glossy` is ρ_s, `exponent` the
    /// lobe's sharpness, and the diffuse lobe is plain Lambert.
    #[default]
    Phong,
    /// The glTF 2.0 metallic-roughness BRDF: GGX with Smith masking and Schlick Fresnel,
    /// `glossy` is F₀, `alpha` the GGX width, and the diffuse lobe is weighted by 1 − s
    /// (see the module documentation and [`crate::brdf::ggx`]).
    Ggx,
}

/// The smallest GGX width the BRDF shaders use: sharper lobes are clamped to it, which keeps
/// D = 1/(πα²) at the peak finite in f32 (glTF roughness 0.03; smoother glTF metals become
/// mirrors in the loader).
pub const MIN_ALPHA: f32 = 1e-3;

/// BRDF parameters of one surface point. See the module documentation for the model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrdfParams {
    /// Lambertian reflectance ρ_d (linear RGB).
    pub diffuse: Vec3,
    /// Reflectance ρ_s of the glossy (modified Phong) lobe.
    pub glossy: Vec3,
    /// Phong exponent n of the glossy lobe (≥ 0; larger is sharper).
    pub exponent: f32,
    /// The glossy lobe's model.
    pub model: GlossyModel,
    /// GGX width α (glTF roughness², in [[`MIN_ALPHA`], 1]) of a [`GlossyModel::Ggx`] lobe.
    pub alpha: f32,
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
            glossy: Vec3::ZERO,
            exponent: 1.0,
            model: GlossyModel::Phong,
            alpha: 1.0,
            mirror: Vec3::ZERO,
            glass: 0.0,
            ior: 1.5,
            shading_normal: n,
            emission: Vec3::ZERO,
        }
    }

    /// True if the surface has a glossy lobe: a Phong lobe of non-zero reflectance, or any
    /// GGX lobe (its Schlick term reflects at grazing angles whatever F₀ is).
    pub fn has_glossy(&self) -> bool {
        self.model == GlossyModel::Ggx || self.glossy.max_element() > 0.0
    }

    /// True if the surface has a lobe the VPLs light (diffuse or glossy).
    pub fn has_non_delta(&self) -> bool {
        self.diffuse.max_element() > 0.0 || self.has_glossy()
    }

    /// The parameters with every reflectance clamped to [0, 1], non-finite values replaced
    /// (reflectances by 0, the exponent and α by 1, the index by 1.5), α clamped to
    /// [[`MIN_ALPHA`], 1], and the lobes scaled down
    /// together where their sum exceeds 1 in some channel, so the surface never creates energy.
    /// One rule for both: this is [`BrdfParams8::conserving`] of one lane.
    pub fn conserving(self) -> Self {
        BrdfParams8::splat(&self).conserving().to_lanes()[0]
    }
}

/// [`BrdfParams`] of eight points, structure of arrays: the output of a
/// [`crate::SurfaceShader`].
#[derive(Clone, Copy, Debug)]
pub struct BrdfParams8 {
    /// Lambertian reflectance ρ_d.
    pub diffuse: Vec3x8,
    /// Reflectance of the glossy lobe.
    pub glossy: Vec3x8,
    /// Phong exponent of the glossy lobe.
    pub exponent: F32x8,
    /// The glossy lobe's model, shared by the eight points (they have one material).
    pub model: GlossyModel,
    /// GGX width α of a [`GlossyModel::Ggx`] lobe.
    pub alpha: F32x8,
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
            glossy: zero,
            exponent: F32x8::splat(1.0),
            model: GlossyModel::Phong,
            alpha: F32x8::splat(1.0),
            mirror: zero,
            glass: F32x8::ZERO,
            ior: F32x8::splat(1.5),
            shading_normal: n,
            emission: zero,
        }
    }

    /// The same parameters in every lane.
    pub fn splat(p: &BrdfParams) -> Self {
        let v = |x: Vec3| Vec3x8::splat(x.to_array());
        Self {
            diffuse: v(p.diffuse),
            glossy: v(p.glossy),
            exponent: F32x8::splat(p.exponent),
            model: p.model,
            alpha: F32x8::splat(p.alpha),
            mirror: v(p.mirror),
            glass: F32x8::splat(p.glass),
            ior: F32x8::splat(p.ior),
            shading_normal: v(p.shading_normal),
            emission: v(p.emission),
        }
    }

    /// [`BrdfParams::conserving`] of every lane.
    pub fn conserving(&self) -> Self {
        let (zero, one) = (F32x8::ZERO, F32x8::splat(1.0));
        let finite = |x: F32x8| x.eq(x) & x.abs().lt(F32x8::splat(f32::INFINITY));
        let unit = |x: F32x8| F32x8::select(finite(x), x.max(zero).min(one), zero);
        let unit3 = |v: Vec3x8| Vec3x8::new(unit(v.x), unit(v.y), unit(v.z));
        let (diffuse, glossy, mirror, glass) =
            (unit3(self.diffuse), unit3(self.glossy), unit3(self.mirror), unit(self.glass));
        let sum = diffuse + glossy + mirror;
        let total = (sum.x.max(sum.y).max(sum.z)) + glass;
        let k = F32x8::select(total.gt(one), one / total, one);
        let exponent =
            F32x8::select(finite(self.exponent), self.exponent.max(zero).min(F32x8::splat(1.0e6)), one);
        let alpha = F32x8::select(finite(self.alpha), self.alpha.max(F32x8::splat(MIN_ALPHA)).min(one), one);
        let ior_ok = finite(self.ior) & self.ior.gt(zero);
        let positive = |x: F32x8| F32x8::select(finite(x), x.max(zero), zero);
        Self {
            diffuse: diffuse * k,
            glossy: glossy * k,
            exponent,
            model: self.model,
            alpha,
            mirror: mirror * k,
            glass: glass * k,
            ior: F32x8::select(ior_ok, self.ior, F32x8::splat(1.5)),
            shading_normal: self.shading_normal,
            emission: Vec3x8::new(
                positive(self.emission.x),
                positive(self.emission.y),
                positive(self.emission.z),
            ),
        }
    }

    /// The eight lanes as scalar parameters.
    pub fn to_lanes(&self) -> [BrdfParams; 8] {
        let v = |x: Vec3x8| {
            let (a, b, c) = (x.x.to_array(), x.y.to_array(), x.z.to_array());
            std::array::from_fn::<Vec3, 8, _>(|i| Vec3::new(a[i], b[i], c[i]))
        };
        let (diffuse, glossy, mirror) = (v(self.diffuse), v(self.glossy), v(self.mirror));
        let (normal, emission) = (v(self.shading_normal), v(self.emission));
        let (exponent, glass, ior) = (self.exponent.to_array(), self.glass.to_array(), self.ior.to_array());
        let alpha = self.alpha.to_array();
        std::array::from_fn(|i| BrdfParams {
            diffuse: diffuse[i],
            glossy: glossy[i],
            exponent: exponent[i],
            model: self.model,
            alpha: alpha[i],
            mirror: mirror[i],
            glass: glass[i],
            ior: ior[i],
            shading_normal: normal[i],
            emission: emission[i],
        })
    }
}
