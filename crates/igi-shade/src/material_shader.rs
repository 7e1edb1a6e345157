//! [`MaterialShader`]: the surface shader of an ordinary material (OBJ/MTL, glTF, PLY, the
//! built-in scenes), mapping its fields onto the BRDF lobes:
//!
//! | material | lobes |
//! |---|---|
//! | `Plastic` | diffuse = `diffuse` × diffuse texture (RGB); glossy = `specular`, `exponent` (MTL `Ks`, `Ns`) |
//! | `Mirror` | mirror = `specular` (white if zero) |
//! | `Glass` | glass = 1 with index `ior` (1.5 if unset or 1) |
//!
//! and emission = `emission` for all. Texture lookups are bilinear with wrap-around.

use crate::{BrdfParams8, ShadingHit8, SurfaceShader};
use glam::{Vec2, Vec3, Vec4};
use igi_scene::{Material, MaterialKind, Texture};
use igi_simd::{F32x8, Vec3x8};
use std::sync::Arc;

/// The surface shader of an ordinary material; see the module documentation.
#[derive(Debug)]
pub struct MaterialShader {
    diffuse: Vec3,
    diffuse_texture: Option<Arc<Texture>>,
    specular: Vec3,
    exponent: f32,
    mirror: Vec3,
    glass: f32,
    ior: f32,
    emission: Vec3,
}

impl MaterialShader {
    /// The shader of `material`, whose texture indices refer to `textures`.
    pub fn new(material: &Material, textures: &[Arc<Texture>]) -> Self {
        let plastic = material.kind == MaterialKind::Plastic;
        let texture = material.diffuse_texture.and_then(|t| textures.get(t as usize)).cloned();
        Self {
            diffuse: if plastic { material.diffuse } else { Vec3::ZERO },
            diffuse_texture: texture.filter(|_| plastic),
            specular: if plastic { material.specular } else { Vec3::ZERO },
            exponent: material.exponent,
            mirror: match material.kind {
                MaterialKind::Mirror if material.specular.max_element() > 0.0 => material.specular,
                MaterialKind::Mirror => Vec3::ONE,
                _ => Vec3::ZERO,
            },
            glass: if material.kind == MaterialKind::Glass { 1.0 } else { 0.0 },
            ior: if material.ior > 0.0 && material.ior != 1.0 { material.ior } else { 1.5 },
            emission: material.emission,
        }
    }
}

impl SurfaceShader for MaterialShader {
    fn shade(&self, hits: &ShadingHit8, out: &mut BrdfParams8) {
        let splat = |v: Vec3| Vec3x8::splat(v.to_array());
        out.diffuse = match &self.diffuse_texture {
            Some(texture) => {
                let (u, v) = (hits.u.to_array(), hits.v.to_array());
                let texels: [[f32; 3]; 8] = std::array::from_fn(|i| {
                    (self.diffuse * bilinear(texture, Vec2::new(u[i], v[i])).truncate()).to_array()
                });
                Vec3x8::from_lanes(texels)
            }
            None => splat(self.diffuse),
        };
        out.specular = splat(self.specular);
        out.exponent = F32x8::splat(self.exponent);
        out.mirror = splat(self.mirror);
        out.glass = F32x8::splat(self.glass);
        out.ior = F32x8::splat(self.ior);
        out.emission = splat(self.emission);
    }
}

/// Bilinear interpolation of the four texels around `uv` (texel centres at half integers, row
/// 0 at v = 0, wrap-around); opaque white for an empty texture or non-finite coordinates.
fn bilinear(tex: &Texture, uv: Vec2) -> Vec4 {
    let (w, h) = (i64::from(tex.width), i64::from(tex.height));
    if w == 0 || h == 0 || tex.texels.len() < (w * h) as usize || !uv.is_finite() {
        return Vec4::ONE;
    }
    let texel =
        |x: i64, y: i64| Vec4::from_array(tex.texels[(y.rem_euclid(h) * w + x.rem_euclid(w)) as usize]);
    let x = (uv.x - uv.x.floor()) * w as f32 - 0.5;
    let y = (uv.y - uv.y.floor()) * h as f32 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (ax, ay) = (x - x0, y - y0);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let top = texel(x0, y0).lerp(texel(x0 + 1, y0), ax);
    let bottom = texel(x0, y0 + 1).lerp(texel(x0 + 1, y0 + 1), ax);
    top.lerp(bottom, ay)
}
