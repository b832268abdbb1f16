//! `ais render`: render a scene (or the built-in default scene) to EXR and a PNG preview.

use crate::gather_flags::GatherFlags;
use crate::{load_world, parse_resolution, start_threads, SceneFlags, SceneRequest, ThreadFlags};
use ais_render::atomic_write::OutputSet;
use ais_render::image_io::{encode_exr, encode_png, RgbImage, WriteError};
use ais_render::integrators::gather::field::LEAST_ROLLING_RAYS;
use ais_render::integrators::gather::mis_share::ROLLING_MIS_SHARE;
use ais_render::integrators::gather::race::RaceResult;
use ais_render::integrators::gather::{GatherStats, MapSource};
use ais_render::integrators::{AmbientOcclusion, Integrator};
use ais_render::render::{render, PixelRect, RenderOutput, RenderSettings};
use ais_render::world::World;
use ais_study::oracle::Oracle;
use ais_study::timing::{TimedGather, SAMPLING};
use clap::ValueEnum;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Duration;

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
pub struct RenderArgs {
    /// The scene file (Mitsuba 3 XML). Omit it to render the built-in default scene.
    scene: Option<PathBuf>,
    /// Output EXR (32-bit float RGB); a tone-mapped PNG preview is written beside it.
    #[arg(short, long, default_value = "ais.exr")]
    output: PathBuf,
    /// Samples per pixel (default: the scene's sample_count; 4 for the default scene).
    #[arg(long)]
    spp: Option<u32>,
    #[command(flatten)]
    threads: ThreadFlags,
    /// Override the film size, e.g. 640x360.
    #[arg(long, value_parser = parse_resolution)]
    resolution: Option<(u32, u32)>,
    /// What to render (default: the gather, with the scene's `<integrator>` settings).
    #[arg(long, value_enum)]
    integrator: Option<IntegratorChoice>,
    #[command(flatten)]
    gather: GatherFlags,
    /// Render the oracle instead of the gather: a bound for studies, the proposal restricted
    /// to directions that bring light, found by free brute-force visibility tests.
    #[arg(long)]
    oracle: bool,
    /// Estimate the time spent in the AIS library (1 in 16 gathers replayed and timed).
    #[arg(long)]
    time_ais: bool,
    /// Also write the mean traced gather rays per camera sample, per pixel, to this EXR.
    #[arg(long)]
    aov_traced: Option<PathBuf>,
    /// Ambient-occlusion rays per camera sample.
    #[arg(long, default_value_t = 16)]
    ao_rays: u32,
    /// Ambient-occlusion distance in world units.
    #[arg(long, default_value_t = 1.0)]
    ao_distance: f32,
    /// Exposure of the PNG preview, in stops (negative darkens).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    exposure: f32,
    /// Base random seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Render only the pixels x..x+w, y..y+h of the image, written as a w×h image: tiles
    /// rendered apart and pasted together equal the whole render (see docs/cli.md).
    #[arg(long, value_parser = parse_crop)]
    crop: Option<[usize; 4]>,
    /// Skip the PNG preview.
    #[arg(long)]
    no_preview: bool,
    /// No progress bar.
    #[arg(short, long)]
    quiet: bool,
    #[command(flatten)]
    scene_flags: SceneFlags,
}

/// What a render produced, whatever integrator made it.
struct Rendered {
    output: RenderOutput<GatherStats>,
    ais_time: Option<Duration>,
}

/// The integrator: the flag, else the gather (which reads the scene's `<integrator>`).
fn integrator(args: &RenderArgs, world: &World) -> Result<Integrator, String> {
    Ok(match args.integrator.unwrap_or(IntegratorChoice::Gather) {
        IntegratorChoice::Gather => {
            Integrator::Gather(args.gather.settings(world, args.scene_flags.strict)?)
        }
        IntegratorChoice::Normals => Integrator::Normals,
        IntegratorChoice::Ao => {
            if args.ao_rays == 0 || args.ao_distance.is_nan() || args.ao_distance <= 0.0 {
                return Err("--ao-rays must be at least 1 and --ao-distance positive".into());
            }
            Integrator::AmbientOcclusion(AmbientOcclusion {
                rays: args.ao_rays,
                distance: args.ao_distance,
            })
        }
    })
}

/// Renders with the integrator, its timed variant, or the oracle.
fn run_integrator(
    args: &RenderArgs,
    world: &World,
    integrator: &Integrator,
    settings: &RenderSettings,
) -> Result<Rendered, String> {
    let gather = match integrator {
        Integrator::Gather(gather) => Some(*gather),
        _ => None,
    };
    match (gather, args.oracle, args.time_ais) {
        (None, true, _) | (None, _, true) => {
            Err("--oracle and --time-ais need the gather integrator".into())
        }
        (Some(_), true, true) => Err("the oracle is not timed: leave out --time-ais".into()),
        (Some(gather), true, false) => {
            let output = render(world, &Oracle(gather), settings);
            Ok(Rendered {
                output: output.map_stats(|_| GatherStats::default()),
                ais_time: None,
            })
        }
        (Some(gather), false, true) => {
            let output = render(world, &TimedGather(gather), settings);
            Ok(Rendered {
                ais_time: Some(output.stats.ais_time),
                output: output.map_stats(|stats| stats.gather),
            })
        }
        (_, false, false) => Ok(Rendered {
            output: render(world, integrator, settings),
            ais_time: None,
        }),
    }
}

