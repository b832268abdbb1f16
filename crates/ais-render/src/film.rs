//! The film: camera samples accumulated into pixels through a reconstruction filter.
//!
//! With Mitsuba's `box` filter a sample counts in its own pixel only. With a wider filter
//! (`tent`, or `gaussian`, Mitsuba's default) a sample at image position p adds its value
//! times w(p − c) to every pixel whose centre c lies within the filter's radius, where w is
//! the separable product of the filter's weights along x and y, and a pixel's value is its
//! sum of weighted values over its sum of weights, as Mitsuba's `hdrfilm` develops it.
//! Samples are drawn inside the image only (Mitsuba's `sample_border` is false).

use crate::image_io::RgbImage;
use crate::render::PixelRect;
use ais::fast_exp;

/// How a camera sample weighs in the pixels around it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ReconstructionFilter {
    /// Each sample counts in its own pixel only (Mitsuba's `box`).
    Box,
    /// Mitsuba's `tent`: weight 1 − |x| / radius along each axis.
    Tent {
        /// Radius in pixels.
        radius: f32,
    },
    /// Mitsuba's `gaussian` (its default): exp(−x² / 2σ²) − exp(−r² / 2σ²), clipped at 0,
    /// along each axis, with radius r = 4σ. Filters reach at most 16 pixels (the scene
    /// reader refuses wider ones; a wider one's outer weights are dropped).
    Gaussian {
        /// σ in pixels.
        stddev: f32,
    },
}

impl ReconstructionFilter {
    /// Mitsuba's default filter: a Gaussian of σ = ½ pixel.
    pub const MITSUBA_DEFAULT: Self = ReconstructionFilter::Gaussian { stddev: 0.5 };

    /// How far from a sample, in pixels, the filter reaches.
    pub fn radius(&self) -> f32 {
        match *self {
            ReconstructionFilter::Box => 0.5,
            ReconstructionFilter::Tent { radius } => radius,
            ReconstructionFilter::Gaussian { stddev } => 4.0 * stddev,
        }
    }

    /// The weight along one axis at distance `x` (pixels) from the sample.
    pub fn eval(&self, x: f32) -> f32 {
        self.eval_lanes(&[x])[0]
    }

    /// The weight of each distance of `xs` along one axis, in a form that the compiler runs
    /// in vector lanes (the same values as [`Self::eval`]): a sample's weights are worked
    /// out for every camera sample, and libm's exp, one call each, took 5-7% of a frame in
    /// scenes cheap to trace.
    #[inline(always)]
    fn eval_lanes<const N: usize>(&self, xs: &[f32; N]) -> [f32; N] {
        match *self {
            ReconstructionFilter::Box => xs.map(|x| if x.abs() <= 0.5 { 1.0 } else { 0.0 }),
            ReconstructionFilter::Tent { radius } => xs.map(|x| (1.0 - x.abs() / radius).max(0.0)),
            ReconstructionFilter::Gaussian { stddev } => {
                let alpha = -1.0 / (2.0 * stddev * stddev);
                let exponentials = fast_exp::exp_lanes(&xs.map(|x| alpha * x * x));
                exponentials.map(|exponential| (exponential - GAUSSIAN_AT_RADIUS).max(0.0))
            }
        }
    }

    /// How many pixels beyond its own a sample can reach (0: the box).
    pub fn margin(&self) -> usize {
        match self {
            ReconstructionFilter::Box => 0,
            _ => (self.radius() - 0.5).ceil().max(0.0) as usize,
        }
    }
}

/// Weighted sums of samples over a rectangle of an image's pixels.
#[derive(Clone, Debug)]
pub struct Film {
    rect: PixelRect,
    /// Each pixel's sums of weighted red, green and blue, then its sum of weights: four
    /// numbers that one vector instruction adds to.
    sums: Vec<[f64; 4]>,
}

impl Film {
    /// An empty `width × height` film.
    pub fn new(width: usize, height: usize) -> Self {
        Film::covering(PixelRect::whole(width, height))
    }

    /// An empty film over the pixels of `rect` (in the whole image's coordinates).
    pub fn covering(rect: PixelRect) -> Self {
        Film {
            rect,
            sums: vec![[0.0; 4]; rect.area()],
        }
    }

    /// The pixels it covers.
    pub fn rect(&self) -> PixelRect {
        self.rect
    }

    /// Adds a sample to pixel (x, y).
    pub fn add(&mut self, x: usize, y: usize, value: [f32; 3]) {
        self.add_weighted(x, y, value, 1.0);
    }

