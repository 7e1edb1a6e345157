//! How a texture's texels are stored, and their values in linear light.
//!
//! 8-bit images stay 8-bit (4 bytes per texel instead of 16 as linear floats): colour maps keep
//! their sRGB encoding and are decoded at lookup through a 256-entry table, which costs a load
//! per channel. Float images (Radiance HDR, OpenEXR) and 16-bit images are kept as linear
//! floats. Texels are reference-counted so that the views of one decoded image (a colour map
//! and a data map of the same file, a texture and its mipmap's finest level) share them.

use std::sync::{Arc, LazyLock};

use rayon::prelude::*;

/// How the stored values of an 8-bit image relate to linear light.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ColorSpace {
    /// Colour maps (diffuse, base colour, emissive): R, G and B are sRGB-encoded.
    Srgb,
    /// Data maps (bump, height, normal, metallic-roughness): values are used as they are,
    /// scaled to [0, 1].
    Linear,
}

/// The texels of an [`Image`], row-major, row 0 at the top, RGBA.
#[derive(Clone)]
pub enum Texels {
    /// 8 bits per channel as the file stored them: R, G and B in `space`, alpha linear.
    Rgba8 {
        /// The texels.
        texels: Arc<Vec<[u8; 4]>>,
        /// What R, G and B encode.
        space: ColorSpace,
    },
    /// 16 bits per channel as the file stored them: R, G and B in `space`, alpha linear.
    Rgba16 {
        /// The texels.
        texels: Arc<Vec<[u16; 4]>>,
        /// What R, G and B encode.
        space: ColorSpace,
    },
    /// Linear-light floats.
    RgbaF32(Arc<Vec<[f32; 4]>>),
}

/// Names the storage and counts the texels: a texture's millions of values help no message.
impl std::fmt::Debug for Texels {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Rgba8 { texels, space } => write!(f, "Rgba8({} texels, {space:?})", texels.len()),
            Self::Rgba16 { texels, space } => write!(f, "Rgba16({} texels, {space:?})", texels.len()),
            Self::RgbaF32(texels) => write!(f, "RgbaF32({} texels)", texels.len()),
        }
    }
}

/// A grid of texels: a decoded image, or one level of a mipmap.
#[derive(Clone, Debug)]
pub struct Image {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// `width * height` texels.
    pub texels: Texels,
}

/// The linear values of the 256 sRGB-encoded 8-bit values.
static SRGB8: LazyLock<Vec<f32>> = LazyLock::new(|| table(256, srgb_to_linear));
/// The linear values of the 256 plain 8-bit values: v / 255.
static LINEAR8: LazyLock<Vec<f32>> = LazyLock::new(|| table(256, |x| x));
/// The linear values of the 65536 sRGB-encoded 16-bit values.
static SRGB16: LazyLock<Vec<f32>> = LazyLock::new(|| table(65536, srgb_to_linear));
/// The linear values of the 65536 plain 16-bit values: v / 65535.
static LINEAR16: LazyLock<Vec<f32>> = LazyLock::new(|| table(65536, |x| x));

fn table(len: usize, decode: impl Fn(f32) -> f32) -> Vec<f32> {
    (0..len).map(|v| decode(v as f32 / (len - 1) as f32)).collect()
}

/// The sRGB transfer function, inverted (IEC 61966-2-1): the linear value of an sRGB-encoded
/// value in [0, 1] (clamped to it). Every decoder of the workspace uses this one, so an 8-bit
/// value decodes to the same float everywhere.
pub fn srgb_to_linear(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.04045 { x / 12.92 } else { ((x + 0.055) / 1.055).powf(2.4) }
}

impl ColorSpace {
    /// The linear value of each 8-bit value in this space.
    pub fn table8(self) -> &'static [f32] {
        match self {
            Self::Srgb => &SRGB8,
            Self::Linear => &LINEAR8,
        }
    }

    /// The linear value of each 16-bit value in this space.
    pub fn table16(self) -> &'static [f32] {
        match self {
            Self::Srgb => &SRGB16,
            Self::Linear => &LINEAR16,
        }
    }
}