/// Parses `--crop x,y,w,h`.
fn parse_crop(text: &str) -> Result<[usize; 4], String> {
    let numbers: Vec<usize> = text
        .split(',')
        .map(|part| part.trim().parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("\"{text}\" is not x,y,w,h (four whole numbers)"))?;
    numbers
        .try_into()
        .map_err(|_| format!("\"{text}\" is not x,y,w,h (four whole numbers)"))
}

/// Checks, before any work, that the outputs can be written: an `.exr` path in an existing
/// folder, not a folder itself, and an AOV that is an `.exr` of its own.
fn check_outputs(args: &RenderArgs) -> Result<(), String> {
    let exr = |path: &Path, flag: &str| -> Result<(), String> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        if extension.as_deref() != Some("exr") {
            return Err(format!("{}: {flag} must be an .exr file", path.display()));
        }
        if path.is_dir() {
            return Err(format!(
                "{}: {flag} is a folder, not a file",
                path.display()
            ));
        }
        let folder = match path.parent() {
            Some(folder) if !folder.as_os_str().is_empty() => folder,
            _ => Path::new("."),
        };
        if !folder.is_dir() {
            return Err(format!(
                "{}: the folder {} does not exist",
                path.display(),
                folder.display()
            ));
        }
        Ok(())
    };
    exr(&args.output, "the output")?;
    if let Some(aov) = &args.aov_traced {
        exr(aov, "--aov-traced")?;
        let preview = args.output.with_extension("png");
        if same_file(aov, &args.output) || same_file(aov, &preview) {
            return Err(format!(
                "{}: --aov-traced would overwrite the image; give it another name",
                aov.display()
            ));
        }
    }
    Ok(())
}

/// Whether two paths name the same file (as written, or once resolved if both exist).
fn same_file(a: &Path, b: &Path) -> bool {
    let absolute = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    absolute(a) == absolute(b)
        || matches!((a.canonicalize(), b.canonicalize()), (Ok(x), Ok(y)) if x == y)
}

/// Writes the image, the AOV and the preview as a unit: all of them, or none.
fn write_outputs(args: &RenderArgs, output: &RenderOutput<GatherStats>) -> Result<(), String> {
    let mut outputs = OutputSet::default();
    let failed = |e: WriteError| e.to_string();
    outputs
        .stage(&args.output, |file| {
            encode_exr(file, &output.image, &args.output)
        })
        .map_err(failed)?;
    if let Some(path) = &args.aov_traced {
        let aov = RgbImage {
            width: output.image.width,
            height: output.image.height,
            pixels: output.work_per_sample.iter().map(|&t| [t; 3]).collect(),
        };
        outputs
            .stage(path, |file| encode_exr(file, &aov, path))
            .map_err(failed)?;
    }
    if !args.no_preview {
        let preview = args.output.with_extension("png");
        outputs
            .stage(&preview, |file| {
                encode_png(file, &output.image, args.exposure, &preview)
            })
            .map_err(failed)?;
    }
    outputs.commit().map_err(|e| e.to_string())
}

/// `ais render`.
pub fn run(args: RenderArgs) -> Result<(), String> {
    start_threads(args.threads)?;
    check_outputs(&args)?;
    let world = load_world(&SceneRequest {
        scene: args.scene.as_deref(),
        flags: &args.scene_flags,
        resolution: args.resolution,
        default_resolution: (640, 360),
    })?;
    let integrator = integrator(&args, &world)?;
    let samples_per_pixel = args.spp.unwrap_or(world.sample_count);
    if samples_per_pixel == 0 {
        return Err("--spp must be at least 1".into());
    }
    let (width, height) = world.resolution;
    let crop = args
        .crop
        .map(|crop| PixelRect::check_crop(crop, (width as usize, height as usize)))
        .transpose()
        .map_err(|message| format!("--crop: {message}"))?;
    let settings = RenderSettings {
        samples_per_pixel,
        seed: args.seed,
        first_sample: 0,
        progress: !args.quiet && std::io::stderr().is_terminal(),
        crop,
    };
    let rendered = run_integrator(&args, &world, &integrator, &settings)?;
    write_outputs(&args, &rendered.output)?;
    print_summary(&args, &world, &integrator, &rendered, samples_per_pixel);
    Ok(())
}

