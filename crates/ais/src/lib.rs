//! # ais: adaptive importance sampling for multi-ray gathering
//!
//! An implementation of Neulander's *Adaptive Importance Sampling for Multi-Ray Gathering*
//! (SIGGRAPH 2011 talk), as a small host-driven library. When a renderer gathers light at a
//! point with a batch of rays, its importance samplers know the lights but not the occluders.
//! AIS learns, within the batch, an *affinity map* of how occluded each direction is, and
//! skips by unbiased Russian roulette the candidates that would probably be blocked.
//!
//! The library never traces a ray and never owns a scene. The host asks a [`Batch`] for
//! candidates, asks whether to trace each one, reports what the traced ray saw, and finally
//! takes the estimate; the n+1 stopping rule that keeps the estimate unbiased lives here.
//! See [`batch`] for the loop a host writes.
//!
//! Modules, one concept each:
//! - [`mapping`]: lat-long direction ↔ texel;
//! - [`affinity_map`]: the map's levels, channels, update rule and modes;
//! - [`halton`]: the scrambled 3-D Halton sequence;
//! - [`epochs`]: frozen-map epochs (the exactly unbiased learning schedule);
//! - [`batch`]: the driver, the stopping rule and the estimator;
//! - [`texel_distribution`]: a piecewise-constant density over a map's texels, to fold a
//!   fixed map into a proposal (guiding) instead of rejecting against it;
//! - [`chi2`]: the chi-square goodness-of-fit test used to validate samplers;
//! - [`stats`]: counters; [`value`]: what a batch can average; [`rng`]: a seedable PCG32;
//! - [`analytic`]: analytic gather scenes with exact integrals, for tests, studies and hosts
//!   that want to validate their integration.

#![warn(missing_docs)]

pub mod affinity_map;
pub mod analytic;
pub mod batch;
pub mod chi2;
pub mod epochs;
pub mod halton;
pub mod mapping;
pub mod rng;
pub mod stats;
pub mod texel_distribution;
pub mod value;

pub use affinity_map::{AffinityMap, LevelRule, MapConfig, MapConfigError, Mode};
pub use batch::{
    rating, Batch, BatchConfig, BatchConfigError, Candidate, Decision, Estimate, Learning,
    MapStart, Placement, RejectReason, Stopping,
};
pub use stats::Stats;
pub use texel_distribution::TexelDistribution;
pub use value::Value;
