//! [`MaterialShader`]: the surface shader of an ordinary material (OBJ/MTL, glTF, PLY, the
//! built-in scenes), mapping its fields onto the BRDF lobes:
//!
//! | material | lobes |
//! |---|---|
//! | `Plastic` | diffuse = `diffuse` × diffuse texture (RGB); glossy = `glossy`, `exponent` (MTL `Ks`, `Ns`) |
//! | `MetallicRoughness` | the GGX model ([`crate::brdf::ggx`]) per hit, from base = `diffuse` × base colour texture (RGB), metallic = `metallic` × texture B, roughness = `roughness` × texture G (glTF `metallicRoughnessTexture`): diffuse = base·(1 − metallic)·(1 − F₀), glossy = F₀ = mix(0.04, base, metallic), α = roughness² ([`metallic_roughness`]) |
//! | `Mirror` | mirror = `glossy` (white if zero) |
//! | `Glass` | glass = 1 with index `ior` (1.5 if unset or 1) |
//!
//! and emission = `emission` × the emission texture (RGB, glTF `emissiveTexture`, MTL `map_Ke`)
//! for all, so the camera sees an emissive map texel by texel; a bump texture (MTL `bump`, `map_bump`) bends the
//! shading normal ([`crate::bump`]), and so does a tangent-space normal map (glTF
//! `normalTexture`, tangent frame from ∂p/∂u; see [`normal_mapped`]). The
//! metallic-roughness mapping runs eight hits at a time after the texture lookups, so every
//! texel of the base colour and metallic-roughness maps gives its own BRDF.
//!
//! Textures are filtered trilinearly: the mipmap level is the one whose texels are as wide as
//! the camera ray's footprint at the hit ([`ShadingHit8::footprint`]), measured against the
//! world size of a texel (from |∂p/∂u × ∂p/∂v|). Hits without a footprint (VPL walk, path
//! tracer) read the full-resolution level.

use crate::bump::bump_normal;
use crate::texture::MipMap;
use crate::{BrdfParams, BrdfParams8, GlossyModel, ShadingHit8, SurfaceShader};
use glam::{Vec2, Vec3};
use igi_scene::{Material, MaterialKind};
use igi_simd::{F32x8, Vec3x8};
use std::sync::Arc;

/// The surface shader of an ordinary material; see the module documentation.
#[derive(Debug)]
pub struct MaterialShader {
    diffuse: Vec3,
    diffuse_texture: Option<Arc<MipMap>>,
    bump_texture: Option<Arc<MipMap>>,
    normal_texture: Option<Arc<MipMap>>,
    normal_scale: f32,
    glossy: Vec3,
    exponent: f32,
    model: GlossyModel,
    metallic: f32,
    roughness: f32,
    metallic_roughness_texture: Option<Arc<MipMap>>,
    mirror: Vec3,
    glass: f32,
    ior: f32,
    emission: Vec3,
    emission_texture: Option<Arc<MipMap>>,
}

impl MaterialShader {
    /// The shader of `material`, whose texture indices refer to `maps` (`None`: a texture
    /// no material reads).
    pub fn new(material: &Material, maps: &[Option<Arc<MipMap>>]) -> Self {
        let ggx = material.kind == MaterialKind::MetallicRoughness;
        let plastic = ggx || material.kind == MaterialKind::Plastic;
        let map = |t: Option<u32>| t.and_then(|t| maps.get(t as usize)).cloned().flatten();
        Self {
            diffuse: if plastic { material.diffuse } else { Vec3::ZERO },
            diffuse_texture: map(material.diffuse_texture).filter(|_| plastic),
            bump_texture: map(material.bump_texture),
            normal_texture: map(material.normal_texture),
            normal_scale: material.normal_scale,
            glossy: if plastic && !ggx { material.glossy } else { Vec3::ZERO },
            exponent: material.exponent,
            model: if ggx { GlossyModel::Ggx } else { GlossyModel::Phong },
            metallic: material.metallic,
            roughness: material.roughness,
            metallic_roughness_texture: map(material.metallic_roughness_texture).filter(|_| ggx),
            mirror: match material.kind {
                MaterialKind::Mirror if material.glossy.max_element() > 0.0 => material.glossy,
                MaterialKind::Mirror => Vec3::ONE,
                _ => Vec3::ZERO,
            },
            glass: if material.kind == MaterialKind::Glass { 1.0 } else { 0.0 },
            ior: if material.ior > 0.0 && material.ior != 1.0 { material.ior } else { 1.5 },
            emission: material.emission,
            emission_texture: map(material.emission_texture),
        }
    }
}

