//! [`Bsdf`]: the lobes of [`BrdfParams`] at one point, as the estimators that follow one
//! direction at a time read them: the VPL random walk and the path tracer evaluate the
//! non-delta lobes ([`Bsdf::f`], [`Bsdf::pdf`]) and sample the whole sum ([`Bsdf::sample`]).
//!
//! A sample first picks one lobe with probability proportional to its largest reflectance
//! channel (for a [`GlossyModel::Ggx`] surface, the diffuse and glossy reflectances weighted
//! by Schlick's weight of the view, [`ggx_lobe_weights`], so the choice depends on ω_o), then
//! a direction from that lobe. Diffuse and glossy directions are weighted by the
//! one-sample mixture density of both non-delta lobes (so the weight is f·cos/pdf of the sum,
//! not of the lobe drawn); a mirror or glass choice is weighted by its reflectance over its
//! probability. The weight of a sample is therefore close to 1 in the brightest channel for
//! any surface, which suits Russian roulette on it.
//!
//! Reflection happens on the side the light arrives from, decided by the geometric normal; the
//! shading normal (turned to that side) gives the cosines and the lobe axes. A direction on the
//! other side of the geometric surface has no reflection (only glass crosses it).

use super::dielectric::{Interface, glass_exit_side, reflect, refract};
use super::ggx::{ggx_brdf, ggx_lobe_weights, ggx_pdf, ggx_terms_vec3, sample_ggx};
use super::lambert::{cosine_hemisphere, cosine_hemisphere_pdf, lambert};
use super::phong::{mirror_direction, phong_lobe, phong_pdf, sample_phong};
use crate::{BrdfParams, GlossyModel};
use glam::{Vec2, Vec3};

/// Which lobe a [`BsdfSample`] came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lobe {
    /// The Lambertian lobe.
    Diffuse,
    /// The glossy lobe (modified Phong or GGX).
    Glossy,
    /// The perfect mirror.
    Mirror,
    /// Fresnel reflection of the glass lobe.
    GlassReflection,
    /// Refraction through the glass lobe.
    GlassTransmission,
}

impl Lobe {
    /// True for the mirror and glass lobes, whose directions have no density.
    pub fn is_delta(self) -> bool {
        !matches!(self, Self::Diffuse | Self::Glossy)
    }
}

/// A sampled direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// Unit direction away from the surface.
    pub wi: Vec3,
    /// The estimator weight: f·|cos θ_i|/pdf for diffuse and glossy directions, the lobe's
    /// reflectance over its probability for mirror and glass.
    pub weight: Vec3,
    /// Solid-angle density of the non-delta lobes at `wi` (diffuse and glossy samples), or the
    /// probability of the discrete choice (mirror and glass).
    pub pdf: f32,
    /// The lobe that produced the sample.
    pub lobe: Lobe,
}

/// The lobes of one surface point. See the module documentation.
#[derive(Clone, Copy, Debug)]
pub struct Bsdf {
    params: BrdfParams,
    ng: Vec3,
    /// Lobe choice probabilities: diffuse, glossy, mirror, glass (sum 1, or all 0); for a
    /// GGX surface the mirror and glass weights before normalisation (see [`Bsdf::choice`]).
    choice: [f32; 4],
}

impl Bsdf {
    /// The BSDF of `params` (made energy-conserving) at a surface of unit geometric normal
    /// `ng`.
    pub fn new(params: BrdfParams, ng: Vec3) -> Self {
        let params = params.conserving();
        let w = [
            params.diffuse.max_element(),
            params.glossy.max_element(),
            params.mirror.max_element(),
            params.glass,
        ];
        let choice = match params.model {
            GlossyModel::Phong => normalised(w),
            GlossyModel::Ggx => w,
        };
        Self { params, ng, choice }
    }

    /// The lobe choice probabilities (diffuse, glossy, mirror, glass) for the view `wo` with
    /// the shading normal `n` on its side: fixed for Phong, view-dependent for GGX.
    #[inline]
    fn choice(&self, wo: Vec3, n: Vec3) -> [f32; 4] {
        match self.params.model {
            GlossyModel::Phong => self.choice,
            GlossyModel::Ggx => {
                let p = &self.params;
                let (wd, wg) = ggx_lobe_weights(p.diffuse, p.glossy, wo.dot(n).clamp(0.0, 1.0));
                normalised([wd, wg, self.choice[2], self.choice[3]])
            }
        }
    }

    /// The (energy-conserving) parameters.
    pub fn params(&self) -> &BrdfParams {
        &self.params
    }

    /// The geometric normal turned to the side of `w`, and the shading normal turned to that
    /// side too.
    fn side(&self, w: Vec3) -> (Vec3, Vec3) {
        let side = if w.dot(self.ng) >= 0.0 { self.ng } else { -self.ng };
        let n = self.params.shading_normal;
        (side, if n.dot(side) >= 0.0 { n } else { -n })
    }

