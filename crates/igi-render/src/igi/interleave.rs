//! Interleaved sampling (paper 2.1 and 3.3, Keller & Heidrich 2001): which VPL set lights a
//! pixel, which part of the set lights each of its anti-aliasing samples, where those samples
//! lie in the pixel, and how a tile's pixels of one set are grouped into blocks of eight
//! (paper Figure 2), the order in which they are shaded and lit.
//!
//! Pixel (x, y) belongs to fine set (x mod n) + n·(y mod m), so every n×m window of the image
//! holds one pixel of every fine set, which is what the discontinuity filter averages over.
//! A second, coarse level (ARCHITECTURE.md, "Two levels of interleaving") repeats the idea one
//! scale up: the n×m block (⌊x/n⌋, ⌊y/m⌋) uses group (⌊x/n⌋ mod K) + K·(⌊y/m⌋ mod K) of K²
//! groups of n·m sets, so pixel (x, y) is lit by set fine + n·m·group, and the pixels of one
//! set lie on a lattice of period nK × mK. The filter's second level merges the groups over
//! (2K − 1)² taps at stride (n, m) around the pixel, weighted by the tent
//! (1 − |i|/K)(1 − |j|/K) of the tap's offset (i, j): over the taps of one residue mod K the
//! tent sums to one, so every set weighs the same and each set's lattice is interpolated
//! bilinearly. A box of K×K taps would hold each set's one lattice point constant over the
//! window, and a set's error would show as an nK × mK square (ARCHITECTURE.md, "The coarse
//! level's tent"). The frame thereby holds K² times the
//! VPLs at the same VPLs per pixel; a VPL's shadow rays come from pixels nK and mK apart. With N
//! samples per pixel, a pixel whose samples all see one surface is shaded once and lit by its
//! whole set; in a pixel across an edge, sample j is lit by the VPLs j, j + N, j + 2N, … of
//! the pixel's set, weighted by N. Either way each pixel uses each VPL of its set once, so
//! anti-aliasing costs extra primary rays only ([`crate::igi::tile_pipeline`]).

use crate::frame::FrameSettings;
use crate::image::pixel_rect::PixelRect;
use crate::image::tile::Tile;
use crate::sampling::Sobol2;

/// The interleaving pattern of a frame: n×m fine sets in K² coarse groups, and N samples per
/// pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Interleave {
    /// Pattern width n.
    pub n: u32,
    /// Pattern height m.
    pub m: u32,
    /// The coarse pattern's side K (1: one level).
    pub coarse: u32,
    /// Samples per pixel N.
    pub aa: u32,
}

/// Offsets of a filter window around its centre: `[left, right]` in x and `[up, down]` in y.
pub type Window = ([u32; 2], [u32; 2]);

impl Interleave {
    /// The pattern of `settings`.
    pub fn of(settings: &FrameSettings) -> Self {
        Self {
            n: settings.interleave[0],
            m: settings.interleave[1],
            coarse: settings.coarse_interleave,
            aa: settings.aa,
        }
    }

    /// Number of fine sets, n·m: the pipeline shades and lights the pixels of one fine set at a
    /// time.
    pub fn fine_sets(&self) -> u32 {
        self.n * self.m
    }

    /// Number of sets, n·m·K².
    pub fn sets(&self) -> u32 {
        self.fine_sets() * self.coarse * self.coarse
    }

    /// The set of the pixels of fine set `fine` in the n×m block of pixel (x, y).
    #[inline]
    pub fn set(&self, fine: u32, x: u32, y: u32) -> u32 {
        let group = (x / self.n) % self.coarse + self.coarse * ((y / self.m) % self.coarse);
        fine + self.fine_sets() * group
    }

    /// The first filter level's window around a pixel, in pixels: the pixel at offset 0 plus
    /// (n − 1) neighbours in x split as evenly as possible, the same in y. Any such window
    /// holds one pixel of each fine set.
    pub fn window(&self) -> Window {
        ([(self.n - 1) / 2, self.n / 2], [(self.m - 1) / 2, self.m / 2])
    }

    /// The second filter level's window, in taps at stride (n, m): K − 1 taps on each side of
    /// the centre, where the tent of [`Interleave::coarse_weight`] is above zero (none without
    /// a coarse level).
    pub fn coarse_window(&self) -> Window {
        let k = self.coarse - 1;
        ([k, k], [k, k])
    }

    /// The second level's weight of the tap `(i, j)` taps away from the centre: the tent
    /// (1 − |i|/K)(1 − |j|/K). For every residue r mod K, the weights of the offsets ≡ r sum
    /// to one along each axis, so each set's taps together weigh one.
    #[inline]
    pub fn coarse_weight(&self, i: u32, j: u32) -> f32 {
        self.coarse_tent(i) * self.coarse_tent(j)
    }

    /// One axis of [`Interleave::coarse_weight`]: 1 − |i|/K.
    #[inline]
    pub fn coarse_tent(&self, i: u32) -> f32 {
        1.0 - i as f32 / self.coarse as f32
    }

    /// The apron of both filter levels: how far the filter of a pixel reads, in pixels.
    pub fn apron(&self) -> Window {
        let (([l, r], [u, d]), ([cl, cr], [cu, cd])) = (self.window(), self.coarse_window());
        ([l + self.n * cl, r + self.n * cr], [u + self.m * cu, d + self.m * cd])
    }

