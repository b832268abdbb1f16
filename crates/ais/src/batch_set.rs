//! Many gathers driven together, a round at a time: for hosts that trace rays in waves
//! (wavefront renderers, GPU or SIMD hosts, Python with numpy or Dr.Jit arrays).
//!
//! Each round asks every unfinished gather for one candidate, then takes the host's
//! directions for all of them at once, then the traced rays' results at once. Each gather
//! is an ordinary [`Batch`] underneath, so a batch set gives exactly the estimates the same
//! batches give one by one (a test checks it bit for bit).
//!
//! ```
//! use ais::{BatchConfig, BatchSet};
//!
//! let gathers = 4;
//! let mut set: BatchSet<f32> = BatchSet::new(BatchConfig::default(), gathers).unwrap();
//! set.begin(16, &[1, 2, 3, 4]);
//! let mut round = set.round_buffers();
//! while set.next_candidates(&mut round) > 0 {
//!     for g in 0..gathers {
//!         // The host's proposal: uniform over the upper hemisphere, from round.u[g].
//!         let [u1, u2] = round.u[g];
//!         let (r, phi) = ((1.0 - u1 * u1).sqrt(), std::f32::consts::TAU * u2);
//!         round.directions[g] = [r * phi.cos(), r * phi.sin(), u1];
//!         round.in_support[g] = true;
//!     }
//!     set.decide(&mut round);
//!     for g in (0..gathers).filter(|&g| round.trace[g]) {
//!         let visible = round.directions[g][0] > 0.0; // the host's ray query
//!         round.contributions[g] = if visible { 2.0 * round.directions[g][2] } else { 0.0 };
//!         round.ratings[g] = if visible { 1.0 } else { 0.0 };
//!     }
//!     set.record(&round);
//! }
//! let estimates = set.finish();
//! assert!(estimates.iter().all(|e| e.value >= 0.0 && e.candidates >= 16));
//! ```

use crate::batch::{Batch, BatchConfig, BatchConfigError, Decision, Estimate, MapStart};
use crate::stats::Stats;
use crate::value::Value;

/// Where one gather of a set stands in the current round.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Slot {
    /// It has a candidate waiting for the host's direction.
    Drawn,
    /// Its candidate was accepted and waits for the traced ray's result.
    Tracing,
    /// Its candidate was rejected, or it has none this round.
    Idle,
    /// Its batch is complete.
    Done,
}

/// One round's data, one entry per gather, exchanged between the host and [`BatchSet`]:
/// the set fills `active`, `u`, `trace` and `weight`; the host fills `directions`,
/// `in_support`, `contributions` and `ratings`.
#[derive(Clone, Debug)]
pub struct Round<V> {
    /// Whether the gather has a candidate this round (false once its batch is complete).
    pub active: Vec<bool>,
    /// The candidate's two numbers for the host's proposal sampler.
    pub u: Vec<[f32; 2]>,
    /// The sampled direction (unit, in the frame the host keeps for this gather).
    pub directions: Vec<[f32; 3]>,
    /// False where the proposal gave a direction outside the BSDF's support.
    pub in_support: Vec<bool>,
    /// Whether to trace the candidate's ray.
    pub trace: Vec<bool>,
    /// 1 / acceptance of a traced candidate (applied by the set; for display).
    pub weight: Vec<f32>,
    /// A traced ray's plain Monte Carlo value `f · L · visibility / p`.
    pub contributions: Vec<V>,
    /// A traced ray's actual over unoccluded radiance, in [0, 1] (see [`crate::rating`]).
    pub ratings: Vec<f32>,
}

impl<V: Value> Round<V> {
    fn new(gathers: usize) -> Self {
        Round {
            active: vec![false; gathers],
            u: vec![[0.0; 2]; gathers],
            directions: vec![[0.0, 0.0, 1.0]; gathers],
            in_support: vec![true; gathers],
            trace: vec![false; gathers],
            weight: vec![0.0; gathers],
            contributions: vec![V::zero(); gathers],
            ratings: vec![1.0; gathers],
        }
    }
}

/// Gathers driven together in rounds; see the module documentation.
pub struct BatchSet<V: Value> {
    batches: Vec<Batch<V>>,
    slots: Vec<Slot>,
    estimates: Vec<Option<Estimate<V>>>,
}

impl<V: Value> BatchSet<V> {
    /// `gathers` batches with one configuration; each allocates its map once.
    pub fn new(config: BatchConfig, gathers: usize) -> Result<Self, BatchConfigError> {
        let batches = (0..gathers)
            .map(|_| Batch::new(config))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(BatchSet {
            batches,
            slots: vec![Slot::Done; gathers],
            estimates: vec![None; gathers],
        })
    }

    /// The number of gathers.
    pub fn len(&self) -> usize {
        self.batches.len()
    }

    /// Whether the set has no gathers.
    pub fn is_empty(&self) -> bool {
        self.batches.is_empty()
    }

