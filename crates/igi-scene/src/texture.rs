//! Image textures: decoding with the `image` crate into compact [`Image`]s, and
//! [`TextureSet`], the textures of one scene: each file decoded once, whatever the colour
//! spaces, slots and spellings of its path that refer to it, within a scene-wide memory budget.
//!
//! Policy for textures that cannot be had (missing file, undecodable image): a warning, and
//! the material keeps its constant colour. A texture only changes how a surface looks, while a
//! missing mesh, buffer or material file changes what the scene *is*, so those are errors. Many
//! published scenes reference a texture or two that were never shipped; refusing to render
//! them would help nobody.
//!
//! Memory: an image is checked against the decoder's cap and against what is left of the
//! scene's budget ([`LoadOptions::texture_budget`](crate::LoadOptions)) from its header,
//! before any texel is allocated; texels are decoded straight into their final storage (8-bit
//! images stay 8-bit, see [`crate::texels`]). An image that does not fit what is left of the
//! budget is decoded once and kept at the largest half-size level that fits, with a warning.

use std::collections::HashMap;
use std::collections::hash_map::Entry;
use std::io::Cursor;
use std::path::Path;
use std::sync::Arc;

use image::{ColorType, ImageDecoder, ImageFormat, ImageReader, Limits};

use crate::error::SceneError;
use crate::model::{Scene, Texture, Wrap};
use crate::report::LoadReport;
use crate::resources;
use crate::texels::{ColorSpace, Image, Texels};

/// Largest accepted width or height.
const MAX_DIMENSION: u32 = 16_384;
/// Bound on one decode's allocations (the decoder's and the decoded texels): a 16k × 16k
/// 8-bit RGBA image, the largest that [`MAX_DIMENSION`] allows, just fits.
const MAX_DECODE_BYTES: u64 = 1 << 30;
/// Default scene-wide bound on the memory of all textures with their mipmaps.
pub const DEFAULT_TEXTURE_BUDGET: u64 = 4 << 30;
/// What the renderer builds per texel of a sky image besides the texture itself, charged to
/// the texture budget with it: the radiance of each texel (three 32-bit floats) and its
/// sampling table (a cumulative and a probability value per texel, 32-bit each). A 16k² sky
/// is five times its texels.
pub const SKY_BYTES_PER_TEXEL: u64 = 20;

/// Bytes of a texture with its mipmap: the coarser levels add up to a third of the finest.
fn with_mipmap(bytes: u64) -> u64 {
    bytes + bytes / 3
}

/// A mebibyte figure for messages.
fn mib(bytes: u64) -> String {
    format!("{:.1} MiB", bytes as f64 / f64::from(1 << 20))
}

/// Decodes an encoded image (PNG, JPEG, Radiance HDR or OpenEXR). `name` is used, if the
/// content is not recognised, to guess the format from its extension. `budget` bounds the
/// bytes the image and its mipmap may keep, with `extra_per_texel` bytes more per texel for
/// what the renderer derives from it ([`SKY_BYTES_PER_TEXEL`] for a sky, else 0): a larger
/// image is halved until it fits (the returned message says so), and one that cannot fit even
/// at 1 × 1 is refused before decoding.
pub(crate) fn decode(
    bytes: &[u8],
    name: &str,
    budget: u64,
    extra_per_texel: u64,
) -> Result<(Image, Option<String>), String> {
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
    let decoder = reader.into_decoder().map_err(|e| e.to_string())?;
    let (width, height) = decoder.dimensions();
    let per_texel = storage_bytes(decoder.color_type())?;
    let stored = u64::from(width) * u64::from(height) * per_texel;
    let needed = stored.max(decoder.total_bytes());
    if needed > MAX_DECODE_BYTES {
        return Err(format!(
            "{width}x{height} needs {} to decode, more than the limit of {}",
            mib(needed),
            mib(MAX_DECODE_BYTES)
        ));
    }
    // How many times the image must be halved (as a mipmap level is: ⌈w/2⌉ × ⌈h/2⌉) to fit
    // what is left of the budget.
    let cost = |w: u32, h: u32| {
        let texels = u64::from(w) * u64::from(h);
        with_mipmap(texels * per_texel) + texels * extra_per_texel
    };
    let (mut w, mut h, mut halvings) = (width, height, 0);
    while cost(w, h) > budget {
        if w == 1 && h == 1 {
            return Err(format!(
                "{width}x{height} ({}) does not fit what is left of the scene's texture budget ({})",
                mib(cost(width, height)),
                mib(budget)
            ));
        }
        (w, h, halvings) = (w.div_ceil(2), h.div_ceil(2), halvings + 1);
    }
    let mut image = Image { width, height, texels: read_texels(decoder)? };
    for _ in 0..halvings {
        image = image.half();
    }
    let note = (halvings > 0).then(|| {
        format!(
            "{width}x{height} ({} with mipmaps{}) exceeds what is left of the scene's texture budget ({}); \
             downscaled to {}x{}",
            mib(cost(width, height)),
            if extra_per_texel > 0 { " and sampling tables" } else { "" },
            mib(budget),
            image.width,
            image.height
        )
    });
    Ok((image, note))
}

