//! Interleaved sampling (paper 2.1 and 3.3, Keller & Heidrich 2001): which VPL set lights a
//! pixel, which part of the set lights each of its anti-aliasing samples, where those samples
//! lie in the pixel, and how a tile's pixels of one set are grouped into 8-ray packets
//! (paper Figure 2).
//!
//! Pixel (x, y) belongs to set (x mod n) + n·(y mod m), so every n×m window of the image holds
//! one pixel of every set, which is what the discontinuity filter averages over. With N
//! samples per pixel, a pixel whose samples all see one surface is shaded once and lit by its
//! whole set; in a pixel across an edge, sample j is lit by the VPLs j, j + N, j + 2N, … of
//! the pixel's set, weighted by N. Either way each pixel uses each VPL of its set once, so
//! anti-aliasing costs extra primary rays only ([`crate::tile_pipeline`]).

use crate::frame::IgiSettings;
use crate::pixel_rect::PixelRect;
use crate::sampling::sobol4;
use crate::tile::Tile;

/// The interleaving pattern of a frame: n×m VPL sets and N samples per pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Interleave {
    /// Pattern width n.
    pub n: u32,
    /// Pattern height m.
    pub m: u32,
    /// Samples per pixel N.
    pub aa: u32,
}

impl Interleave {
    /// The pattern of `settings`.
    pub fn of(settings: &IgiSettings) -> Self {
        Self { n: settings.interleave[0], m: settings.interleave[1], aa: settings.aa }
    }

    /// Number of sets, n·m.
    pub fn sets(&self) -> u32 {
        self.n * self.m
    }

    /// The filter window around a pixel as offsets `[left, right]` in x and `[up, down]` in y:
    /// the pixel at offset 0 plus (n − 1) neighbours in x split as evenly as possible, the same
    /// in y. Any such window holds one pixel of each set.
    pub fn window(&self) -> ([u32; 2], [u32; 2]) {
        ([(self.n - 1) / 2, self.n / 2], [(self.m - 1) / 2, self.m / 2])
    }

    /// `tile` grown by the filter window (the apron, paper 3.4) and clipped to a `width` ×
    /// `height` image. Every pixel the filter of the tile reads lies in it.
    pub fn region(&self, tile: &Tile, width: u32, height: u32) -> PixelRect {
        let ([left, right], [up, down]) = self.window();
        PixelRect {
            x0: tile.rect.x0.saturating_sub(left),
            y0: tile.rect.y0.saturating_sub(up),
            x1: (tile.rect.x1 + right).min(width),
            y1: (tile.rect.y1 + down).min(height),
        }
    }

    /// Where sample `index` of a pixel lies in it, as offsets in [0, 1)² from its top-left
    /// corner: the centre if `centre` (one sample per pixel in a still frame), else point
    /// `index` of the Owen-scrambled Sobol sequence of the pixel's sequence seed
    /// `pixel_seed` ([`crate::sampling::pixel_seed`]: stratified within the pixel; see
    /// [`crate::frame::FrameState::sequence`] for the index).
    #[inline]
    pub fn sample_offset(&self, index: u32, pixel_seed: u32, centre: bool) -> (f32, f32) {
        if centre {
            return (0.5, 0.5);
        }
        let [u, v, _, _] = sobol4(index, 0, pixel_seed);
        (u, v)
    }

    /// The pixels of set `set` inside `region`, grouped into packets of 4×2 pixels of the set's
    /// sub-grid (paper Figure 2: neighbouring pixels of one set, so each packet's rays stay
    /// coherent). Each packet lists up to 8 pixels; the last ones of a row or column may be
    /// partial.
    pub fn packets(&self, region: &PixelRect, set: u32, mut f: impl FnMut(&[(u32, u32)])) {
        let (sx, sy) = (set % self.n, set / self.n);
        let first = |start: u32, phase: u32, period: u32| start + (phase + period - start % period) % period;
        let (x_first, y_first) = (first(region.x0, sx, self.n), first(region.y0, sy, self.m));
        let xs: Vec<u32> = (x_first..region.x1).step_by(self.n as usize).collect();
        let ys: Vec<u32> = (y_first..region.y1).step_by(self.m as usize).collect();
        let mut lanes = Vec::with_capacity(8);
        for row in ys.chunks(2) {
            for col in xs.chunks(4) {
                lanes.clear();
                for &y in row {
                    lanes.extend(col.iter().map(|&x| (x, y)));
                }
                f(&lanes);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The set of pixel `(x, y)`, (x mod n) + n·(y mod m) (the module documentation).
    fn set_of(il: &Interleave, x: u32, y: u32) -> u32 {
        x % il.n + il.n * (y % il.m)
    }

    #[test]
    fn every_window_holds_every_set_once() {
        for (n, m) in [(3, 3), (2, 4), (4, 1), (1, 1)] {
            let il = Interleave { n, m, aa: 1 };
            let ([l, r], [u, d]) = il.window();
            assert_eq!(l + r + 1, n);
            assert_eq!(u + d + 1, m);
            for (cx, cy) in [(5u32, 7u32), (10, 3)] {
                let mut seen = vec![0; il.sets() as usize];
                for y in cy - u..=cy + d {
                    for x in cx - l..=cx + r {
                        seen[set_of(&il, x, y) as usize] += 1;
                    }
                }
                assert!(seen.iter().all(|&c| c == 1), "{n}x{m}: {seen:?}");
            }
        }
    }

    #[test]
    fn packets_cover_each_pixel_of_a_set_once() {
        let il = Interleave { n: 3, m: 3, aa: 1 };
        let region = PixelRect { x0: 5, y0: 2, x1: 40, y1: 23 };
        let mut count = vec![0; region.pixel_count()];
        for set in 0..il.sets() {
            il.packets(&region, set, |lanes| {
                assert!(!lanes.is_empty() && lanes.len() <= 8);
                for &(x, y) in lanes {
                    assert_eq!(set_of(&il, x, y), set);
                    count[region.index(x, y)] += 1;
                }
            });
        }
        assert!(count.iter().all(|&c| c == 1));
    }

    #[test]
    fn region_is_the_tile_plus_the_apron_inside_the_image() {
        let il = Interleave { n: 3, m: 3, aa: 1 };
        let tile = Tile { index: 0, rect: PixelRect { x0: 0, y0: 16, x1: 16, y1: 32 } };
        assert_eq!(il.region(&tile, 20, 32), PixelRect { x0: 0, y0: 15, x1: 17, y1: 32 });
    }
}
