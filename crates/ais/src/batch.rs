//! The batch driver: candidate placement, acceptance, the unbiased n+1 stopping rule and the
//! estimator. The host traces rays; the batch decides which ones.
//!
//! ```
//! use ais::{Batch, BatchConfig, Decision, MapStart, rating};
//! use glam::Vec3;
//!
//! let mut batch: Batch<f32> = Batch::new(BatchConfig::default()).unwrap();
//! batch.begin(16, 7, MapStart::Empty);
//! while let Some(candidate) = batch.next_candidate() {
//!     // The host's proposal: here, uniform over the upper hemisphere (pdf 1/2π).
//!     let z = candidate.u[0];
//!     let phi = std::f32::consts::TAU * candidate.u[1];
//!     let r = (1.0 - z * z).sqrt();
//!     let direction = Vec3::new(r * phi.cos(), r * phi.sin(), z);
//!     match batch.decide(direction, true) {
//!         Decision::Reject(_) => continue,
//!         Decision::Trace { .. } => {
//!             let visible = direction.x > 0.0; // the host's ray query
//!             let radiance = if visible { 1.0 } else { 0.0 };
//!             let pdf = 1.0 / std::f32::consts::TAU;
//!             batch.record(radiance * z / std::f32::consts::PI / pdf, rating(radiance, 1.0));
//!         }
//!     }
//! }
//! let estimate = batch.finish();
//! // 16 candidates; roulette may have skipped some of them.
//! assert!(estimate.value > 0.0 && estimate.candidates == 16 && estimate.traced <= 16);
//! ```

use crate::affinity_map::{AffinityMap, Lookup, MapConfig, MapConfigError};
use crate::epochs::{EpochPlan, MAX_EPOCHS};
use crate::halton::ScrambledHalton;
use crate::rng::Pcg32;
use crate::stats::Stats;
use crate::value::Value;
use glam::Vec3;

mod plain;
pub use plain::PlainTally;

/// When the affinity map learns during a batch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Learning {
    /// The talk's rule: every traced ray updates the map at once. Not exactly unbiased, since
    /// acceptance probabilities change inside the batch (a positive bias of up to several
    /// standard errors with fast-learning maps). Study only: kept to measure that bias and to
    /// reproduce the talk.
    #[cfg(feature = "study")]
    Continuous,
    /// Frozen-map epochs: the map changes only between epochs, each run under a fixed map,
    /// so each epoch is exactly unbiased given the past. `epochs` is the number of
    /// doubling epochs, e.g. 4 gives `n/8, n/8, n/4, n/2`.
    Epochs {
        /// Number of epochs (1..=[`crate::MAX_EPOCHS`]).
        epochs: u32,
    },
    /// The map is used but never updated (a fixed map, e.g. learned elsewhere): exactly unbiased.
    Off,
}

/// Where candidates' random numbers come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Placement {
    /// The 3-D Halton sequence, scrambled per batch (the talk's choice).
    Halton,
    /// Independent uniform random numbers (the talk's "simple random" comparison).
    Random,
}

/// When a batch (or epoch) stops.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stopping {
    /// The talk's rule: draw until `n + 1` candidates are accepted, drop the last one
    /// untraced, and divide by the number of candidates before it. Unbiased for independent
    /// candidates and a fixed acceptance probability, i.e. with [`Placement::Random`]. With
    /// Halton placement the stopping time depends on correlated points and the estimate is
    /// biased low (about −4% at n = 8 even for a fixed map). Study only: kept to reproduce
    /// the talk and to measure that bias.
    #[cfg(feature = "study")]
    DropLast,
    /// Our rule for stratified placement: every epoch draws a fixed number of candidates
    /// `M_e = ⌈n_e / q⌉`, where `q` is the acceptance rate (traced per candidate) of the
    /// batch's earlier epochs (1 for the first), from its own independently scrambled
    /// sequence, traces every accepted one and divides by `M_e`. `M_e` depends only on the
    /// past, so each epoch is exactly unbiased given the past with any placement; the number
    /// of traced rays is `n` on average rather than exactly. Needs frozen maps within an
    /// epoch ([`Learning::Epochs`] or [`Learning::Off`]); without a map or with
    /// [`Learning::Off`] the batch is split into 4 doubling epochs just to adapt `M_e`.
    CandidateBudget,
    /// Every epoch draws exactly `n_e` candidates and traces only the accepted ones, each
    /// weighted by 1 / acceptance: AIS then saves rays (and time) per batch instead of
    /// spending more candidates to trace `n`. Exactly unbiased with any placement (the
    /// candidate count is fixed); needs frozen maps within an epoch, as
    /// [`Stopping::CandidateBudget`] does.
    FixedCandidates,
    /// Stop at the `n`-th accepted candidate. Biased toward high-affinity directions (the
    /// talk's "families until n boys"). Study only: kept to measure that bias.
    #[cfg(feature = "study")]
    AtN,
}

/// Everything that configures a batch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BatchConfig {
    /// The affinity map, or `None` for AIS off (every in-support candidate is traced).
    pub affinity: Option<MapConfig>,
    /// When the map learns.
    pub learning: Learning,
    /// Halton or random placement.
    pub placement: Placement,
    /// The stopping rule.
    pub stopping: Stopping,
    /// An epoch of `n_e` rays stops after at most `candidate_cap * n_e` candidates (at least 1).
    /// An epoch ended by the cap averages all its candidates; with a fixed map this is still
    /// exactly unbiased (the inverse-hypergeometric argument), and it is counted in
    /// [`Stats::cap_hits`].
    pub candidate_cap: u32,
}

