//! `ais bench`: BVH build time and ray throughput on the built-in default scene.

use crate::parse_resolution;

#[derive(clap::Args)]
pub struct BenchArgs {
    /// Image size whose pixel-centre camera rays are traced (gathers start at their hits).
    #[arg(long, value_parser = parse_resolution, default_value = "320x180")]
    resolution: (u32, u32),
    /// Thread counts to measure.
    #[arg(long, value_delimiter = ',', default_value = "1,2")]
    threads: Vec<usize>,
    /// Runs per measurement (the median is reported).
    #[arg(long, default_value_t = 5)]
    runs: usize,
    /// Rays per gather.
    #[arg(long, default_value_t = 256)]
    gather_rays: u32,
}

pub fn run(args: BenchArgs) -> Result<(), String> {
    if args.runs == 0 || args.threads.contains(&0) || args.gather_rays == 0 {
        return Err("--runs, --threads and --gather-rays must be positive".into());
    }
    eprintln!("measuring {} runs each; this takes a minute…", args.runs);
    let rows = ais_study::benchmark::run(&ais_study::benchmark::BenchSettings {
        resolution: args.resolution,
        thread_counts: args.threads.clone(),
        runs: args.runs,
        gather_rays: args.gather_rays,
    });
    println!("| measurement | threads | median time (s) | median rays/s |");
    println!("|---|---|---|---|");
    for row in rows {
        let rate = if row.rays_per_second > 0.0 {
            format!("{:.2} M", row.rays_per_second / 1e6)
        } else {
            "—".into()
        };
        println!(
            "| {} | {} | {:.3} | {rate} |",
            row.name, row.threads, row.seconds
        );
    }
    Ok(())
}
