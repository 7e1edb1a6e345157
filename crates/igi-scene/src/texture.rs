//! Image textures: decoding with the `image` crate into linear-light [`Texture`]s, and
//! [`TextureSet`], which loads each (file, colour space) pair once per scene.
//!
//! Policy for textures that cannot be had (missing file, undecodable image): a warning, and
//! the material keeps its constant colour. A texture only changes how a surface looks, while a
//! missing mesh, buffer or material file changes what the scene *is*, so those are errors. Many
//! published scenes reference a texture or two that were never shipped; refusing to render
//! them would help nobody.

use std::collections::HashMap;
use std::collections::hash_map::Entry;
use std::io::Cursor;
use std::path::Path;

use glam::Vec3;
use image::{DynamicImage, ImageFormat, ImageReader, Limits};

use crate::model::{Texture, Wrap};
use crate::report::LoadReport;
use crate::resources;

/// Largest accepted width or height. 16k × 16k RGBA f32 texels are already 4 GiB; anything
/// larger in a scene file is a mistake or an attack.
const MAX_DIMENSION: u32 = 16_384;
/// Bound on the decoder's own allocations.
const MAX_DECODE_BYTES: u64 = 1 << 30;

/// How the stored values of an image relate to linear light.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum ColorSpace {
    /// Colour maps (diffuse, base colour, emissive): 8- and 16-bit values are sRGB-encoded.
    Srgb,
    /// Data maps (bump, height): values are used as they are, scaled to [0, 1].
    Linear,
}

/// Decodes an encoded image (PNG, JPEG, Radiance HDR or OpenEXR) into linear RGBA texels.
/// `name` is used for the texture's name and, if the content is not recognised, to guess the
/// format from its extension.
pub(crate) fn decode(bytes: &[u8], name: &str, space: ColorSpace) -> Result<Texture, String> {
    let mut reader = ImageReader::new(Cursor::new(bytes)).with_guessed_format().map_err(|e| e.to_string())?;
    if reader.format().is_none() {
        if let Some(format) = Path::new(name).extension().and_then(ImageFormat::from_extension) {
            reader.set_format(format);
        }
    }
    let mut limits = Limits::default();
    limits.max_image_width = Some(MAX_DIMENSION);
    limits.max_image_height = Some(MAX_DIMENSION);
    limits.max_alloc = Some(MAX_DECODE_BYTES);
    reader.limits(limits);
    let image = reader.decode().map_err(|e| e.to_string())?;
    Ok(Texture {
        name: name.to_owned(),
        width: image.width(),
        height: image.height(),
        texels: linear_texels(image, space),
        wrap: [Wrap::Repeat; 2],
    })
}

/// Average linear RGB of an encoded image (glTF emissive maps: see `gltf_loader`).
pub(crate) fn mean_rgb(bytes: &[u8], name: &str, space: ColorSpace) -> Result<Vec3, String> {
    let texture = decode(bytes, name, space)?;
    let sum = texture
        .texels
        .iter()
        .fold(glam::DVec3::ZERO, |sum, t| sum + glam::DVec3::new(t[0].into(), t[1].into(), t[2].into()));
    Ok((sum / texture.texels.len().max(1) as f64).as_vec3())
}

fn linear_texels(image: DynamicImage, space: ColorSpace) -> Vec<[f32; 4]> {
    let decode8 = lut8(space);
    match image {
        DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_) => {
            // Float images (HDR, EXR) are linear already, whatever the slot.
            image.into_rgba32f().pixels().map(|p| p.0).collect()
        }
        DynamicImage::ImageLuma16(_)
        | DynamicImage::ImageLumaA16(_)
        | DynamicImage::ImageRgb16(_)
        | DynamicImage::ImageRgba16(_) => image
            .into_rgba16()
            .pixels()
            .map(|p| {
                let [r, g, b, a] = p.0.map(|v| f32::from(v) / 65535.0);
                match space {
                    ColorSpace::Srgb => [srgb_to_linear(r), srgb_to_linear(g), srgb_to_linear(b), a],
                    ColorSpace::Linear => [r, g, b, a],
                }
            })
            .collect(),
        _ => image
            .into_rgba8()
            .pixels()
            .map(|p| {
                let [r, g, b, a] = p.0;
                [
                    decode8[usize::from(r)],
                    decode8[usize::from(g)],
                    decode8[usize::from(b)],
                    f32::from(a) / 255.0,
                ]
            })
            .collect(),
    }
}

/// The 256 linear values of 8-bit channel values: a table, because textures of big scenes
/// have tens of millions of texels and `powf` per channel would dominate their load time.
fn lut8(space: ColorSpace) -> [f32; 256] {
    std::array::from_fn(|v| {
        let x = v as f32 / 255.0;
        match space {
            ColorSpace::Srgb => srgb_to_linear(x),
            ColorSpace::Linear => x,
        }
    })
}

/// The sRGB transfer function, inverted (IEC 61966-2-1): the linear value of an sRGB-encoded
/// value in [0, 1] (clamped to it). Every decoder of the workspace uses this one, so an
/// 8-bit value decodes to the same float everywhere.
pub fn srgb_to_linear(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.04045 { x / 12.92 } else { ((x + 0.055) / 1.055).powf(2.4) }
}

