//! The affinity map: a (multi-resolution) spherical texture of how likely a ray in each
//! direction is to be worth tracing.
//!
//! Every texel holds the talk's three channels, `[affinity sum s, weight sum ω, reset
//! counter]`, plus a count of recorded rays (used by a study-only level rule). A
//! fresh texel has `[s, ω] = [1, 1]`, i.e. affinity 1. With `h` the height of the texel's
//! level, the affinity is
//!
//! ```text
//! a_min = 1 / (tol · h²)            (tol = ∞ gives a_min = 0)
//! a     = a_min + (s / ω) · (1 − a_min)
//! ```
//!
//! and recording a ray of rating `r` that was accepted with affinity `a_used` adds
//! `w = 1 / a_used` as `s += r·w, ω += w`.
//!
//! Clearing the map is O(1): every texel carries the generation in which it was last
//! written, and a texel from an older generation reads as fresh. A batch therefore starts
//! with an empty map without touching memory.

use crate::mapping::{LatLong, SphericalCoordinates};

/// Most levels a multi-resolution map may have.
pub const MAX_LEVELS: usize = 8;

/// How the map reacts to increases in affinity.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// The plain update rule.
    Aggressive,
    /// Whenever an update increases a texel's affinity, that texel and its 1-texel border are
    /// forced back to affinity 1 (the talk's shadow-edge solution); the reset is counted.
    Conservative,
}

/// How the levels of a multi-resolution map are combined at lookup.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LevelRule {
    /// One level at the configured height.
    Single,
    /// The talk's literal reading: `count` levels of heights `h, h/2, h/4, …`; every level is
    /// updated, and the lookup uses the finest level whose affinity is below 1, else 1.
    /// Study only: it raised the bias of the n+1 rule and lost to a single level.
    #[cfg(feature = "study")]
    FinestBelowOne {
        /// Number of levels (at most [`MAX_LEVELS`], and no coarser than height 1).
        count: u32,
    },
    /// `count` levels as above; the lookup uses the finest level whose texel has recorded at
    /// least `min_samples` rays, else 1. Coarse levels answer early, fine levels take over
    /// once they have evidence. Study only: it learned fast and raised the bias most.
    #[cfg(feature = "study")]
    FinestWithSamples {
        /// Number of levels (at most [`MAX_LEVELS`], and no coarser than height 1).
        count: u32,
        /// Rays a texel must have recorded before its level is trusted.
        min_samples: u32,
    },
}

impl LevelRule {
    /// Number of levels the rule asks for.
    pub fn level_count(self) -> u32 {
        match self {
            LevelRule::Single => 1,
            #[cfg(feature = "study")]
            LevelRule::FinestBelowOne { count } | LevelRule::FinestWithSamples { count, .. } => {
                count
            }
        }
    }
}

/// The shape and update rule of an affinity map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapConfig {
    /// Height (rows) of the finest level; its width is twice this.
    pub height: u32,
    /// Tolerance: `a_min = 1 / (tol · h²)`. `f32::INFINITY` gives `a_min = 0`.
    pub tol: f32,
    /// Aggressive or conservative updates.
    pub mode: Mode,
    /// Single level or one of the multi-level rules.
    pub levels: LevelRule,
}

impl Default for MapConfig {
    /// The defaults chosen by measurement: one level of height 4, tol 1, aggressive.
    fn default() -> Self {
        MapConfig {
            height: 4,
            tol: 1.0,
            mode: Mode::Aggressive,
            levels: LevelRule::Single,
        }
    }
}

/// One texel's channels.
#[derive(Clone, Copy, Debug, PartialEq)]
struct TexelState {
    sum: f32,
    weight: f32,
    resets: u32,
    samples: u32,
    generation: u32,
}

impl TexelState {
    const FRESH: TexelState = TexelState {
        sum: 1.0,
        weight: 1.0,
        resets: 0,
        samples: 0,
        generation: 0,
    };
}

/// One resolution of the map.
#[derive(Clone, Copy, Debug)]
struct Level {
    layout: LatLong,
    first_texel: usize,
    min_affinity: f32,
}

/// Where a direction falls in every level of a map, and the affinity the map gives it.
///
/// Computed once per candidate and reused when the traced ray is recorded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lookup {
    /// The affinity used for acceptance, in (0, 1].
    pub affinity: f32,
    texels: [u32; MAX_LEVELS],
}

/// The result of recording one ray.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RecordOutcome {
    /// Conservative resets triggered by this ray (one per level whose affinity increased).
    pub resets: u32,
}

