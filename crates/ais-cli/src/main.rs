//! The `ais` command.

use ais_render::default_scene::default_world;
use ais_render::image_io::{write_exr, write_png};
use ais_render::integrator::Integrator;
use ais_render::render::{render, RenderSettings};
use ais_render::scene::load_scene;
use ais_render::world::World;
use clap::{Parser, Subcommand, ValueEnum};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

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
    Render(RenderArgs),
    /// Measure BVH build time and ray throughput on the built-in default scene.
    Bench(BenchArgs),
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

#[derive(Clone, Copy, ValueEnum)]
enum IntegratorChoice {
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
    /// What to render until the lighting integrators land.
    #[arg(long, value_enum, default_value = "ao")]
    integrator: IntegratorChoice,
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

fn run_render(args: RenderArgs) -> Result<(), String> {
    if let Some(threads) = args.threads {
        if threads == 0 {
            return Err("--threads must be at least 1".into());
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build_global()
            .map_err(|e| format!("cannot start {threads} threads: {e}"))?;
    }
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
    let world = match &args.scene {
        Some(path) => {
            let mut description = load_scene(path, &args.define).map_err(|e| e.to_string())?;
            if let Some(resolution) = args.resolution {
                description.resolution = resolution;
            }
            World::from_description(description).map_err(|e| e.to_string())?
        }
        None => {
            let (width, height) = args.resolution.unwrap_or((640, 360));
            default_world(width, height)
        }
    };
    for warning in &world.warnings {
        eprintln!("warning: {warning}");
    }
    let integrator = match args.integrator {
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
    println!("wrote        {}", args.output.display());
    if !args.no_preview {
        println!("preview      {}", preview.display());
    }
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => run_render(args),
        Command::Bench(args) => run_bench(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
