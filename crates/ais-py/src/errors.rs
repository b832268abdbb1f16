//! How the renderer's errors reach Python: `SceneError` for bad input (with `file`, `line`
//! and `message` attributes), `ValueError` for bad arguments.

use ais_render::InputError;
use pyo3::exceptions::{PyUserWarning, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(
    ais,
    SceneError,
    PyValueError,
    "A scene, mesh or image that cannot be used. Its attributes `file`, `line` (None where \
     unknown) and `message` say where and what."
);

/// `error` as a `SceneError` carrying its file, line and message.
pub fn scene_error(py: Python<'_>, error: &InputError) -> PyErr {
    let raised = SceneError::new_err(error.to_string());
    let value = raised.value(py);
    // Setting attributes on a fresh exception object cannot fail in practice; if it did,
    // the message still names the file and line.
    let _ = value.setattr("file", error.file.display().to_string());
    let _ = value.setattr("message", error.message.as_str());
    let _ = value.setattr("line", error.line);
    raised
}

/// A bad argument, as `ValueError`.
pub fn argument_error(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

/// Issues each warning about the input as a Python `UserWarning`.
pub fn warn_all(py: Python<'_>, warnings: &[String]) -> PyResult<()> {
    let category = py.get_type::<PyUserWarning>();
    for warning in warnings {
        let message = std::ffi::CString::new(warning.replace('\0', " "))
            .map_err(|e| argument_error(e.to_string()))?;
        PyErr::warn(py, &category, &message, 1)?;
    }
    Ok(())
}