    /// The non-delta BRDF (diffuse plus glossy) for light arriving from `wi` and leaving
    /// toward `wo` (both unit, away from the surface). Zero if they lie on opposite sides of
    /// the geometric surface or below the shading hemisphere.
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let (side, n) = self.side(wo);
        if wi.dot(side) <= 0.0 || wi.dot(n) <= 0.0 || wo.dot(n) <= 0.0 {
            return Vec3::ZERO;
        }
        let p = &self.params;
        if p.model == GlossyModel::Ggx {
            return ggx_brdf(p.diffuse, p.glossy, ggx_terms_vec3(p.alpha, n, wo, wi));
        }
        let mut f = lambert(p.diffuse);
        if p.glossy.max_element() > 0.0 {
            let cos_alpha = mirror_direction(wo, n).dot(wi);
            f += p.glossy * phong_lobe(p.exponent, cos_alpha);
        }
        f
    }

    /// The solid-angle density with which [`Bsdf::sample`] draws `wi` through the diffuse and
    /// glossy lobes (lobe choice included).
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (side, n) = self.side(wo);
        // Directions below the shading hemisphere are never returned by `sample` (f is zero
        // there), so they have no density.
        if wi.dot(side) <= 0.0 || wi.dot(n) <= 0.0 || wo.dot(n) <= 0.0 {
            return 0.0;
        }
        let [pd, ps, ..] = self.choice(wo, n);
        let mut pdf = pd * cosine_hemisphere_pdf(wi.dot(n));
        if ps > 0.0 {
            pdf += ps
                * match self.params.model {
                    GlossyModel::Phong => phong_pdf(self.params.exponent, mirror_direction(wo, n).dot(wi)),
                    GlossyModel::Ggx => ggx_pdf(n, wo, wi, self.params.alpha),
                };
        }
        pdf
    }

    /// Samples a direction of incident light for the outgoing direction `wo` (or, by
    /// reciprocity of the reflection lobes, an outgoing direction for light arriving from
    /// `wo`), with `u_lobe` choosing the lobe and `u` the direction. `None` if the surface is
    /// black or the direction drawn falls below the surface.
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let (side, n) = self.side(wo);
        let [pd, ps, pm, pg] = self.choice(wo, n);
        if u_lobe < pd + ps {
            if wo.dot(n) <= 0.0 {
                return None;
            }
            let (wi, lobe) = if u_lobe < pd {
                (cosine_hemisphere(n, u), Lobe::Diffuse)
            } else {
                let wi = match self.params.model {
                    GlossyModel::Phong => sample_phong(mirror_direction(wo, n), self.params.exponent, u),
                    GlossyModel::Ggx => sample_ggx(n, wo, self.params.alpha, u),
                };
                (wi, Lobe::Glossy)
            };
            let pdf = self.pdf(wo, wi);
            let f = self.f(wo, wi);
            if pdf <= 0.0 || f == Vec3::ZERO {
                return None;
            }
            return Some(BsdfSample { wi, weight: f * (wi.dot(n) / pdf), pdf, lobe });
        }
        if u_lobe < pd + ps + pm {
            let wi = reflect(-wo, n);
            return (wi.dot(side) > 0.0).then(|| BsdfSample {
                wi,
                weight: self.params.mirror / pm,
                pdf: pm,
                lobe: Lobe::Mirror,
            });
        }
        if pg <= 0.0 {
            return None;
        }
        // Fresnel decides between reflection and refraction with the remaining fraction of
        // `u_lobe`, so one number serves both choices.
        let u_fresnel = ((u_lobe - (pd + ps + pm)) / pg).clamp(0.0, 1.0);
        let d = -wo;
        let interface = Interface::new(d, self.params.shading_normal, self.params.ior);
        let refracted = if u_fresnel < interface.reflectance {
            None
        } else {
            refract(d, interface.normal, interface.eta)
        };
        let (wi, lobe) = match refracted {
            Some(t) => (t, Lobe::GlassTransmission),
            None => (reflect(d, interface.normal), Lobe::GlassReflection),
        };
        glass_exit_side(d, wi, self.ng, lobe == Lobe::GlassReflection)?;
        Some(BsdfSample { wi, weight: Vec3::splat(self.params.glass / pg), pdf: pg, lobe })
    }
}

/// `w` scaled to sum 1 (all zero if the sum is not positive).
#[inline]
fn normalised(w: [f32; 4]) -> [f32; 4] {
    let total: f32 = w.iter().sum();
    if total > 0.0 { w.map(|x| x / total) } else { [0.0; 4] }
}
