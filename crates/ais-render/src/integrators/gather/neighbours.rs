//! Shared affinity maps: each gather starts from a fixed map blended from what the batches
//! at neighbouring gather points traced before it.
//!
//! Every gather with `map = neighbours` records its traced rays in an observation map
//! ([`ais::Batch::observe_rays`]). A thread remembers the last [`NEIGHBOURS`] gathers of its
//! current tile (point, normal, observations). The next gather blends them into its own
//! map, each weighted by `exp(−d²/r²) · max(0, n·n')⁸` (distance `d`, normals `n`, `n'`,
//! radius `r` = [`RADIUS_PIXELS`] pixel footprints at the hit), and holds that map fixed
//! while it runs: its acceptance probabilities do not depend on its own rays, so the
//! estimate is exactly unbiased. Across depth or normal discontinuities the weights vanish
//! and the map stays fresh (affinity 1, i.e. AIS off). Maps are in world-space directions.
//!
//! The memory is per thread, bounded by [`NEIGHBOURS`] maps, and starts empty at every tile,
//! so what a gather sees depends only on the gathers before it in its tile, in the tile's
//! fixed pixel order: the image is the same for any number of threads. With
//! [`super::Sharing::LearningPass`] the maps of a learning pass around the tile
//! ([`super::learning_pass`]) are blended in as well.

use ais::AffinityMap;
use glam::Vec3;

/// How many recent gathers a thread remembers.
pub const NEIGHBOURS: usize = 16;
/// The neighbourhood radius, in pixel footprints at the gather point.
pub const RADIUS_PIXELS: f32 = 3.0;
/// Neighbours weighing less than this are ignored.
const LEAST_WEIGHT: f32 = 1e-3;

/// One finished gather whose observations a later gather may blend.
#[derive(Clone, Debug)]
pub(crate) struct Neighbour {
    /// Where it gathered.
    pub point: Vec3,
    /// Its shading normal.
    pub normal: Vec3,
    /// The rays it traced.
    pub observations: AffinityMap,
}

impl Neighbour {
    /// Bytes held (its map's texels and itself).
    pub fn memory_bytes(&self) -> usize {
        self.observations.memory_bytes() + std::mem::size_of::<Neighbour>()
    }
}

/// A group of neighbours and the radius of their weights.
#[derive(Clone, Copy)]
pub(crate) struct NeighbourSource<'a> {
    /// The neighbours.
    pub neighbours: &'a [Neighbour],
    /// The radius r of their weights, in world units.
    pub radius: f32,
}

/// Sets `map` to the blend of the neighbours near `point` (shading normal `normal`) in
/// each group of `sources`, a neighbour of a group with radius `r` weighing
/// `exp(−d²/r²) · max(0, n·n')⁸`; returns how many weighed at least [`LEAST_WEIGHT`]. With
/// none, `map` is fresh (affinity 1).
pub(crate) fn blend_neighbours(
    map: &mut AffinityMap,
    sources: &[NeighbourSource],
    point: Vec3,
    normal: Vec3,
) -> usize {
    let mut count = 0;
    map.blend_from(
        sources
            .iter()
            .flat_map(|&NeighbourSource { neighbours, radius }| {
                let inverse_r2 = 1.0 / (radius * radius).max(f32::MIN_POSITIVE);
                neighbours.iter().filter_map(move |neighbour| {
                    let facing = neighbour.normal.dot(normal).max(0.0);
                    let weight = (-(neighbour.point - point).length_squared() * inverse_r2).exp()
                        * facing.powi(8);
                    (weight >= LEAST_WEIGHT).then_some((&neighbour.observations, weight))
                })
            })
            .inspect(|_| count += 1),
    );
    count
}

/// The recent gathers of one thread's current tile.
#[derive(Clone, Debug, Default)]
pub struct RecentGathers {
    neighbours: Vec<Neighbour>,
    next: usize,
}

impl RecentGathers {
    /// The remembered gathers, oldest first or in any order (blending does not care).
    pub(crate) fn neighbours(&self) -> &[Neighbour] {
        &self.neighbours
    }

    /// Remembers a finished gather's observations, replacing the oldest beyond
    /// [`NEIGHBOURS`].
    pub fn remember(&mut self, point: Vec3, normal: Vec3, observations: &AffinityMap) {
        if self.neighbours.len() < NEIGHBOURS {
            self.neighbours.push(Neighbour {
                point,
                normal,
                observations: observations.clone(),
            });
        } else {
            let slot = &mut self.neighbours[self.next];
            slot.point = point;
            slot.normal = normal;
            slot.observations.copy_from(observations);
        }
        self.next = (self.next + 1) % NEIGHBOURS;
    }

    /// Bytes held (the maps' texels).
    pub fn memory_bytes(&self) -> usize {
        self.neighbours.iter().map(Neighbour::memory_bytes).sum()
    }
}
