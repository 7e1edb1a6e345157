//! Tone mapping: from linear radiance to display values in [0, 1], then sRGB-encoded 8-bit.
//!
//! Three operators:
//! - [`ToneMap::Filmic`] (the default): the log-average luminance L̄ maps to the middle grey
//!   `key` (0.18), as for Reinhard, then the filmic curve [`filmic_curve`], Narkowicz's 2016
//!   fit of the ACES reference rendering and output transforms, compresses the luminance with
//!   a toe and a shoulder: middle grey shows at 0.27 (Reinhard: 0.15, so a white wall lit as
//!   the image's average showed mid-grey), and a luminance 40 times the average (5.3 stops
//!   above) reaches white. The curve acts on the luminance and colours are scaled by
//!   L_d / L, so hue and saturation are kept; a colour whose brightest channel would pass 1
//!   is mixed with the grey of its own luminance until it fits (a highlight rolls off toward
//!   white along the line to white, its dominant wavelength kept), never clipped per channel,
//!   which would turn an orange highlight yellow. The ACES curve applied per channel, as
//!   games do, shifts hues in its shoulder the same way.
//! - [`ToneMap::Reinhard`]: the global operator of Reinhard et al. 2002,
//!   "Photographic Tone Reproduction for Digital Images", eq. 1-3. The log-average luminance
//!   L̄ = exp(mean(ln(δ + L))) of the image maps to the middle grey `key` (0.18), then
//!   L_d = L (1 + L / L_white²) / (1 + L) compresses highlights (eq. 4). Reinhard takes
//!   L_white as the image's largest luminance; igi takes the 99.5th percentile (at most the
//!   largest), so that a few outliers, such as one VPL's blotch near a wall, cannot darken
//!   the whole picture: 0.5 % of the lit pixels may reach white. (At the 99th percentile the
//!   Cornell box's light, 0.7 % of its image, burned out, and 16 accumulated frames measured
//!   0.079 mean FLIP against the path tracer instead of 0.071, `igi bench quality`.) Colours are scaled by
//!   L_d / L (hue kept) and clipped per channel.
//! - [`ToneMap::Exposure`]: a fixed linear scale by 2^stops and a clip at 1, for comparable
//!   images across frames and scenes.
//!
//! Image statistics are gathered in [`LuminanceStats`], which merge: a tile can report its own
//! and the compositor combines them in tile order (paper 3.4).

use crate::image::film::Film;
use glam::Vec3;
use igi_simd::{F32x8, M32x8};

/// δ of the log-average: keeps ln finite for black pixels.
const LOG_DELTA: f32 = 1e-6;

/// Luminance statistics of a set of pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LuminanceStats {
    /// Σ ln(δ + L) over the counted pixels.
    pub log_sum: f64,
    /// Number of counted pixels.
    pub count: u64,
    /// Largest luminance seen.
    pub max: f32,
    /// Counted pixels by log2(δ + L): bin b holds [2^(2b − 32), 2^(2b − 30)) (two stops
    /// each), the first and last bins everything below and above. Counts add up when tiles
    /// merge, so the percentiles do not depend on the tiles' order or size.
    pub histogram: [u32; HISTOGRAM_BINS],
}

/// Bins of [`LuminanceStats::histogram`].
pub const HISTOGRAM_BINS: usize = 32;

/// The share of the counted pixels below Reinhard's L_white (module documentation).
pub const WHITE_PERCENTILE: f64 = 0.995;

impl LuminanceStats {
    /// The statistics of `pixels`, accumulated in order. Pixels of zero (or invalid)
    /// luminance, such as background or full shadow, are not counted, so a small object on
    /// black is not exposed as if the image were mostly dark. Eight pixels at a time: ln(δ + L)
    /// as log2 · ln 2 in SIMD ([`igi_simd::F32x8::log2`], within 1e-6), summed in f64 in pixel
    /// order, so the sums do not depend on the lane width.
    pub fn of_pixels(pixels: &[Vec3]) -> Self {
        let mut s = Self::default();
        let mut max = F32x8::ZERO;
        for chunk in pixels.chunks(8) {
            let Soa8 { rgb, lanes } = Soa8::load(chunk);
            let l = luminance8(rgb);
            let counted = lanes & l.gt(F32x8::ZERO) & l.lt(F32x8::splat(f32::INFINITY));
            let log2 = (F32x8::splat(LOG_DELTA) + l).log2();
            let ln = log2 * F32x8::splat(std::f32::consts::LN_2);
            let (bits, ln, log2) = (counted.bitmask(), ln.to_array(), log2.to_array());
            for lane in (0..8).filter(|lane| bits & (1 << lane) != 0) {
                s.log_sum += f64::from(ln[lane]);
                s.histogram[histogram_bin(log2[lane])] += 1;
            }
            s.count += u64::from(bits.count_ones());
            max = max.max(F32x8::select(counted, l, F32x8::ZERO));
        }
        s.max = max.reduce_max();
        s
    }

