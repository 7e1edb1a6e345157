//! [`ShaderTable`]: the surface shader of every material of a scene, built once when the scene
//! is prepared: a material's procedural `[[shader]]` ([`ProceduralShader`]) if it has one,
//! else its [`MaterialShader`]. Textures are shared between the materials that use them.

use crate::{MaterialShader, ProceduralShader, SurfaceShader};
use igi_scene::{Material, Texture};
use std::sync::Arc;

/// One surface shader per material, in the order of the scene's materials.
#[derive(Debug)]
pub struct ShaderTable {
    shaders: Vec<Arc<dyn SurfaceShader>>,
}

impl ShaderTable {
    /// The shaders of `materials`, whose texture indices refer to `textures`.
    pub fn new(materials: &[Material], textures: &[Texture]) -> Self {
        let textures: Vec<Arc<Texture>> = textures.iter().cloned().map(Arc::new).collect();
        let shaders = materials
            .iter()
            .map(|m| -> Arc<dyn SurfaceShader> {
                match &m.shader {
                    Some(desc) => Arc::new(ProceduralShader::new(desc)),
                    None => Arc::new(MaterialShader::new(m, &textures)),
                }
            })
            .collect();
        Self { shaders }
    }

    /// The shaders, indexed by material.
    pub fn into_shaders(self) -> Vec<Arc<dyn SurfaceShader>> {
        self.shaders
    }
}
