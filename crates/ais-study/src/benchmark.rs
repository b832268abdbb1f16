//! `ais bench`: BVH build time and closest-hit / occlusion throughput on the default scene,
//! for camera rays and for 256-ray gathers at the first hit, at several thread counts.
//! Each figure is the median of several runs measured in one process.

use ais::rng::Pcg32;
use ais::sampling::cosine_hemisphere;
use ais_render::default_scene::default_world;
use ais_render::geometry::{basis, spawn_ray, Geometry};
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

/// Measures the default scene at `width × height`, for each thread count, `runs` times.
pub fn run(
    width: u32,
    height: u32,
    thread_counts: &[usize],
    runs: usize,
    gather_rays: u32,
) -> Vec<BenchRow> {
    let mut rows = Vec::new();
    let mut build_times = Vec::new();
    let mut world = default_world(width, height);
    for _ in 0..runs {
        world = default_world(width, height);
        build_times.push(world.geometry.build_time().as_secs_f64());
    }
    rows.push(BenchRow {
        name: format!("BVH build ({} triangles)", world.geometry.triangle_count()),
        threads: rayon::current_num_threads(),
        rays_per_second: 0.0,
        seconds: median(build_times),
    });
    let rays = camera_rays(&world);
    let geometry: &Geometry = &world.geometry;
    // First hits, for the gathers.
    let hits: Vec<_> = rays.iter().filter_map(|r| geometry.intersect(r)).collect();
    for &threads in thread_counts {
        let (rate, seconds) = measure(threads, runs, || {
            rays.par_iter()
                .filter(|r| geometry.intersect(r).is_some())
                .count();
            rays.len() as u64
        });
        rows.push(BenchRow {
            name: "camera rays, closest hit".into(),
            threads,
            rays_per_second: rate,
            seconds,
        });
        let (rate, seconds) = measure(threads, runs, || {
            rays.par_iter().filter(|r| geometry.occluded(r)).count();
            rays.len() as u64
        });
        rows.push(BenchRow {
            name: "camera rays, occlusion".into(),
            threads,
            rays_per_second: rate,
            seconds,
        });
        for closest in [true, false] {
            let (rate, seconds) = measure(threads, runs, || {
                hits.par_iter()
                    .enumerate()
                    .map(|(i, hit)| {
                        let mut rng = Pcg32::new(i as u64, 3);
                        let n = hit.geometric_normal;
                        let (t, b) = basis(n);
                        for _ in 0..gather_rays {
                            let l = cosine_hemisphere([rng.next_f32(), rng.next_f32()]);
                            let d = (t * l.x + b * l.y + n * l.z).normalize();
                            let ray = spawn_ray(hit.point, n, d);
                            if closest {
                                std::hint::black_box(geometry.intersect(&ray));
                            } else {
                                std::hint::black_box(geometry.occluded(&ray));
                            }
                        }
                        gather_rays as u64
                    })
                    .sum::<u64>()
            });
            rows.push(BenchRow {
                name: format!(
                    "{gather_rays}-ray gathers (cosine), {}",
                    if closest { "closest hit" } else { "occlusion" }
                ),
                threads,
                rays_per_second: rate,
                seconds,
            });
        }
    }
    rows
}
