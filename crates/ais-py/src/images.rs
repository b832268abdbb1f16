//! `ais.write_exr`: an `(H, W, 3)` array written as a 32-bit float EXR, all or nothing.

use crate::errors::argument_error;
use ais_render::atomic_write::OutputSet;
use ais_render::image_io::{encode_exr, RgbImage};
use numpy::PyReadonlyArray3;
use pyo3::exceptions::PyOSError;
use pyo3::prelude::*;
use std::path::PathBuf;

/// Writes `image` (an `(H, W, 3)` float32 array) to `path` as an RGB EXR. The file appears
/// complete or not at all: an existing file is replaced only once the new one is written.
#[pyfunction]
pub fn write_exr(path: PathBuf, image: PyReadonlyArray3<'_, f32>) -> PyResult<()> {
    let view = image.as_array();
    let (height, width, channels) = view.dim();
    if channels != 3 || width == 0 || height == 0 {
        return Err(argument_error(format!(
            "image must have shape (H, W, 3) with H, W ≥ 1, not {:?}",
            view.dim()
        )));
    }
    let pixels = view
        .outer_iter()
        .flat_map(|row| {
            row.outer_iter()
                .map(|p| [p[0], p[1], p[2]])
                .collect::<Vec<_>>()
        })
        .collect();
    let image = RgbImage {
        width,
        height,
        pixels,
    };
    let mut outputs = OutputSet::default();
    outputs
        .stage(&path, |file| encode_exr(file, &image, &path))
        .map_err(|e| argument_error(e.0))?;
    outputs
        .commit()
        .map_err(|e| PyOSError::new_err(format!("{}: {e}", path.display())))
}
