//! [`Accumulator`]: the running mean of the frames of a still view. Each frame uses fresh VPL
//! sets and sample patterns (consecutive blocks of one Sobol sequence, see
//! `FrameState::sequence`), so the mean converges to the instant-radiosity solution.

use glam::Vec3;
use igi_render::Film;

/// Sum of the frames since the last reset.
#[derive(Clone, Debug, Default)]
pub struct Accumulator {
    sum: Vec<Vec3>,
    width: u32,
    height: u32,
    frames: u32,
}

impl Accumulator {
    /// Forgets every frame.
    pub fn reset(&mut self) {
        self.frames = 0;
    }

    /// Frames in the mean.
    pub fn frames(&self) -> u32 {
        self.frames
    }

    /// Adds a frame (a frame of another size starts over).
    pub fn add(&mut self, film: &Film) {
        if self.frames == 0 || (film.width(), film.height()) != (self.width, self.height) {
            self.sum.clear();
            self.sum.extend_from_slice(film.pixels());
            (self.width, self.height, self.frames) = (film.width(), film.height(), 1);
            return;
        }
        self.sum.iter_mut().zip(film.pixels()).for_each(|(s, p)| *s += *p);
        self.frames += 1;
    }

    /// The mean of the frames added since the last reset (an empty film before the first).
    pub fn mean(&self) -> Film {
        let scale = 1.0 / self.frames.max(1) as f32;
        let pixels =
            if self.frames == 0 { Vec::new() } else { self.sum.iter().map(|&s| s * scale).collect() };
        Film::from_pixels(
            if self.frames == 0 { 0 } else { self.width },
            if self.frames == 0 { 0 } else { self.height },
            pixels,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_of_frames_and_reset() {
        let mut acc = Accumulator::default();
        acc.add(&Film::from_pixels(2, 1, vec![Vec3::ONE, Vec3::ZERO]));
        acc.add(&Film::from_pixels(2, 1, vec![Vec3::splat(3.0), Vec3::X]));
        assert_eq!(acc.frames(), 2);
        assert_eq!(acc.mean().pixels(), &[Vec3::splat(2.0), Vec3::new(0.5, 0.0, 0.0)]);
        acc.reset();
        acc.add(&Film::from_pixels(1, 1, vec![Vec3::Y]));
        assert_eq!((acc.frames(), acc.mean().pixels()), (1, &[Vec3::Y][..]));
    }
}