/// The stored value whose linear value in `table` (increasing) is nearest to `x`: the exact
/// inverse of the lookup, with no transfer function evaluated.
fn encode(table: &[f32], x: f32) -> usize {
    let above = table.partition_point(|&v| v < x);
    if above == 0 {
        return 0;
    }
    if above == table.len() {
        return table.len() - 1;
    }
    nearer(table, x, above - 1)
}

/// `below` or `below + 1`, whichever has the linear value in `table` nearer to `x`.
fn nearer(table: &[f32], x: f32, below: usize) -> usize {
    match table.get(below + 1) {
        Some(&next) if next - x < x - table[below] => below + 1,
        _ => below,
    }
}

/// Bins of the unit interval fine enough that each holds at most one boundary between the
/// nearest 8-bit sRGB values (their linear values are at least 1/(255 · 12.92) apart).
const SRGB8_BINS: usize = 1 << 16;

/// For each bin of [0, 1], the largest 8-bit sRGB value whose linear value lies at or below
/// the bin's start.
static SRGB8_BELOW: LazyLock<Vec<u8>> = LazyLock::new(|| {
    (0..SRGB8_BINS)
        .map(|b| (SRGB8.partition_point(|&v| v <= b as f32 / (SRGB8_BINS - 1) as f32) - 1) as u8)
        .collect()
});

/// The 8-bit value in a colour space nearest to a linear value: [`encode`] in constant time
/// (a mipmap re-encodes every texel it averages), with its tables looked up once.
struct Encoder8 {
    space: ColorSpace,
    srgb: &'static [f32],
    srgb_below: &'static [u8],
}

impl Encoder8 {
    fn new(space: ColorSpace) -> Self {
        Self { space, srgb: &SRGB8, srgb_below: &SRGB8_BELOW }
    }

    fn encode(&self, x: f32) -> u8 {
        let x = x.clamp(0.0, 1.0);
        match self.space {
            ColorSpace::Linear => (x * 255.0).round() as u8,
            ColorSpace::Srgb => {
                // The bin's start is at or below x, so the nearest value is the one at or
                // below the start or the next; the bin holds no further boundary.
                let below = self.srgb_below[(x * (SRGB8_BINS - 1) as f32) as usize];
                nearer(self.srgb, x, usize::from(below)) as u8
            }
        }
    }
}

/// The linear RGBA value of a stored integer texel: R, G and B through `rgb`, alpha through
/// `alpha`.
#[inline]
fn decode_texel<T: Copy + Into<usize>>(texel: [T; 4], rgb: &[f32], alpha: &[f32]) -> [f32; 4] {
    let [r, g, b, a] = texel.map(Into::into);
    [rgb[r], rgb[g], rgb[b], alpha[a]]
}

impl Texels {
    /// Number of texels.
    pub fn len(&self) -> usize {
        match self {
            Self::Rgba8 { texels, .. } => texels.len(),
            Self::Rgba16 { texels, .. } => texels.len(),
            Self::RgbaF32(texels) => texels.len(),
        }
    }

    /// True if there are no texels.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Where the texels are stored: the same for the views of one decoded image.
    pub(crate) fn storage(&self) -> *const u8 {
        match self {
            Self::Rgba8 { texels, .. } => texels.as_ptr().cast(),
            Self::Rgba16 { texels, .. } => texels.as_ptr().cast(),
            Self::RgbaF32(texels) => texels.as_ptr().cast(),
        }
    }

    /// Bytes one texel occupies.
    pub fn bytes_per_texel(&self) -> usize {
        match self {
            Self::Rgba8 { .. } => 4,
            Self::Rgba16 { .. } => 8,
            Self::RgbaF32(_) => 16,
        }
    }

    /// The linear RGBA value of texel `i`.
    #[inline]
    pub fn linear(&self, i: usize) -> [f32; 4] {
        match self {
            Self::Rgba8 { texels, space } => decode_texel(texels[i], space.table8(), &LINEAR8),
            Self::Rgba16 { texels, space } => decode_texel(texels[i], space.table16(), &LINEAR16),
            Self::RgbaF32(texels) => texels[i],
        }
    }