/// Bytes per texel of the storage that decoded images of `color` get.
fn storage_bytes(color: ColorType) -> Result<u64, String> {
    match color {
        ColorType::L8 | ColorType::La8 | ColorType::Rgb8 | ColorType::Rgba8 => Ok(4),
        ColorType::L16 | ColorType::La16 | ColorType::Rgb16 | ColorType::Rgba16 => Ok(8),
        ColorType::Rgb32F | ColorType::Rgba32F => Ok(16),
        other => Err(format!("unsupported pixel format {other:?}")),
    }
}

/// Reads the decoder's pixels into RGBA storage. 8-bit pixels are read straight into the
/// final buffer and widened to four channels in place, so a decode allocates its texels once.
/// The colour space is set later, by the view ([`Texels::in_space`]).
fn read_texels(decoder: impl ImageDecoder) -> Result<Texels, String> {
    let color = decoder.color_type();
    let (width, height) = decoder.dimensions();
    let n = width as usize * height as usize;
    let channels = usize::from(color.channel_count());
    match color {
        ColorType::L8 | ColorType::La8 | ColorType::Rgb8 | ColorType::Rgba8 => {
            let mut texels = vec![[0u8; 4]; n];
            let bytes = texels.as_flattened_mut();
            decoder.read_image(&mut bytes[..n * channels]).map_err(|e| e.to_string())?;
            // Widen from the back, so no pixel is overwritten before it is read.
            for i in (0..n).rev() {
                let rgba = rgba(&bytes[i * channels..(i + 1) * channels], u8::MAX);
                bytes[i * 4..i * 4 + 4].copy_from_slice(&rgba);
            }
            Ok(Texels::Rgba8 { texels: Arc::new(texels), space: ColorSpace::Srgb })
        }
        ColorType::L16 | ColorType::La16 | ColorType::Rgb16 | ColorType::Rgba16 => {
            let raw = read_raw(decoder, n * channels * 2)?;
            let texels = pixels(&raw, channels, |c| u16::from_ne_bytes([c[0], c[1]]), u16::MAX);
            Ok(Texels::Rgba16 { texels: Arc::new(texels), space: ColorSpace::Srgb })
        }
        ColorType::Rgb32F | ColorType::Rgba32F => {
            let raw = read_raw(decoder, n * channels * 4)?;
            let texels = pixels(&raw, channels, |c| f32::from_ne_bytes([c[0], c[1], c[2], c[3]]), 1.0);
            Ok(Texels::RgbaF32(Arc::new(texels)))
        }
        other => Err(format!("unsupported pixel format {other:?}")),
    }
}

/// The decoder's pixels as bytes (native-endian channels).
fn read_raw(decoder: impl ImageDecoder, len: usize) -> Result<Vec<u8>, String> {
    let mut raw = vec![0u8; len];
    decoder.read_image(&mut raw).map_err(|e| e.to_string())?;
    Ok(raw)
}