    /// `tile` grown by the apron of the filter (paper 3.4) and clipped to a `width` × `height`
    /// image. Every pixel the filter of the tile reads lies in it.
    pub fn region(&self, tile: &Tile, width: u32, height: u32) -> PixelRect {
        let ([left, right], [up, down]) = self.apron();
        PixelRect {
            x0: tile.rect.x0.saturating_sub(left),
            y0: tile.rect.y0.saturating_sub(up),
            x1: (tile.rect.x1 + right).min(width),
            y1: (tile.rect.y1 + down).min(height),
        }
    }

    /// Where sample `index` of eight pixels lies in each, as offsets in [0, 1)² from its
    /// top-left corner: the centre if `centre` (one sample per pixel in a still frame), else
    /// point `index` of the Owen-scrambled Sobol sequence of each pixel's sequence seed
    /// ([`crate::sampling::pixel_seed`], given as its [`Sobol2`]: stratified within the pixel;
    /// see [`crate::frame::FrameState::sequence`] for the index).
    #[inline]
    pub fn sample_offsets(&self, index: u32, pixels: &[Sobol2; 8], centre: bool) -> [(f32, f32); 8] {
        if centre {
            return [(0.5, 0.5); 8];
        }
        let unscrambled = Sobol2::unscrambled(index);
        pixels.map(|pixel| {
            let [u, v] = pixel.point(unscrambled);
            (u, v)
        })
    }

    /// The pixels of fine set `fine` inside `region`, grouped into blocks of 4×2 pixels of the
    /// set's sub-grid (paper Figure 2: neighbouring pixels of one set, so the shadow packets of
    /// their points toward one VPL stay coherent). Each block lists up to 8 pixels; the last
    /// ones of a row or column may be partial.
    pub fn set_blocks(&self, region: &PixelRect, fine: u32, mut f: impl FnMut(&[(u32, u32)])) {
        let (sx, sy) = (fine % self.n, fine / self.n);
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

    /// The set of pixel `(x, y)` as the module documentation defines it.
    fn set_of(il: &Interleave, x: u32, y: u32) -> u32 {
        let fine = x % il.n + il.n * (y % il.m);
        let group = (x / il.n) % il.coarse + il.coarse * ((y / il.m) % il.coarse);
        fine + il.n * il.m * group
    }

    #[test]
    fn every_set_weighs_the_same_in_the_two_levels() {
        for (n, m, coarse) in [(3, 3, 1), (2, 4, 1), (4, 1, 1), (1, 1, 1), (3, 3, 3), (3, 3, 2), (2, 3, 4)] {
            let il = Interleave { n, m, coarse, aa: 1 };
            let ([l, r], [u, d]) = il.window();
            assert_eq!((l + r + 1, u + d + 1), (n, m));
            let ([cl, cr], [cu, cd]) = il.coarse_window();
            assert_eq!((cl + cr + 1, cu + cd + 1), (2 * coarse - 1, 2 * coarse - 1));
            for (cx, cy) in [(17u32, 19u32), (30, 23)] {
                // The first-level windows around the second level's taps, each pixel weighted
                // by its tap's tent: each set weighs exactly one.
                let mut weight = vec![0.0f64; il.sets() as usize];
                for (j, ty) in (cy - il.m * cu..=cy + il.m * cd).step_by(il.m as usize).enumerate() {
                    for (i, tx) in (cx - il.n * cl..=cx + il.n * cr).step_by(il.n as usize).enumerate() {
                        let w =
                            il.coarse_weight(i.abs_diff(cl as usize) as u32, j.abs_diff(cu as usize) as u32);
                        for y in ty - u..=ty + d {
                            for x in tx - l..=tx + r {
                                weight[set_of(&il, x, y) as usize] += f64::from(w);
                                assert_eq!(il.set(x % n + n * (y % m), x, y), set_of(&il, x, y));
                            }
                        }
                    }
                }
                assert!(weight.iter().all(|&w| (w - 1.0).abs() < 1e-6), "{n}x{m}, K = {coarse}: {weight:?}");
            }
        }
    }

    #[test]
    fn set_blocks_cover_each_pixel_of_a_fine_set_once() {
        let il = Interleave { n: 3, m: 3, coarse: 3, aa: 1 };
        let region = PixelRect { x0: 5, y0: 2, x1: 40, y1: 23 };
        let mut count = vec![0; region.pixel_count()];
        for fine in 0..il.fine_sets() {
            il.set_blocks(&region, fine, |lanes| {
                assert!(!lanes.is_empty() && lanes.len() <= 8);
                for &(x, y) in lanes {
                    assert_eq!(set_of(&il, x, y) % il.fine_sets(), fine);
                    count[region.index(x, y)] += 1;
                }
            });
        }
        assert!(count.iter().all(|&c| c == 1));
    }

    #[test]
    fn region_is_the_tile_plus_the_apron_inside_the_image() {
        let tile = Tile { index: 0, rect: PixelRect { x0: 0, y0: 16, x1: 16, y1: 32 } };
        let il = Interleave { n: 3, m: 3, coarse: 1, aa: 1 };
        assert_eq!(il.region(&tile, 20, 40), PixelRect { x0: 0, y0: 15, x1: 17, y1: 33 });
        let il = Interleave { coarse: 3, ..il };
        assert_eq!(il.region(&tile, 20, 40), PixelRect { x0: 0, y0: 9, x1: 20, y1: 39 });
        let il = Interleave { coarse: 2, ..il };
        assert_eq!(il.apron(), ([4, 4], [4, 4]));
    }
}
