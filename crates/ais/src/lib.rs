//! # ais: adaptive importance sampling for multi-ray gathering
//!
//! An implementation of Neulander's *Adaptive Importance Sampling for Multi-Ray Gathering*
//! (SIGGRAPH 2011 talk), as a small host-driven library, and what goes beyond it. When a
//! renderer gathers light at a point with a batch of rays, its importance samplers know the
//! lights but not the occluders. AIS keeps an *affinity map* of how occluded each direction
//! is, and skips by unbiased Russian roulette the candidates that would probably be blocked.
//!
//! The library never traces a ray and never owns a scene. The host asks a [`Batch`] for
//! candidates (or brings its own random numbers), asks whether to trace each one, reports
//! what the traced ray saw, and finally takes the estimate; the stopping rules that keep the
//! estimate unbiased live here. See [`batch`] for the loop a host writes, and [`shared`] for
//! maps learned at neighbouring gathers, which is where the gain is.
//!
//! Modules, one concept each:
//! - [`batch`]: the driver, the stopping rules and the estimator;
//! - [`affinity_map`]: the map's channels, update rules (aggressive, conservative) and
//!   blending;
//! - [`shared`]: maps blended from neighbouring gathers, held fixed for a batch;
//! - [`field`]: a learned visibility field over the whole image, fixed during a pass, and
//!   the acceptance it gives each candidate;
//! - [`mapping`]: lat-long direction ↔ texel;
//! - [`fast_trig`]: f32 atan2 and acos within 4e-7 rad, sin and cos within 2e-7, for
//!   per-candidate lookups and draws;
//! - [`fast_exp`]: f32 exp within 1.2e-7 relative, in vector lanes, for a film's Gaussian
//!   weights;
//! - [`sampling`]: warps and piecewise-constant distributions (sample, pdf, invert), including
//!   a density over a map's texels to fold a fixed map into a proposal;
//! - [`stats`]: counters; [`value`]: what a batch can average; [`rng`]: a seedable PCG32 and
//!   a seed mixer, for hosts that want them;
//! - `testing` (feature `testing`): the chi-square harness and `analytic` gather scenes
//!   with exact integrals, to validate a host's samplers and integration.
//!
//! ## Cargo features
//! - `testing`: the test kit above.
//! - `study`: options kept only to study the technique, each documented with why it exists:
//!   the talk's n+1 stopping rule (biased with stratified candidates), stopping at the n-th
//!   accepted candidate (biased by design), continuous learning inside a batch (biased),
//!   and two multi-level lookup rules that measured worse than one level.
//!
//! The measured reasons for every default are in the repository's `docs/technique.md`.

#![warn(missing_docs)]

pub mod affinity_map;
#[cfg(feature = "testing")]
pub mod analytic;
pub mod batch;
pub mod batch_set;
pub(crate) mod epochs;
pub mod fast_exp;
pub mod fast_trig;
pub mod field;
pub(crate) mod halton;
pub mod mapping;
pub mod rng;
pub mod sampling;
pub mod shared;
pub mod stats;
#[cfg(feature = "testing")]
pub mod testing;
pub mod value;

pub use affinity_map::{AffinityMap, LevelRule, MapConfig, MapConfigError, Mode};
pub use batch::{
    rating, Batch, BatchConfig, BatchConfigError, Candidate, Decision, Estimate, Learning,
    MapStart, Placement, PlainTally, RejectReason, Stopping,
};
pub use batch_set::{BatchSet, Round};
pub use sampling::TexelDistribution;
pub use stats::Stats;
pub use value::Value;

/// The largest number of frozen-map epochs a batch may use.
pub const MAX_EPOCHS: usize = epochs::MAX_EPOCHS;

/// The README's host loop, compiled and run as a doc test so that it stays true.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
pub struct ReadmeHostLoop;
