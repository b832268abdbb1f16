//! Studies (`ais compare`): configurations of the gather rendered against a converged
//! reference at equal wall time and at equal traced rays, with several seeds, and a
//! self-contained HTML report.
//!
//! Each run renders progressive passes until its budget is spent: first those a render of
//! its own would take ([`Configuration::leading_passes`]), then passes of one sample per
//! pixel (or [`StudySettings::pass_spp`]),
//! recording relMSE after every pass (the convergence curves). Equal-time runs stop at the
//! time budget; equal-ray runs stop when they have traced as many rays (camera plus gather
//! rays) as the baseline configuration traced in its equal-time runs (median over seeds).
//! The oracle runs at equal rays only: its free visibility tests make its time meaningless.

pub mod affinity_figure;
pub mod metrics;
pub mod plots;
pub mod reference;
pub mod report;
pub mod request;
pub mod summary;

use crate::oracle::Oracle;
use ais::rng::mix64;
use ais_render::film::Film;
use ais_render::image_io::RgbImage;
use ais_render::integrators::gather::{
    GatherLearning, GatherSettings, GatherStats, Preset, Strategy,
};
use ais_render::integrators::Integrator;
use ais_render::render::{render, render_learning, RayCounts, RenderSettings, SampleIntegrator};
use ais_render::world::World;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::Path;
use std::time::Duration;

/// Most passes of a run, whatever its budget.
const MOST_PASSES: u32 = 1 << 14;

/// What a configuration renders with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Technique {
    /// The renderer's gather.
    Gather,
    /// The oracle with the gather's strategy and rays (a bound, run at equal rays only).
    Oracle,
}

/// One configuration of the gather under study.
#[derive(Clone, Debug, PartialEq)]
pub struct Configuration {
    /// Short name, also used in file names.
    pub name: String,
    /// What the talk would call it, for figures.
    pub label: String,
    /// The gather's settings.
    pub settings: GatherSettings,
    /// The gather or the oracle.
    pub technique: Technique,
}

impl Configuration {
    /// A gather configuration.
    pub fn new(name: &str, label: &str, settings: GatherSettings) -> Self {
        Configuration {
            name: name.into(),
            label: label.into(),
            settings,
            technique: Technique::Gather,
        }
    }

    /// The oracle with `settings`' strategy and rays.
    pub fn oracle(name: &str, label: &str, settings: GatherSettings) -> Self {
        Configuration {
            technique: Technique::Oracle,
            ..Configuration::new(name, label, settings)
        }
    }

    /// Whether this is the oracle (run at equal rays only).
    pub fn is_oracle(&self) -> bool {
        self.technique == Technique::Oracle
    }

    /// The samples per pixel of a run's first passes, as a render of its own takes them
    /// (`ais auto`'s field learns and races in passes of 1, 1, 2 and 4): a study's run
    /// learns, races and chooses exactly as `ais render` does. Empty where a render is one
    /// pass.
    pub fn leading_passes(&self, world: &World) -> Vec<u32> {
        if self.is_oracle() {
            return Vec::new();
        }
        // A render of endless samples: every pass but the last, which holds the rest.
        let mut passes = Integrator::Gather(self.settings).passes(world, 0, u32::MAX);
        passes.pop();
        passes
    }

    /// Renders one pass of the `samples` of each pixel with `seed`, from what the run's
    /// earlier passes learned (`learned`: the visibility field of `ais auto`), adding to it.
    pub fn render_pass(
        &self,
        world: &World,
        samples: SampleRange,
        seed: u64,
        learned: &mut GatherLearning,
    ) -> Pass {
        let settings = RenderSettings {
            samples_per_pixel: samples.count,
            seed,
            first_sample: samples.first,
            progress: false,
            crop: None,
        };
        let output = match self.technique {
            Technique::Gather => render_learning(
                world,
                &Integrator::Gather(self.settings),
                &settings,
                learned,
            ),
            Technique::Oracle => render(world, &Oracle(self.settings), &settings)
                .map_stats(|_| GatherStats::default()),
        };
        Pass {
            film: output.film,
            seconds: output.time.as_secs_f64(),
            rays: output.rays,
            stats: output.stats.ais,
            ais_memory_per_thread: output.stats.memory_per_thread,
        }
    }
}