/// The normal that a tangent-space normal-map texel `rgb` (each channel 2c − 1, X and Y times
/// `scale`) gives a surface of unit normal `n` whose u grows along `dpdu`: X along the tangent
/// (∂p/∂u made orthogonal to n), Y along n × tangent (toward decreasing v, glTF's image-up),
/// Z along n. Returns `n` where the tangent or the texel is degenerate.
fn normal_mapped(rgb: Vec3, scale: f32, n: Vec3, dpdu: Vec3) -> Vec3 {
    let t = (dpdu - n * n.dot(dpdu)).normalize_or_zero();
    let local = 2.0 * rgb - Vec3::ONE;
    let local = Vec3::new(local.x * scale, local.y * scale, local.z);
    let mapped = (t * local.x + n.cross(t) * local.y + n * local.z).normalize_or_zero();
    if t == Vec3::ZERO || mapped == Vec3::ZERO || !mapped.is_finite() { n } else { mapped }
}

/// The glTF metallic-roughness mapping of eight hits (glTF 2.0 appendix B, as
/// [`crate::brdf::ggx`] reads it): from the base colour, metallic and perceptual roughness
/// (each in [0, 1]) the diffuse reflectance c_diff·(1 − F₀) with c_diff = base·(1 − metallic),
/// the glossy reflectance F₀ = mix(0.04, base, metallic), and the GGX width α = roughness².
pub fn metallic_roughness(base: Vec3x8, metallic: F32x8, roughness: F32x8) -> (Vec3x8, Vec3x8, F32x8) {
    let one = F32x8::splat(1.0);
    let dielectric = one - metallic;
    let f0 = base * metallic + Vec3x8::splat([0.04; 3]) * dielectric;
    let c_diff = base * dielectric;
    let diffuse = Vec3x8::new(c_diff.x * (one - f0.x), c_diff.y * (one - f0.y), c_diff.z * (one - f0.z));
    (diffuse, f0, roughness * roughness)
}

/// The level of detail of `map` for a footprint of `footprint` world units where the texture
/// tile [0, 1]² covers `tile_area` world units².
#[inline]
fn lod(map: &MipMap, footprint: f32, tile_area: f32) -> f32 {
    let (w, h) = map.size();
    let texel = (tile_area / (w as f32 * h as f32)).sqrt();
    if texel > 0.0 { map.lod(footprint / texel) } else { 0.0 }
}

impl SurfaceShader for MaterialShader {
    fn uniform(&self) -> Option<BrdfParams> {
        let textured = self.diffuse_texture.is_some()
            || self.emission_texture.is_some()
            || self.bump_texture.is_some()
            || self.normal_texture.is_some()
            || self.metallic_roughness_texture.is_some();
        let mut params = BrdfParams {
            diffuse: self.diffuse,
            glossy: self.glossy,
            exponent: self.exponent,
            model: self.model,
            alpha: 1.0,
            mirror: self.mirror,
            glass: self.glass,
            ior: self.ior,
            shading_normal: Vec3::Z,
            emission: self.emission,
        };
        if self.model == GlossyModel::Ggx {
            let (diffuse, glossy, alpha) = metallic_roughness(
                Vec3x8::splat(self.diffuse.to_array()),
                F32x8::splat(self.metallic),
                F32x8::splat(self.roughness),
            );
            (params.diffuse, params.glossy) = (Vec3::from(diffuse.lane(0)), Vec3::from(glossy.lane(0)));
            params.alpha = alpha.lane(0);
        }
        (!textured).then_some(params)
    }

