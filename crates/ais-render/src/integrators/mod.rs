//! What a camera sample computes: the AIS gather (see [`gather`]), or shading normals and
//! ambient occlusion for checking geometry.

pub mod ambient_occlusion;
pub mod gather;
pub mod normals;

pub use ambient_occlusion::AmbientOcclusion;

use crate::geometry::Ray;
use crate::render::{RayCounts, SampleIntegrator, Tile, TileState};
use crate::world::World;
use ais::rng::Pcg32;
use gather::FieldPass;
use gather::{GatherLearning, GatherSettings, GatherStats, GatherTile};

/// What to compute at each camera sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integrator {
    /// Direct light gathered at the first hit with `rays` rays through the AIS batch
    /// driver, plus emitters seen directly.
    Gather(GatherSettings),
    /// Shading normal mapped to colour, (n + 1) / 2; black on a miss.
    Normals,
    /// Ambient occlusion by cosine-weighted hemisphere rays of bounded length.
    AmbientOcclusion(AmbientOcclusion),
}

/// The per-tile state of an [`Integrator`]: the gather's, or none.
pub enum IntegratorTile {
    /// The gather's state.
    Gather(Box<GatherTile>),
    /// Normals and ambient occlusion keep nothing.
    Stateless,
}

impl TileState for IntegratorTile {
    type Stats = GatherStats;
    type Observed = Option<FieldPass>;

    fn take_observed(&mut self) -> Option<FieldPass> {
        match self {
            IntegratorTile::Gather(state) => state.take_observed(),
            IntegratorTile::Stateless => None,
        }
    }

    fn work(&self) -> u64 {
        match self {
            IntegratorTile::Gather(state) => state.work(),
            IntegratorTile::Stateless => 0,
        }
    }

    fn begin_pixel(&mut self, x: usize, y: usize) {
        if let IntegratorTile::Gather(state) = self {
            state.begin_pixel(x, y);
        }
    }

    fn sampled(&mut self, value: [f32; 3]) {
        if let IntegratorTile::Gather(state) = self {
            state.sampled(value);
        }
    }

    fn finish(self) -> GatherStats {
        match self {
            IntegratorTile::Gather(state) => state.finish(),
            IntegratorTile::Stateless => GatherStats::default(),
        }
    }
}

impl SampleIntegrator for Integrator {
    type Learned = GatherLearning;
    type Tile = IntegratorTile;

    fn passes(&self, world: &World, first_sample: u32, spp: u32) -> Vec<u32> {
        match self {
            Integrator::Gather(settings)
                if gather::field_has_use(world, settings)
                    || gather::field::chooses_sizes(settings) =>
            {
                gather::field_passes(first_sample, spp)
            }
            _ => vec![spp],
        }
    }

    fn new_learning(&self, world: &World) -> GatherLearning {
        match self {
            Integrator::Gather(settings) => GatherLearning::new(world, settings),
            _ => GatherLearning::new(world, &GatherSettings::default()),
        }
    }

    fn begin_tile(
        &self,
        world: &World,
        tile: &Tile,
        learned: &GatherLearning,
        counts: &mut RayCounts,
    ) -> IntegratorTile {
        match self {
            Integrator::Gather(settings) => IntegratorTile::Gather(Box::new(GatherTile::begin(
                world,
                settings,
                tile,
                learned,
                counts,
                (),
            ))),
            _ => IntegratorTile::Stateless,
        }
    }

    fn radiance(
        &self,
        world: &World,
        ray: &Ray,
        rng: &mut Pcg32,
        state: &mut IntegratorTile,
        counts: &mut RayCounts,
    ) -> [f32; 3] {
        match (self, state) {
            (Integrator::Gather(settings), IntegratorTile::Gather(state)) => {
                gather::gather(world, settings, ray, rng, state, counts).to_array()
            }
            (Integrator::Normals, _) => normals::normal_colour(world, ray, counts),
            (Integrator::AmbientOcclusion(ao), _) => ao.value(world, ray, rng, counts),
            (Integrator::Gather(_), IntegratorTile::Stateless) => {
                unreachable!("a gather's tiles begin with a gather state")
            }
        }
    }

    fn pixel_radiance(
        &self,
        world: &World,
        rays: &[Ray],
        rng: &mut Pcg32,
        state: &mut IntegratorTile,
        counts: &mut RayCounts,
        values: &mut Vec<[f32; 3]>,
    ) {
        match (self, state) {
            (Integrator::Gather(settings), IntegratorTile::Gather(state)) => {
                gather::gather_samples(world, settings, rays, rng, state, counts, values)
            }
            (_, state) => self.radiance_of_each(world, rays, rng, state, counts, values),
        }
    }
}
