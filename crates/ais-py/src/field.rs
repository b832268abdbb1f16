//! `ais.VisibilityField`: the library's learned visibility field over arrays, for Python
//! hosts. Fixed while a pass renders (so roulette against it stays exactly unbiased);
//! what the pass traced is merged by `end_pass`.

use crate::errors::argument_error;
use ais::field::{CellKey, FieldObservations, VisibilityField};
use numpy::ndarray::{Array1, ArrayView1, ArrayView2};
use numpy::{IntoPyArray, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use std::sync::Mutex;

/// The learned field and the current pass's observations.
#[pyclass(module = "ais", frozen, name = "VisibilityField")]
pub struct PyVisibilityField {
    state: Mutex<FieldState>,
}

struct FieldState {
    field: VisibilityField,
    observations: FieldObservations,
}

/// Where each gather is: positions, normals and the spacing of neighbouring gathers there
/// (e.g. a few pixel footprints), as arrays of one row per gather.
struct Sites<'a> {
    positions: ArrayView2<'a, f32>,
    normals: ArrayView2<'a, f32>,
    spacings: ArrayView1<'a, f32>,
}

impl Sites<'_> {
    fn check(&self, rows: usize) -> PyResult<()> {
        let shapes = [
            self.positions.dim(),
            self.normals.dim(),
            (self.spacings.len(), 3),
        ];
        if shapes.iter().any(|&shape| shape != (rows, 3)) {
            return Err(argument_error(format!(
                "positions and normals must be ({rows}, 3) and spacings ({rows},)"
            )));
        }
        Ok(())
    }

    fn key(&self, g: usize) -> CellKey {
        let row = |a: &ArrayView2<f32>| [a[(g, 0)], a[(g, 1)], a[(g, 2)]];
        let level = CellKey::level_for(self.spacings[g]);
        CellKey::new(row(&self.positions), row(&self.normals), level)
    }
}

fn direction(directions: &ArrayView2<'_, f32>, g: usize) -> [f32; 3] {
    [directions[(g, 0)], directions[(g, 1)], directions[(g, 2)]]
}

#[pymethods]
impl PyVisibilityField {
    #[new]
    #[pyo3(signature = (side=ais::field::DEFAULT_SIDE, prior=ais::field::PRIOR_FREE))]
    fn new(side: u32, prior: f32) -> PyResult<Self> {
        if !(1..=64).contains(&side) {
            return Err(argument_error("side must lie in 1..=64"));
        }
        Ok(PyVisibilityField {
            state: Mutex::new(FieldState {
                field: VisibilityField::new(side).with_prior(prior),
                observations: FieldObservations::new(side),
            }),
        })
    }

    /// Each gather's acceptance for its candidate in `directions`: from the cell where the
    /// gather is, 1 where the field knows too little or predicts no gain (`cost_ratio`: a
    /// candidate's cost besides tracing over tracing's).
    fn acceptance<'py>(
        &self,
        py: Python<'py>,
        positions: PyReadonlyArray2<'_, f32>,
        normals: PyReadonlyArray2<'_, f32>,
        spacings: PyReadonlyArray1<'_, f32>,
        directions: PyReadonlyArray2<'_, f32>,
        cost_ratio: f32,
    ) -> PyResult<Bound<'py, PyAny>> {
        let sites = Sites {
            positions: positions.as_array(),
            normals: normals.as_array(),
            spacings: spacings.as_array(),
        };
        let directions = directions.as_array();
        sites.check(directions.nrows())?;
        let mut state = self.lock();
        state.field.plan(cost_ratio);
        let acceptance: Vec<f32> = (0..directions.nrows())
            .map(|g| match state.field.cell(&sites.key(g)) {
                Some(cell) if cell.worth_rolling(cost_ratio) => {
                    cell.acceptance(direction(&directions, g), cost_ratio)
                }
                _ => 1.0,
            })
            .collect();
        Ok(Array1::from(acceptance).into_pyarray(py).into_any())
    }

    /// Records the traced rays (`traced`) of this pass: whether each arrived `free`.
    fn record(
        &self,
        positions: PyReadonlyArray2<'_, f32>,
        normals: PyReadonlyArray2<'_, f32>,
        spacings: PyReadonlyArray1<'_, f32>,
        directions: PyReadonlyArray2<'_, f32>,
        free: PyReadonlyArray1<'_, bool>,
        traced: PyReadonlyArray1<'_, bool>,
    ) -> PyResult<()> {
        let sites = Sites {
            positions: positions.as_array(),
            normals: normals.as_array(),
            spacings: spacings.as_array(),
        };
        let (directions, free, traced) =
            (directions.as_array(), free.as_array(), traced.as_array());
        sites.check(directions.nrows())?;
        if free.len() != directions.nrows() || traced.len() != directions.nrows() {
            return Err(argument_error("free and traced need one entry per gather"));
        }
        let mut state = self.lock();
        for g in (0..directions.nrows()).filter(|&g| traced[g]) {
            state
                .observations
                .record(sites.key(g), direction(&directions, g), free[g]);
        }
        Ok(())
    }

    /// Merges the pass's observations into the field; the next pass rolls against them.
    fn end_pass(&self) {
        let mut state = self.lock();
        let FieldState {
            field,
            observations,
        } = &mut *state;
        field.merge(observations);
        observations.clear();
    }

    /// Cells learned so far.
    #[getter]
    fn cell_count(&self) -> usize {
        self.lock().field.cell_count()
    }

    /// Bytes held by the field and the pass's observations.
    #[getter]
    fn memory_bytes(&self) -> usize {
        let state = self.lock();
        state.field.memory_bytes() + state.observations.memory_bytes()
    }
}

impl PyVisibilityField {
    fn lock(&self) -> std::sync::MutexGuard<'_, FieldState> {
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }
}
