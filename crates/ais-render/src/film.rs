//! The film: box-filtered pixel samples accumulated per pixel.

use crate::image_io::RgbImage;

/// Accumulates weighted samples per pixel and averages them (a box filter over the pixel).
/// A render in passes adds each pass's pixel mean weighted by its samples per pixel.
#[derive(Clone, Debug)]
pub struct Film {
    width: usize,
    height: usize,
    sums: Vec<[f64; 3]>,
    weights: Vec<f64>,
}

impl Film {
    /// An empty film.
    pub fn new(width: usize, height: usize) -> Self {
        Film {
            width,
            height,
            sums: vec![[0.0; 3]; width * height],
            weights: vec![0.0; width * height],
        }
    }

    /// Adds a sample to pixel (x, y).
    pub fn add(&mut self, x: usize, y: usize, value: [f32; 3]) {
        self.add_weighted(x, y, value, 1.0);
    }

    /// Adds a sample of weight `weight` (e.g. the mean of that many samples) to pixel (x, y).
    pub fn add_weighted(&mut self, x: usize, y: usize, value: [f32; 3], weight: f64) {
        let index = y * self.width + x;
        for (sum, v) in self.sums[index].iter_mut().zip(value) {
            *sum += v as f64 * weight;
        }
        self.weights[index] += weight;
    }

    /// The averaged image (pixels without samples are black).
    pub fn image(&self) -> RgbImage {
        RgbImage {
            width: self.width,
            height: self.height,
            pixels: self
                .sums
                .iter()
                .zip(&self.weights)
                .map(|(sum, &weight)| {
                    if weight == 0.0 {
                        [0.0; 3]
                    } else {
                        sum.map(|s| (s / weight) as f32)
                    }
                })
                .collect(),
        }
    }
}
