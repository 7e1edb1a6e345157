//! [`MipMap`]: an image and its chain of box-filtered half-size levels (Williams 1983), and
//! the bilinear and trilinear lookups that choose a level by the footprint of a ray.

use super::wrap::wrap_texel;
use glam::{Vec2, Vec4};
use igi_scene::{Image, Texels, Texture, Wrap};
use std::sync::Arc;

/// One level of a [`MipMap`]: an image, stored as its source is (see [`igi_scene::Texels`]).
#[derive(Clone, Debug)]
pub struct Level(Image);

impl Level {
    /// Width in texels.
    pub fn width(&self) -> u32 {
        self.0.width
    }

    /// Height in texels.
    pub fn height(&self) -> u32 {
        self.0.height
    }

    /// The four texels around texture coordinates `uv` (top left, top right, bottom left,
    /// bottom right) and the position of `uv` between their centres.
    #[inline]
    fn quad(&self, uv: Vec2, wrap: [Wrap; 2]) -> ([Vec4; 4], Vec2) {
        let (width, height) = (self.0.width, self.0.height);
        let x = uv.x * width as f32 - 0.5;
        let y = uv.y * height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        // The texel columns and rows on either side, wrapped once per axis (not per texel).
        let [c0, c1] = wrap_pair(x0, width, wrap[0]);
        let [r0, r1] = wrap_pair(y0, height, wrap[1]);
        let (r0, r1) = (r0 * width as usize, r1 * width as usize);
        let texels = self.0.texels.linear4([r0 + c0, r0 + c1, r1 + c0, r1 + c1]);
        (texels.map(Vec4::from_array), Vec2::new(x - x0, y - y0))
    }

    /// Bilinear interpolation of the four texels around texture coordinates `uv`.
    #[inline]
    pub fn bilinear(&self, uv: Vec2, wrap: [Wrap; 2]) -> Vec4 {
        let ([a, b, c, d], f) = self.quad(uv, wrap);
        a.lerp(b, f.x).lerp(c.lerp(d, f.x), f.y)
    }

    /// The bilinear interpolant at `uv` and its derivatives ∂/∂u and ∂/∂v (the exact
    /// derivatives of the bilinear patch between the four texel centres around `uv`).
    #[inline]
    pub fn bilinear_gradient(&self, uv: Vec2, wrap: [Wrap; 2]) -> (Vec4, Vec4, Vec4) {
        let ([a, b, c, d], f) = self.quad(uv, wrap);
        let value = a.lerp(b, f.x).lerp(c.lerp(d, f.x), f.y);
        let d_dx = (b - a).lerp(d - c, f.y);
        let d_dy = c.lerp(d, f.x) - a.lerp(b, f.x);
        (value, d_dx * self.0.width as f32, d_dy * self.0.height as f32)
    }
}

/// The wrapped indices of texel coordinate `i` (an integer-valued float) and of `i + 1` along
/// an axis of `size` texels.
#[inline]
fn wrap_pair(i: f32, size: u32, wrap: Wrap) -> [usize; 2] {
    // Far outside the image every mode has wrapped or clamped already: keep the integer
    // conversion in range.
    let i = i.clamp(-1.0e9, 1.0e9) as i64;
    let size = i64::from(size);
    let [a, b] = match wrap {
        // Bilinear lookups of coordinates in [0, 1] only step one texel outside.
        Wrap::Repeat if (-1..size).contains(&i) => {
            [if i < 0 { size - 1 } else { i }, if i + 1 == size { 0 } else { i + 1 }]
        }
        _ => [wrap_texel(i, size, wrap), wrap_texel(i + 1, size, wrap)],
    };
    [a as usize, b as usize]
}

/// A texture ready for filtered lookups: level 0 is the image, each further level half the
/// size of the one before, down to 1 × 1.
#[derive(Clone, Debug)]
pub struct MipMap {
    levels: Vec<Level>,
    wrap: [Wrap; 2],
}