impl Default for BatchConfig {
    /// The defaults chosen by measurement: a single-level map of height 4, 4 frozen-map
    /// epochs, Halton placement and the candidate-budget stopping rule.
    fn default() -> Self {
        BatchConfig {
            affinity: Some(MapConfig::default()),
            learning: Learning::Epochs { epochs: 4 },
            placement: Placement::Halton,
            stopping: Stopping::CandidateBudget,
            candidate_cap: 64,
        }
    }
}

impl BatchConfig {
    /// AIS off: a plain batch of `n` candidates, every one inside the support traced (the
    /// baseline every mode is compared with).
    pub fn off() -> Self {
        BatchConfig {
            affinity: None,
            learning: Learning::Off,
            stopping: Stopping::FixedCandidates,
            ..BatchConfig::default()
        }
    }

    /// AIS off with the talk's n+1 rule ([`Stopping::DropLast`]): `n` traced rays exactly.
    /// Study only: the baseline of the talk's comparisons and of the library's study.
    #[cfg(feature = "study")]
    pub fn talk_off() -> Self {
        BatchConfig {
            stopping: Stopping::DropLast,
            ..BatchConfig::off()
        }
    }
}

/// How a batch starts its map.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MapStart {
    /// An empty map (affinity 1 everywhere), as in the talk.
    Empty,
    /// The map as it is now: what the previous batch left, or what the host wrote with
    /// [`Batch::map_mut`] (warm start; with [`Learning::Off`], a fixed map).
    Current,
}

/// A candidate's random numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    /// Index of the candidate in the batch (also its Halton index).
    pub index: u32,
    /// The two numbers for the host's proposal sampler, in [0, 1)².
    pub u: [f32; 2],
}

/// Why a candidate was not traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RejectReason {
    /// Outside the BSDF's support: a known zero.
    OutsideSupport,
    /// Rejected by Russian roulette against the affinity map.
    Roulette,
    /// The (n_e + 1)-th accepted candidate of an epoch: dropped untraced.
    Dropped,
}

/// What the host should do with a candidate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Decision {
    /// Do not trace; go on to the next candidate.
    Reject(RejectReason),
    /// Trace the ray, then call [`Batch::record`]. `weight` = 1 / affinity is applied by the
    /// batch itself; it is given for hosts that want to display it.
    Trace {
        /// 1 / affinity.
        weight: f32,
    },
}

/// The result of a batch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate<V> {
    /// The unbiased estimate of the gathered integral.
    pub value: V,
    /// Candidates counted by the estimator.
    pub candidates: u32,
    /// Rays traced.
    pub traced: u32,
    /// Whether any epoch ended at the candidate cap.
    pub hit_cap: bool,
}

/// A traced candidate waiting for its [`Batch::record`].
#[derive(Clone, Copy, Debug)]
struct Pending {
    lookup: Option<Lookup>,
    affinity: f32,
    /// The epoch it was drawn in, whose sum its contribution joins.
    epoch: usize,
}

/// A recorded ray held back until its epoch ends.
#[derive(Clone, Copy, Debug)]
struct DeferredUpdate {
    lookup: Lookup,
    rating: f32,
    accepted_with: f32,
}

/// Why a [`BatchConfig`] was refused.
#[derive(Clone, Debug, PartialEq)]
pub enum BatchConfigError {
    /// The affinity map configuration is invalid.
    Map(MapConfigError),
    /// The candidate cap is 0.
    ZeroCandidateCap,
    /// The epoch count is 0 or above [`crate::MAX_EPOCHS`].
    BadEpochCount(u32),
    /// [`Stopping::CandidateBudget`] with continuous learning (a study option): the map would change
    /// inside an epoch of fixed size.
    BudgetNeedsFrozenMap,
}

impl std::fmt::Display for BatchConfigError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BatchConfigError::Map(e) => e.fmt(f),
            BatchConfigError::ZeroCandidateCap => write!(f, "candidate cap must be at least 1"),
            BatchConfigError::BudgetNeedsFrozenMap => write!(
                f,
                "the candidate-budget and fixed-candidates stopping rules need epochs or a fixed map, not continuous learning"
            ),
            BatchConfigError::BadEpochCount(n) => write!(
                f,
                "epoch count {n} is invalid: it must be 1..={}",
                crate::epochs::MAX_EPOCHS
            ),
        }
    }
}

impl std::error::Error for BatchConfigError {}