    /// The statistics of both sets (combine tiles in a fixed order for reproducible sums).
    pub fn merge(self, o: Self) -> Self {
        Self {
            log_sum: self.log_sum + o.log_sum,
            count: self.count + o.count,
            max: self.max.max(o.max),
            histogram: std::array::from_fn(|b| self.histogram[b].saturating_add(o.histogram[b])),
        }
    }

    /// The luminance below which a share `p` of the counted pixels lie (0 if none is counted),
    /// at most the largest: from the histogram, log-linearly within the bin it falls in.
    pub fn percentile(&self, p: f64) -> f32 {
        if self.count == 0 {
            return 0.0;
        }
        let target = p.clamp(0.0, 1.0) * self.count as f64;
        let mut below = 0.0;
        for (b, &c) in self.histogram.iter().enumerate() {
            let c = f64::from(c);
            if c > 0.0 && below + c >= target {
                let within = ((target - below) / c).clamp(0.0, 1.0);
                let log2 = 2.0 * (b as f64 + within) - 32.0;
                return (log2.exp2() as f32).min(self.max);
            }
            below += c;
        }
        self.max
    }

    /// The log-average luminance, or `None` if no pixel was counted.
    pub fn log_average(&self) -> Option<f32> {
        (self.count > 0).then(|| (self.log_sum / self.count as f64).exp() as f32)
    }
}

/// Eight pixels in structure-of-arrays form, and which lanes hold one (the last chunk of a
/// slice may be short; its empty lanes are black).
struct Soa8 {
    rgb: [F32x8; 3],
    lanes: M32x8,
}

impl Soa8 {
    #[inline(always)]
    fn load(pixels: &[Vec3]) -> Self {
        let mut c = [[0.0f32; 8]; 3];
        for (i, p) in pixels.iter().enumerate() {
            (c[0][i], c[1][i], c[2][i]) = (p.x, p.y, p.z);
        }
        Self { rgb: c.map(F32x8::from_array), lanes: M32x8::from_bitmask((1u32 << pixels.len()) - 1) }
    }
}

/// The [`LuminanceStats::histogram`] bin of a pixel with log2(δ + L) = `log2`.
#[inline]
fn histogram_bin(log2: f32) -> usize {
    // NaN cannot occur (counted pixels have 0 < L < ∞); `as` saturates.
    (((log2 + 32.0) * 0.5).floor() as i64).clamp(0, HISTOGRAM_BINS as i64 - 1) as usize
}

/// Relative luminance of linear RGB (Rec. 709 primaries).
#[inline]
pub fn luminance(rgb: Vec3) -> f32 {
    0.2126 * rgb.x + 0.7152 * rgb.y + 0.0722 * rgb.z
}

/// [`luminance`] of eight colours, with its operations in its order.
#[inline(always)]
fn luminance8([r, g, b]: [F32x8; 3]) -> F32x8 {
    F32x8::splat(0.2126) * r + F32x8::splat(0.7152) * g + F32x8::splat(0.0722) * b
}

/// The curve of an automatic tone map: how the exposed luminance is compressed into the
/// display's range (`igi render --tone-map`, a frame setting the viewers share).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ToneCurve {
    /// The ACES filmic curve (Narkowicz's fit) on the luminance, highlights rolling off to
    /// white with their hue kept (module documentation).
    #[default]
    Filmic,
    /// Reinhard's eq. 4 with the white point at the 99.5th percentile of the luminance.
    Reinhard,
}

