//! `ais._BatchSet`: the library's [`ais::BatchSet`] over numpy arrays, so that a Python host
//! drives many gathers per call (the package's `ais.BatchSet` wraps it and converts
//! arrays). Values are RGB.

use crate::errors::argument_error;
use crate::options::parameter_text;
use ais::{BatchConfig, BatchSet, Round};
use ais_render::integrators::gather::{GatherSettings, MapSource};
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Mutex;

/// The gather parameters a batch set takes (the rest need the renderer's neighbours).
const BATCH_PARAMETERS: [&str; 5] = ["ais", "budget", "placement", "map_res", "tol"];

/// Many gathers' batches, driven a round at a time with arrays.
#[pyclass(module = "ais", frozen, name = "_BatchSet")]
pub struct PyBatchSet {
    state: Mutex<State>,
}

struct State {
    set: BatchSet<[f32; 3]>,
    round: Round<[f32; 3]>,
}

/// The library configuration from `ais=…` and the other batch parameters.
fn batch_config(options: Option<&Bound<'_, PyDict>>) -> PyResult<BatchConfig> {
    let mut settings = GatherSettings::default();
    if let Some(options) = options {
        for (key, value) in options.iter() {
            let name: String = key.extract()?;
            if !BATCH_PARAMETERS.contains(&name.as_str()) {
                return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                    "BatchSet() got an unexpected keyword argument '{name}' (known: {})",
                    BATCH_PARAMETERS.join(", ")
                )));
            }
            settings
                .set(&name, &parameter_text(&value)?)
                .map_err(|m| argument_error(format!("{name}: {m}")))?;
        }
    }
    settings.validate().map_err(argument_error)?;
    if settings.map != MapSource::None && settings.map != MapSource::Batch {
        return Err(argument_error(
            "a batch set learns within each gather: ais must be off, aggressive or conservative",
        ));
    }
    Ok(settings.batch_config())
}

/// Checks that an array has one row per gather.
fn check_rows(name: &str, rows: usize, gathers: usize) -> PyResult<()> {
    if rows == gathers {
        Ok(())
    } else {
        Err(argument_error(format!(
            "{name} has {rows} rows for {gathers} gathers"
        )))
    }
}

#[pymethods]
impl PyBatchSet {
    #[new]
    #[pyo3(signature = (gathers, **options))]
    fn new(gathers: usize, options: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let config = batch_config(options)?;
        let set = BatchSet::new(config, gathers).map_err(|e| argument_error(format!("{e:?}")))?;
        let round = set.round_buffers();
        Ok(PyBatchSet {
            state: Mutex::new(State { set, round }),
        })
    }

    fn __len__(&self) -> usize {
        self.lock().set.len()
    }

    fn begin(&self, n: u32, seeds: PyReadonlyArray1<'_, u64>) -> PyResult<()> {
        let mut state = self.lock();
        let seeds = seeds.as_array();
        check_rows("seeds", seeds.len(), state.set.len())?;
        if n == 0 {
            return Err(argument_error("n must be at least 1"));
        }
        state.set.begin(n, &seeds.to_vec());
        Ok(())
    }

    fn next_candidates<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let mut state = self.lock();
        let State { set, round } = &mut *state;
        if set.awaits_record() {
            return Err(argument_error(
                "record() the traced candidates before the next round",
            ));
        }
        set.next_candidates(round);
        let active = Array1::from(round.active.clone()).into_pyarray(py);
        let u = Array2::from(round.u.clone()).into_pyarray(py);
        Ok((active.into_any(), u.into_any()))
    }

    fn decide<'py>(
        &self,
        py: Python<'py>,
        directions: PyReadonlyArray2<'_, f32>,
        in_support: PyReadonlyArray1<'_, bool>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let mut state = self.lock();
        let State { set, round } = &mut *state;
        let (directions, in_support) = (directions.as_array(), in_support.as_array());
        check_rows("directions", directions.nrows(), set.len())?;
        check_rows("in_support", in_support.len(), set.len())?;
        if directions.ncols() != 3 {
            return Err(argument_error("directions must have 3 columns"));
        }
        for (g, row) in directions.outer_iter().enumerate() {
            round.directions[g] = [row[0], row[1], row[2]];
            round.in_support[g] = in_support[g];
        }
        set.decide(round);
        let trace = Array1::from(round.trace.clone()).into_pyarray(py);
        let weight = Array1::from(round.weight.clone()).into_pyarray(py);
        Ok((trace.into_any(), weight.into_any()))
    }

    fn record(
        &self,
        contributions: PyReadonlyArray2<'_, f32>,
        ratings: PyReadonlyArray1<'_, f32>,
    ) -> PyResult<()> {
        let mut state = self.lock();
        let State { set, round } = &mut *state;
        let (contributions, ratings) = (contributions.as_array(), ratings.as_array());
        check_rows("contributions", contributions.nrows(), set.len())?;
        check_rows("ratings", ratings.len(), set.len())?;
        if contributions.ncols() != 3 {
            return Err(argument_error("contributions must have 3 columns (RGB)"));
        }
        for (g, row) in contributions.outer_iter().enumerate() {
            round.contributions[g] = [row[0], row[1], row[2]];
            round.ratings[g] = ratings[g];
        }
        set.record(round);
        Ok(())
    }

    fn finish<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let mut state = self.lock();
        if !state.set.is_finished() {
            return Err(argument_error(
                "finish() before every gather completed: call next_candidates() until none is active",
            ));
        }
        let estimates = state.set.finish();
        let values: Vec<[f32; 3]> = estimates.iter().map(|e| e.value).collect();
        let candidates: Vec<u32> = estimates.iter().map(|e| e.candidates).collect();
        let traced: Vec<u32> = estimates.iter().map(|e| e.traced).collect();
        Ok((
            Array2::from(values).into_pyarray(py).into_any(),
            Array1::from(candidates).into_pyarray(py).into_any(),
            Array1::from(traced).into_pyarray(py).into_any(),
        ))
    }

    /// Counters summed over every gather so far.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let stats = self.lock().set.stats();
        let dict = PyDict::new(py);
        dict.set_item("gathers", stats.batches)?;
        dict.set_item("candidates", stats.candidates)?;
        dict.set_item("traced", stats.traced)?;
        dict.set_item("rejected_outside_support", stats.rejected_outside_support)?;
        dict.set_item("rejected_by_roulette", stats.rejected_roulette)?;
        Ok(dict)
    }
}

impl PyBatchSet {
    fn lock(&self) -> std::sync::MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }
}