/// What one rendered pass gives a study.
pub struct Pass {
    /// Its film (weighted sums: passes add up by [`Film::add_film`]).
    pub film: Film,
    /// Its render time.
    pub seconds: f64,
    /// Rays traced.
    pub rays: RayCounts,
    /// AIS statistics (zero for the oracle).
    pub stats: ais::Stats,
    /// The most AIS state one thread held (bytes).
    pub ais_memory_per_thread: usize,
}

/// The talk's comparison on top of `base`: uniform, the importance sampler without and with
/// AIS (aggressive, conservative), random against Halton placement, and the oracle.
pub fn talk_configurations(base: GatherSettings) -> Vec<Configuration> {
    let with = |strategy, preset, placement| GatherSettings {
        strategy,
        placement,
        ..base.with_preset(preset)
    };
    use ais::Placement::{Halton, Random};
    vec![
        Configuration::new(
            "mis-off",
            "PHIS (MIS), AIS off",
            with(Strategy::Mis, Preset::Off, Halton),
        ),
        Configuration::new(
            "uniform-off",
            "Uniform",
            with(Strategy::Uniform, Preset::Off, Halton),
        ),
        Configuration::new(
            "mis-aggressive",
            "PHIS + AIS aggressive",
            with(Strategy::Mis, Preset::Aggressive, Halton),
        ),
        Configuration::new(
            "mis-conservative",
            "PHIS + AIS conservative",
            with(Strategy::Mis, Preset::Conservative, Halton),
        ),
        Configuration::new(
            "mis-off-random",
            "PHIS, random placement",
            with(Strategy::Mis, Preset::Off, Random),
        ),
        Configuration::new(
            "mis-aggressive-random",
            "PHIS + AIS aggressive, random placement",
            with(Strategy::Mis, Preset::Aggressive, Random),
        ),
        Configuration::oracle(
            "mis-oracle",
            "PHIS restricted to visible directions (oracle)",
            with(Strategy::Mis, Preset::Off, Halton),
        ),
    ]
}

/// How a study runs.
#[derive(Clone, Debug)]
pub struct StudySettings {
    /// Configurations; the first is the baseline of the ratios.
    pub configurations: Vec<Configuration>,
    /// Wall time of each equal-time run.
    pub time_budget: Duration,
    /// Independent runs per configuration and budget.
    pub seeds: u32,
    /// Samples per pixel of the reference (MIS, AIS off).
    pub reference_spp: u32,
    /// Samples per pixel of each progressive pass (one render call): what a per-render cost,
    /// such as the learning pass of shared maps, is spread over.
    pub pass_spp: u32,
    /// Where the reference's two halves are cached (None: not cached).
    pub reference_cache: Option<[std::path::PathBuf; 2]>,
    /// The pixel of the affinity-map figure.
    pub figure_pixel: (u32, u32),
    /// Show progress bars.
    pub progress: bool,
}

/// relMSE after a pass (less the reference's own noise), with what it cost.
#[derive(Clone, Copy, Debug)]
pub struct CurvePoint {
    /// Render time so far (seconds).
    pub seconds: f64,
    /// Rays traced so far (camera and gather rays).
    pub rays: u64,
    /// relMSE of the image so far.
    pub rel_mse: f64,
}

/// One progressive run.
#[derive(Clone, Debug)]
pub struct Run {
    /// The final image.
    pub image: RgbImage,
    /// Samples per pixel reached.
    pub spp: u32,
    /// Render time (seconds).
    pub seconds: f64,
    /// Rays traced.
    pub rays: RayCounts,
    /// AIS statistics.
    pub stats: ais::Stats,
    /// relMSE after every pass.
    pub curve: Vec<CurvePoint>,
    /// The most AIS state one thread held (bytes).
    pub ais_memory_per_thread: usize,
    /// The final image's relative error with every pixel alike
    /// ([`metrics::PixelWeight::RelativeAlike`]) and its MSE in radiance, less the
    /// reference's noise.
    pub alike: AlikeErrors,
}