    /// Adds a sample of weight `weight` (e.g. the mean of that many samples) to pixel (x, y)
    /// of the image (which must be covered).
    pub fn add_weighted(&mut self, x: usize, y: usize, value: [f32; 3], weight: f64) {
        let index = (y - self.rect.y0) * self.rect.width() + (x - self.rect.x0);
        let [r, g, b] = value;
        // The weight's own sum adds 1 × weight, which is the weight to the bit.
        for (sum, v) in self.sums[index].iter_mut().zip([r, g, b, 1.0]) {
            *sum += v as f64 * weight;
        }
    }

    /// Adds a sample at image position `position` (pixels; pixel (x, y) spans [x, x + 1) ×
    /// [y, y + 1)) to the covered pixels within `filter`'s reach.
    pub fn splat(&mut self, filter: &ReconstructionFilter, position: [f32; 2], value: [f32; 3]) {
        // Mitsuba's default filter reaches at most 5 pixel centres along an axis (4 but for
        // a sample exactly half-way): its weights fit one run of vector lanes, in registers.
        match filter.margin() <= NARROW_MARGIN {
            true => self.splat_within::<NARROW_REACH>(filter, position, value),
            false => self.splat_within::<MOST_REACHED>(filter, position, value),
        }
    }

    /// [`Film::splat`] for a filter that reaches at most `N` pixels along an axis.
    #[inline(always)]
    fn splat_within<const N: usize>(
        &mut self,
        filter: &ReconstructionFilter,
        position: [f32; 2],
        value: [f32; 3],
    ) {
        let columns = AxisWeights::<N>::new(filter, position[0], self.rect.x0, self.rect.x1);
        let rows = AxisWeights::<N>::new(filter, position[1], self.rect.y0, self.rect.y1);
        for (y, &wy) in rows.pixels() {
            for (x, &wx) in columns.pixels() {
                let weight = wy * wx;
                if weight > 0.0 {
                    self.add_weighted(x, y, value, weight as f64);
                }
            }
        }
    }

    /// Adds the sums and weights of `other` where the two overlap.
    pub fn add_film(&mut self, other: &Film) {
        let Some(overlap) = self.rect.intersection(&other.rect) else {
            return;
        };
        for (x, y) in overlap.pixels() {
            let from = (y - other.rect.y0) * other.rect.width() + (x - other.rect.x0);
            let to = (y - self.rect.y0) * self.rect.width() + (x - self.rect.x0);
            for (sum, add) in self.sums[to].iter_mut().zip(other.sums[from]) {
                *sum += add;
            }
        }
    }

    /// The averaged image of the pixels of `rect` (covered; pixels without samples are
    /// black).
    pub fn image_of(&self, rect: PixelRect) -> RgbImage {
        let pixels = rect
            .pixels()
            .map(|(x, y)| {
                let index = (y - self.rect.y0) * self.rect.width() + (x - self.rect.x0);
                let [r, g, b, weight] = self.sums[index];
                if weight == 0.0 {
                    [0.0; 3]
                } else {
                    [r, g, b].map(|s| (s / weight) as f32)
                }
            })
            .collect();
        RgbImage {
            width: rect.width(),
            height: rect.height(),
            pixels,
        }
    }

    /// The averaged image of every covered pixel.
    pub fn image(&self) -> RgbImage {
        self.image_of(self.rect)
    }
}

/// A Gaussian's value at its radius, exp(−r² / 2σ²) with r = 4σ: exp(−8) whatever σ (the
/// f32 nearest it, which [`fast_exp::exp`] gives too).
const GAUSSIAN_AT_RADIUS: f32 = 3.354_626_2e-4;

/// The widest margin of a filter whose weights along an axis fit [`NARROW_REACH`] lanes
/// (radius at most 3.5 pixels: at most 8 pixel centres within it).
const NARROW_MARGIN: usize = 3;
/// Lanes for the weights along an axis of a filter of at most [`NARROW_MARGIN`].
const NARROW_REACH: usize = 8;
/// The most pixels a filter reaches along one axis (radius at most 16: 33 pixels).
const MOST_REACHED: usize = 34;

/// A filter's weights along one axis for a sample at `p`: the pixels whose centres lie
/// within its radius, in `[low, high)` (at most `N` of them), each weighed once for all
/// the rows or columns.
struct AxisWeights<const N: usize> {
    first: usize,
    weights: [f32; N],
    count: usize,
}

impl<const N: usize> AxisWeights<N> {
    #[inline(always)]
    fn new(filter: &ReconstructionFilter, p: f32, low: usize, high: usize) -> Self {
        let radius = filter.radius();
        let first = (p - 0.5 - radius).ceil().max(low as f32) as usize;
        let last = ((p - 0.5 + radius).floor() as i64).min(high as i64 - 1);
        let count = (last + 1 - first as i64).clamp(0, N as i64) as usize;
        // Every lane weighed: the weights past `count` are never read.
        let offsets = std::array::from_fn(|i| (first + i) as f32 + 0.5 - p);
        AxisWeights {
            first,
            weights: filter.eval_lanes(&offsets),
            count,
        }
    }

