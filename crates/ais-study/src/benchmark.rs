//! `ais bench`: BVH build time and closest-hit / occlusion throughput on the default scene,
//! for camera rays and for 256-ray gathers at the first hit, at several thread counts.
//! Each figure is the median of several runs measured in one process.

use ais::rng::Pcg32;
use ais::sampling::cosine_hemisphere;
use ais_render::default_scene::default_world;
use ais_render::geometry::{basis, spawn_ray, Geometry, Hit};
use ais_render::world::World;
use rayon::prelude::*;
use std::time::Instant;

/// One measured row.
#[derive(Clone, Debug)]
pub struct BenchRow {
    /// What was measured.
    pub name: String,
    /// Threads used.
    pub threads: usize,
    /// Median rays per second (or builds per second for the BVH row).
    pub rays_per_second: f64,
    /// Median wall time of one run, in seconds.
    pub seconds: f64,
}

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

/// Camera rays of a `width × height` image, one per pixel centre.
fn camera_rays(world: &World) -> Vec<ais_render::geometry::Ray> {
    let (w, h) = world.resolution;
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            world
                .camera
                .ray((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32)
        })
        .collect()
}

/// Runs `work` (which returns rays traced) `runs` times on a pool of `threads`.
fn measure(threads: usize, runs: usize, work: impl Fn() -> u64 + Sync) -> (f64, f64) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    let mut rates = Vec::new();
    let mut times = Vec::new();
    for _ in 0..runs {
        let started = Instant::now();
        let rays = pool.install(&work);
        let seconds = started.elapsed().as_secs_f64();
        rates.push(rays as f64 / seconds);
        times.push(seconds);
    }
    (median(rates), median(times))
}

/// What `ais bench` measures.
#[derive(Clone, Debug)]
pub struct BenchSettings {
    /// Image size whose pixel-centre camera rays are traced, `(width, height)`.
    pub resolution: (u32, u32),
    /// Thread counts to measure.
    pub thread_counts: Vec<usize>,
    /// Runs per measurement (the median is reported).
    pub runs: usize,
    /// Rays per gather.
    pub gather_rays: u32,
}

/// The median BVH build time of the default scene over `runs` builds, and the last world.
fn bvh_row(settings: &BenchSettings) -> (BenchRow, World) {
    let (width, height) = settings.resolution;
    let mut build_times = Vec::new();
    let mut world = default_world(width, height);
    for _ in 0..settings.runs {
        world = default_world(width, height);
        build_times.push(world.geometry.build_time().as_secs_f64());
    }
    let row = BenchRow {
        name: format!("BVH build ({} triangles)", world.geometry.triangle_count()),
        threads: rayon::current_num_threads(),
        rays_per_second: 0.0,
        seconds: median(build_times),
    };
    (row, world)
}

/// Cosine-distributed gathers of `rays` rays from every hit, closest-hit or occlusion
/// queries; returns the rays traced.
fn trace_gathers(geometry: &Geometry, hits: &[Hit], rays: u32, closest: bool) -> u64 {
    hits.par_iter()
        .enumerate()
        .map(|(i, hit)| {
            let mut rng = Pcg32::new(i as u64, 3);
            let n = hit.geometric_normal;
            let (t, b) = basis(n);
            for _ in 0..rays {
                let l = cosine_hemisphere([rng.next_f32(), rng.next_f32()]);
                let d = (t * l.x + b * l.y + n * l.z).normalize();
                let ray = spawn_ray(hit.point, n, d);
                if closest {
                    std::hint::black_box(geometry.intersect(&ray));
                } else {
                    std::hint::black_box(geometry.occluded(&ray));
                }
            }
            rays as u64
        })
        .sum()
}

/// Measures the default scene for each thread count.
pub fn run(settings: &BenchSettings) -> Vec<BenchRow> {
    let (bvh, world) = bvh_row(settings);
    let mut rows = vec![bvh];
    let rays = camera_rays(&world);
    let geometry: &Geometry = &world.geometry;
    // First hits, for the gathers.
    let hits: Vec<Hit> = rays.iter().filter_map(|r| geometry.intersect(r)).collect();
    let runs = settings.runs;
    for &threads in &settings.thread_counts {
        let mut row = |name: String, (rate, seconds): (f64, f64)| {
            rows.push(BenchRow {
                name,
                threads,
                rays_per_second: rate,
                seconds,
            })
        };
        row(
            "camera rays, closest hit".into(),
            measure(threads, runs, || {
                rays.par_iter()
                    .filter(|r| geometry.intersect(r).is_some())
                    .count();
                rays.len() as u64
            }),
        );
        row(
            "camera rays, occlusion".into(),
            measure(threads, runs, || {
                rays.par_iter().filter(|r| geometry.occluded(r)).count();
                rays.len() as u64
            }),
        );
        for (closest, kind) in [(true, "closest hit"), (false, "occlusion")] {
            let n = settings.gather_rays;
            row(
                format!("{n}-ray gathers (cosine), {kind}"),
                measure(threads, runs, || trace_gathers(geometry, &hits, n, closest)),
            );
        }
    }
    rows
}