    fn shade(&self, hits: &ShadingHit8, out: &mut BrdfParams8) {
        let splat = |v: Vec3| Vec3x8::splat(v.to_array());
        out.glossy = splat(self.glossy);
        out.exponent = F32x8::splat(self.exponent);
        out.mirror = splat(self.mirror);
        out.glass = F32x8::splat(self.glass);
        out.ior = F32x8::splat(self.ior);
        out.emission = splat(self.emission);
        out.diffuse = splat(self.diffuse);
        out.model = self.model;
        if self.diffuse_texture.is_none()
            && self.emission_texture.is_none()
            && self.bump_texture.is_none()
            && self.normal_texture.is_none()
            && self.metallic_roughness_texture.is_none()
        {
            if self.model == GlossyModel::Ggx {
                let (metallic, roughness) = (F32x8::splat(self.metallic), F32x8::splat(self.roughness));
                (out.diffuse, out.glossy, out.alpha) = metallic_roughness(out.diffuse, metallic, roughness);
            }
            return;
        }
        let (u, v, footprint) = (hits.u.to_array(), hits.v.to_array(), hits.footprint.to_array());
        let tile_area = hits.dpdu.cross(hits.dpdv).length().to_array();
        let (dpdu, dpdv) = (hits.dpdu.to_lanes(), hits.dpdv.to_lanes());
        let active = hits.active.bitmask();
        if let Some(map) = &self.diffuse_texture {
            let mut rgb = [[0.0f32; 3]; 8];
            for (i, c) in rgb.iter_mut().enumerate().filter(|(i, _)| active & (1 << i) != 0) {
                let texel = map.trilinear(Vec2::new(u[i], v[i]), lod(map, footprint[i], tile_area[i]));
                *c = (self.diffuse * texel.truncate()).to_array();
            }
            out.diffuse = Vec3x8::from_lanes(rgb);
        }
        if let Some(map) = &self.emission_texture {
            let mut rgb = [[0.0f32; 3]; 8];
            for (i, c) in rgb.iter_mut().enumerate().filter(|(i, _)| active & (1 << i) != 0) {
                let texel = map.trilinear(Vec2::new(u[i], v[i]), lod(map, footprint[i], tile_area[i]));
                *c = (self.emission * texel.truncate()).to_array();
            }
            out.emission = Vec3x8::from_lanes(rgb);
        }
        if let Some(map) = &self.bump_texture {
            out.shading_normal = map_active_lanes(hits.shading_normal, active, |i, ns| {
                let (dpdu, dpdv) = (Vec3::from(dpdu[i]), Vec3::from(dpdv[i]));
                bump_normal(map, Vec2::new(u[i], v[i]), lod(map, footprint[i], tile_area[i]), ns, dpdu, dpdv)
            });
        }
        if let Some(map) = &self.normal_texture {
            out.shading_normal = map_active_lanes(out.shading_normal, active, |i, ns| {
                let texel = map.trilinear(Vec2::new(u[i], v[i]), lod(map, footprint[i], tile_area[i]));
                normal_mapped(texel.truncate(), self.normal_scale, ns, Vec3::from(dpdu[i]))
            });
        }
        if self.model == GlossyModel::Ggx {
            let (mut metallic, mut roughness) = ([self.metallic; 8], [self.roughness; 8]);
            if let Some(map) = &self.metallic_roughness_texture {
                for i in (0..8).filter(|i| active & (1 << i) != 0) {
                    let texel = map.trilinear(Vec2::new(u[i], v[i]), lod(map, footprint[i], tile_area[i]));
                    // glTF: blue is metalness, green is roughness (linear).
                    metallic[i] *= texel.z;
                    roughness[i] *= texel.y;
                }
            }
            let (metallic, roughness) = (F32x8::from_array(metallic), F32x8::from_array(roughness));
            (out.diffuse, out.glossy, out.alpha) = metallic_roughness(out.diffuse, metallic, roughness);
        }
    }
}