/// RGBA pixels from raw pixels of `channels` channels of `size_of::<T>()` bytes each.
fn pixels<T: Copy + Default>(raw: &[u8], channels: usize, value: impl Fn(&[u8]) -> T, one: T) -> Vec<[T; 4]> {
    let size = size_of::<T>();
    raw.chunks_exact(channels * size)
        .map(|pixel| {
            let mut c = [T::default(); 4];
            pixel.chunks_exact(size).zip(&mut c).for_each(|(bytes, c)| *c = value(bytes));
            rgba(&c[..channels], one)
        })
        .collect()
}

/// An RGBA pixel from a grey, grey + alpha, RGB or RGBA one; `one` is opaque alpha.
fn rgba<T: Copy>(c: &[T], one: T) -> [T; 4] {
    match *c {
        [l] => [l, l, l, one],
        [l, a] => [l, l, l, a],
        [r, g, b] => [r, g, b, one],
        [r, g, b, a, ..] => [r, g, b, a],
        [] => [one; 4],
    }
}

/// The textures of one scene, each image decoded once however many materials, slots, colour
/// spaces and spellings of its path use it.
#[derive(Debug)]
pub(crate) struct TextureSet {
    textures: Vec<Texture>,
    /// The decoded image of each source (a canonical file path, or a name for an embedded
    /// image), or why it cannot be had: failures are remembered so that a broken texture used
    /// by twenty materials gives one warning, not twenty.
    images: HashMap<String, Result<Image, String>>,
    /// The texture of each source read in each colour space.
    views: HashMap<(String, ColorSpace), u32>,
    /// Bytes the textures and their mipmaps may still take.
    budget_left: u64,
}

impl Default for TextureSet {
    fn default() -> Self {
        Self::with_budget(DEFAULT_TEXTURE_BUDGET)
    }
}

impl TextureSet {
    /// An empty set whose textures, with their mipmaps, may take `budget` bytes.
    pub fn with_budget(budget: u64) -> Self {
        Self { textures: Vec::new(), images: HashMap::new(), views: HashMap::new(), budget_left: budget }
    }

    /// The texture of the image file that `referrer` names `reference`, relative to `dir`,
    /// read in `space`.
    pub fn file(
        &mut self,
        dir: &Path,
        reference: &str,
        space: ColorSpace,
        referrer: &Path,
        report: &mut LoadReport,
    ) -> Option<u32> {
        let Some(path) = resources::resolve(dir, reference) else {
            let key = dir.join(reference).display().to_string();
            if let Entry::Vacant(entry) = self.images.entry(key) {
                report.warn(referrer, format!("texture `{reference}` not found in {}", dir.display()));
                entry.insert(Err("not found".into()));
            }
            return None;
        };
        let (key, fresh) = self.load_file(&path, 0, referrer, report);
        if let (Err(err), true) = (&self.images[&key], fresh) {
            report.warn(referrer, format!("texture `{key}` skipped: {err}"));
        }
        self.view(&key, space)
    }

    /// The texture of the sky image file at `path` (resolved) read in `space`, or why there is
    /// none (the scene cannot do without it). The image is charged with what the renderer
    /// derives from it ([`SKY_BYTES_PER_TEXEL`]), so it is decoded apart from any surface
    /// texture of the same file.
    pub fn sky_file(
        &mut self,
        path: &Path,
        space: ColorSpace,
        referrer: &Path,
        report: &mut LoadReport,
    ) -> Result<u32, String> {
        let (key, _) = self.load_file(path, SKY_BYTES_PER_TEXEL, referrer, report);
        match &self.images[&key] {
            Err(err) => Err(err.clone()),
            Ok(_) => self.view(&key, space).ok_or_else(|| "too many textures".into()),
        }
    }

    /// Reads and decodes the file at `path` unless that was done before, charging
    /// `extra_per_texel` beside its texels (see [`decode`]); returns its key (one per file and
    /// use, however its path is spelled: `x.png`, `./x.png`, links) and whether this call
    /// decoded it.
    fn load_file(
        &mut self,
        path: &Path,
        extra_per_texel: u64,
        referrer: &Path,
        report: &mut LoadReport,
    ) -> (String, bool) {
        let file = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
        let key = match extra_per_texel {
            0 => file.display().to_string(),
            _ => format!("{} (sky)", file.display()),
        };
        if self.images.contains_key(&key) {
            return (key, false);
        }
        let image = match resources::read(path, report) {
            Ok(bytes) => self.decoded(&bytes, &key, extra_per_texel, referrer, report),
            Err(err) => Err(err.to_string()),
        };
        self.images.insert(key.clone(), image);
        (key, true)
    }