/// The textures of one scene, each loaded once however many materials use it.
#[derive(Debug, Default)]
pub(crate) struct TextureSet {
    textures: Vec<Texture>,
    /// Outcome per source and colour space; failures are remembered so that a missing texture
    /// used by twenty materials gives one warning, not twenty.
    loaded: HashMap<(String, ColorSpace), Option<u32>>,
}

impl TextureSet {
    /// Loads the texture that `referrer` names `reference`, relative to `dir`.
    pub fn file(
        &mut self,
        dir: &Path,
        reference: &str,
        space: ColorSpace,
        referrer: &Path,
        report: &mut LoadReport,
    ) -> Option<u32> {
        let Some(path) = resources::resolve(dir, reference) else {
            let key = (dir.join(reference).display().to_string(), space);
            if let Entry::Vacant(entry) = self.loaded.entry(key) {
                report.warn(referrer, format!("texture `{reference}` not found in {}", dir.display()));
                entry.insert(None);
            }
            return None;
        };
        let key = (path.display().to_string(), space);
        if let Some(&outcome) = self.loaded.get(&key) {
            return outcome;
        }
        let outcome = match resources::read(&path, report) {
            Ok(bytes) => self.insert_decoded(&bytes, &key.0, space, referrer, report),
            Err(err) => {
                report.warn(referrer, format!("texture skipped: {err}"));
                None
            }
        };
        self.loaded.insert(key, outcome);
        outcome
    }

    /// Decodes an in-memory image (glTF buffer views, data URIs) identified by `key`.
    pub fn bytes(
        &mut self,
        key: &str,
        bytes: &[u8],
        space: ColorSpace,
        referrer: &Path,
        report: &mut LoadReport,
    ) -> Option<u32> {
        let key = (key.to_owned(), space);
        if let Some(&outcome) = self.loaded.get(&key) {
            return outcome;
        }
        let outcome = self.insert_decoded(bytes, &key.0, space, referrer, report);
        self.loaded.insert(key, outcome);
        outcome
    }

    fn insert_decoded(
        &mut self,
        bytes: &[u8],
        name: &str,
        space: ColorSpace,
        referrer: &Path,
        report: &mut LoadReport,
    ) -> Option<u32> {
        match decode(bytes, name, space) {
            Ok(texture) => {
                let index = u32::try_from(self.textures.len()).ok()?;
                self.textures.push(texture);
                Some(index)
            }
            Err(err) => {
                report.warn(referrer, format!("texture `{name}` skipped: {err}"));
                None
            }
        }
    }

    /// Sets the wrap modes (along u and v) of texture `index`.
    pub fn set_wrap(&mut self, index: u32, wrap: [Wrap; 2]) {
        if let Some(texture) = self.textures.get_mut(index as usize) {
            texture.wrap = wrap;
        }
    }

    /// The loaded textures, in the order their indices refer to.
    pub fn into_textures(self) -> Vec<Texture> {
        self.textures
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn png(pixels: &[[u8; 4]], width: u32) -> Vec<u8> {
        let image = image::RgbaImage::from_fn(width, pixels.len() as u32 / width, |x, y| {
            image::Rgba(pixels[(y * width + x) as usize])
        });
        let mut bytes = Vec::new();
        image.write_to(&mut Cursor::new(&mut bytes), ImageFormat::Png).unwrap();
        bytes
    }

    #[test]
    fn colour_maps_are_srgb_decoded_and_data_maps_are_not() {
        let bytes = png(&[[255, 128, 0, 255], [10, 20, 30, 64]], 2);
        let colour = decode(&bytes, "t.png", ColorSpace::Srgb).unwrap();
        assert_eq!((colour.width, colour.height), (2, 1));
        assert_eq!(colour.texels[0][0], 1.0);
        assert!((colour.texels[0][1] - 0.2158605).abs() < 1e-6);
        assert!((colour.texels[1][3] - 64.0 / 255.0).abs() < 1e-6, "alpha stays linear");
        let data = decode(&bytes, "t.png", ColorSpace::Linear).unwrap();
        assert!((data.texels[0][1] - 128.0 / 255.0).abs() < 1e-6);
    }

    #[test]
    fn garbage_is_an_error_not_a_panic() {
        assert!(decode(b"\x89PNG\r\n\x1a\nnot really", "x.png", ColorSpace::Srgb).is_err());
        assert!(decode(&[], "x.jpg", ColorSpace::Srgb).is_err());
    }

    #[test]
    fn each_texture_is_loaded_once_and_failures_warn_once() {
        let mut set = TextureSet::default();
        let mut report = LoadReport::default();
        let bytes = png(&[[1, 2, 3, 4]], 1);
        let referrer = Path::new("scene.gltf");
        let a = set.bytes("img0", &bytes, ColorSpace::Srgb, referrer, &mut report);
        let b = set.bytes("img0", &bytes, ColorSpace::Srgb, referrer, &mut report);
        let c = set.bytes("img0", &bytes, ColorSpace::Linear, referrer, &mut report);
        assert_eq!((a, b, c), (Some(0), Some(0), Some(1)));
        let dir = Path::new("/nonexistent-igi-dir");
        for _ in 0..3 {
            assert_eq!(set.file(dir, "x.png", ColorSpace::Srgb, referrer, &mut report), None);
        }
        assert_eq!(report.warnings.len(), 1, "{:?}", report.warnings);
        assert_eq!(set.into_textures().len(), 2);
    }
}
