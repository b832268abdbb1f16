//! The oracle gather: a bound on what any affinity map could achieve, for studies.
//!
//! It draws candidates from the same proposal, but knows which of them bring light: it
//! tests every candidate against the scene for free (counted in [`OracleStats::free_tests`],
//! not as traced rays) and pays a traced ray only for those that bring light. Its
//! candidate count is chosen from an independent pilot so that about `n` candidates bring
//! light; the estimate is plain Monte Carlo over all candidates, hence exactly unbiased, at
//! the cost of `n` traced rays: the best an ideal map could do.

use ais::rng::Pcg32;
use ais_render::geometry::Ray;
use ais_render::integrators::gather::{arriving_light, gather_point, GatherPoint, GatherSettings};
use ais_render::render::{RayCounts, SampleIntegrator, Tile, TileState, TileStats};
use ais_render::world::World;
use glam::Vec3;

/// Pilot candidates per gather ray, to estimate the fraction that brings light.
const PILOT_PER_RAY: u32 = 4;
/// Most candidates per gather ray (where almost nothing brings light).
const MOST_PER_RAY: u32 = 64;

/// The oracle gather with a gather's strategy and `rays` (the other settings are unused).
#[derive(Clone, Copy, Debug)]
pub struct Oracle(pub GatherSettings);

/// What the oracle reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OracleStats {
    /// Visibility tests made for free (not in the render's ray counts).
    pub free_tests: u64,
}

impl TileStats for OracleStats {
    fn merge(&mut self, other: OracleStats) {
        self.free_tests += other.free_tests;
    }
}

impl TileState for OracleStats {
    type Stats = OracleStats;

    fn finish(self) -> OracleStats {
        self
    }
}

impl SampleIntegrator for Oracle {
    type Tile = OracleStats;

    fn begin_tile(&self, _: &World, _: &Tile, _: &mut RayCounts) -> OracleStats {
        OracleStats::default()
    }

    fn radiance(
        &self,
        world: &World,
        ray: &Ray,
        rng: &mut Pcg32,
        stats: &mut OracleStats,
        counts: &mut RayCounts,
    ) -> [f32; 3] {
        counts.closest_hit += 1;
        let Some(hit) = world.geometry.intersect(ray) else {
            return world.lights.background(ray.direction).to_array();
        };
        let emitted = world
            .lights
            .emitted(hit.shape, hit.geometric_normal, ray.direction);
        if world.lights.is_empty() {
            return emitted.to_array();
        }
        let at = gather_point(world, &hit, -ray.direction);
        let mut draw = Draw {
            world,
            settings: &self.0,
            at: &at,
            stats,
        };
        (emitted + draw.gather(rng, counts)).to_array()
    }
}

/// Candidates of one oracle gather.
struct Draw<'a> {
    world: &'a World,
    settings: &'a GatherSettings,
    at: &'a GatherPoint<'a>,
    stats: &'a mut OracleStats,
}

impl Draw<'_> {
    /// What a fresh candidate brings, weighed f / p (None: nothing, or outside support).
    fn candidate(&mut self, rng: &mut Pcg32) -> Option<Vec3> {
        let at = self.at;
        let u = [rng.next_f32(), rng.next_f32()];
        let (direction, pdf) = self.settings.strategy.sample(at, u).filter(|s| s.1 > 0.0)?;
        if !at.material.in_support(&at.frame, at.wo, direction) {
            return None;
        }
        let mut test = RayCounts::default();
        let actual = arriving_light(self.world, at, direction, &mut test);
        self.stats.free_tests += test.occlusion;
        (actual != Vec3::ZERO)
            .then(|| at.material.eval(&at.frame, at.wo, direction) * actual / pdf as f32)
    }

    /// Direct light with `rays` traced rays on average.
    fn gather(&mut self, rng: &mut Pcg32, counts: &mut RayCounts) -> Vec3 {
        let n = self.settings.rays.max(1);
        let pilot = PILOT_PER_RAY * n;
        let bringing = (0..pilot).filter(|_| self.candidate(rng).is_some()).count() as u64;
        let candidates = if bringing == 0 {
            n as u64
        } else {
            (n as u64 * pilot as u64).div_ceil(bringing)
        }
        .clamp(n as u64, (MOST_PER_RAY * n) as u64);
        let mut sum = Vec3::ZERO;
        for _ in 0..candidates {
            if let Some(value) = self.candidate(rng) {
                counts.occlusion += 1;
                sum += value;
            }
        }
        sum / candidates as f32
    }
}
