//! The field raced against AIS off on the image itself: whether guiding pays in this
//! scene, measured where it is judged (the noise of pixels), not predicted from the field.
//!
//! Guiding lowers the variance of light sampling within a gather; whether that shows in
//! the image depends on what else is noisy there. Where pixel sampling dominates (edges,
//! lights seen directly, foliage at every scale) the guided gathers' extra cost buys
//! nothing. So in the race passes ([`RACE_PASSES`]) one pixel in four ([`races_off`])
//! gathers as AIS off and the others with the field; both arms record their rays for the
//! field alike. Each pixel's samples give an unbiased estimate of its per-sample variance;
//! weighted as relMSE weighs them (1 / (r² + 0.01), with r the mean of the 3 × 3 pixels
//! around, both arms), capped at the 99th percentile of both arms ([`CAP_QUANTILE`]: a few
//! fireflies must not decide) and averaged per arm, they say which arm's image is less
//! noisy. Neighbouring pixels see the same scene, so the arms differ only in how they
//! gather.
//!
//! Where the field only guides (below 64 candidates), the verdict after the race passes
//! keeps the field only if its arm's variance, times [`RACE_MARGIN`], is below AIS off's.
//! It reads sample values only, merged in a fixed order, so the image stays the same at
//! any thread count. Where the field's roulette runs, its gain is in time, which variance
//! does not show: there each arm's pixels are also timed, and the field is kept only if
//! its variance times its time per sample is below AIS off's (such renders already depend
//! on timings, through the measured cost ratio; with the cost ratio pinned, they do not
//! race); a field that only rolled is kept only for time it saves
//! ([`RaceResult::field_pays`]). The arms' pixels are interleaved in space and in time, so
//! the machine's drifting speed falls on both alike. Where the field loses, the rest of the render gathers as AIS
//! off, with no field work at all. Choosing how later passes gather from what earlier
//! passes saw keeps every pass unbiased.
//!
//! **Where the race also chooses gather sizes** (`field_sizes`, the default), the arms are
//! compared as they will render: each arm's pixels choose the candidates per block they
//! would get ([`super::gather_sizes`]), and the field is kept only if its arm predicts the
//! lower error at the render's end, at its own pace (its measured time per sample, or
//! AIS off's over [`RACE_MARGIN`] where untimed). A field can be worth little at `n`
//! candidates and much at the fewer it will get: guided gathers of a few dozen candidates
//! in a room lit through a window beat AIS off's of that size far more than at 128, and
//! compared at `n` the field stood aside there (2.9× against AIS off at n = 128, 9.5× kept;
//! the repository's BENCHMARKS.md, section 5.6).

use super::gather_sizes::{BlockMoments, GatherSizes, WeighedBlocks};
use crate::render::{PixelRect, TILE_SIZE};
use crate::texture::luminance;
use glam::Vec3;
use std::time::Instant;

/// The passes (by index) whose pixels race: the first two that read a field (1 and 2
/// samples per pixel), so a pixel has 3 samples for its variance.
pub const RACE_PASSES: std::ops::RangeInclusive<u32> = 1..=2;

/// The field must lower the race's variance by this factor to keep guiding. Two measured
/// effects meet in it (the repository's BENCHMARKS.md, section 5.6): a guided pass costs
/// 1.16–1.27 times an AIS-off pass at equal samples in the rooms and the courtyard (guided
/// candidates draw from a mixture and weigh by both densities, and the free rays they aim
/// at cross more of the scene); and the race, run on a field learned from 1 and 2 samples
/// per pixel, overstates the variance that the later, better-taught field gives by 0–20%
/// (race ratio against final relMSE ratio: sunlit room 0.46 / 0.39, interior 0.90 /
/// 0.75, courtyard 0.67 / 0.68).
pub const RACE_MARGIN: f64 = 1.1;

/// The floor under a pixel's squared brightness in relMSE's weight, 1 / (r² + 0.01): the
/// race's verdict and the gather sizes weigh pixels so.
pub const RELATIVE_FLOOR: f64 = 0.01;

/// The floor under a pixel's squared brightness where every pixel's relative error counts
/// alike, down to pixels a tenth as bright as relMSE's floor lets count: the gather sizes
/// weigh pixels so too, so that the counts that lower relMSE do not starve dark blocks.
pub const ALIKE_FLOOR: f64 = 1e-4;

/// Pixels' weighted variances are capped at this quantile of both arms' before the arms
/// are averaged. Three samples per pixel make the plain mean hostage to a few fireflies:
/// over four seeds it gave 0.79–1.20 for a room whose relMSE ratio is 0.74; capped, 0.74–0.83
/// (and within ±0.03 of the plain mean in the other scenes of the suite).
pub const CAP_QUANTILE: f64 = 0.99;

