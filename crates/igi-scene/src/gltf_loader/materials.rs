//! glTF materials (metallic-roughness, emission with its texture per texel, normal maps,
//! transmission, alpha cut-outs) mapped onto [`Material`] (a [`MaterialKind::MetallicRoughness`]
//! keeps glTF's base colour, metallic and roughness factors and textures for the renderer's GGX
//! BRDF), and their textures and images.

use std::path::PathBuf;

use glam::Vec3;

use super::buffers::{Uri, classify_uri};
use super::loader::Loader;
use crate::model::{AlphaMask, CoverageChannel, Material, MaterialKind, Wrap};
use crate::texels::ColorSpace;

impl Loader<'_> {
    pub(super) fn material(&mut self, material: gltf::Material) -> u32 {
        if let Some(&index) = self.materials.get(&material.index()) {
            return index;
        }
        let converted = match material.index() {
            None => Material::default(),
            Some(index) => self.convert_material(&material, index),
        };
        self.scene.materials.push(converted);
        let index = (self.scene.materials.len() - 1) as u32;
        self.materials.insert(material.index(), index);
        index
    }

    fn convert_material(&mut self, material: &gltf::Material, index: usize) -> Material {
        let pbr = material.pbr_metallic_roughness();
        let [r, g, b, a] = pbr.base_color_factor();
        let base = Vec3::new(r, g, b).clamp(Vec3::ZERO, Vec3::ONE);
        let metallic = pbr.metallic_factor().clamp(0.0, 1.0);
        let roughness = pbr.roughness_factor().clamp(0.0, 1.0);
        let diffuse_texture = pbr
            .base_color_texture()
            .and_then(|info| self.texture_info(index, "base colour", &info, ColorSpace::Srgb));
        // Linear: blue is metalness, green roughness (read per texel by the surface shader).
        let metallic_roughness_texture = pbr
            .metallic_roughness_texture()
            .and_then(|info| self.texture_info(index, "metallic-roughness", &info, ColorSpace::Linear));
        let transmission = material.transmission().map_or(0.0, |t| t.transmission_factor());
        let kind = if transmission > 0.0 {
            MaterialKind::Glass
        } else if metallic >= 0.99 && roughness <= 0.01 && metallic_roughness_texture.is_none() {
            // A polished metal: GGX this sharp is a mirror, which the renderer follows as a ray.
            MaterialKind::Mirror
        } else {
            MaterialKind::MetallicRoughness
        };
        let (normal_texture, normal_scale) = match material.normal_texture() {
            Some(info) if info.tex_coord() == 0 => {
                (self.texture(info.texture(), ColorSpace::Linear), info.scale())
            }
            Some(info) => {
                self.report.warn(
                    self.file,
                    format!("materials[{index}]: normal texture uses TEXCOORD_{}; ignored", info.tex_coord()),
                );
                (None, 1.0)
            }
            None => (None, 1.0),
        };
        let emission = Vec3::from(material.emissive_factor()) * material.emissive_strength().unwrap_or(1.0);
        // glTF 2.0, 3.9.3: the emissive texture (sRGB) multiplies emissiveFactor per texel.
        let emission_texture = material
            .emissive_texture()
            .and_then(|info| self.texture_info(index, "emissive", &info, ColorSpace::Srgb));
        // An emissive map that cannot be read gives no emission rather than turning the whole
        // surface into a uniform emitter of `emissiveFactor`.
        let emission = match (material.emissive_texture(), emission_texture) {
            (Some(_), None) => Vec3::ZERO,
            _ => emission,
        };
        Material {
            name: material.name().map_or_else(|| format!("materials[{index}]"), str::to_owned),
            diffuse: base,
            diffuse_texture,
            // A mirror's reflectance (glossy lobes of glTF materials are GGX, from the fields
            // below).
            glossy: if kind == MaterialKind::Mirror { base } else { Vec3::ZERO },
            exponent: 1.0,
            metallic,
            roughness,
            metallic_roughness_texture,
            emission: emission.max(Vec3::ZERO),
            emission_texture,
            bump_texture: None,
            normal_texture,
            normal_scale,
            transparency: if material.alpha_mode() == gltf::material::AlphaMode::Blend {
                (1.0 - a).clamp(0.0, 1.0)
            } else {
                0.0
            },
            // glTF 3.9.4: MASK cuts where baseColorFactor.a × the base colour texture's alpha
            // is below alphaCutoff (default 0.5); OPAQUE ignores alpha, and BLEND, which the
            // renderer does not blend, renders opaque too.
            alpha_mask: (material.alpha_mode() == gltf::material::AlphaMode::Mask).then(|| AlphaMask {
                factor: a,
                texture: diffuse_texture,
                channel: CoverageChannel::Alpha,
                cutoff: material.alpha_cutoff().unwrap_or(0.5),
            }),
            ior: material.ior().filter(|&ior| ior > 0.0).unwrap_or(1.5),
            kind,
            shader: None,
        }
    }

    /// The texture index of the texture of material `index` that `info` refers to (`what`
    /// names it in warnings), or `None` with a warning if it uses a second set of texture
    /// coordinates, which the meshes do not load.
    fn texture_info(
        &mut self,
        index: usize,
        what: &str,
        info: &gltf::texture::Info,
        space: ColorSpace,
    ) -> Option<u32> {
        if info.tex_coord() != 0 {
            self.report.warn(
                self.file,
                format!("materials[{index}]: {what} texture uses TEXCOORD_{}; ignored", info.tex_coord()),
            );
            return None;
        }
        self.texture(info.texture(), space)
    }

    /// The texture index of a glTF texture: its image, with the wrap modes of its sampler.
    /// An image that two samplers wrap differently keeps the modes of the last one read.
    fn texture(&mut self, texture: gltf::Texture, space: ColorSpace) -> Option<u32> {
        let index = self.image(texture.source(), space)?;
        let wrap = |mode: gltf::texture::WrappingMode| match mode {
            gltf::texture::WrappingMode::ClampToEdge => Wrap::Clamp,
            gltf::texture::WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
            gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
        };
        let sampler = texture.sampler();
        self.textures.set_wrap(index, [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())]);
        Some(index)
    }

    /// The encoded bytes of an image, or where to find them.
    fn image_source(&mut self, image: &gltf::Image) -> Option<Result<Vec<u8>, PathBuf>> {
        let at = format!("images[{}]", image.index());
        match image.source() {
            gltf::image::Source::View { view, .. } => {
                let data = self.buffers.get(view.buffer().index())?;
                let end = view.offset().checked_add(view.length())?;
                match data.get(view.offset()..end) {
                    Some(bytes) => Some(Ok(bytes.to_vec())),
                    None => {
                        self.report.warn(self.file, format!("{at}: buffer view out of range; image skipped"));
                        None
                    }
                }
            }
            gltf::image::Source::Uri { uri, .. } => match classify_uri(uri) {
                Ok(Uri::Data(bytes)) => Some(Ok(bytes)),
                Ok(Uri::File(relative)) => Some(Err(PathBuf::from(relative))),
                Err(message) => {
                    self.report.warn(self.file, format!("{at}: {message}; image skipped"));
                    None
                }
            },
        }
    }

    fn image(&mut self, image: gltf::Image, space: ColorSpace) -> Option<u32> {
        match self.image_source(&image)? {
            Ok(bytes) => {
                // One key per embedded image, however the file's path is spelled.
                let file = std::fs::canonicalize(self.file).unwrap_or_else(|_| self.file.to_path_buf());
                let key = format!("{}#images[{}]", file.display(), image.index());
                self.textures.bytes(&key, &bytes, space, self.file, self.report)
            }
            Err(relative) => {
                let dir = self.base_dir?;
                self.textures.file(dir, &relative.to_string_lossy(), space, self.file, self.report)
            }
        }
    }
}
