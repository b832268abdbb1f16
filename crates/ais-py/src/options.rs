//! The keyword arguments of `Scene.render`: the render's own (`spp`, `resolution`, `seed`,
//! `threads`, `crop`, `progress`, `stats`) and any of the gather's parameters (`rays`,
//! `ais`, `strategy`, …, as in the scene's `<integrator type="gather">`).

use crate::errors::argument_error;
use ais_render::integrators::gather::settings::PARAMETERS;
use ais_render::request::ParameterOverride;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict};

/// A render's options, read from keyword arguments.
#[derive(Default)]
pub struct RenderOptions {
    /// Samples per pixel (None: the scene's).
    pub spp: Option<u32>,
    /// The film size `(width, height)` (None: the scene's).
    pub resolution: Option<(u32, u32)>,
    /// The base seed.
    pub seed: u64,
    /// Worker threads (None: all cores).
    pub threads: Option<usize>,
    /// `(x, y, w, h)` in pixels of the whole image.
    pub crop: Option<[usize; 4]>,
    /// Show a progress bar on stderr.
    pub progress: bool,
    /// Return `(image, stats)` rather than the image.
    pub stats: bool,
    /// Gather parameters by name, as text.
    pub gather: Vec<ParameterOverride<'static>>,
}

/// The render's own keywords.
const RENDER_KEYWORDS: [&str; 7] = [
    "spp",
    "resolution",
    "seed",
    "threads",
    "crop",
    "progress",
    "stats",
];

impl RenderOptions {
    /// Reads `kwargs`; an unknown keyword is a `TypeError` that lists the known ones.
    pub fn from_kwargs(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut options = RenderOptions::default();
        let Some(kwargs) = kwargs else {
            return Ok(options);
        };
        for (key, value) in kwargs.iter() {
            let name: String = key.extract()?;
            if value.is_none() {
                continue;
            }
            options.set(&name, &value)?;
        }
        Ok(options)
    }

    fn set(&mut self, name: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let named = |e: PyErr| argument_error(format!("{name}: {e}"));
        match name {
            "spp" => self.spp = Some(value.extract().map_err(named)?),
            "resolution" => self.resolution = Some(value.extract().map_err(named)?),
            "seed" => self.seed = value.extract().map_err(named)?,
            "threads" => self.threads = Some(value.extract().map_err(named)?),
            "crop" => {
                let (x, y, w, h) = value.extract().map_err(named)?;
                self.crop = Some([x, y, w, h]);
            }
            "progress" => self.progress = value.extract().map_err(named)?,
            "stats" => self.stats = value.extract().map_err(named)?,
            _ => {
                let Some(&parameter) = PARAMETERS.iter().find(|&&p| p == name) else {
                    return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                        "render() got an unexpected keyword argument '{name}' (render: {}; gather: {})",
                        RENDER_KEYWORDS.join(", "),
                        PARAMETERS.join(", ")
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

/// A Python value as the text the scene file would hold: `true`/`false` for booleans.
pub fn parameter_text(value: &Bound<'_, PyAny>) -> PyResult<String> {
    if let Ok(flag) = value.cast::<PyBool>() {
        return Ok(if flag.is_true() { "true" } else { "false" }.to_string());
    }
    Ok(value.str()?.to_string())
}