/// How linear radiance becomes a display value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ToneMap {
    /// The filmic curve after the log-average luminance is mapped to `key`, from image
    /// statistics.
    Filmic {
        /// Luminance the log-average maps to before the curve (0.18 usual).
        key: f32,
    },
    /// Reinhard's global operator with the given key (middle grey), from image statistics.
    Reinhard {
        /// Display luminance the log-average maps to before compression (0.18 usual).
        key: f32,
    },
    /// Multiply by 2^stops, clip at 1.
    Exposure {
        /// Exposure in photographic stops (0 = radiance 1 shows as white).
        stops: f32,
    },
}

/// The key of the automatic tone maps: middle grey.
pub const DEFAULT_KEY: f32 = 0.18;

/// The most stops a fixed exposure may take either way: 2^±64 spans every radiance a 32-bit
/// float holds (and more brings only white or black), and 2^128 would overflow the scale.
pub const MAX_EXPOSURE_STOPS: f32 = 64.0;

/// `stops` if it is a fixed exposure igi takes ([`MAX_EXPOSURE_STOPS`] either way), else
/// what is wrong with it.
pub fn check_exposure(stops: f32) -> Result<f32, String> {
    if stops.is_finite() && stops.abs() <= MAX_EXPOSURE_STOPS {
        Ok(stops)
    } else {
        Err(format!("{stops} is not a number of stops in [-{MAX_EXPOSURE_STOPS}, {MAX_EXPOSURE_STOPS}]"))
    }
}

impl Default for ToneMap {
    fn default() -> Self {
        Self::automatic(ToneCurve::default(), DEFAULT_KEY)
    }
}

impl ToneMap {
    /// The automatic tone map of `curve` that maps the log-average luminance to `key`.
    pub fn automatic(curve: ToneCurve, key: f32) -> Self {
        match curve {
            ToneCurve::Filmic => Self::Filmic { key },
            ToneCurve::Reinhard => Self::Reinhard { key },
        }
    }

    /// `Exposure` if `stops` is given, else the automatic tone map of `curve` with the
    /// default key.
    pub fn chosen(curve: ToneCurve, stops: Option<f32>) -> Self {
        stops.map_or(Self::automatic(curve, DEFAULT_KEY), |stops| Self::Exposure { stops })
    }
}

/// A tone map with its parameters fixed, ready to map pixels.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ToneMapper {
    /// Linear scale applied to radiance first.
    pub scale: f32,
    /// The curve that compresses the scaled luminance; `None` for a plain clip at 1.
    pub curve: Option<ToneCurve>,
    /// L_white of the Reinhard compression after scaling, the smallest luminance shown as
    /// white; 0 for none (plain L / (1 + L)), and unused by the other curves.
    pub white: f32,
}

impl ToneMapper {
    /// No tone mapping: radiance clipped to [0, 1] (for frames whose 8-bit output is unused).
    pub const LINEAR: Self = Self { scale: 1.0, curve: None, white: 0.0 };
}

/// Narkowicz's coefficients (2016, "ACES Filmic Tone Mapping Curve") of the rational fit
/// x (a x + b) / (x (c x + d) + e) to the ACES reference rendering and output transforms.
const FILMIC: [f32; 5] = [2.51, 0.03, 2.43, 0.59, 0.14];

/// A scaled luminance at which [`filmic_curve`] has passed 1 (it does at 7.3), so larger ones
/// are not evaluated (their squares could overflow).
const FILMIC_SATURATED: f32 = 16.0;

/// Largest channel of scaled radiance the filmic map evaluates: larger ones (a scale that
/// overflows a huge but finite radiance) show as white, as a value of this size does.
const FILMIC_CAP: f32 = 1e30;

/// The filmic curve of a scaled luminance `l` ≥ 0, in [0, 1]: Narkowicz's fit of ACES, 0 at
/// 0, increasing (its derivative's numerator 1.408 l² + 0.7028 l + 0.0042 is positive), 1 from
/// l ≈ 7.3 on.
#[inline]
pub fn filmic_curve(l: f32) -> f32 {
    let [a, b, c, d, e] = FILMIC;
    let l = l.min(FILMIC_SATURATED);
    ((l * (a * l + b)) / (l * (c * l + d) + e)).min(1.0)
}

