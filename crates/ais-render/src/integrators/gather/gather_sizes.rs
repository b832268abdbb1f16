//! How many candidates a gather gets, per block of the image: the counts that give the
//! least error in the time the render takes, chosen from what the race passes measured.
//!
//! A pixel sample's variance has two parts: what its camera ray sees (which surface, which
//! edge, a light seen directly), `V_cam`, and its gather's, which falls as `V₁ / m` with `m`
//! candidates. A camera sample costs its own work, `ρ₀` candidates' worth, plus `m`
//! candidates where its ray gathers (a share `g` of its samples). Fewer candidates in a
//! block buy every pixel more samples in the same time.
//!
//! **The camera's part falls faster than one over the samples.** A pixel's camera samples
//! are stratified (an Owen-scrambled Sobol sequence per pixel). Where a pixel holds an edge,
//! the error of the mean of `N` stratified samples falls as `N^(-3/2)`, not `N^(-1)`, and
//! faster where the pixel is smooth. So the image's error after `N` samples per pixel,
//! with `m_b` candidates in block `b`, is taken as
//!
//!   E = Σ_b [ V_cam,b / N^(3/2) + V₁,b / (m_b N) ],
//!
//! with `N` the samples the render's time buys at those counts. The camera's part weighs
//! most in a short render: at a few dozen samples per pixel, fewer candidates and more
//! camera samples pay where what the camera sees dominates (foliage, edges); at a few
//! hundred, the gathers' part is nearly all that is left. (Counting the camera's part as
//! that of independent samples, `V_cam / N`, gave 4× over AIS off in the foliage at 128
//! candidates, where a render takes a few dozen samples per pixel, but lost in the sphere
//! lights at 16 candidates, where it takes a few hundred; leaving it out lost the foliage's
//! gain: the repository's BENCHMARKS.md, section 5.6.)
//!
//! Setting each `m_b`'s derivative to zero at a fixed time gives `m_b = λ · √(V₁,b / g_b)`,
//! one scale `λ` for the image: blocks whose gathers vary little (in shadow, or lit evenly)
//! get fewer candidates. `λ` is found by scanning. A gather never gets more than `n`
//! (time per sample never grows) nor fewer than [`FEWEST_SHARE`] of it or [`FEWEST`], and
//! the image keeps `n` everywhere unless the predicted gain is at least [`LEAST_GAIN`].
//!
//! **The render's length.** `N` is what the render will take: the samples done, plus those
//! left, scaled by how much cheaper a sample gets. A render that does not know its end
//! (later renders go on from it, with no horizon given) is taken as endless: only the
//! gathers' spread over the image counts, and a single block keeps `n`. The film averages
//! every sample alike, so the samples taken with `n` candidates before the choice stay in
//! the image with their variance.
//!
//! Each pixel's variances are weighed two ways ([`WeighedBlocks`]): as relMSE weighs them
//! and with dark pixels' relative error counted alike. The counts minimise both errors
//! together, and none may be predicted to grow.
//!
//! `V₁` comes from the gathers' own estimate of their variance, which counts the candidates
//! as independent: Halton's stratified candidates vary less, so the estimate is high where
//! they stratify well, and `V_cam` (the pixels' sample variance less that estimate) low.
//! (Making each block as efficient as it can be on its own, instead of the image, almost
//! never changed a count. One count for the whole image gained less than a count per
//! block.)
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
/// pixel's variances weighted as one of [`WeighedBlocks`]'s weighings weighs them).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BlockMoments {
    /// Pixels measured.
    pub pixels: f64,
    /// Σ per-sample variance of the pixels (camera and gather together).
    pub total: f64,
    /// Σ per-sample variance of the pixels' gathers, at `n` candidates.
    pub gather: f64,
    /// Σ share of the pixels' samples whose camera ray gathered.
    pub gathered: f64,
}

impl BlockMoments {
    /// Adds one pixel: its weighted variance per sample, its gathers' weighted variance per
    /// sample, and the share of its samples that gathered.
    pub fn add_pixel(&mut self, total: f64, gather: f64, gathered: f64) {
        self.pixels += 1.0;
        self.total += total;
        self.gather += gather;
        self.gathered += gathered;
    }

    /// The gathers' variance per candidate (`V₁`), from their variance at `n` candidates.
    fn per_candidate(&self, n: u32) -> f64 {
        self.gather * n as f64
    }

    /// The camera's part of the variance per sample (what no count of candidates changes).
    fn camera(&self) -> f64 {
        (self.total - self.gather).max(0.0)
    }

