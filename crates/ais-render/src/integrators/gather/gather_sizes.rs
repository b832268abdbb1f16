//! How many candidates a gather gets, per block of the image: the counts that give the
//! least noise per unit of time, chosen from what the race passes measured.
//!
//! A gather's variance falls as `V₁ / m` with `m` candidates. A camera sample costs its own
//! work, `ρ₀` candidates' worth, plus `m` candidates where its ray gathers (a share `g` of
//! its samples). Over the image's blocks `b`, minimising (Σ variance) × (Σ cost) gives,
//! setting each `m_b`'s derivative to zero,
//!
//!   m_b = λ · √(V₁,b / g_b),   λ = √(C / V),
//!
//! with `C` and `V` the image's cost and variance at the optimum: one scale `λ` for the
//! image, found by scanning it. Blocks whose gathers vary little (in shadow, or lit evenly)
//! get fewer candidates, and the time they save buys every pixel more samples; blocks whose
//! gathers vary most keep the user's `n`. A gather never gets more than `n` (time per
//! sample never grows) nor fewer than [`FEWEST_SHARE`] of it or [`FEWEST`], and the image
//! keeps `n` everywhere unless the predicted gain is at least [`LEAST_GAIN`].
//!
//! **What the camera sees is left out.** A pixel's samples also vary with what their camera
//! rays see (an edge, a light seen directly), but camera samples are stratified (an
//! Owen-scrambled Sobol sequence per pixel), and that part of the error falls much faster
//! than one over the samples, so the model leaves it out, and a single block keeps `n`: the
//! counts follow only how the gathers' variance is spread over the image. (Measured, this
//! changed no scene's gain beyond noise: the camera's term was small next to that spread.
//! Where the choice loses, in the sphere lights and the foliage at n = 16, it is not the
//! camera's term; the repository's BENCHMARKS.md, section 5.6.)
//!
//! **The samples already taken count.** The film averages every sample alike, so the
//! samples taken with `n` candidates before the choice stay in the image with their
//! variance and cost; with few samples left, variance added to them cannot be repaid.
//! Where later renders go on learning, the end is open and only the per-sample optimum
//! counts.
//!
//! `V₁` comes from the gathers' own estimate of their variance, which counts the candidates
//! as independent: Halton's stratified candidates vary less, so the estimate is high where
//! they stratify well. (Making each block as efficient as it can be on its own, instead of
//! the image, almost never changed a count. One count for the whole image gained less than
//! a count per block.)
//!
//! The counts change only between passes and are read per pixel: each pass stays unbiased
//! (a gather of any fixed size is), and the image does not depend on threads.

use crate::render::{PassEnd, TILE_SIZE};

/// What a camera sample costs apart from its candidates, in candidates (its camera ray, the
/// shading point, the film). Measured from the render times of AIS off at 16 and 128
/// candidates (BENCHMARKS.md, section 5.6): 1.1–1.3 in the sunlit room and the courtyard.
/// It enters beside the mean count `m̄` in `C`, so its error moves `λ` by a fraction of it.
pub const SAMPLE_COST: f64 = 1.0;

/// No gather gets fewer than this share of the settings' `n` candidates, nor fewer than
/// [`FEWEST`].
pub const FEWEST_SHARE: f64 = 1.0 / 8.0;

/// No gather gets fewer candidates than this. With one-sample MIS, a gather of two has no
/// light sample at all one time in four: its variance is carried by rare events that the
/// race's three samples per pixel do not see (gathers of 2 lost in the Cornell box).
pub const FEWEST: u32 = 4;

/// The counts change from `n` only where they are predicted to lower variance × time by at
/// least this factor: a smaller predicted gain is within the noise of the estimates.
pub const LEAST_GAIN: f64 = 1.1;

/// What the race passes measured in one block of the image, summed over its pixels (each
/// pixel's variances weighted as relMSE weighs them).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BlockMoments {
    /// Pixels measured.
    pub pixels: f64,
    /// Σ per-sample variance of the pixels' gathers, at `n` candidates.
    pub gather: f64,
    /// Σ share of the pixels' samples whose camera ray gathered.
    pub gathered: f64,
}

impl BlockMoments {
    /// Adds one pixel: its gathers' weighted variance per sample, and the share of its
    /// samples that gathered.
    pub fn add_pixel(&mut self, gather: f64, gathered: f64) {
        self.pixels += 1.0;
        self.gather += gather;
        self.gathered += gathered;
    }

    /// The gathers' variance per candidate (`V₁`), from their variance at `n` candidates.
    fn per_candidate(&self, n: u32) -> f64 {
        self.gather * n as f64
    }
}

