//! [`Film`]: the framebuffer, linear RGB radiance in f32, row-major with row 0 at the top.

use crate::image::tile::Tile;
use glam::Vec3;

/// A `width` × `height` image of linear RGB values.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    width: u32,
    height: u32,
    pixels: Vec<Vec3>,
}

impl Film {
    /// A black film.
    pub fn new(width: u32, height: u32) -> Self {
        Self { width, height, pixels: vec![Vec3::ZERO; width as usize * height as usize] }
    }

    /// A film from row-major pixels (row 0 at the top). Panics if the count is not
    /// `width * height`.
    pub fn from_pixels(width: u32, height: u32, pixels: Vec<Vec3>) -> Self {
        assert_eq!(pixels.len(), width as usize * height as usize, "pixel count must be width * height");
        Self { width, height, pixels }
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// All pixels, row-major, row 0 at the top.
    pub fn pixels(&self) -> &[Vec3] {
        &self.pixels
    }

    /// The pixel at column `x`, row `y`.
    #[inline]
    pub fn get(&self, x: u32, y: u32) -> Vec3 {
        self.pixels[self.index(x, y)]
    }

    /// Sets the pixel at column `x`, row `y`.
    #[inline]
    pub fn set(&mut self, x: u32, y: u32, value: Vec3) {
        let i = self.index(x, y);
        self.pixels[i] = value;
    }

    #[inline]
    fn index(&self, x: u32, y: u32) -> usize {
        assert!(x < self.width && y < self.height, "pixel ({x}, {y}) outside the film");
        y as usize * self.width as usize + x as usize
    }

    /// Copies a tile's pixels (row-major within the tile) into place.
    pub fn write_tile(&mut self, tile: &Tile, pixels: &[Vec3]) {
        assert!(tile.rect.x1 <= self.width && tile.rect.y1 <= self.height, "tile outside the film");
        copy_tile(&mut self.pixels, self.width as usize, tile, pixels, 1);
    }
}

/// Copies a tile's values (row-major within the tile, `per_pixel` values each) into a
/// row-major image whose rows are `row_len` values long: the one way tiles become images.
pub(crate) fn copy_tile<T: Copy>(
    image: &mut [T],
    row_len: usize,
    tile: &Tile,
    values: &[T],
    per_pixel: usize,
) {
    let w = tile.rect.width() as usize * per_pixel;
    assert_eq!(values.len(), w * tile.rect.height() as usize, "tile pixel count");
    for (row, src) in values.chunks_exact(w).enumerate() {
        let start = (tile.rect.y0 as usize + row) * row_len + tile.rect.x0 as usize * per_pixel;
        image[start..start + w].copy_from_slice(src);
    }
}
