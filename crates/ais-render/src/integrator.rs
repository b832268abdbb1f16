//! What a camera sample computes: the AIS gather (see [`crate::gather`]), or shading
//! normals and ambient occlusion for checking geometry; and the per-thread state they share.

use crate::gather::{gather, GatherSettings, Sharing};
use crate::geometry::{basis, cosine_hemisphere, spawn_ray, Ray};
use crate::world::World;
use ais::rng::Pcg32;
use ais::Batch;

/// Rays traced, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// Closest-hit queries (camera rays).
    pub closest_hit: u64,
    /// Occlusion (any-hit) queries.
    pub occlusion: u64,
    /// Visibility tests the oracle made for free (studies only; not in [`RayCounts::total`]).
    pub oracle_tests: u64,
}

impl RayCounts {
    /// Adds another count.
    pub fn merge(&mut self, other: RayCounts) {
        self.closest_hit += other.closest_hit;
        self.occlusion += other.occlusion;
        self.oracle_tests += other.oracle_tests;
    }

    /// All rays.
    pub fn total(&self) -> u64 {
        self.closest_hit + self.occlusion
    }
}

/// Per-thread state of a render: counters and the reusable AIS batch.
#[derive(Default)]
pub struct SampleContext {
    /// Rays traced.
    pub counts: RayCounts,
    /// The gather's batch driver (allocated on first use).
    pub batch: Option<Batch<[f32; 3]>>,
    /// Time spent in AIS calls (sampled).
    pub ais_timer: crate::ais_timer::AisTimer,
    /// The recent gathers of this tile, for shared maps in tile order.
    pub shared: crate::shared_maps::SharedMaps,
    /// The learning pass around this tile, for shared maps from a learning pass.
    pub learned: crate::learning_pass::LearningPass,
    /// The guide distribution of guided gathers (allocated on first use).
    pub guide: Option<crate::guiding::Guide>,
}

impl SampleContext {
    /// Prepares for the tile `tile` of a `width × height` image rendered with `integrator`
    /// and base seed `seed`: runs its learning pass, if the gather shares maps from one.
    pub fn begin_tile(
        &mut self,
        world: &World,
        integrator: &Integrator,
        seed: u64,
        tile: crate::learning_pass::PixelRect,
        size: (usize, usize),
    ) {
        if let Integrator::Gather(settings) = integrator {
            if let (true, Sharing::LearningPass { stride }) =
                (settings.shares_maps(), settings.sharing)
            {
                self.learned.learn(
                    world,
                    settings,
                    stride as usize,
                    seed,
                    tile,
                    size,
                    &mut self.counts,
                );
            }
        }
    }

    /// Bytes of AIS state this context holds: the batch's map and observations, the shared
    /// maps of the tile's recent gathers or of its learning pass, and the guides.
    pub fn ais_memory_bytes(&self) -> usize {
        self.batch.as_ref().map_or(0, Batch::memory_bytes)
            + self.shared.memory_bytes()
            + self.learned.memory_bytes()
            + self
                .guide
                .as_ref()
                .map_or(0, crate::guiding::Guide::memory_bytes)
    }
}

/// What to compute at each camera sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integrator {
    /// Direct light gathered at the first hit with `rays` rays through the AIS batch
    /// driver, plus emitters seen directly.
    Gather(GatherSettings),
    /// Shading normal mapped to colour, (n + 1) / 2; black on a miss.
    Normals,
    /// Ambient occlusion by `rays` cosine-weighted hemisphere rays of length `distance`
    /// around the shading normal: 1 where nothing is within `distance`. White on a miss.
    AmbientOcclusion {
        /// Rays per camera sample.
        rays: u32,
        /// Occlusion distance (world units).
        distance: f32,
    },
}

impl Integrator {
    /// The value of one camera ray.
    pub fn radiance(
        &self,
        world: &World,
        ray: &Ray,
        rng: &mut Pcg32,
        context: &mut SampleContext,
    ) -> [f32; 3] {
        if let Integrator::Gather(settings) = self {
            return gather(world, settings, ray, rng, context).to_array();
        }
        let counts = &mut context.counts;
        counts.closest_hit += 1;
        let hit = world.geometry.intersect(ray);
        match (self, hit) {
            (Integrator::Gather(_), _) => unreachable!("handled above"),
            (Integrator::Normals, None) => [0.0; 3],
            (Integrator::Normals, Some(hit)) => (hit.shading_normal * 0.5 + 0.5).to_array(),
            (Integrator::AmbientOcclusion { .. }, None) => [1.0; 3],
            (Integrator::AmbientOcclusion { rays, distance }, Some(hit)) => {
                // Face the normals toward the viewer so both sides of thin surfaces get AO.
                let facing = if hit.geometric_normal.dot(ray.direction) > 0.0 {
                    -1.0
                } else {
                    1.0
                };
                let n = hit.shading_normal * facing;
                let ng = hit.geometric_normal * facing;
                let (t, b) = basis(n);
                let mut visible = 0u32;
                for _ in 0..*rays {
                    let local = cosine_hemisphere([rng.next_f32(), rng.next_f32()]);
                    let direction = (t * local.x + b * local.y + n * local.z).normalize();
                    if direction.dot(ng) <= 0.0 {
                        continue; // below the geometric surface: blocked by it
                    }
                    let mut shadow = spawn_ray(hit.point, ng, direction);
                    shadow.t_max = *distance;
                    counts.occlusion += 1;
                    if !world.geometry.occluded(&shadow) {
                        visible += 1;
                    }
                }
                [visible as f32 / *rays as f32; 3]
            }
        }
    }
}
