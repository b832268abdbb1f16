//! A plain batch: AIS off without a call into the driver per candidate.
//!
//! A batch with no map and a fixed count of candidates ([`Batch::is_plain`]) traces every
//! candidate inside the BSDF's support with weight 1: nothing the host sees can change a
//! decision. The host can then take all of the batch's numbers at once
//! ([`Batch::begin_plain`]), trace the candidates in whatever order suits its work, and
//! hand back their sum ([`Batch::finish_plain`]). The numbers, the estimate (to the bit)
//! and the counts are those of the candidate-by-candidate calls, which cost a few
//! nanoseconds per candidate more.
//!
//! ```
//! use ais::{Batch, BatchConfig, PlainTally};
//!
//! let mut batch: Batch<f32> = Batch::new(BatchConfig::off()).unwrap();
//! assert!(batch.is_plain());
//! let (mut sum, mut tally) = (0.0, PlainTally::default());
//! for &[u1, _u2] in batch.begin_plain(16, 7) {
//!     // The host's proposal and ray; here the lower half of the square is outside the
//!     // support and every traced candidate brings u1.
//!     if u1 < 0.5 {
//!         tally.outside_support += 1;
//!     } else {
//!         tally.traced += 1;
//!         sum += u1;
//!     }
//! }
//! let estimate = batch.finish_plain(sum, tally);
//! assert_eq!((estimate.candidates, estimate.traced), (16, tally.traced));
//! ```

use super::{Batch, Estimate, Placement, Stopping};
use crate::stats::Stats;
use crate::value::Value;

/// What the host did with a plain batch's candidates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PlainTally {
    /// Candidates traced (those inside the support).
    pub traced: u32,
    /// Candidates outside the support, or whose direction could not be drawn: not traced.
    pub outside_support: u32,
}

impl<V: Value> Batch<V> {
    /// Whether the batch is plain Monte Carlo: no map and a fixed count of candidates
    /// ([`BatchConfig::off`](super::BatchConfig::off)), so that every candidate inside the
    /// support is traced with weight 1 and the host may use [`Batch::begin_plain`].
    pub fn is_plain(&self) -> bool {
        self.map.is_none() && self.config.stopping == Stopping::FixedCandidates
    }

    /// Begins a plain batch of `n` candidates with scrambling seed `seed` and returns the
    /// numbers of all of them, in order: each `[u1, u2]` as [`Batch::next_candidate`] would
    /// give it (the roulette's number is not needed). The host traces those inside the
    /// support, adds up their contributions `f(w) · visibility / p(w)` in this order, and
    /// ends the batch with [`Batch::finish_plain`].
    ///
    /// # Panics
    /// If the batch is not [plain](Batch::is_plain), or `n` is 0.
    pub fn begin_plain(&mut self, n: u32, seed: u64) -> &[[f32; 2]] {
        assert!(self.is_plain(), "Batch::begin_plain needs a plain batch");
        assert!(n >= 1, "a batch needs at least one ray");
        self.n = n;
        self.seed = seed;
        // One epoch of n candidates, scrambled as `start_epoch` scrambles the first.
        let epoch_seed = super::epoch_seed(seed, 0);
        self.plain_points.clear();
        match self.config.placement {
            Placement::Halton => {
                // Two coordinates each: the third's permutations are not drawn (the
                // next batch that reads them scrambles them afresh).
                self.halton.rescramble_2d(epoch_seed, n);
                let points = (0..n).map(|index| self.halton.point_2d(index));
                self.plain_points.extend(points);
            }
            Placement::Random => {
                self.rng = super::random_placement(epoch_seed);
                for _ in 0..n {
                    let [u1, u2, _] = super::random_point(&mut self.rng);
                    self.plain_points.push([u1, u2]);
                }
            }
        }
        // Nothing is left to draw one by one.
        self.done = true;
        self.pending.clear();
        self.recorded = 0;
        &self.plain_points
    }

