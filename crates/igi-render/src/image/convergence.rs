//! When a mean of frames is done: the stopping rule of accumulation ([`Until`]) and the
//! estimate of a mean's remaining error from its own frames ([`BlotchEstimate`]).
//!
//! The error that matters in a mean of instant-radiosity frames is the patches of wrong
//! brightness each frame's VPLs leave ([`crate::image::blotch`]); the frames of a mean carry
//! independent ones. So the image is cut into [`WINDOW`]-pixel blocks, and each frame's block
//! means of luminance, divided by the frame's mean luminance (the blotch figure compares
//! images after matching their means), give per block a sample mean M and a sample variance
//! s² over the k frames so far. The mean image's block is off by a normal error of standard
//! deviation σ = s/√k, so the share of blocks more than [`THRESHOLD`] off is estimated as
//!
//! ```text
//! blotch10 ≈ mean over blocks of erfc(t / (σ √2)),   t = THRESHOLD · (M + DARK_FLOOR)
//! ```
//!
//! the expected value of the figure against the converged image, as adaptive renderers stop
//! on a variance estimate. The estimate sees noise only, not bias (the filter's blur, the
//! clamp's remainder), and it needs a few frames before s² means anything
//! ([`StoppingRule::min_frames`]).

use crate::image::blotch::{DARK_FLOOR, THRESHOLD, WINDOW};
use crate::image::film::Film;
use crate::image::tonemap::luminance;
use std::time::Duration;

/// When accumulating frames stops.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Until {
    /// After exactly this many frames.
    Frames(u32),
    /// When the stopping rule says the mean is done.
    Converged(StoppingRule),
}

/// The stopping rule of a converging mean: the estimated blotch figure reaches `target`, with
/// a time budget as the ceiling.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StoppingRule {
    /// The estimated blotch10 at which the mean is done.
    pub target: f64,
    /// No frame starts that is expected to end after this time from the first frame's start
    /// (the first frame always runs).
    pub time_budget: Duration,
    /// Frames before the estimate is trusted: the variance of fewer frames is itself too
    /// noisy to stop on.
    pub min_frames: u32,
}

impl StoppingRule {
    /// The rule of `igi render` with the time budget `time_budget`: an estimated blotch10 of
    /// 0.5 %, after at least 4 frames. The estimate errs either way by a factor of about two
    /// (it sees noise only, and consecutive frames of one sequence are better than
    /// independent); at 0.5 % the measured figure against converged references is at most
    /// 1 % (ARCHITECTURE.md, "Convergence by the blotch figure").
    pub fn still_image(time_budget: Duration) -> Self {
        Self { target: 0.005, time_budget, min_frames: 4 }
    }
}

/// Why a mean stopped where it did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stopped {
    /// It had the frames it was asked for.
    Frames,
    /// Its estimated blotch figure reached the target.
    Converged,
    /// Another frame would have overrun the time budget.
    TimeBudget,
}

/// The running block statistics of the frames of a mean, from which its remaining error is
/// estimated (see the module documentation).
#[derive(Clone, Debug, Default)]
pub struct BlotchEstimate {
    /// Blocks across and down.
    blocks: (usize, usize),
    /// Pixels per block (smaller at the right and bottom edges).
    pixels: Vec<u32>,
    /// Per block: the running mean and sum of squared deviations (Welford) of the block's
    /// normalised luminance over the frames.
    mean: Vec<f64>,
    m2: Vec<f64>,
    frames: u32,
    /// Scratch: one frame's block sums.
    sums: Vec<f64>,
}

impl BlotchEstimate {
    /// An estimate over no frame yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Frames added.
    pub fn frames(&self) -> u32 {
        self.frames
    }