/// A reusable batch driver with its affinity map. One per thread; allocation-free per batch
/// once it has seen its largest `n`.
#[derive(Clone, Debug)]
pub struct Batch<V: Value> {
    config: BatchConfig,
    map: Option<AffinityMap>,
    halton: ScrambledHalton,
    rng: Pcg32,
    deferred: Vec<DeferredUpdate>,
    plan: EpochPlan,
    n: u32,
    seed: u64,
    epoch: usize,
    /// Candidates the current epoch may draw (the budget, or the cap).
    epoch_limit: u32,
    previous_epoch_accepted: u32,
    previous_epoch_candidates: u32,
    epoch_candidates: u32,
    epoch_accepted: u32,
    /// Each epoch's sum of weighted contributions, recorded in the order decided.
    epoch_sums: [V; MAX_EPOCHS],
    /// Each closed epoch's weight `n_e / n / candidates` (None: it drew no candidate).
    epoch_weights: [Option<f64>; MAX_EPOCHS],
    next_index: u32,
    /// Numbers placed ahead by [`Batch::upcoming`]; those from `ahead_taken` on belong to
    /// the next candidates, in order.
    ahead: Vec<[f32; 3]>,
    ahead_taken: usize,
    /// The current candidate's acceptance number u3.
    acceptance: f32,
    /// Candidates decided for tracing, in order; those from `recorded` on await their
    /// record (at most one unless the batch decides ahead).
    pending: Vec<Pending>,
    recorded: usize,
    done: bool,
    batch_stats: Stats,
    stats: Stats,
    /// Every traced ray of the current batch, recorded whatever the learning mode (see
    /// [`Batch::observe_rays`]).
    observations: Option<AffinityMap>,
    /// The numbers of a plain batch's candidates ([`Batch::begin_plain`]).
    plain_points: Vec<[f32; 2]>,
}

impl<V: Value> Batch<V> {
    /// A batch driver; allocates its map once.
    pub fn new(config: BatchConfig) -> Result<Self, BatchConfigError> {
        if config.candidate_cap == 0 {
            return Err(BatchConfigError::ZeroCandidateCap);
        }
        #[cfg(feature = "study")]
        if matches!(
            config.stopping,
            Stopping::CandidateBudget | Stopping::FixedCandidates
        ) && config.affinity.is_some()
            && config.learning == Learning::Continuous
        {
            return Err(BatchConfigError::BudgetNeedsFrozenMap);
        }
        if let Learning::Epochs { epochs } = config.learning {
            if epochs == 0 || epochs as usize > crate::epochs::MAX_EPOCHS {
                return Err(BatchConfigError::BadEpochCount(epochs));
            }
        }
        let map = config
            .affinity
            .map(AffinityMap::new)
            .transpose()
            .map_err(BatchConfigError::Map)?;
        Ok(Batch {
            config,
            map,
            halton: ScrambledHalton::unscrambled(),
            rng: Pcg32::new(0, 0),
            deferred: Vec::new(),
            plan: EpochPlan::single(1),
            n: 0,
            seed: 0,
            epoch: 0,
            epoch_limit: 0,
            previous_epoch_accepted: 0,
            previous_epoch_candidates: 0,
            epoch_candidates: 0,
            epoch_accepted: 0,
            epoch_sums: [V::zero(); MAX_EPOCHS],
            epoch_weights: [None; MAX_EPOCHS],
            next_index: 0,
            ahead: Vec::new(),
            ahead_taken: 0,
            acceptance: 0.0,
            pending: Vec::new(),
            recorded: 0,
            done: true,
            batch_stats: Stats::default(),
            stats: Stats::default(),
            observations: None,
            plain_points: Vec::new(),
        })
    }

    /// Also record every traced ray of each batch in an aggressive map of the same shape,
    /// whatever the learning mode (off by default). A host that shares maps between gather
    /// points reads it after [`Batch::finish`] with [`Batch::observations`] and blends such
    /// maps into the next batch's fixed map ([`AffinityMap::blend_from`]). Needs a map.
    pub fn observe_rays(&mut self, on: bool) {
        self.observations = match (on, self.config.affinity) {
            (true, Some(config)) => Some(
                AffinityMap::new(MapConfig {
                    mode: crate::Mode::Aggressive,
                    ..config
                })
                .expect("the map's own configuration is valid"),
            ),
            _ => None,
        };
    }

    /// What the current (or last) batch traced, when [`Batch::observe_rays`] is on.
    pub fn observations(&self) -> Option<&AffinityMap> {
        self.observations.as_ref()
    }

    /// Bytes held by its maps (the affinity map and the observation map, when present).
    pub fn memory_bytes(&self) -> usize {
        self.map.as_ref().map_or(0, AffinityMap::memory_bytes)
            + self
                .observations
                .as_ref()
                .map_or(0, AffinityMap::memory_bytes)
    }

    /// The configuration.
    pub fn config(&self) -> &BatchConfig {
        &self.config
    }

    /// The affinity map (`None` when AIS is off).
    pub fn map(&self) -> Option<&AffinityMap> {
        self.map.as_ref()
    }

    /// The affinity map, for a host that loads a learned map before [`MapStart::Current`].
    pub fn map_mut(&mut self) -> Option<&mut AffinityMap> {
        self.map.as_mut()
    }

    /// Whether the host may decide further candidates before recording those it traces:
    /// true when no decision can depend on an earlier one's outcome (no map, or a map that
    /// does not learn, under the candidate-budget or fixed-candidates rule). A host can then
    /// draw and decide a run of candidates, trace their rays together, and record them in
    /// the order decided; the estimate is the same, to the bit, as deciding and recording
    /// one at a time.
    pub fn decides_ahead(&self) -> bool {
        let outcomes_unused = self.map.is_none() || self.config.learning == Learning::Off;
        let stopping_fixed = matches!(
            self.config.stopping,
            Stopping::CandidateBudget | Stopping::FixedCandidates
        );
        outcomes_unused && stopping_fixed
    }

    /// Candidates decided for tracing whose [`Batch::record`] has not come yet.
    pub fn awaiting_record(&self) -> usize {
        self.pending.len() - self.recorded
    }

