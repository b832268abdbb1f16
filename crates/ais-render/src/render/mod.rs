//! Parallel tiled rendering with per-pixel seeds: the image does not depend on the number
//! of threads or on scheduling.
//!
//! The tile loop knows nothing about what an integrator computes: it hands every tile a
//! fresh state from the integrator ([`SampleIntegrator::begin_tile`]), asks it for the
//! value of each camera ray, and merges the tiles' statistics. An integrator that learns
//! renders in passes ([`SampleIntegrator::passes`]): after each pass the loop merges what
//! the tiles observed into its [`Learning`], which the next pass reads; once the learning
//! says more passes cannot pay ([`Learning::keeps_learning`]), the remaining samples run as
//! one pass. The samples from rank 0 seed each pixel's generator as a one-pass render does;
//! a later pass mixes the rank of its first sample into the seed. Where a camera sample
//! falls in its pixel and on the lens comes from the pixel's own stratified sequence
//! ([`CameraSamples`]), which runs on across passes and does not depend on what the
//! integrator draws.

mod camera_samples;
mod counts;
mod integrator;
mod tile;

pub use camera_samples::CameraSamples;
pub use counts::RayCounts;
pub use integrator::{Learning, PassEnd, SampleIntegrator, TileState, TileStats};
pub use tile::{pixel_seed, tiles, PixelRect, Tile, TILE_SIZE};

use crate::film::{Film, ReconstructionFilter};
use crate::geometry::Ray;
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
    /// The rank, in each pixel's camera sequence, of this render's first sample: 0 for a
    /// render of its own. A render that continues earlier ones of the same seed (a
    /// progressive study's passes) starts where they stopped: its camera samples stay
    /// stratified with theirs, and its random numbers differ from theirs.
    pub first_sample: u32,
    /// Show a progress bar on stderr (it also hides itself when stderr is not a terminal).
    pub progress: bool,
    /// Render only these pixels of the image (None: all of them). The image returned is the
    /// crop's size. Pixels keep their seeds and tiles keep their place in the whole image's
    /// grid, so a crop's pixels equal the whole render's wherever pixels are rendered
    /// independently (see [`PixelRect::check_crop`]).
    pub crop: Option<PixelRect>,
}

/// A finished render.
pub struct RenderOutput<S> {
    /// The image.
    pub image: RgbImage,
    /// The weighted sums the image was developed from, over the pixels rendered. Renders
    /// that continue one another (a progressive study's passes) are combined by adding their
    /// films ([`Film::add_film`]) and developing the sum: that is the image one render of
    /// all their samples gives. Averaging their images instead is not, where a filter wider
    /// than a pixel splats: a pixel's value is a ratio of sums, and the mean of few-sample
    /// ratios is noisier, and biased, at edges.
    pub film: Film,
    /// Rays traced.
    pub rays: RayCounts,
    /// The integrator's statistics, merged over tiles.
    pub stats: S,
    /// The integrator's work counter ([`TileState::work`]; for the gather, traced rays) per
    /// camera sample, per pixel (an AOV).
    pub work_per_sample: Vec<f32>,
    /// Wall time of the render loop.
    pub time: Duration,
    /// Time the threads spent rendering tiles, summed over them: over [`RenderOutput::time`],
    /// how many threads were busy on average (short of the thread count where threads
    /// waited for the last tiles of a pass).
    pub busy: Duration,
}

impl<S> RenderOutput<S> {
    /// How many threads were rendering tiles on average over the render ([`RenderOutput::busy`]
    /// over [`RenderOutput::time`]).
    pub fn threads_busy(&self) -> f64 {
        self.busy.as_secs_f64() / self.time.as_secs_f64().max(1e-9)
    }

    /// The same render with its statistics turned into `T` (e.g. a study's own).
    pub fn map_stats<T>(self, f: impl FnOnce(S) -> T) -> RenderOutput<T> {
        RenderOutput {
            image: self.image,
            film: self.film,
            rays: self.rays,
            stats: f(self.stats),
            work_per_sample: self.work_per_sample,
            time: self.time,
            busy: self.busy,
        }
    }
}

/// A tile's camera samples in one pass.
enum TileSamples {
    /// Box filter: the mean of each pixel's samples, row-major over the tile.
    Means(Vec<[f32; 3]>),
    /// A wider filter: the samples splatted over the tile and the pixels around it.
    Splats(Film),
}

/// What one tile's render produced in one pass.
struct TileResult<S, O> {
    rect: PixelRect,
    samples: TileSamples,
    /// Work per camera sample, per pixel.
    work: Vec<f32>,
    counts: RayCounts,
    stats: S,
    observed: O,
    /// How long the tile took.
    took: Duration,
}

/// One pass of a render.
#[derive(Clone, Copy, Debug)]
struct Pass {
    /// Its samples per pixel.
    samples: u32,
    /// The rank in the render of its first sample of each pixel.
    first_sample: u32,
}