    /// Ends a plain batch begun with [`Batch::begin_plain`]: `sum` is the sum of the traced
    /// candidates' contributions (in the order of the numbers), `tally` what became of the
    /// `n` candidates. Returns the estimate and adds the counts to [`Batch::stats`], as
    /// [`Batch::finish`] does.
    pub fn finish_plain(&mut self, sum: V, tally: PlainTally) -> Estimate<V> {
        debug_assert_eq!(
            tally.traced + tally.outside_support,
            self.n,
            "every candidate of a plain batch is traced or outside the support"
        );
        let n = self.n;
        // The weight `close_epoch` gives the single epoch, n_e / n / candidates: n / n / n,
        // which is 1 / n to the bit.
        let weight = 1.0 / n as f64;
        self.batch_stats = Stats {
            batches: 1,
            candidates: n as u64,
            traced: tally.traced as u64,
            rejected_outside_support: tally.outside_support as u64,
            ..Stats::default()
        };
        self.stats.merge(&self.batch_stats);
        Estimate {
            value: V::zero().add(sum.scale(weight)),
            candidates: n,
            traced: tally.traced,
            hit_cap: false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{BatchConfig, Decision, MapStart};

    /// A host's candidate: outside the support below u1 = 0.3, else worth u1 + u2² (in a
    /// batch of RGB values, spread over the channels).
    fn contribution([u1, u2]: [f32; 2]) -> Option<[f32; 3]> {
        (u1 >= 0.3).then_some([u1 + u2 * u2, u2, 0.1 * u1])
    }

    fn by_candidates(batch: &mut Batch<[f32; 3]>, n: u32, seed: u64) -> Estimate<[f32; 3]> {
        batch.begin(n, seed, MapStart::Empty);
        while let Some(candidate) = batch.next_candidate() {
            let value = contribution(candidate.u);
            if let Decision::Trace { .. } = batch.decide([0.0, 0.0, 1.0], value.is_some()) {
                batch.record(value.expect("traced inside the support"), 1.0);
            }
        }
        batch.finish()
    }

    fn plainly(batch: &mut Batch<[f32; 3]>, n: u32, seed: u64) -> Estimate<[f32; 3]> {
        let (mut sum, mut tally) = ([0.0; 3], PlainTally::default());
        let points = batch.begin_plain(n, seed).to_vec();
        for value in points.into_iter().map(contribution) {
            match value {
                Some(value) => {
                    sum = Value::add(sum, value);
                    tally.traced += 1;
                }
                None => tally.outside_support += 1,
            }
        }
        batch.finish_plain(sum, tally)
    }

    #[test]
    fn a_plain_batch_gives_the_candidates_estimate_and_counts_to_the_bit() {
        for placement in [Placement::Halton, Placement::Random] {
            let config = BatchConfig {
                placement,
                ..BatchConfig::off()
            };
            let mut one_by_one = Batch::new(config).unwrap();
            let mut plain = Batch::new(config).unwrap();
            for (n, seed) in [(1, 3), (7, 11), (16, 5), (128, 9), (13, 0)] {
                let expected = by_candidates(&mut one_by_one, n, seed);
                let got = plainly(&mut plain, n, seed);
                assert_eq!(
                    got.value.map(f32::to_bits),
                    expected.value.map(f32::to_bits)
                );
                assert_eq!(
                    (got.candidates, got.traced, got.hit_cap),
                    (expected.candidates, expected.traced, expected.hit_cap)
                );
            }
            assert_eq!(plain.stats(), one_by_one.stats());
        }
    }

    #[test]
    fn batches_with_a_map_or_a_candidate_budget_are_not_plain() {
        let budget = BatchConfig {
            stopping: Stopping::CandidateBudget,
            ..BatchConfig::off()
        };
        for config in [BatchConfig::default(), budget] {
            assert!(!Batch::<f32>::new(config).unwrap().is_plain());
        }
    }
}
