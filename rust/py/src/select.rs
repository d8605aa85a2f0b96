//! Binding of `contactlab_core::select`: order statistics.

use contactlab_core::select::order_stats;
use numpy::{IntoPyArray, PyReadonlyArray1};
use pyo3::prelude::*;

use crate::error::slice;
use crate::{detach_guarded, Arr};

/// The values of rank `ranks` (0-based, ascending values) of `x`, those of a sort
/// (`contactlab_core::select::order_stats`: near the ends of a long sample from its tails
/// only); `x` finite (the caller's check).
#[pyfunction]
#[pyo3(name = "order_stats")]
fn order_stats_py<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    ranks: Vec<usize>,
) -> PyResult<Arr<'py>> {
    let xs = slice(&x, "x")?;
    let v = detach_guarded(py, || order_stats(xs, &ranks))?;
    Ok(v.into_pyarray(py))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(order_stats_py, m)?)?;
    Ok(())
}
