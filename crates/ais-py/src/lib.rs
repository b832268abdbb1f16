//! # ais for Python
//!
//! The extension module `ais._ais` behind the Python package `ais`: scenes loaded once and
//! rendered many times into numpy arrays ([`scene::Scene`]), with the GIL released while
//! the renderer works, and errors raised as `ais.SceneError` naming the file and line; and
//! the library's batch driver for Python hosts, many gathers per call ([`batch_set`]).

use pyo3::prelude::*;

mod batch_set;
mod compare;
mod errors;
mod field;
mod images;
mod options;
mod scene;
mod stats;

/// The extension module.
#[pymodule]
fn _ais(module: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = module.py();
    module.add("SceneError", py.get_type::<errors::SceneError>())?;
    module.add_class::<scene::Scene>()?;
    module.add_class::<batch_set::PyBatchSet>()?;
    module.add_class::<field::PyVisibilityField>()?;
    module.add_function(wrap_pyfunction!(images::write_exr, module)?)?;
    module.add_function(wrap_pyfunction!(compare::compare, module)?)?;
    module.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