    /// Counts over every batch finished so far.
    pub fn stats(&self) -> &Stats {
        &self.stats
    }

    /// Counts of the current (or last) batch.
    pub fn batch_stats(&self) -> &Stats {
        &self.batch_stats
    }

    /// Starts a batch of `n` traced rays (`n >= 1`) with scrambling seed `seed`.
    ///
    /// # Panics
    /// If `n` is 0.
    pub fn begin(&mut self, n: u32, seed: u64, start: MapStart) {
        assert!(n >= 1, "a batch needs at least one ray");
        if start == MapStart::Empty {
            if let Some(map) = self.map.as_mut() {
                map.clear();
            }
        }
        if let Some(observations) = self.observations.as_mut() {
            observations.clear();
        }
        self.plan = match (self.config.learning, self.config.stopping) {
            (Learning::Epochs { epochs }, _) if self.map.is_some() => {
                EpochPlan::doubling(n, epochs)
            }
            (_, Stopping::CandidateBudget) => EpochPlan::doubling(n, 4),
            _ => EpochPlan::single(n),
        };
        if self.deferred.capacity() < n as usize {
            self.deferred.reserve(n as usize);
        }
        self.deferred.clear();
        self.n = n;
        self.seed = seed;
        self.epoch = 0;
        self.previous_epoch_accepted = 0;
        self.previous_epoch_candidates = 0;
        self.epoch_sums = [V::zero(); MAX_EPOCHS];
        self.epoch_weights = [None; MAX_EPOCHS];
        self.pending.clear();
        self.recorded = 0;
        self.done = false;
        self.batch_stats = Stats {
            batches: 1,
            ..Stats::default()
        };
        self.start_epoch();
    }

    /// Resets the epoch's counters, gives it an independently scrambled sequence, and sets
    /// how many candidates it may draw.
    fn start_epoch(&mut self) {
        self.epoch_candidates = 0;
        self.epoch_accepted = 0;
        self.next_index = 0;
        self.ahead.clear();
        self.ahead_taken = 0;
        let size = self.plan.sizes()[self.epoch];
        let cap = self.config.candidate_cap.saturating_mul(size);
        self.epoch_limit = match self.config.stopping {
            Stopping::CandidateBudget => {
                // The previous epoch's acceptance rate (with one accepted pseudo-candidate so that
                // a tiny epoch cannot give 0): it depends only on the past, so the budget is
                // fixed given the past, and it reflects the most recent map.
                let rate = (self.previous_epoch_accepted + 1) as f64
                    / (self.previous_epoch_candidates + 1) as f64;
                ((size as f64 / rate).ceil() as u32).clamp(size, cap)
            }
            Stopping::FixedCandidates => size,
            #[cfg(feature = "study")]
            Stopping::DropLast | Stopping::AtN => cap,
        };
        let epoch_seed = epoch_seed(self.seed, self.epoch);
        match self.config.placement {
            Placement::Halton => self.halton.rescramble(epoch_seed, self.epoch_limit),
            Placement::Random => self.rng = random_placement(epoch_seed),
        }
    }

    /// The next candidate, with numbers from the batch's [`Placement`], or `None` when the
    /// batch is complete.
    ///
    /// # Panics
    /// If a candidate accepted for tracing is not recorded yet, unless the batch
    /// [decides ahead](Batch::decides_ahead).
    pub fn next_candidate(&mut self) -> Option<Candidate> {
        self.advance()?;
        let index = self.next_index - 1;
        let [u1, u2, u3] = match self.ahead.get(self.ahead_taken) {
            Some(&point) => {
                self.ahead_taken += 1;
                point
            }
            None => self.place(index),
        };
        self.acceptance = u3;
        Some(Candidate { index, u: [u1, u2] })
    }

    /// The next candidate with the host's own numbers `u` ∈ [0, 1)³ instead of the batch's
    /// placement (for a host with its own sampler): `u[0]` and `u[1]` come back in the
    /// candidate for the host's proposal, `u[2]` decides the roulette. `None` when the batch
    /// is complete. Exactly unbiased when the host's numbers are uniform and independent of
    /// the map, as the built-in placements are.
    ///
    /// # Panics
    /// If a candidate accepted for tracing is not recorded yet, unless the batch
    /// [decides ahead](Batch::decides_ahead).
    pub fn next_candidate_with(&mut self, u: [f32; 3]) -> Option<Candidate> {
        self.advance()?;
        // Numbers placed ahead are not this candidate's: a later one must not take them.
        self.ahead.clear();
        self.ahead_taken = 0;
        self.acceptance = u[2];
        Some(Candidate {
            index: self.next_index - 1,
            u: [u[0], u[1]],
        })
    }

