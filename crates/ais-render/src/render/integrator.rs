//! What the tile loop asks of an integrator. The loop knows tiles, seeds and ray counts;
//! everything an integrator keeps between samples (the gather's batch and maps, say) is its
//! own per-tile state, and what it reports is its own statistics type.

use super::{RayCounts, Tile};
use crate::geometry::Ray;
use crate::world::World;
use ais::rng::Pcg32;

/// Statistics an integrator gathers per tile and the render merges.
pub trait TileStats: Default + Send {
    /// Folds another tile's statistics into these.
    fn merge(&mut self, other: Self);
}

impl TileStats for () {
    fn merge(&mut self, _: ()) {}
}

/// What an integrator learns over a render: state that every tile of a pass reads and
/// that changes only between passes, from what the pass's tiles observed. Fixed within a
/// pass, it keeps each pass unbiased and the image independent of threads.
pub trait Learning: Sync {
    /// What one tile observed in a pass.
    type Observed: Send;

    /// Adds a tile's observations. The result must not depend on the order of tiles.
    fn merge(&mut self, observed: Self::Observed);

    /// Called once a pass's observations are all merged, before the next pass starts;
    /// `samples` says how many samples per pixel the render has taken and has left.
    fn end_pass(&mut self, _samples: PassEnd) {}

    /// Whether more learning passes can pay (asked after [`Learning::end_pass`]); if not,
    /// the render's remaining samples run as one last pass.
    fn keeps_learning(&self) -> bool {
        true
    }

    /// Whether a pass that starts after `samples_before` samples per pixel (taken by this
    /// render and the renders it goes on from) should still observe, where only later
    /// renders would read what it learns: a learning that has learned enough says no, and
    /// such passes do none of the work of observing.
    fn wants_observations(&self, _samples_before: u32) -> bool {
        true
    }
}

/// Where a render stands when a pass ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PassEnd {
    /// Samples per pixel taken so far, by this render and the renders it goes on from.
    pub done: u32,
    /// Samples per pixel it has left (`None` where later renders go on from what this one
    /// learns: the end is not known).
    pub left: Option<u32>,
}

impl Learning for () {
    type Observed = ();
    fn merge(&mut self, _: ()) {}
}

/// Per-tile state of an integrator.
pub trait TileState {
    /// What the tile reports when it is done.
    type Stats: TileStats;
    /// What it observed for the integrator's [`Learning`].
    type Observed: Send;

    /// Hands over what the tile observed in this pass.
    fn take_observed(&mut self) -> Self::Observed;

    /// A counter of the integrator's own work that only grows (the gather's traced rays);
    /// the render reports its increase per camera sample, per pixel, as an AOV.
    fn work(&self) -> u64 {
        0
    }

    /// Pixel (`x`, `y`) of the image begins: the camera samples that follow are its own,
    /// until the next call.
    fn begin_pixel(&mut self, _x: usize, _y: usize) {}

    /// The value of the current pixel's latest camera sample.
    fn sampled(&mut self, _value: [f32; 3]) {}

    /// The tile's statistics.
    fn finish(self) -> Self::Stats;
}

impl TileState for () {
    type Stats = ();
    type Observed = ();
    fn take_observed(&mut self) {}
    fn finish(self) {}
}

/// An integrator the tile loop can drive: it computes the value of camera rays, with a
/// state made fresh for every tile (so the image does not depend on threads or on the
/// order of tiles).
pub trait SampleIntegrator: Sync {
    /// What it learns between passes (`()` for nothing).
    type Learned: Learning<Observed = <Self::Tile as TileState>::Observed>;
    /// Per-tile state.
    type Tile: TileState;

    /// How `spp` samples per pixel from sample `first_sample` on split into passes in
    /// `world` (one pass unless it learns).
    fn passes(&self, _world: &World, _first_sample: u32, spp: u32) -> Vec<u32> {
        vec![spp]
    }

    /// What it knows of `world` before the first pass.
    fn new_learning(&self, world: &World) -> Self::Learned;

    /// The state for `tile`, reading what was learned before this pass; work done here (a
    /// learning pass, say) counts its rays in `counts`.
    fn begin_tile(
        &self,
        world: &World,
        tile: &Tile,
        learned: &Self::Learned,
        counts: &mut RayCounts,
    ) -> Self::Tile;

    /// The value of one camera ray.
    fn radiance(
        &self,
        world: &World,
        ray: &Ray,
        rng: &mut Pcg32,
        state: &mut Self::Tile,
        counts: &mut RayCounts,
    ) -> [f32; 3];

    /// The values of a pixel's camera `rays` (its samples, in order), pushed onto `values`:
    /// [`SampleIntegrator::radiance`] of each, unless the integrator makes some of their
    /// work together.
    fn pixel_radiance(
        &self,
        world: &World,
        rays: &[Ray],
        rng: &mut Pcg32,
        state: &mut Self::Tile,
        counts: &mut RayCounts,
        values: &mut Vec<[f32; 3]>,
    ) {
        self.radiance_of_each(world, rays, rng, state, counts, values);
    }

    /// [`SampleIntegrator::radiance`] of each of `rays`, in order, pushed onto `values`: what
    /// [`SampleIntegrator::pixel_radiance`] does by default, and what an integrator's own
    /// form of it can fall back to (not meant to be overridden).
    fn radiance_of_each(
        &self,
        world: &World,
        rays: &[Ray],
        rng: &mut Pcg32,
        state: &mut Self::Tile,
        counts: &mut RayCounts,
        values: &mut Vec<[f32; 3]>,
    ) {
        for ray in rays {
            values.push(self.radiance(world, ray, rng, state, counts));
        }
    }
}
