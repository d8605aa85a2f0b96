//! Binding of `contactlab_core::isotonic`: the monotone projection of a path.

use contactlab_core::isotonic::monotone_path;
use numpy::{IntoPyArray, PyReadonlyArray1};
use pyo3::prelude::*;

use crate::error::{input, slice};
use crate::{detach_guarded, Arr};

/// `x` projected on monotone stretches between `edges` (isotonic regressions; see
/// `contactlab_core::isotonic::monotone_path`).
#[pyfunction]
#[pyo3(name = "monotone_path")]
fn monotone_path_py<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    edges: PyReadonlyArray1<'py, i64>,
) -> PyResult<Arr<'py>> {
    let xs = slice(&x, "x")?;
    let mut ed = Vec::new();
    for &e in &edges.as_array() {
        ed.push(usize::try_from(e).map_err(|_| input(py, "edges must be >= 0"))?);
    }
    let out = detach_guarded(py, || monotone_path(xs, &ed))?;
    Ok(out.into_pyarray(py))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(monotone_path_py, m)?)?;
    Ok(())
}
