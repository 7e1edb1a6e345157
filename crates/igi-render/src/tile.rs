//! Image tiles: the unit of work of the renderer. An image is cut into a fixed grid of square
//! tiles (the last row and column may be smaller), numbered row by row. A tile's pixels depend
//! only on the scene, the settings and the tile, so tiles can be rendered in any order, on any
//! thread or node (DESIGN.md section 1).

/// One rectangle of pixels `[x0, x1) × [y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tile {
    /// Row-major index of the tile in its grid.
    pub index: u32,
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl Tile {
    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.y1 - self.y0
    }

    /// Number of pixels.
    pub fn pixel_count(&self) -> usize {
        self.width() as usize * self.height() as usize
    }
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
        Tile { index, x0, y0, x1: (x0 + self.size).min(self.width), y1: (y0 + self.size).min(self.height) }
    }

    /// All tiles in index order.
    pub fn tiles(&self) -> impl Iterator<Item = Tile> + '_ {
        (0..self.len()).map(|i| self.tile(i))
    }
}
