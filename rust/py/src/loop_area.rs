//! Binding of `contactlab_core::loop_area` (and `masing::loop_area`): loop areas of cycles
//! and their noise sensitivity.

use contactlab_core::loop_area::{loop_area_sensitivity, loop_areas};
use contactlab_core::masing;
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;

use crate::error::slice;
use crate::{detach_guarded, FloatPair};

/// `∮ F dx` of the closed polygon through the samples (positive for a dissipative loop).
#[pyfunction]
#[pyo3(name = "loop_area")]
fn loop_area_py(
    py: Python<'_>,
    x: PyReadonlyArray1<'_, f64>,
    f: PyReadonlyArray1<'_, f64>,
) -> PyResult<f64> {
    let (xs, fs) = (slice(&x, "x")?, slice(&f, "F")?);
    detach_guarded(py, || masing::loop_area(xs, fs))
}

/// `∮ F dx` of each cycle between consecutive `bounds` (NaN below 3 samples).
#[pyfunction]
#[pyo3(name = "loop_areas")]
fn loop_areas_py<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    f: PyReadonlyArray1<'py, f64>,
    bounds: Vec<usize>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let (xs, fs) = (slice(&x, "x")?, slice(&f, "F")?);
    let a = detach_guarded(py, || loop_areas(xs, fs, &bounds))?;
    Ok(a.into_pyarray(py))
}

/// Per cycle between consecutive `bounds`: `(Σ coef_F², Σ coef_x²)`, the loop area's noise
/// sensitivities (see `contactlab_core::loop_area::loop_area_sensitivity`).
#[pyfunction]
#[pyo3(name = "loop_area_sensitivity")]
fn loop_area_sensitivity_py<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    f: PyReadonlyArray1<'py, f64>,
    bounds: Vec<usize>,
) -> PyResult<FloatPair<'py>> {
    let (xs, fs) = (slice(&x, "x")?, slice(&f, "F")?);
    let (a, b) = detach_guarded(py, || loop_area_sensitivity(xs, fs, &bounds))?;
    Ok((a.into_pyarray(py), b.into_pyarray(py)))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(loop_area_py, m)?)?;
    m.add_function(wrap_pyfunction!(loop_areas_py, m)?)?;
    m.add_function(wrap_pyfunction!(loop_area_sensitivity_py, m)?)?;
    Ok(())
}
