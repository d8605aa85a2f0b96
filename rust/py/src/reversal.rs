//! Binding of `contactlab_core::reversal`: the streaming hysteresis-threshold reversal
//! detector.

use contactlab_core::reversal::{Excursion, Schmitt};
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;

use crate::detach_guarded;
use crate::error::{slice, to_pyerr};

/// Streaming hysteresis-threshold reversal detector (state carried across `push` calls).
#[pyclass(module = "contactlab._core")]
struct ReversalDetector {
    inner: Schmitt,
}

/// Excursions as columns, one row each (`push`, `open`): `sign`, `start`, `extreme`,
/// `last_beyond`, `extreme_value`, `returned`.
#[pyclass(module = "contactlab._core", frozen, get_all)]
struct ExcursionTable {
    sign: Py<PyArray1<i64>>,
    start: Py<PyArray1<i64>>,
    extreme: Py<PyArray1<i64>>,
    last_beyond: Py<PyArray1<i64>>,
    extreme_value: Py<PyArray1<f64>>,
    returned: Py<PyArray1<bool>>,
}

fn table(py: Python<'_>, ex: &[Excursion]) -> ExcursionTable {
    let idx = |f: &dyn Fn(&Excursion) -> u64| {
        ex.iter()
            .map(|e| i64::try_from(f(e)).unwrap_or(i64::MAX))
            .collect::<Vec<i64>>()
            .into_pyarray(py)
            .unbind()
    };
    ExcursionTable {
        sign: ex
            .iter()
            .map(|e| i64::from(e.sign))
            .collect::<Vec<_>>()
            .into_pyarray(py)
            .unbind(),
        start: idx(&|e| e.start),
        extreme: idx(&|e| e.extreme),
        last_beyond: idx(&|e| e.last_beyond),
        extreme_value: ex
            .iter()
            .map(|e| e.extreme_value)
            .collect::<Vec<_>>()
            .into_pyarray(py)
            .unbind(),
        returned: ex
            .iter()
            .map(|e| e.returned)
            .collect::<Vec<_>>()
            .into_pyarray(py)
            .unbind(),
    }
}

#[pymethods]
impl ReversalDetector {
    #[new]
    fn new(py: Python<'_>, centre: f64, threshold: f64) -> PyResult<Self> {
        let inner = Schmitt::new(centre, threshold).map_err(|e| to_pyerr(py, &e))?;
        Ok(Self { inner })
    }

    /// Excursions completed in this chunk (an `ExcursionTable`). `value` (default `x`) is where extremes are
    /// located. `finite`: the caller has checked the samples finite (no pass to check them).
    #[pyo3(signature = (x, value=None, finite=false))]
    fn push<'py>(
        &mut self,
        py: Python<'py>,
        x: PyReadonlyArray1<'py, f64>,
        value: Option<PyReadonlyArray1<'py, f64>>,
        finite: bool,
    ) -> PyResult<ExcursionTable> {
        let xs = slice(&x, "x")?;
        let vs = value.as_ref().map(|v| slice(v, "value")).transpose()?;
        let mut st = self.inner.clone();
        let (done, st) = detach_guarded(py, || {
            let mut done = Vec::new();
            if finite {
                st.push_finite(xs, vs, &mut done)?;
            } else {
                st.push(xs, vs, &mut done)?;
            }
            Ok((done, st))
        })?;
        self.inner = st;
        Ok(table(py, &done))
    }

    /// The excursion in progress (0 or 1 rows, same columns as `push`).
    fn open(&self, py: Python<'_>) -> ExcursionTable {
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
    m.add_class::<ExcursionTable>()?;
    Ok(())
}