    /// The numbers of the next candidates, up to `points.len()` of them, without taking
    /// them: each `[u1, u2, u3]` as [`Batch::next_candidate`] would place it; the next calls
    /// of `next_candidate` take them, in order. Returns how many were written: 0 when the
    /// batch is complete, and none beyond the current epoch (where the next one starts
    /// depends on the decisions before it). A host that [decides
    /// ahead](Batch::decides_ahead) can so draw a run of candidates before deciding any, and
    /// their draws overlap instead of waiting on one another.
    ///
    /// # Panics
    /// If a candidate taken is not decided yet.
    pub fn upcoming(&mut self, points: &mut [[f32; 3]]) -> usize {
        assert!(
            self.epoch_candidates == self.next_index,
            "Batch::upcoming called before the last candidate was decided"
        );
        self.close_spent_epoch();
        if self.done {
            return 0;
        }
        if self.ahead_taken == self.ahead.len() {
            self.ahead.clear();
            self.ahead_taken = 0;
        }
        let count = ((self.epoch_limit - self.epoch_candidates) as usize).min(points.len());
        let pending = self.ahead.len() - self.ahead_taken;
        for k in pending..count {
            let point = self.place(self.next_index + k as u32);
            self.ahead.push(point);
        }
        points[..count].copy_from_slice(&self.ahead[self.ahead_taken..][..count]);
        count
    }

    /// The numbers of candidate `index` of the epoch (for random placement, the next three
    /// of the epoch's stream).
    fn place(&mut self, index: u32) -> [f32; 3] {
        match self.config.placement {
            Placement::Halton => self.halton.point(index),
            Placement::Random => random_point(&mut self.rng),
        }
    }

    /// Moves to the next candidate (closing an epoch whose candidates are spent); `None`
    /// when the batch is complete.
    fn advance(&mut self) -> Option<()> {
        assert!(
            self.awaiting_record() == 0 || self.decides_ahead(),
            "Batch::record must follow a Decision::Trace before the next candidate"
        );
        self.close_spent_epoch();
        if self.done {
            return None;
        }
        self.next_index += 1;
        Some(())
    }

    /// Closes the current epoch if its candidates are spent.
    fn close_spent_epoch(&mut self) {
        if !self.done && self.epoch_candidates >= self.epoch_limit {
            if !matches!(
                self.config.stopping,
                Stopping::CandidateBudget | Stopping::FixedCandidates
            ) {
                self.batch_stats.cap_hits += 1;
            }
            self.close_epoch();
        }
    }

    /// Decides whether the current candidate, in `direction` (unit, in the map's frame; any
    /// `[f32; 3]`-like vector, such as a glam `Vec3` of any version), is traced. `in_support`
    /// is false for directions outside the BSDF's support.
    pub fn decide(&mut self, direction: impl Into<[f32; 3]>, in_support: bool) -> Decision {
        self.decide_with(direction, in_support, |affinity| affinity)
    }

    /// [`Batch::decide`] with the host choosing the acceptance probability from the map's
    /// affinity: `acceptance(affinity)` must lie in (0, 1] and may depend on the candidate
    /// itself (its direction, its unoccluded contribution) and on what happened before it,
    /// but not on its own acceptance. The traced ray's weight is `1 / acceptance`, so the
    /// estimate stays exactly unbiased (value-aware acceptance: never skip a bright light).
    /// Values above 1 count as 1; 0 or NaN rejects the candidate.
    pub fn decide_with(
        &mut self,
        direction: impl Into<[f32; 3]>,
        in_support: bool,
        acceptance: impl FnOnce(f32) -> f32,
    ) -> Decision {
        debug_assert!(!self.done, "decide called on a finished batch");
        self.epoch_candidates += 1;
        self.batch_stats.candidates += 1;
        if !in_support {
            self.batch_stats.rejected_outside_support += 1;
            return Decision::Reject(RejectReason::OutsideSupport);
        }
        let direction = Vec3::from(direction.into());
        let lookup = self.map.as_ref().map(|map| map.lookup(direction));
        let chosen = acceptance(lookup.map_or(1.0, |l| l.affinity));
        // An acceptance of 0 (or NaN) always rejects, as an affinity of 0 would.
        let affinity = if chosen.is_nan() {
            0.0
        } else {
            chosen.clamp(0.0, 1.0)
        };
        if self.acceptance >= affinity {
            self.batch_stats.rejected_roulette += 1;
            return Decision::Reject(RejectReason::Roulette);
        }
        #[cfg(feature = "study")]
        if self.config.stopping == Stopping::DropLast
            && self.epoch_accepted == self.plan.sizes()[self.epoch]
        {
            // The (n_e + 1)-th acceptance: not traced and not counted.
            self.epoch_candidates -= 1;
            self.batch_stats.candidates -= 1;
            self.batch_stats.dropped += 1;
            self.close_epoch();
            return Decision::Reject(RejectReason::Dropped);
        }
        self.epoch_accepted += 1;
        self.pending.push(Pending {
            lookup,
            affinity,
            epoch: self.epoch,
        });
        Decision::Trace {
            weight: 1.0 / affinity,
        }
    }