    /// The pixels reached, with their weights.
    fn pixels(&self) -> impl Iterator<Item = (usize, &f32)> {
        (self.first..).zip(&self.weights[..self.count])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mitsuba_gaussian_weights_and_reach() {
        let filter = ReconstructionFilter::MITSUBA_DEFAULT;
        assert_eq!(filter.radius(), 2.0);
        assert_eq!(filter.margin(), 2);
        // exp(−2x²) − exp(−8): Mitsuba's windowed Gaussian at σ = ½.
        let bias = (-8.0f32).exp();
        assert_eq!(GAUSSIAN_AT_RADIUS, bias);
        assert_eq!(GAUSSIAN_AT_RADIUS, fast_exp::exp(-8.0));
        assert!((filter.eval(0.0) - (1.0 - bias)).abs() < 1e-7);
        assert!((filter.eval(1.0) - ((-2.0f32).exp() - bias)).abs() < 1e-7);
        assert_eq!(filter.eval(2.0), 0.0);
        assert_eq!(ReconstructionFilter::Box.margin(), 0);
        assert_eq!(ReconstructionFilter::Tent { radius: 1.0 }.margin(), 1);
    }

    #[test]
    fn a_splat_reaches_the_pixels_within_the_radius_only() {
        let filter = ReconstructionFilter::Tent { radius: 1.0 };
        let mut film = Film::new(4, 4);
        // At the centre of pixel (1, 1): only that pixel's centre lies within a tent of
        // radius 1 (the neighbours' centres are exactly 1 away, where the tent is 0).
        film.splat(&filter, [1.5, 1.5], [2.0; 3]);
        let image = film.image();
        assert_eq!(image.pixels[4 + 1], [2.0; 3]);
        assert_eq!(image.pixels.iter().filter(|p| p[0] != 0.0).count(), 1);
        // On the corner between four pixels, each gets a quarter of the weight: the
        // normalised value is the sample's in all four.
        let mut film = Film::new(4, 4);
        film.splat(&filter, [2.0, 2.0], [3.0; 3]);
        let image = film.image();
        for (x, y) in [(1, 1), (2, 1), (1, 2), (2, 2)] {
            assert!((image.pixels[y * 4 + x][0] - 3.0).abs() < 1e-6);
        }
        assert_eq!(image.pixels.iter().filter(|p| p[0] != 0.0).count(), 4);
    }

    #[test]
    fn the_widest_tent_reaches_every_pixel_within_16() {
        let filter = ReconstructionFilter::Tent { radius: 16.0 };
        let mut film = Film::new(40, 1);
        film.splat(&filter, [20.3, 0.5], [1.0; 3]);
        let weights: Vec<f64> = film.sums.iter().map(|sums| sums[3]).collect();
        let reached = weights.iter().filter(|&&w| w > 0.0).count();
        // The centres 4.5 … 35.5 lie within 16 of 20.3.
        assert_eq!(reached, 32, "{weights:?}");
        assert!(weights[4] > 0.0 && weights[35] > 0.0);
        assert!(weights[3] == 0.0 && weights[36] == 0.0);
    }

    #[test]
    fn films_of_parts_add_up_to_the_film_of_the_whole() {
        let filter = ReconstructionFilter::MITSUBA_DEFAULT;
        let samples = [
            ([0.3f32, 0.7f32], 1.0f32),
            ([3.9, 2.2], 5.0),
            ([2.5, 3.5], 2.0),
        ];
        let mut whole = Film::new(5, 4);
        let mut left = Film::covering(PixelRect {
            x0: 0,
            y0: 0,
            x1: 3,
            y1: 4,
        });
        let mut right = Film::covering(PixelRect {
            x0: 1,
            y0: 0,
            x1: 5,
            y1: 4,
        });
        for (position, value) in samples {
            whole.splat(&filter, position, [value; 3]);
            let part = if position[0] < 2.0 {
                &mut left
            } else {
                &mut right
            };
            part.splat(&filter, position, [value; 3]);
        }
        let mut merged = Film::new(5, 4);
        merged.add_film(&left);
        merged.add_film(&right);
        for (a, b) in merged.image().pixels.iter().zip(whole.image().pixels) {
            for c in 0..3 {
                assert!((a[c] - b[c]).abs() <= 1e-6 * b[c].abs(), "{a:?} vs {b:?}");
            }
        }
    }
}
