//! Tiles: how an image is split for parallel rendering, and the per-pixel seeds that make
//! the image independent of that split.

use ais::rng::mix64;

/// Edge length of a square tile, in pixels.
pub const TILE_SIZE: usize = 16;

/// A rectangle of pixels, `[x0, x1) × [y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelRect {
    /// First column.
    pub x0: usize,
    /// First row.
    pub y0: usize,
    /// One past the last column.
    pub x1: usize,
    /// One past the last row.
    pub y1: usize,
}

impl PixelRect {
    /// Columns covered.
    pub fn width(&self) -> usize {
        self.x1 - self.x0
    }

    /// Pixels covered.
    pub fn area(&self) -> usize {
        self.width() * (self.y1 - self.y0)
    }

    /// Its pixels, row by row.
    pub fn pixels(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        (self.y0..self.y1).flat_map(move |y| (self.x0..self.x1).map(move |x| (x, y)))
    }
}

/// One tile of an image being rendered: where it is and what it belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tile {
    /// Its pixels.
    pub rect: PixelRect,
    /// The whole image's size, `(width, height)`.
    pub image: (usize, usize),
    /// The render's base seed.
    pub seed: u64,
}

/// The tiles of a `width × height` image, row by row.
pub fn tiles(width: usize, height: usize) -> Vec<PixelRect> {
    (0..height.div_ceil(TILE_SIZE))
        .flat_map(|ty| {
            (0..width.div_ceil(TILE_SIZE)).map(move |tx| {
                let (x0, y0) = (tx * TILE_SIZE, ty * TILE_SIZE);
                PixelRect {
                    x0,
                    y0,
                    x1: (x0 + TILE_SIZE).min(width),
                    y1: (y0 + TILE_SIZE).min(height),
                }
            })
        })
        .collect()
}

/// The seed of pixel (x, y) of a `width`-wide image.
pub fn pixel_seed(seed: u64, x: usize, y: usize, width: usize) -> u64 {
    mix64(seed ^ mix64((y * width + x) as u64))
}