/// [`filmic_curve`] of eight luminances, with its operations in its order.
#[inline(always)]
fn filmic_curve8(l: F32x8) -> F32x8 {
    let [a, b, c, d, e] = FILMIC.map(F32x8::splat);
    let l = l.min(F32x8::splat(FILMIC_SATURATED));
    ((l * (a * l + b)) / (l * (c * l + d) + e)).min(F32x8::splat(1.0))
}

/// The filmic map of scaled radiance `rgb` (finite, ≥ 0): its luminance through
/// [`filmic_curve`], the colour scaled alike, then mixed with the grey of its luminance just
/// enough that no channel passes 1.
#[inline]
fn filmic(rgb: Vec3) -> Vec3 {
    let rgb = rgb.min(Vec3::splat(FILMIC_CAP));
    let l = luminance(rgb);
    if l <= 0.0 {
        return Vec3::ZERO;
    }
    let y = filmic_curve(l);
    let c = rgb * (y / l);
    let m = c.x.max(c.y).max(c.z);
    // The share t of grey that brings the brightest channel to 1: m + t (y − m) = 1, with
    // y < m since y is a weighted mean of the channels and not every channel is m.
    let t = if m > 1.0 { (m - 1.0) / (m - y) } else { 0.0 };
    c + (Vec3::splat(y) - c) * t
}

/// [`filmic`] of eight pixels, with its operations in its order (black lanes give 0).
#[inline(always)]
fn filmic8(rgb: [F32x8; 3]) -> [F32x8; 3] {
    let (zero, one) = (F32x8::ZERO, F32x8::splat(1.0));
    let rgb = rgb.map(|c| c.min(F32x8::splat(FILMIC_CAP)));
    let l = luminance8(rgb);
    let y = filmic_curve8(l);
    let k = y / l;
    let c = rgb.map(|c| c * k);
    let m = c[0].max(c[1]).max(c[2]);
    let t = F32x8::select(m.gt(one), (m - one) / (m - y), zero);
    let lit = l.gt(zero);
    c.map(|c| F32x8::select(lit, c + (y - c) * t, zero))
}

impl ToneMapper {
    /// Fixes the parameters of `op` for an image with statistics `stats`.
    pub fn new(op: ToneMap, stats: &LuminanceStats) -> Self {
        let exposed =
            |key: f32| stats.log_average().filter(|a| *a > 0.0 && a.is_finite()).map_or(1.0, |a| key / a);
        match op {
            ToneMap::Exposure { stops } => Self { scale: stops.exp2(), curve: None, white: 0.0 },
            ToneMap::Filmic { key } => {
                Self { scale: exposed(key), curve: Some(ToneCurve::Filmic), white: 0.0 }
            }
            ToneMap::Reinhard { key } => {
                let scale = exposed(key);
                // Reinhard's eq. 4 with L_white the 99.5th percentile of the luminance (module
                // documentation): everything below keeps more contrast than with L / (1 + L).
                let white = stats.percentile(WHITE_PERCENTILE) * scale;
                let white = if white.is_finite() { white } else { 0.0 };
                Self { scale, curve: Some(ToneCurve::Reinhard), white }
            }
        }
    }

    /// This tone map moved the share `a` of the way toward `target` in log scale and log
    /// white point (the same mapping as `target` where they cannot be blended: another
    /// operator, no white point).
    pub fn adapted_toward(&self, target: &Self, a: f32) -> Self {
        let blend = |x: f32, y: f32| (x.ln() * (1.0 - a) + y.ln() * a).exp();
        let positive = |x: f32| x > 0.0 && x.is_finite();
        if self.curve != target.curve || ![self.scale, target.scale].into_iter().all(positive) {
            return *target;
        }
        let white = if positive(self.white) && positive(target.white) {
            blend(self.white, target.white)
        } else {
            target.white
        };
        Self { scale: blend(self.scale, target.scale), curve: target.curve, white }
    }

    /// The tone mapper of `op` for `film`.
    pub fn for_film(op: ToneMap, film: &Film) -> Self {
        Self::new(op, &LuminanceStats::of_pixels(film.pixels()))
    }

