//! Binding of `contactlab_core::extrema`: one pass for finiteness and the extremes.

use contactlab_core::extrema::finite_min_max;
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;

use crate::detach_guarded;
use crate::error::input;

/// ``(all finite, min, max)`` of a float64 array in one pass, the extremes over its finite
/// values (``(inf, -inf)`` when none); see `contactlab_core::extrema::finite_min_max`.
#[pyfunction]
#[pyo3(name = "finite_min_max")]
fn finite_min_max_py<'py>(
    py: Python<'py>,
    v: PyReadonlyArray1<'py, f64>,
) -> PyResult<(bool, f64, f64)> {
    let vs = v
        .as_slice()
        .map_err(|_| input(py, "v must be a contiguous array"))?;
    detach_guarded(py, || Ok(finite_min_max(vs)))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(finite_min_max_py, m)?)?;
    Ok(())
}