/// The candidates per gather, per 16 × 16-pixel block of the image.
#[derive(Clone, Debug, PartialEq)]
pub struct GatherSizes {
    /// Blocks per row.
    columns: usize,
    /// Candidates per gather, per block, row by row.
    counts: Vec<u32>,
}

impl GatherSizes {
    /// The counts for `n`-candidate gathers over blocks measured as `blocks` (row by row,
    /// `columns` per row), the render standing at `samples`; `None` where keeping `n`
    /// everywhere is as good (within [`LEAST_GAIN`]) or nothing was measured.
    pub fn choose(
        blocks: &[BlockMoments],
        columns: usize,
        n: u32,
        samples: PassEnd,
    ) -> Option<GatherSizes> {
        let fewest = ((n as f64 * FEWEST_SHARE).ceil() as u32).max(FEWEST).min(n);
        let kept = efficiency_cost(blocks, &vec![n; blocks.len()], n, samples)?;
        // λ on a log scale (steps of 2^(1/12)) wide enough for every count from 1 to n.
        let (best, counts) = (0..=240)
            .map(|step| 2f64.powf(step as f64 / 12.0 - 10.0))
            .map(|scale| counts_at(blocks, scale, n, fewest))
            .filter_map(|counts| Some((efficiency_cost(blocks, &counts, n, samples)?, counts)))
            .min_by(|a, b| a.0.total_cmp(&b.0))?;
        (kept >= LEAST_GAIN * best).then_some(GatherSizes { columns, counts })
    }

    /// Candidates for a gather in pixel (`x`, `y`).
    pub fn at(&self, x: usize, y: usize) -> u32 {
        self.counts[Self::block_of(x, y, self.columns)]
    }

    /// The mean count over the image's blocks.
    pub fn mean(&self) -> f64 {
        self.counts.iter().map(|&c| c as f64).sum::<f64>() / self.counts.len().max(1) as f64
    }

    /// Blocks per row of a `width`-pixel-wide image.
    pub fn columns_for(width: usize) -> usize {
        width.div_ceil(TILE_SIZE)
    }

    /// The block (row-major index) of pixel (`x`, `y`) in an image `columns` blocks wide.
    pub fn block_of(x: usize, y: usize, columns: usize) -> usize {
        (y / TILE_SIZE) * columns + x / TILE_SIZE
    }
}

/// Each block's count at scale `λ`: `λ · √(V₁ / g)` rounded, within [`fewest`, `n`].
fn counts_at(blocks: &[BlockMoments], scale: f64, n: u32, fewest: u32) -> Vec<u32> {
    blocks
        .iter()
        .map(|block| {
            if block.gathered <= 0.0 {
                return n;
            }
            let count = scale * (block.per_candidate(n) / block.gathered).sqrt();
            (count.round().min(n as f64) as u32).max(fewest)
        })
        .collect()
}

/// Variance × cost of the image with `counts` per block, after the `samples.done` samples
/// per pixel taken with `n` candidates and for the `samples.left` still to take (all that
/// counts where that is open-ended); `None` if nothing was measured. The film averages
/// every sample alike, so the samples already taken weigh in with what they cost and how
/// they vary: a few samples left cannot repay much variance added to them.
fn efficiency_cost(
    blocks: &[BlockMoments],
    counts: &[u32],
    n: u32,
    samples: PassEnd,
) -> Option<f64> {
    let (done, left) = match samples.left {
        Some(left) => (samples.done as f64, left as f64),
        None => (0.0, 1.0),
    };
    let (mut variance, mut cost) = (0.0, 0.0);
    for (block, &count) in blocks.iter().zip(counts) {
        let per_candidate = block.per_candidate(n);
        let block_cost = |m: f64| SAMPLE_COST * block.pixels + block.gathered * m;
        variance += done * block.gather + left * per_candidate / count as f64;
        cost += done * block_cost(n as f64) + left * block_cost(count as f64);
    }
    (variance > 0.0 && cost > 0.0).then_some(variance * cost)
}

/// One gather's candidates as its estimate weighs them (luminance of value / acceptance),
/// for the variance of that estimate.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CandidateSpread {
    sum: f64,
    sum_squares: f64,
    /// The last ended gather's variance.
    variance: Option<f64>,
}

impl CandidateSpread {
    /// Adds a traced candidate's weighted luminance (untraced candidates add zero).
    pub fn add(&mut self, weighted: f64) {
        self.sum += weighted;
        self.sum_squares += weighted * weighted;
    }