    /// Display-linear value in [0, 1]³ of radiance `rgb` (non-finite or negative values
    /// become 0).
    #[inline]
    pub fn map(&self, rgb: Vec3) -> Vec3 {
        let rgb = Vec3::select(rgb.cmpgt(Vec3::ZERO) & rgb.is_finite_mask(), rgb, Vec3::ZERO) * self.scale;
        let out = match self.curve {
            None => rgb,
            Some(ToneCurve::Filmic) => filmic(rgb),
            Some(ToneCurve::Reinhard) => {
                let l = luminance(rgb);
                let burn = if self.white > 0.0 { 1.0 + l / (self.white * self.white) } else { 1.0 };
                if l > 0.0 { rgb * (burn / (1.0 + l)) } else { Vec3::ZERO }
            }
        };
        out.clamp(Vec3::ZERO, Vec3::ONE)
    }

    /// 8-bit sRGB of radiance `rgb`.
    #[inline]
    pub fn to_srgb8(&self, rgb: Vec3) -> [u8; 3] {
        let e = Srgb8Encoder::get();
        let m = self.map(rgb);
        [e.encode(m.x), e.encode(m.y), e.encode(m.z)]
    }

    /// Writes the 8-bit sRGB values of `pixels` into `out`, 3 bytes per pixel (`out` holds
    /// exactly `3 * pixels.len()` bytes): [`ToneMapper::to_srgb8`] of every pixel, eight at
    /// a time ([`ToneMapper::map8`]).
    pub fn encode_pixels(&self, pixels: &[Vec3], out: &mut [u8]) {
        assert_eq!(out.len(), 3 * pixels.len(), "3 bytes per pixel");
        let e = Srgb8Encoder::get();
        for (chunk, bytes) in pixels.chunks(8).zip(out.chunks_mut(24)) {
            let m = self.map8(Soa8::load(chunk).rgb);
            // c ∈ [0, 1]: ⌊min(c · BINS, BINS − 1)⌋ is the scalar bin.
            let bins = m.map(|c| {
                (c * F32x8::splat(BINS as f32)).min(F32x8::splat((BINS - 1) as f32)).to_i32().to_array()
            });
            let values = m.map(F32x8::to_array);
            for (i, rgb) in bytes.chunks_exact_mut(3).enumerate() {
                for (c, byte) in rgb.iter_mut().enumerate() {
                    *byte = e.encode_in_bin(values[c][i], bins[c][i] as usize);
                }
            }
        }
    }

    /// [`ToneMapper::map`] of eight pixels, channel by channel, with the same operations in
    /// the same order, so every lane equals the scalar value bit for bit.
    #[inline(always)]
    fn map8(&self, rgb: [F32x8; 3]) -> [F32x8; 3] {
        let (zero, one) = (F32x8::ZERO, F32x8::splat(1.0));
        let valid = |c: F32x8| c.gt(zero) & c.lt(F32x8::splat(f32::INFINITY));
        let rgb = rgb.map(|c| F32x8::select(valid(c), c, zero) * F32x8::splat(self.scale));
        let out = match self.curve {
            None => rgb,
            Some(ToneCurve::Filmic) => filmic8(rgb),
            Some(ToneCurve::Reinhard) => {
                let l = luminance8(rgb);
                let burn =
                    if self.white > 0.0 { one + l / F32x8::splat(self.white * self.white) } else { one };
                let f = burn / (one + l);
                let lit = l.gt(zero);
                rgb.map(|c| F32x8::select(lit, c * f, zero))
            }
        };
        out.map(|c| c.max(zero).min(one))
    }
}

/// Number of bins of [`Srgb8Encoder`]'s table.
const BINS: usize = 4096;

/// Encodes display-linear values in [0, 1] as 8-bit sRGB codes, round(255 ·
/// [`linear_to_srgb`]), without a `powf` (the display step of every frame encodes every pixel).
/// The linear values where the code steps up are tabulated; a 4096-bin table gives the code at
/// the start of a value's bin, and one comparison with the next step finishes it. The steps
/// are at least 1/(255 · 12.92) ≈ 3.0e-4 apart, more than a bin (2.4e-4), so a bin holds at
/// most one step.
#[derive(Debug)]
pub struct Srgb8Encoder {
    steps: [f32; 255],
    start: [u8; BINS],
}

