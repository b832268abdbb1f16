//! `ais compare`: a study of gather configurations on one scene, with an HTML report.

use crate::gather_flags::GatherFlags;
use crate::{load_world, parse_resolution, start_threads, SceneFlags, SceneRequest, ThreadFlags};
use ais_study::compare::request::CompareRequest;
use std::io::IsTerminal;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct CompareArgs {
    /// The scene file (Mitsuba 3 XML). Omit it to study the built-in default scene.
    scene: Option<PathBuf>,
    /// The report's folder (index.html, tables.md, images/, cache/).
    #[arg(short, long, default_value = "report")]
    output: PathBuf,
    /// Wall time of each equal-time run, in seconds.
    #[arg(long, default_value_t = 3.0)]
    time_budget: f64,
    /// Independent runs per configuration and budget (for error bars).
    #[arg(long, default_value_t = 3)]
    seeds: u32,
    /// Proposals to compare (uniform, bsdf, light, mis); with --configs, replaces the talk's
    /// set of configurations by every strategy × configuration (and the oracle).
    #[arg(long, value_delimiter = ',')]
    strategies: Vec<String>,
    /// Configurations to compare, each an AIS preset (off, aggressive, conservative, shared,
    /// warm, guided) or gather parameters as name=value words applied over the base settings,
    /// e.g. "ais=shared acceptance=efficient sharing=pass:8"; see --strategies. The first is
    /// the baseline of the ratios.
    #[arg(long, value_delimiter = ',')]
    configs: Vec<String>,
    /// Leave out the oracle (with --configs; it traces every candidate, so it is slow).
    #[arg(long)]
    no_oracle: bool,
    /// The base settings of every configuration (and of the reference's rays).
    #[command(flatten)]
    gather: GatherFlags,
    /// Film size (default: the scene's; 320x180 for the default scene).
    #[arg(long, value_parser = parse_resolution)]
    resolution: Option<(u32, u32)>,
    /// Samples per pixel of the reference (cached in the report's cache/ folder).
    #[arg(long, default_value_t = 256)]
    reference_spp: u32,
    /// Samples per pixel of each progressive pass (one render call; per-render costs such as
    /// the learning pass of shared maps are spread over them).
    #[arg(long, default_value_t = 1)]
    pass_spp: u32,
    /// The pixel of the affinity-map figure, x,y (default: the image centre).
    #[arg(long, value_parser = parse_pixel)]
    pixel: Option<(u32, u32)>,
    #[command(flatten)]
    threads: ThreadFlags,
    /// No progress bars.
    #[arg(short, long)]
    quiet: bool,
    #[command(flatten)]
    scene_flags: SceneFlags,
}

fn parse_pixel(text: &str) -> Result<(u32, u32), String> {
    let (x, y) = text
        .split_once(',')
        .ok_or_else(|| format!("\"{text}\" is not x,y"))?;
    let parse = |s: &str| {
        s.trim()
            .parse::<u32>()
            .map_err(|_| format!("\"{s}\" is not a pixel coordinate"))
    };
    Ok((parse(x)?, parse(y)?))
}

/// `ais compare`.
pub fn run(args: CompareArgs) -> Result<(), String> {
    start_threads(args.threads)?;
    let world = load_world(&SceneRequest {
        scene: args.scene.as_deref(),
        flags: &args.scene_flags,
        resolution: args.resolution,
        default_resolution: (320, 180),
    })?;
    let base = args.gather.settings(&world, args.scene_flags.strict)?;
    let request = CompareRequest {
        scene: args.scene.as_deref(),
        defines: &args.scene_flags.define,
        output: &args.output,
        time_budget: args.time_budget,
        seeds: args.seeds,
        strategies: &args.strategies,
        configs: &args.configs,
        oracle: !args.no_oracle,
        reference_spp: args.reference_spp,
        pass_spp: args.pass_spp,
        pixel: args.pixel,
        progress: !args.quiet && std::io::stderr().is_terminal(),
    };
    let settings = request.settings(&world, base)?;
    if !args.quiet {
        let runs = settings.configurations.len() * 2 - 1;
        eprintln!(
            "studying {} configurations × {} seeds (about {:.0} s after the reference)…",
            settings.configurations.len(),
            args.seeds,
            runs as f64 * args.seeds as f64 * args.time_budget
        );
    }
    let comparison = request.run(&world, &settings)?;
    println!("{}", comparison.tables);
    println!("report       {}", comparison.report.display());
    Ok(())
}