/// A run's errors with every pixel weighted alike: by its relative error, and by its
/// absolute error.
#[derive(Clone, Copy, Debug)]
pub struct AlikeErrors {
    /// Relative error, ε = 10⁻⁴.
    pub relative: f64,
    /// Squared error in radiance.
    pub mse: f64,
}

impl Run {
    /// The final relMSE.
    pub fn rel_mse(&self) -> f64 {
        self.curve.last().map_or(f64::NAN, |p| p.rel_mse)
    }

    /// The final error with pixels weighed by `weight`: relMSE, or one of the errors alike.
    pub fn error(&self, weight: metrics::PixelWeight) -> f64 {
        match weight {
            metrics::PixelWeight::Relative => self.rel_mse(),
            metrics::PixelWeight::RelativeAlike => self.alike.relative,
            metrics::PixelWeight::Alike => self.alike.mse,
        }
    }
}

/// A configuration's runs.
#[derive(Clone, Debug)]
pub struct ConfigurationResult {
    /// What was run.
    pub configuration: Configuration,
    /// Equal-time runs, one per seed (empty for the oracle).
    pub equal_time: Vec<Run>,
    /// Equal-ray runs, one per seed.
    pub equal_rays: Vec<Run>,
}

/// Everything a study measured.
#[derive(Clone, Debug)]
pub struct StudyResults {
    /// The reference.
    pub reference: reference::Reference,
    /// The ray budget of the equal-ray runs.
    pub ray_budget: u64,
    /// Per configuration, in the order given.
    pub results: Vec<ConfigurationResult>,
    /// The affinity-map figure's snapshots (None: the pixel sees no gather).
    pub figure: Option<Vec<affinity_figure::MapSnapshot>>,
}

/// Mean and standard error of the mean.
pub fn mean_and_error(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    if values.len() < 2 {
        return (mean, f64::NAN);
    }
    let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (variance / n).sqrt())
}

/// A pass's samples of each pixel: their ranks `first..first + count` in the run.
#[derive(Clone, Copy, Debug)]
pub struct SampleRange {
    /// The rank of the first.
    pub first: u32,
    /// How many.
    pub count: u32,
}

/// When a progressive run stops.
#[derive(Clone, Copy, Debug)]
enum Budget {
    Seconds(f64),
    Rays(u64),
}

impl Budget {
    /// The samples per pixel a run will have taken when this budget is spent, at the pace
    /// of its passes so far: `spp` samples in `seconds`, tracing `rays` (`None` before any).
    fn expected_samples(&self, spp: u32, seconds: f64, rays: u64) -> Option<u32> {
        let share_spent = match *self {
            Budget::Seconds(limit) => seconds / limit,
            Budget::Rays(limit) => rays as f64 / limit as f64,
        };
        (spp > 0 && share_spent > 0.0)
            .then(|| (spp as f64 / share_spent).min(MOST_PASSES as f64).round() as u32)
    }
}

