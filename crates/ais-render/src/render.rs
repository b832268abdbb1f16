//! Parallel tiled rendering with per-pixel seeds: the image does not depend on the number
//! of threads or on scheduling.

use crate::film::Film;
use crate::image_io::RgbImage;
use crate::integrator::{Integrator, RayCounts, SampleContext};
use crate::learning_pass::PixelRect;
use crate::world::World;
use ais::rng::{mix64, Pcg32};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// Edge length of a square tile, in pixels.
pub const TILE_SIZE: usize = 16;

/// Render settings.
#[derive(Clone, Copy, Debug)]
pub struct RenderSettings {
    /// Samples per pixel.
    pub samples_per_pixel: u32,
    /// What to compute.
    pub integrator: Integrator,
    /// Base seed; each pixel derives its own from it.
    pub seed: u64,
    /// Show a progress bar on stderr (it also hides itself when stderr is not a terminal).
    pub progress: bool,
}

/// A finished render.
pub struct RenderOutput {
    /// The image.
    pub image: RgbImage,
    /// Rays traced.
    pub rays: RayCounts,
    /// Counts of the AIS batches (gather integrator only).
    pub ais: ais::Stats,
    /// Estimated time spent in AIS calls, summed over threads (see [`crate::ais_timer`]).
    pub ais_time: Duration,
    /// Mean traced gather rays per camera sample, per pixel (an AOV).
    pub traced_per_sample: Vec<f32>,
    /// Wall time of the render loop.
    pub time: Duration,
    /// The most AIS state (maps, shared maps, guides) any one tile held, in bytes: what a
    /// thread needs on top of the scene.
    pub ais_memory_per_thread: usize,
}

/// What one tile's render produced.
struct TileResult {
    tile: PixelRect,
    /// Row-major, `tile`'s width per row.
    pixels: Vec<[f32; 3]>,
    /// Traced gather rays per camera sample, per pixel.
    traced: Vec<f32>,
    counts: RayCounts,
    stats: ais::Stats,
    ais_time: Duration,
    ais_memory: usize,
}

/// The seed of pixel (x, y) of a `width`-wide image.
pub fn pixel_seed(seed: u64, x: usize, y: usize, width: usize) -> u64 {
    mix64(seed ^ mix64((y * width + x) as u64))
}

/// Renders `world` with `settings` on the current rayon pool.
pub fn render(world: &World, settings: &RenderSettings) -> RenderOutput {
    let (width, height) = (world.resolution.0 as usize, world.resolution.1 as usize);
    let tiles: Vec<(usize, usize)> = (0..height.div_ceil(TILE_SIZE))
        .flat_map(|ty| {
            (0..width.div_ceil(TILE_SIZE)).map(move |tx| (tx * TILE_SIZE, ty * TILE_SIZE))
        })
        .collect();
    let progress = if settings.progress {
        let bar =
            ProgressBar::with_draw_target(Some(tiles.len() as u64), ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template(
                "{spinner} rendering [{bar:40}] {pos}/{len} tiles, {elapsed} elapsed, ETA {eta}",
            )
            .expect("valid template")
            .progress_chars("=> "),
        );
        bar
    } else {
        ProgressBar::hidden()
    };
    let started = Instant::now();
    let results: Vec<TileResult> = tiles
        .par_iter()
        .map(|&(x0, y0)| {
            let mut context = SampleContext::default();
            let tile = PixelRect {
                x0,
                y0,
                x1: (x0 + TILE_SIZE).min(width),
                y1: (y0 + TILE_SIZE).min(height),
            };
            context.begin_tile(
                world,
                &settings.integrator,
                settings.seed,
                tile,
                (width, height),
            );
            let mut pixels = Vec::with_capacity(TILE_SIZE * TILE_SIZE);
            let mut traced = Vec::with_capacity(TILE_SIZE * TILE_SIZE);
            for y in tile.y0..tile.y1 {
                for x in tile.x0..tile.x1 {
                    let mut rng = Pcg32::new(pixel_seed(settings.seed, x, y, width), 0);
                    let traced_before = context.batch.as_ref().map_or(0, |b| b.stats().traced);
                    let mut sum = [0.0f64; 3];
                    for _ in 0..settings.samples_per_pixel {
                        let u = (x as f32 + rng.next_f32()) / width as f32;
                        let v = (y as f32 + rng.next_f32()) / height as f32;
                        let ray = world.camera.ray(u, v);
                        let value =
                            settings
                                .integrator
                                .radiance(world, &ray, &mut rng, &mut context);
                        for (s, c) in sum.iter_mut().zip(value) {
                            *s += c as f64;
                        }
                    }
                    pixels.push(sum.map(|s| (s / settings.samples_per_pixel as f64) as f32));
                    let traced_after = context.batch.as_ref().map_or(0, |b| b.stats().traced);
                    traced.push(
                        (traced_after - traced_before) as f32 / settings.samples_per_pixel as f32,
                    );
                }
            }
            progress.inc(1);
            TileResult {
                tile,
                stats: context
                    .batch
                    .as_ref()
                    .map(|b| *b.stats())
                    .unwrap_or_default(),
                ais_time: context.ais_timer.estimate(),
                ais_memory: context.ais_memory_bytes(),
                counts: context.counts,
                pixels,
                traced,
            }
        })
        .collect();
    progress.finish_and_clear();
    let mut film = Film::new(width, height);
    let mut rays = RayCounts::default();
    let mut ais_stats = ais::Stats::default();
    let mut traced_per_sample = vec![0.0; width * height];
    let mut ais_time = Duration::ZERO;
    let mut ais_memory_per_thread = 0;
    for result in results {
        ais_memory_per_thread = ais_memory_per_thread.max(result.ais_memory);
        rays.merge(result.counts);
        ais_time += result.ais_time;
        ais_stats.merge(&result.stats);
        let tile = result.tile;
        let tile_width = tile.x1 - tile.x0;
        for (i, (value, traced)) in result.pixels.into_iter().zip(result.traced).enumerate() {
            let (x, y) = (tile.x0 + i % tile_width, tile.y0 + i / tile_width);
            film.add(x, y, value);
            traced_per_sample[y * width + x] = traced;
        }
    }
    RenderOutput {
        image: film.image(),
        rays,
        ais: ais_stats,
        ais_time,
        traced_per_sample,
        time: started.elapsed(),
        ais_memory_per_thread,
    }
}
