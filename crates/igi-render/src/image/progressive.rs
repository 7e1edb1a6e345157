//! [`Progressive`]: what carries over from one frame of a view to the next. It is the one owner
//! of two mechanisms:
//!
//! - **progressive refinement**: while the view stands still, frames with fresh VPL sets and
//!   sample patterns (consecutive blocks of one Sobol sequence, see
//!   [`FrameState::sequence`](crate::FrameState::sequence)) are averaged, and the mean converges
//!   to the instant-radiosity solution;
//! - **tone-map feedback** (paper 3.4): each frame is tone-mapped with the luminance
//!   statistics of the image shown before it, so render nodes can send finished 8-bit pixels.
//!
//! A frame's statistics are those its tiles combined in tile order; a mean of several frames
//! is measured itself, and its display image is tone-mapped with its own statistics. While the
//! view moves (one frame at a time), the next tone map only moves part of the way toward the
//! last frame's ([`TONE_MAP_ADAPTATION`]), so exposure and white point do not jump with the
//! VPLs of each frame.

use crate::image::film::Film;
use crate::image::frame_image::FrameImage;
use crate::image::tonemap::{LuminanceStats, ToneMap, ToneMapper};
use glam::Vec3;

/// The share of the way, in log exposure and log white point, that the tone map of a moving
/// view goes toward the last frame's statistics each frame: a change of view settles to within
/// 10 % of its stops in 8 frames (0.75⁸ ≈ 0.1).
pub const TONE_MAP_ADAPTATION: f32 = 0.25;

/// The running mean of a view's frames and the tone map of its next frame.
#[derive(Clone, Debug)]
pub struct Progressive {
    tone_map: ToneMap,
    /// The tone map of the next frame.
    next: ToneMapper,
    sum: Vec<Vec3>,
    width: u32,
    height: u32,
    frames: u32,
    /// The last frame as rendered while it is what to show (an 8-bit frame, or the first of a
    /// mean); `None` once a mean of several frames is.
    latest: Option<Shown>,
    /// Whether `next` comes from an image's statistics yet (else it is the guess of `new`).
    measured: bool,
}

/// What a view shows after a frame: its image (or the mean of the frames so far) and the
/// image's luminance statistics.
#[derive(Clone, Debug)]
pub struct Shown {
    /// The image.
    pub image: FrameImage,
    /// Its luminance statistics.
    pub stats: LuminanceStats,
}

impl Progressive {
    /// A view with no frame yet, tone-mapped with `tone_map`. Before any statistics exist its
    /// first frame's tone map is exact for a fixed exposure and a guess for Reinhard.
    pub fn new(tone_map: ToneMap) -> Self {
        Self {
            tone_map,
            next: ToneMapper::new(tone_map, &LuminanceStats::default()),
            sum: Vec::new(),
            width: 0,
            height: 0,
            frames: 0,
            latest: None,
            measured: false,
        }
    }

    /// Changes the tone map from the next image shown on.
    pub fn set_tone_map(&mut self, tone_map: ToneMap) {
        self.tone_map = tone_map;
    }

    /// The tone map of the next frame: fixed from the statistics of the last image shown.
    pub fn tone_mapper(&self) -> ToneMapper {
        self.next
    }

    /// Frames in the mean (0 after a reset).
    pub fn frames(&self) -> u32 {
        self.frames
    }

    /// Forgets the frames averaged so far (the view changed). The tone-map feedback goes on.
    pub fn reset(&mut self) {
        self.frames = 0;
    }

    /// Takes a rendered frame and its tile statistics. A linear frame joins the mean (a frame
    /// of another size starts it anew); an 8-bit frame, which cannot be averaged, ends it.
    pub fn add(&mut self, image: FrameImage, stats: LuminanceStats) {
        match image.film() {
            None => self.frames = 0,
            Some(film) if self.frames == 0 || (film.width(), film.height()) != (self.width, self.height) => {
                self.sum.clear();
                self.sum.extend_from_slice(film.pixels());
                (self.width, self.height, self.frames) = (film.width(), film.height(), 1);
            }
            Some(film) => {
                self.sum.iter_mut().zip(film.pixels()).for_each(|(s, p)| *s += *p);
                self.frames += 1;
                self.latest = None;
                return;
            }
        }
        self.latest = Some(Shown { image, stats });
    }