    /// The linear RGBA values of the four texels `indices`, with one dispatch on the storage
    /// for all four (a bilinear lookup's footprint).
    #[inline]
    pub fn linear4(&self, indices: [usize; 4]) -> [[f32; 4]; 4] {
        match self {
            Self::Rgba8 { texels, space } => {
                let (rgb, alpha) = (space.table8(), &**LINEAR8);
                indices.map(|i| decode_texel(texels[i], rgb, alpha))
            }
            Self::Rgba16 { texels, space } => {
                let (rgb, alpha) = (space.table16(), &**LINEAR16);
                indices.map(|i| decode_texel(texels[i], rgb, alpha))
            }
            Self::RgbaF32(texels) => indices.map(|i| texels[i]),
        }
    }

    /// The same texels read in another colour space (integer texels only; floats are linear
    /// whatever the slot). Shares the storage.
    pub fn in_space(&self, space: ColorSpace) -> Self {
        match self {
            Self::Rgba8 { texels, .. } => Self::Rgba8 { texels: texels.clone(), space },
            Self::Rgba16 { texels, .. } => Self::Rgba16 { texels: texels.clone(), space },
            Self::RgbaF32(texels) => Self::RgbaF32(texels.clone()),
        }
    }
}

/// The ⌈w/2⌉ × ⌈h/2⌉ means of the (up to) 2 × 2 texels of a `w × h` grid that each covers,
/// read by `texel` (linear light, by index) and stored by `store`; rows in parallel.
fn box_halve<T: Copy + Default + Send>(
    w: u32,
    h: u32,
    texel: impl Fn(usize) -> [f32; 4] + Sync,
    store: impl Fn([f32; 4]) -> T + Sync,
) -> Vec<T> {
    let (width, height) = (w.div_ceil(2).max(1), h.div_ceil(2).max(1));
    // Written in place, row by row: collecting a parallel iterator would hold the level twice.
    let mut halved = vec![T::default(); width as usize * height as usize];
    halved.par_chunks_mut(width as usize).zip(0..height).for_each(|(out, y)| {
        let rows = 2 * y..(2 * y + 2).min(h);
        for (x, out) in (0..width).zip(out) {
            let columns = 2 * x..(2 * x + 2).min(w);
            let mut sum = [0.0f32; 4];
            let mut n = 0.0;
            for row in rows.clone() {
                for column in columns.clone() {
                    let t = texel((row * w + column) as usize);
                    sum.iter_mut().zip(t).for_each(|(s, t)| *s += t);
                    n += 1.0;
                }
            }
            *out = store(sum.map(|s| s / n));
        }
    });
    halved
}

impl Image {
    /// Bytes its texels occupy.
    pub fn bytes(&self) -> u64 {
        self.texels.len() as u64 * self.texels.bytes_per_texel() as u64
    }

    /// True if it has as many texels as its size says, and at least one.
    pub fn is_complete(&self) -> bool {
        self.width > 0 && self.height > 0 && self.texels.len() == self.width as usize * self.height as usize
    }