    /// The texture of an in-memory image (glTF buffer views, data URIs) identified by `key`,
    /// read in `space`.
    pub fn bytes(
        &mut self,
        key: &str,
        bytes: &[u8],
        space: ColorSpace,
        referrer: &Path,
        report: &mut LoadReport,
    ) -> Option<u32> {
        if !self.images.contains_key(key) {
            let image = self.decoded(bytes, key, 0, referrer, report);
            if let Err(err) = &image {
                report.warn(referrer, format!("texture `{key}` skipped: {err}"));
            }
            self.images.insert(key.to_owned(), image);
        }
        self.view(key, space)
    }

    /// Decodes an image within what is left of the budget and charges it, with
    /// `extra_per_texel` (see [`decode`]); a downscale is reported as a warning.
    fn decoded(
        &mut self,
        bytes: &[u8],
        name: &str,
        extra_per_texel: u64,
        referrer: &Path,
        report: &mut LoadReport,
    ) -> Result<Image, String> {
        let (image, note) = decode(bytes, name, self.budget_left, extra_per_texel)?;
        if let Some(note) = note {
            report.warn(referrer, format!("texture `{name}`: {note}"));
        }
        let texels = u64::from(image.width) * u64::from(image.height);
        self.budget_left -= with_mipmap(image.bytes()) + texels * extra_per_texel;
        Ok(image)
    }

    /// The texture reading the decoded image of `key` in `space`, made on first use. Each
    /// colour space gets its own mipmap (levels average linear light), so a second view is
    /// charged another third of the image.
    fn view(&mut self, key: &str, space: ColorSpace) -> Option<u32> {
        if let Some(&index) = self.views.get(&(key.to_owned(), space)) {
            return Some(index);
        }
        let image = self.images.get(key)?.as_ref().ok()?;
        // The image itself was charged when it was decoded, with room for one mipmap.
        if self.views.keys().any(|(k, _)| k == key) {
            let mipmap = with_mipmap(image.bytes()) - image.bytes();
            self.budget_left = self.budget_left.saturating_sub(mipmap);
        }
        let texture = Texture {
            name: key.to_owned(),
            image: Image { width: image.width, height: image.height, texels: image.texels.in_space(space) },
            wrap: [Wrap::Repeat; 2],
        };
        let index = u32::try_from(self.textures.len()).ok()?;
        self.textures.push(texture);
        self.views.insert((key.to_owned(), space), index);
        Some(index)
    }

    /// Sets the wrap modes (along u and v) of texture `index`.
    pub fn set_wrap(&mut self, index: u32, wrap: [Wrap; 2]) {
        if let Some(texture) = self.textures.get_mut(index as usize) {
            texture.wrap = wrap;
        }
    }

    /// True if every texel of texture `index` has alpha 1 (an image without an alpha channel,
    /// or one that does not use it).
    pub fn is_opaque(&self, index: u32) -> bool {
        self.textures.get(index as usize).is_none_or(|t| {
            let texels = &t.image.texels;
            (0..texels.len()).all(|i| texels.linear(i)[3] >= 1.0)
        })
    }

    /// The loaded textures, in the order their indices refer to.
    pub fn into_textures(self) -> Vec<Texture> {
        self.textures
    }

    /// Runs the loader of a scene whose textures all come from this set, and gives the scene
    /// the set's textures.
    pub fn owning(
        mut self,
        load: impl FnOnce(&mut Self) -> Result<Scene, SceneError>,
    ) -> Result<Scene, SceneError> {
        let mut scene = load(&mut self)?;
        scene.textures = self.into_textures();
        Ok(scene)
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
        let mut set = TextureSet::default();
        let mut report = LoadReport::default();
        let referrer = Path::new("scene.gltf");
        let colour = set.bytes("t.png", &bytes, ColorSpace::Srgb, referrer, &mut report).unwrap();
        let data = set.bytes("t.png", &bytes, ColorSpace::Linear, referrer, &mut report).unwrap();
        let textures = set.into_textures();
        let colour = &textures[colour as usize].image;
        assert_eq!((colour.width, colour.height), (2, 1));
        assert_eq!(colour.texels.linear(0)[0], 1.0);
        assert!((colour.texels.linear(0)[1] - 0.2158605).abs() < 1e-6);
        assert!((colour.texels.linear(1)[3] - 64.0 / 255.0).abs() < 1e-6, "alpha stays linear");
        let data = &textures[data as usize].image;
        assert!((data.texels.linear(0)[1] - 128.0 / 255.0).abs() < 1e-6);
    }

