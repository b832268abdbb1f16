//! `ais.Scene`: a scene loaded once (meshes read, BVH built) and rendered many times.

use crate::errors::{argument_error, scene_error, warn_all};
use crate::options::{parameter_text, RenderOptions};
use crate::stats::stats_dict;
use ais_render::integrators::gather::{GatherSettings, GatherStats};
use ais_render::integrators::Integrator;
use ais_render::render::{render, PixelRect, RenderOutput, RenderSettings};
use ais_render::request::{gather_settings, load_world, SceneRequest, SceneSource};
use ais_render::world::World;
use numpy::ndarray::Array3;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::path::PathBuf;
use std::sync::RwLock;

/// The size of the built-in default scene when none is asked for.
const BUILT_IN_RESOLUTION: (u32, u32) = (640, 360);

/// A Mitsuba 3 XML scene (a file, XML text, or None for the built-in default scene) with
/// its `$name` parameters, ready to render.
#[pyclass(module = "ais", frozen)]
pub struct Scene {
    /// The world; written only to change the film size between renders.
    world: RwLock<World>,
    /// What messages call the scene.
    name: String,
    /// The scene's own film size, used when a render does not ask for another.
    resolution: (u32, u32),
    /// The scene's samples per pixel.
    sample_count: u32,
}

/// Where a scene argument points: XML text (it starts with `<`), a path, or nothing.
enum Source {
    Text(String),
    File(PathBuf),
    BuiltIn,
}

fn source(scene: Option<&Bound<'_, PyAny>>) -> PyResult<Source> {
    let Some(scene) = scene.filter(|s| !s.is_none()) else {
        return Ok(Source::BuiltIn);
    };
    if let Ok(text) = scene.extract::<String>() {
        if text.trim_start().starts_with('<') {
            return Ok(Source::Text(text));
        }
    }
    Ok(Source::File(scene.extract().map_err(|_| {
        argument_error("scene must be a path, XML text or None")
    })?))
}

/// `**defines` as `(name, text)` pairs.
pub fn defines(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<(String, String)>> {
    let Some(kwargs) = kwargs else {
        return Ok(Vec::new());
    };
    kwargs
        .iter()
        .map(|(name, value)| Ok((name.extract()?, parameter_text(&value)?)))
        .collect()
}

/// Loads a scene argument (a path, XML text or None) without the GIL; issues its
/// warnings as Python warnings.
pub fn load(
    py: Python<'_>,
    scene: Option<&Bound<'_, PyAny>>,
    defines: &[(String, String)],
    resolution: Option<(u32, u32)>,
) -> PyResult<World> {
    let source = source(scene)?;
    let world = py.detach(|| {
        let source = match &source {
            Source::Text(text) => SceneSource::Text {
                text,
                name: std::path::Path::new("<xml text>"),
            },
            Source::File(path) => SceneSource::File(path),
            Source::BuiltIn => SceneSource::BuiltIn,
        };
        load_world(&SceneRequest {
            source,
            defines,
            resolution,
            default_resolution: BUILT_IN_RESOLUTION,
        })
    });
    let world = world.map_err(|e| scene_error(py, &e))?;
    warn_all(py, &world.warnings)?;
    Ok(world)
}

#[pymethods]
impl Scene {
    /// Loads `scene` with `$name` parameters `**defines`.
    #[new]
    #[pyo3(signature = (scene=None, **defines))]
    fn new(
        py: Python<'_>,
        scene: Option<&Bound<'_, PyAny>>,
        defines: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let defines = self::defines(defines)?;
        let world = load(py, scene, &defines, None)?;
        Ok(Scene {
            name: world.description.file.display().to_string(),
            resolution: world.resolution,
            sample_count: world.sample_count,
            world: RwLock::new(world),
        })
    }

    /// The film size `(width, height)` the next render uses unless told otherwise.
    #[getter]
    fn resolution(&self) -> (u32, u32) {
        self.resolution
    }

    /// The scene's samples per pixel (its sampler's `sample_count`).
    #[getter]
    fn spp(&self) -> u32 {
        self.sample_count
    }

    /// The scene file (or what stands for it).
    #[getter]
    fn file(&self) -> &str {
        &self.name
    }

    /// Renders the scene's direct light with the gather; see the package's documentation.
    #[pyo3(signature = (**options))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        options: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let options = RenderOptions::from_kwargs(options)?;
        let job = self.prepare(py, &options)?;
        let threads = options.threads;
        let output = py.detach(|| self.run(&job, threads))?;
        let image = image_array(py, &output)?;
        if !options.stats {
            return Ok(image);
        }
        let stats = stats_dict(py, &output, &job.gather, job.settings.samples_per_pixel)?;
        Ok(PyTuple::new(py, [image, stats.into_any()])?.into_any())
    }

    fn __repr__(&self) -> String {
        let (width, height) = self.resolution;
        format!("ais.Scene({:?}, {width}×{height})", self.name)
    }
}

