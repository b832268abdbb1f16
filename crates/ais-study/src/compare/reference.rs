//! The converged reference of a study, cached on disk by a hash of what determines it.

use super::metrics::{weighted_mse, PixelWeight};
use ais_render::film::Film;
use ais_render::image_io::{read_image, write_exr, RgbImage};
use ais_render::integrators::gather::{GatherSettings, Preset, Strategy};
use ais_render::integrators::Integrator;
use ais_render::render::{render, RenderSettings};
use ais_render::world::World;
use indicatif::ProgressBar;
use std::path::{Path, PathBuf};

/// Samples per pixel rendered per progress step.
const CHUNK: u32 = 8;

/// FNV-1a, 64 bits: a stable hash for cache keys (std's hasher may change between releases).
pub fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |hash, &b| {
        (hash ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// A converged reference and the variance of its own pixels, so that relMSE can be
/// corrected for the reference's remaining noise.
#[derive(Clone, Debug)]
pub struct Reference {
    /// The mean of two independent halves.
    pub image: RgbImage,
    /// Per pixel and channel, the estimated variance of `image`: (A − B)² / 4 for halves A, B.
    pub variance: Vec<[f32; 3]>,
    /// Whether it came from the cache.
    pub cached: bool,
}

impl Reference {
    /// relMSE of `image` against the reference, minus the part that the reference's own
    /// noise adds on average: E[(X − R)²] = E[(X − μ)²] + Var R for an independent R.
    pub fn rel_mse(&self, image: &RgbImage) -> f64 {
        self.error(image, PixelWeight::Relative)
    }

    /// The error of `image` against the reference with pixels weighed by `weight`, minus the
    /// part that the reference's own noise adds on average (as [`Reference::rel_mse`]).
    pub fn error(&self, image: &RgbImage, weight: PixelWeight) -> f64 {
        weighted_mse(image, &self.image, weight) - self.noise_floor_weighed(weight)
    }

    /// The relMSE that the reference's own noise adds on average (what
    /// [`Reference::rel_mse`] removes).
    pub fn noise_floor(&self) -> f64 {
        self.noise_floor_weighed(PixelWeight::Relative)
    }

    /// The error with pixels weighed by `weight` that the reference's own noise adds on
    /// average.
    pub fn noise_floor_weighed(&self, weight: PixelWeight) -> f64 {
        let noise: f64 = self
            .image
            .pixels
            .iter()
            .zip(&self.variance)
            .map(|(r, v)| {
                (0..3)
                    .map(|c| v[c] as f64 * weight.of(r[c] as f64))
                    .sum::<f64>()
            })
            .sum();
        noise / (3 * self.variance.len().max(1)) as f64
    }
}

/// Where the halves of the reference for `key` are cached in `cache`.
pub fn cache_paths(cache: &Path, key: &str) -> [PathBuf; 2] {
    let hash = fnv1a(key.as_bytes());
    [
        cache.join(format!("reference-{hash:016x}-a.exr")),
        cache.join(format!("reference-{hash:016x}-b.exr")),
    ]
}

fn render_half(
    world: &World,
    settings: GatherSettings,
    spp: u32,
    seed: u64,
    progress: &ProgressBar,
) -> RgbImage {
    let (width, height) = (world.resolution.0 as usize, world.resolution.1 as usize);
    // The chunks' films add up to the film of one render of all their samples.
    let mut film = Film::new(width, height);
    let mut done = 0;
    while done < spp {
        let chunk = CHUNK.min(spp - done);
        let output = render(
            world,
            &Integrator::Gather(settings),
            &RenderSettings {
                samples_per_pixel: chunk,
                seed,
                first_sample: done,
                progress: false,
                crop: None,
            },
        );
        film.add_film(&output.film);
        done += chunk;
        progress.inc(chunk as u64);
    }
    film.image()
}

/// The reference: the gather with MIS and AIS off at `spp` samples per pixel (two
/// independent halves), read from `paths` when an earlier study wrote it there.
pub fn reference(
    world: &World,
    gather: &GatherSettings,
    spp: u32,
    paths: &[PathBuf; 2],
    progress: &ProgressBar,
) -> Result<Reference, String> {
    let (width, height) = (world.resolution.0 as usize, world.resolution.1 as usize);
    let cached: Vec<RgbImage> = paths
        .iter()
        .filter_map(|p| read_image(p).ok())
        .map(|l| l.image)
        .filter(|i| (i.width, i.height) == (width, height))
        .collect();
    let (halves, was_cached) = if cached.len() == 2 {
        (cached, true)
    } else {
        let settings = GatherSettings {
            strategy: Strategy::Mis,
            ..gather.with_preset(Preset::Off)
        };
        let half = spp.div_ceil(2);
        progress.set_length(2 * half as u64);
        let halves = vec![
            render_half(world, settings, half, 0x5eed_a000_0000, progress),
            render_half(world, settings, half, 0x5eed_b000_0000, progress),
        ];
        for (path, image) in paths.iter().zip(&halves) {
            if let Some(folder) = path.parent() {
                std::fs::create_dir_all(folder)
                    .map_err(|e| format!("{}: cannot create the cache: {e}", folder.display()))?;
            }
            write_exr(path, image).map_err(|e| e.to_string())?;
        }
        (halves, false)
    };
    let (a, b) = (&halves[0], &halves[1]);
    Ok(Reference {
        image: RgbImage {
            width,
            height,
            pixels: a
                .pixels
                .iter()
                .zip(&b.pixels)
                .map(|(x, y)| [0, 1, 2].map(|c| 0.5 * (x[c] + y[c])))
                .collect(),
        },
        variance: a
            .pixels
            .iter()
            .zip(&b.pixels)
            .map(|(x, y)| [0, 1, 2].map(|c| 0.25 * (x[c] - y[c]).powi(2)))
            .collect(),
        cached: was_cached,
    })
}
