//! The oracle gather: a bound on what any affinity map could achieve, for studies.
//!
//! It draws candidates from the same proposal, but knows which of them bring light: it
//! tests every candidate against the scene for free (counted in
//! [`RayCounts::oracle_tests`], not as traced rays) and pays a traced ray only for those
//! that bring light. Its candidate count is chosen from an independent pilot so that about
//! `n` candidates bring light; the estimate is plain Monte Carlo over all candidates, hence
//! exactly unbiased, at the cost of `n` traced rays: the best an ideal map could do.

use crate::gather::{light_along, GatherSettings};
use crate::integrator::RayCounts;
use crate::proposal::GatherPoint;
use crate::world::World;
use ais::rng::Pcg32;
use glam::Vec3;

/// Pilot candidates per gather ray, to estimate the fraction that brings light.
const PILOT_PER_RAY: u32 = 4;
/// Most candidates per gather ray (where almost nothing brings light).
const MOST_PER_RAY: u32 = 64;

/// Direct light at `at` by the oracle, with `settings.rays` traced rays on average.
pub(crate) fn gather_with_oracle(
    world: &World,
    settings: &GatherSettings,
    at: &GatherPoint,
    rng: &mut Pcg32,
    counts: &mut RayCounts,
) -> Vec3 {
    let n = settings.rays.max(1);
    // What candidate `u` brings, and its weight f / p (None: nothing, or outside support).
    let draw = |rng: &mut Pcg32, counts: &mut RayCounts| -> Option<Vec3> {
        let u = [rng.next_f32(), rng.next_f32()];
        let (direction, pdf) = settings.strategy.sample(at, u).filter(|s| s.1 > 0.0)?;
        if !at.material.in_support(&at.frame, at.wo, direction) {
            return None;
        }
        let mut test = RayCounts::default();
        let (actual, _) = light_along(world, at, direction, &mut test);
        counts.oracle_tests += test.occlusion;
        (actual != Vec3::ZERO)
            .then(|| at.material.eval(&at.frame, at.wo, direction) * actual / pdf as f32)
    };
    let pilot = PILOT_PER_RAY * n;
    let bringing = (0..pilot).filter(|_| draw(rng, counts).is_some()).count() as u64;
    let candidates = if bringing == 0 {
        n as u64
    } else {
        (n as u64 * pilot as u64).div_ceil(bringing)
    }
    .clamp(n as u64, (MOST_PER_RAY * n) as u64);
    let mut sum = Vec3::ZERO;
    for _ in 0..candidates {
        if let Some(value) = draw(rng, counts) {
            counts.occlusion += 1;
            sum += value;
        }
    }
    sum / candidates as f32
}
