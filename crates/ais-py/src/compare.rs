//! `ais.compare`: the study of `ais compare` from Python; returns its tables as dicts and
//! writes the HTML report.

use crate::errors::argument_error;
use crate::options::parameter_text;
use crate::scene::{defines, load};
use ais_render::request::{gather_settings, ParameterOverride};
use ais_study::compare::request::CompareRequest;
use ais_study::compare::summary::{Measured, SummaryRow};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::PathBuf;

/// The study's options, read from keyword arguments (the rest are gather parameters).
struct CompareOptions {
    output: PathBuf,
    time_budget: f64,
    seeds: u32,
    strategies: Vec<String>,
    configs: Vec<String>,
    oracle: bool,
    reference_spp: u32,
    pass_spp: u32,
    pixel: Option<(u32, u32)>,
    resolution: Option<(u32, u32)>,
    defines: Vec<(String, String)>,
    threads: Option<usize>,
    progress: bool,
    gather: Vec<ParameterOverride<'static>>,
}

impl Default for CompareOptions {
    /// `ais compare`'s defaults.
    fn default() -> Self {
        CompareOptions {
            output: "report".into(),
            time_budget: 3.0,
            seeds: 3,
            strategies: Vec::new(),
            configs: Vec::new(),
            oracle: true,
            reference_spp: 256,
            pass_spp: 1,
            pixel: None,
            resolution: None,
            defines: Vec::new(),
            threads: None,
            progress: false,
            gather: Vec::new(),
        }
    }
}

impl CompareOptions {
    fn from_kwargs(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut options = CompareOptions::default();
        for (key, value) in kwargs.into_iter().flat_map(|k| k.iter()) {
            let name: String = key.extract()?;
            if !value.is_none() {
                options.set(&name, &value)?;
            }
        }
        Ok(options)
    }

    fn set(&mut self, name: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let named = |e: PyErr| argument_error(format!("{name}: {e}"));
        match name {
            "output" => self.output = value.extract().map_err(named)?,
            "time_budget" => self.time_budget = value.extract().map_err(named)?,
            "seeds" => self.seeds = value.extract().map_err(named)?,
            "strategies" => self.strategies = value.extract().map_err(named)?,
            "configs" => self.configs = value.extract().map_err(named)?,
            "oracle" => self.oracle = value.extract().map_err(named)?,
            "reference_spp" => self.reference_spp = value.extract().map_err(named)?,
            "pass_spp" => self.pass_spp = value.extract().map_err(named)?,
            "pixel" => self.pixel = Some(value.extract().map_err(named)?),
            "resolution" => self.resolution = Some(value.extract().map_err(named)?),
            "defines" => self.defines = defines(Some(value.cast::<PyDict>()?))?,
            "threads" => self.threads = Some(value.extract().map_err(named)?),
            "progress" => self.progress = value.extract().map_err(named)?,
            _ => {
                let parameters = ais_render::integrators::gather::settings::PARAMETERS;
                let Some(&parameter) = parameters.iter().find(|&&p| p == name) else {
                    return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                        "compare() got an unexpected keyword argument '{name}'"
                    )));
                };
                self.gather.push(ParameterOverride {
                    name: parameter,
                    value: parameter_text(value)?,
                });
            }
        }
        Ok(())
    }
}

fn measured<'py>(py: Python<'py>, value: Measured) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    dict.set_item("mean", value.mean)?;
    dict.set_item("error", value.error)?;
    Ok(dict)
}

