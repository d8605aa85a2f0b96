//! Binding of `contactlab_core::stream`: the reading side of a streamed analysis.

use contactlab_core::stream::fill_time;
use numpy::PyReadwriteArray1;
use pyo3::prelude::*;

use crate::detach_guarded;
use crate::error::input;

/// ``out[i] = t0 + dt * (offset + i)`` (see `contactlab_core::stream::fill_time`).
#[pyfunction]
#[pyo3(name = "fill_time")]
fn fill_time_py<'py>(
    py: Python<'py>,
    mut out: PyReadwriteArray1<'py, f64>,
    t0: f64,
    dt: f64,
    offset: u64,
) -> PyResult<()> {
    let os = out
        .as_slice_mut()
        .map_err(|_| input(py, "out must be a contiguous array"))?;
    detach_guarded(py, || fill_time(os, t0, dt, offset))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fill_time_py, m)?)?;
    Ok(())
}
