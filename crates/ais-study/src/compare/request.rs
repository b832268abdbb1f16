//! What a front end asks of a study (the `ais compare` command, the Python package's
//! `ais.compare`), turned into [`StudySettings`], run, and written as a report.

use super::report::{self, ReportContext};
use super::summary::{summary, SummaryRow};
use super::{reference, talk_configurations, Configuration, StudyResults, StudySettings};
use ais_render::integrators::gather::{Acceptance, GatherSettings, Preset, Strategy};
use ais_render::request::settings_from_words;
use ais_render::world::World;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// A study of gather configurations on one scene.
#[derive(Clone, Copy, Debug)]
pub struct CompareRequest<'a> {
    /// The scene file (None: the built-in default scene); its bytes key the cached reference.
    pub scene: Option<&'a Path>,
    /// The scene's `$name` parameters (they key the cached reference too).
    pub defines: &'a [(String, String)],
    /// The report's folder (index.html, tables.md, images/, cache/).
    pub output: &'a Path,
    /// Wall time of each equal-time run, in seconds.
    pub time_budget: f64,
    /// Independent runs per configuration and budget.
    pub seeds: u32,
    /// Proposals to compare (empty with `configs` empty: the talk's configurations).
    pub strategies: &'a [String],
    /// Configurations: AIS presets or `name=value` words (the first is the baseline).
    pub configs: &'a [String],
    /// Add the oracle (with `strategies` or `configs`).
    pub oracle: bool,
    /// Samples per pixel of the reference.
    pub reference_spp: u32,
    /// Samples per pixel of each progressive pass.
    pub pass_spp: u32,
    /// The pixel of the affinity-map figure (None: the image centre).
    pub pixel: Option<(u32, u32)>,
    /// Show progress bars.
    pub progress: bool,
}

/// A finished study.
pub struct Comparison {
    /// Everything measured.
    pub results: StudyResults,
    /// One row per configuration: the tables as data.
    pub summary: Vec<SummaryRow>,
    /// The tables as Markdown.
    pub tables: String,
    /// The report's index.html.
    pub report: PathBuf,
}

/// A configuration's settings: a preset's name, or name=value words.
fn configuration_settings(base: &GatherSettings, text: &str) -> Result<GatherSettings, String> {
    match Preset::parse(text.trim()) {
        Some(preset) => Ok(base.with_preset(preset)),
        None if text.contains('=') => settings_from_words(base, text),
        None => Err(format!(
            "\"{text}\" is neither an AIS preset (off, aggressive, conservative, shared, warm, \
             guided, auto) nor name=value words"
        )),
    }
}

impl CompareRequest<'_> {
    /// The configurations: the talk's, or every strategy × configuration plus the oracle.
    pub fn configurations(&self, base: GatherSettings) -> Result<Vec<Configuration>, String> {
        if self.strategies.is_empty() && self.configs.is_empty() {
            return Ok(talk_configurations(base));
        }
        let strategies = match self.strategies {
            [] => vec!["mis".to_string()],
            given => given.to_vec(),
        };
        let configs = match self.configs {
            [] => vec!["off".to_string(), "aggressive".to_string()],
            given => given.to_vec(),
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
        if self.oracle {
            list.push(Configuration::oracle(
                &format!("{}-oracle", strategies[0]),
                "oracle: the first strategy restricted to directions that bring light",
                GatherSettings {
                    acceptance: Acceptance::Affinity,
                    ..list[0].settings.with_preset(Preset::Off)
                },
            ));
        }
        Ok(list)
    }

    /// The key of the cached reference: the scene file's hash, the defines, the size and
    /// the reference's settings.
    fn reference_key(&self, (width, height): (u32, u32), rays: u32) -> Result<String, String> {
        let scene_identity = match self.scene {
            Some(path) => {
                let bytes = std::fs::read(path)
                    .map_err(|e| format!("{}: cannot read the scene: {e}", path.display()))?;
                format!("{:016x}", reference::fnv1a(&bytes))
            }
            None => "built-in default scene".into(),
        };
        Ok(format!(
            "{scene_identity}|{:?}|{width}x{height}|{}|{}|{}|{}",
            self.defines,
            self.reference_spp,
            rays,
            env!("CARGO_PKG_VERSION"),
            "reference v3"
        ))
    }

    /// Checks the request and makes the study's settings for `world` with the base gather
    /// settings `base`.
    pub fn settings(&self, world: &World, base: GatherSettings) -> Result<StudySettings, String> {
        if !(self.time_budget > 0.0 && self.time_budget.is_finite()) {
            return Err("the time budget must be a positive number of seconds".into());
        }
        if self.seeds == 0 || self.reference_spp == 0 || self.pass_spp == 0 {
            return Err("seeds, reference spp and pass spp must be at least 1".into());
        }
        let (width, height) = world.resolution;
        let pixel = self.pixel.unwrap_or((width / 2, height / 2));
        if pixel.0 >= width || pixel.1 >= height {
            return Err(format!(
                "the figure's pixel {},{} is outside the {width}×{height} image",
                pixel.0, pixel.1
            ));
        }
        let key = self.reference_key(world.resolution, base.rays)?;
        Ok(StudySettings {
            configurations: self.configurations(base)?,
            time_budget: Duration::from_secs_f64(self.time_budget),
            seeds: self.seeds,
            reference_spp: self.reference_spp,
            pass_spp: self.pass_spp,
            reference_cache: Some(reference::cache_paths(&self.output.join("cache"), &key)),
            figure_pixel: pixel,
            progress: self.progress,
        })
    }

    /// Runs the study with `settings` (from [`CompareRequest::settings`]) and writes the
    /// report.
    pub fn run(&self, world: &World, settings: &StudySettings) -> Result<Comparison, String> {
        let results = super::run(world, settings)?;
        let scene_name = self.scene.map_or("the built-in default scene".into(), |p| {
            p.display().to_string()
        });
        let context = ReportContext {
            scene: &scene_name,
            resolution: world.resolution,
            rays: settings.configurations[0].settings.rays,
            time_budget: self.time_budget,
            seeds: self.seeds,
            reference_spp: self.reference_spp,
            threads: rayon::current_num_threads(),
            figure_pixel: settings.figure_pixel,
        };
        let report = report::write(self.output, &results, &context)?;
        Ok(Comparison {
            summary: summary(&results, &context),
            tables: report::markdown_tables(&results, &context),
            report,
            results,
        })
    }
}