    /// A sample's cost in candidates' worth with `m` candidates per gather.
    fn cost(&self, m: f64) -> f64 {
        SAMPLE_COST * self.pixels + self.gathered * m
    }
}

/// What the race passes measured per block of the image, with each pixel weighed two ways:
/// as relMSE weighs it, 1 / (r² + 0.01), and with every pixel's relative error alike down
/// to ten times darker, 1 / (r² + 10⁻⁴).
///
/// relMSE's floor discounts pixels darker than about 0.1: counts that minimise it alone
/// cut the candidates of dark blocks first, and there the image got noisier than AIS off's
/// (sphere lights among occluders at 16 candidates: in pixels darker than 0.03, twice AIS
/// off's error with each pixel's relative error alike; the repository's BENCHMARKS.md,
/// section 5.6). Weighed both ways, the counts change only where neither image error is
/// predicted to grow.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WeighedBlocks {
    /// The blocks with pixels weighed as relMSE weighs them.
    pub relative: Vec<BlockMoments>,
    /// The blocks with every pixel's relative error alike, dark pixels included.
    pub alike: Vec<BlockMoments>,
}

impl WeighedBlocks {
    /// The blocks with the alike weighing's variances scaled by `alike` and added to
    /// relMSE's: what the counts minimise. (The error at the render's end is linear in the
    /// variances, for any counts, up to the camera's part floored at zero per block, so the
    /// blend's error is the scaled errors' sum.)
    fn blended(&self, alike: f64) -> Vec<BlockMoments> {
        self.relative
            .iter()
            .zip(&self.alike)
            .map(|(r, a)| BlockMoments {
                pixels: r.pixels,
                total: r.total + a.total * alike,
                gather: r.gather + a.gather * alike,
                gathered: r.gathered,
            })
            .collect()
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
    /// `columns` per row), the render standing at `samples` (its end as far as known);
    /// `None` where keeping `n` everywhere is as good (within [`LEAST_GAIN`]) or nothing
    /// was measured.
    ///
    /// The counts minimise the sum of the two weighings' errors, each relative to its error
    /// with `n` everywhere, among those that predict neither weighing's error to grow.
    pub fn choose(
        blocks: &WeighedBlocks,
        columns: usize,
        n: u32,
        samples: PassEnd,
    ) -> Option<GatherSizes> {
        let everywhere = vec![n; blocks.relative.len()];
        let kept = [&blocks.relative, &blocks.alike]
            .map(|weighed| final_error(weighed, &everywhere, n, samples));
        let [Some(relative), Some(alike)] = kept else {
            return None;
        };
        // Scaled to relMSE's own size, so that the scan's scales cover its counts.
        let blended = blocks.blended(relative / alike);
        let no_worse = |counts: &Vec<u32>| {
            let error = |weighed| final_error(weighed, counts, n, samples).unwrap_or(0.0);
            error(&blocks.relative) <= relative && error(&blocks.alike) <= alike
        };
        let (best, counts) = scanned_counts(&blended, n)
            .filter(no_worse)
            .filter_map(|counts| Some((final_error(&blended, &counts, n, samples)?, counts)))
            .min_by(|a, b| a.0.total_cmp(&b.0))?;
        // With `n` everywhere, the blend's error is twice relMSE's.
        (2.0 * relative >= LEAST_GAIN * best).then_some(GatherSizes { columns, counts })
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

/// The least error per pixel that counts chosen over `blocks` predict at the render's end
/// (with `n` everywhere where no choice does better), for gathers that take `1 / pace` of
/// the time per sample that the render's horizon was measured at: how two ways to gather,
/// each with its own counts, compare. `None` if nothing was measured.
pub fn least_error(blocks: &[BlockMoments], n: u32, samples: PassEnd, pace: f64) -> Option<f64> {
    let pixels: f64 = blocks.iter().map(|b| b.pixels).sum();
    let samples = PassEnd {
        left: samples.left.map(|left| (left as f64 * pace).round() as u32),
        ..samples
    };
    let least = scanned_counts(blocks, n)
        .chain([vec![n; blocks.len()]])
        .filter_map(|counts| final_error(blocks, &counts, n, samples))
        .min_by(f64::total_cmp)?;
    // Endless: variance × cost per sample, both summed over the pixels, and time per sample.
    Some(match samples.left {
        Some(_) => least / pixels,
        None => least / (pixels * pixels * pace),
    })
}

/// The counts of every scale `λ` scanned: a log scale (steps of 2^(1/12)) wide enough for
/// every count from 1 to `n`.
fn scanned_counts(blocks: &[BlockMoments], n: u32) -> impl Iterator<Item = Vec<u32>> + '_ {
    let fewest = ((n as f64 * FEWEST_SHARE).ceil() as u32).max(FEWEST).min(n);
    (0..=240)
        .map(|step| 2f64.powf(step as f64 / 12.0 - 10.0))
        .map(move |scale| counts_at(blocks, scale, n, fewest))
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

/// The image's error at the render's end with `counts` per block, in the time it would
/// take with `n` everywhere, up to a factor that is the same for every choice of counts;
/// `None` if nothing was measured. After the `samples.done` samples taken with `n`, the
/// `samples.left` it would take with `n` become as many more as the cheaper samples buy.
/// Where the end is not known the render is taken as endless: its variance × cost per
/// sample, where the camera's part has vanished.
fn final_error(blocks: &[BlockMoments], counts: &[u32], n: u32, samples: PassEnd) -> Option<f64> {
    let kept_cost: f64 = blocks.iter().map(|b| b.cost(n as f64)).sum();
    let cost: f64 = blocks
        .iter()
        .zip(counts)
        .map(|(b, &m)| b.cost(m as f64))
        .sum();
    let gathers = |done: f64, left: f64| -> f64 {
        blocks
            .iter()
            .zip(counts)
            .map(|(b, &m)| done * b.gather + left * b.per_candidate(n) / m as f64)
            .sum()
    };
    let Some(left) = samples.left else {
        let variance = gathers(0.0, 1.0);
        return (variance > 0.0 && cost > 0.0).then_some(variance * cost);
    };
    let done = samples.done as f64;
    let left = left as f64 * kept_cost / cost;
    let total = done + left;
    let camera: f64 = blocks.iter().map(BlockMoments::camera).sum();
    let error = gathers(done, left) / (total * total) + camera / total.powf(1.5);
    (error > 0.0 && total > 0.0).then_some(error)
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

    /// A block of 256 gathering pixels whose samples vary by `camera` per sample through
    /// what the camera sees and by `gather` through their gathers.
    fn block(camera: f64, gather: f64) -> BlockMoments {
        BlockMoments {
            pixels: 256.0,
            total: 256.0 * (camera + gather),
            gather: 256.0 * gather,
            gathered: 256.0,
        }
    }

    /// `blocks` with both weighings alike: as if every pixel were brighter than relMSE's
    /// floor.
    fn alike(blocks: &[BlockMoments]) -> WeighedBlocks {
        WeighedBlocks {
            relative: blocks.to_vec(),
            alike: blocks.to_vec(),
        }
    }

    /// A render at 4 samples per pixel with `left` to go.
    fn ending_after(left: u32) -> PassEnd {
        PassEnd {
            done: 4,
            left: Some(left),
        }
    }

    #[test]
    fn an_endless_render_keeps_a_single_blocks_candidates() {
        // (V₁ / m)(ρ₀ + m) only falls as m grows: where the camera's part has vanished,
        // fewer candidates pay only where another block needs them more.
        for gather in [1e-4, 0.01, 0.05] {
            for n in [16, 128] {
                let blocks = [block(0.05, gather)];
                assert_eq!(GatherSizes::choose(&alike(&blocks), 1, n, OPEN), None);
            }
        }
    }

    #[test]
    fn a_short_render_where_the_camera_dominates_takes_fewer_candidates() {
        // The gathers vary by 0.002 per sample at 128 candidates, the camera's part by 0.01.
        // At 32 samples per pixel the camera's part of the error, 0.01 / 32^1.5, is 0.9 of
        // the gathers', 0.002 / 32: fewer candidates and more samples pay (1.56× predicted
        // at 20). At 4004 it is 0.08 of it: they do not (1.05×, below the least gain).
        let blocks = [block(0.01, 0.002)];
        let short = GatherSizes::choose(&alike(&blocks), 1, 128, ending_after(28)).unwrap();
        assert!(short.at(0, 0) <= 24, "{short:?}");
        assert_eq!(
            GatherSizes::choose(&alike(&blocks), 1, 128, ending_after(4000)),
            None
        );
        // Without the camera's part, no render is short enough.
        assert_eq!(
            GatherSizes::choose(&alike(&[block(0.0, 0.002)]), 1, 128, ending_after(28)),
            None
        );
    }

    #[test]
    fn evenly_varying_blocks_keep_their_candidates() {
        let blocks = [block(0.0, 0.01), block(0.0, 0.012), block(0.0, 0.009)];
        assert_eq!(GatherSizes::choose(&alike(&blocks), 3, 128, OPEN), None);
    }

    #[test]
    fn blocks_get_counts_by_their_gathers_variance() {
        // Side by side: the first block's gathers hardly vary (a shadow), the second's do.
        // The first drops to the floor, the second keeps more.
        let blocks = [block(0.0, 0.0001), block(0.0, 0.05)];
        for samples in [OPEN, ending_after(100)] {
            let sizes = GatherSizes::choose(&alike(&blocks), 2, 128, samples).unwrap();
            let counts = [sizes.at(0, 0), sizes.at(TILE_SIZE, 3)];
            assert_eq!(counts[0], 16);
            assert!(counts[1] >= 2 * counts[0], "{counts:?}");
            assert!((sizes.mean() - (counts[0] + counts[1]) as f64 / 2.0).abs() < 1e-9);
            // No block's count one away does better: the scan found the optimum.
            let best = final_error(&blocks, &counts, 128, samples).unwrap();
            for block in 0..2 {
                for step in [-1i32, 1] {
                    let mut moved = counts;
                    moved[block] = (moved[block] as i32 + step).clamp(16, 128) as u32;
                    let error = final_error(&blocks, &moved, 128, samples).unwrap();
                    assert!(error >= best * (1.0 - 1e-9), "{moved:?}");
                }
            }
        }
    }

    #[test]
    fn a_dark_block_keeps_what_its_relative_error_needs() {
        // relMSE's floor sees the first block's gathers hardly vary: it is dark. Weighed
        // alike, its gathers vary as much as the bright block's, relative to their light.
        let relative = [block(0.0, 0.0001), block(0.0, 0.05)];
        let both = WeighedBlocks {
            relative: relative.to_vec(),
            alike: vec![block(0.0, 0.05), block(0.0, 0.05)],
        };
        for samples in [OPEN, ending_after(100)] {
            let cut = GatherSizes::choose(&alike(&relative), 2, 128, samples).unwrap();
            assert_eq!(
                cut.at(0, 0),
                16,
                "relMSE alone cuts the dark block to the floor"
            );
            let kept = GatherSizes::choose(&both, 2, 128, samples);
            // Either no count changes or the dark block keeps more: never the cut above.
            let dark = kept.map_or(128, |sizes| sizes.at(0, 0));
            assert!(dark > 2 * cut.at(0, 0), "{samples:?}: {dark}");
        }
    }

    #[test]
    fn the_least_error_is_per_pixel_and_falls_with_pace() {
        let blocks = [block(0.01, 0.002), block(0.0, 0.05)];
        for samples in [OPEN, ending_after(28)] {
            let at = |pace| least_error(&blocks, 128, samples, pace).unwrap();
            assert!(at(2.0) < at(1.0), "{samples:?}");
            // No better than the best counts' error, no worse than keeping n.
            let kept = final_error(&blocks, &[128, 128], 128, samples).unwrap();
            // Per pixel: the endless error is variance × cost, both summed over pixels.
            let pixels = if samples.left.is_some() {
                512.0
            } else {
                512.0 * 512.0
            };
            assert!(at(1.0) <= kept / pixels * (1.0 + 1e-12), "{samples:?}");
        }
        // Twice the pixels measuring the same: the same error per pixel.
        let doubled = [blocks[0], blocks[0], blocks[1], blocks[1]];
        let [one, two] = [&blocks[..], &doubled[..]]
            .map(|b| least_error(b, 128, ending_after(28), 1.0).unwrap());
        assert!((one - two).abs() < 1e-9 * one, "{one} {two}");
    }

    #[test]
    fn few_samples_left_keep_more_candidates() {
        // With 4 samples taken, the fewer are left the more of the 128 the quiet block
        // keeps: the film's plain average holds the samples taken, and variance added to a
        // few cannot be repaid.
        let blocks = [block(0.0, 0.002), block(0.0, 0.05)];
        let count_with = |left| {
            GatherSizes::choose(&alike(&blocks), 2, 128, ending_after(left))
                .map(|sizes| sizes.at(0, 0))
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
        assert_eq!(GatherSizes::choose(&alike(&[]), 0, 16, OPEN), None);
        assert_eq!(
            GatherSizes::choose(&alike(&[BlockMoments::default()]), 1, 16, OPEN),
            None
        );
        assert_eq!(
            GatherSizes::choose(&alike(&[BlockMoments::default()]), 1, 16, ending_after(10)),
            None
        );
    }
}