impl MipMap {
    /// The pyramid of `texture`; level 0 shares the texture's texels. A texture whose texels
    /// do not match its size becomes a single opaque white texel, so a broken texture leaves
    /// the material's colour.
    pub fn new(texture: &Texture) -> Self {
        let base = if texture.image.is_complete() {
            texture.image.clone()
        } else {
            Image { width: 1, height: 1, texels: Texels::RgbaF32(Arc::new(vec![[1.0; 4]])) }
        };
        let mut levels = vec![Level(base)];
        while let Some(last) = levels.last().filter(|l| l.width() > 1 || l.height() > 1) {
            let next = Level(last.0.half());
            levels.push(next);
        }
        Self { levels, wrap: texture.wrap }
    }

    /// The levels, finest first.
    pub fn levels(&self) -> &[Level] {
        &self.levels
    }

    /// Width and height of level 0.
    pub fn size(&self) -> (u32, u32) {
        (self.levels[0].width(), self.levels[0].height())
    }

    /// The continuous level of detail at which one texel spans `footprint` texels of level
    /// 0: log2 of it, 0 for footprints of a texel or less.
    #[inline]
    pub fn lod(&self, footprint_texels: f32) -> f32 {
        if footprint_texels > 1.0 { footprint_texels.log2().min((self.levels.len() - 1) as f32) } else { 0.0 }
    }

    /// Bilinear lookup in level `level` (clamped to the coarsest); opaque white for
    /// non-finite coordinates.
    #[inline]
    pub fn bilinear(&self, uv: Vec2, level: usize) -> Vec4 {
        if !uv.is_finite() {
            return Vec4::ONE;
        }
        self.levels[level.min(self.levels.len() - 1)].bilinear(uv, self.wrap)
    }

    /// The level `lod` rounds to (clamped to the pyramid).
    #[inline]
    pub fn level(&self, lod: f32) -> &Level {
        let level = if lod.is_finite() { lod.round().max(0.0) as usize } else { 0 };
        &self.levels[level.min(self.levels.len() - 1)]
    }

    /// The wrap modes along u and v.
    pub fn wrap(&self) -> [Wrap; 2] {
        self.wrap
    }