    /// Adds a frame of the mean (a frame of another size starts the estimate anew). A black
    /// frame carries no information about relative error and is skipped.
    pub fn add(&mut self, film: &Film) {
        let (w, h) = (film.width() as usize, film.height() as usize);
        let b = WINDOW as usize;
        let blocks = (w.div_ceil(b), h.div_ceil(b));
        if blocks != self.blocks {
            *self = Self { blocks, ..Self::default() };
            self.pixels = vec![0; blocks.0 * blocks.1];
            for y in 0..h {
                for x in 0..w {
                    self.pixels[(y / b) * blocks.0 + x / b] += 1;
                }
            }
            self.mean = vec![0.0; self.pixels.len()];
            self.m2 = vec![0.0; self.pixels.len()];
        }
        self.sums.clear();
        self.sums.resize(self.pixels.len(), 0.0);
        let mut total = 0.0;
        for (i, &p) in film.pixels().iter().enumerate() {
            let l = f64::from(luminance(p));
            let l = if l.is_finite() { l } else { 0.0 };
            self.sums[(i / w / b) * blocks.0 + (i % w) / b] += l;
            total += l;
        }
        let frame_mean = total / (w * h).max(1) as f64;
        if frame_mean <= 0.0 {
            return;
        }
        self.frames += 1;
        let k = f64::from(self.frames);
        for (j, &sum) in self.sums.iter().enumerate() {
            let v = sum / f64::from(self.pixels[j]) / frame_mean;
            let delta = v - self.mean[j];
            self.mean[j] += delta / k;
            self.m2[j] += delta * (v - self.mean[j]);
        }
    }

    /// The estimated blotch10 of the mean of the frames so far; `None` before two frames.
    pub fn blotch(&self) -> Option<f64> {
        if self.frames < 2 {
            return None;
        }
        let k = f64::from(self.frames);
        let (mut sum, mut count) = (0.0, 0.0);
        for ((&mean, &m2), &pixels) in self.mean.iter().zip(&self.m2).zip(&self.pixels) {
            let sigma = (m2 / (k - 1.0) / k).sqrt();
            let t = THRESHOLD * (mean + DARK_FLOOR);
            let off = if sigma > 0.0 { libm::erfc(t / (sigma * std::f64::consts::SQRT_2)) } else { 0.0 };
            sum += off * f64::from(pixels);
            count += f64::from(pixels);
        }
        Some(sum / count.max(1.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::hash32;
    use glam::Vec3;

    /// Frames that are a smooth image times per-block factors 1 + σ·z (z standard normal):
    /// the estimate of the mean of k such frames is close to the share predicted for blocks
    /// off by σ/√k.
    #[test]
    fn the_estimate_predicts_the_share_of_blocks_off_by_noise() {
        let (w, h, sigma) = (180u32, 90u32, 0.3f64);
        let mut state = 7u32;
        let mut uniform = || {
            // In (0, 1].
            state = hash32(state.wrapping_add(1));
            (f64::from(state) + 1.0) / 4294967296.0
        };
        // Box-Muller.
        let mut normal = || (-2.0 * uniform().ln()).sqrt() * (std::f64::consts::TAU * uniform()).cos();
        let mut estimate = BlotchEstimate::new();
        assert_eq!(estimate.blotch(), None);
        for k in 1..=16 {
            let factors: Vec<f64> = (0..(w / 9) * (h / 9)).map(|_| 1.0 + sigma * normal()).collect();
            let film = Film::from_pixels(
                w,
                h,
                (0..w * h)
                    .map(|i| {
                        let (x, y) = (i % w, i / w);
                        Vec3::splat(
                            (factors[((y / 9) * (w / 9) + x / 9) as usize] * (1.0 + x as f64 / 400.0)) as f32,
                        )
                    })
                    .collect(),
            );
            estimate.add(&film);
            if k >= 4 {
                // Relative error of one block of the mean: about σ/√k (the frame mean barely
                // moves over 200 blocks).
                let want = libm::erfc(THRESHOLD / (sigma / f64::from(k).sqrt() * std::f64::consts::SQRT_2));
                let got = estimate.blotch().unwrap();
                assert!((got - want).abs() < 0.25 * want + 0.01, "{k} frames: {got} against {want}");
            }
        }
    }

    #[test]
    fn identical_frames_have_no_error_and_a_new_size_starts_anew() {
        let film = Film::from_pixels(20, 10, (0..200).map(|i| Vec3::splat(1.0 + i as f32)).collect());
        let mut estimate = BlotchEstimate::new();
        estimate.add(&film);
        estimate.add(&film);
        assert_eq!(estimate.blotch(), Some(0.0));
        estimate.add(&Film::new(5, 5));
        assert_eq!(estimate.frames(), 0, "a black frame of a new size: nothing to estimate from");
        estimate.add(&Film::from_pixels(5, 5, vec![Vec3::ONE; 25]));
        assert_eq!((estimate.frames(), estimate.blotch()), (1, None));
    }
}
