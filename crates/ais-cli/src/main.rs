//! The `ais` command.

use ais_render::request::SceneSource;
use ais_render::world::World;
use clap::{Parser, Subcommand};
use std::process::ExitCode;

mod bench_command;
mod compare;
mod gather_flags;
mod render_command;

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
    Render(Box<render_command::RenderArgs>),
    /// Measure BVH build time and ray throughput on the built-in default scene.
    Bench(bench_command::BenchArgs),
    /// Compare gather configurations (the talk's by default) at equal time and equal rays
    /// against a converged reference, and write an HTML report.
    Compare(Box<compare::CompareArgs>),
    /// Write the built-in default scene as a Mitsuba 3 scene folder (default.xml, the
    /// sculpture as PLY, the sky as EXR), to render it in Mitsuba or time both renderers.
    ExportDefault {
        /// The folder to write into (created if missing).
        folder: std::path::PathBuf,
    },
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

/// How many worker threads to start.
#[derive(clap::Args, Clone, Copy)]
struct ThreadFlags {
    /// Worker threads (default: all cores; at most 4 per core unless --force-threads).
    #[arg(long)]
    threads: Option<usize>,
    /// Allow more than 4 threads per core.
    #[arg(long)]
    force_threads: bool,
}

/// Starts the worker threads the flags ask for (default: one per core).
fn start_threads(flags: ThreadFlags) -> Result<(), String> {
    if let Some(threads) = flags.threads {
        ais_render::limits::check_threads(threads, flags.force_threads)?;
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build_global()
            .map_err(|e| format!("cannot start {threads} threads: {e}"))?;
    }
    Ok(())
}

/// The flags of `render` and `compare` about reading the scene.
#[derive(clap::Args, Clone)]
struct SceneFlags {
    /// Set a scene $parameter: -D name=value (repeatable).
    #[arg(short = 'D', value_parser = parse_define)]
    define: Vec<(String, String)>,
    /// Treat every warning about the scene as an error.
    #[arg(long)]
    strict: bool,
}

/// What `render` and `compare` ask to load.
struct SceneRequest<'a> {
    /// The scene file, or None for the built-in default scene.
    scene: Option<&'a std::path::Path>,
    /// `-D name=value` parameters and `--strict`.
    flags: &'a SceneFlags,
    /// `--resolution`, if given.
    resolution: Option<(u32, u32)>,
    /// The built-in scene's size without `--resolution`.
    default_resolution: (u32, u32),
}

/// The scene file's world (resolution overridden if given), or the built-in default scene;
/// prints the scene's warnings, or refuses the scene for them with `--strict`.
fn load_world(request: &SceneRequest) -> Result<World, String> {
    let world = ais_render::request::load_world(&ais_render::request::SceneRequest {
        source: match request.scene {
            Some(path) => SceneSource::File(path),
            None => SceneSource::BuiltIn,
        },
        defines: &request.flags.define,
        resolution: request.resolution,
        default_resolution: request.default_resolution,
    })
    .map_err(|e| e.to_string())?;
    report_warnings(&world.warnings, request.flags.strict)?;
    Ok(world)
}

/// Prints warnings about the input; with `--strict` (`strict`), any warning is an error.
fn report_warnings(warnings: &[String], strict: bool) -> Result<(), String> {
    for warning in warnings {
        eprintln!("warning: {warning}");
    }
    if strict && !warnings.is_empty() {
        return Err(format!(
            "{} warning(s) above, and --strict makes them errors",
            warnings.len()
        ));
    }
    Ok(())
}

fn main() -> ExitCode {
    // An interrupted render leaves no temporary file behind, and keeps the old outputs.
    let _ = ctrlc::set_handler(|| {
        ais_render::atomic_write::remove_temporaries();
        eprintln!("\ninterrupted: the previous outputs are unchanged");
        std::process::exit(130);
    });
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => render_command::run(*args),
        Command::Bench(args) => bench_command::run(args),
        Command::Compare(args) => compare::run(*args),
        Command::ExportDefault { folder } => {
            ais_render::default_scene::export::write_mitsuba_scene(&folder).map(|scene| {
                println!("wrote        {}", scene.display());
            })
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
