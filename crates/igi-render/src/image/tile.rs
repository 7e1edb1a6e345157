//! Image tiles: the unit of work of the renderer. An image is cut into a fixed grid of square
//! tiles (the last row and column may be smaller), numbered row by row. A tile's pixels depend
//! only on the scene, the settings and the tile, so tiles can be rendered in any order, on any
//! thread or node (paper 3.4).

use crate::image::pixel_rect::PixelRect;

/// One tile: its index in the grid and its rectangle of pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Tile {
    /// Row-major index of the tile in its grid.
    pub index: u32,
    /// The tile's pixels.
    pub rect: PixelRect,
}

/// The tiling of a `width` × `height` image into `size` × `size` tiles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TileGrid {
    width: u32,
    height: u32,
    size: u32,
    columns: u32,
    rows: u32,
}

impl TileGrid {
    /// The grid for an image; `size` is clamped to at least 1.
    pub fn new(width: u32, height: u32, size: u32) -> Self {
        let size = size.max(1);
        Self { width, height, size, columns: width.div_ceil(size), rows: height.div_ceil(size) }
    }

    /// Number of tiles.
    pub fn len(&self) -> u32 {
        self.columns * self.rows
    }

    /// True for an image without pixels.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Edge length of a full tile.
    pub fn size(&self) -> u32 {
        self.size
    }

    /// Tile `index` (row-major). Panics if out of range.
    pub fn tile(&self, index: u32) -> Tile {
        assert!(index < self.len(), "tile {index} out of range");
        let (cx, cy) = (index % self.columns, index / self.columns);
        let (x0, y0) = (cx * self.size, cy * self.size);
        let rect =
            PixelRect { x0, y0, x1: (x0 + self.size).min(self.width), y1: (y0 + self.size).min(self.height) };
        Tile { index, rect }
    }

    /// The tiles that share a pixel with `rect` (a rectangle inside the image), in index order.
    pub fn tiles_overlapping(&self, rect: &PixelRect) -> impl Iterator<Item = Tile> + '_ {
        let (columns, rows) = (
            rect.x0 / self.size..rect.x1.div_ceil(self.size),
            rect.y0 / self.size..rect.y1.div_ceil(self.size),
        );
        rows.flat_map(move |cy| columns.clone().map(move |cx| self.tile(cy * self.columns + cx)))
    }

    /// All tiles in index order.
    pub fn tiles(&self) -> impl Iterator<Item = Tile> + '_ {
        (0..self.len()).map(|i| self.tile(i))
    }
}
