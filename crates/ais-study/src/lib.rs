//! # ais-study: measuring adaptive importance sampling
//!
//! Everything here studies the technique and stays off the renderer's hot path:
//! - [`oracle`]: the oracle gather, a bound on what any affinity map could achieve;
//! - [`timing`]: the time spent inside the AIS library during a render, by timed replay;
//! - [`benchmark`]: `ais bench`, BVH build time and ray throughput;
//! - [`compare`]: `ais compare`, equal-time and equal-ray studies against a converged
//!   reference, with a self-contained HTML report.

#![warn(missing_docs)]

pub mod benchmark;
pub mod compare;
pub mod oracle;
pub mod timing;
