//! An estimate of the time spent inside the AIS library during a render.
//!
//! Timing each library call directly would be dominated by the clock (the calls take a few
//! nanoseconds each). Instead, one gather in [`SAMPLING`] records the inputs it gave the
//! library; afterwards the same calls are replayed on a spare batch driver with nothing else
//! in between, and that replay is timed as one region. The batch is deterministic, so the
//! replay takes the same path; the image is not affected (the replay uses its own driver).

use ais::rng::Pcg32;
use ais::{Batch, BatchConfig, Decision, MapStart};
use ais_render::geometry::Ray;
use ais_render::integrators::gather::FieldPass;
use ais_render::integrators::gather::{
    gather, BatchProbe, GatherLearning, GatherSettings, GatherStats, GatherTile,
};
use ais_render::integrators::Integrator;
use ais_render::render::{RayCounts, SampleIntegrator, Tile, TileState, TileStats};
use ais_render::world::World;
use glam::Vec3;
use std::time::{Duration, Instant};

/// One gather in this many is replayed and timed.
pub const SAMPLING: u64 = 16;

/// What one candidate gave the library: its direction, whether it was in the support, and
/// what its traced ray recorded.
#[derive(Clone, Copy, Debug)]
struct CandidateInput {
    direction: Vec3,
    in_support: bool,
    recorded: Option<([f32; 3], f32)>,
}

/// Per-thread estimator of time spent in AIS calls.
#[derive(Default)]
pub struct AisTimer {
    gathers: u64,
    recording: bool,
    inputs: Vec<CandidateInput>,
    replay: Option<Batch<[f32; 3]>>,
    replayed: u64,
    spent: Duration,
}

impl BatchProbe for AisTimer {
    /// Marks the start of a gather; decides whether it is recorded for a timed replay.
    fn started(&mut self) {
        self.recording = self.gathers.is_multiple_of(SAMPLING);
        self.gathers += 1;
        self.inputs.clear();
    }

    /// Notes the inputs of one `decide` call.
    #[inline]
    fn decided(&mut self, direction: Vec3, in_support: bool) {
        if self.recording {
            self.inputs.push(CandidateInput {
                direction,
                in_support,
                recorded: None,
            });
        }
    }

    /// Notes the inputs of the `record` call that follows the last `decide`.
    #[inline]
    fn recorded(&mut self, _: &Batch<[f32; 3]>, value: [f32; 3], rating: f32) {
        if self.recording {
            if let Some(last) = self.inputs.last_mut() {
                last.recorded = Some((value, rating));
            }
        }
    }

    /// Ends a gather: if it was recorded, replays its AIS calls and times them.
    fn finished(&mut self, config: &BatchConfig, rays: u32, seed: u64) {
        if !self.recording {
            return;
        }
        let batch = self
            .replay
            .get_or_insert_with(|| Batch::new(*config).expect("valid gather configuration"));
        let inputs = &self.inputs;
        let start = Instant::now();
        batch.begin(rays, seed, MapStart::Empty);
        let mut next = 0;
        while batch.next_candidate().is_some() {
            let input = inputs.get(next).copied().unwrap_or(CandidateInput {
                direction: Vec3::Z,
                in_support: false,
                recorded: None,
            });
            next += 1;
            if let Decision::Trace { .. } = batch.decide(input.direction, input.in_support) {
                let (value, rating) = input.recorded.unwrap_or(([0.0; 3], 1.0));
                batch.record(value, rating);
            }
        }
        std::hint::black_box(batch.finish());
        self.spent += start.elapsed();
        self.replayed += 1;
    }
}

impl AisTimer {
    /// Estimated time in AIS calls over all gathers so far.
    pub fn estimate(&self) -> Duration {
        if self.replayed == 0 {
            return Duration::ZERO;
        }
        self.spent
            .mul_f64(self.gathers as f64 / self.replayed as f64)
    }
}

/// The gather, with the time spent in the AIS library estimated by [`AisTimer`]. The image
/// is the same as the plain gather's.
#[derive(Clone, Copy, Debug)]
pub struct TimedGather(pub GatherSettings);

/// A timed gather's tile.
pub struct TimedTile(GatherTile<AisTimer>);

/// What a timed gather reports.
#[derive(Clone, Copy, Debug, Default)]
pub struct TimedStats {
    /// The gather's own statistics.
    pub gather: GatherStats,
    /// Estimated time spent in AIS calls, summed over threads.
    pub ais_time: Duration,
}

impl TileStats for TimedStats {
    fn merge(&mut self, other: TimedStats) {
        self.gather.merge(other.gather);
        self.ais_time += other.ais_time;
    }
}

impl TileState for TimedTile {
    type Stats = TimedStats;
    type Observed = Option<FieldPass>;

    fn take_observed(&mut self) -> Option<FieldPass> {
        self.0.take_observed()
    }

    fn work(&self) -> u64 {
        self.0.work()
    }

    fn begin_pixel(&mut self, x: usize, y: usize) {
        self.0.begin_pixel(x, y);
    }

    fn sampled(&mut self, value: [f32; 3]) {
        self.0.sampled(value);
    }

    fn finish(self) -> TimedStats {
        let ais_time = self.0.probe.estimate();
        TimedStats {
            gather: self.0.finish(),
            ais_time,
        }
    }
}

impl SampleIntegrator for TimedGather {
    type Learned = GatherLearning;
    type Tile = TimedTile;

    fn passes(&self, world: &World, first_sample: u32, spp: u32) -> Vec<u32> {
        Integrator::Gather(self.0).passes(world, first_sample, spp)
    }

    fn new_learning(&self, world: &World) -> GatherLearning {
        GatherLearning::new(world, &self.0)
    }

    fn begin_tile(
        &self,
        world: &World,
        tile: &Tile,
        learned: &GatherLearning,
        counts: &mut RayCounts,
    ) -> TimedTile {
        TimedTile(GatherTile::begin(
            world,
            &self.0,
            tile,
            learned,
            counts,
            AisTimer::default(),
        ))
    }

    fn radiance(
        &self,
        world: &World,
        ray: &Ray,
        rng: &mut Pcg32,
        state: &mut TimedTile,
        counts: &mut RayCounts,
    ) -> [f32; 3] {
        gather(world, &self.0, ray, rng, &mut state.0, counts).to_array()
    }
}
