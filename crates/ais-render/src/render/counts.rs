//! Counters of the rays a render traced, by kind.

/// Rays traced, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// Closest-hit queries (camera rays).
    pub closest_hit: u64,
    /// Occlusion (any-hit) queries.
    pub occlusion: u64,
}

impl RayCounts {
    /// Adds another count.
    pub fn merge(&mut self, other: RayCounts) {
        self.closest_hit += other.closest_hit;
        self.occlusion += other.occlusion;
    }

    /// All rays.
    pub fn total(&self) -> u64 {
        self.closest_hit + self.occlusion
    }
}