fn progressive(
    world: &World,
    configuration: &Configuration,
    reference: &reference::Reference,
    (seed, pass_spp): (u64, u32),
    budget: Budget,
) -> Run {
    let (width, height) = (reference.image.width, reference.image.height);
    // The passes' films add up to the film of one render of all their samples.
    let mut film = Film::new(width, height);
    let mut run = Run {
        image: film.image(),
        spp: 0,
        seconds: 0.0,
        rays: RayCounts::default(),
        stats: ais::Stats::default(),
        curve: Vec::new(),
        ais_memory_per_thread: 0,
        alike: AlikeErrors {
            relative: f64::NAN,
            mse: f64::NAN,
        },
    };
    let mut learned = GatherLearning::new(world, &configuration.settings);
    let leading = configuration.leading_passes(world);
    let mut pass = 0;
    loop {
        // One seed for the run: its passes continue each pixel's camera sequence.
        let samples = SampleRange {
            first: run.spp,
            count: leading.get(pass).copied().unwrap_or(pass_spp),
        };
        // A render of its own knows its samples; a run knows its budget.
        learned.expect_samples(budget.expected_samples(run.spp, run.seconds, run.rays.total()));
        let output = configuration.render_pass(world, samples, seed, &mut learned);
        film.add_film(&output.film);
        run.spp += samples.count;
        pass += 1;
        run.seconds += output.seconds;
        run.rays.merge(output.rays);
        run.stats.merge(&output.stats);
        run.ais_memory_per_thread = run.ais_memory_per_thread.max(output.ais_memory_per_thread);
        run.image = film.image();
        run.curve.push(CurvePoint {
            seconds: run.seconds,
            rays: run.rays.total(),
            rel_mse: reference.rel_mse(&run.image),
        });
        let spent = match budget {
            Budget::Seconds(limit) => run.seconds >= limit,
            Budget::Rays(limit) => run.rays.total() >= limit,
        };
        if spent || run.spp >= MOST_PASSES {
            run.alike = AlikeErrors {
                relative: reference.error(&run.image, metrics::PixelWeight::RelativeAlike),
                mse: reference.error(&run.image, metrics::PixelWeight::Alike),
            };
            return run;
        }
    }
}

fn bar(progress: &MultiProgress, enabled: bool, template: &str) -> ProgressBar {
    if !enabled {
        return ProgressBar::hidden();
    }
    let bar = progress.add(ProgressBar::new(0));
    bar.set_style(
        ProgressStyle::with_template(template)
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar
}

/// The study's reference: cached in the given files, or in temporary ones removed after.
fn study_reference(
    world: &World,
    settings: &StudySettings,
    progress: &ProgressBar,
) -> Result<reference::Reference, String> {
    let base = settings.configurations[0].settings;
    match &settings.reference_cache {
        Some(paths) => reference::reference(world, &base, settings.reference_spp, paths, progress),
        None => {
            let key = format!("ais study {}", std::process::id());
            let paths = reference::cache_paths(&std::env::temp_dir(), &key);
            let result =
                reference::reference(world, &base, settings.reference_spp, &paths, progress);
            for path in &paths {
                let _ = std::fs::remove_file(path);
            }
            result
        }
    }
}

/// The seed of run `s` of every configuration.
fn seed_of(s: u32) -> u64 {
    mix64(0xa15 ^ s as u64)
}

/// What the runs share: the scene, the reference, the settings and the progress bar.
struct Runner<'a> {
    world: &'a World,
    reference: &'a reference::Reference,
    settings: &'a StudySettings,
    bar: &'a ProgressBar,
}