    #[test]
    fn grey_and_rgb_images_widen_to_rgba() {
        let grey = image::GrayImage::from_raw(2, 1, vec![0, 255]).unwrap();
        let mut bytes = Vec::new();
        grey.write_to(&mut Cursor::new(&mut bytes), ImageFormat::Png).unwrap();
        let (image, note) = decode(&bytes, "g.png", u64::MAX, 0).unwrap();
        assert!(note.is_none());
        let texels = image.texels.in_space(ColorSpace::Linear);
        assert_eq!(texels.linear(0), [0.0, 0.0, 0.0, 1.0]);
        assert_eq!(texels.linear(1), [1.0, 1.0, 1.0, 1.0]);
        let rgb = image::RgbImage::from_raw(2, 1, vec![1, 2, 3, 4, 5, 6]).unwrap();
        let mut bytes = Vec::new();
        rgb.write_to(&mut Cursor::new(&mut bytes), ImageFormat::Png).unwrap();
        let (image, _) = decode(&bytes, "c.png", u64::MAX, 0).unwrap();
        match &image.texels {
            Texels::Rgba8 { texels, .. } => assert_eq!(**texels, [[1, 2, 3, 255], [4, 5, 6, 255]]),
            other => panic!("8-bit stays 8-bit: {other:?}"),
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::test_runner::Config::with_cases(2000))]