    /// Trilinear lookup: bilinear in the two levels around `lod`, blended linearly.
    #[inline]
    pub fn trilinear(&self, uv: Vec2, lod: f32) -> Vec4 {
        let lod = if lod.is_finite() { lod.clamp(0.0, (self.levels.len() - 1) as f32) } else { 0.0 };
        let fine = lod.floor();
        let t = lod - fine;
        let a = self.bilinear(uv, fine as usize);
        if t == 0.0 { a } else { a.lerp(self.bilinear(uv, fine as usize + 1), t) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texture(width: u32, height: u32, texels: Vec<[f32; 4]>) -> Texture {
        Texture::from_linear("t", width, height, texels)
    }

    /// The linear RGBA value of texel (`x`, `y`) of `level`.
    fn texel(level: &Level, x: u32, y: u32) -> Vec4 {
        Vec4::from_array(level.0.texels.linear((y * level.0.width + x) as usize))
    }

    /// 2 × 2: top row red, green; bottom row blue, white.
    fn four() -> MipMap {
        MipMap::new(&texture(
            2,
            2,
            vec![[1.0, 0.0, 0.0, 1.0], [0.0, 1.0, 0.0, 1.0], [0.0, 0.0, 1.0, 1.0], [1.0, 1.0, 1.0, 1.0]],
        ))
    }

    #[test]
    fn bilinear_lookups_equal_hand_computed_values() {
        let m = four();
        // Texel centres are the texels.
        assert_eq!(m.bilinear(Vec2::new(0.25, 0.25), 0), Vec4::new(1.0, 0.0, 0.0, 1.0));
        assert_eq!(m.bilinear(Vec2::new(0.75, 0.75), 0), Vec4::ONE);
        // Halfway between red and green: (0.5, 0.5, 0, 1).
        assert_eq!(m.bilinear(Vec2::new(0.5, 0.25), 0), Vec4::new(0.5, 0.5, 0.0, 1.0));
        // A quarter of the way from the red centre to the blue one (v from 0.25 to 0.75).
        let q = m.bilinear(Vec2::new(0.25, 0.375), 0);
        assert!((q - Vec4::new(0.75, 0.0, 0.25, 1.0)).abs().max_element() < 1e-6, "{q}");
        // The image centre and, across the wrap, the corner: the mean of all four.
        for uv in [Vec2::new(0.5, 0.5), Vec2::ZERO, Vec2::new(3.0, -2.0)] {
            let c = m.bilinear(uv, 0);
            assert!((c - Vec4::new(0.5, 0.5, 0.5, 1.0)).abs().max_element() < 1e-6, "{uv}: {c}");
        }
    }

    #[test]
    fn clamp_and_mirror_wrap_outside_the_image() {
        let mut t = texture(4, 1, vec![[0.0; 4], [1.0; 4], [2.0; 4], [3.0; 4]]);
        t.wrap = [Wrap::Clamp, Wrap::Clamp];
        let clamp = MipMap::new(&t);
        // u = 1.25 is beyond the last texel: its value; u = -0.25 the first's.
        assert_eq!(clamp.bilinear(Vec2::new(1.25, 0.5), 0).x, 3.0);
        assert_eq!(clamp.bilinear(Vec2::new(-0.25, 0.5), 0).x, 0.0);
        t.wrap = [Wrap::MirroredRepeat, Wrap::Clamp];
        let mirror = MipMap::new(&t);
        // u = 1.125 is texel coordinate 4.5: the mirrored copy's first texel, 3.
        assert_eq!(mirror.bilinear(Vec2::new(1.125, 0.5), 0).x, 3.0);
        // u = -0.125 (texel -0.5) mirrors texel 0; u = 2.875 (texel 11.5) is texel 3 of the
        // third (plain) copy.
        assert_eq!(mirror.bilinear(Vec2::new(-0.125, 0.5), 0).x, 0.0);
        assert_eq!(mirror.bilinear(Vec2::new(2.875, 0.5), 0).x, 3.0);
        t.wrap = [Wrap::Repeat, Wrap::Clamp];
        assert_eq!(MipMap::new(&t).bilinear(Vec2::new(1.125, 0.5), 0).x, 0.0);
    }

    #[test]
    fn each_level_is_the_box_average_of_the_one_below_odd_sizes_too() {
        // 5 × 3 texels of distinct values.
        let t = texture(5, 3, (0..15).map(|i| [i as f32, 0.0, 0.0, 1.0]).collect());
        let m = MipMap::new(&t);
        let sizes: Vec<(u32, u32)> = m.levels().iter().map(|l| (l.width(), l.height())).collect();
        assert_eq!(sizes, [(5, 3), (3, 2), (2, 1), (1, 1)]);
        let l1 = &m.levels()[1];
        // (0, 0) covers texels 0, 1, 5, 6; (2, 0) the odd column 4, 9; (2, 1) the corner 14.
        assert_eq!(texel(l1, 0, 0).x, (0.0 + 1.0 + 5.0 + 6.0) / 4.0);
        assert_eq!(texel(l1, 2, 0).x, (4.0 + 9.0) / 2.0);
        assert_eq!(texel(l1, 2, 1).x, 14.0);
    }

    #[test]
    fn trilinear_is_bilinear_at_level_zero_and_the_mean_at_the_top() {
        let t = texture(4, 4, (0..16).map(|i| [(i * i) as f32, 0.0, 0.0, 1.0]).collect());
        let m = MipMap::new(&t);
        let mean = (0..16).map(|i| (i * i) as f32).sum::<f32>() / 16.0;
        for uv in [Vec2::new(0.1, 0.3), Vec2::new(0.7, 0.9), Vec2::new(0.5, 0.5)] {
            assert_eq!(m.trilinear(uv, 0.0), m.bilinear(uv, 0));
            assert!((m.trilinear(uv, 10.0).x - mean).abs() < 1e-4, "{}", m.trilinear(uv, 10.0));
            let half = m.trilinear(uv, 0.5).x;
            assert!((half - 0.5 * (m.bilinear(uv, 0).x + m.bilinear(uv, 1).x)).abs() < 1e-4);
        }
        assert_eq!(m.lod(1.0), 0.0);
        assert_eq!(m.lod(4.0), 2.0);
    }
}