impl Pass {
    /// The seed of a pixel's generator in this pass, from the pixel's `own` seed: that
    /// seed for the samples from rank 0, mixed with the rank of the pass's first sample
    /// after it. (PCG streams of one seed are correlated, so passes take new seeds rather
    /// than new streams.)
    fn generator_seed(self, own: u64) -> u64 {
        if self.first_sample == 0 {
            own
        } else {
            let rank = self.first_sample as u64;
            ais::rng::mix64(own ^ rank.wrapping_mul(0x9E37_79B9_7F4A_7C15))
        }
    }
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
    let mut learned = integrator.new_learning(world);
    render_passes(world, integrator, settings, &mut learned, false)
}

/// [`render`], starting from what earlier renders of the same scene learned (`learned`)
/// and adding what this one learns: a progressive study's passes keep one field.
pub fn render_learning<I: SampleIntegrator>(
    world: &World,
    integrator: &I,
    settings: &RenderSettings,
    learned: &mut I::Learned,
) -> RenderOutput<<I::Tile as TileState>::Stats> {
    render_passes(world, integrator, settings, learned, true)
}

/// The passes of a render; what the last one observes is recorded only if
/// `learning_goes_on` (later renders use it).
fn render_passes<I: SampleIntegrator>(
    world: &World,
    integrator: &I,
    settings: &RenderSettings,
    learned: &mut I::Learned,
    learning_goes_on: bool,
) -> RenderOutput<<I::Tile as TileState>::Stats> {
    let (width, height) = (world.resolution.0 as usize, world.resolution.1 as usize);
    let region = settings.crop.unwrap_or(PixelRect::whole(width, height));
    // A filter wider than a pixel needs the samples of the pixels around the region too.
    let rendered = region.grown(world.filter.margin(), (width, height));
    let rects = tiles_of(rendered, (width, height));
    let mut passes = integrator.passes(world, settings.first_sample, settings.samples_per_pixel);
    let progress = progress_bar(rects.len() * passes.len(), settings.progress);
    let started = Instant::now();
    let mut busy = Duration::ZERO;
    let mut output = Accumulated::<<I::Tile as TileState>::Stats>::new(region, rendered);
    let mut index = 0;
    while index < passes.len() {
        let samples = passes[index];
        let pass = Pass {
            samples,
            first_sample: settings.first_sample + passes[..index].iter().sum::<u32>(),
        };
        // A render's own passes learn for the passes after them; its last pass learns only
        // for later renders, and only while the learning wants it.
        let learns = index + 1 < passes.len()
            || (learning_goes_on && learned.wants_observations(pass.first_sample));
        // Tiles are handed out one at a time: in runs of several, a thread could be left
        // with a run of costly tiles (a floor in shadow) while the others wait at the end.
        // Results come back in tile order whatever the threads did.
        let results: Vec<_> = rects
            .par_iter()
            .with_max_len(1)
            .map(|&rect| {
                let tile = Tile {
                    rect,
                    image: (width, height),
                    seed: settings.seed,
                    learns,
                };
                let result = render_tile(world, integrator, learned, pass, &tile);
                progress.inc(1);
                result
            })
            .collect();
        for result in results {
            busy += result.took;
            learned.merge(output.add(result, samples, settings.samples_per_pixel));
        }
        learned.end_pass(PassEnd {
            done: settings.first_sample + passes[..=index].iter().sum::<u32>(),
            left: (!learning_goes_on).then(|| passes[index + 1..].iter().sum()),
        });
        if index + 2 < passes.len() && !learned.keeps_learning() {
            // Learning cannot pay: the remaining samples in one last pass.
            let rest = passes[index + 1..].iter().sum();
            passes.truncate(index + 1);
            passes.push(rest);
            progress.set_length((rects.len() * passes.len()) as u64);
        }
        index += 1;
    }
    progress.finish_and_clear();
    RenderOutput {
        image: output.film.image_of(region),
        film: output.film,
        rays: output.rays,
        stats: output.stats,
        work_per_sample: output.work_per_sample,
        time: started.elapsed(),
        busy,
    }
}

/// The tiles of a `size` image that hold pixels of `rendered`, cut to it (each keeps its
/// place in the whole image's grid).
fn tiles_of(rendered: PixelRect, (width, height): (usize, usize)) -> Vec<PixelRect> {
    tiles(width, height)
        .iter()
        .filter_map(|tile| tile.intersection(&rendered))
        .collect()
}

/// The passes' results so far, over the rendered region.
struct Accumulated<S> {
    film: Film,
    rays: RayCounts,
    stats: S,
    work_per_sample: Vec<f32>,
    region: PixelRect,
}