/// A multi-resolution lat-long affinity map with O(1) clearing.
#[derive(Clone, Debug)]
pub struct AffinityMap {
    config: MapConfig,
    levels: [Level; MAX_LEVELS],
    level_count: usize,
    texels: Vec<TexelState>,
    generation: u32,
}

/// Why a [`MapConfig`] was refused.
#[derive(Clone, Debug, PartialEq)]
pub enum MapConfigError {
    /// The height is zero.
    ZeroHeight,
    /// The level count is zero, above [`MAX_LEVELS`], or would make a level coarser than one row.
    BadLevelCount(u32),
    /// `tol` is not positive (it may be infinite).
    BadTolerance(f32),
}

impl std::fmt::Display for MapConfigError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MapConfigError::ZeroHeight => write!(f, "affinity map height must be at least 1"),
            MapConfigError::BadLevelCount(n) => write!(
                f,
                "affinity map level count {n} is invalid: it must be 1..={MAX_LEVELS} and halving the height that often must leave at least one row"
            ),
            MapConfigError::BadTolerance(t) => {
                write!(f, "affinity map tol must be positive or infinite, got {t}")
            }
        }
    }
}

impl std::error::Error for MapConfigError {}

impl AffinityMap {
    /// Allocates a map (the only allocation it ever makes).
    pub fn new(config: MapConfig) -> Result<Self, MapConfigError> {
        if config.height == 0 {
            return Err(MapConfigError::ZeroHeight);
        }
        // NaN fails this comparison too.
        if config.tol.is_nan() || config.tol <= 0.0 {
            return Err(MapConfigError::BadTolerance(config.tol));
        }
        let count = config.levels.level_count();
        if count == 0 || count as usize > MAX_LEVELS || (config.height >> (count - 1)) == 0 {
            return Err(MapConfigError::BadLevelCount(count));
        }
        let mut levels = [Level {
            layout: LatLong::new(1),
            first_texel: 0,
            min_affinity: 0.0,
        }; MAX_LEVELS];
        let mut first_texel = 0;
        for (index, level) in levels.iter_mut().take(count as usize).enumerate() {
            let layout = LatLong::new(config.height >> index);
            let h = layout.height() as f32;
            *level = Level {
                layout,
                first_texel,
                min_affinity: (1.0 / (config.tol * h * h)).min(1.0),
            };
            first_texel += layout.texel_count();
        }
        Ok(AffinityMap {
            config,
            levels,
            level_count: count as usize,
            texels: vec![TexelState::FRESH; first_texel],
            generation: 1,
        })
    }

    /// The configuration the map was built with.
    pub fn config(&self) -> &MapConfig {
        &self.config
    }

    /// Bytes of texel storage.
    pub fn memory_bytes(&self) -> usize {
        self.texels.len() * std::mem::size_of::<TexelState>()
    }

    /// Number of levels (1 for a single-level map).
    pub fn level_count(&self) -> usize {
        self.level_count
    }

    /// The layout of level `level` (0 is the finest).
    pub fn level_layout(&self, level: usize) -> LatLong {
        assert!(level < self.level_count, "level {level} out of range");
        self.levels[level].layout
    }

