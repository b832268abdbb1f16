//! Shared affinity maps: each gather starts from a fixed map blended from what the batches
//! at neighbouring gather points traced before it.
//!
//! A batch that observes its rays ([`crate::Batch::observe_rays`]) keeps every traced ray in
//! an observation map. The host remembers finished gathers as [`Neighbour`]s (point, normal,
//! observations), for instance the last [`NEIGHBOURS`] of a tile in [`RecentGathers`]. The
//! next gather blends those near it into its own map with [`blend_neighbours`], each weighted
//! by `exp(−d²/r²) · max(0, n·n')⁸` (distance `d`, normals `n`, `n'`, radius `r`), and holds
//! that map fixed while it runs ([`crate::Learning::Off`], [`crate::MapStart::Current`]): its
//! acceptance probabilities do not depend on its own rays, so the estimate is exactly
//! unbiased. Across depth or normal discontinuities the weights vanish and the map stays
//! fresh (affinity 1, i.e. AIS off). Directions are in the frame the host's maps use (world
//! space, say).
//!
//! ```
//! use ais::shared::{blend_neighbours, NeighbourSource, RecentGathers};
//! use ais::{Batch, BatchConfig, Learning, MapStart};
//!
//! let config = BatchConfig { learning: Learning::Off, ..BatchConfig::default() };
//! let mut batch: Batch<f32> = Batch::new(config).unwrap();
//! batch.observe_rays(true);
//! let mut recent = RecentGathers::default();
//! for x in 0..4 {
//!     let (point, normal) = ([x as f32 * 0.01, 0.0, 0.0], [0.0, 0.0, 1.0]);
//!     let source = NeighbourSource { neighbours: recent.neighbours(), radius: 0.05 };
//!     blend_neighbours(batch.map_mut().unwrap(), &[source], point, normal);
//!     batch.begin(16, x, MapStart::Current);
//!     while let Some(candidate) = batch.next_candidate() {
//!         let direction = [0.0, candidate.u[0].sqrt(), (1.0 - candidate.u[0]).sqrt()];
//!         if let ais::Decision::Trace { .. } = batch.decide(direction, true) {
//!             let visible = candidate.u[1] < 0.5; // the host's ray query
//!             batch.record(if visible { 1.0 } else { 0.0 }, ais::rating(visible as u8 as f32, 1.0));
//!         }
//!     }
//!     batch.finish();
//!     recent.remember(point, normal, batch.observations().unwrap());
//! }
//! ```

use crate::AffinityMap;
use glam::Vec3;

/// How many recent gathers [`RecentGathers`] remembers.
pub const NEIGHBOURS: usize = 16;
/// Neighbours weighing less than this are ignored.
const LEAST_WEIGHT: f32 = 1e-3;

/// One finished gather whose observations a later gather may blend.
#[derive(Clone, Debug)]
pub struct Neighbour {
    /// Where it gathered.
    pub point: Vec3,
    /// Its shading normal.
    pub normal: Vec3,
    /// The rays it traced.
    pub observations: AffinityMap,
}

impl Neighbour {
    /// A neighbour at `point` with shading normal `normal`.
    pub fn new(
        point: impl Into<[f32; 3]>,
        normal: impl Into<[f32; 3]>,
        observations: AffinityMap,
    ) -> Self {
        Neighbour {
            point: Vec3::from(point.into()),
            normal: Vec3::from(normal.into()),
            observations,
        }
    }

    /// Bytes held (its map's texels and itself).
    pub fn memory_bytes(&self) -> usize {
        self.observations.memory_bytes() + std::mem::size_of::<Neighbour>()
    }
}

/// A group of neighbours and the radius of their weights.
#[derive(Clone, Copy, Debug)]
pub struct NeighbourSource<'a> {
    /// The neighbours.
    pub neighbours: &'a [Neighbour],
    /// The radius r of their weights, in the host's length units.
    pub radius: f32,
}

/// Sets `map` to the blend of the neighbours near `point` (shading normal `normal`) in
/// each group of `sources`, a neighbour of a group with radius `r` weighing
/// `exp(−d²/r²) · max(0, n·n')⁸`; returns how many weighed at least 10⁻³. With none, `map`
/// is fresh (affinity 1).
pub fn blend_neighbours(
    map: &mut AffinityMap,
    sources: &[NeighbourSource],
    point: impl Into<[f32; 3]>,
    normal: impl Into<[f32; 3]>,
) -> usize {
    let (point, normal) = (Vec3::from(point.into()), Vec3::from(normal.into()));
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

/// The last [`NEIGHBOURS`] finished gathers, in a ring that reuses its maps.
#[derive(Clone, Debug, Default)]
pub struct RecentGathers {
    neighbours: Vec<Neighbour>,
    next: usize,
}

impl RecentGathers {
    /// The remembered gathers, in any order (blending does not care).
    pub fn neighbours(&self) -> &[Neighbour] {
        &self.neighbours
    }

    /// Remembers a finished gather's observations, replacing the oldest beyond
    /// [`NEIGHBOURS`].
    pub fn remember(
        &mut self,
        point: impl Into<[f32; 3]>,
        normal: impl Into<[f32; 3]>,
        observations: &AffinityMap,
    ) {
        if self.neighbours.len() < NEIGHBOURS {
            self.neighbours
                .push(Neighbour::new(point, normal, observations.clone()));
        } else {
            let slot = &mut self.neighbours[self.next];
            slot.point = Vec3::from(point.into());
            slot.normal = Vec3::from(normal.into());
            slot.observations.copy_from(observations);
        }
        self.next = (self.next + 1) % NEIGHBOURS;
    }

    /// Bytes held (the maps' texels).
    pub fn memory_bytes(&self) -> usize {
        self.neighbours.iter().map(Neighbour::memory_bytes).sum()
    }
}
