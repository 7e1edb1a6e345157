//! [`ShaderTable`]: the surface shader of every material of a scene, built once when the scene
//! is prepared: a material's procedural `[[shader]]` ([`ProceduralShader`]) if it has one,
//! else its [`MaterialShader`]. Each texture a material reads is turned into a [`MipMap`] once
//! and shared between the materials that use it; the renderer's light sampling reads the
//! same pyramids of the emission textures and the alpha cut-outs' masks
//! ([`ShaderTable::maps`]).

use crate::texture::MipMap;
use crate::{MaterialShader, ProceduralShader, SurfaceShader};
use igi_scene::{Material, Texture};
use std::sync::Arc;

/// One surface shader per material, in the order of the scene's materials.
#[derive(Debug)]
pub struct ShaderTable {
    shaders: Vec<Arc<dyn SurfaceShader>>,
    maps: Vec<Option<Arc<MipMap>>>,
}

impl ShaderTable {
    /// The shaders of `materials`, whose texture indices refer to `textures`.
    pub fn new(materials: &[Material], textures: &[Texture]) -> Self {
        // Only the textures some material reads get a pyramid (the sky's image, say, does not);
        // the renderer reads a cut-out's mask whatever shades the surface.
        let used = |t: usize| {
            materials.iter().any(|m| {
                m.alpha_mask.is_some_and(|mask| mask.texture == Some(t as u32))
                    || (m.shader.is_none()
                        && [
                            m.diffuse_texture,
                            m.emission_texture,
                            m.bump_texture,
                            m.normal_texture,
                            m.metallic_roughness_texture,
                        ]
                        .contains(&Some(t as u32)))
            })
        };
        let maps: Vec<Option<Arc<MipMap>>> =
            textures.iter().enumerate().map(|(i, t)| used(i).then(|| Arc::new(MipMap::new(t)))).collect();
        let shaders = materials
            .iter()
            .map(|m| -> Arc<dyn SurfaceShader> {
                match &m.shader {
                    Some(desc) => Arc::new(ProceduralShader::new(desc)),
                    None => Arc::new(MaterialShader::new(m, &maps)),
                }
            })
            .collect();
        Self { shaders, maps }
    }

    /// The pyramid of each texture, indexed as the scene's textures (`None` for a texture no
    /// material shader reads).
    pub fn maps(&self) -> &[Option<Arc<MipMap>>] {
        &self.maps
    }

    /// The shaders, indexed by material.
    pub fn into_shaders(self) -> Vec<Arc<dyn SurfaceShader>> {
        self.shaders
    }
}
