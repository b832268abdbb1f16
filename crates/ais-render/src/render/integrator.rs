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

/// Per-tile state of an integrator.
pub trait TileState {
    /// What the tile reports when it is done.
    type Stats: TileStats;

    /// A counter of the integrator's own work that only grows (the gather's traced rays);
    /// the render reports its increase per camera sample, per pixel, as an AOV.
    fn work(&self) -> u64 {
        0
    }

    /// The tile's statistics.
    fn finish(self) -> Self::Stats;
}

impl TileState for () {
    type Stats = ();
    fn finish(self) {}
}

/// An integrator the tile loop can drive: it computes the value of camera rays, with a
/// state made fresh for every tile (so the image does not depend on threads or on the
/// order of tiles).
pub trait SampleIntegrator: Sync {
    /// Per-tile state.
    type Tile: TileState;

    /// The state for `tile`; work done here (a learning pass, say) counts its rays in
    /// `counts`.
    fn begin_tile(&self, world: &World, tile: &Tile, counts: &mut RayCounts) -> Self::Tile;

    /// The value of one camera ray.
    fn radiance(
        &self,
        world: &World,
        ray: &Ray,
        rng: &mut Pcg32,
        state: &mut Self::Tile,
        counts: &mut RayCounts,
    ) -> [f32; 3];
}