/// Whether pixel (`x`, `y`) gathers as AIS off while racing: one pixel in four, on a
/// regular lattice. (Where the field wins, every sample gathered as AIS off costs
/// variance: with half the pixels racing, the sunlit room's relMSE rose 5%. A quarter of
/// the pixels still tells the arms apart on every scene of the suite.)
pub fn races_off(x: usize, y: usize) -> bool {
    !x.is_multiple_of(2) && y.is_multiple_of(2)
}

/// The `q`-quantile of `values` (the value at rank ⌊q · (len − 1)⌋); infinity if empty.
fn quantile(mut values: Vec<f64>, q: f64) -> f64 {
    if values.is_empty() {
        return f64::INFINITY;
    }
    let rank = ((values.len() - 1) as f64 * q) as usize;
    *values.select_nth_unstable_by(rank, f64::total_cmp).1
}

/// Sums of one pixel's sample luminances.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelMoments {
    /// Samples.
    pub count: u32,
    /// Their sum.
    pub sum: f64,
    /// The sum of their squares.
    pub sum_squares: f64,
    /// Seconds spent on them (0 where the race is not timed).
    pub seconds: f64,
    /// Of the samples, those whose camera ray gathered.
    pub gathers: u32,
    /// The sum of those gathers' variances (each estimated from its own candidates).
    pub gather_variance: f64,
}

impl PixelMoments {
    fn add(&mut self, value: f64) {
        self.count += 1;
        self.sum += value;
        self.sum_squares += value * value;
    }

    fn merge(&mut self, other: PixelMoments) {
        self.count += other.count;
        self.sum += other.sum;
        self.sum_squares += other.sum_squares;
        self.seconds += other.seconds;
        self.gathers += other.gathers;
        self.gather_variance += other.gather_variance;
    }

    fn mean(&self) -> Option<f64> {
        (self.count > 0).then(|| self.sum / self.count as f64)
    }

    /// The unbiased sample variance (None below two samples).
    fn variance(&self) -> Option<f64> {
        (self.count >= 2).then(|| {
            let n = self.count as f64;
            ((self.sum_squares - self.sum * self.sum / n) / (n - 1.0)).max(0.0)
        })
    }
}

/// A tile's pixel moments in one race pass.
#[derive(Clone, Debug)]
pub struct TileMoments {
    /// The tile's pixels.
    pub rect: PixelRect,
    /// Per pixel, row-major over `rect`.
    pub pixels: Vec<PixelMoments>,
    /// The pixel being sampled (index into `pixels`).
    current: usize,
    /// When the current pixel began, where pixels are timed.
    started: Option<Instant>,
    /// Whether pixels are timed.
    timed: bool,
}

impl TileMoments {
    /// Empty moments over `rect`; each pixel's time is measured if `timed`.
    pub fn new(rect: PixelRect, timed: bool) -> Self {
        TileMoments {
            rect,
            pixels: vec![PixelMoments::default(); rect.area()],
            current: 0,
            started: None,
            timed,
        }
    }

    /// Pixel (`x`, `y`), inside the rectangle, is sampled next.
    pub fn begin_pixel(&mut self, x: usize, y: usize) {
        self.end_pixel();
        self.current = (y - self.rect.y0) * self.rect.width() + (x - self.rect.x0);
        self.started = self.timed.then(Instant::now);
    }

    /// Adds the time of the current pixel, if timed (the tile's last pixel ends here).
    pub fn end_pixel(&mut self) {
        if let Some(started) = self.started.take() {
            self.pixels[self.current].seconds += started.elapsed().as_secs_f64();
        }
    }

    /// The current pixel's camera ray gathered with this variance, estimated from the
    /// gather's own candidates (`None`: too few to tell; the sample counts as not gathered).
    pub fn gathered(&mut self, variance: Option<f64>) {
        if let Some(variance) = variance.filter(|v| v.is_finite()) {
            let pixel = &mut self.pixels[self.current];
            pixel.gathers += 1;
            pixel.gather_variance += variance;
        }
    }

    /// Adds a sample of the current pixel.
    pub fn sampled(&mut self, value: [f32; 3]) {
        let value = luminance(Vec3::from(value)) as f64;
        // A non-finite sample would poison the sums; the film reports it elsewhere.
        if value.is_finite() {
            self.pixels[self.current].add(value);
        }
    }
}

