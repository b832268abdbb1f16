//! `ais._BatchSet`: the library's [`ais::BatchSet`] over numpy arrays, so that a Python host
//! drives many gathers per call (the package's `ais.BatchSet` wraps it and converts
//! arrays). Values are RGB. Gathers are split into chunks that run in parallel without the
//! GIL.

use crate::errors::argument_error;
use crate::options::parameter_text;
use ais::{BatchConfig, BatchSet, Round};
use ais_render::integrators::gather::{GatherSettings, MapSource, Preset};
use numpy::ndarray::{Array1, Array2, ArrayView2};
use numpy::{IntoPyArray, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use std::sync::Mutex;

/// The gather parameters a batch set takes (the rest need the renderer's neighbours).
const BATCH_PARAMETERS: [&str; 5] = ["ais", "budget", "placement", "map_res", "tol"];

/// Gathers per chunk: each chunk is a library `BatchSet` of its own, and chunks run in
/// parallel on rayon's threads (a chunk's batches stay in one thread's cache).
const CHUNK: usize = 1024;

/// Many gathers' batches, driven a round at a time with arrays.
#[pyclass(module = "ais", frozen, name = "_BatchSet")]
pub struct PyBatchSet {
    state: Mutex<Vec<Chunk>>,
    gathers: usize,
}

/// Consecutive gathers driven by one library batch set.
struct Chunk {
    set: BatchSet<[f32; 3]>,
    round: Round<[f32; 3]>,
    /// The index of its first gather.
    start: usize,
}

/// The library configuration from `ais=…` and the other batch parameters.
fn batch_config(options: Option<&Bound<'_, PyDict>>) -> PyResult<BatchConfig> {
    // A batch set learns within each gather: AIS off unless asked.
    let mut settings = GatherSettings::preset(Preset::Off);
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

/// Hands each gather's row of `rows` (one row of 3 per gather, checked) to `set`, with
/// the gather's chunk round, index in the chunk and index in the set.
fn scatter(
    chunks: &mut [Chunk],
    name: &str,
    rows: ArrayView2<'_, f32>,
    mut set: impl FnMut(&mut Round<[f32; 3]>, usize, [f32; 3], usize),
) -> PyResult<()> {
    let gathers: usize = chunks.iter().map(|c| c.set.len()).sum();
    check_rows(name, rows.nrows(), gathers)?;
    if rows.ncols() != 3 {
        return Err(argument_error(format!("{name} must have 3 columns")));
    }
    for chunk in chunks.iter_mut() {
        for g in 0..chunk.set.len() {
            let row = rows.row(chunk.start + g);
            set(
                &mut chunk.round,
                g,
                [row[0], row[1], row[2]],
                chunk.start + g,
            );
        }
    }
    Ok(())
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
        let mut chunks = Vec::new();
        for start in (0..gathers).step_by(CHUNK) {
            let set = BatchSet::new(config, CHUNK.min(gathers - start))
                .map_err(|e| argument_error(format!("{e:?}")))?;
            let round = set.round_buffers();
            chunks.push(Chunk { set, round, start });
        }
        Ok(PyBatchSet {
            state: Mutex::new(chunks),
            gathers,
        })
    }

    fn __len__(&self) -> usize {
        self.gathers
    }

    fn begin(&self, n: u32, seeds: PyReadonlyArray1<'_, u64>) -> PyResult<()> {
        let seeds = seeds.as_array();
        check_rows("seeds", seeds.len(), self.gathers)?;
        if n == 0 {
            return Err(argument_error("n must be at least 1"));
        }
        let seeds = seeds.to_vec();
        for chunk in self.lock().iter_mut() {
            let end = chunk.start + chunk.set.len();
            chunk.set.begin(n, &seeds[chunk.start..end]);
        }
        Ok(())
    }

    fn next_candidates<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let mut chunks = self.lock();
        if chunks.iter().any(|c| c.set.awaits_record()) {
            return Err(argument_error(
                "record() the traced candidates before the next round",
            ));
        }
        let all: &mut [Chunk] = &mut chunks;
        py.detach(|| {
            all.par_iter_mut()
                .for_each(|c| _ = c.set.next_candidates(&mut c.round));
        });
        let active: Vec<bool> = chunks.iter().flat_map(|c| c.round.active.clone()).collect();
        let u: Vec<[f32; 2]> = chunks.iter().flat_map(|c| c.round.u.clone()).collect();
        Ok((
            Array1::from(active).into_pyarray(py).into_any(),
            Array2::from(u).into_pyarray(py).into_any(),
        ))
    }

    #[pyo3(signature = (directions, in_support, acceptance=None))]
    fn decide<'py>(
        &self,
        py: Python<'py>,
        directions: PyReadonlyArray2<'_, f32>,
        in_support: PyReadonlyArray1<'_, bool>,
        acceptance: Option<PyReadonlyArray1<'_, f32>>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let (directions, in_support) = (directions.as_array(), in_support.as_array());
        check_rows("in_support", in_support.len(), self.gathers)?;
        let acceptance = acceptance.map(|a| a.as_array().to_vec());
        if let Some(acceptance) = &acceptance {
            check_rows("acceptance", acceptance.len(), self.gathers)?;
        }
        let mut chunks = self.lock();
        scatter(
            &mut chunks,
            "directions",
            directions,
            |round, g, row, global| {
                round.directions[g] = row;
                round.in_support[g] = in_support[global];
            },
        )?;
        let all: &mut [Chunk] = &mut chunks;
        py.detach(|| {
            all.par_iter_mut().for_each(|c| match &acceptance {
                None => c.set.decide(&mut c.round),
                Some(acceptance) => {
                    let own = &acceptance[c.start..c.start + c.set.len()];
                    c.set.decide_with(&mut c.round, own)
                }
            })
        });
        let trace: Vec<bool> = chunks.iter().flat_map(|c| c.round.trace.clone()).collect();
        let weight: Vec<f32> = chunks.iter().flat_map(|c| c.round.weight.clone()).collect();
        Ok((
            Array1::from(trace).into_pyarray(py).into_any(),
            Array1::from(weight).into_pyarray(py).into_any(),
        ))
    }

    fn record(
        &self,
        py: Python<'_>,
        contributions: PyReadonlyArray2<'_, f32>,
        ratings: PyReadonlyArray1<'_, f32>,
    ) -> PyResult<()> {
        let (contributions, ratings) = (contributions.as_array(), ratings.as_array());
        check_rows("ratings", ratings.len(), self.gathers)?;
        let mut chunks = self.lock();
        scatter(
            &mut chunks,
            "contributions",
            contributions,
            |round, g, row, global| {
                round.contributions[g] = row;
                round.ratings[g] = ratings[global];
            },
        )?;
        let all: &mut [Chunk] = &mut chunks;
        py.detach(|| all.par_iter_mut().for_each(|c| c.set.record(&c.round)));
        Ok(())
    }

    fn finish<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let mut chunks = self.lock();
        if !chunks.iter().all(|c| c.set.is_finished()) {
            return Err(argument_error(
                "finish() before every gather completed: call next_candidates() until none is active",
            ));
        }
        let estimates: Vec<_> = chunks.iter_mut().flat_map(|c| c.set.finish()).collect();
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
        let mut stats = ais::Stats::default();
        for chunk in self.lock().iter() {
            stats.merge(&chunk.set.stats());
        }
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
    fn lock(&self) -> std::sync::MutexGuard<'_, Vec<Chunk>> {
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }
}