impl<S: TileStats> Accumulated<S> {
    /// Sums for the pixels of `region`, from the samples of the pixels of `rendered`.
    fn new(region: PixelRect, rendered: PixelRect) -> Self {
        Accumulated {
            film: Film::covering(rendered),
            rays: RayCounts::default(),
            stats: S::default(),
            work_per_sample: vec![0.0; region.area()],
            region,
        }
    }

    /// Adds a tile's pass of `samples` of `spp` samples per pixel; returns its observations.
    fn add<O>(&mut self, result: TileResult<S, O>, samples: u32, spp: u32) -> O {
        self.rays.merge(result.counts);
        self.stats.merge(result.stats);
        let rect = result.rect;
        match &result.samples {
            TileSamples::Means(means) => {
                for ((x, y), &value) in rect.pixels().zip(means) {
                    self.film.add_weighted(x, y, value, samples as f64);
                }
            }
            TileSamples::Splats(film) => self.film.add_film(film),
        }
        let share = samples as f32 / spp.max(1) as f32;
        for ((x, y), work) in rect.pixels().zip(result.work) {
            // Pixels rendered around the region for a wide filter keep no work map.
            if !self.region.contains(x, y) {
                continue;
            }
            let (x, y) = (x - self.region.x0, y - self.region.y0);
            let slot = &mut self.work_per_sample[y * self.region.width() + x];
            *slot = if samples == spp {
                work
            } else {
                *slot + work * share
            };
        }
        result.observed
    }
}

/// Renders one pass of one tile with a fresh integrator state.
/// A pixel's camera samples: where each falls on the image, and its camera ray.
#[derive(Default)]
struct PixelRays {
    positions: Vec<[f32; 2]>,
    rays: Vec<Ray>,
}

impl PixelRays {
    /// The samples `ranks` of `pixel` in an image of `size`, in place of the last pixel's.
    fn fill(
        &mut self,
        world: &World,
        samples: &CameraSamples,
        pixel: (usize, usize),
        ranks: std::ops::Range<u32>,
        size: (usize, usize),
    ) {
        self.positions.clear();
        self.rays.clear();
        for rank in ranks {
            let [dx, dy] = samples.position(rank);
            let position = [pixel.0 as f32 + dx, pixel.1 as f32 + dy];
            let (u, v) = (position[0] / size.0 as f32, position[1] / size.1 as f32);
            self.rays.push(if world.camera.has_aperture() {
                world.camera.ray_through_lens(u, v, samples.lens(rank))
            } else {
                world.camera.ray(u, v)
            });
            self.positions.push(position);
        }
    }
}

fn render_tile<I: SampleIntegrator>(
    world: &World,
    integrator: &I,
    learned: &I::Learned,
    pass: Pass,
    tile: &Tile,
) -> TileResult<<I::Tile as TileState>::Stats, <I::Tile as TileState>::Observed> {
    let started = Instant::now();
    let mut counts = RayCounts::default();
    let mut state = integrator.begin_tile(world, tile, learned, &mut counts);
    let width = tile.image.0;
    let spp = pass.samples;
    let filter = world.filter;
    let mut means = Vec::with_capacity(tile.rect.area());
    let mut splats = (filter != ReconstructionFilter::Box)
        .then(|| Film::covering(tile.rect.grown(filter.margin(), tile.image)));
    let mut work = Vec::with_capacity(tile.rect.area());
    let (mut samples, mut values) = (PixelRays::default(), Vec::new());
    for (x, y) in tile.rect.pixels() {
        let own = pixel_seed(tile.seed, x, y, width);
        let mut rng = Pcg32::new(pass.generator_seed(own), 0);
        let work_before = state.work();
        state.begin_pixel(x, y);
        let mut sum = [0.0f64; 3];
        // The pixel's camera rays first, then their values all together (an integrator
        // may make some of their work together), then the film in the samples' order.
        let ranks = pass.first_sample..pass.first_sample + spp;
        samples.fill(world, &CameraSamples::new(own), (x, y), ranks, tile.image);
        values.clear();
        let rays = &samples.rays;
        integrator.pixel_radiance(world, rays, &mut rng, &mut state, &mut counts, &mut values);
        for (&value, &position) in values.iter().zip(&samples.positions) {
            state.sampled(value);
            match splats.as_mut() {
                Some(film) => film.splat(&filter, position, value),
                None => {
                    for (s, c) in sum.iter_mut().zip(value) {
                        *s += c as f64;
                    }
                }
            }
        }
        if splats.is_none() {
            means.push(sum.map(|s| (s / spp as f64) as f32));
        }
        work.push((state.work() - work_before) as f32 / spp as f32);
    }
    let observed = state.take_observed();
    TileResult {
        rect: tile.rect,
        samples: splats.map_or(TileSamples::Means(means), TileSamples::Splats),
        work,
        counts,
        stats: state.finish(),
        observed,
        took: started.elapsed(),
    }
}