    /// Whether every gather's batch is complete (after [`BatchSet::next_candidates`]
    /// returned 0), so that [`BatchSet::finish`] may be called.
    pub fn is_finished(&self) -> bool {
        self.slots.iter().all(|&slot| slot == Slot::Done)
    }

    /// Whether a traced candidate waits for [`BatchSet::record`].
    pub fn awaits_record(&self) -> bool {
        self.slots.contains(&Slot::Tracing)
    }

    /// Buffers for the rounds of this set (allocate once, reuse for every round).
    pub fn round_buffers(&self) -> Round<V> {
        Round::new(self.len())
    }

    /// Starts every gather: `n` rays each (`n >= 1`), gather `g` scrambled with `seeds[g]`,
    /// maps empty (AIS learns within each gather).
    ///
    /// # Panics
    /// If `n` is 0 or `seeds` does not hold one seed per gather.
    pub fn begin(&mut self, n: u32, seeds: &[u64]) {
        assert_eq!(seeds.len(), self.len(), "one seed per gather");
        for ((batch, slot), &seed) in self.batches.iter_mut().zip(&mut self.slots).zip(seeds) {
            batch.begin(n, seed, MapStart::Empty);
            *slot = Slot::Idle;
        }
        self.estimates.iter_mut().for_each(|e| *e = None);
    }

    /// Draws the next candidate of every unfinished gather into `round.u` (and
    /// `round.active`); returns how many gathers have one. A gather whose batch completes
    /// is finished here, and its estimate kept for [`BatchSet::finish`].
    ///
    /// # Panics
    /// If a traced candidate of the previous round was not recorded.
    pub fn next_candidates(&mut self, round: &mut Round<V>) -> usize {
        let mut active = 0;
        for g in 0..self.len() {
            assert_ne!(self.slots[g], Slot::Tracing, "record the traced rays first");
            round.trace[g] = false;
            round.active[g] = false;
            if self.slots[g] == Slot::Done {
                continue;
            }
            match self.batches[g].next_candidate() {
                Some(candidate) => {
                    round.u[g] = candidate.u;
                    round.active[g] = true;
                    self.slots[g] = Slot::Drawn;
                    active += 1;
                }
                None => {
                    self.estimates[g] = Some(self.batches[g].finish());
                    self.slots[g] = Slot::Done;
                }
            }
        }
        active
    }

    /// Decides the round's candidates from `round.directions` and `round.in_support`:
    /// sets `round.trace` and `round.weight`.
    pub fn decide(&mut self, round: &mut Round<V>) {
        self.decide_each(round, |_, affinity| affinity);
    }

    /// [`BatchSet::decide`] with the host's acceptance probability for each gather's
    /// candidate, `acceptance[g]` (see [`Batch::decide_with`]: it may depend on the
    /// candidate and the past, not on the candidate's own roulette number), e.g. from a
    /// learned [`crate::field::VisibilityField`] with AIS off in the batches.
    ///
    /// # Panics
    /// If `acceptance` does not hold one value per gather.
    pub fn decide_with(&mut self, round: &mut Round<V>, acceptance: &[f32]) {
        assert_eq!(acceptance.len(), self.len(), "one acceptance per gather");
        self.decide_each(round, |g, _| acceptance[g]);
    }

    fn decide_each(&mut self, round: &mut Round<V>, acceptance: impl Fn(usize, f32) -> f32) {
        for g in 0..self.len() {
            if self.slots[g] != Slot::Drawn {
                continue;
            }
            let decision =
                self.batches[g].decide_with(round.directions[g], round.in_support[g], |affinity| {
                    acceptance(g, affinity)
                });
            (round.trace[g], round.weight[g], self.slots[g]) = match decision {
                Decision::Trace { weight } => (true, weight, Slot::Tracing),
                Decision::Reject(_) => (false, 0.0, Slot::Idle),
            };
        }
    }

    /// Records the traced candidates' `round.contributions` and `round.ratings`.
    pub fn record(&mut self, round: &Round<V>) {
        for g in 0..self.len() {
            if self.slots[g] == Slot::Tracing {
                self.batches[g].record(round.contributions[g], round.ratings[g]);
                self.slots[g] = Slot::Idle;
            }
        }
    }

    /// Every gather's estimate, in order.
    ///
    /// # Panics
    /// If a gather is unfinished ([`BatchSet::next_candidates`] has not returned 0).
    pub fn finish(&mut self) -> Vec<Estimate<V>> {
        self.estimates
            .iter_mut()
            .map(|e| {
                e.take()
                    .expect("finish called before every gather completed")
            })
            .collect()
    }

    /// Counters summed over every gather and every round so far.
    pub fn stats(&self) -> Stats {
        let mut total = Stats::default();
        for batch in &self.batches {
            total.merge(batch.stats());
        }
        total
    }
}