impl Runner<'_> {
    /// Every configuration at equal time (but the oracle), then at equal rays with the
    /// baseline's median ray count, which is returned too. The equal-time runs take turns,
    /// seed by seed (every configuration's first seed, then every configuration's second,
    /// …): the machine's drift during the study touches every configuration alike.
    fn all(&self) -> (Vec<ConfigurationResult>, u64) {
        let time_budget = Budget::Seconds(self.settings.time_budget.as_secs_f64());
        let configurations = &self.settings.configurations;
        let mut equal_time: Vec<Vec<Run>> = configurations.iter().map(|_| Vec::new()).collect();
        for s in 0..self.settings.seeds {
            for (configuration, runs) in configurations.iter().zip(&mut equal_time) {
                if !configuration.is_oracle() {
                    runs.push(self.run(configuration, time_budget, seed_of(s), s));
                }
            }
        }
        let mut results: Vec<ConfigurationResult> = configurations
            .iter()
            .zip(equal_time)
            .map(|(configuration, equal_time)| ConfigurationResult {
                configuration: configuration.clone(),
                equal_time,
                equal_rays: Vec::new(),
            })
            .collect();
        let mut baseline_rays: Vec<u64> = results[0]
            .equal_time
            .iter()
            .map(|r| r.rays.total())
            .collect();
        baseline_rays.sort_unstable();
        let ray_budget = baseline_rays[baseline_rays.len() / 2];
        for result in &mut results {
            result.equal_rays = (0..self.settings.seeds)
                .map(|s| {
                    let seed = seed_of(s) ^ 0xe0;
                    self.run(&result.configuration, Budget::Rays(ray_budget), seed, s)
                })
                .collect();
        }
        (results, ray_budget)
    }

    /// Run `s` of `configuration` within `budget`, seeded with `seed`.
    fn run(&self, configuration: &Configuration, budget: Budget, seed: u64, s: u32) -> Run {
        let what = match budget {
            Budget::Seconds(_) => "equal time",
            Budget::Rays(_) => "equal rays",
        };
        self.bar
            .set_message(format!("{} ({what}, seed {s})", configuration.name));
        let run = progressive(
            self.world,
            configuration,
            self.reference,
            (seed, self.settings.pass_spp),
            budget,
        );
        self.bar.inc(1);
        run
    }
}

/// Runs the study on `world` (its resolution as given).
pub fn run(world: &World, settings: &StudySettings) -> Result<StudyResults, String> {
    if settings.configurations.is_empty() || settings.seeds == 0 || settings.pass_spp == 0 {
        return Err(
            "a study needs at least one configuration, one seed and one sample per pass".into(),
        );
    }
    if settings.configurations[0].is_oracle() {
        return Err("the first configuration is the baseline and cannot be the oracle".into());
    }
    let multi = MultiProgress::with_draw_target(ProgressDrawTarget::stderr());
    let reference_bar = bar(
        &multi,
        settings.progress,
        "reference  [{bar:40}] {pos}/{len} spp, {elapsed} elapsed, ETA {eta}",
    );
    let reference = study_reference(world, settings, &reference_bar)?;
    reference_bar.finish_and_clear();
    let timed = settings
        .configurations
        .iter()
        .filter(|c| !c.is_oracle())
        .count();
    let study_bar = bar(
        &multi,
        settings.progress,
        "study      [{bar:40}] {pos}/{len} runs, {elapsed} elapsed, ETA {eta}  {msg}",
    );
    study_bar.set_length((timed + settings.configurations.len()) as u64 * settings.seeds as u64);
    let runner = Runner {
        world,
        reference: &reference,
        settings,
        bar: &study_bar,
    };
    let (results, ray_budget) = runner.all();
    study_bar.finish_and_clear();
    let base = settings.configurations[0].settings;
    let figure = affinity_figure::snapshots(world, &base, settings.figure_pixel, seed_of(0));
    Ok(StudyResults {
        reference,
        ray_budget,
        results,
        figure,
    })
}

/// Writes `text` to `path` through a temporary file (an error names the path).
pub fn write_text(path: &Path, text: &str) -> Result<(), String> {
    ais_render::atomic_write::write_atomically(path, |temporary| std::fs::write(temporary, text))
        .map_err(|e: std::io::Error| format!("{}: cannot write: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_run_expects_the_samples_its_budget_buys_at_its_pace() {
        let seconds = Budget::Seconds(3.0);
        assert_eq!(seconds.expected_samples(0, 0.0, 0), None, "no pass yet");
        assert_eq!(seconds.expected_samples(4, 0.5, 1000), Some(24));
        assert_eq!(
            Budget::Rays(10_000).expected_samples(4, 0.5, 1000),
            Some(40)
        );
        // A pass that took no measurable time does not promise endless samples.
        assert_eq!(seconds.expected_samples(4, 0.0, 1000), None);
        assert_eq!(seconds.expected_samples(4, 1e-12, 1), Some(MOST_PASSES));
    }
}
