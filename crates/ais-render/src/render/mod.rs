//! Parallel tiled rendering with per-pixel seeds: the image does not depend on the number
//! of threads or on scheduling.
//!
//! The tile loop knows nothing about what an integrator computes: it hands every tile a
//! fresh state from the integrator ([`SampleIntegrator::begin_tile`]), asks it for the
//! value of each camera ray, and merges the tiles' statistics.

mod counts;
mod integrator;
mod tile;

pub use counts::RayCounts;
pub use integrator::{SampleIntegrator, TileState, TileStats};
pub use tile::{pixel_seed, tiles, PixelRect, Tile, TILE_SIZE};

use crate::film::Film;
use crate::image_io::RgbImage;
use crate::world::World;
use ais::rng::Pcg32;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// Render settings.
#[derive(Clone, Copy, Debug)]
pub struct RenderSettings {
    /// Samples per pixel.
    pub samples_per_pixel: u32,
    /// Base seed; each pixel derives its own from it.
    pub seed: u64,
    /// Show a progress bar on stderr (it also hides itself when stderr is not a terminal).
    pub progress: bool,
}

/// A finished render.
pub struct RenderOutput<S> {
    /// The image.
    pub image: RgbImage,
    /// Rays traced.
    pub rays: RayCounts,
    /// The integrator's statistics, merged over tiles.
    pub stats: S,
    /// The integrator's work counter ([`TileState::work`]; for the gather, traced rays) per
    /// camera sample, per pixel (an AOV).
    pub work_per_sample: Vec<f32>,
    /// Wall time of the render loop.
    pub time: Duration,
}

impl<S> RenderOutput<S> {
    /// The same render with its statistics turned into `T` (e.g. a study's own).
    pub fn map_stats<T>(self, f: impl FnOnce(S) -> T) -> RenderOutput<T> {
        RenderOutput {
            image: self.image,
            rays: self.rays,
            stats: f(self.stats),
            work_per_sample: self.work_per_sample,
            time: self.time,
        }
    }
}

/// What one tile's render produced.
struct TileResult<S> {
    rect: PixelRect,
    /// Row-major, `rect`'s width per row.
    pixels: Vec<[f32; 3]>,
    /// Work per camera sample, per pixel.
    work: Vec<f32>,
    counts: RayCounts,
    stats: S,
}

fn progress_bar(tiles: usize, visible: bool) -> ProgressBar {
    if !visible {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(tiles as u64), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} rendering [{bar:40}] {pos}/{len} tiles, {elapsed} elapsed, ETA {eta}",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    bar
}

/// Renders `world` with `integrator` and `settings` on the current rayon pool.
pub fn render<I: SampleIntegrator>(
    world: &World,
    integrator: &I,
    settings: &RenderSettings,
) -> RenderOutput<<I::Tile as TileState>::Stats> {
    let (width, height) = (world.resolution.0 as usize, world.resolution.1 as usize);
    let rects = tiles(width, height);
    let progress = progress_bar(rects.len(), settings.progress);
    let started = Instant::now();
    let results: Vec<_> = rects
        .par_iter()
        .map(|&rect| {
            let tile = Tile {
                rect,
                image: (width, height),
                seed: settings.seed,
            };
            let result = render_tile(world, integrator, settings, &tile);
            progress.inc(1);
            result
        })
        .collect();
    progress.finish_and_clear();
    let mut film = Film::new(width, height);
    let mut rays = RayCounts::default();
    let mut stats = <<I::Tile as TileState>::Stats>::default();
    let mut work_per_sample = vec![0.0; width * height];
    for result in results {
        rays.merge(result.counts);
        stats.merge(result.stats);
        let rect = result.rect;
        for (i, (value, work)) in result.pixels.into_iter().zip(result.work).enumerate() {
            let (x, y) = (rect.x0 + i % rect.width(), rect.y0 + i / rect.width());
            film.add(x, y, value);
            work_per_sample[y * width + x] = work;
        }
    }
    RenderOutput {
        image: film.image(),
        rays,
        stats,
        work_per_sample,
        time: started.elapsed(),
    }
}

/// Renders one tile with a fresh integrator state.
fn render_tile<I: SampleIntegrator>(
    world: &World,
    integrator: &I,
    settings: &RenderSettings,
    tile: &Tile,
) -> TileResult<<I::Tile as TileState>::Stats> {
    let mut counts = RayCounts::default();
    let mut state = integrator.begin_tile(world, tile, &mut counts);
    let (width, height) = tile.image;
    let spp = settings.samples_per_pixel;
    let mut pixels = Vec::with_capacity(tile.rect.area());
    let mut work = Vec::with_capacity(tile.rect.area());
    for (x, y) in tile.rect.pixels() {
        let mut rng = Pcg32::new(pixel_seed(settings.seed, x, y, width), 0);
        let work_before = state.work();
        let mut sum = [0.0f64; 3];
        for _ in 0..spp {
            let u = (x as f32 + rng.next_f32()) / width as f32;
            let v = (y as f32 + rng.next_f32()) / height as f32;
            let ray = world.camera.ray(u, v);
            let value = integrator.radiance(world, &ray, &mut rng, &mut state, &mut counts);
            for (s, c) in sum.iter_mut().zip(value) {
                *s += c as f64;
            }
        }
        pixels.push(sum.map(|s| (s / spp as f64) as f32));
        work.push((state.work() - work_before) as f32 / spp as f32);
    }
    TileResult {
        rect: tile.rect,
        pixels,
        work,
        counts,
        stats: state.finish(),
    }
}