        /// Mutated images of every stored kind (8- and 16-bit grey, grey + alpha, RGB, RGBA)
        /// decode to complete images or to an error, never a panic.
        #[test]
        fn mutated_images_decode_or_fail_cleanly(
            kind in 0usize..8,
            flips in proptest::collection::vec((0usize..4096, proptest::num::u8::ANY), 0..8),
            cut in 0usize..4096,
            budget in 0u64..4096,
        ) {
            let (w, h) = (5, 3);
            let mut buffer = Cursor::new(Vec::new());
            let image = match kind {
                0 => image::DynamicImage::ImageLuma8(image::GrayImage::from_fn(w, h, |x, _| image::Luma([x as u8 * 40]))),
                1 => image::DynamicImage::ImageLumaA8(image::GrayAlphaImage::from_pixel(w, h, image::LumaA([9, 200]))),
                2 => image::DynamicImage::ImageRgb8(image::RgbImage::from_pixel(w, h, image::Rgb([1, 2, 3]))),
                3 => image::DynamicImage::ImageRgba8(image::RgbaImage::from_pixel(w, h, image::Rgba([1, 2, 3, 4]))),
                4 => image::DynamicImage::ImageLuma16(image::ImageBuffer::from_pixel(w, h, image::Luma([60000]))),
                5 => image::DynamicImage::ImageRgb16(image::ImageBuffer::from_pixel(w, h, image::Rgb([1, 2, 65535]))),
                6 => image::DynamicImage::ImageRgba16(image::ImageBuffer::from_pixel(w, h, image::Rgba([7; 4]))),
                _ => image::DynamicImage::ImageRgb32F(image::ImageBuffer::from_pixel(w, h, image::Rgb([0.5, 2.0, 1e3]))),
            };
            let format = if kind == 7 { ImageFormat::OpenExr } else { ImageFormat::Png };
            image.write_to(&mut buffer, format).unwrap();
            let mut bytes = buffer.into_inner();
            for (at, value) in flips {
                let len = bytes.len().max(1);
                if let Some(byte) = bytes.get_mut(at % len) {
                    *byte ^= value;
                }
            }
            bytes.truncate(cut.max(8));
            if let Ok((image, _)) = decode(&bytes, "fuzz.png", budget, 0) {
                proptest::prop_assert!(image.is_complete());
                proptest::prop_assert!(with_mipmap(image.bytes()) <= budget);
            }
        }
    }

    #[test]
    fn garbage_is_an_error_not_a_panic() {
        assert!(decode(b"\x89PNG\r\n\x1a\nnot really", "x.png", u64::MAX, 0).is_err());
        assert!(decode(&[], "x.jpg", u64::MAX, 0).is_err());
    }

    #[test]
    fn images_over_the_budget_are_halved_until_they_fit_or_refused() {
        let bytes = png(&[[200, 100, 50, 255]; 64 * 64], 64);
        // 64 × 64 × 4 bytes = 16 KiB, 21.3 KiB with its mipmap.
        let (image, note) = decode(&bytes, "t.png", 22 << 10, 0).unwrap();
        assert_eq!((image.width, note), (64, None));
        let (image, note) = decode(&bytes, "t.png", 6 << 10, 0).unwrap();
        assert_eq!((image.width, image.height), (32, 32));
        assert!(note.unwrap().contains("downscaled to 32x32"));
        // Odd sizes halve to ⌈w/2⌉: 5 × 3 texels become 3 × 2 (24 bytes, 32 with mipmaps).
        let odd = png(&[[1, 2, 3, 255]; 15], 5);
        let (image, _) = decode(&odd, "t.png", 32, 0).unwrap();
        assert_eq!((image.width, image.height), (3, 2));
        let (image, _) = decode(&odd, "t.png", 31, 0).unwrap();
        assert_eq!((image.width, image.height), (2, 1));
        // Even one texel (4 bytes, 5 with its "mipmap") is over a budget of 4.
        assert!(decode(&bytes, "t.png", 4, 0).unwrap_err().contains("texture budget"));
    }

    #[test]
    fn a_sky_is_charged_with_its_sampling_tables() {
        let bytes = png(&[[200, 100, 50, 255]; 64 * 64], 64);
        // As a surface texture 64 × 64 fits 22 KiB; as a sky it also needs 20 bytes a texel
        // (80 KiB), so it is halved twice: 16 × 16 is 1.3 + 5 KiB.
        let (image, note) = decode(&bytes, "sky.png", 22 << 10, SKY_BYTES_PER_TEXEL).unwrap();
        assert_eq!((image.width, image.height), (16, 16));
        assert!(note.unwrap().contains("sampling tables"));
        let mut set = TextureSet::with_budget(128 << 10);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sky.png");
        std::fs::write(&path, &bytes).unwrap();
        let mut report = LoadReport::default();
        set.sky_file(&path, ColorSpace::Srgb, Path::new("s.toml"), &mut report).unwrap();
        assert_eq!(set.budget_left, (128 << 10) - (64 * 64 * 4 * 4 / 3 + 64 * 64 * SKY_BYTES_PER_TEXEL));
    }

    #[test]
    fn each_image_is_decoded_once_and_failures_warn_once() {
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
        let textures = set.into_textures();
        assert_eq!(textures.len(), 2);
        // The two colour spaces read one decode.
        match (&textures[0].image.texels, &textures[1].image.texels) {
            (Texels::Rgba8 { texels: x, .. }, Texels::Rgba8 { texels: y, .. }) => assert!(Arc::ptr_eq(x, y)),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn one_decode_per_file_however_its_path_is_spelled() {
        let dir = std::env::temp_dir().join(format!("igi-texture-spellings-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        std::fs::write(dir.join("x.png"), png(&[[9, 9, 9, 255]], 1)).unwrap();
        let mut set = TextureSet::default();
        let mut report = LoadReport::default();
        let referrer = Path::new("scene.mtl");
        let ids: Vec<_> = ["x.png", "./x.png", "sub/../x.png"]
            .iter()
            .map(|r| set.file(&dir, r, ColorSpace::Srgb, referrer, &mut report))
            .collect();
        assert_eq!(ids, [Some(0), Some(0), Some(0)]);
        assert_eq!(report.files.len(), 1, "read once: {:?}", report.files);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