/// `v` with lane `i` replaced by `f(i, lane i)` where bit `i` of `active` is set.
fn map_active_lanes(v: Vec3x8, active: u32, mut f: impl FnMut(usize, Vec3) -> Vec3) -> Vec3x8 {
    let mut lanes = v.to_lanes();
    for (i, lane) in lanes.iter_mut().enumerate().filter(|(i, _)| active & (1 << i) != 0) {
        *lane = f(i, Vec3::from(*lane)).to_array();
    }
    Vec3x8::from_lanes(lanes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use igi_scene::Texture;
    use igi_simd::{I32x8, M32x8};

    /// Eight hits on a flat +Z surface at texture coordinates `u` (v = 0.5), a unit texture
    /// tile per unit of world space, footprint 0 (full resolution).
    fn hits_at(u: [f32; 8]) -> ShadingHit8 {
        let v3 = |v: Vec3| Vec3x8::splat(v.to_array());
        ShadingHit8 {
            position: v3(Vec3::ZERO),
            object_position: v3(Vec3::ZERO),
            geometric_normal: v3(Vec3::Z),
            shading_normal: v3(Vec3::Z),
            u: F32x8::from_array(u),
            v: F32x8::splat(0.5),
            dpdu: v3(Vec3::X),
            dpdv: v3(Vec3::Y),
            footprint: F32x8::ZERO,
            object: I32x8::splat(0),
            active: M32x8::ALL,
            material: 0,
            time: 0.0,
        }
    }

    #[test]
    fn metallic_roughness_texture_sets_f0_diffuse_and_alpha_per_texel() {
        // Two texels: left metal (B = 1) with roughness 0.2 (G), right dielectric (B = 0) with
        // roughness 1; R and A are ignored, as glTF says.
        let texture = Texture::from_linear("mr", 2, 1, vec![[0.7, 0.2, 1.0, 0.3], [0.1, 1.0, 0.0, 0.9]]);
        let maps = [Some(Arc::new(MipMap::new(&texture)))];
        let base = Vec3::new(0.9, 0.5, 0.1);
        let material = Material {
            kind: MaterialKind::MetallicRoughness,
            diffuse: base,
            metallic: 1.0,
            roughness: 1.0,
            metallic_roughness_texture: Some(0),
            ..Material::default()
        };
        let shader = MaterialShader::new(&material, &maps);
        assert_eq!(shader.uniform(), None, "a textured material is shaded per hit");
        let mut out = BrdfParams8::black(Vec3x8::splat([0.0, 0.0, 1.0]));
        // Texel centres are at u = 0.25 and 0.75.
        shader.shade(&hits_at([0.25, 0.75, 0.25, 0.75, 0.25, 0.75, 0.25, 0.75]), &mut out);
        assert_eq!(out.model, GlossyModel::Ggx);
        for (i, p) in out.to_lanes().iter().enumerate() {
            let close = |a: Vec3, b: Vec3| (a - b).abs().max_element() < 1e-6;
            if i % 2 == 0 {
                // Metal: F₀ = base, no diffuse, α = 0.2².
                assert!(close(p.glossy, base) && close(p.diffuse, Vec3::ZERO), "lane {i}: {p:?}");
                assert!((p.alpha - 0.04).abs() < 1e-6, "lane {i}: {p:?}");
            } else {
                // Dielectric: F₀ = 0.04, diffuse = base·(1 − 0.04), α = 1.
                assert!(
                    close(p.glossy, Vec3::splat(0.04)) && close(p.diffuse, base * 0.96),
                    "lane {i}: {p:?}"
                );
                assert!((p.alpha - 1.0).abs() < 1e-6, "lane {i}: {p:?}");
            }
        }
        // Without the texture, the factors alone: the uniform parameters agree with `shade`.
        let plain = MaterialShader::new(&Material { metallic_roughness_texture: None, ..material }, &maps);
        let uniform = plain.uniform().expect("untextured");
        let mut out = BrdfParams8::black(Vec3x8::splat([0.0, 0.0, 1.0]));
        plain.shade(&hits_at([0.5; 8]), &mut out);
        let lane = out.to_lanes()[0];
        assert_eq!((uniform.diffuse, uniform.glossy, uniform.alpha), (lane.diffuse, lane.glossy, lane.alpha));
        assert_eq!((uniform.glossy, uniform.alpha, uniform.model), (base, 1.0, GlossyModel::Ggx));
    }

    #[test]
    fn emission_is_the_factor_times_the_texel_at_each_hit() {
        // Left texel black, right texel orange; factor (2, 3, 4).
        let texture = Texture::from_linear("glow", 2, 1, vec![[0.0, 0.0, 0.0, 1.0], [1.0, 0.5, 0.25, 1.0]]);
        let maps = [Some(Arc::new(MipMap::new(&texture)))];
        let factor = Vec3::new(2.0, 3.0, 4.0);
        let material = Material { emission: factor, emission_texture: Some(0), ..Material::default() };
        let shader = MaterialShader::new(&material, &maps);
        assert_eq!(shader.uniform(), None, "an emission map is read per hit");
        let mut out = BrdfParams8::black(Vec3x8::splat([0.0, 0.0, 1.0]));
        shader.shade(&hits_at([0.25, 0.75, 0.25, 0.75, 0.25, 0.75, 0.25, 0.75]), &mut out);
        for (i, p) in out.to_lanes().iter().enumerate() {
            let want = if i % 2 == 0 { Vec3::ZERO } else { Vec3::new(2.0, 1.5, 1.0) };
            assert!((p.emission - want).abs().max_element() < 1e-6, "lane {i}: {p:?}");
        }
    }

    #[test]
    fn a_flat_normal_map_keeps_the_normal_and_a_tilted_texel_tilts_it_along_u() {
        let n = Vec3::new(0.0, 0.6, 0.8);
        let dpdu = Vec3::new(2.0, 0.0, 0.0);
        let flat = normal_mapped(Vec3::new(0.5, 0.5, 1.0), 1.0, n, dpdu);
        assert!((flat - n).length() < 1e-6, "{flat}");
        // (1, 0.5, 0.5): X = 1, Y = 0, Z = 0: the tangent itself.
        let along_u = normal_mapped(Vec3::new(1.0, 0.5, 0.5), 1.0, n, dpdu);
        assert!((along_u - Vec3::X).length() < 1e-6, "{along_u}");
        // Scale 0 flattens any texel to the normal.
        let flattened = normal_mapped(Vec3::new(0.9, 0.1, 0.7), 0.0, n, dpdu);
        assert!((flattened - n).length() < 1e-6, "{flattened}");
    }
}
