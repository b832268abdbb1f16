//! Gathers direct light at a point of an analytic scene with AIS off and on, and prints the
//! estimate, the exact value, and where the candidates went.
//!
//! Run: `cargo run --release -p ais --example gather -- [--scene open|courtyard|window35|window10] [--rays N] [--batches B]`

use ais::analytic::{AnalyticGather, GatherTarget, Moments, Proposal, Scene};
use ais::{Batch, BatchConfig, MapStart, Mode};

fn parse_args() -> Result<(Scene, u32, u32), String> {
    let (mut scene, mut rays, mut batches) = (Scene::window(0.10), 256u32, 2_000u32);
    let mut args = std::env::args().skip(1);
    while let Some(flag) = args.next() {
        let value = args.next().ok_or(format!("{flag} needs a value"))?;
        match flag.as_str() {
            "--scene" => {
                scene = match value.as_str() {
                    "open" => Scene::open(),
                    "courtyard" => Scene::courtyard(),
                    "window35" => Scene::window(0.35),
                    "window10" => Scene::window(0.10),
                    other => {
                        return Err(format!(
                            "unknown scene {other:?}: use open, courtyard, window35 or window10"
                        ))
                    }
                }
            }
            "--rays" => {
                rays = value
                    .parse()
                    .ok()
                    .filter(|&n| n >= 1)
                    .ok_or("--rays needs a positive integer")?
            }
            "--batches" => {
                batches = value
                    .parse()
                    .ok()
                    .filter(|&n| n >= 2)
                    .ok_or("--batches needs an integer of at least 2")?
            }
            other => return Err(format!("unknown flag {other:?}")),
        }
    }
    Ok((scene, rays, batches))
}

/// Runs `batches` batches of `config` and prints a row of the table.
fn print_mode(name: &str, config: BatchConfig, job: &AnalyticGather, batches: u32) {
    let exact = job.scene.exact();
    let mut batch: Batch<f64> = Batch::new(config).expect("valid configuration");
    let (mut moments, mut squared_error) = (Moments::default(), 0.0);
    for seed in 0..batches {
        let estimate = job.run(&mut batch, seed as u64, MapStart::Empty);
        moments.add(estimate.value);
        squared_error += (estimate.value - exact).powi(2);
    }
    let count = batches as f64;
    let (mean, standard_error) = (moments.mean(), moments.standard_error());
    let stats = batch.stats();
    println!(
        "{:<24} {:>10.6} {:>9.6} {:>+8.2} {:>11.4} {:>9.1} {:>9.1} {:>9.1} {:>10}",
        name,
        mean,
        standard_error,
        (mean - exact) / standard_error,
        (squared_error / count).sqrt() / exact,
        stats.traced as f64 / count,
        stats.rejected() as f64 / count,
        stats.dropped as f64 / count,
        batch.map().map_or(0, |m| m.memory_bytes()),
    );
}

fn main() {
    let (scene, rays, batches) = parse_args().unwrap_or_else(|message| {
        eprintln!("error: {message}");
        std::process::exit(2);
    });
    println!(
        "scene {}: {:.0}% of the cosine-weighted hemisphere visible, exact integral {:.6}",
        scene.name(),
        scene.visible_cosine_fraction() * 100.0,
        scene.exact()
    );
    println!("{batches} batches of {rays} rays each, cosine proposal\n");
    println!(
        "{:<24} {:>10} {:>9} {:>8} {:>11} {:>9} {:>9} {:>9} {:>10}",
        "mode",
        "estimate",
        "± 1 SE",
        "z",
        "rel. RMSE",
        "traced",
        "rejected",
        "dropped",
        "map bytes"
    );
    let conservative = BatchConfig {
        affinity: Some(ais::MapConfig {
            mode: Mode::Conservative,
            ..ais::MapConfig::default()
        }),
        ..BatchConfig::default()
    };
    let job = AnalyticGather {
        scene: &scene,
        proposal: Proposal::CosineHemisphere,
        n: rays,
        target: GatherTarget::Normal,
    };
    print_mode("off", BatchConfig::off(), &job, batches);
    print_mode(
        "aggressive (default)",
        BatchConfig::default(),
        &job,
        batches,
    );
    print_mode("conservative", conservative, &job, batches);
    println!("\nper batch: traced = rays traced, rejected = skipped untraced (outside support or by roulette).");
    println!("rel. RMSE is per batch; lower is better at similar traced counts.");
}