/// A pixel's per-sample variance, weighted as relMSE weighs it.
struct WeightedPixel {
    x: usize,
    y: usize,
    /// Whether it raced as AIS off.
    races_off: bool,
    /// 1 / (r² + floor), with r the mean of the pixels around.
    weight: f64,
    /// Its per-sample variance times `weight`.
    variance: f64,
}

/// The race's evidence over the image, and its verdict.
#[derive(Clone, Debug, Default)]
pub struct Race {
    width: usize,
    height: usize,
    pixels: Vec<PixelMoments>,
}

/// The per-arm weighted variances of a race (means over the arm's pixels, each capped at
/// the [`CAP_QUANTILE`] of all), and their times.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RaceResult {
    /// The field's arm.
    pub field: f64,
    /// AIS off's arm.
    pub off: f64,
    /// Seconds per sample of the field's arm and of AIS off's, where the race was timed.
    pub seconds_per_sample: Option<[f64; 2]>,
    /// Whether the field's arm guided any gather (else it only rolled).
    pub guided: bool,
    /// The error per pixel each arm (field, AIS off) predicts at the render's end, each with
    /// the gather sizes chosen from its own pixels, at its own pace (where sizes are chosen).
    pub sized: Option<[f64; 2]>,
}

impl RaceResult {
    /// Whether the field pays: where each arm chose its gather sizes
    /// ([`RaceResult::sized`]), its predicted error at the render's end below AIS off's;
    /// else its variance times its time per sample below AIS off's where timed, and its
    /// variance times [`RACE_MARGIN`] below AIS off's where not.
    ///
    /// A field that only rolled cannot have lowered the variance of a sample (skipping
    /// candidates only adds to it): a lower variance in its arm is the race's own noise
    /// (±20% between the arms' pixels, which differ). So there its variance counts as at
    /// least AIS off's, and it is kept only for time it saves. (A room lit through a door
    /// gap read 0.78–0.92 in the race, and its render ended 8% worse at equal time.)
    pub fn field_pays(&self) -> bool {
        if let (Some([field, off]), true) = (self.sized, self.guided) {
            return field < off;
        }
        let field = if self.guided {
            self.field
        } else {
            self.field.max(self.off)
        };
        match self.seconds_per_sample {
            Some([field_seconds, off_seconds]) => field * field_seconds < self.off * off_seconds,
            None => field * RACE_MARGIN < self.off,
        }
    }
}

impl Race {
    /// An empty race over a `width × height` image.
    pub fn new(width: usize, height: usize) -> Self {
        Race {
            width,
            height,
            pixels: Vec::new(),
        }
    }

    /// The image's width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Adds a tile's moments (allocating the image's on first use).
    pub fn merge(&mut self, tile: &TileMoments) {
        if self.pixels.is_empty() {
            self.pixels = vec![PixelMoments::default(); self.width * self.height];
        }
        for ((x, y), &moments) in tile.rect.pixels().zip(&tile.pixels) {
            self.pixels[y * self.width + x].merge(moments);
        }
    }

    /// Each arm's mean relMSE-weighted per-sample variance; `None` until both arms have
    /// pixels with two samples or more. The field's arm is taken to have guided
    /// ([`RaceResult::guided`]): a host whose field only rolled says so.
    pub fn result(&self) -> Option<RaceResult> {
        let (pixels, cap) = self.weighted_pixels(RELATIVE_FLOOR);
        let mut sums = [[0.0f64; 2]; 2]; // [field, off] × [capped variance, pixels]
        for pixel in pixels {
            let arm = &mut sums[usize::from(pixel.races_off)];
            arm[0] += pixel.variance.min(cap);
            arm[1] += 1.0;
        }
        let [field, off] = sums;
        (field[1] > 0.0 && off[1] > 0.0).then(|| RaceResult {
            field: field[0] / field[1],
            off: off[0] / off[1],
            seconds_per_sample: self.seconds_per_sample(),
            guided: true,
            sized: None,
        })
    }

    /// What the pixels measured (one arm's: AIS off's if `off_arm` is `Some(true)`, the
    /// field's if `Some(false)`; all where nothing raced), summed per 16 × 16 block of the
    /// image (row by row), weighed both ways ([`WeighedBlocks`]): their weighted variances
    /// as [`Race::result`] weighs and caps them, their gathers', and how many of their
    /// samples gathered.
    pub fn blocks(&self, off_arm: Option<bool>) -> WeighedBlocks {
        WeighedBlocks {
            relative: self.blocks_weighed(off_arm, RELATIVE_FLOOR),
            alike: self.blocks_weighed(off_arm, ALIKE_FLOOR),
        }
    }

