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

    /// Rows covered.
    pub fn height(&self) -> usize {
        self.y1 - self.y0
    }

    /// Pixels covered.
    pub fn area(&self) -> usize {
        self.width() * self.height()
    }

    /// All pixels of a `width × height` image.
    pub fn whole(width: usize, height: usize) -> Self {
        PixelRect {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        }
    }

    /// The pixels in both rectangles, if any.
    pub fn intersection(&self, other: &PixelRect) -> Option<PixelRect> {
        let rect = PixelRect {
            x0: self.x0.max(other.x0),
            y0: self.y0.max(other.y0),
            x1: self.x1.min(other.x1),
            y1: self.y1.min(other.y1),
        };
        (rect.x0 < rect.x1 && rect.y0 < rect.y1).then_some(rect)
    }

    /// A crop `(x, y, w, h)` of a `width × height` image, checked: not empty, and inside.
    pub fn check_crop(
        [x, y, w, h]: [usize; 4],
        (width, height): (usize, usize),
    ) -> Result<PixelRect, String> {
        if w == 0 || h == 0 {
            return Err(format!("crop {x},{y},{w},{h} is empty"));
        }
        if x.saturating_add(w) > width || y.saturating_add(h) > height {
            return Err(format!(
                "crop {x},{y},{w},{h} reaches outside the {width}×{height} image"
            ));
        }
        Ok(PixelRect {
            x0: x,
            y0: y,
            x1: x + w,
            y1: y + h,
        })
    }

    /// Whether pixel (x, y) is in it.
    pub fn contains(&self, x: usize, y: usize) -> bool {
        (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y)
    }

    /// It and `margin` pixels around it, within a `width × height` image.
    pub fn grown(&self, margin: usize, (width, height): (usize, usize)) -> PixelRect {
        PixelRect {
            x0: self.x0.saturating_sub(margin),
            y0: self.y0.saturating_sub(margin),
            x1: (self.x1 + margin).min(width),
            y1: (self.y1 + margin).min(height),
        }
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
    /// Whether what this pass observes is used afterwards (false in the last pass of a
    /// render whose learning ends with it): an integrator may skip recording it.
    pub learns: bool,
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