    /// The next coarser level of a mipmap (Williams 1983): ⌈w/2⌉ × ⌈h/2⌉ texels, each the mean
    /// in linear light of the (up to) 2 × 2 texels it covers (an odd last column or row is
    /// averaged with what it has), stored as this image is.
    pub fn half(&self) -> Self {
        let (w, h) = (self.width, self.height);
        let (width, height) = (w.div_ceil(2).max(1), h.div_ceil(2).max(1));
        let texels = match &self.texels {
            Texels::Rgba8 { texels, space } => {
                let (rgb, alpha): (&[f32], &[f32]) = (space.table8(), &LINEAR8);
                let (colour, linear) = (Encoder8::new(*space), Encoder8::new(ColorSpace::Linear));
                let halved = box_halve(
                    w,
                    h,
                    |i| decode_texel(texels[i], rgb, alpha),
                    |[r, g, b, a]| [colour.encode(r), colour.encode(g), colour.encode(b), linear.encode(a)],
                );
                Texels::Rgba8 { texels: Arc::new(halved), space: *space }
            }
            Texels::Rgba16 { texels, space } => {
                let (rgb, alpha): (&[f32], &[f32]) = (space.table16(), &LINEAR16);
                let halved = box_halve(
                    w,
                    h,
                    |i| decode_texel(texels[i], rgb, alpha),
                    |[r, g, b, a]| {
                        [encode(rgb, r), encode(rgb, g), encode(rgb, b), encode(alpha, a)].map(|v| v as u16)
                    },
                );
                Texels::Rgba16 { texels: Arc::new(halved), space: *space }
            }
            Texels::RgbaF32(texels) => Texels::RgbaF32(Arc::new(box_halve(w, h, |i| texels[i], |t| t))),
        };
        Self { width, height, texels }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encoding_inverts_the_tables_exactly() {
        for space in [ColorSpace::Srgb, ColorSpace::Linear] {
            let table = space.table8();
            for v in 0..=255u8 {
                assert_eq!(Encoder8::new(space).encode(table[usize::from(v)]), v, "{space:?} {v}");
                // Anywhere between two values, the constant-time encoder agrees with the search.
                if v < 255 {
                    for t in [0.1, 0.49, 0.51, 0.9] {
                        let x = table[usize::from(v)] * (1.0 - t) + table[usize::from(v) + 1] * t;
                        assert_eq!(
                            usize::from(Encoder8::new(space).encode(x)),
                            encode(table, x),
                            "{space:?} {v} {t}"
                        );
                    }
                }
            }
            let e = Encoder8::new(space);
            assert_eq!((e.encode(-1.0), e.encode(2.0), e.encode(f32::NAN)), (0, 255, 0));
            for table in [space.table8(), space.table16()] {
                for v in (0..table.len()).step_by(7).chain([table.len() - 1]) {
                    assert_eq!(encode(table, table[v]), v, "{space:?} {v}");
                }
                assert_eq!(encode(table, -1.0), 0);
                assert_eq!(encode(table, 2.0), table.len() - 1);
                assert_eq!(encode(table, f32::NAN), 0, "NaN never indexes out of range");
            }
        }
        // Between two linear values, the nearer one.
        let t = ColorSpace::Linear.table8();
        assert_eq!(encode(t, (t[10] + t[11]) * 0.5 - 1e-6), 10);
        assert_eq!(encode(t, (t[10] + t[11]) * 0.5 + 1e-6), 11);
    }

    #[test]
    fn srgb_texels_decode_at_lookup_and_views_share_storage() {
        let texels = Arc::new(vec![[255u8, 128, 0, 64]]);
        let colour = Texels::Rgba8 { texels: texels.clone(), space: ColorSpace::Srgb };
        let [r, g, b, a] = colour.linear(0);
        assert_eq!((r, b), (1.0, 0.0));
        assert!((g - 0.2158605).abs() < 1e-6, "{g}");
        assert!((a - 64.0 / 255.0).abs() < 1e-6, "alpha stays linear");
        let data = colour.in_space(ColorSpace::Linear);
        assert!((data.linear(0)[1] - 128.0 / 255.0).abs() < 1e-6);
        assert_eq!(Arc::strong_count(&texels), 3, "one copy of the texels for all views");
    }

    #[test]
    fn halving_averages_linear_light_and_keeps_the_storage() {
        // Black and white sRGB texels average to linear 0.5, which is sRGB 188, not 128.
        let image = Image {
            width: 2,
            height: 1,
            texels: Texels::Rgba8 {
                texels: Arc::new(vec![[0, 0, 0, 255], [255, 255, 255, 255]]),
                space: ColorSpace::Srgb,
            },
        };
        let half = image.half();
        assert_eq!((half.width, half.height), (1, 1));
        match &half.texels {
            Texels::Rgba8 { texels, space } => {
                assert_eq!(*space, ColorSpace::Srgb);
                assert_eq!(texels[0], [188, 188, 188, 255]);
            }
            other => panic!("8-bit stays 8-bit: {other:?}"),
        }
    }
}