/// A summary row as a dict: name, label, oracle, equal_time (None for the oracle) and
/// equal_rays.
fn row_dict<'py>(py: Python<'py>, row: &SummaryRow) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    dict.set_item("name", &row.name)?;
    dict.set_item("label", &row.label)?;
    dict.set_item("oracle", row.oracle)?;
    let time = match &row.equal_time {
        None => None,
        Some(time) => {
            let entry = PyDict::new(py);
            entry.set_item("spp", time.spp)?;
            entry.set_item("ms_per_spp", time.ms_per_spp)?;
            entry.set_item("nominal_rays_per_pixel", time.nominal_rays_per_pixel)?;
            entry.set_item("traced_rays_per_pixel", time.traced_rays_per_pixel)?;
            entry.set_item("rejected_per_pixel", time.rejected_per_pixel)?;
            entry.set_item("ais_kib_per_thread", time.ais_kib_per_thread)?;
            entry.set_item("rel_mse", measured(py, time.rel_mse)?)?;
            entry.set_item("ratio", time.ratio)?;
            entry.set_item("mse", measured(py, time.mse)?)?;
            entry.set_item("mse_ratio", time.mse_ratio)?;
            entry.set_item("relative_alike", measured(py, time.relative_alike)?)?;
            entry.set_item("relative_alike_ratio", time.relative_alike_ratio)?;
            Some(entry)
        }
    };
    dict.set_item("equal_time", time)?;
    let rays = PyDict::new(py);
    rays.set_item("spp", row.equal_rays.spp)?;
    rays.set_item("seconds", row.equal_rays.seconds)?;
    rays.set_item("rel_mse", measured(py, row.equal_rays.rel_mse)?)?;
    rays.set_item("ratio", row.equal_rays.ratio)?;
    rays.set_item("mse", measured(py, row.equal_rays.mse)?)?;
    rays.set_item("mse_ratio", row.equal_rays.mse_ratio)?;
    rays.set_item(
        "relative_alike",
        measured(py, row.equal_rays.relative_alike)?,
    )?;
    rays.set_item("relative_alike_ratio", row.equal_rays.relative_alike_ratio)?;
    rays.set_item("oracle_share", row.equal_rays.oracle_share)?;
    dict.set_item("equal_rays", rays)?;
    Ok(dict)
}

/// Runs the study of gather configurations on `scene` (a path, or None for the built-in
/// default scene) and writes its report; returns the tables as dicts.
#[pyfunction]
#[pyo3(signature = (scene=None, **options))]
pub fn compare<'py>(
    py: Python<'py>,
    scene: Option<&Bound<'py, PyAny>>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let options = CompareOptions::from_kwargs(options)?;
    let file: Option<PathBuf> = match scene.filter(|s| !s.is_none()) {
        None => None,
        Some(scene) => Some(scene.extract().map_err(|_| {
            argument_error("compare needs a scene file's path (or None for the built-in scene)")
        })?),
    };
    let resolution = options.resolution.or(file.is_none().then_some((320, 180)));
    let world = load(py, scene, &options.defines, resolution)?;
    let mut warnings = Vec::new();
    let base = gather_settings(&world, &options.gather, str::to_string, &mut warnings)
        .map_err(argument_error)?;
    crate::errors::warn_all(py, &warnings)?;
    let request = CompareRequest {
        scene: file.as_deref(),
        defines: &options.defines,
        output: &options.output,
        time_budget: options.time_budget,
        seeds: options.seeds,
        strategies: &options.strategies,
        configs: &options.configs,
        oracle: options.oracle,
        reference_spp: options.reference_spp,
        pass_spp: options.pass_spp,
        pixel: options.pixel,
        progress: options.progress,
    };
    let settings = request.settings(&world, base).map_err(argument_error)?;
    let run = || request.run(&world, &settings);
    let comparison = py
        .detach(|| crate::scene::on_threads(options.threads, run))?
        .map_err(argument_error)?;
    let result = PyDict::new(py);
    let rows = comparison
        .summary
        .iter()
        .map(|row| row_dict(py, row))
        .collect::<PyResult<Vec<_>>>()?;
    result.set_item("configurations", PyList::new(py, rows)?)?;
    result.set_item("tables", &comparison.tables)?;
    result.set_item("report", comparison.report.display().to_string())?;
    result.set_item("ray_budget", comparison.results.ray_budget)?;
    result.set_item(
        "reference_noise",
        comparison.results.reference.noise_floor(),
    )?;
    Ok(result)
}
