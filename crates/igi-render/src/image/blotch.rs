//! The blotch figure: the share of pixels whose [`WINDOW`]-wide window mean luminance differs
//! from the reference's by more than 10 % ([`Blotch::over_10`]) or 25 %, after the test image is
//! scaled to the reference's mean luminance.
//!
//! Mean FLIP hides the error of one instant-radiosity frame: its few hundred VPLs leave patches
//! of wrong brightness as large as a wall, which FLIP scores like the fine noise of a path
//! tracer at 16 samples per pixel. Noise averages out over a window of 81 pixels, patches do
//! not, so the figure separates them (ARCHITECTURE.md, "Convergence by the blotch figure").
//! The definition is the one of the project's comparison tool, window edges replicated; a
//! test holds the two to the same numbers.

use crate::image::film::Film;
use crate::image::tonemap::luminance;

/// Side of the window whose mean luminance is compared, in pixels.
pub const WINDOW: u32 = 9;

/// A window mean is "off" when it differs from the reference's by more than this share of the
/// reference's window mean plus [`DARK_FLOOR`] times the image's mean luminance.
pub const THRESHOLD: f64 = 0.10;

/// The share of the image's mean luminance added to a window's reference mean before the
/// relative difference is taken, so that the noise of nearly black regions does not count as
/// blotches.
pub const DARK_FLOOR: f64 = 0.02;

/// The blotch figures of an image against a reference.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Blotch {
    /// Share of pixels whose window mean is more than 10 % off (blotch10).
    pub over_10: f64,
    /// Share of pixels whose window mean is more than 25 % off (blotch25).
    pub over_25: f64,
}

impl Blotch {
    /// The figures of `test` against `reference` (the same size; panics otherwise).
    /// Non-finite values count as 0.
    pub fn between(reference: &Film, test: &Film) -> Self {
        assert_eq!(
            (reference.width(), reference.height()),
            (test.width(), test.height()),
            "image sizes differ"
        );
        let lum = |film: &Film| -> Vec<f64> {
            film.pixels()
                .iter()
                .map(|&p| {
                    let l = f64::from(luminance(p));
                    if l.is_finite() { l } else { 0.0 }
                })
                .collect()
        };
        let (w, h) = (reference.width() as usize, reference.height() as usize);
        let (lr, mut lt) = (lum(reference), lum(test));
        let n = (w * h).max(1) as f64;
        let (mean_r, mean_t) = (lr.iter().sum::<f64>() / n, lt.iter().sum::<f64>() / n);
        if mean_t > 0.0 {
            lt.iter_mut().for_each(|l| *l *= mean_r / mean_t);
        }
        let radius = (WINDOW / 2) as usize;
        let (br, bt) = (box_mean(&lr, w, h, radius), box_mean(&lt, w, h, radius));
        let floor = DARK_FLOOR * mean_r + 1e-12;
        let (mut over_10, mut over_25) = (0usize, 0usize);
        for (r, t) in br.iter().zip(&bt) {
            let rel = (t - r).abs() / (r + floor);
            over_10 += usize::from(rel > THRESHOLD);
            over_25 += usize::from(rel > 0.25);
        }
        Self { over_10: over_10 as f64 / n, over_25: over_25 as f64 / n }
    }
}

/// The mean of `values` (a `w` × `h` image, row-major) over the (2r + 1)² window around each
/// pixel, the image's edge pixels repeated outside it: a summed-area table over the padded
/// image.
fn box_mean(values: &[f64], w: usize, h: usize, r: usize) -> Vec<f64> {
    let k = 2 * r + 1;
    let (pw, ph) = (w + 2 * r, h + 2 * r);
    // sat[(y, x)] is the sum of the padded image's rows < y and columns < x.
    let mut sat = vec![0.0f64; (pw + 1) * (ph + 1)];
    for y in 0..ph {
        let sy = y.saturating_sub(r).min(h - 1);
        let mut row = 0.0;
        for x in 0..pw {
            let sx = x.saturating_sub(r).min(w - 1);
            row += values[sy * w + sx];
            sat[(y + 1) * (pw + 1) + x + 1] = sat[y * (pw + 1) + x + 1] + row;
        }
    }
    let at = |y: usize, x: usize| sat[y * (pw + 1) + x];
    let mut out = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let sum = at(y + k, x + k) - at(y, x + k) - at(y + k, x) + at(y, x);
            out.push(sum / (k * k) as f64);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn film(w: u32, h: u32, f: impl Fn(u32, u32) -> f32) -> Film {
        Film::from_pixels(w, h, (0..w * h).map(|i| Vec3::splat(f(i % w, i / w))).collect())
    }

    #[test]
    fn box_mean_repeats_the_edges() {
        // 1D along x: values 0, 1, 2, 3 with a window of 3 repeat the ends.
        let m = box_mean(&[0.0, 1.0, 2.0, 3.0], 4, 1, 1);
        let want = [1.0 / 3.0, 1.0, 2.0, 8.0 / 3.0];
        assert!(m.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-12), "{m:?}");
    }

    #[test]
    fn an_image_has_no_blotch_against_itself_or_a_brighter_copy() {
        let a = film(40, 30, |x, y| 0.1 + (x * y) as f32 * 0.01);
        let brighter = film(40, 30, |x, y| 3.0 * (0.1 + (x * y) as f32 * 0.01));
        assert_eq!(Blotch::between(&a, &a), Blotch::default());
        assert_eq!(Blotch::between(&a, &brighter), Blotch::default());
    }

    /// The same numbers as the project's comparison tool (`compare.py`, `blotch()`), which
    /// returns (0.274, 0.182) for these two images:
    ///
    /// ```text
    /// ref = 1 + x/50 (50×40);  test = ref, times 1.6 on the square 10 ≤ x, y < 30,
    ///                                and 0 on the corner x < 6, y ≥ 34
    /// ```
    #[test]
    fn agrees_with_the_comparison_tool() {
        let reference = film(50, 40, |x, _| 1.0 + x as f32 / 50.0);
        let test = film(50, 40, |x, y| {
            let r = 1.0 + x as f32 / 50.0;
            match (x, y) {
                (10..30, 10..30) => 1.6 * r,
                (0..6, 34..) => 0.0,
                _ => r,
            }
        });
        let b = Blotch::between(&reference, &test);
        assert!((b.over_10 - 0.274).abs() < 1e-9 && (b.over_25 - 0.182).abs() < 1e-9, "{b:?}");
    }
}