    /// [`Race::blocks`] weighed as relMSE weighs pixels only: how the race's arms compare.
    pub fn relative_blocks(&self, off_arm: Option<bool>) -> Vec<BlockMoments> {
        self.blocks_weighed(off_arm, RELATIVE_FLOOR)
    }

    /// [`Race::blocks`] with each pixel weighed by 1 / (r² + `floor`).
    fn blocks_weighed(&self, off_arm: Option<bool>, floor: f64) -> Vec<BlockMoments> {
        let columns = GatherSizes::columns_for(self.width);
        let rows = self.height.div_ceil(TILE_SIZE);
        let mut blocks = vec![BlockMoments::default(); columns * rows];
        let (pixels, cap) = self.weighted_pixels(floor);
        for pixel in pixels
            .iter()
            .filter(|p| off_arm.is_none_or(|off| p.races_off == off))
        {
            let moments = &self.pixels[pixel.y * self.width + pixel.x];
            let samples = moments.count as f64;
            let gather = pixel.weight * moments.gather_variance / samples;
            blocks[GatherSizes::block_of(pixel.x, pixel.y, columns)].add_pixel(
                pixel.variance.min(cap),
                gather.min(cap),
                moments.gathers as f64 / samples,
            );
        }
        blocks
    }

    /// Every pixel with two samples or more, its variance weighted by 1 / (r² + `floor`)
    /// (r the mean of the pixels around), and the cap on those variances (their
    /// [`CAP_QUANTILE`]).
    fn weighted_pixels(&self, floor: f64) -> (Vec<WeightedPixel>, f64) {
        let mut weighted = Vec::new();
        for y in 0..self.height.min(self.pixels.len() / self.width.max(1)) {
            for x in 0..self.width {
                if let Some(variance) = self.pixels[y * self.width + x].variance() {
                    let reference = self.neighbourhood_mean(x, y);
                    let weight = 1.0 / (reference * reference + floor);
                    weighted.push(WeightedPixel {
                        x,
                        y,
                        races_off: races_off(x, y),
                        weight,
                        variance: variance * weight,
                    });
                }
            }
        }
        let cap = quantile(weighted.iter().map(|p| p.variance).collect(), CAP_QUANTILE);
        // Where nearly every pixel is noiseless, capping would hide the rest.
        let cap = if cap > 0.0 { cap } else { f64::INFINITY };
        (weighted, cap)
    }

    /// Each arm's seconds per sample, if its pixels were timed.
    fn seconds_per_sample(&self) -> Option<[f64; 2]> {
        let mut sums = [[0.0f64; 2]; 2]; // [field, off] × [seconds, samples]
        for (index, pixel) in self.pixels.iter().enumerate() {
            let off = races_off(index % self.width, index / self.width);
            let arm = &mut sums[usize::from(off)];
            arm[0] += pixel.seconds;
            arm[1] += pixel.count as f64;
        }
        let [field, off] = sums;
        (field[0] > 0.0 && off[0] > 0.0).then(|| [field[0] / field[1], off[0] / off[1]])
    }