    /// The gather ended with `candidates` candidates: the variance of their mean is
    /// estimated from their sample variance (none below two), and the sums clear.
    /// Candidates placed by Halton's sequence are stratified and vary less than independent
    /// ones: the estimate is high, which keeps counts high.
    pub fn end_gather(&mut self, candidates: u32) {
        let m = candidates as f64;
        self.variance = (candidates >= 2)
            .then(|| ((self.sum_squares - self.sum * self.sum / m) / (m - 1.0)).max(0.0) / m);
        self.sum = 0.0;
        self.sum_squares = 0.0;
    }

    /// The variance of the last ended gather's estimate, taken (`None`: none, or too few
    /// candidates to tell).
    pub fn take_variance(&mut self) -> Option<f64> {
        self.variance.take()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An open-ended number of samples after the choice.
    const OPEN: PassEnd = PassEnd {
        done: 4,
        left: None,
    };

    /// A block of 256 gathering pixels whose gathers vary by `gather` per sample.
    fn block(gather: f64) -> BlockMoments {
        BlockMoments {
            pixels: 256.0,
            gather: 256.0 * gather,
            gathered: 256.0,
        }
    }

    #[test]
    fn a_single_block_keeps_its_candidates() {
        // (V₁ / m)(ρ₀ + m) only falls as m grows: with the camera's noise left out, fewer
        // candidates pay only where another block needs them more.
        for gather in [1e-4, 0.01, 0.05] {
            for n in [16, 128] {
                assert_eq!(GatherSizes::choose(&[block(gather)], 1, n, OPEN), None);
            }
        }
    }

    #[test]
    fn evenly_varying_blocks_keep_their_candidates() {
        let blocks = [block(0.01), block(0.012), block(0.009)];
        assert_eq!(GatherSizes::choose(&blocks, 3, 128, OPEN), None);
    }

    #[test]
    fn blocks_get_counts_by_their_gathers_variance() {
        // Side by side: the first block's gathers hardly vary (a shadow), the second's do.
        // The first drops to the floor, the second keeps more.
        let blocks = [block(0.0001), block(0.05)];
        let sizes = GatherSizes::choose(&blocks, 2, 128, OPEN).unwrap();
        let counts = [sizes.at(0, 0), sizes.at(TILE_SIZE, 3)];
        assert_eq!(counts[0], 16);
        assert!(counts[1] >= 2 * counts[0], "{counts:?}");
        assert!((sizes.mean() - (counts[0] + counts[1]) as f64 / 2.0).abs() < 1e-9);
        // No block's count one away does better: the scan found the optimum.
        let best = efficiency_cost(&blocks, &counts, 128, OPEN).unwrap();
        for block in 0..2 {
            for step in [-1i32, 1] {
                let mut moved = counts;
                moved[block] = (moved[block] as i32 + step).clamp(16, 128) as u32;
                let cost = efficiency_cost(&blocks, &moved, 128, OPEN).unwrap();
                assert!(cost >= best * (1.0 - 1e-9), "{moved:?}");
            }
        }
    }

    #[test]
    fn few_samples_left_keep_more_candidates() {
        // With 4 samples taken, the fewer are left the more of the 128 the quiet block
        // keeps: the film's plain average holds the samples taken, and variance added to a
        // few cannot be repaid.
        let blocks = [block(0.002), block(0.05)];
        let count_with = |left| {
            let samples = PassEnd {
                done: 4,
                left: Some(left),
            };
            GatherSizes::choose(&blocks, 2, 128, samples).map(|sizes| sizes.at(0, 0))
        };
        assert_eq!(count_with(1), None);
        let [four, many] = [count_with(4).unwrap(), count_with(1000).unwrap()];
        assert!(four > many, "{four} {many}");
    }

    #[test]
    fn a_gathers_spread_gives_the_variance_of_its_mean() {
        let mut spread = CandidateSpread::default();
        // Four candidates, two traced: 0, 2, 0, 2: sample variance 4/3, of the mean 1/3.
        spread.add(2.0);
        spread.add(2.0);
        spread.end_gather(4);
        let variance = spread.take_variance().unwrap();
        assert!((variance - 1.0 / 3.0).abs() < 1e-12, "{variance}");
        assert_eq!(spread, CandidateSpread::default(), "cleared");
        spread.add(1.0);
        spread.end_gather(1);
        assert_eq!(spread.take_variance(), None, "one candidate cannot tell");
    }

    #[test]
    fn nothing_measured_changes_nothing() {
        assert_eq!(GatherSizes::choose(&[], 0, 16, OPEN), None);
        assert_eq!(
            GatherSizes::choose(&[BlockMoments::default()], 1, 16, OPEN),
            None
        );
    }
}
