//! `ais compare`: a study of gather configurations on one scene, with an HTML report.

use crate::gather_flags::{configuration, GatherFlags};
use crate::{load_world, parse_resolution, start_threads, SceneFlags, SceneRequest, ThreadFlags};
use ais_render::integrators::gather::{Acceptance, GatherSettings, Preset, Strategy};
use ais_study::compare::report::{self, ReportContext};
use ais_study::compare::{reference, talk_configurations, Configuration, StudySettings};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Duration;

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

/// A configuration's settings: a preset's name, or name=value words.
fn configuration_settings(base: &GatherSettings, text: &str) -> Result<GatherSettings, String> {
    match Preset::parse(text.trim()) {
        Some(preset) => Ok(base.with_preset(preset)),
        None if text.contains('=') => configuration(base, text),
        None => Err(format!(
            "\"{text}\" is neither an AIS preset (off, aggressive, conservative, shared, warm, \
             guided) nor name=value words"
        )),
    }
}

/// The configurations: the talk's, or every given strategy × configuration plus the oracle.
fn configurations(args: &CompareArgs, base: GatherSettings) -> Result<Vec<Configuration>, String> {
    if args.strategies.is_empty() && args.configs.is_empty() {
        return Ok(talk_configurations(base));
    }
    let strategies = if args.strategies.is_empty() {
        vec!["mis".to_string()]
    } else {
        args.strategies.clone()
    };
    let configs = if args.configs.is_empty() {
        vec!["off".to_string(), "aggressive".to_string()]
    } else {
        args.configs.clone()
    };
    let mut list = Vec::new();
    for strategy_name in &strategies {
        let strategy = Strategy::parse(strategy_name).ok_or_else(|| {
            format!("unknown strategy \"{strategy_name}\" (uniform, bsdf, light, mis)")
        })?;
        for text in &configs {
            let settings = configuration_settings(&GatherSettings { strategy, ..base }, text)?;
            let name = format!("{strategy_name}-{}", text.trim().replace([' ', '='], "-"));
            list.push(Configuration::new(&name, &name, settings));
        }
    }
    if args.no_oracle {
        return Ok(list);
    }
    let first = list[0].settings;
    list.push(Configuration::oracle(
        &format!("{}-oracle", strategies[0]),
        "oracle: the first strategy restricted to directions that bring light",
        GatherSettings {
            acceptance: Acceptance::Affinity,
            ..first.with_preset(Preset::Off)
        },
    ));
    Ok(list)
}

/// The key of the cached reference: the scene file's hash, the defines, the size and the
/// reference's settings.
fn reference_key(
    args: &CompareArgs,
    (width, height): (u32, u32),
    rays: u32,
) -> Result<String, String> {
    let scene_identity = match &args.scene {
        Some(path) => {
            let bytes = std::fs::read(path)
                .map_err(|e| format!("{}: cannot read the scene: {e}", path.display()))?;
            format!("{:016x}", reference::fnv1a(&bytes))
        }
        None => "built-in default scene".into(),
    };
    Ok(format!(
        "{scene_identity}|{:?}|{width}x{height}|{}|{}|{}|{}",
        args.scene_flags.define,
        args.reference_spp,
        rays,
        env!("CARGO_PKG_VERSION"),
        "reference v2"
    ))
}

/// The pixel of the affinity-map figure: the flag's, else the image centre.
fn figure_pixel(args: &CompareArgs, (width, height): (u32, u32)) -> Result<(u32, u32), String> {
    let pixel = args.pixel.unwrap_or((width / 2, height / 2));
    if pixel.0 >= width || pixel.1 >= height {
        return Err(format!(
            "--pixel {},{} is outside the {width}×{height} image",
            pixel.0, pixel.1
        ));
    }
    Ok(pixel)
}

/// Checks the flags that need no scene.
fn check_arguments(args: &CompareArgs) -> Result<(), String> {
    if !(args.time_budget > 0.0 && args.time_budget.is_finite()) {
        return Err("--time-budget must be a positive number of seconds".into());
    }
    if args.seeds == 0 || args.reference_spp == 0 || args.pass_spp == 0 {
        return Err("--seeds, --reference-spp and --pass-spp must be at least 1".into());
    }
    Ok(())
}

/// `ais compare`.
pub fn run(args: CompareArgs) -> Result<(), String> {
    start_threads(args.threads)?;
    check_arguments(&args)?;
    let world = load_world(&SceneRequest {
        scene: args.scene.as_deref(),
        flags: &args.scene_flags,
        resolution: args.resolution,
        default_resolution: (320, 180),
    })?;
    let base = args.gather.settings(&world, args.scene_flags.strict)?;
    let pixel = figure_pixel(&args, world.resolution)?;
    let key = reference_key(&args, world.resolution, base.rays)?;
    let settings = StudySettings {
        configurations: configurations(&args, base)?,
        time_budget: Duration::from_secs_f64(args.time_budget),
        seeds: args.seeds,
        reference_spp: args.reference_spp,
        pass_spp: args.pass_spp,
        reference_cache: Some(reference::cache_paths(&args.output.join("cache"), &key)),
        figure_pixel: pixel,
        progress: !args.quiet && std::io::stderr().is_terminal(),
    };
    if !args.quiet {
        let runs = settings.configurations.len() * 2 - 1;
        eprintln!(
            "studying {} configurations × {} seeds (about {:.0} s after the reference)…",
            settings.configurations.len(),
            args.seeds,
            runs as f64 * args.seeds as f64 * args.time_budget
        );
    }
    let results = ais_study::compare::run(&world, &settings)?;
    let scene_name = args
        .scene
        .as_ref()
        .map_or("the built-in default scene".into(), |p| {
            p.display().to_string()
        });
    let context = ReportContext {
        scene: &scene_name,
        resolution: world.resolution,
        rays: base.rays,
        time_budget: args.time_budget,
        seeds: args.seeds,
        reference_spp: args.reference_spp,
        threads: rayon::current_num_threads(),
        figure_pixel: pixel,
    };
    let path = report::write(&args.output, &results, &context)?;
    println!("{}", report::markdown_tables(&results, &context));
    println!("report       {}", path.display());
    Ok(())
}
