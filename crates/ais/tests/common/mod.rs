//! Helpers shared by the statistical tests: batch statistics and the chi-square test.
#![allow(dead_code)]

use ais::analytic::{AnalyticGather, GatherTarget, Moments, Proposal, Scene};
use ais::{Batch, BatchConfig, MapStart};

/// The sample mean, variance and mean traced rays of many independent batches.
#[derive(Clone, Copy, Debug)]
pub struct Summary {
    pub mean: f64,
    pub variance: f64,
    pub standard_error: f64,
    pub traced: f64,
}

impl Summary {
    /// Bias in standard errors against `exact`.
    pub fn z(&self, exact: f64) -> f64 {
        (self.mean - exact) / self.standard_error
    }

    /// Variance times mean traced rays: what equal-traced-ray comparisons divide.
    pub fn cost_variance(&self) -> f64 {
        self.variance * self.traced
    }
}

/// Runs `batches` batches with seeds `seed_base..seed_base + batches`.
pub fn summarize(
    config: BatchConfig,
    scene: &Scene,
    proposal: Proposal,
    n: u32,
    batches: u32,
    target: GatherTarget,
) -> Summary {
    let mut batch: Batch<f64> = Batch::new(config).expect("valid configuration");
    summarize_with(
        &mut batch,
        scene,
        proposal,
        n,
        batches,
        target,
        MapStart::Empty,
    )
}

/// [`summarize`] with a prepared batch (e.g. holding a fixed map) and map start.
pub fn summarize_with(
    batch: &mut Batch<f64>,
    scene: &Scene,
    proposal: Proposal,
    n: u32,
    batches: u32,
    target: GatherTarget,
    start: MapStart,
) -> Summary {
    let traced_before = batch.stats().traced;
    let mut moments = Moments::default();
    let job = AnalyticGather {
        scene,
        proposal,
        n,
        target,
    };
    for seed in 0..batches {
        moments.add(job.run(batch, 1_000_003 * seed as u64 + 17, start).value);
    }
    Summary {
        mean: moments.mean(),
        variance: moments.variance(),
        standard_error: moments.standard_error(),
        traced: (batch.stats().traced - traced_before) as f64 / batches as f64,
    }
}
