//! The oracle gather: a bound on what any affinity map could achieve, for studies.
//!
//! It draws candidates from the same proposal with the same placement as the gather it
//! bounds (the scrambled Halton sequence, by default), through the same batch driver, but
//! knows which of them bring light: it tests every candidate against the scene for free
//! (counted in [`OracleStats::free_tests`], not as traced rays) and traces only those that
//! bring light; the others are known zeros, like candidates outside the BSDF's support. Its
//! candidate count is fixed from an independent pilot so that about `n` candidates bring
//! light; with a fixed count the estimate is exactly unbiased, at the cost of about `n`
//! traced rays: the best an ideal map could do with this proposal and this placement.

use ais::rng::Pcg32;
use ais::{Batch, BatchConfig, Decision, Learning, MapStart, Stopping};
use ais_render::geometry::Ray;
use ais_render::integrators::gather::{arriving_light, gather_point, GatherPoint, GatherSettings};
use ais_render::render::{RayCounts, SampleIntegrator, Tile, TileState, TileStats};
use ais_render::world::World;
use glam::Vec3;

/// Pilot candidates per gather ray, to estimate the fraction that brings light.
const PILOT_PER_RAY: u32 = 4;
/// Most candidates per gather ray (where almost nothing brings light).
const MOST_PER_RAY: u32 = 64;

/// The oracle gather with a gather's strategy, `rays` and placement (the other settings are
/// unused).
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

/// A tile's oracle state: its batch driver and its counts.
#[derive(Default)]
pub struct OracleTile {
    batch: Option<Batch<[f32; 3]>>,
    stats: OracleStats,
}

impl TileState for OracleTile {
    type Stats = OracleStats;
    type Observed = ();

    fn take_observed(&mut self) {}

    fn finish(self) -> OracleStats {
        self.stats
    }
}

impl SampleIntegrator for Oracle {
    type Learned = ();
    type Tile = OracleTile;

    fn new_learning(&self, _world: &World) {}

    fn begin_tile(&self, _: &World, _: &Tile, _: &(), _: &mut RayCounts) -> OracleTile {
        OracleTile::default()
    }

    fn radiance(
        &self,
        world: &World,
        ray: &Ray,
        rng: &mut Pcg32,
        tile: &mut OracleTile,
        counts: &mut RayCounts,
    ) -> [f32; 3] {
        counts.closest_hit += 1;
        let Some(hit) = world.geometry.intersect(ray) else {
            return world.lights.background(ray.direction).to_array();
        };
        let emitted = world
            .lights
            .emitted(hit.shape, hit.geometric_normal, ray.direction, hit.uv);
        if world.lights.is_empty() {
            return emitted.to_array();
        }
        let settings = &self.0;
        let mut at = gather_point(world, &hit, -ray.direction);
        // AIS off's proposal: its MIS share, where one is given.
        if let Some(share) = settings.mis_share {
            at.mis_bsdf_share = share as f64;
        }
        let batch = tile.batch.get_or_insert_with(|| {
            Batch::new(BatchConfig {
                affinity: None,
                learning: Learning::Off,
                placement: settings.placement,
                stopping: Stopping::FixedCandidates,
                ..BatchConfig::default()
            })
            .expect("a valid oracle configuration")
        });
        let mut draw = Draw {
            world,
            settings,
            at: &at,
            stats: &mut tile.stats,
        };
        (emitted + draw.gather(batch, rng, counts)).to_array()
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
    /// What the candidate from `u` brings, weighed f / p (None: nothing, or outside the
    /// support), found by a free visibility test.
    fn candidate(&mut self, u: [f32; 2]) -> Option<Vec3> {
        let at = self.at;
        let strategy = self.settings.strategy;
        let mut toward = strategy.sample_direction(at, u)?;
        let pdf = strategy.pdf(at, &mut toward);
        if pdf <= 0.0 || !at.carries(&toward) {
            return None;
        }
        let mut test = RayCounts::default();
        let actual = arriving_light(self.world, at, &mut toward, &mut test);
        self.stats.free_tests += test.occlusion;
        (actual != Vec3::ZERO).then(|| at.scattering(&toward) * actual / pdf as f32)
    }

    /// The candidate count for about `rays` candidates that bring light, from a pilot of
    /// independent candidates (so that the count does not depend on the batch's own).
    fn candidate_count(&mut self, rng: &mut Pcg32) -> u32 {
        let n = self.settings.rays.max(1);
        let pilot = PILOT_PER_RAY * n;
        let bringing = (0..pilot)
            .filter(|_| self.candidate([rng.next_f32(), rng.next_f32()]).is_some())
            .count() as u64;
        let count = if bringing == 0 {
            n as u64
        } else {
            (n as u64 * pilot as u64).div_ceil(bringing)
        };
        count.clamp(n as u64, (MOST_PER_RAY * n) as u64) as u32
    }

    /// Direct light with about `rays` traced rays: a fixed count of candidates through
    /// `batch`, those that bring no light rejected as known zeros.
    fn gather(
        &mut self,
        batch: &mut Batch<[f32; 3]>,
        rng: &mut Pcg32,
        counts: &mut RayCounts,
    ) -> Vec3 {
        let count = self.candidate_count(rng);
        let seed = ((rng.next_u32() as u64) << 32) | rng.next_u32() as u64;
        batch.begin(count, seed, MapStart::Empty);
        while let Some(candidate) = batch.next_candidate() {
            let brings = self.candidate(candidate.u);
            let direction = self.at.frame.normal;
            if let Decision::Trace { .. } = batch.decide(direction, brings.is_some()) {
                counts.occlusion += 1;
                let value = brings.expect("only candidates that bring light are traced");
                batch.record(value.to_array(), 1.0);
            }
        }
        Vec3::from(batch.finish().value)
    }
}
