//! [`ProceduralShader`]: the procedural surface shaders of paper 3.2 (Figure 3's marble, wood,
//! brick and turbulence) built from a scene's [`ShaderDesc`], eight hits at a time.
//!
//! Every pattern is a solid texture of q = `scale` · (object-space position), computed with
//! [`crate::noise`] in eight lanes. A pattern yields a blend factor t in [0, 1] (diffuse =
//! (1 − t) · colour 0 + t · colour 1) and, when the desc asks for bump mapping, the gradient
//! ∇_q h of its height field h. The surface is then shaded as if displaced by `bump` · h along
//! the normal: with g = `bump` · `scale` · ∇_q h (chain rule) the perturbed normal is
//!
//! ```text
//! n′ = normalize(n − (g − (g · n) n))
//! ```
//!
//! (the surface gradient of the displacement tilts the normal away from rising height, Blinn
//! 1978), then nudged into the hemisphere of the geometric normal. The gradient is taken in
//! object space and applied in world space, which is exact for instances that are only
//! translated (as every built-in scene's); a rotated instance would need its rotation here.

mod brick;
mod checker;
mod marble;
mod turbulence;
mod wood;

use glam::Vec3;
use igi_scene::{Pattern, ShaderDesc};
use igi_simd::{F32x8, Vec3x8};

use crate::{BrdfParams8, ShadingHit8, SurfaceShader};

/// What a pattern computes at eight points.
struct Sample {
    /// Blend factor between colour 0 (t = 0) and colour 1 (t = 1).
    t: F32x8,
    /// Gradient ∇_q h of the height field, when bump mapping asked for it and the pattern has
    /// one.
    height_gradient: Option<Vec3x8>,
}

/// A procedural surface shader: one of the [`Pattern`]s with its colours, glossy lobe and bump
/// amplitude, from a scene's [`ShaderDesc`].
#[derive(Clone, Debug)]
pub struct ProceduralShader {
    pattern: Pattern,
    scale: f32,
    colors: [Vec3; 2],
    glossy: Vec3,
    exponent: f32,
    bump: f32,
}

impl ProceduralShader {
    /// The shader `desc` describes.
    pub fn new(desc: &ShaderDesc) -> Self {
        Self {
            pattern: desc.pattern,
            scale: desc.scale,
            colors: desc.colors,
            glossy: desc.glossy,
            exponent: desc.exponent,
            bump: desc.bump,
        }
    }

    fn sample(&self, q: Vec3x8) -> Sample {
        let bump = self.bump != 0.0;
        match self.pattern {
            Pattern::Checker => checker::sample(q),
            Pattern::Marble { octaves, turbulence } => marble::sample(q, octaves, turbulence, bump),
            Pattern::Wood { rings, turbulence } => wood::sample(q, rings, turbulence, bump),
            Pattern::Brick { size, mortar } => brick::sample(q, size, mortar, bump),
            Pattern::Turbulence { octaves } => turbulence::sample(q, octaves, bump),
        }
    }
}

impl SurfaceShader for ProceduralShader {
    fn shade(&self, hits: &ShadingHit8, out: &mut BrdfParams8) {
        let s = F32x8::splat(self.scale);
        let p = hits.object_position;
        let sample = self.sample(Vec3x8::new(p.x * s, p.y * s, p.z * s));
        let [c0, c1] = self.colors;
        // (1 − t) a + t b: exactly a at t = 0 and exactly b at t = 1.
        let rest = F32x8::splat(1.0) - sample.t;
        let blend = |a: f32, b: f32| sample.t.mul_add(F32x8::splat(b), rest * F32x8::splat(a));
        out.diffuse = Vec3x8::new(blend(c0.x, c1.x), blend(c0.y, c1.y), blend(c0.z, c1.z));
        out.glossy = Vec3x8::splat(self.glossy.to_array());
        out.exponent = F32x8::splat(self.exponent);
        if let Some(grad) = sample.height_gradient {
            let g = grad * F32x8::splat(self.bump * self.scale);
            out.shading_normal = bumped_normal(out.shading_normal, hits.geometric_normal, g);
        }
    }
}

/// Smallest cosine allowed between a bumped normal and the geometric normal.
const MIN_COS_TO_GEOMETRIC: f32 = 0.02;

/// `normalize(n − (g − (g · n) n))`, moved into the hemisphere of the geometric normal `ng`
/// where a strong bump tips it over (by adding enough of `ng` for a cosine of at least
/// [`MIN_COS_TO_GEOMETRIC`] before normalising). `n` and `ng` are unit vectors.
fn bumped_normal(n: Vec3x8, ng: Vec3x8, g: Vec3x8) -> Vec3x8 {
    let tangential = g - n * g.dot(n);
    // |n − tangential| ≥ 1 since the two are orthogonal: the normalisation is safe.
    let bent = (n - tangential).normalize();
    let cos = bent.dot(ng);
    let min = F32x8::splat(MIN_COS_TO_GEOMETRIC);
    let fixed = (bent + ng * (min - cos)).normalize();
    Vec3x8::select(cos.lt(min), fixed, bent)
}

/// A smooth periodic band of period 1: 1 at integers, 0 at half-integers, C¹ (a smoothstep of
/// the triangle wave |2 fract(s) − 1|). Marble veins and wood rings use it where Perlin's
/// originals use a sine: it costs a floor and five multiply-adds.
fn band(s: F32x8) -> F32x8 {
    let tri = (F32x8::splat(2.0) * (s - s.floor()) - F32x8::splat(1.0)).abs();
    tri * tri * F32x8::splat(-2.0).mul_add(tri, F32x8::splat(3.0))
}

/// `v` clamped to [0, 1].
fn saturate(v: F32x8) -> F32x8 {
    F32x8::splat(1.0).min(F32x8::ZERO.max(v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn band_is_periodic_and_bounded() {
        let s = F32x8::from_array([0.0, 0.5, 1.0, -1.0, 0.25, 3.75, -0.5, 2.0]);
        assert_eq!(band(s).to_array(), [1.0, 0.0, 1.0, 1.0, 0.5, 0.5, 0.0, 1.0]);
    }

    #[test]
    fn bumped_normal_stays_in_the_geometric_hemisphere() {
        let n = Vec3x8::splat([0.0, 0.0, 1.0]);
        let g = Vec3x8::from_lanes([
            [100.0, 0.0, 0.0],
            [0.0, 0.0, 5.0],
            [0.0; 3],
            [0.3, -0.2, 0.0],
            [-1e4, 3e3, 0.0],
            [0.0, -2.0, -9.0],
            [1.0, 1.0, 1.0],
            [0.0, 1e-3, 0.0],
        ]);
        let out = bumped_normal(n, n, g);
        for i in 0..8 {
            let v = Vec3::from(out.lane(i));
            assert!((v.length() - 1.0).abs() < 1e-6 && v.z >= MIN_COS_TO_GEOMETRIC * 0.999, "{v}");
        }
        assert_eq!(out.lane(2), [0.0, 0.0, 1.0], "no gradient, no change");
        assert_eq!(out.lane(1), [0.0, 0.0, 1.0], "a gradient along n does not tilt");
    }
}
