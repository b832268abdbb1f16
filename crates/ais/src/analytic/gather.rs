//! A complete host for the analytic scenes: one gather batch driven through [`Batch`].

use super::{Proposal, Scene};
use crate::batch::{rating, Batch, Decision, Estimate, MapStart};

/// What the gather's candidates may skip for free.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GatherTarget {
    /// The real gather: only directions below the surface are known zeros.
    Normal,
    /// The oracle: occluded directions are known zeros too (visibility precomputed by brute
    /// force), so they are rejected unconditionally, untraced. Bounds what AIS can gain.
    Oracle,
}

/// A gather on an analytic scene: what every batch of it shares.
#[derive(Clone, Copy, Debug)]
pub struct AnalyticGather<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// The proposal.
    pub proposal: Proposal,
    /// Rays per batch, n.
    pub n: u32,
    /// Whether occluded candidates are known zeros (the oracle).
    pub target: GatherTarget,
}

impl AnalyticGather<'_> {
    /// Runs one batch with scrambling `seed`; the batch's map starts as `start` says.
    pub fn run(&self, batch: &mut Batch<f64>, seed: u64, start: MapStart) -> Estimate<f64> {
        gather(batch, self, seed, start)
    }
}

/// One batch of `job` through `batch`.
fn gather(
    batch: &mut Batch<f64>,
    job: &AnalyticGather,
    seed: u64,
    start: MapStart,
) -> Estimate<f64> {
    let AnalyticGather {
        scene,
        proposal,
        n,
        target,
    } = *job;
    batch.begin(n, seed, start);
    while let Some(candidate) = batch.next_candidate() {
        let (direction, pdf) = proposal.sample(candidate.u);
        let above = direction.z > 0.0;
        let known_zero = !above || (target == GatherTarget::Oracle && !scene.visible(direction));
        match batch.decide(direction.as_vec3(), !known_zero) {
            Decision::Reject(_) => {}
            Decision::Trace { .. } => {
                let unoccluded = scene.unoccluded_radiance(direction);
                let actual = if scene.visible(direction) {
                    unoccluded
                } else {
                    0.0
                };
                batch.record(
                    actual * scene.cosine_bsdf(direction) / pdf,
                    rating(actual as f32, unoccluded as f32),
                );
            }
        }
    }
    batch.finish()
}