    /// What to show now: the last frame itself while the mean has one frame (or it came as
    /// 8-bit pixels), else the mean, measured and tone-mapped with its own statistics (an
    /// empty image before any frame). The next frame's tone map follows from its statistics.
    /// Averaging many frames and showing only the end measures and encodes the mean once.
    pub fn show(&mut self) -> Shown {
        let single = self.latest.is_some();
        let shown = match self.latest.take() {
            Some(latest) => latest,
            None if self.frames == 0 => Shown {
                image: FrameImage::Srgb8 { width: 0, height: 0, bytes: Vec::new() },
                stats: LuminanceStats::default(),
            },
            None => {
                let scale = 1.0 / self.frames as f32;
                let mean =
                    Film::from_pixels(self.width, self.height, self.sum.iter().map(|&s| s * scale).collect());
                let stats = LuminanceStats::of_pixels(mean.pixels());
                Shown { image: FrameImage::from_film(mean, &ToneMapper::new(self.tone_map, &stats)), stats }
            }
        };
        let measured = ToneMapper::new(self.tone_map, &shown.stats);
        self.next = if single && self.measured && shown.stats.count > 0 {
            self.next.adapted_toward(&measured, TONE_MAP_ADAPTATION)
        } else {
            measured
        };
        self.measured |= shown.stats.count > 0;
        shown
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn linear(pixels: Vec<Vec3>) -> (FrameImage, LuminanceStats) {
        let stats = LuminanceStats::of_pixels(&pixels);
        let film = Film::from_pixels(pixels.len() as u32, 1, pixels);
        (FrameImage::from_film(film, &ToneMapper::LINEAR), stats)
    }

    #[test]
    fn mean_of_frames_and_reset() {
        let mut p = Progressive::new(ToneMap::default());
        let (a, sa) = linear(vec![Vec3::ONE, Vec3::ZERO]);
        p.add(a.clone(), sa);
        assert_eq!(p.show().image, a, "one frame is shown as rendered");
        let (b, sb) = linear(vec![Vec3::splat(3.0), Vec3::X]);
        p.add(b, sb);
        let shown = p.show();
        assert_eq!(p.frames(), 2);
        assert_eq!(shown.image.film().unwrap().pixels(), &[Vec3::splat(2.0), Vec3::new(0.5, 0.0, 0.0)]);
        assert_eq!(shown.stats, LuminanceStats::of_pixels(shown.image.film().unwrap().pixels()));
        assert_eq!(p.tone_mapper(), ToneMapper::new(ToneMap::default(), &shown.stats));
        p.reset();
        let (c, sc) = linear(vec![Vec3::Y]);
        p.add(c, sc);
        assert_eq!((p.show().image.film().unwrap().pixels(), p.frames()), (&[Vec3::Y][..], 1));
    }

    #[test]
    fn an_8bit_frame_ends_the_mean_and_feeds_the_tone_map() {
        let mut p = Progressive::new(ToneMap::default());
        let (a, sa) = linear(vec![Vec3::ONE]);
        p.add(a, sa);
        let stats = LuminanceStats { log_sum: 0.5, count: 1, max: 2.0, ..LuminanceStats::default() };
        let image = FrameImage::Srgb8 { width: 1, height: 1, bytes: vec![1, 2, 3] };
        p.add(image.clone(), stats);
        assert_eq!(p.show().image, image);
        assert_eq!(p.frames(), 0);
        // Nothing was shown before it: its statistics set the tone map at once.
        assert_eq!(p.tone_mapper(), ToneMapper::new(ToneMap::default(), &stats));
    }

    /// A moving view's tone map goes part of the way toward each frame's; the first measured
    /// frame and a still view's mean set it at once.
    #[test]
    fn a_moving_views_tone_map_adapts_over_frames() {
        let mut p = Progressive::new(ToneMap::default());
        let (dark, sd) = linear(vec![Vec3::splat(0.01), Vec3::splat(0.02)]);
        p.add(dark, sd);
        p.show();
        let at_dark = ToneMapper::new(ToneMap::default(), &sd);
        assert_eq!(p.tone_mapper(), at_dark, "the first frame sets the tone map");
        let (bright, sb) = linear(vec![Vec3::splat(10.0), Vec3::splat(20.0)]);
        let at_bright = ToneMapper::new(ToneMap::default(), &sb);
        let mut stops = Vec::new();
        for _ in 0..8 {
            p.reset();
            p.add(bright.clone(), sb);
            p.show();
            stops.push((p.tone_mapper().scale / at_bright.scale).log2().abs());
        }
        // log2 of the scale is off by (1 − a)^k of the jump's ten stops.
        let jump = (at_dark.scale / at_bright.scale).log2().abs();
        for (k, s) in stops.iter().enumerate() {
            let want = jump * (1.0 - TONE_MAP_ADAPTATION).powi(k as i32 + 1);
            assert!((s - want).abs() < 1e-3 * jump, "frame {k}: {s} stops off, want {want}");
        }
        // A still view's mean is measured and sets the tone map at once.
        p.add(bright.clone(), sb);
        p.show();
        assert_eq!(p.tone_mapper(), at_bright);
    }
}