impl Srgb8Encoder {
    /// The shared encoder (its tables are built on first use).
    pub fn get() -> &'static Self {
        static ENCODER: std::sync::LazyLock<Srgb8Encoder> = std::sync::LazyLock::new(|| {
            let steps: [f32; 255] = std::array::from_fn(|k| srgb_to_linear((k as f32 + 0.5) / 255.0));
            let start =
                std::array::from_fn(|i| steps.partition_point(|&step| step <= i as f32 / BINS as f32) as u8);
            Srgb8Encoder { steps, start }
        });
        &ENCODER
    }

    /// The code of `c` (NaN and negative values give 0, values ≥ 1 give 255).
    #[inline]
    pub fn encode(&self, c: f32) -> u8 {
        self.encode_in_bin(c, ((c * BINS as f32) as usize).min(BINS - 1))
    }

    /// The code of `c` in [0, 1], whose table bin `bin` = ⌊c · BINS⌋ (at most BINS − 1) is
    /// known.
    #[inline(always)]
    fn encode_in_bin(&self, c: f32, bin: usize) -> u8 {
        let code = self.start[bin];
        match self.steps.get(code as usize) {
            Some(&step) if c >= step => code + 1,
            _ => code,
        }
    }
}

/// The 8-bit sRGB code of a display-linear value (see [`Srgb8Encoder`]).
#[inline]
pub fn encode_srgb8(c: f32) -> u8 {
    Srgb8Encoder::get().encode(c)
}

/// The sRGB transfer function (IEC 61966-2-1) of a display-linear value in [0, 1].
#[inline]
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

/// Inverse of [`linear_to_srgb`] (the scene loaders' decoder).
pub use igi_scene::srgb_to_linear;

#[cfg(test)]
mod tests {
    use super::*;

