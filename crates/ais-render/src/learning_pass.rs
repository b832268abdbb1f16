//! The learning pass of shared maps ([`crate::gather::Sharing::LearningPass`]): before a
//! tile is rendered, gathers at a coarse grid of points around it trace their rays with AIS
//! off and keep what they saw; every gather of the tile then blends the learned maps near
//! it (within `stride` pixel footprints), together with the tile's earlier gathers of
//! [`crate::shared_maps::SharedMaps`].
//!
//! The grid has one learning gather per `stride × stride` block of pixels, at the block's
//! centre, and covers the tile plus one block on every side, so every gather point, even at
//! a tile's edge, has learned neighbours all around it (the tile-order source of
//! [`crate::shared_maps::SharedMaps`] only has the gathers before it). A block's learning
//! gather depends only on the render seed and the block, never on which tile or thread
//! computes it, so the image is the same for any number of threads. The maps are fixed
//! while the tile renders, so every gather of it is exactly unbiased.
//!
//! What it costs: `(T/s + 2)²` gathers of `n` rays per `T × T` tile and render call
//! (`T` = [`crate::render::TILE_SIZE`]), whatever the samples per pixel; the memory is one
//! observation map per learning gather, per thread.

use crate::ais_timer::AisTimer;
use crate::gather::{gather_point, run_batch, Acceptance, AisMode, GatherSettings};
use crate::guiding::Proposal;
use crate::integrator::RayCounts;
use crate::shared_maps::Neighbour;
use crate::world::World;
use ais::rng::{mix64, Pcg32};
use ais::{Batch, MapStart};

/// Seeds of learning gathers are drawn from a domain apart from the pixels' seeds, so that a
/// pixel's gather never reuses the random numbers its map was learned from.
const SEED_DOMAIN: u64 = 0x6c65_6172_6e20_7061;

/// A rectangle of pixels, `[x0, x1) × [y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelRect {
    /// First column.
    pub x0: usize,
    /// First row.
    pub y0: usize,
    /// One past the last column.
    pub x1: usize,
    /// One past the last row.
    pub y1: usize,
}

/// The learned maps around the current tile.
#[derive(Default)]
pub struct LearningPass {
    cells: Vec<Neighbour>,
    batch: Option<Batch<[f32; 3]>>,
    // Learning gathers are not part of the render's AIS-time estimate (their wall time is).
    timer: AisTimer,
}

impl LearningPass {
    /// Runs the learning gathers of the `stride`-pixel blocks over `tile` and one block
    /// around it, in an image `width × height`, with the render's `seed`; the rays are
    /// counted in `counts`. Replaces what the previous tile learned.
    #[allow(clippy::too_many_arguments)]
    pub fn learn(
        &mut self,
        world: &World,
        settings: &GatherSettings,
        stride: usize,
        seed: u64,
        tile: PixelRect,
        (width, height): (usize, usize),
        counts: &mut RayCounts,
    ) {
        self.cells.clear();
        if world.lights.is_empty() {
            return;
        }
        // A fresh map held fixed accepts every candidate: AIS off, with every traced ray
        // observed.
        let learning = GatherSettings {
            ais: AisMode::Shared,
            acceptance: Acceptance::Affinity,
            ..*settings
        };
        let batch = self.batch.get_or_insert_with(|| {
            let mut batch =
                Batch::new(learning.batch_config()).expect("valid gather configuration");
            batch.observe_rays(true);
            batch
        });
        let proposal = Proposal::plain(settings.strategy);
        let (columns, rows) = (width.div_ceil(stride), height.div_ceil(stride));
        let first = |p: usize| (p / stride).saturating_sub(1);
        let (cx0, cy0) = (first(tile.x0), first(tile.y0));
        let cx1 = ((tile.x1 - 1) / stride + 2).min(columns);
        let cy1 = ((tile.y1 - 1) / stride + 2).min(rows);
        let domain = mix64(seed ^ SEED_DOMAIN);
        for cy in cy0..cy1 {
            for cx in cx0..cx1 {
                let mut rng = Pcg32::new(mix64(domain ^ (cy * columns + cx) as u64), 0);
                // The block's centre, jittered within a pixel.
                let centre = |c: usize, extent: usize| {
                    (c * stride + (c * stride + stride).min(extent)) as f32 * 0.5
                };
                let u = (centre(cx, width) + rng.next_f32() - 0.5) / width as f32;
                let v = (centre(cy, height) + rng.next_f32() - 0.5) / height as f32;
                let ray = world.camera.ray(u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
                counts.closest_hit += 1;
                let Some(hit) = world.geometry.intersect(&ray) else {
                    continue;
                };
                let at = gather_point(world, &hit, -ray.direction);
                let batch_seed = ((rng.next_u32() as u64) << 32) | rng.next_u32() as u64;
                run_batch(
                    world,
                    &learning,
                    &at,
                    (batch, &proposal),
                    (batch_seed, MapStart::Empty),
                    counts,
                    &mut self.timer,
                    &mut |_| {},
                );
                self.cells.push(Neighbour {
                    point: hit.point,
                    normal: at.frame.normal,
                    observations: batch
                        .observations()
                        .expect("learning gathers observe their rays")
                        .clone(),
                });
            }
        }
    }

    /// The learned maps around the current tile.
    pub(crate) fn neighbours(&self) -> &[Neighbour] {
        &self.cells
    }

    /// Bytes held: the learned maps and the learning batch's own.
    pub fn memory_bytes(&self) -> usize {
        self.batch.as_ref().map_or(0, Batch::memory_bytes)
            + self
                .cells
                .iter()
                .map(Neighbour::memory_bytes)
                .sum::<usize>()
    }
}