    /// Records what the traced ray of the current candidate saw.
    ///
    /// `contribution` is the plain Monte Carlo value `f(w) · visibility / p(w)` (the batch
    /// applies the 1/affinity weight itself); `rating` ∈ [0, 1] is actual over unoccluded
    /// radiance (see [`rating`]).
    ///
    /// Candidates decided ahead are recorded in the order they were decided.
    ///
    /// # Panics
    /// If no candidate accepted for tracing awaits its record.
    pub fn record(&mut self, contribution: V, rating: f32) {
        let pending = *self
            .pending
            .get(self.recorded)
            .expect("Batch::record called without a Decision::Trace");
        self.recorded += 1;
        self.batch_stats.traced += 1;
        let sum = &mut self.epoch_sums[pending.epoch];
        *sum = sum.add(contribution.scale(1.0 / pending.affinity as f64));
        if let (Some(observations), Some(lookup)) = (self.observations.as_mut(), pending.lookup) {
            observations.record(&lookup, rating.clamp(0.0, 1.0), pending.affinity);
        }
        if let (Some(_map), Some(lookup)) = (self.map.as_mut(), pending.lookup) {
            let rating = rating.clamp(0.0, 1.0);
            match self.config.learning {
                #[cfg(feature = "study")]
                Learning::Continuous => {
                    let outcome = _map.record(&lookup, rating, pending.affinity);
                    self.batch_stats.resets += outcome.resets as u64;
                }
                Learning::Epochs { .. } => self.deferred.push(DeferredUpdate {
                    lookup,
                    rating,
                    accepted_with: pending.affinity,
                }),
                Learning::Off => {}
            }
        }
        #[cfg(feature = "study")]
        if self.config.stopping == Stopping::AtN
            && self.epoch_accepted == self.plan.sizes()[self.epoch]
        {
            self.close_epoch();
        }
    }

    /// Ends the current epoch: adds its estimate with weight `n_e / n`, applies deferred map
    /// updates, and moves on (or completes the batch).
    fn close_epoch(&mut self) {
        let size = self.plan.sizes()[self.epoch];
        if self.epoch_candidates > 0 {
            let weight = size as f64 / self.n as f64 / self.epoch_candidates as f64;
            self.epoch_weights[self.epoch] = Some(weight);
        }
        if let Some(map) = self.map.as_mut() {
            for update in self.deferred.drain(..) {
                let outcome = map.record(&update.lookup, update.rating, update.accepted_with);
                self.batch_stats.resets += outcome.resets as u64;
            }
        }
        self.previous_epoch_accepted = self.epoch_accepted;
        self.previous_epoch_candidates = self.epoch_candidates;
        self.epoch += 1;
        if self.epoch == self.plan.sizes().len() {
            self.done = true;
        } else {
            self.start_epoch();
        }
    }

    /// The estimate of the finished batch; adds its counts to [`Batch::stats`].
    ///
    /// # Panics
    /// If the batch is not complete ([`Batch::next_candidate`] has not returned `None`).
    pub fn finish(&mut self) -> Estimate<V> {
        assert!(
            self.done && self.awaiting_record() == 0,
            "Batch::finish called before next_candidate returned None and every traced candidate was recorded"
        );
        self.stats.merge(&self.batch_stats);
        let value = (self.epoch_sums.iter())
            .zip(&self.epoch_weights)
            .filter_map(|(sum, weight)| Some(sum.scale((*weight)?)))
            .fold(V::zero(), V::add);
        Estimate {
            value,
            candidates: self.batch_stats.candidates as u32,
            traced: self.batch_stats.traced as u32,
            hit_cap: self.batch_stats.cap_hits > 0,
        }
    }
}

/// The scrambling seed of a batch's epoch `epoch`: each epoch's numbers are independent.
fn epoch_seed(batch_seed: u64, epoch: usize) -> u64 {
    crate::rng::mix64(batch_seed ^ (epoch as u64).wrapping_mul(0x9E37_79B9))
}

/// The generator of an epoch's random placement.
fn random_placement(epoch_seed: u64) -> Pcg32 {
    Pcg32::new(epoch_seed, 0x5241_4e44) // stream "RAND"
}

/// A candidate's three numbers under random placement.
fn random_point(rng: &mut Pcg32) -> [f32; 3] {
    [rng.next_f32(), rng.next_f32(), rng.next_f32()]
}

