//! Tone mapping: from linear radiance to display values in [0, 1], then sRGB-encoded 8-bit.
//!
//! Two operators:
//! - [`ToneMap::Reinhard`] (the default): the global operator of Reinhard et al. 2002,
//!   "Photographic Tone Reproduction for Digital Images", eq. 1-3. The log-average luminance
//!   L̄ = exp(mean(ln(δ + L))) of the image maps to the middle grey `key` (0.18), then
//!   L_d = L / (1 + L) compresses highlights. Colours are scaled by L_d / L (hue kept) and
//!   clipped per channel.
//! - [`ToneMap::Exposure`]: a fixed linear scale by 2^stops and a clip at 1, for comparable
//!   images across frames and scenes.
//!
//! Image statistics are gathered in [`LuminanceStats`], which merge: a tile can report its own
//! and the compositor combines them in tile order (DESIGN.md section 1, paper 3.4).

use crate::film::Film;
use crate::lights::luminance;
use glam::Vec3;

/// δ of the log-average: keeps ln finite for black pixels.
const LOG_DELTA: f64 = 1e-6;

/// Luminance statistics of a set of pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LuminanceStats {
    /// Σ ln(δ + L) over the counted pixels.
    pub log_sum: f64,
    /// Number of counted pixels.
    pub count: u64,
    /// Largest luminance seen.
    pub max: f32,
}

impl LuminanceStats {
    /// Adds one pixel. Pixels of zero (or invalid) luminance, such as background or full
    /// shadow, are not counted, so a small object on black is not exposed as if the image
    /// were mostly dark.
    #[inline]
    pub fn add(&mut self, rgb: Vec3) {
        let l = luminance(rgb);
        if l > 0.0 && l.is_finite() {
            self.log_sum += (LOG_DELTA + f64::from(l)).ln();
            self.count += 1;
            self.max = self.max.max(l);
        }
    }

    /// The statistics of `pixels`, accumulated in order.
    pub fn of_pixels(pixels: &[Vec3]) -> Self {
        let mut s = Self::default();
        pixels.iter().for_each(|&p| s.add(p));
        s
    }

    /// The statistics of both sets (combine tiles in a fixed order for reproducible sums).
    pub fn merge(self, o: Self) -> Self {
        Self { log_sum: self.log_sum + o.log_sum, count: self.count + o.count, max: self.max.max(o.max) }
    }

    /// The log-average luminance, or `None` if no pixel was counted.
    pub fn log_average(&self) -> Option<f32> {
        (self.count > 0).then(|| (self.log_sum / self.count as f64).exp() as f32)
    }
}

/// How linear radiance becomes a display value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ToneMap {
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

impl Default for ToneMap {
    fn default() -> Self {
        Self::Reinhard { key: 0.18 }
    }
}

impl ToneMap {
    /// `Exposure` if `stops` is given, else the default Reinhard operator.
    pub fn from_exposure(stops: Option<f32>) -> Self {
        stops.map_or_else(Self::default, |stops| Self::Exposure { stops })
    }
}

/// A tone map with its parameters fixed, ready to map pixels.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ToneMapper {
    /// Linear scale applied to radiance first.
    pub scale: f32,
    /// Whether the Reinhard compression L / (1 + L) follows.
    pub compress: bool,
}

impl ToneMapper {
    /// Fixes the parameters of `op` for an image with statistics `stats`.
    pub fn new(op: ToneMap, stats: &LuminanceStats) -> Self {
        match op {
            ToneMap::Exposure { stops } => Self { scale: stops.exp2(), compress: false },
            ToneMap::Reinhard { key } => {
                let scale =
                    stats.log_average().filter(|a| *a > 0.0 && a.is_finite()).map_or(1.0, |a| key / a);
                Self { scale, compress: true }
            }
        }
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
        let out = if self.compress {
            let l = luminance(rgb);
            if l > 0.0 { rgb * (1.0 / (1.0 + l)) } else { Vec3::ZERO }
        } else {
            rgb
        };
        out.clamp(Vec3::ZERO, Vec3::ONE)
    }

    /// 8-bit sRGB of radiance `rgb`.
    #[inline]
    pub fn to_srgb8(&self, rgb: Vec3) -> [u8; 3] {
        self.map(rgb).to_array().map(|c| (linear_to_srgb(c) * 255.0 + 0.5) as u8)
    }
}

/// The sRGB transfer function (IEC 61966-2-1) of a display-linear value in [0, 1].
#[inline]
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

/// Inverse of [`linear_to_srgb`].
#[inline]
pub fn srgb_to_linear(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.040_45 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}
