//! [`PixelRect`]: a rectangle of image pixels, the shape of a tile and of the tile grown by the
//! filter's apron (paper 3.4), with the row-major indexing of the buffers that cover it.

/// A rectangle of pixels `[x0, x1) × [y0, y1)` of an image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PixelRect {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl PixelRect {
    /// Width in pixels.
    #[inline]
    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }

    /// Height in pixels.
    #[inline]
    pub fn height(&self) -> u32 {
        self.y1 - self.y0
    }

    /// Number of pixels.
    #[inline]
    pub fn pixel_count(&self) -> usize {
        self.width() as usize * self.height() as usize
    }

    /// True if `(x, y)` lies inside.
    #[inline]
    pub fn contains(&self, x: u32, y: u32) -> bool {
        x >= self.x0 && x < self.x1 && y >= self.y0 && y < self.y1
    }

    /// Row-major index of pixel `(x, y)` inside the rectangle.
    #[inline]
    pub fn index(&self, x: u32, y: u32) -> usize {
        (y - self.y0) as usize * self.width() as usize + (x - self.x0) as usize
    }

    /// The pixel `(x, y)` at row-major `index` inside the rectangle (the inverse of
    /// [`PixelRect::index`]).
    #[inline]
    pub fn pixel(&self, index: u32) -> (u32, u32) {
        let w = self.width();
        (self.x0 + index % w, self.y0 + index / w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixel_inverts_index() {
        let r = PixelRect { x0: 5, y0: 2, x1: 12, y1: 9 };
        assert_eq!((r.width(), r.height(), r.pixel_count()), (7, 7, 49));
        for y in r.y0..r.y1 {
            for x in r.x0..r.x1 {
                assert!(r.contains(x, y));
                assert_eq!(r.pixel(r.index(x, y) as u32), (x, y));
            }
        }
        assert!(!r.contains(4, 2) && !r.contains(12, 2) && !r.contains(5, 1) && !r.contains(5, 9));
    }
}