fn print_summary(
    args: &RenderArgs,
    world: &World,
    integrator: &Integrator,
    rendered: &Rendered,
    samples_per_pixel: u32,
) {
    let output = &rendered.output;
    let (width, height) = world.resolution;
    let seconds = output.time.as_secs_f64();
    println!("scene        {}", world.description.file.display());
    println!(
        "resolution   {width}×{height}, {samples_per_pixel} spp, {} threads",
        rayon::current_num_threads()
    );
    if let Some([x, y, w, h]) = args.crop {
        println!("crop         {w}×{h} pixels from ({x}, {y})");
    }
    let geometry = &world.geometry;
    let instances = match geometry.instance_count() {
        0 => String::new(),
        n => format!(", {n} of them instances of shape groups, each group stored once"),
    };
    println!(
        "triangles    {} ({} primitives{instances})",
        geometry.triangle_count(),
        geometry.primitive_count()
    );
    println!(
        "BVH build    {:.3} s ({})",
        world.geometry.build_time().as_secs_f64(),
        world.geometry.accelerator_name()
    );
    println!(
        "render time  {seconds:.3} s ({:.2} threads busy on average)",
        output.threads_busy()
    );
    println!(
        "rays         {} camera + {} occlusion = {:.2} M rays/s",
        output.rays.closest_hit,
        output.rays.occlusion,
        output.rays.total() as f64 / seconds.max(1e-9) / 1e6
    );
    if let Integrator::Gather(settings) = integrator {
        print_gather_summary(args, settings, rendered, seconds);
    }
    println!("wrote        {}", args.output.display());
    if !args.no_preview {
        println!(
            "preview      {}",
            args.output.with_extension("png").display()
        );
    }
}

fn print_gather_summary(
    args: &RenderArgs,
    settings: &ais_render::integrators::gather::GatherSettings,
    rendered: &Rendered,
    seconds: f64,
) {
    if args.oracle {
        println!(
            "gather       oracle ({} strategy, n = {}): visibility tested for free",
            settings.strategy.name(),
            settings.rays
        );
        return;
    }
    let stats = rendered.output.stats.ais;
    let gathers = stats.batches.max(1) as f64;
    println!(
        "gather       {} strategy, AIS {}, n = {}",
        settings.strategy.name(),
        settings.ais_label(),
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
    if let Some(ais_time) = rendered.ais_time {
        let cpu = seconds * rayon::current_num_threads() as f64;
        println!(
            "AIS code     ≈ {:.3} s of {cpu:.3} thread-seconds ({:.1}%; 1 in {SAMPLING} gathers replayed and timed)",
            ais_time.as_secs_f64(),
            100.0 * ais_time.as_secs_f64() / cpu.max(1e-9),
        );
    }
    println!(
        "AIS memory   {:.1} KiB per thread (maps, shared maps, guides)",
        rendered.output.stats.memory_per_thread as f64 / 1024.0
    );
    print_field_summary(settings, &rendered.output.stats);
}

/// What the learned field did: its size and use, the MIS share it learned, its race against
/// AIS off and the gather sizes it chose.
fn print_field_summary(
    settings: &ais_render::integrators::gather::GatherSettings,
    stats: &GatherStats,
) {
    let [rolled, aside] = stats.field_gathers;
    if settings.map == MapSource::Field && rolled + aside == 0 {
        println!(
            "field        not used: nothing to guide (no environment, and one light without regions), and roulette needs {LEAST_ROLLING_RAYS} rays per gather (rendered as AIS off)"
        );
    }
    if rolled + aside > 0 {
        println!(
            "field        {:.1} KiB; roulette in {:.1}% of gathers, stood aside in the rest; light sampling guided in {:.1}%; cost ratio {:.2}",
            stats.field_memory as f64 / 1024.0,
            100.0 * rolled as f64 / (rolled + aside) as f64,
            100.0 * stats.field_guided as f64 / (rolled + aside) as f64,
            stats.field_cost_ratio
        );
    }
    match (stats.mis_share, settings.mis_share) {
        (Some(share), Some(_)) => println!("MIS          BSDF share {share} (given)"),
        (Some(share), None) => println!(
            "MIS          BSDF share {share} (auto's: learned from the first passes below {LEAST_ROLLING_RAYS} candidates, {ROLLING_MIS_SHARE} from {LEAST_ROLLING_RAYS} on; AIS off uses 0.5)"
        ),
        (None, _) => {}
    }
    if settings.map == MapSource::Field && stats.field_stood_aside && stats.field_race.is_none() {
        println!("field        stood aside after its first passes: it found almost nothing to guide or roll, and the rest gathered as AIS off");
    }
    if let Some(race) = stats.field_race {
        print_race(&race);
    }
    if let Some(mean) = stats.gather_sizes {
        println!(
            "gather sizes {mean:.1} candidates per gather on average over the image's blocks after the race (fewer where gathers vary little or the camera's noise dominates; {} asked)",
            settings.rays
        );
    }
}

/// The field's race against AIS off: each arm's pixel variance, their times, the verdict.
fn print_race(race: &RaceResult) {
    let timed = race
        .seconds_per_sample
        .map_or(String::new(), |[field, off]| {
            format!(
                "; time per sample with the field / AIS off {:.3}",
                field / off
            )
        });
    println!(
        "field race   pixel variance with the field {:.3e}, AIS off {:.3e} (ratio {:.3}{timed}): {}",
        race.field,
        race.off,
        race.field / race.off,
        if race.field_pays() {
            "the field guides the rest"
        } else {
            "the rest gathers as AIS off"
        }
    );
}