    /// Forgets everything: every texel reads as fresh (affinity 1). O(1).
    pub fn clear(&mut self) {
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            // After 2^32 clears, really reset so that no stale texel matches a new generation.
            self.texels.fill(TexelState::FRESH);
            self.generation = 1;
        }
    }

    /// Makes this map a copy of `other` (same configuration required), without allocating.
    pub fn copy_from(&mut self, other: &AffinityMap) {
        assert_eq!(
            self.config, other.config,
            "copy_from needs maps of the same configuration"
        );
        self.texels.copy_from_slice(&other.texels);
        self.generation = other.generation;
    }

    /// Sets this map to what `sources` learned, each weighted: every texel becomes
    /// `[s, ω] = [1, 1] + Σ w · ([s, ω]_source − [1, 1])`, i.e. the fresh prior plus the
    /// weighted evidence of each source (their recorded rays count `w` times). Used to start
    /// a batch from maps learned at neighbouring gather points ("shared maps"). Sources must
    /// have this map's height and levels (their `mode` and `tol` may differ); weights must
    /// be finite and non-negative. Resets are not carried over.
    pub fn blend_from<'a>(&mut self, sources: impl IntoIterator<Item = (&'a AffinityMap, f32)>) {
        self.clear();
        let mut sources = sources.into_iter().peekable();
        if sources.peek().is_none() {
            return;
        }
        let fresh = TexelState {
            generation: self.generation,
            ..TexelState::FRESH
        };
        self.texels.fill(fresh);
        for (source, weight) in sources {
            assert!(
                source.config.height == self.config.height
                    && source.config.levels == self.config.levels,
                "blend_from needs sources of the same height and levels"
            );
            assert!(
                weight.is_finite() && weight >= 0.0,
                "blend weights must be finite and non-negative, got {weight}"
            );
            for (index, blended) in self.texels.iter_mut().enumerate() {
                let state = source.state(index);
                blended.sum += weight * (state.sum - 1.0);
                blended.weight += weight * (state.weight - 1.0);
                blended.samples += (weight * state.samples as f32).round() as u32;
            }
        }
    }

    #[inline]
    fn state(&self, index: usize) -> TexelState {
        let state = self.texels[index];
        if state.generation == self.generation {
            state
        } else {
            TexelState {
                resets: 0,
                ..TexelState::FRESH
            }
        }
    }

    #[inline]
    fn affinity_of(state: TexelState, min_affinity: f32) -> f32 {
        let mean = state.sum / state.weight;
        if mean >= 1.0 {
            1.0
        } else {
            min_affinity + mean * (1.0 - min_affinity)
        }
    }

    /// Where `direction` falls, and the affinity the map gives it under its level rule.
    #[inline]
    pub fn lookup(&self, direction: glam::Vec3) -> Lookup {
        self.lookup_coordinates(SphericalCoordinates::of(direction))
    }

    /// [`AffinityMap::lookup`] from precomputed spherical coordinates.
    #[inline]
    pub fn lookup_coordinates(&self, coordinates: SphericalCoordinates) -> Lookup {
        let mut texels = [0u32; MAX_LEVELS];
        for (slot, level) in texels.iter_mut().zip(&self.levels[..self.level_count]) {
            let texel = level.layout.texel_at(coordinates);
            *slot = (level.first_texel + level.layout.index(texel)) as u32;
        }
        let affinity = match self.config.levels {
            LevelRule::Single => {
                Self::affinity_of(self.state(texels[0] as usize), self.levels[0].min_affinity)
            }
            #[cfg(feature = "study")]
            LevelRule::FinestBelowOne { .. } => (0..self.level_count)
                .map(|l| {
                    Self::affinity_of(self.state(texels[l] as usize), self.levels[l].min_affinity)
                })
                .find(|&a| a < 1.0)
                .unwrap_or(1.0),
            #[cfg(feature = "study")]
            LevelRule::FinestWithSamples { min_samples, .. } => (0..self.level_count)
                .map(|l| (l, self.state(texels[l] as usize)))
                .find(|(_, state)| state.samples >= min_samples)
                .map(|(l, state)| Self::affinity_of(state, self.levels[l].min_affinity))
                .unwrap_or(1.0),
        };
        Lookup { affinity, texels }
    }

    /// Records a traced ray of rating `rating` ∈ [0, 1] at the texels of `lookup`, accepted
    /// with affinity `accepted_with` (its weight is `1 / accepted_with`).
    pub fn record(&mut self, lookup: &Lookup, rating: f32, accepted_with: f32) -> RecordOutcome {
        let weight = 1.0 / accepted_with;
        let mut outcome = RecordOutcome::default();
        for level_index in 0..self.level_count {
            let level = self.levels[level_index];
            let index = lookup.texels[level_index] as usize;
            let mut state = self.state(index);
            let before = Self::affinity_of(state, level.min_affinity);
            state.sum += rating * weight;
            state.weight += weight;
            state.samples += 1;
            state.generation = self.generation;
            let after = Self::affinity_of(state, level.min_affinity);
            self.texels[index] = state;
            if self.config.mode == Mode::Conservative && after > before {
                self.reset_neighbourhood(level, index);
                outcome.resets += 1;
            }
        }
        outcome
    }

    /// Forces the texel at `index` and its 1-texel border to affinity 1, counting the reset.
    fn reset_neighbourhood(&mut self, level: Level, index: usize) {
        let center = level.layout.texel_of_index(index - level.first_texel);
        let generation = self.generation;
        let mut neighbourhood = [0usize; 9];
        let mut count = 0;
        level.layout.for_each_in_neighbourhood(center, |texel| {
            neighbourhood[count] = level.first_texel + level.layout.index(texel);
            count += 1;
        });
        for &neighbour in &neighbourhood[..count] {
            let resets = self.state(neighbour).resets;
            self.texels[neighbour] = TexelState {
                resets,
                generation,
                ..TexelState::FRESH
            };
        }
        self.texels[index].resets += 1;
    }

    /// The affinity floor `a_min` of one level (its affinity with every ray blocked).
    pub fn min_affinity(&self, level: usize) -> f32 {
        self.levels[..self.level_count][level].min_affinity
    }

    /// Affinity of one texel of one level, as that level alone would give it.
    pub fn texel_affinity(&self, level: usize, texel: crate::mapping::Texel) -> f32 {
        let level = self.levels[..self.level_count][level];
        let state = self.state(level.first_texel + level.layout.index(texel));
        Self::affinity_of(state, level.min_affinity)
    }

    /// The reset counter of one texel of one level.
    pub fn texel_resets(&self, level: usize, texel: crate::mapping::Texel) -> u32 {
        let level = self.levels[..self.level_count][level];
        self.state(level.first_texel + level.layout.index(texel))
            .resets
    }

    /// Rays recorded in one texel of one level since it was last fresh.
    pub fn texel_samples(&self, level: usize, texel: crate::mapping::Texel) -> u32 {
        let level = self.levels[..self.level_count][level];
        self.state(level.first_texel + level.layout.index(texel))
            .samples
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn map(mode: Mode, tol: f32, levels: LevelRule) -> AffinityMap {
        AffinityMap::new(MapConfig {
            height: 8,
            tol,
            mode,
            levels,
        })
        .unwrap()
    }

    #[test]
    fn blending_adds_weighted_evidence_to_the_prior() {
        let dir = Vec3::new(0.3, 0.2, 0.9).normalize();
        let mut a = map(Mode::Aggressive, f32::INFINITY, LevelRule::Single);
        let mut b = map(Mode::Conservative, 4.0, LevelRule::Single);
        // a: two rays of rating 0 at weight 1 → [s, ω] = [1, 3].
        for _ in 0..2 {
            let lookup = a.lookup(dir);
            a.record(&lookup, 0.0, 1.0);
        }
        // b: one ray of rating 1 at weight 2 → [3, 3].
        let lookup = b.lookup(dir);
        b.record(&lookup, 1.0, 0.5);
        let mut blended = map(Mode::Aggressive, f32::INFINITY, LevelRule::Single);
        blended.blend_from([(&a, 0.5), (&b, 1.0)]);
        // [1 + 0.5·0 + 1·2, 1 + 0.5·2 + 1·2] = [3, 4] → affinity 0.75.
        assert!((blended.lookup(dir).affinity - 0.75).abs() < 1e-6);
        // Other texels stay fresh; no sources gives a fresh map.
        assert_eq!(blended.lookup(-dir).affinity, 1.0);
        blended.blend_from([]);
        assert_eq!(blended.lookup(dir).affinity, 1.0);
    }

    #[test]
    fn conservative_sequence_from_the_talk() {
        // tol = ∞: repeated zero ratings halve the affinity; the first increase forces 1.
        let mut m = map(Mode::Conservative, f32::INFINITY, LevelRule::Single);
        let dir = Vec3::new(0.3, 0.2, 0.9).normalize();
        let mut seen = Vec::new();
        for _ in 0..3 {
            let lookup = m.lookup(dir);
            seen.push(lookup.affinity);
            assert_eq!(m.record(&lookup, 0.0, lookup.affinity).resets, 0);
        }
        let lookup = m.lookup(dir);
        seen.push(lookup.affinity);
        assert_eq!(m.record(&lookup, 1.0, lookup.affinity).resets, 1);
        seen.push(m.lookup(dir).affinity);
        assert_eq!(seen, vec![1.0, 0.5, 0.25, 0.125, 1.0]);
        let texel = m.level_layout(0).texel(dir);
        assert_eq!(m.texel_resets(0, texel), 1);
    }

    #[test]
    fn conservative_reset_covers_the_border_but_not_beyond() {
        let mut m = map(Mode::Conservative, f32::INFINITY, LevelRule::Single);
        let layout = m.level_layout(0);
        let center = crate::mapping::Texel { row: 4, column: 5 };
        // Darken a 5x5 block around the centre.
        for row in 2..=6 {
            for column in 3..=7 {
                let dir = layout.center_direction(crate::mapping::Texel { row, column });
                let lookup = m.lookup(dir);
                m.record(&lookup, 0.0, 1.0);
            }
        }
        let lookup = m.lookup(layout.center_direction(center));
        m.record(&lookup, 1.0, lookup.affinity);
        for row in 2..=6u32 {
            for column in 3..=7u32 {
                let a = m.texel_affinity(0, crate::mapping::Texel { row, column });
                let inside = row.abs_diff(4) <= 1 && column.abs_diff(5) <= 1;
                assert_eq!(a == 1.0, inside, "row {row} column {column}: {a}");
            }
        }
    }

    #[test]
    fn aggressive_mode_never_resets() {
        let mut m = map(Mode::Aggressive, f32::INFINITY, LevelRule::Single);
        let dir = Vec3::Z;
        let l = m.lookup(dir);
        m.record(&l, 0.0, 1.0);
        let l = m.lookup(dir);
        assert_eq!(l.affinity, 0.5);
        assert_eq!(m.record(&l, 1.0, 0.5).resets, 0);
        // s = 1 + 2, ω = 2 + 2.
        assert_eq!(m.lookup(dir).affinity, 0.75);
    }

    #[test]
    fn tolerance_sets_the_floor_per_level() {
        // a_min = 1 / (tol h²) = 1 / (1 · 64).
        let mut m = map(Mode::Aggressive, 1.0, LevelRule::Single);
        let dir = Vec3::X;
        for _ in 0..40 {
            let l = m.lookup(dir);
            m.record(&l, 0.0, l.affinity);
        }
        let a = m.lookup(dir).affinity;
        // s/ω → 0 but never reaches it (s starts at 1), so a → a_min from above.
        assert!((1.0 / 64.0..1.0 / 64.0 + 1e-3).contains(&a), "{a}");
    }

    #[test]
    fn clear_is_constant_time_and_forgets() {
        let mut m = map(Mode::Aggressive, f32::INFINITY, LevelRule::Single);
        let l = m.lookup(Vec3::Y);
        m.record(&l, 0.0, 1.0);
        assert!(m.lookup(Vec3::Y).affinity < 1.0);
        m.clear();
        assert_eq!(m.lookup(Vec3::Y).affinity, 1.0);
        assert_eq!(m.texel_samples(0, m.level_layout(0).texel(Vec3::Y)), 0);
    }

    #[test]
    fn literal_multilevel_uses_finest_level_below_one() {
        let mut m = map(
            Mode::Aggressive,
            f32::INFINITY,
            LevelRule::FinestBelowOne { count: 3 },
        );
        let dir = Vec3::new(0.5, 0.5, 0.7).normalize();
        let l = m.lookup(dir);
        m.record(&l, 0.0, 1.0);
        assert_eq!(m.lookup(dir).affinity, 0.5);
        // A direction in the same coarse texel but another fine texel sees the coarse level.
        let layout = m.level_layout(0);
        let coarse = m.level_layout(2);
        let texel = layout.texel(dir);
        let neighbour = (0..layout.texel_count())
            .map(|i| layout.texel_of_index(i))
            .find(|&t| t != texel && coarse.texel(layout.center_direction(t)) == coarse.texel(dir))
            .unwrap();
        assert_eq!(m.lookup(layout.center_direction(neighbour)).affinity, 0.5);
    }

    #[test]
    fn samples_rule_waits_for_evidence() {
        let mut m = map(
            Mode::Aggressive,
            f32::INFINITY,
            LevelRule::FinestWithSamples {
                count: 2,
                min_samples: 2,
            },
        );
        let dir = Vec3::new(0.1, 0.9, 0.3).normalize();
        let l = m.lookup(dir);
        m.record(&l, 0.0, 1.0);
        assert_eq!(m.lookup(dir).affinity, 1.0);
        let l = m.lookup(dir);
        m.record(&l, 0.0, 1.0);
        assert_eq!(m.lookup(dir).affinity, 1.0 / 3.0);
    }

    #[test]
    fn bad_configurations_are_refused() {
        let base = MapConfig::default();
        assert_eq!(
            AffinityMap::new(MapConfig { height: 0, ..base }).unwrap_err(),
            MapConfigError::ZeroHeight
        );
        assert!(AffinityMap::new(MapConfig { tol: 0.0, ..base }).is_err());
        assert!(AffinityMap::new(MapConfig {
            tol: f32::NAN,
            ..base
        })
        .is_err());
        assert!(AffinityMap::new(MapConfig {
            height: 4,
            levels: LevelRule::FinestBelowOne { count: 4 },
            ..base
        })
        .is_err());
        assert!(AffinityMap::new(MapConfig {
            height: 8,
            levels: LevelRule::FinestBelowOne { count: 4 },
            ..base
        })
        .is_ok());
    }

    #[test]
    fn copy_from_transfers_learned_state() {
        let mut learned = map(Mode::Aggressive, f32::INFINITY, LevelRule::Single);
        let l = learned.lookup(Vec3::Z);
        learned.record(&l, 0.0, 1.0);
        let mut other = map(Mode::Aggressive, f32::INFINITY, LevelRule::Single);
        other.clear();
        other.clear();
        other.copy_from(&learned);
        assert_eq!(other.lookup(Vec3::Z).affinity, 0.5);
    }
}