/// The rating of a traced ray: actual over unoccluded radiance (luminance), clamped to
/// [0, 1]; 1 when the unoccluded radiance is 0, since such a ray says nothing about occlusion.
#[inline]
pub fn rating(actual: f32, unoccluded: f32) -> f32 {
    if unoccluded > 0.0 {
        (actual / unoccluded).clamp(0.0, 1.0)
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::affinity_map::Mode;

    /// Drives a batch whose host alternates in- and out-of-support candidates and sees every
    /// traced ray occluded when `x < 0`.
    fn drive(batch: &mut Batch<f32>, n: u32, seed: u64, start: MapStart) -> Estimate<f32> {
        batch.begin(n, seed, start);
        while let Some(candidate) = batch.next_candidate() {
            let phi = std::f32::consts::TAU * candidate.u[1];
            let direction = Vec3::new(phi.cos(), phi.sin(), 0.2).normalize();
            let in_support = candidate.u[0] < 0.5;
            if let Decision::Trace { .. } = batch.decide(direction, in_support) {
                let visible = direction.x >= 0.0;
                batch.record(
                    if visible { 1.0 } else { 0.0 },
                    rating(visible as u8 as f32, 1.0),
                );
            }
        }
        batch.finish()
    }

    #[test]
    fn outside_support_candidates_count_but_are_never_traced() {
        let mut batch: Batch<f32> = Batch::new(BatchConfig {
            placement: Placement::Random,
            ..BatchConfig::off()
        })
        .unwrap();
        let estimate = drive(&mut batch, 64, 3, MapStart::Empty);
        let stats = batch.stats();
        assert_eq!(estimate.candidates, 64);
        assert_eq!(stats.dropped, 0);
        assert_eq!(stats.rejected_roulette, 0);
        assert_eq!(
            stats.candidates,
            stats.traced + stats.rejected_outside_support
        );
        assert!(stats.rejected_outside_support > 20);
    }

    #[test]
    fn a_fixed_map_is_never_changed_and_a_warm_map_keeps_learning() {
        let map = MapConfig {
            height: 8,
            mode: Mode::Aggressive,
            ..MapConfig::default()
        };
        let mut fixed: Batch<f32> = Batch::new(BatchConfig {
            affinity: Some(map),
            learning: Learning::Off,
            ..BatchConfig::default()
        })
        .unwrap();
        let before = fixed.map().unwrap().clone();
        drive(&mut fixed, 32, 1, MapStart::Current);
        let after = fixed.map().unwrap();
        let layout = after.level_layout(0);
        for index in 0..layout.texel_count() {
            let texel = layout.texel_of_index(index);
            assert_eq!(
                before.texel_samples(0, texel),
                after.texel_samples(0, texel)
            );
        }

        let mut warm: Batch<f32> = Batch::new(BatchConfig {
            affinity: Some(map),
            learning: Learning::Continuous,
            stopping: Stopping::DropLast,
            ..BatchConfig::default()
        })
        .unwrap();
        let samples = |b: &Batch<f32>| {
            let m = b.map().unwrap();
            let layout = m.level_layout(0);
            (0..layout.texel_count())
                .map(|i| m.texel_samples(0, layout.texel_of_index(i)))
                .sum::<u32>()
        };
        drive(&mut warm, 32, 1, MapStart::Empty);
        let first = samples(&warm);
        drive(&mut warm, 32, 2, MapStart::Current);
        assert!(
            samples(&warm) > first,
            "a warm start keeps what was learned"
        );
        drive(&mut warm, 32, 3, MapStart::Empty);
        assert!(samples(&warm) <= 32, "an empty start forgets");
    }

    #[test]
    fn epochs_defer_updates_to_epoch_ends() {
        let mut batch: Batch<f32> = Batch::new(BatchConfig {
            affinity: Some(MapConfig::default()),
            learning: Learning::Epochs { epochs: 4 },
            stopping: Stopping::DropLast,
            placement: Placement::Random,
            ..BatchConfig::default()
        })
        .unwrap();
        let estimate = drive(&mut batch, 64, 9, MapStart::Empty);
        assert_eq!(estimate.traced, 64);
        // One dropped candidate per epoch.
        assert_eq!(batch.stats().dropped, 4);
    }

    #[test]
    fn invalid_configurations_are_refused() {
        let zero_cap = BatchConfig {
            candidate_cap: 0,
            ..BatchConfig::default()
        };
        assert_eq!(
            Batch::<f32>::new(zero_cap).unwrap_err(),
            BatchConfigError::ZeroCandidateCap
        );
        let budget_continuous = BatchConfig {
            learning: Learning::Continuous,
            ..BatchConfig::default()
        };
        assert_eq!(
            Batch::<f32>::new(budget_continuous).unwrap_err(),
            BatchConfigError::BudgetNeedsFrozenMap
        );
        let many_epochs = BatchConfig {
            learning: Learning::Epochs { epochs: 99 },
            ..BatchConfig::default()
        };
        assert_eq!(
            Batch::<f32>::new(many_epochs).unwrap_err(),
            BatchConfigError::BadEpochCount(99)
        );
    }

    /// The test scene's candidate: a direction, whether it is in the support, and what
    /// its traced ray brings.
    fn test_candidate(u: [f32; 2]) -> (Vec3, bool, f32) {
        let phi = std::f32::consts::TAU * u[1];
        let direction = Vec3::new(phi.cos(), phi.sin(), 0.2).normalize();
        let value = if direction.x >= 0.0 { 1.0 + u[0] } else { 0.0 };
        (direction, u[0] < 0.8, value)
    }

    /// The host's acceptance in these tests: low toward x < 0.
    fn test_acceptance(direction: Vec3, affinity: f32) -> f32 {
        affinity * if direction.x < 0.0 { 0.3 } else { 1.0 }
    }

    /// Decides `ahead` candidates before recording them, in order.
    fn drive_ahead(batch: &mut Batch<f32>, n: u32, seed: u64, ahead: usize) -> Estimate<f32> {
        batch.begin(n, seed, MapStart::Current);
        let mut values = Vec::new();
        let mut complete = false;
        while !complete {
            values.clear();
            while values.len() < ahead {
                let Some(candidate) = batch.next_candidate() else {
                    complete = true;
                    break;
                };
                let (direction, in_support, value) = test_candidate(candidate.u);
                let decision =
                    batch.decide_with(direction, in_support, |a| test_acceptance(direction, a));
                if let Decision::Trace { .. } = decision {
                    values.push(value);
                }
            }
            assert_eq!(batch.awaiting_record(), values.len());
            for &value in &values {
                batch.record(value, (value > 0.0) as u8 as f32);
            }
        }
        batch.finish()
    }

    /// A batch whose map learned from one gather of 256 candidates (a map to fix).
    fn learned_batch() -> Batch<f32> {
        let mut learner: Batch<f32> = Batch::new(BatchConfig {
            affinity: Some(MapConfig::default()),
            ..BatchConfig::default()
        })
        .unwrap();
        drive(&mut learner, 256, 5, MapStart::Empty);
        learner
    }

    #[test]
    fn deciding_ahead_gives_the_same_estimate_to_the_bit() {
        let learner = learned_batch();
        let mut fixed_map: Batch<f32> = Batch::new(BatchConfig {
            affinity: Some(MapConfig::default()),
            learning: Learning::Off,
            ..BatchConfig::default()
        })
        .unwrap();
        fixed_map
            .map_mut()
            .unwrap()
            .copy_from(learner.map().unwrap());
        let budget_without_map = BatchConfig {
            affinity: None,
            learning: Learning::Off,
            ..BatchConfig::default()
        };
        let batches = [
            Batch::new(BatchConfig::off()).unwrap(),
            Batch::new(budget_without_map).unwrap(),
            fixed_map,
        ];
        for (which, template) in batches.into_iter().enumerate() {
            assert!(template.decides_ahead());
            for (n, seed) in [(16, 1), (37, 2), (128, 3)] {
                let mut one_by_one = template.clone();
                let expected = drive_ahead(&mut one_by_one, n, seed, 1);
                for ahead in [4, 16, 1000] {
                    let mut batch = template.clone();
                    let estimate = drive_ahead(&mut batch, n, seed, ahead);
                    assert_eq!(
                        estimate.value.to_bits(),
                        expected.value.to_bits(),
                        "batch {which}, n {n}, {ahead} ahead"
                    );
                    assert_eq!(estimate.candidates, expected.candidates);
                    assert_eq!(estimate.traced, expected.traced);
                }
            }
        }
    }

    /// Every candidate's numbers and decision, the candidates drawn `run` at a time through
    /// [`Batch::upcoming`] (0: one at a time, without it).
    fn placed_and_decided(batch: &mut Batch<f32>, n: u32, seed: u64, run: usize) -> Vec<u32> {
        batch.begin(n, seed, MapStart::Current);
        let mut seen = Vec::new();
        let mut points = vec![[0.0; 3]; run.max(1)];
        loop {
            let count = if run > 0 {
                batch.upcoming(&mut points)
            } else {
                1
            };
            for point in &points[..count.max(1)] {
                let Some(candidate) = batch.next_candidate() else {
                    assert!(
                        run == 0 || count == 0,
                        "upcoming promised a candidate that never came"
                    );
                    return seen;
                };
                if run > 0 {
                    assert_eq!(candidate.u, [point[0], point[1]]);
                }
                let (direction, in_support, value) = test_candidate(candidate.u);
                let decision = batch.decide(direction, in_support);
                if let Decision::Trace { .. } = decision {
                    batch.record(value, (value > 0.0) as u8 as f32);
                }
                let traced = matches!(decision, Decision::Trace { .. });
                seen.extend(candidate.u.map(f32::to_bits));
                seen.push(traced as u32);
            }
        }
    }

    #[test]
    fn upcoming_numbers_are_those_the_candidates_get() {
        let learner = learned_batch();
        for placement in [Placement::Halton, Placement::Random] {
            // One epoch; four epochs of a candidate budget; and those with roulette on a
            // fixed map, where an epoch's end depends on the decisions before it.
            let single = BatchConfig {
                placement,
                ..BatchConfig::off()
            };
            let budget = BatchConfig {
                affinity: None,
                learning: Learning::Off,
                placement,
                ..BatchConfig::default()
            };
            let mut fixed_map: Batch<f32> = Batch::new(BatchConfig {
                affinity: Some(MapConfig::default()),
                ..budget
            })
            .unwrap();
            let learned = learner.map().unwrap();
            fixed_map.map_mut().unwrap().copy_from(learned);
            let templates = [
                Batch::new(single).unwrap(),
                Batch::new(budget).unwrap(),
                fixed_map,
            ];
            for (which, template) in templates.iter().enumerate() {
                for (n, seed) in [(16, 1), (37, 2)] {
                    let expected = placed_and_decided(&mut template.clone(), n, seed, 0);
                    assert!(expected.len() >= 3 * n as usize);
                    for run in [1, 3, 16, 1000] {
                        let seen = placed_and_decided(&mut template.clone(), n, seed, run);
                        assert_eq!(seen, expected, "{placement:?}, batch {which}, n {n}, {run}");
                    }
                }
            }
        }
    }

    #[test]
    #[should_panic(expected = "Batch::record must follow")]
    fn a_learning_batch_does_not_decide_ahead() {
        let mut batch: Batch<f32> = Batch::new(BatchConfig {
            affinity: Some(MapConfig::default()),
            ..BatchConfig::default()
        })
        .unwrap();
        assert!(!batch.decides_ahead());
        batch.begin(8, 0, MapStart::Empty);
        while let Some(candidate) = batch.next_candidate() {
            let (direction, _, _) = test_candidate(candidate.u);
            batch.decide(direction, true);
        }
    }

    #[test]
    #[should_panic(expected = "without a Decision::Trace")]
    fn record_without_trace_panics() {
        let mut batch: Batch<f32> = Batch::new(BatchConfig::default()).unwrap();
        batch.begin(4, 0, MapStart::Empty);
        batch.next_candidate();
        batch.record(1.0, 1.0);
    }

    #[test]
    fn rating_is_clamped_and_uninformative_rays_rate_one() {
        assert_eq!(rating(0.5, 1.0), 0.5);
        assert_eq!(rating(3.0, 1.0), 1.0);
        assert_eq!(rating(0.0, 0.0), 1.0);
        assert_eq!(rating(-1.0, 2.0), 0.0);
    }
}