    /// The mean of the pixel means around (`x`, `y`), itself included (both arms).
    fn neighbourhood_mean(&self, x: usize, y: usize) -> f64 {
        let (mut sum, mut count) = (0.0, 0.0);
        for ny in y.saturating_sub(1)..(y + 2).min(self.height) {
            for nx in x.saturating_sub(1)..(x + 2).min(self.width) {
                if let Some(mean) = self.pixels[ny * self.width + nx].mean() {
                    sum += mean;
                    count += 1.0;
                }
            }
        }
        sum / count
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A race over a 16 × 16 image whose pixels all hold `samples(x, y)`.
    fn race_of(samples: impl Fn(usize, usize) -> Vec<f32>) -> Race {
        let rect = PixelRect::whole(16, 16);
        let mut tile = TileMoments::new(rect, false);
        for (x, y) in rect.pixels() {
            tile.begin_pixel(x, y);
            for value in samples(x, y) {
                tile.sampled([value; 3]);
            }
        }
        let mut race = Race::new(16, 16);
        race.merge(&tile);
        race
    }

    #[test]
    fn the_quieter_arm_wins() {
        // Both arms average 1; the off arm's samples spread by ±0.5, the field's by ±0.1.
        let spread = |x, y| if races_off(x, y) { 0.5 } else { 0.1 };
        let race = race_of(|x, y| vec![1.0 - spread(x, y), 1.0 + spread(x, y)]);
        let result = race.result().unwrap();
        // Variance of two samples ±s: 2s²; weighted by 1 / (1 + 0.01).
        assert!((result.off - 0.5 / 1.01).abs() < 1e-6, "{result:?}");
        assert!((result.field - 0.02 / 1.01).abs() < 1e-6, "{result:?}");
        assert!(result.field_pays());
        // Reversed, the field does not pay.
        let race = race_of(|x, y| vec![1.0 - spread(y + 1, x), 1.0 + spread(y + 1, x)]);
        assert!(!race.result().unwrap().field_pays());
    }

    #[test]
    fn a_small_gain_does_not_pay_for_guiding() {
        // The field's variance 5% below off's: less than guiding costs.
        let spread = |x, y| if races_off(x, y) { 1.0 } else { 0.95f32.sqrt() };
        let race = race_of(|x, y| vec![1.0 - spread(x, y), 1.0 + spread(x, y)]);
        assert!(!race.result().unwrap().field_pays());
    }

    #[test]
    fn a_few_fireflies_do_not_decide_the_race() {
        // The field's pixels are quieter, but two of them hold a firefly: the plain mean of
        // the field's arm would be many times AIS off's.
        let firefly = |x, y| y == 3 && (x == 2 || x == 9);
        let race = race_of(|x, y| match (races_off(x, y), firefly(x, y)) {
            (true, _) => vec![0.5, 1.5],
            (false, true) => vec![1.0, 1.0, 10_000.0],
            (false, false) => vec![0.8, 1.2],
        });
        let result = race.result().unwrap();
        assert!(result.field_pays(), "{result:?}");
    }

    #[test]
    fn a_timed_tile_measures_its_pixels() {
        let rect = PixelRect::whole(2, 2);
        let mut tile = TileMoments::new(rect, true);
        for (x, y) in rect.pixels() {
            tile.begin_pixel(x, y);
            tile.sampled([1.0; 3]);
            tile.sampled([3.0; 3]);
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
        tile.end_pixel();
        assert!(tile.pixels.iter().all(|p| p.seconds >= 1e-3), "{tile:?}");
        let mut race = Race::new(2, 2);
        race.merge(&tile);
        let [field, off] = race.result().unwrap().seconds_per_sample.unwrap();
        assert!(field >= 5e-4 && off >= 5e-4, "{field} {off}");
        // Untimed, a race has no times.
        let mut untimed = Race::new(2, 2);
        untimed.merge(&TileMoments::new(rect, false));
        assert_eq!(untimed.seconds_per_sample(), None);
    }

    #[test]
    fn a_timed_race_weighs_variance_by_time() {
        let variance_and_time = |field: f64, off: f64, seconds_per_sample: Option<[f64; 2]>| {
            RaceResult {
                field,
                off,
                seconds_per_sample,
                guided: true,
                sized: None,
            }
            .field_pays()
        };
        // Half the variance at 1.5 times the time pays; at 2.5 times it does not.
        assert!(variance_and_time(0.5, 1.0, Some([1.5, 1.0])));
        assert!(!variance_and_time(0.5, 1.0, Some([2.5, 1.0])));
        // Roulette: 20% more variance at 30% less time pays, untimed it would not.
        assert!(variance_and_time(1.2, 1.0, Some([0.7, 1.0])));
        assert!(!variance_and_time(1.2, 1.0, None));
        // A field that only rolled is kept for time alone: its lower variance is noise.
        let rolled_only = |field: f64, seconds_per_sample: [f64; 2]| {
            RaceResult {
                field,
                off: 1.0,
                seconds_per_sample: Some(seconds_per_sample),
                guided: false,
                sized: None,
            }
            .field_pays()
        };
        assert!(!rolled_only(0.8, [1.01, 1.0]), "no time saved");
        assert!(rolled_only(0.8, [0.9, 1.0]));
        assert!(
            !rolled_only(1.2, [0.9, 1.0]),
            "more variance than time saved"
        );
    }

    #[test]
    fn a_sized_race_compares_the_arms_as_they_will_render() {
        // The field's variance at n candidates is above AIS off's, but with the sizes each
        // arm would get it predicts half AIS off's error: it pays.
        let sized = |sized, guided| RaceResult {
            field: 1.2,
            off: 1.0,
            seconds_per_sample: Some([1.0, 1.0]),
            guided,
            sized,
        };
        assert!(!sized(None, true).field_pays());
        assert!(sized(Some([0.5, 1.0]), true).field_pays());
        assert!(!sized(Some([1.5, 1.0]), true).field_pays());
        // A field that only rolled is still judged by the time it saves.
        assert!(!sized(Some([0.5, 1.0]), false).field_pays());
    }

    #[test]
    fn one_sample_per_pixel_gives_no_verdict() {
        assert_eq!(race_of(|_, _| vec![1.0]).result(), None);
    }
}