/// A render, checked and ready to run.
struct Job {
    gather: GatherSettings,
    settings: RenderSettings,
    resolution: (u32, u32),
}

impl Scene {
    fn read(&self) -> std::sync::RwLockReadGuard<'_, World> {
        self.world
            .read()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// Checks the options against the scene and builds the render's settings.
    fn prepare(&self, py: Python<'_>, options: &RenderOptions) -> PyResult<Job> {
        let world = self.read();
        let resolution = options.resolution.unwrap_or(self.resolution);
        if resolution.0 == 0 || resolution.1 == 0 || resolution.0 > 65536 || resolution.1 > 65536 {
            return Err(argument_error(format!(
                "resolution {resolution:?} is not a size in 1..=65536"
            )));
        }
        ais_render::limits::check_image_memory(resolution).map_err(argument_error)?;
        let mut warnings = Vec::new();
        let gather = gather_settings(&world, &options.gather, str::to_string, &mut warnings)
            .map_err(argument_error)?;
        warn_all(py, &warnings)?;
        let crop = options
            .crop
            .map(|crop| PixelRect::check_crop(crop, (resolution.0 as usize, resolution.1 as usize)))
            .transpose()
            .map_err(argument_error)?;
        let samples_per_pixel = options.spp.unwrap_or(self.sample_count);
        if samples_per_pixel == 0 {
            return Err(argument_error("spp must be at least 1"));
        }
        if let Some(threads) = options.threads {
            ais_render::limits::check_threads(threads, false).map_err(argument_error)?;
        }
        let settings = RenderSettings {
            samples_per_pixel,
            seed: options.seed,
            first_sample: 0,
            progress: options.progress,
            crop,
        };
        Ok(Job {
            gather,
            settings,
            resolution,
        })
    }

    /// Renders `job` on `threads` threads (all cores if None), without the GIL.
    fn run(&self, job: &Job, threads: Option<usize>) -> PyResult<RenderOutput<GatherStats>> {
        if self.read().resolution != job.resolution {
            let mut world = self.world.write().unwrap_or_else(|p| p.into_inner());
            world.set_resolution(job.resolution);
        }
        let world = self.read();
        let integrator = Integrator::Gather(job.gather);
        on_threads(threads, || render(&world, &integrator, &job.settings))
    }
}

/// Runs `work` on `threads` threads (None: the global pool, one per core).
pub fn on_threads<T: Send>(threads: Option<usize>, work: impl FnOnce() -> T + Send) -> PyResult<T> {
    match threads {
        None => Ok(work()),
        Some(threads) => {
            ais_render::limits::check_threads(threads, false).map_err(argument_error)?;
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .map(|pool| pool.install(work))
                .map_err(|e| argument_error(format!("cannot start {threads} threads: {e}")))
        }
    }
}

/// The image as an `(H, W, 3)` float32 array.
fn image_array<'py>(
    py: Python<'py>,
    output: &RenderOutput<GatherStats>,
) -> PyResult<Bound<'py, PyAny>> {
    let image = &output.image;
    let values: Vec<f32> = image.pixels.iter().flatten().copied().collect();
    let array = Array3::from_shape_vec((image.height, image.width, 3), values)
        .map_err(|e| argument_error(e.to_string()))?;
    Ok(array.into_pyarray(py).into_any())
}