    /// Pixels of every kind: dark, mid, bright, beyond white, black, negative, NaN, infinite.
    fn pixels() -> Vec<Vec3> {
        let mut state = 7u32;
        let mut next = || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 8) as f32 / (1u32 << 24) as f32
        };
        let mut px: Vec<Vec3> =
            (0..997).map(|_| Vec3::new(next(), next(), next()) * 8.0f32.powf(4.0 * next() - 2.0)).collect();
        px.extend([
            Vec3::ZERO,
            Vec3::new(-1.0, 0.5, 0.2),
            Vec3::new(f32::NAN, 0.3, 0.1),
            Vec3::new(f32::INFINITY, 1.0, 1.0),
            Vec3::splat(3e38),
            Vec3::splat(1e-30),
        ]);
        px
    }

    /// The eight-lane encoder writes what the per-pixel one does, byte for byte, for every
    /// operator.
    #[test]
    fn encoding_eight_pixels_at_once_equals_one_at_a_time() {
        let px = pixels();
        let stats = LuminanceStats::of_pixels(&px);
        for op in
            [ToneMap::Filmic { key: 0.18 }, ToneMap::Reinhard { key: 0.18 }, ToneMap::Exposure { stops: 1.5 }]
        {
            for mapper in [ToneMapper::new(op, &stats), ToneMapper::LINEAR] {
                let mut out = vec![0u8; 3 * px.len()];
                mapper.encode_pixels(&px, &mut out);
                for (p, rgb) in px.iter().zip(out.chunks_exact(3)) {
                    assert_eq!(rgb, mapper.to_srgb8(*p), "pixel {p} with {mapper:?}");
                }
            }
        }
    }

    /// The statistics count the lit finite pixels, take the largest luminance and sum
    /// ln(δ + L) to within the SIMD logarithm's accuracy.
    #[test]
    fn statistics_are_the_log_sum_count_and_maximum_of_the_lit_pixels() {
        let px = pixels();
        let s = LuminanceStats::of_pixels(&px);
        let lit: Vec<f32> = px.iter().map(|&p| luminance(p)).filter(|l| *l > 0.0 && l.is_finite()).collect();
        assert_eq!(s.count, lit.len() as u64);
        assert_eq!(s.max, lit.iter().fold(0.0f32, |m, &l| m.max(l)));
        assert_eq!(s.histogram.iter().map(|&c| u64::from(c)).sum::<u64>(), s.count);
        let want: f64 = lit.iter().map(|&l| f64::from(LOG_DELTA + l).ln()).sum();
        assert!((s.log_sum - want).abs() < 1e-5 * lit.len() as f64, "{} vs {want}", s.log_sum);
    }

    /// The percentile follows the counted pixels within a bin's resolution, never exceeds
    /// the largest luminance, and one outlier in a thousand pixels leaves the white point of
    /// the rest, where the maximum would follow it.
    #[test]
    fn the_white_point_is_a_percentile_an_outlier_cannot_move() {
        // 1000 pixels of luminance 1, 2, …, 1000 (up to 2^10).
        let px: Vec<Vec3> = (1..=1000).map(|i| Vec3::splat(i as f32)).collect();
        let s = LuminanceStats::of_pixels(&px);
        for p in [0.5, 0.9, 0.99] {
            let want = p as f32 * 1000.0;
            let got = s.percentile(p);
            assert!(got > want / 2.0 && got < want * 2.0, "p {p}: {got} vs {want}");
        }
        assert_eq!(s.percentile(1.0), s.max);
        let mut with_outlier = px.clone();
        with_outlier[500] = Vec3::splat(1e6);
        let o = LuminanceStats::of_pixels(&with_outlier);
        assert_eq!(o.max, 1e6);
        let (white, white_outlier) = (s.percentile(WHITE_PERCENTILE), o.percentile(WHITE_PERCENTILE));
        assert!((white_outlier / white - 1.0).abs() < 0.05, "{white} vs {white_outlier}");
        // Merged tiles give the statistics of the whole.
        let (a, b) = with_outlier.split_at(377);
        let merged = LuminanceStats::of_pixels(a).merge(LuminanceStats::of_pixels(b));
        assert_eq!((merged.histogram, merged.max, merged.count), (o.histogram, o.max, o.count));
        assert_eq!(LuminanceStats::default().percentile(0.99), 0.0);
    }

    /// The filmic curve maps 0 to 0, never decreases, passes middle grey brighter than
    /// Reinhard's L / (1 + L) does, and saturates to exactly 1.
    #[test]
    fn the_filmic_curve_is_monotonic_from_0_to_1() {
        assert_eq!(filmic_curve(0.0), 0.0);
        let mut last = 0.0;
        for i in 1..=100_000 {
            let l = i as f32 * 1e-4;
            let y = filmic_curve(l);
            assert!(y >= last && y <= 1.0, "f({l}) = {y} after {last}");
            last = y;
        }
        assert_eq!(filmic_curve(7.5), 1.0);
        assert_eq!(filmic_curve(1e30), 1.0);
        assert!(filmic_curve(7.0) > 0.99);
        assert!(filmic_curve(0.18) > 0.18 / 1.18 + 0.1, "{}", filmic_curve(0.18));
    }

    /// Greys stay grey at every brightness; a colour keeps its hue (its direction away from
    /// the grey of its luminance) while it brightens, and ends white, never clipped to a
    /// more yellow or more saturated colour.
    #[test]
    fn filmic_keeps_greys_grey_and_hues_while_highlights_roll_off_to_white() {
        let m = ToneMapper { scale: 1.0, curve: Some(ToneCurve::Filmic), white: 0.0 };
        for i in 0..200 {
            let v = 1e-4 * 1.1f32.powi(i);
            let out = m.map(Vec3::splat(v));
            assert!(out.x == out.y && out.y == out.z, "grey {v} -> {out}");
        }
        let hue = |c: Vec3| (c - Vec3::splat(luminance(c))).normalize();
        for colour in [Vec3::new(1.0, 0.5, 0.1), Vec3::new(0.1, 0.2, 1.0), Vec3::new(0.9, 0.05, 0.3)] {
            let mut last = 0.0;
            for i in 0..120 {
                let input = colour * 0.01 * 1.1f32.powi(i);
                let out = m.map(input);
                assert!(out.max_element() <= 1.0 && luminance(out) >= last, "{input} -> {out}");
                last = luminance(out);
                if out.min_element() < 0.999 {
                    assert!(hue(out).dot(hue(colour)) > 0.9999, "{input} -> {out}: hue moved");
                }
            }
            assert!(m.map(colour * 1e6).min_element() > 0.999, "{colour} x 1e6 is white");
        }
    }
}
