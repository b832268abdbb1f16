//! The `ais` command.

use ais_render::default_scene::default_world;
use ais_render::gather::{Acceptance, AisMode, GatherSettings, RayBudget, Sharing};
use ais_render::image_io::RgbImage;
use ais_render::image_io::{write_exr, write_png};
use ais_render::integrator::Integrator;
use ais_render::proposal::Strategy;
use ais_render::render::{render, RenderSettings};
use ais_render::scene::load_scene;
use ais_render::world::World;
use clap::{Parser, Subcommand, ValueEnum};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

mod compare;

/// Adaptive importance sampling for multi-ray gathering: a renderer for studying it.
#[derive(Parser)]
#[command(name = "ais", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a Mitsuba 3 XML scene, or the built-in default scene when none is given.
    Render(Box<RenderArgs>),
    /// Measure BVH build time and ray throughput on the built-in default scene.
    Bench(BenchArgs),
    /// Compare gather configurations (the talk's by default) at equal time and equal rays
    /// against a converged reference, and write an HTML report.
    Compare(Box<compare::CompareArgs>),
}

#[derive(clap::Args)]
struct BenchArgs {
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

fn run_bench(args: BenchArgs) -> Result<(), String> {
    if args.runs == 0 || args.threads.contains(&0) || args.gather_rays == 0 {
        return Err("--runs, --threads and --gather-rays must be positive".into());
    }
    let (width, height) = args.resolution;
    eprintln!("measuring {} runs each; this takes a minute…", args.runs);
    let rows =
        ais_render::benchmark::run(width, height, &args.threads, args.runs, args.gather_rays);
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

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum IntegratorChoice {
    /// Direct light gathered with `--rays` rays per camera sample through the AIS driver.
    Gather,
    /// Ambient occlusion (cosine-weighted, bounded distance).
    Ao,
    /// Shading normals as colours.
    Normals,
}

#[derive(clap::Args)]
struct RenderArgs {
    /// The scene file (Mitsuba 3 XML). Omit it to render the built-in default scene.
    scene: Option<PathBuf>,
    /// Output EXR (32-bit float RGB); a tone-mapped PNG preview is written beside it.
    #[arg(short, long, default_value = "ais.exr")]
    output: PathBuf,
    /// Samples per pixel (default: the scene's sample_count; 4 for the default scene).
    #[arg(long)]
    spp: Option<u32>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Override the film size, e.g. 640x360.
    #[arg(long, value_parser = parse_resolution)]
    resolution: Option<(u32, u32)>,
    /// What to render (default: the scene's `<integrator type="gather">`, else gather).
    #[arg(long, value_enum)]
    integrator: Option<IntegratorChoice>,
    /// Gather proposal: uniform, bsdf, light or mis.
    #[arg(long)]
    strategy: Option<String>,
    /// AIS mode: off, aggressive, conservative (the talk's per-batch maps), shared (fixed
    /// maps blended from neighbouring gather points), warm (that map as a warm start, then
    /// per-batch learning), guided (the shared map folded into the
    /// proposal: nothing rejected), or oracle (a bound for studies: the
    /// proposal restricted to directions that bring light, found by free brute-force tests).
    /// Append +sqrt (accept with √affinity), or +value or +efficient for value-aware
    /// acceptance (e.g. shared+efficient); then @tile or @pass[:S] for where shared maps
    /// come from (see --sharing; e.g. shared@pass).
    #[arg(long)]
    ais: Option<String>,
    /// Acceptance rule: affinity (the talk's), sqrt (√affinity), value (always trace
    /// candidates worth over twice the batch's mean) or efficient (√affinity · value / mean).
    #[arg(long)]
    acceptance: Option<String>,
    #[command(flatten)]
    batch: BatchArgs,
    /// Candidate placement: halton (scrambled per batch) or random.
    #[arg(long)]
    placement: Option<String>,
    /// Also write the mean traced gather rays per camera sample, per pixel, to this EXR.
    #[arg(long)]
    aov_traced: Option<PathBuf>,
    /// Ambient-occlusion rays per camera sample.
    #[arg(long, default_value_t = 16)]
    ao_rays: u32,
    /// Ambient-occlusion distance in world units (default: a fifth of the scene's extent
    /// is not known here, so 1.0).
    #[arg(long, default_value_t = 1.0)]
    ao_distance: f32,
    /// Exposure of the PNG preview, in stops.
    #[arg(long, default_value_t = 0.0)]
    exposure: f32,
    /// Base random seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Skip the PNG preview.
    #[arg(long)]
    no_preview: bool,
    /// No progress bar.
    #[arg(short, long)]
    quiet: bool,
    /// Set a scene $parameter: -D name=value (repeatable).
    #[arg(short = 'D', value_parser = parse_define)]
    define: Vec<(String, String)>,
}

/// The batch and map flags that `render` and `compare` share (None: not given).
#[derive(clap::Args, Clone, Default)]
struct BatchArgs {
    /// Rays per gather (n).
    #[arg(long)]
    rays: Option<u32>,
    /// Affinity-map tol (a_min = 1/(tol·h²)); "inf" for no floor.
    #[arg(long)]
    tol: Option<f32>,
    /// Affinity-map height in texels (width is twice this).
    #[arg(long)]
    map_res: Option<u32>,
    /// Guided gathers: the guide's share of the proposal mixture, in [0, 0.99].
    #[arg(long)]
    guide_fraction: Option<f32>,
    /// What --rays counts: traced (AIS draws extra candidates to trace about that many) or
    /// candidates (AIS traces only the accepted ones: cheaper gathers).
    #[arg(long)]
    budget: Option<String>,
    /// Where shared, warm and guided gathers find their neighbours' maps: tile (the gathers
    /// before them in their tile's order) or pass (a learning pass of AIS-off gathers, one
    /// per 4×4 pixels, around each tile; pass:S for S×S blocks, S in 1..=16).
    #[arg(long)]
    sharing: Option<String>,
}

/// Gather flags given on the command line (None: not given).
#[derive(Default)]
struct GatherFlags {
    strategy: Option<String>,
    ais: Option<String>,
    placement: Option<String>,
    batch: BatchArgs,
    acceptance: Option<String>,
}

/// Gather settings: defaults, then the scene's `<integrator type="gather">` properties,
/// then command-line flags.
fn gather_settings(
    args: &GatherFlags,
    plugin: Option<&ais_render::scene::Plugin>,
) -> Result<GatherSettings, String> {
    let mut settings = GatherSettings::default();
    let mut strategy = None;
    let mut ais = None;
    let mut budget = None;
    let mut sharing = None;
    if let Some(plugin) = plugin.filter(|p| p.kind == "gather") {
        let at = |(line, message): (u32, String)| format!("line {line}: {message}");
        strategy = plugin.string("strategy").map_err(at)?.map(str::to_string);
        ais = plugin.string("ais").map_err(at)?.map(str::to_string);
        budget = plugin.string("budget").map_err(at)?.map(str::to_string);
        sharing = plugin.string("sharing").map_err(at)?.map(str::to_string);
        settings.rays = plugin
            .integer("rays", settings.rays as i64)
            .map_err(at)?
            .clamp(0, u32::MAX as i64) as u32;
        settings.tol = plugin.float("tol", settings.tol as f64).map_err(at)? as f32;
        settings.map_height = plugin
            .integer("map_res", settings.map_height as i64)
            .map_err(at)?
            .clamp(0, 4096) as u32;
    }
    strategy = args.strategy.clone().or(strategy);
    ais = args.ais.clone().or(ais);
    if let Some(name) = strategy {
        settings.strategy = Strategy::parse(&name)
            .ok_or_else(|| format!("unknown strategy \"{name}\" (uniform, bsdf, light, mis)"))?;
    }
    if let Some(name) = ais {
        let (mode, acceptance, sharing) = parse_ais(&name)?;
        settings.ais = mode;
        settings.acceptance = acceptance;
        settings.sharing = sharing.unwrap_or(settings.sharing);
    }
    if let Some(name) = &args.acceptance {
        settings.acceptance = Acceptance::parse(name).ok_or_else(|| {
            format!("unknown acceptance \"{name}\" (affinity, sqrt, value, efficient)")
        })?;
    }
    if settings.ais == AisMode::Guided && settings.acceptance != Acceptance::Affinity {
        return Err("guided gathers reject no candidate, so they take no acceptance rule".into());
    }
    if let Some(name) = &args.placement {
        settings.placement = match name.as_str() {
            "halton" => ais::Placement::Halton,
            "random" => ais::Placement::Random,
            other => return Err(format!("unknown placement \"{other}\" (halton, random)")),
        };
    }
    settings.rays = args.batch.rays.unwrap_or(settings.rays);
    settings.tol = args.batch.tol.unwrap_or(settings.tol);
    settings.map_height = args.batch.map_res.unwrap_or(settings.map_height);
    settings.guide_fraction = args.batch.guide_fraction.unwrap_or(settings.guide_fraction);
    if let Some(name) = args.batch.budget.as_ref().or(budget.as_ref()) {
        settings.budget = RayBudget::parse(name)
            .ok_or_else(|| format!("unknown budget \"{name}\" (traced, candidates)"))?;
    }
    if let Some(name) = args.batch.sharing.as_ref().or(sharing.as_ref()) {
        settings.sharing = Sharing::parse(name).ok_or_else(|| {
            format!("unknown sharing \"{name}\" (tile, pass, or pass:S with S in 1..=16)")
        })?;
    }
    if !(0.0..=0.99).contains(&settings.guide_fraction) {
        return Err("--guide-fraction must lie in [0, 0.99]".into());
    }
    if settings.rays == 0 {
        return Err("the gather needs at least one ray (--rays)".into());
    }
    if settings.tol.is_nan() || settings.tol <= 0.0 {
        return Err("--tol must be positive (or inf)".into());
    }
    if settings.map_height == 0 {
        return Err("--map-res must be at least 1".into());
    }
    Ok(settings)
}

/// An AIS mode name, optionally with "+sqrt", "+value" or "+efficient" for another
/// acceptance rule, then optionally "@tile" or "@pass[:S]" for where a mode that shares maps
/// finds them (e.g. shared+sqrt@pass:8).
fn parse_ais(name: &str) -> Result<(AisMode, Acceptance, Option<Sharing>), String> {
    let unknown = || {
        format!(
            "unknown AIS mode \"{name}\" (off, aggressive, conservative, shared, warm, guided, oracle; \
             +sqrt, +value or +efficient for another acceptance rule, e.g. shared+sqrt; \
             @tile, @pass or @pass:S for where shared maps come from, e.g. shared@pass:8)"
        )
    };
    let (rest, sharing) = match name.split_once('@') {
        Some((rest, sharing)) => (rest, Some(Sharing::parse(sharing).ok_or_else(unknown)?)),
        None => (name, None),
    };
    let (mode, rule) = rest.split_once('+').unwrap_or((rest, ""));
    match (AisMode::parse(mode), Acceptance::parse(rule)) {
        (Some(mode), Some(acceptance)) => Ok((mode, acceptance, sharing)),
        _ => Err(unknown()),
    }
}

fn parse_resolution(text: &str) -> Result<(u32, u32), String> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("\"{text}\" is not WIDTHxHEIGHT"))?;
    let parse = |s: &str| {
        s.parse::<u32>()
            .ok()
            .filter(|&v| (1..=65536).contains(&v))
            .ok_or_else(|| format!("\"{s}\" is not a size in 1..=65536"))
    };
    Ok((parse(w)?, parse(h)?))
}

