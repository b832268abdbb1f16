//! Counters a batch keeps, so that hosts and reports can show where the candidates went.

/// Counts over one or many batches. Merge per-thread counts with [`Stats::merge`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Batches finished.
    pub batches: u64,
    /// Candidates counted by the estimators (every sample of the estimator, traced or not).
    pub candidates: u64,
    /// Candidates accepted and traced.
    pub traced: u64,
    /// Candidates rejected unconditionally because they lie outside the BSDF's support.
    pub rejected_outside_support: u64,
    /// Candidates rejected by Russian roulette against the affinity map.
    pub rejected_roulette: u64,
    /// Accepted candidates dropped untraced by the n+1 stopping rule (one per epoch).
    pub dropped: u64,
    /// Epochs ended by the candidate cap rather than by the stopping rule.
    pub cap_hits: u64,
    /// Conservative-mode resets (texel plus border forced to affinity 1).
    pub resets: u64,
}

impl Stats {
    /// Adds another set of counts to this one.
    pub fn merge(&mut self, other: &Stats) {
        self.batches += other.batches;
        self.candidates += other.candidates;
        self.traced += other.traced;
        self.rejected_outside_support += other.rejected_outside_support;
        self.rejected_roulette += other.rejected_roulette;
        self.dropped += other.dropped;
        self.cap_hits += other.cap_hits;
        self.resets += other.resets;
    }

    /// Candidates rejected for any reason (outside support or roulette; dropped not included).
    pub fn rejected(&self) -> u64 {
        self.rejected_outside_support + self.rejected_roulette
    }

    /// Mean traced rays per batch (0 when no batch finished).
    pub fn traced_per_batch(&self) -> f64 {
        if self.batches == 0 {
            0.0
        } else {
            self.traced as f64 / self.batches as f64
        }
    }
}
