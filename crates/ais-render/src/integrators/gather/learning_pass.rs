//! The learning pass of shared maps ([`super::settings::Sharing::LearningPass`]): before a
//! tile is rendered, gathers at a coarse grid of points around it trace their rays with AIS
//! off and keep what they saw; every gather of the tile then blends the learned maps near
//! it (within `stride` pixel footprints), together with the tile's earlier gathers of
//! [`ais::shared::RecentGathers`].
//!
//! The grid has one learning gather per `stride × stride` block of pixels, at the block's
//! centre, and covers the tile plus one block on every side, so every gather point, even at
//! a tile's edge, has learned neighbours all around it (the tile-order source of
//! [`ais::shared::RecentGathers`] only has the gathers before it). A block's learning
//! gather depends only on the render seed and the block, never on which tile or thread
//! computes it, so the image is the same for any number of threads. The maps are fixed
//! while the tile renders, so every gather of it is exactly unbiased.
//!
//! What it costs: `(T/s + 2)²` gathers of `n` rays per `T × T` tile and render call
//! (`T` = [`crate::render::TILE_SIZE`]), whatever the samples per pixel; the memory is one
//! observation map per learning gather, per thread.

use super::acceptance::Acceptance;
use super::batch_loop::{run_batch, BatchRun, Lessons};
use super::guiding::CandidateSampler;
use super::settings::{GatherSettings, MapSource, MapUse, Update};
use super::strategy::gather_point;
use crate::geometry::RecentBlockers;
use crate::render::{PixelRect, RayCounts, Tile};
use crate::world::World;
use ais::rng::{mix64, Pcg32};
use ais::shared::Neighbour;
use ais::{Batch, MapStart};
use std::cell::Cell;

/// Seeds of learning gathers are drawn from a domain apart from the pixels' seeds, so that a
/// pixel's gather never reuses the random numbers its map was learned from.
const SEED_DOMAIN: u64 = 0x6c65_6172_6e20_7061;

/// The learned maps around the current tile.
#[derive(Default)]
pub struct LearningPass {
    cells: Vec<Neighbour>,
    batch: Option<Batch<[f32; 3]>>,
    /// What blocked the last learning gather's shadow rays, passed on to the next.
    blockers: Cell<RecentBlockers>,
}

/// The blocks a tile's learning pass covers: the tile's and one around it.
struct BlockGrid {
    /// Block edge in pixels.
    stride: usize,
    /// Blocks per image row.
    columns: usize,
    /// The image's size, `(width, height)`.
    image: (usize, usize),
    /// Seeds of the blocks' gathers derive from this.
    domain: u64,
    /// Covered block columns and rows, `[first, end)`.
    x: std::ops::Range<usize>,
    y: std::ops::Range<usize>,
}

impl BlockGrid {
    fn around(rect: &PixelRect, stride: usize, (width, height): (usize, usize)) -> Self {
        let first = |p: usize| (p / stride).saturating_sub(1);
        let (columns, rows) = (width.div_ceil(stride), height.div_ceil(stride));
        BlockGrid {
            stride,
            columns,
            image: (width, height),
            domain: 0,
            x: first(rect.x0)..((rect.x1 - 1) / stride + 2).min(columns),
            y: first(rect.y0)..((rect.y1 - 1) / stride + 2).min(rows),
        }
    }

    /// The centre of block `c` along an axis of `extent` pixels.
    fn centre(&self, c: usize, extent: usize) -> f32 {
        (c * self.stride + (c * self.stride + self.stride).min(extent)) as f32 * 0.5
    }
}

impl LearningPass {
    /// Runs the learning gathers of the `stride`-pixel blocks over `tile` and one block
    /// around it; the rays are counted in `counts`. Replaces what the previous tile learned.
    pub fn learn(
        &mut self,
        world: &World,
        settings: &GatherSettings,
        stride: usize,
        tile: &Tile,
        counts: &mut RayCounts,
    ) {
        self.cells.clear();
        if world.lights.is_empty() {
            return;
        }
        // A fresh map held fixed accepts every candidate: AIS off, with every traced ray
        // observed.
        let learning = GatherSettings {
            map: MapSource::Neighbours,
            update: Update::Off,
            map_use: MapUse::Roulette,
            acceptance: Acceptance::Affinity,
            ..*settings
        };
        let grid = BlockGrid::around(&tile.rect, stride, tile.image);
        let domain = mix64(tile.seed ^ SEED_DOMAIN);
        let grid = BlockGrid { domain, ..grid };
        for cy in grid.y.clone() {
            for cx in grid.x.clone() {
                if let Some(cell) = self.learn_block(world, &learning, &grid, [cx, cy], counts) {
                    self.cells.push(cell);
                }
            }
        }
    }

    /// The learning gather of block `[cx, cy]`: what it traced from its first hit, if the
    /// camera ray through the block's centre hits anything.
    fn learn_block(
        &mut self,
        world: &World,
        learning: &GatherSettings,
        grid: &BlockGrid,
        [cx, cy]: [usize; 2],
        counts: &mut RayCounts,
    ) -> Option<Neighbour> {
        let mut rng = Pcg32::new(mix64(grid.domain ^ (cy * grid.columns + cx) as u64), 0);
        let (width, height) = grid.image;
        // The block's centre, jittered within a pixel.
        let u = (grid.centre(cx, width) + rng.next_f32() - 0.5) / width as f32;
        let v = (grid.centre(cy, height) + rng.next_f32() - 0.5) / height as f32;
        let ray = world.camera.ray(u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
        counts.closest_hit += 1;
        let hit = world.geometry.intersect(&ray)?;
        let at = gather_point(world, &hit, -ray.direction);
        let batch = self.batch.get_or_insert_with(|| {
            let mut batch =
                Batch::new(learning.batch_config()).expect("valid gather configuration");
            batch.observe_rays(true);
            batch
        });
        let run = BatchRun {
            world,
            settings: learning,
            at: &at,
            sampler: &CandidateSampler::plain(learning.strategy),
            seed: ((rng.next_u32() as u64) << 32) | rng.next_u32() as u64,
            rays: learning.rays,
            start: MapStart::Empty,
            field: None,
            clock: None,
            blockers: &self.blockers,
            pixel_pool: None,
        };
        run_batch(&run, batch, counts, &mut (), Lessons::default());
        let observations = batch
            .observations()
            .expect("learning gathers observe their rays");
        Some(Neighbour::new(
            hit.point,
            at.frame.normal,
            observations.clone(),
        ))
    }

    /// The learned maps around the current tile.
    pub fn neighbours(&self) -> &[Neighbour] {
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