fn parse_define(text: &str) -> Result<(String, String), String> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| format!("\"{text}\" is not name=value"))?;
    Ok((name.to_string(), value.to_string()))
}

/// Starts `threads` rayon workers (None: one per core).
fn start_threads(threads: Option<usize>) -> Result<(), String> {
    if let Some(threads) = threads {
        if threads == 0 {
            return Err("--threads must be at least 1".into());
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build_global()
            .map_err(|e| format!("cannot start {threads} threads: {e}"))?;
    }
    Ok(())
}

/// The scene file's world (resolution overridden if given), or the built-in default scene at
/// `resolution` or `default_resolution`; prints the scene's warnings.
fn load_world(
    scene: Option<&std::path::Path>,
    defines: &[(String, String)],
    resolution: Option<(u32, u32)>,
    default_resolution: (u32, u32),
) -> Result<World, String> {
    let world = match scene {
        Some(path) => {
            let mut description = load_scene(path, defines).map_err(|e| e.to_string())?;
            if let Some(resolution) = resolution {
                description.resolution = resolution;
            }
            World::from_description(description).map_err(|e| e.to_string())?
        }
        None => {
            let (width, height) = resolution.unwrap_or(default_resolution);
            default_world(width, height)
        }
    };
    for warning in &world.warnings {
        eprintln!("warning: {warning}");
    }
    Ok(world)
}

fn run_render(args: RenderArgs) -> Result<(), String> {
    start_threads(args.threads)?;
    let extension = args
        .output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if extension.as_deref() != Some("exr") {
        return Err(format!(
            "{}: the output must be an .exr file",
            args.output.display()
        ));
    }
    let world = load_world(
        args.scene.as_deref(),
        &args.define,
        args.resolution,
        (640, 360),
    )?;
    let scene_integrator = world.description.integrator.clone();
    let choice = match (args.integrator, &scene_integrator) {
        (Some(choice), _) => choice,
        (None, Some(plugin)) if plugin.kind == "gather" => IntegratorChoice::Gather,
        (None, Some(plugin)) if plugin.kind == "direct" || plugin.kind == "path" => {
            eprintln!(
                "warning: {}:{}: integrator \"{}\" rendered with ais's gather (MIS, direct light only)",
                world.description.file.display(),
                plugin.line,
                plugin.kind
            );
            IntegratorChoice::Gather
        }
        (None, Some(plugin)) => {
            return Err(format!(
                "{}:{}: integrator \"{}\" is not supported (gather, direct)",
                world.description.file.display(),
                plugin.line,
                plugin.kind
            ))
        }
        (None, None) => IntegratorChoice::Gather,
    };
    let integrator = match choice {
        IntegratorChoice::Gather => {
            let flags = GatherFlags {
                strategy: args.strategy.clone(),
                ais: args.ais.clone(),
                placement: args.placement.clone(),
                batch: args.batch,
                acceptance: args.acceptance.clone(),
            };
            Integrator::Gather(gather_settings(&flags, scene_integrator.as_ref())?)
        }
        IntegratorChoice::Normals => Integrator::Normals,
        IntegratorChoice::Ao => {
            if args.ao_rays == 0 || args.ao_distance.is_nan() || args.ao_distance <= 0.0 {
                return Err("--ao-rays must be at least 1 and --ao-distance positive".into());
            }
            Integrator::AmbientOcclusion {
                rays: args.ao_rays,
                distance: args.ao_distance,
            }
        }
    };
    let samples_per_pixel = args.spp.unwrap_or(world.sample_count);
    if samples_per_pixel == 0 {
        return Err("--spp must be at least 1".into());
    }
    let settings = RenderSettings {
        samples_per_pixel,
        integrator,
        seed: args.seed,
        progress: !args.quiet && std::io::stderr().is_terminal(),
    };
    let output = render(&world, &settings);
    write_exr(&args.output, &output.image).map_err(|e| e.to_string())?;
    if let Some(path) = &args.aov_traced {
        let (width, height) = world.resolution;
        let aov = RgbImage {
            width: width as usize,
            height: height as usize,
            pixels: output.traced_per_sample.iter().map(|&t| [t; 3]).collect(),
        };
        write_exr(path, &aov).map_err(|e| e.to_string())?;
    }
    let preview = args.output.with_extension("png");
    if !args.no_preview {
        write_png(&preview, &output.image, args.exposure).map_err(|e| e.to_string())?;
    }
    let (width, height) = world.resolution;
    let seconds = output.time.as_secs_f64();
    println!("scene        {}", world.description.file.display());
    println!(
        "resolution   {width}×{height}, {samples_per_pixel} spp, {} threads",
        rayon::current_num_threads()
    );
    println!(
        "triangles    {} ({} primitives)",
        world.geometry.triangle_count(),
        world.geometry.primitive_count()
    );
    println!(
        "BVH build    {:.3} s",
        world.geometry.build_time().as_secs_f64()
    );
    println!("render time  {seconds:.3} s");
    println!(
        "rays         {} camera + {} occlusion = {:.2} M rays/s",
        output.rays.closest_hit,
        output.rays.occlusion,
        output.rays.total() as f64 / seconds.max(1e-9) / 1e6
    );
    if let Integrator::Gather(settings) = integrator {
        let stats = output.ais;
        let gathers = stats.batches.max(1) as f64;
        println!(
            "gather       {} strategy, AIS {:?}, n = {}",
            settings.strategy.name(),
            settings.ais,
            settings.rays
        );
        println!(
            "candidates   {} ({:.1} per gather): traced {:.1}, rejected outside support {:.1}, by roulette {:.1} per gather; {} resets",
            stats.candidates,
            stats.candidates as f64 / gathers,
            stats.traced as f64 / gathers,
            stats.rejected_outside_support as f64 / gathers,
            stats.rejected_roulette as f64 / gathers,
            stats.resets
        );
        let cpu = seconds * rayon::current_num_threads() as f64;
        println!(
            "AIS code     ≈ {:.3} s of {cpu:.3} thread-seconds ({:.1}%; 1 in {} gathers replayed and timed)",
            output.ais_time.as_secs_f64(),
            100.0 * output.ais_time.as_secs_f64() / cpu.max(1e-9),
            ais_render::ais_timer::SAMPLING
        );
        println!(
            "AIS memory   {:.1} KiB per thread (maps, shared maps, guides)",
            output.ais_memory_per_thread as f64 / 1024.0
        );
    }
    println!("wrote        {}", args.output.display());
    if !args.no_preview {
        println!("preview      {}", preview.display());
    }
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => run_render(*args),
        Command::Bench(args) => run_bench(args),
        Command::Compare(args) => compare::run(*args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
