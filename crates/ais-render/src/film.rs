//! The film: box-filtered pixel samples accumulated per pixel.

use crate::image_io::RgbImage;

/// Accumulates samples per pixel and averages them (a box filter over the pixel).
#[derive(Clone, Debug)]
pub struct Film {
    width: usize,
    height: usize,
    sums: Vec<[f64; 3]>,
    counts: Vec<u32>,
}

impl Film {
    /// An empty film.
    pub fn new(width: usize, height: usize) -> Self {
        Film {
            width,
            height,
            sums: vec![[0.0; 3]; width * height],
            counts: vec![0; width * height],
        }
    }

    /// Adds a sample to pixel (x, y).
    pub fn add(&mut self, x: usize, y: usize, value: [f32; 3]) {
        let index = y * self.width + x;
        for (sum, v) in self.sums[index].iter_mut().zip(value) {
            *sum += v as f64;
        }
        self.counts[index] += 1;
    }

    /// The averaged image (pixels without samples are black).
    pub fn image(&self) -> RgbImage {
        RgbImage {
            width: self.width,
            height: self.height,
            pixels: self
                .sums
                .iter()
                .zip(&self.counts)
                .map(|(sum, &count)| {
                    if count == 0 {
                        [0.0; 3]
                    } else {
                        sum.map(|s| (s / count as f64) as f32)
                    }
                })
                .collect(),
        }
    }
}
