//! A render's statistics as a Python dict.

use ais_render::integrators::gather::{GatherSettings, GatherStats};
use ais_render::render::RenderOutput;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// What a render reports besides its image: time, rays, and the gather's counts per gather.
pub fn stats_dict<'py>(
    py: Python<'py>,
    output: &RenderOutput<GatherStats>,
    gather: &GatherSettings,
    samples_per_pixel: u32,
) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    let seconds = output.time.as_secs_f64();
    let ais = &output.stats.ais;
    let gathers = ais.batches.max(1) as f64;
    dict.set_item("render_time", seconds)?;
    dict.set_item("threads_busy", output.threads_busy())?;
    dict.set_item("spp", samples_per_pixel)?;
    dict.set_item("camera_rays", output.rays.closest_hit)?;
    dict.set_item("occlusion_rays", output.rays.occlusion)?;
    dict.set_item(
        "rays_per_second",
        output.rays.total() as f64 / seconds.max(1e-9),
    )?;
    dict.set_item("strategy", gather.strategy.name())?;
    dict.set_item("ais", gather.ais_label())?;
    dict.set_item("rays", gather.rays)?;
    dict.set_item("gathers", ais.batches)?;
    dict.set_item("candidates_per_gather", ais.candidates as f64 / gathers)?;
    dict.set_item("traced_per_gather", ais.traced as f64 / gathers)?;
    dict.set_item(
        "rejected_outside_support_per_gather",
        ais.rejected_outside_support as f64 / gathers,
    )?;
    dict.set_item(
        "rejected_by_roulette_per_gather",
        ais.rejected_roulette as f64 / gathers,
    )?;
    dict.set_item("memory_per_thread", output.stats.memory_per_thread)?;
    dict.set_item("field_memory", output.stats.field_memory)?;
    Ok(dict)
}
