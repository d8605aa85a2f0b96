//! Binding of `contactlab_core::reversal`: the streaming hysteresis-threshold reversal
//! detector.

use contactlab_core::reversal::{Excursion, Schmitt};
use numpy::{IntoPyArray, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::detach_guarded;
use crate::error::{slice, to_pyerr};

/// Streaming hysteresis-threshold reversal detector (state carried across `push` calls).
#[pyclass(module = "contactlab._core")]
struct ReversalDetector {
    inner: Schmitt,
}

fn table<'py>(py: Python<'py>, ex: &[Excursion]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let idx = |f: &dyn Fn(&Excursion) -> u64| -> Vec<i64> {
        ex.iter()
            .map(|e| i64::try_from(f(e)).unwrap_or(i64::MAX))
            .collect()
    };
    d.set_item(
        "sign",
        ex.iter()
            .map(|e| i64::from(e.sign))
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    d.set_item("start", idx(&|e| e.start).into_pyarray(py))?;
    d.set_item("extreme", idx(&|e| e.extreme).into_pyarray(py))?;
    d.set_item("last_beyond", idx(&|e| e.last_beyond).into_pyarray(py))?;
    d.set_item(
        "extreme_value",
        ex.iter()
            .map(|e| e.extreme_value)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    d.set_item(
        "returned",
        ex.iter()
            .map(|e| e.returned)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    Ok(d)
}

#[pymethods]
impl ReversalDetector {
    #[new]
    fn new(py: Python<'_>, centre: f64, threshold: f64) -> PyResult<Self> {
        let inner = Schmitt::new(centre, threshold).map_err(|e| to_pyerr(py, &e))?;
        Ok(Self { inner })
    }

    /// Excursions completed in this chunk: dict of arrays `sign, start, extreme,
    /// last_beyond, extreme_value, returned`. `value` (default `x`) is where extremes are
    /// located.
    #[pyo3(signature = (x, value=None))]
    fn push<'py>(
        &mut self,
        py: Python<'py>,
        x: PyReadonlyArray1<'py, f64>,
        value: Option<PyReadonlyArray1<'py, f64>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let xs = slice(&x, "x")?;
        let vs = value.as_ref().map(|v| slice(v, "value")).transpose()?;
        let mut st = self.inner.clone();
        let (done, st) = detach_guarded(py, || {
            let mut done = Vec::new();
            st.push(xs, vs, &mut done)?;
            Ok((done, st))
        })?;
        self.inner = st;
        table(py, &done)
    }

    /// The excursion in progress (0 or 1 rows, same columns as `push`).
    fn open<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let open: Vec<Excursion> = self.inner.open.iter().copied().collect();
        table(py, &open)
    }

    #[getter]
    fn count(&self) -> u64 {
        self.inner.count
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<ReversalDetector>()?;
    Ok(())
}
